"""The symmetric two-impacts-per-period orbit of a two-sided stop (analysis.two_sided) against its defining conditions,
an independent integration (tests/analysis/impact_flow.py: DOP853, events on both gaps) and an analytic special case.

Derivation: the module docstring of vibroimpact.analysis.greens (antiperiodic Green function).
"""

from __future__ import annotations

import numpy as np
import pytest

from vibroimpact.analysis.impact_orbit import ImpactOrbit
from vibroimpact.analysis.stability import floquet_multipliers, half_period_jacobian, monodromy
from vibroimpact.analysis.two_sided import solve_two_impacts
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.contact import Stop
from vibroimpact.model.structure import LinearStructure
from vibroimpact.model.system import PAPER_SYSTEM

from tests.analysis.impact_flow import ImpactFlow
from tests.analysis.test_impact_orbit import finite_difference_monodromy, scales


def pair(clearance: float = 3e-3, restitution: float = 0.6, other: int | None = None) -> tuple[Stop, Stop]:
    """Upper and lower stop on x2 (or on x2 - x1), same clearance and restitution."""
    return (Stop(RigidStop(clearance, restitution), 1, other=other), Stop(RigidStop(clearance, restitution), 1, other=other, side="lower"))


def problem_at(frequency: float, other: int | None = None, phase: float = 0.3) -> ImpactProblem:
    return ImpactProblem(PAPER_SYSTEM.structure, pair(other=other), HarmonicForce(10.0, frequency, phase))


def test_impact_conditions_at_both_stops() -> None:
    """u(0) = Delta, u(T/2) = -Delta; each impact restitutes n.x' by -R with the impulse m_eff (1 + R) |n.x'(t-)|;
    x(t + T/2) = -x(t) over the period (1e-13 of the motion's scale)."""
    problem = problem_at(25.0)
    orbit = solve_two_impacts(problem)
    assert orbit.exists and orbit.admissible() and orbit.impacts_per_period == 2
    n, r, size = orbit.normal, float(orbit.restitution), problem.size
    period = float(orbit.period)
    states = orbit.state(np.array([[0.0, 0.5 * period, 0.5 * period * (1 + 1e-13), period]]))[0]
    length, velocity = scales(problem, orbit)[0], scales(problem, orbit)[-1]
    assert n @ states[0, :size] == pytest.approx(3e-3, abs=1e-14 * length)
    assert n @ states[1, :size] == pytest.approx(-3e-3, abs=1e-14 * length)
    before_upper, after_upper = n @ states[3, size:], n @ states[0, size:]
    before_lower, after_lower = n @ states[1, size:], n @ states[2, size:]
    assert before_upper > 0 > before_lower
    assert after_upper == pytest.approx(-r * before_upper, abs=1e-12 * velocity)
    assert after_lower == pytest.approx(-r * before_lower, abs=1e-12 * velocity)
    assert float(orbit.impulse) == pytest.approx(orbit.layout.effective_mass * (1 + r) * before_upper, rel=1e-12)
    t = np.linspace(0.0, 0.5, 11)[1:-1] * period
    first, second = orbit.state(t[None, :])[0], orbit.state(t[None, :] + 0.5 * period)[0]
    np.testing.assert_allclose(second, -first, atol=1e-13 * velocity)


@pytest.mark.parametrize(("frequency", "other"), [(25.0, None), (40.0, None), (23.0, 0)])
def test_orbit_repeats_under_independent_integration(frequency: float, other: int | None) -> None:
    """Absolute (x2, at 25 Hz stable and 40 Hz unstable) and relative (x2 - x1) pairs: the closed-form state integrated
    over 3 periods repeats to 1e-9 of the motion's scale; 6 impacts alternate upper/lower every T/2 with the closed
    form's impulse (1e-9)."""
    problem = problem_at(frequency, other)
    orbit = solve_two_impacts(problem)
    assert orbit.exists and orbit.admissible()
    start = orbit.state_at(np.array([0.0]))[0]
    end, impacts = ImpactFlow(problem).run(start, 0.0, 3 * problem.period)
    assert np.max(np.abs(end - start) / scales(problem, orbit)) < 1e-9
    assert len(impacts) == 6
    kinds = [impact.stop for impact in impacts]
    assert all(a != b for a, b in zip(kinds, kinds[1:]))
    for impact in impacts:
        assert impact.impulse == pytest.approx(float(orbit.impulse), rel=1e-9)
        offset = ((impact.time - float(orbit.impact_time)) / (0.5 * problem.period)) % 1.0
        assert min(offset, 1.0 - offset) < 1e-9


def test_monodromy_equals_integrated_jacobian_and_half_map_squared() -> None:
    """At 25 Hz: the multipliers equal the eigenvalues of the finite-difference Jacobian of the integrated map
    (1e-5 of the largest); the monodromy is the square of the half-period Jacobian (1e-12); det = R^4 exp(tr A T)."""
    problem = problem_at(25.0)
    orbit = solve_two_impacts(problem)
    expected = np.linalg.eigvals(finite_difference_monodromy(problem, orbit))
    ours = floquet_multipliers(orbit)
    largest = float(np.max(np.abs(expected)))
    np.testing.assert_allclose(np.sort(np.abs(ours)), np.sort(np.abs(expected)), atol=1e-5 * largest)
    full = monodromy(orbit)
    half = half_period_jacobian(orbit)
    np.testing.assert_allclose(half @ half, full, atol=1e-12 * np.max(np.abs(full)))
    determinant = np.linalg.det(full)
    trace = np.trace(PAPER_SYSTEM.state_matrix)
    assert determinant == pytest.approx(0.6**4 * np.exp(trace * problem.period), rel=1e-9)


def test_stable_orbit_attracts_a_perturbed_start() -> None:
    """max |mu| = 0.847 at 25 Hz: a start 1e-4 off the orbit is within 100 max|mu|^60 1e-4 of it after 60 periods."""
    problem = problem_at(25.0)
    orbit = solve_two_impacts(problem)
    modulus = float(np.max(np.abs(floquet_multipliers(orbit))))
    assert modulus < 0.9
    start = orbit.state_at(np.array([0.0]))[0]
    scale = scales(problem, orbit)
    end, _ = ImpactFlow(problem, rtol=1e-11).run(start + 1e-4 * scale * np.array([0.5, -1.0, 0.3, 0.4]), 0.0, 60 * problem.period)
    assert np.max(np.abs(end - start) / scale) < 100.0 * modulus**60 * 1e-4


def test_fundamental_harmonic_is_the_fourier_projection() -> None:
    """X = H F e^{j(phi - theta)} - (4 J / T) H n equals the Gauss-Legendre projection of the reconstructed motion
    over both halves of the period (1e-12 of |X|)."""
    orbit = solve_two_impacts(problem_at(25.0), omega=2 * np.pi * np.array([22.0, 25.0, 27.0]))
    points, weights = np.polynomial.legendre.leggauss(200)
    fractions = np.concatenate([(points + 1) / 4, (points + 3) / 4])
    weights = np.concatenate([weights, weights]) / 4
    t = fractions[None, :] * orbit.period[:, None]
    x = orbit.displacement(t)
    basis = 2.0 * np.exp(-1j * orbit.omega[:, None] * t)
    projection = np.einsum("smi,sm,m->si", x, basis, weights)
    harmonics = orbit.harmonics()
    np.testing.assert_allclose(projection, harmonics, atol=1e-12 * np.max(np.abs(harmonics)))


def test_undamped_oscillator_ellipse() -> None:
    """x'' + x = cos(w t), |x| <= sigma (unit mass): with h(t) = sin t, psi0 = -tan(T/4)/2 and psi'(0-) = -1/2, so the
    impact speed V = J / (1 + r) lies on (sigma - (1 + r) tan(T/4) V / 2)^2 + ((1 - r) V / (2 w))^2 = gamma^2,
    gamma = 1 / (1 - w^2) (the analogue of Budd & Dux's ellipse for the symmetric stop), to 1e-12."""
    oscillator = LinearStructure([[1.0]], [[1.0]], [[0.0]], ("x",))
    for w, r in ((2.8, 0.8), (0.6, 0.5), (1.7, 0.3)):
        stops = (Stop(RigidStop(0.1, r), 0), Stop(RigidStop(0.1, r), 0, side="lower"))
        problem = ImpactProblem(oscillator, stops, HarmonicForce(1.0, w / (2 * np.pi)))
        gamma, period = 1.0 / (1.0 - w * w), 2 * np.pi / w
        sigma = np.linspace(0.02, 1.2, 60) * abs(gamma)
        for root in ("+", "-"):
            orbit: ImpactOrbit = solve_two_impacts(problem, clearance=sigma, root=root)
            e = orbit.exists
            assert e.any() or root == "-"
            v = orbit.impulse[e] / (1 + r)
            residual = (sigma[e] - (1 + r) * np.tan(period / 4) * v / 2) ** 2 + ((1 - r) * v / (2 * w)) ** 2 - gamma**2
            assert np.all(np.abs(residual) < 1e-12 * gamma**2)
