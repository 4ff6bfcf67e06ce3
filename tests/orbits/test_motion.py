"""Classification of non-periodic motion: maps whose kind is known (Henon: chaotic; a map contracting onto an
invariant circle with irrational rotation: quasi-periodic; a stable period-5 orbit: contracting), the undecided
cases, and the paper's system past its Neimark-Sacker points (21.1 Hz: a torus; 37.5 Hz: chaos), each confirmed by
an independent method."""

from __future__ import annotations

import inspect
import math

import numpy as np
import pytest

from vibroimpact.analysis.stability import Regime
from vibroimpact.engines.exact import ExactEngine
from vibroimpact.engines.momentary import MomentaryEngine
from vibroimpact.orbits.lyapunov import LyapunovEstimate, lyapunov_two_trajectories
from vibroimpact.orbits.motion import MotionEvidence, MotionThresholds, classify_motion, classify_strobes

from tests.engine_cases import pgf_start
from tests.orbits.test_lyapunov import HENON_EXPONENT, henon


def circle_map(n: int, rho: float = math.sqrt(2.0) - 1.0, k: float = 0.3, contraction: float = 0.5) -> tuple[np.ndarray, np.ndarray, float]:
    """A planar map attracting onto the unit circle, r -> 1 + c (r - 1), theta -> theta + 2 pi rho + k sin(theta)
    (k < 1: a circle homeomorphism): strobes (n, 4) in a non-linear embedding, exact Jacobians (n, 2, 2) in (x, y),
    and the rotation number from the lifted angle itself."""
    r, theta = 1.3, 0.2
    strobes, jacobians, increments = np.empty((n, 4)), np.empty((n, 2, 2)), np.empty(n)

    def polar(radius: float, angle: float) -> np.ndarray:  # d(x, y) / d(r, theta)
        return np.array([[math.cos(angle), -radius * math.sin(angle)], [math.sin(angle), radius * math.cos(angle)]])

    for i in range(n):
        x, y = r * math.cos(theta), r * math.sin(theta)
        strobes[i] = x, y, 0.3 * x + 0.1 * y, -y + 0.2 * x * x
        r_next, theta_next = 1.0 + contraction * (r - 1.0), theta + 2.0 * math.pi * rho + k * math.sin(theta)
        jacobians[i] = polar(r_next, theta_next) @ np.diag([contraction, 1.0 + k * math.cos(theta)]) @ np.linalg.inv(polar(r, theta))
        increments[i] = theta_next - theta
        r, theta = r_next, theta_next
    return strobes, jacobians, float(np.mean(increments[n // 10 :]) / (2.0 * math.pi))


def test_henon_is_chaotic() -> None:
    points, jacobians = henon(4000)
    evidence = classify_motion(jacobians, points)
    assert evidence.kind == "chaotic" and evidence.regime is Regime.CHAOTIC and evidence.method == "jacobians"
    assert evidence.lyapunov_exponent == pytest.approx(HENON_EXPONENT, abs=4.0 * evidence.lyapunov_error + 5e-3)
    assert not evidence.rotation_regular and evidence.spectral_line_fraction < 0.5
    assert classify_strobes(points).kind == "chaotic"  # broadband and no rotation: the strobes alone decide too


def test_an_invariant_circle_is_quasi_periodic_with_its_rotation_number() -> None:
    strobes, jacobians, rho = circle_map(2000)
    evidence = classify_motion(jacobians[200:], strobes[200:])
    assert evidence.kind == "quasi_periodic" and evidence.regime is Regime.QUASI_PERIODIC
    assert abs(evidence.lyapunov_exponent) < 1e-3
    assert evidence.rotation_number == pytest.approx(min(rho, 1.0 - rho), abs=2e-3)
    assert evidence.rotation_regular and evidence.spectral_line_fraction > 0.99
    assert classify_strobes(strobes[200:]).kind == "quasi_periodic"


def test_a_stable_periodic_orbit_is_contracting_not_quasi_periodic() -> None:
    """A period-5 orbit attracting at e^-0.2 per period: the exponent is clearly negative, so no kind is claimed."""
    strobes, jacobians, _rho = circle_map(600, rho=0.4, k=0.0, contraction=0.5)
    jacobians = jacobians * math.exp(-0.2)  # the angle contracts too: a stable cycle
    evidence = classify_motion(jacobians, strobes)
    assert evidence.kind == "irregular" and evidence.regime is Regime.IRREGULAR
    assert evidence.lyapunov_exponent == pytest.approx(-0.2, abs=1e-9)
    assert "contracting" in evidence.reason


def test_undecided_evidence_is_irregular() -> None:
    strobes, _jacobians, _rho = circle_map(400)
    noise = np.random.default_rng(2).standard_normal((400, 4))
    uncertain = LyapunovEstimate(0.05, 0.03, 400, np.zeros(400), np.array([0.05]), np.array([0.03]))
    evidence = classify_strobes(noise, uncertain)
    assert evidence.kind == "irregular" and evidence.method == "estimate"  # positive, but within 3 errors
    zero = LyapunovEstimate(0.001, 0.001, 400, np.zeros(400), np.array([0.001]), np.array([0.001]))
    assert classify_strobes(noise, zero).kind == "irregular"  # exponent 0 but broadband strobes
    assert classify_strobes(strobes, zero).kind == "quasi_periodic"
    assert classify_strobes(strobes[:40], zero).kind == "irregular"  # too few periods
    assert "fewer" in classify_strobes(strobes[:40], zero).reason


def test_thresholds_and_kinds_are_validated() -> None:
    with pytest.raises(ValueError, match="chaotic_exponent"):
        MotionThresholds(chaotic_exponent=0.0)
    with pytest.raises(ValueError, match="broadband_fraction"):
        MotionThresholds(line_fraction=0.5, broadband_fraction=0.8)
    with pytest.raises(ValueError, match="kind"):
        MotionEvidence("periodic", 0.0, 0.0, 0.0, True, 1.0, 1.0, (), 100, "strobes", "")
    strict = MotionThresholds(zero_band=1e-6)
    strobes, jacobians, _rho = circle_map(2000)
    assert classify_motion(jacobians[200:], strobes[200:], strict).kind == "irregular"  # O(1/n) is not within 1e-6


# ------------------------------------------------------------------ the paper's system past its Neimark-Sacker points


def _has_jacobians() -> bool:
    return "jacobians" in inspect.signature(ExactEngine.integrate).parameters


@pytest.mark.skipif(not _has_jacobians(), reason="the exact engine does not return strobe Jacobians yet")
@pytest.mark.parametrize(("frequency", "kind", "exponent"), [(21.1, "quasi_periodic", 0.0), (37.5, "chaotic", 0.10)])
def test_the_paper_system_where_the_one_impact_orbit_is_unstable(frequency: float, kind: str, exponent: float) -> None:
    """Delta = 3 mm, q = 10 N, R = 0.2, 2000 periods from the perturbed one-impact orbit, then 1000 periods.

    21.1 Hz (past the loss near 21.2 Hz): an invariant circle, exponent 0 +- 0.003 from the exact Jacobians, its
    rotation number (0.159) equal to the strobe spectrum's strongest line. 37.5 Hz (below the loss near 39.0 Hz):
    chaos, exponent 0.10 +- 0.01 per period. Each exponent is confirmed by two nearby trajectories of the exact engine
    and of the ``momentary`` integrator (rtol 1e-8, separation 1e-6), which classify the same way."""
    problem, state, t0, _orbit = pgf_start(frequency, 0.2)
    engine = ExactEngine()
    settle = engine.integrate(problem, state * (1.0 + 1e-3), t0, 2000)
    run = engine.integrate(problem, settle.final_state, settle.strobe_times[-1], 1000, jacobians=True)  # type: ignore[call-arg]
    evidence = classify_motion(run.strobe_jacobians, run.strobe_states)
    assert evidence.kind == kind
    assert evidence.lyapunov_exponent == pytest.approx(exponent, abs=max(4.0 * evidence.lyapunov_error, 0.01))
    for other, periods in ((engine, 1000), (MomentaryEngine(), 200)):
        estimate = lyapunov_two_trajectories(other, problem, settle.final_state, settle.strobe_times[-1], periods)
        both = math.hypot(evidence.lyapunov_error, estimate.error)
        assert estimate.exponent == pytest.approx(evidence.lyapunov_exponent, abs=4.0 * both + 0.005)
        assert classify_strobes(run.strobe_states, estimate).kind == kind
    if kind == "quasi_periodic":
        assert evidence.rotation_regular and evidence.spectral_line_fraction > 0.99
        assert evidence.rotation_number == pytest.approx(evidence.peak_frequencies[0], abs=2.0 / 1000)
        assert 0.15 < evidence.rotation_number < 0.17
