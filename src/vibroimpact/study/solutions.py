"""The values of each solution over a study's grid: the closed forms (``linear``, ``pgf``, ``pgf_paper``) and the
steady states of the time-domain engines, each as ``{quantity: array}`` on the full grid (restitution, clearance,
bumper_frequency, sweep, frequency), or along the axes it depends on, broadcast by the caller."""

from __future__ import annotations

import functools
from typing import Callable

import numpy as np

from vibroimpact.analysis.linear import linear_response
from vibroimpact.analysis.pgf import OneImpactSolution, PgfVariant, green_models, solve_one_impact
from vibroimpact.analysis.regime import Regime, classify
from vibroimpact.analysis.stability import MARGINAL_MODULUS, floquet_multipliers
from vibroimpact.engines.registry import BUMPER, engine_spec
from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop, peak_acceleration_factor
from vibroimpact.scene.schema import MOTION_QUANTITIES, Scene
from vibroimpact.scene.variables import STABLE_MARGINAL
from vibroimpact.simulation.settings import SWEEP_STARTS
from vibroimpact.study.cases import FIELDS, SimulationCase
from vibroimpact.study.runner import Runner

__all__ = ["linear_values", "pgf_values", "peak_estimates", "no_one_impact_orbit", "simulated_values", "MARGINAL_MODULUS", "CASE_CHUNK"]

#: Frequencies per simulation case when points are independent (load balancing between processes).
CASE_CHUNK = 16
_IMPACT_REGIMES = (Regime.ONE_IMPACT, Regime.ONE_IMPACT_COEXISTING_LINEAR)
_LINEAR_REGIMES = (Regime.LINEAR, Regime.LINEAR_WITH_INADMISSIBLE_ONE_IMPACT, Regime.LINEAR_WITH_UNSTABLE_ONE_IMPACT)


def linear_values(scene: Scene, omega: np.ndarray, delta: np.ndarray, shape: tuple[int, ...]) -> dict[str, np.ndarray]:
    """The linear steady state (no stop) at ``omega`` [rad s-1], flagged where its absorber amplitude exceeds
    ``delta`` [m]; values of the scene's quantities broadcast to ``shape``."""
    response = linear_response(scene.system, omega, scene.amplitude)
    fits = np.abs(response.x2) <= delta
    values = {
        "x1_amplitude": np.abs(response.x1),
        "x2_amplitude": np.abs(response.x2),
        "force_amplitude": np.abs(response.force),
        "suspension_force_amplitude": np.abs(response.force),
        "impulse": np.zeros(shape),
        "phase": np.full(shape, np.nan),
        "regime": np.where(fits, Regime.LINEAR, Regime.LINEAR_EXCEEDS_CLEARANCE).astype(np.int8),
        **no_one_impact_orbit(shape),
        "impacts_per_period": np.zeros(shape),
        "converged": np.full(shape, -1, dtype=np.int8),
        "x1_rms": np.abs(response.x1) / np.sqrt(2.0) * np.ones(shape),
        "x2_rms": np.abs(response.x2) / np.sqrt(2.0) * np.ones(shape),
        "peak_acceleration": np.where(fits, 0.0, np.nan),
        "peak_contact_force": np.where(fits, 0.0, np.nan),
        "wall_time": np.full(shape, np.nan),
        **{name: np.full(shape, np.nan) for name in MOTION_QUANTITIES},
    }
    return {k: np.broadcast_to(v, shape) for k, v in values.items() if k in scene.quantities}


def pgf_values(scene: Scene, variant: PgfVariant, omega: np.ndarray, delta: np.ndarray, r: np.ndarray, shape: tuple[int, ...]) -> dict[str, np.ndarray]:
    """The one-impact periodic orbit of the PGF ``variant`` at ``omega`` [rad s-1], clearance ``delta`` [m] and
    restitution ``r`` [-] where it is admissible (and, for ``pgf``, stable), else the linear motion where that fits;
    each of the scene's quantities computed only if asked for."""
    solution = solve_one_impact(scene.system, omega, delta, r, scene.amplitude, variant, green_models(scene.system, variant))
    linear = linear_response(scene.system, np.broadcast_to(omega, shape), scene.amplitude)
    fits = solution.linear_amplitude_x2 <= solution.clearance
    admissible = solution.admissible(scene.admissibility)
    regime = classify(fits, solution.exists, admissible)
    modulus = np.full(shape, np.nan)
    if variant is PgfVariant.EXACT:
        # Floquet analysis of the exact orbits only: the paper variant's orbits are not orbits of the real system
        modulus = np.where(admissible, np.max(np.abs(floquet_multipliers(solution)), axis=-1), np.nan)
        unstable = modulus > 1.0 + MARGINAL_MODULUS
        regime[(regime == Regime.ONE_IMPACT_COEXISTING_LINEAR) & unstable] = Regime.LINEAR_WITH_UNSTABLE_ONE_IMPACT
    impact = np.isin(regime, _IMPACT_REGIMES)
    free = np.isin(regime, _LINEAR_REGIMES)

    def choose(impact_value: np.ndarray, linear_value: np.ndarray) -> np.ndarray:
        return np.where(impact, impact_value, np.where(free, linear_value, np.nan))

    # computed once each, and only if a quantity that needs them is asked for
    rms = functools.cache(solution.rms)
    peaks = functools.cache(lambda: peak_estimates(scene, solution, r))

    def stable_flag() -> np.ndarray:
        flag = np.where(np.abs(modulus - 1.0) <= MARGINAL_MODULUS, STABLE_MARGINAL, modulus < 1.0)
        return np.where(impact & np.isfinite(modulus), flag, -1).astype(np.int8)

    # each quantity is computed only if the scene asks for it
    makers: dict[str, Callable[[], np.ndarray]] = {
        "regime": lambda: regime,
        "x1_amplitude": lambda: choose(np.abs(solution.x1_harmonic()), np.abs(linear.x1)),
        "x2_amplitude": lambda: choose(np.abs(solution.x2_harmonic()), np.abs(linear.x2)),
        "force_amplitude": lambda: choose(np.abs(solution.force_harmonic()), np.abs(linear.force)),
        "suspension_force_amplitude": lambda: choose(np.abs(solution.suspension_force_harmonic()), np.abs(linear.force)),
        "impulse": lambda: choose(solution.impulse, np.zeros(shape)),
        "phase": lambda: np.where(impact, solution.phase, np.nan),
        "floquet_modulus": lambda: modulus,
        "stable": stable_flag,
        # the raw one-impact solution of eqs. 15-18 wherever it exists, admissible or not (what the paper plots)
        "one_impact_x1_amplitude": lambda: np.where(solution.exists, np.abs(solution.x1_harmonic()), np.nan),
        "one_impact_x2_amplitude": lambda: np.where(solution.exists, np.abs(solution.x2_harmonic()), np.nan),
        "one_impact_force_amplitude": lambda: np.where(solution.exists, np.abs(solution.force_harmonic()), np.nan),
        "one_impact_impulse": lambda: solution.impulse,
        "impacts_per_period": lambda: np.where(impact, 1.0, np.where(free, 0.0, np.nan)),
        "converged": lambda: np.full(shape, -1, dtype=np.int8),
        "x1_rms": lambda: choose(rms()[0], np.abs(linear.x1) / np.sqrt(2.0)),
        "x2_rms": lambda: choose(rms()[1], np.abs(linear.x2) / np.sqrt(2.0)),
        "peak_acceleration": lambda: choose(peaks()[0], np.zeros(shape)),
        "peak_contact_force": lambda: choose(peaks()[1], np.zeros(shape)),
        "wall_time": lambda: np.full(shape, np.nan),
        **{name: (lambda: np.full(shape, np.nan)) for name in MOTION_QUANTITIES},
    }
    return {q: makers[q]() for q in scene.quantities}


def peak_estimates(scene: Scene, solution: OneImpactSolution, r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """PGF-based peak deceleration of the absorber [m s-2] and peak bumper force [N] (section 6.3, corrected).

    The rigid-stop impulse J gives the entry speed v0 = J / (M2 (1 + R)); one collision with the bumper then peaks at
    the force M2 Gamma(xi_b) Omega_b v0. The absorber's deceleration is that force less the absorber spring's pull
    at the impact, K2 (X1 - Delta) + B2 (X1' - X2'(0-)), over M2 (the contact is too short for the spring to change).
    NaN without a bumper.
    """
    if scene.bumper_frequency is None:
        nan = np.full(np.broadcast_shapes(np.shape(solution.impulse), r.shape), np.nan)
        return nan, nan
    s = scene.system
    gamma = np.array([peak_acceleration_factor(xi) if np.isfinite(xi) else np.nan for xi in scene.loss_factors()])[:, None, None, None, None]
    omega_b = 2.0 * np.pi * scene.bumper_frequency[None, None, :, None, None]
    force = gamma * omega_b * solution.impulse / (1.0 + r)
    at_impact = np.zeros(1)
    with np.errstate(invalid="ignore"):
        spring = s.k2 * (solution.x1(at_impact)[..., 0] - solution.clearance) + s.b2 * (solution.x1(at_impact, 1)[..., 0] - solution.pre_impact_velocity)
    return (force - spring) / s.m2, force


def no_one_impact_orbit(shape: tuple[int, ...]) -> dict[str, np.ndarray]:
    """Values of the variables that describe the PGF orbit, for solutions that have none."""
    nan = np.full(shape, np.nan)
    return {
        "stable": np.full(shape, -1, dtype=np.int8),
        "floquet_modulus": nan,
        "one_impact_x1_amplitude": nan,
        "one_impact_x2_amplitude": nan,
        "one_impact_force_amplitude": nan,
        "one_impact_impulse": nan,
    }


def simulated_regime(fields: dict[str, np.ndarray], one_impact_orbit: np.ndarray) -> np.ndarray:
    """The ``regime`` flag of simulated steady states from a case's measured fields (the arrays of the grid).

    Not computed, failed, or: not converged -> the motion's own classification (quasi-periodic, chaotic) else
    irregular; converged -> linear when there was neither an impact nor a contact force (a structure held on a stop
    without impacts, by a preloading stop the force never lifts it from, is periodic motion with sticking, not
    linear), one impact where ``one_impact_orbit`` (the closed form's kind of orbit: one impact per period, or one
    on each side of a symmetric two-sided stop) holds at multiplicity 1, else periodic impacts.
    """
    computed = ~np.isnan(fields["converged"])
    converged = fields["converged"] == 1.0
    regime = np.full(fields["converged"].shape, Regime.NOT_COMPUTED, dtype=np.int8)
    regime[computed & ~converged] = Regime.IRREGULAR
    classified = computed & ~converged & ~np.isnan(fields["motion_regime"])
    regime[classified] = fields["motion_regime"][classified].astype(np.int8)  # quasi_periodic, chaotic or irregular
    regime[computed & converged] = Regime.PERIODIC_IMPACTS
    held = np.abs(fields["contact_force"]) > 1e-9 * (np.abs(fields["suspension_force"]) + np.abs(fields["contact_force"]))
    regime[computed & converged & (fields["impacts_per_period"] == 0.0) & ~held] = Regime.LINEAR
    regime[computed & converged & (fields["multiplicity"] == 1.0) & one_impact_orbit] = Regime.ONE_IMPACT
    regime[fields["failed"] == 1.0] = Regime.FAILED
    return regime


def simulated_values(scene: Scene, engine: str, shape: tuple[int, ...], runner: Runner) -> dict[str, np.ndarray]:
    """Steady states of a time-domain engine on the simulation grid; NaN at the other frequencies.

    Only a bumper engine (``compliant``) depends on the bumper: the rigid engines run once per (restitution, clearance).
    """
    assert scene.simulation is not None
    sim = scene.simulation
    columns = np.searchsorted(scene.all_frequencies, sim.frequency)
    on_bumper = engine_spec(engine).contact == BUMPER  # the registry says which contact law the engine solves
    bumpers = scene.bumper_frequency if on_bumper and scene.bumper_frequency is not None else np.array([np.nan])
    losses = scene.loss_factors() if on_bumper else np.full(scene.restitution.shape, np.nan)
    # a sweep is one chain; independent starts are split into chunks so that processes share the work evenly
    chunk = sim.frequency.size if sim.start in SWEEP_STARTS else CASE_CHUNK
    cases, places = [], []
    for i, restitution in enumerate(scene.restitution):
        for j, clearance in enumerate(scene.clearance):
            for k, bumper in enumerate(bumpers):
                for first in range(0, sim.frequency.size, chunk):
                    frequencies = tuple(float(f) for f in sim.frequency[first : first + chunk])
                    stop = RigidStop(float(clearance), float(restitution))  # the compliant engine's pgf start follows its orbit
                    contact = KelvinVoigtBumper(float(clearance), float(bumper), float(losses[i])) if on_bumper else stop
                    case = SimulationCase(engine, scene.system, scene.amplitude, contact, frequencies, sim.start, sim.engine, sim.steady, None if contact is stop else stop)
                    cases.append(case)
                    places.append((i, j, k, columns[first : first + chunk]))
    results = runner.map(cases)
    grid = (shape[0], shape[1], bumpers.size, 1, shape[4])
    fields = {name: np.full(grid, np.nan, dtype=complex if name in ("x1", "x2", "suspension_force", "contact_force") else float) for name in FIELDS}
    for (i, j, k, where), result in zip(places, results):
        for name in FIELDS:
            fields[name][i, j, k, 0, where] = result[name]
    computed = ~np.isnan(fields["converged"])
    converged = fields["converged"] == 1.0
    impacts = fields["impacts_per_period"]
    regime = simulated_regime(fields, impacts == 1.0)
    force = fields["suspension_force"] + fields["contact_force"]
    values = {
        "x1_amplitude": np.abs(fields["x1"]),
        "x2_amplitude": np.abs(fields["x2"]),
        "force_amplitude": np.abs(force),
        "suspension_force_amplitude": np.abs(fields["suspension_force"]),
        "impulse": fields["impulse_per_period"],
        "phase": np.full(grid, np.nan),
        "regime": regime,
        **no_one_impact_orbit(grid),
        "impacts_per_period": impacts,
        "converged": np.where(computed, converged, -1).astype(np.int8),
        "x1_rms": fields["x1_rms"],
        "x2_rms": fields["x2_rms"],
        "peak_acceleration": fields["peak_acceleration"],
        "peak_contact_force": fields["peak_contact_force"],
        "wall_time": fields["wall_time"],
        "lyapunov_exponent": fields["lyapunov_exponent"],
        "lyapunov_error": fields["lyapunov_error"],
        "rotation_number": fields["rotation_number"],
        "spectral_line_fraction": fields["spectral_line_fraction"],
    }
    return {q: values[q] for q in scene.quantities}
