"""Lyapunov exponents: the renormalised Jacobian product and the two-trajectory estimate against known exponents
(Henon map, logistic map, linear and triangular maps, the Floquet multipliers of the paper's one-impact orbit)."""

from __future__ import annotations

import inspect
import math
from types import SimpleNamespace

import numpy as np
import pytest

from vibroimpact.analysis.stability import floquet_multipliers
from vibroimpact.engines.exact import ExactEngine
from vibroimpact.engines.momentary import MomentaryEngine
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.orbits.lyapunov import block_estimate, lyapunov_from_jacobians, lyapunov_spectrum, lyapunov_two_trajectories, state_scales

from tests.engine_cases import pgf_start

#: Largest Lyapunov exponent of the Henon map a = 1.4, b = 0.3 [1/iteration] (0.41922 in Sprott, Chaos and Time-Series
#: Analysis, 2003); the two exponents sum to ln b exactly (det J = -b).
HENON_EXPONENT = 0.41922


def henon(n: int, start: tuple[float, float] = (0.1, 0.1), a: float = 1.4, b: float = 0.3) -> tuple[np.ndarray, np.ndarray]:
    """n points of the Henon attractor (after 1000 transient iterations) and the Jacobian at each."""
    x, y = start
    for _ in range(1000):
        x, y = 1.0 - a * x * x + y, b * x
    points, jacobians = np.empty((n, 2)), np.empty((n, 2, 2))
    for k in range(n):
        points[k] = x, y
        jacobians[k] = [[-2.0 * a * x, 1.0], [b, 0.0]]
        x, y = 1.0 - a * x * x + y, b * x
    return points, jacobians


def test_henon_largest_exponent_and_the_sum_of_the_spectrum() -> None:
    _points, jacobians = henon(20_000)
    largest = lyapunov_from_jacobians(jacobians)
    assert largest.exponent == pytest.approx(HENON_EXPONENT, abs=max(4.0 * largest.error, 2e-3))
    assert 0.0 < largest.error < 0.01 and largest.periods == 18_000
    spectrum = lyapunov_spectrum(jacobians)
    assert spectrum.spectrum[0] == pytest.approx(largest.exponent, abs=1e-3)  # same limit, another start vector
    assert spectrum.spectrum[1] < 0.0
    assert spectrum.spectrum.sum() == pytest.approx(math.log(0.3), abs=1e-12)  # ln |det J| every iteration


def test_the_error_estimate_is_honest() -> None:
    """Ten independent Henon runs of 2000 iterations: each is within 4 of its own errors of the exponent, and the
    spread of the ten estimates is of the size the errors claim (ratio between 1/3 and 3)."""
    estimates = [lyapunov_from_jacobians(henon(2000, start=(0.1 + 0.01 * i, 0.05))[1]) for i in range(10)]
    values = np.array([e.exponent for e in estimates])
    errors = np.array([e.error for e in estimates])
    assert np.all(np.abs(values - HENON_EXPONENT) < 4.0 * errors)
    assert 1.0 / 3.0 < np.std(values, ddof=1) / np.mean(errors) < 3.0


def test_logistic_map_at_r4_has_exponent_ln2() -> None:
    x, jacobians = 0.3, np.empty((20_000, 1, 1))
    for k in range(jacobians.shape[0]):
        jacobians[k, 0, 0] = 4.0 * (1.0 - 2.0 * x)
        x = 4.0 * x * (1.0 - x)
    estimate = lyapunov_from_jacobians(jacobians)
    assert estimate.exponent == pytest.approx(math.log(2.0), abs=max(4.0 * estimate.error, 5e-3))
    assert estimate.error < 0.01


def test_linear_map_exponents_are_the_logs_of_its_eigenvalue_moduli() -> None:
    """A constant non-normal 4 x 4 map with eigenvalues 1.5, -0.8 and 0.6 e^{+-i}: the exponents are ln|eigenvalue|
    (the complex pair twice), to round-off once the transient has aligned the frame."""
    eigenvalues = np.array([1.5, -0.8, 0.6 * np.exp(1j), 0.6 * np.exp(-1j)])
    rng = np.random.default_rng(3)
    basis = rng.standard_normal((4, 4))
    real_block = np.diag([1.5, -0.8, 0.0, 0.0])
    real_block[2:, 2:] = 0.6 * np.array([[math.cos(1.0), -math.sin(1.0)], [math.sin(1.0), math.cos(1.0)]])
    matrix = basis @ real_block @ np.linalg.inv(basis)
    np.testing.assert_allclose(np.sort(np.abs(np.linalg.eigvals(matrix))), np.sort(np.abs(eigenvalues)), rtol=1e-12)
    jacobians = np.broadcast_to(matrix, (400, 4, 4))
    largest = lyapunov_from_jacobians(jacobians)
    assert largest.exponent == pytest.approx(math.log(1.5), abs=1e-9)
    assert largest.error < 1e-9
    spectrum = lyapunov_spectrum(jacobians)
    # the complex pair's two exponents oscillate about ln 0.6 with the angle; their sum is exact
    np.testing.assert_allclose(spectrum.spectrum[:2], [math.log(1.5), math.log(0.8)], atol=1e-6)  # the second converges as 0.75^k
    assert spectrum.spectrum[2] + spectrum.spectrum[3] == pytest.approx(2.0 * math.log(0.6), abs=1e-6)
    assert spectrum.spectrum.sum() == pytest.approx(math.log(abs(np.prod(eigenvalues))), abs=1e-12)  # ln |det| per step
    np.testing.assert_allclose(spectrum.spectrum[2:], math.log(0.6), atol=0.02)


def test_a_rotation_has_exponent_zero_and_a_triangular_cocycle_its_mean_diagonal_logs() -> None:
    """Products of rotations keep every length: exponent 0. A random sequence of upper-triangular matrices has
    exponents equal to the mean logs of its diagonal entries (theorem for triangular cocycles), sorted."""
    rotation = np.array([[math.cos(2.0), -math.sin(2.0)], [math.sin(2.0), math.cos(2.0)]])
    assert lyapunov_from_jacobians(np.broadcast_to(rotation, (100, 2, 2))).exponent == pytest.approx(0.0, abs=1e-12)
    rng = np.random.default_rng(7)
    n, means = 20_000, np.array([-0.5, 0.3, -1.2])
    diagonal = np.exp(means + 0.4 * rng.standard_normal((n, 3))) * rng.choice([-1.0, 1.0], size=(n, 3))
    jacobians = np.triu(rng.standard_normal((n, 3, 3)))
    jacobians[:, range(3), range(3)] = diagonal
    truth = np.sort(np.log(np.abs(diagonal[n // 10 :])).mean(axis=0))[::-1]
    spectrum = lyapunov_spectrum(jacobians)
    np.testing.assert_allclose(spectrum.spectrum, truth, atol=4.0 * spectrum.spectrum_error.max() + 1e-3)
    assert lyapunov_from_jacobians(jacobians).exponent == pytest.approx(truth[0], abs=0.01)


def test_a_singular_jacobian_gives_minus_infinity() -> None:
    """Sticking can forget the absorber's state: a rank-deficient product can annihilate the tangent vector."""
    jacobians = np.broadcast_to(np.diag([0.0, 0.0]), (20, 2, 2))
    estimate = lyapunov_from_jacobians(jacobians, transient=0)
    assert estimate.exponent == -math.inf and estimate.error == math.inf
    assert lyapunov_spectrum(jacobians).spectrum[0] == -math.inf


def test_bad_input_is_refused() -> None:
    with pytest.raises(ValueError, match="shape"):
        lyapunov_from_jacobians(np.zeros((5, 2, 3)))
    with pytest.raises(ValueError, match="transient"):
        lyapunov_from_jacobians(np.ones((5, 1, 1)), transient=5)
    with pytest.raises(ValueError, match="non-finite"):
        lyapunov_spectrum(np.full((5, 1, 1), np.nan))
    with pytest.raises(ValueError, match="empty"):
        block_estimate([])
    assert block_estimate([1.0, 3.0], blocks=1) == (2.0, math.inf)


# ------------------------------------------------------------------ two nearby trajectories


class MapEngine:
    """A stand-in engine whose stroboscopic map is a given function, with optional noise of the size an integrator
    makes (relative to the state scales), independent between calls."""

    name = "map"

    def __init__(self, step, noise: float = 0.0, seed: int = 0) -> None:  # type: ignore[no-untyped-def]
        self.step, self.noise, self.rng = step, noise, np.random.default_rng(seed)

    def integrate(self, problem: ImpactProblem, state: np.ndarray, t_start: float, periods: int, moments: bool = False) -> SimpleNamespace:
        y = np.array(state, dtype=float)
        for _ in range(periods):
            y = self.step(y) + self.noise * state_scales(problem) * self.rng.standard_normal(4)
        return SimpleNamespace(final_state=y, strobe_times=np.array([t_start, t_start + periods * problem.period]))


def henon_4d(problem: ImpactProblem):  # type: ignore[no-untyped-def]
    """The Henon map on (X1, X1') in the problem's scales, two contracting directions on (X2, X2') kept far below
    the stop: exponents 0.419, ln 0.5 and ln 0.3 - 0.419."""
    scale = state_scales(problem)

    def step(y: np.ndarray) -> np.ndarray:
        x, v = y[0] / scale[0], y[2] / scale[2]
        return np.array([(1.0 - 1.4 * x * x + v) * scale[0], -0.5 * problem.clearance + 0.5 * (y[1] + 0.5 * problem.clearance), 0.3 * x * scale[2], 0.5 * y[3]])

    return step


@pytest.fixture(scope="module")
def problem_25hz() -> tuple[ImpactProblem, np.ndarray, float, object]:
    return pgf_start(25.0, 0.2)


@pytest.mark.slow
def test_two_trajectories_on_the_henon_map(problem_25hz: tuple) -> None:
    problem = problem_25hz[0]
    scale = state_scales(problem)
    start = np.array([0.1 * scale[0], -0.5 * problem.clearance, 0.1 * scale[2], 0.0])
    engine = MapEngine(henon_4d(problem))
    warm = engine.integrate(problem, start, 0.0, 500).final_state
    estimate = lyapunov_two_trajectories(engine, problem, warm, 0.0, 8000)
    assert estimate.exponent == pytest.approx(HENON_EXPONENT, abs=max(4.0 * estimate.error, 5e-3))
    every = lyapunov_two_trajectories(engine, problem, warm, 0.0, 8000, renormalise_every=2)
    assert every.exponent == pytest.approx(HENON_EXPONENT, abs=max(4.0 * every.error, 5e-3))


def test_two_trajectories_need_a_separation_above_the_engines_noise(problem_25hz: tuple) -> None:
    """A linear map with largest eigenvalue 0.9 (exponent ln 0.9 < 0) reproduced with noise 1e-9 of the scale: a
    separation of 1e-6 reads the exponent, one of 1e-10 reads the noise as growth (the docstring's warning)."""
    problem = problem_25hz[0]
    matrix = np.diag([0.9, 0.5, -0.4, 0.2])
    engine = MapEngine(lambda y: matrix @ y, noise=1e-9, seed=1)
    start = np.array([1e-4, -1e-3, 0.0, 0.0])
    good = lyapunov_two_trajectories(engine, problem, start, 0.0, 400)
    assert good.exponent == pytest.approx(math.log(0.9), abs=max(4.0 * good.error, 0.01))
    bad = lyapunov_two_trajectories(engine, problem, start, 0.0, 400, relative_size=1e-10)
    assert bad.exponent > 0.5


def test_the_perturbation_never_pushes_the_absorber_through_the_stop(problem_25hz: tuple) -> None:
    """The reference sits 1e-9 L below the stop and the separation grows with a positive X2 component: rescaled to
    1e-6 L it would start the perturbed copy inside the stop, which the engines refuse. Its X2 component is turned
    away from the stop instead, and the exponent (ln 2 of the expanding X1 direction) is still read."""
    problem = problem_25hz[0]
    length = state_scales(problem)[0]
    top = problem.clearance - 1e-9 * length

    def step(y: np.ndarray) -> np.ndarray:
        if y[1] > problem.clearance:
            raise ValueError("X2 > Delta: the absorber starts inside the stop")
        return np.array([2.0 * y[0], top + 0.5 * y[0], 0.0, 0.0])

    estimate = lyapunov_two_trajectories(MapEngine(step), problem, np.array([0.0, top, 0.0, 0.0]), 0.0, 20)
    assert estimate.exponent == pytest.approx(math.log(2.0), abs=1e-6)


def test_two_trajectories_refuse_bad_arguments(problem_25hz: tuple) -> None:
    problem, state, t0, _orbit = problem_25hz
    engine = MapEngine(lambda y: y)
    with pytest.raises(ValueError, match="relative_size"):
        lyapunov_two_trajectories(engine, problem, state, t0, 10, relative_size=0.1)
    with pytest.raises(ValueError, match="renormalise_every"):
        lyapunov_two_trajectories(engine, problem, state, t0, 3, renormalise_every=4)


# ------------------------------------------------------------------ the paper's system: Floquet multipliers as the truth


@pytest.mark.parametrize(("frequency", "periods"), [(25.0, 200), (37.0, 60)])
def test_two_exact_trajectories_on_the_one_impact_orbit_grow_as_its_largest_multiplier(frequency: float, periods: int) -> None:
    """Started on the PGF orbit (R = 0.2), a nearby copy approaches (25 Hz, stable) or leaves (37 Hz, past the
    Neimark-Sacker point) at the rate ln max |mu| of the closed-form Floquet multipliers. At 37 Hz the run is short
    enough (60 periods) that the reference stays on the unstable orbit (its own round-off grows as 1.30^k)."""
    problem, state, t0, orbit = pgf_start(frequency, 0.2)
    truth = float(np.log(np.abs(floquet_multipliers(orbit)[0])).max())
    estimate = lyapunov_two_trajectories(ExactEngine(), problem, state, t0, periods)
    assert estimate.exponent == pytest.approx(truth, abs=3.0 * estimate.error + 0.01)


def test_two_momentary_trajectories_on_the_stable_one_impact_orbit() -> None:
    """The integrator engine at its default rtol 1e-8 with the default separation 1e-6 reads the same rate."""
    problem, state, t0, orbit = pgf_start(25.0, 0.2)
    truth = float(np.log(np.abs(floquet_multipliers(orbit)[0])).max())
    estimate = lyapunov_two_trajectories(MomentaryEngine(), problem, state, t0, 100)
    assert estimate.exponent == pytest.approx(truth, abs=3.0 * estimate.error + 0.01)


def _has_jacobians() -> bool:
    return "jacobians" in inspect.signature(ExactEngine.integrate).parameters


@pytest.mark.skipif(not _has_jacobians(), reason="the exact engine does not return strobe Jacobians yet")
@pytest.mark.parametrize("frequency", [25.0, 37.0])
def test_exact_jacobians_give_the_floquet_exponent_on_the_one_impact_orbit(frequency: float) -> None:
    """The product of the exact engine's per-period Jacobians along the PGF orbit: every factor is the monodromy,
    so the exponents are ln |mu| of the closed-form multipliers."""
    problem, state, t0, orbit = pgf_start(frequency, 0.2)
    truth = np.sort(np.log(np.abs(floquet_multipliers(orbit)[0])))[::-1]
    trajectory = ExactEngine().integrate(problem, state, t0, 40, jacobians=True)  # type: ignore[call-arg]
    spectrum = lyapunov_spectrum(trajectory.strobe_jacobians)
    assert spectrum.spectrum[0] == pytest.approx(truth[0], abs=3.0 * spectrum.error + 0.02)
    assert spectrum.spectrum.sum() == pytest.approx(truth.sum(), abs=1e-6)


def test_exponent_along_a_run_of_a_linear_motion_is_its_slowest_decay() -> None:
    """Far from the stop the map is the flow exp(A T): every separation decays like the slowest mode, so the exponent
    is max Re(lambda) T per period (to 1 % over 320 periods: the separation turns in that mode's plane, and the mean
    converges like 1 / n), and the run used as its own reference gives what two separate trajectories give."""
    from vibroimpact.orbits.lyapunov import lyapunov_two_trajectories

    from vibroimpact.engines.exact import ExactEngine
    from vibroimpact.model.contact import RigidStop
    from vibroimpact.model.excitation import HarmonicForce
    from vibroimpact.model.problem import ImpactProblem
    from vibroimpact.model.system import PAPER_SYSTEM
    from vibroimpact.orbits.lyapunov import lyapunov_along_run

    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(1.0, 0.5), HarmonicForce(10.0, 25.0))
    run = ExactEngine().integrate(problem, np.zeros(4), 0.0, 320)
    estimate = lyapunov_along_run(ExactEngine(), problem, run, every=8)
    slowest = float(np.max(np.linalg.eigvals(PAPER_SYSTEM.state_matrix).real)) * problem.period
    assert estimate.exponent == pytest.approx(slowest, rel=1e-2)
    separate = lyapunov_two_trajectories(ExactEngine(), problem, np.zeros(4), 0.0, 320, renormalise_every=8)
    assert estimate.exponent == pytest.approx(separate.exponent, rel=1e-6)
    assert estimate.periods == 288  # exact: 40 intervals of 8 periods, the first 4 discarded
