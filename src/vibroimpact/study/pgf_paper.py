"""``pgf_paper``: the paper's own closed form over a study's grid, where the scene has the paper's layout on its named
system (:attr:`vibroimpact.model.problem.ImpactProblem.named_system`; the scene checker refuses it elsewhere).

The route is :func:`vibroimpact.analysis.pgf.solve_one_impact` with :attr:`~vibroimpact.analysis.pgf.PgfVariant.PAPER`:
curve-fitted modal parameters of H22 (eq. 10) and the constant chi22'(0-) = -1/(2 M2). Its orbits are not orbits of
the real system, so they get no Floquet analysis (``floquet_modulus`` NaN, ``stable`` not applicable). Values are laid
out as those of the other closed forms (:mod:`vibroimpact.study.general_values`): per-coordinate quantities named after
the coordinates (``x1``, ``x2``), per-stop ones with a leading axis of the one stop; where the orbit is not admissible
the linear motion (the same as ``linear``'s) stands where it fits.
"""

from __future__ import annotations

import functools
from typing import Callable

import numpy as np

from vibroimpact.analysis.linear import linear_amplitudes
from vibroimpact.analysis.pgf import OneImpactSolution, PgfVariant, green_models, solve_one_impact
from vibroimpact.analysis.regime import Regime, classify
from vibroimpact.model.contact import peak_acceleration_factor
from vibroimpact.model.system import TwoDofSystem
from vibroimpact.scene.schema import MOTION_QUANTITIES, Scene
from vibroimpact.simulation.layout import base_force
from vibroimpact.study.general_values import broadcast_quantities, first_problem, stop_clearances

__all__ = ["paper_pgf_values"]

_IMPACT_REGIMES = (Regime.ONE_IMPACT, Regime.ONE_IMPACT_COEXISTING_LINEAR)
_LINEAR_REGIMES = (Regime.LINEAR, Regime.LINEAR_WITH_INADMISSIBLE_ONE_IMPACT, Regime.LINEAR_WITH_UNSTABLE_ONE_IMPACT)


def paper_pgf_values(scene: Scene, omega: np.ndarray, delta: np.ndarray, r: np.ndarray, shape: tuple[int, ...]) -> dict[str, np.ndarray]:
    """The paper's one-impact orbit at ``omega`` [rad s-1] (axes of the full grid), clearance ``delta`` [m] and
    restitution ``r`` [-] where it is admissible, else the linear motion where that fits; NaN elsewhere. Each of the
    scene's quantities is computed only if asked for, broadcast to ``shape`` (per-stop ones to (1, *shape)).

    Raises
    ------
    ValueError
        If the scene does not have the paper's layout on its named system.
    """
    problem = first_problem(scene)
    system = problem.named_system
    if system is None:
        raise ValueError("pgf_paper is the paper's route for its layout (a two-mass chain x1, x2; one upper stop on x2; force on x1): use pgf")
    solution = solve_one_impact(system, omega, delta, r, scene.amplitude, PgfVariant.PAPER, green_models(system, PgfVariant.PAPER))
    w = np.broadcast_to(omega, shape)
    linear = linear_amplitudes(problem, w)
    fits = np.broadcast_to(linear.fits(stop_clearances(scene)[None, :, None, None, None, :]), shape)
    regime = classify(fits, solution.exists, solution.admissible(scene.admissibility))
    impact = np.isin(regime, _IMPACT_REGIMES)
    free = np.isin(regime, _LINEAR_REGIMES)

    def choose(impact_value: np.ndarray, linear_value: np.ndarray) -> np.ndarray:
        return np.where(impact, impact_value, np.where(free, linear_value, np.nan))

    def per_stop(values: np.ndarray) -> np.ndarray:
        return np.broadcast_to(values, shape)[None]

    rms = functools.cache(solution.rms)
    peaks = functools.cache(lambda: _peak_estimates(scene, system, solution, r, shape))
    x = linear.coordinates
    linear_force = np.abs(base_force(scene.system, w, x))
    linear_rms = np.sqrt(linear.static**2 + 0.5 * np.abs(x) ** 2)
    nan = np.full(shape, np.nan)
    makers: dict[str, Callable[[], np.ndarray]] = {
        "regime": lambda: regime,
        "x1_amplitude": lambda: choose(np.abs(solution.x1_harmonic()), np.abs(x[..., 0])),
        "x2_amplitude": lambda: choose(np.abs(solution.x2_harmonic()), np.abs(x[..., 1])),
        "force_amplitude": lambda: choose(np.abs(solution.force_harmonic()), linear_force),
        "suspension_force_amplitude": lambda: choose(np.abs(solution.suspension_force_harmonic()), linear_force),
        "impulse": lambda: per_stop(choose(solution.impulse, np.zeros(shape))),
        "phase": lambda: np.where(impact, solution.phase, np.nan),
        "floquet_modulus": lambda: nan,  # the paper's orbits are not orbits of the real system: no Floquet analysis
        "stable": lambda: np.full(shape, -1, dtype=np.int8),
        # the raw one-impact solution of eqs. 15-18 wherever it exists, admissible or not (what the paper plots)
        "one_impact_x1_amplitude": lambda: np.where(solution.exists, np.abs(solution.x1_harmonic()), np.nan),
        "one_impact_x2_amplitude": lambda: np.where(solution.exists, np.abs(solution.x2_harmonic()), np.nan),
        "one_impact_force_amplitude": lambda: np.where(solution.exists, np.abs(solution.force_harmonic()), np.nan),
        "one_impact_impulse": lambda: per_stop(solution.impulse),
        "impacts_per_period": lambda: np.where(impact, 1.0, np.where(free, 0.0, np.nan)),
        "converged": lambda: np.full(shape, -1, dtype=np.int8),
        "x1_rms": lambda: choose(rms()[0], linear_rms[..., 0]),
        "x2_rms": lambda: choose(rms()[1], linear_rms[..., 1]),
        "peak_acceleration": lambda: per_stop(choose(peaks()[0], np.zeros(shape))),
        "peak_contact_force": lambda: per_stop(choose(peaks()[1], np.zeros(shape))),
        "wall_time": lambda: nan,
        **{name: (lambda: nan) for name in MOTION_QUANTITIES},
    }
    return broadcast_quantities(scene, {q: makers[q]() for q in scene.quantities}, shape)


def _peak_estimates(scene: Scene, system: TwoDofSystem, solution: OneImpactSolution, r: np.ndarray, shape: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Peak deceleration of the absorber [m s-2] and peak bumper force [N] from the paper's impulse (section 6.3,
    corrected): one collision with the bumper entered at J / (M2 (1 + R)) peaks at M2 Gamma(xi_b) Omega_b v0; the
    deceleration is that force less the absorber spring's pull at the impact, K2 (X1 - Delta) + B2 (X1' - X2'(0-)),
    over M2. NaN without one bumper frequency (a swept bumper: one per grid point)."""
    if scene.bumper_frequency is None:
        return np.full(shape, np.nan), np.full(shape, np.nan)
    gamma = np.array([peak_acceleration_factor(xi) if np.isfinite(xi) else np.nan for xi in scene.loss_factors()])[:, None, None, None, None]
    omega_b = 2.0 * np.pi * scene.bumper_frequency[None, None, :, None, None]
    force = gamma * omega_b * solution.impulse / (1.0 + r)
    at_impact = np.zeros(1)
    with np.errstate(invalid="ignore"):
        spring = system.k2 * (solution.x1(at_impact)[..., 0] - solution.clearance) + system.b2 * (solution.x1(at_impact, 1)[..., 0] - solution.pre_impact_velocity)
    return np.broadcast_to((force - spring) / system.m2, shape), np.broadcast_to(force, shape)
