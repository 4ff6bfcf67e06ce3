"""Expand a scene into its grid, compute the solutions it asks for, and gather one labelled ``xarray.Dataset``.

Output contract (read by other tools; keep these names): dimensions ``solution`` (strings), each swept parameter
(``restitution`` [1], ``clearance`` [m]) and ``frequency`` [Hz]; variables ``x1_amplitude`` [m],
``x2_amplitude`` [m], ``force_amplitude`` [N], ``suspension_force_amplitude`` [N], ``impulse`` [N s], ``phase``
[rad] and ``regime`` (CF flags). Unswept stop parameters are scalar coordinates. Swept-sine scenes add dimension
``sweep``: the swept runs' estimates are ``swept_<quantity>`` (sweep, frequency) and their running estimates
``running_<quantity>`` (sweep, elapsed_time); the steady-state solutions are not repeated along ``sweep``.
"""

from __future__ import annotations

import functools
import sys
from dataclasses import asdict
from datetime import datetime, timezone
from pathlib import Path
from typing import Callable

import numpy as np
import xarray as xr

from vibroimpact import __version__
from vibroimpact.study.io import atomic_path
from vibroimpact.benchmarks.accuracy import run_benchmark
from vibroimpact.model.contact import peak_acceleration_factor
from vibroimpact.study.fingerprint import source_hash
from vibroimpact.analysis.linear import linear_response
from vibroimpact.model.modal import fit_modal_parameters
from vibroimpact.analysis.pgf import OneImpactSolution, PgfVariant, green_models, solve_one_impact
from vibroimpact.analysis.regime import Regime, classify, regime_attributes
from vibroimpact.scene.core import ENGINE_SOLUTIONS, GRID_DIMS, Scene
from vibroimpact.study.runner import run_cases
from vibroimpact.study.cases import FIELDS, SWEEP_STARTS, SimulationCase
from vibroimpact.study.swept_cases import SWEEP_QUANTITIES, SWEEP_STATS, SweepCase

#: Frequencies per simulation case when points are independent (load balancing between processes).
CASE_CHUNK = 16
from vibroimpact.analysis.stability import floquet_multipliers

__all__ = ["run_study", "write_dataset", "VARIABLE_ATTRIBUTES"]

VARIABLE_ATTRIBUTES: dict[str, dict[str, str]] = {
    "x1_amplitude": {"units": "m", "long_name": "fundamental-harmonic amplitude of the primary-mass displacement X1"},
    "x2_amplitude": {"units": "m", "long_name": "fundamental-harmonic amplitude of the absorber displacement X2"},
    "force_amplitude": {"units": "N", "long_name": "fundamental-harmonic amplitude of the force transmitted to the base (suspension plus impacts, eq. 23)"},
    "suspension_force_amplitude": {"units": "N", "long_name": "fundamental-harmonic amplitude of the force through the suspension alone (eq. 21)"},
    "impulse": {"units": "N s", "long_name": "impact impulse per period (0 where the motion is linear; simulations: total impulse of the impacts per period)"},
    "phase": {"units": "rad", "long_name": "phase of the impact relative to the linear absorber motion (varphi + psi12, eq. 15)"},
    "floquet_modulus": {"units": "1", "long_name": "largest modulus of the Floquet multipliers of the admissible one-impact orbit (< 1: stable); solution pgf only"},
    "one_impact_x1_amplitude": {"units": "m", "long_name": "|X1| fundamental of the one-impact solution of eqs. 15-17 wherever it exists, unchecked (admissible or not, stable or not)"},
    "one_impact_x2_amplitude": {"units": "m", "long_name": "|X2| fundamental of the one-impact solution of eqs. 15-18 wherever it exists, unchecked"},
    "one_impact_force_amplitude": {"units": "N", "long_name": "force fundamental (eq. 23) of the one-impact solution wherever it exists, unchecked"},
    "one_impact_impulse": {"units": "N s", "long_name": "impulse (eq. 16) of the one-impact solution wherever it exists, unchecked"},
    "impacts_per_period": {"units": "1", "long_name": "impacts per excitation period (simulations: measured over whole periods)"},
    "x1_rms": {"units": "m", "long_name": "RMS of X1 (simulations: over the measured periods; pgf: of the reconstructed orbit, 512 samples per period; linear regimes: |X1| / sqrt 2)"},
    "x2_rms": {"units": "m", "long_name": "RMS of X2 (simulations: over the measured periods; pgf: of the reconstructed orbit, 512 samples per period; linear regimes: |X2| / sqrt 2)"},
    "peak_acceleration": {"units": "m s-2", "long_name": "largest deceleration of the absorber on the bumper, bumper force less absorber spring over M2 (compliant: measured; pgf: (M2 Gamma(xi_b) Omega_b J / (M2 (1 + R)) - absorber spring force at the impact) / M2; rigid engines: NaN; no contact: 0)"},
    "peak_contact_force": {"units": "N", "long_name": "largest bumper force (compliant: measured; pgf: Gamma(xi_b) Omega_b J / (1 + R); rigid engines: NaN; no contact: 0)"},
    "wall_time": {"units": "s", "long_name": "wall time of the simulation at this point (one process; swept-sine tests: the whole sweep)"},
}
SWEEP_STAT_ATTRIBUTES: dict[str, dict[str, str]] = {
    "sweep_wall_time": {"units": "s", "long_name": "wall time of the whole swept-sine run"},
    "sweep_steps": {"units": "1", "long_name": "integrator steps of the swept-sine run"},
    "sweep_contacts": {"units": "1", "long_name": "bumper contacts during the swept-sine run"},
    "sweep_rhs_calls": {"units": "1", "long_name": "right-hand-side (residual) evaluations of the swept-sine run"},
    "sweep_linear_start": {"units": "1", "long_name": "1: the run started on the linear steady state at its first frequency; 0: at rest (asked for, or the linear state would cross the stop)"},
    "sweep_failed": {"units": "1", "long_name": "1: the integrator failed (values NaN, regime failed); 0: the run finished"},
}
CONVERGED_ATTRIBUTES = {
    "long_name": "the simulated stroboscopic state repeated to the steady-state tolerance",
    "units": "1",
    "flag_values": np.array([-1, 0, 1], dtype=np.int8),
    "flag_meanings": "not_applicable not_converged converged",
}
#: |Floquet multiplier| within this distance of 1 is reported as marginal, not decided by round-off.
MARGINAL_MODULUS = 1e-9
STABLE_MARGINAL = 2
STABLE_ATTRIBUTES = {
    "long_name": "Floquet stability of the reported one-impact orbit (solution pgf only)",
    "units": "1",
    "flag_values": np.array([-1, 0, 1, STABLE_MARGINAL], dtype=np.int8),
    "flag_meanings": "not_applicable unstable stable marginal",
}
COORDINATE_ATTRIBUTES: dict[str, dict[str, str]] = {
    "frequency": {"units": "Hz", "long_name": "excitation frequency"},
    "restitution": {"units": "1", "long_name": "restitution ratio R"},
    "clearance": {"units": "m", "long_name": "clearance Delta between absorber and stop"},
    "solution": {"long_name": "solution method"},
    "bumper_frequency": {"units": "Hz", "long_name": "apparent natural frequency Omega_b / 2 pi of the compliant bumper"},
    "bumper_loss_factor": {"units": "1", "long_name": "loss factor xi_b of the compliant bumper"},
    "sweep": {"long_name": "direction of the swept-sine test"},
}
_IMPACT_REGIMES = (Regime.ONE_IMPACT, Regime.ONE_IMPACT_COEXISTING_LINEAR)
_LINEAR_REGIMES = (Regime.LINEAR, Regime.LINEAR_WITH_INADMISSIBLE_ONE_IMPACT, Regime.LINEAR_WITH_UNSTABLE_ONE_IMPACT)

Progress = Callable[[str], None]


def _stderr_progress(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def run_study(scene: Scene, progress: Progress | None = _stderr_progress, jobs: int = 1, cache_dir: Path | None = None) -> xr.Dataset:
    """Compute every solution of ``scene`` over its grid.

    Parameters
    ----------
    scene : Scene
        A validated scene.
    progress : callable, optional
        Receives one line per finished step; ``None`` for silence (also silences the simulation progress bar).
    jobs : int
        Processes for the time-domain solutions.
    cache_dir : Path, optional
        Folder where finished simulation cases are kept, so that an interrupted study resumes.

    Returns
    -------
    xarray.Dataset
        Dimensions ``solution``, the swept parameters (``sweep`` for swept-sine tests) and ``frequency``.
    """
    if scene.benchmark is not None:
        dataset = run_benchmark(list(scene.benchmark.cases), scene.benchmark.settings, progress=progress is not None)
        dataset.attrs.update({"title": f"vibroimpact benchmark '{scene.name}'", "scene_name": scene.name, "scene": scene.text} | _provenance())
        return dataset
    report = progress or (lambda _message: None)
    # full grid (restitution, clearance, bumper_frequency, sweep, frequency): unswept axes have length 1 and are
    # squeezed at the end; each solution computes only along the axes it depends on, then is broadcast
    frequency = scene.all_frequencies
    bumper = scene.bumper_frequency if scene.bumper_frequency is not None else np.array([np.nan])
    directions = scene.sweep_directions or ("",)
    full = (scene.restitution.size, scene.clearance.size, bumper.size, len(directions), frequency.size)
    r = scene.restitution[:, None, None, None, None]
    delta = scene.clearance[None, :, None, None, None]
    omega = 2.0 * np.pi * frequency[None, None, None, None, :]
    base = np.broadcast_shapes(r.shape, delta.shape, omega.shape)
    total = len(scene.solutions)
    per_solution = []
    running: dict[str, np.ndarray] = {}
    sweep_axes: dict[str, np.ndarray] = {}
    for i, name in enumerate(scene.solutions, start=1):
        if name == "linear":
            values = _linear(scene, omega, delta, base)
        elif name in ENGINE_SOLUTIONS and scene.swept_sine is not None:
            values, running, sweep_axes = _swept(scene, full, jobs, cache_dir, progress is not None)
        elif name in ENGINE_SOLUTIONS:
            values = _simulated(scene, name, full, jobs, cache_dir, progress is not None)
        else:
            values = _pgf(scene, PgfVariant(name), omega, delta, r, base)
        per_solution.append(values)
        report(f"[{i}/{total}] {name}: done")

    # a swept-sine test depends on its direction, the steady-state solutions do not: they are not repeated along
    # ``sweep``; the swept runs' estimates on the frequency grid are the ``swept_*`` variables (sweep, frequency)
    steady_solutions = [name for name in scene.solutions if not (name in ENGINE_SOLUTIONS and scene.swept_sine is not None)]
    steady_dims = tuple(d for d in GRID_DIMS if d != "sweep" or scene.swept_sine is None)
    coords: dict[str, object] = {"solution": np.array(steady_solutions, dtype=object), "restitution": scene.restitution, "clearance": scene.clearance, "frequency": frequency}
    if scene.bumper_frequency is not None:
        coords["bumper_frequency"] = scene.bumper_frequency
    if scene.swept_sine is not None:
        coords["sweep"] = np.array(directions, dtype=object)
    if not steady_solutions:
        del coords["solution"]
    data_vars = {}
    for quantity in scene.quantities:
        attrs = _quantity_attributes(quantity)
        steady = [np.broadcast_to(values[quantity], full) for name, values in zip(scene.solutions, per_solution) if name in steady_solutions]
        if steady:
            stacked = np.stack(steady)
            data_vars[quantity] = xr.Variable(("solution", *steady_dims), stacked if scene.swept_sine is None else stacked[:, :, :, :, 0, :], attrs)
        for name, values in zip(scene.solutions, per_solution):
            if name not in steady_solutions:
                data_vars[f"swept_{quantity}"] = xr.Variable(GRID_DIMS, values[quantity], _swept_attributes(name, attrs))
    for name, values in running.items():
        if name.startswith("sweep_"):  # one value per sweep run
            data_vars[name] = xr.Variable(GRID_DIMS[:-1], values, SWEEP_STAT_ATTRIBUTES[name])
        else:
            data_vars[name] = xr.Variable((*GRID_DIMS[:-1], "elapsed_time"), values, _running_attributes(name))
    dataset = xr.Dataset(data_vars, coords=coords)
    if running:
        dataset = dataset.assign_coords(
            # an elapsed duration, not a date: CF's standard_name ``time`` would need "seconds since <epoch>" units,
            # which readers decode into calendar dates; so no standard_name, and not the reserved name ``time``
            elapsed_time=("elapsed_time", sweep_axes["time"], {"units": "s", "long_name": "simulated time since the start of the sweep"}),
            instantaneous_frequency=(("sweep", "elapsed_time"), sweep_axes["instantaneous_frequency"], {"units": "Hz", "long_name": "instantaneous excitation frequency f0 + alpha t"}),
        )
    for key in ("restitution", "clearance", "bumper_frequency", "sweep"):
        if key == "sweep" and scene.swept_sine is not None:
            continue  # a swept-sine study keeps its sweep dimension even with one direction
        swept = key in scene.swept or (key == "restitution" and "bumper_loss_factor" in scene.swept)
        if not swept and key in dataset.dims:
            dataset = dataset.squeeze(key, drop=key not in coords)
    if scene.bumper_frequency is not None:
        losses = scene.loss_factors()
        dataset = dataset.assign_coords(bumper_loss_factor=("restitution", losses) if "restitution" in dataset.dims else float(losses[0]))
        if "bumper_loss_factor" in scene.swept:
            dataset = dataset.swap_dims({"restitution": "bumper_loss_factor"})
    for key, attrs in COORDINATE_ATTRIBUTES.items():
        if key in dataset.coords:
            dataset[key].attrs.update(attrs)
    dataset.attrs.update(_metadata(scene))
    return dataset


def _quantity_attributes(quantity: str) -> dict[str, object]:
    """Units, long name and (for flags) CF flag attributes of a quantity."""
    return dict({"regime": regime_attributes(), "stable": STABLE_ATTRIBUTES, "converged": CONVERGED_ATTRIBUTES}.get(quantity, VARIABLE_ATTRIBUTES.get(quantity, {})))


def _swept_attributes(solution: str, attrs: dict[str, object]) -> dict[str, object]:
    """Attributes of a swept-sine estimate on the frequency grid: the quantity's, with the run named."""
    long_name = attrs.get("long_name", "")
    return attrs | {"long_name": f"{solution} swept-sine running estimate centred at each frequency: {long_name}"}


def _running_attributes(name: str) -> dict[str, str]:
    quantity = name.removeprefix("running_")
    base = VARIABLE_ATTRIBUTES.get(quantity, {})
    return {"units": base.get("units", "1"), "long_name": f"running estimate over the sweep's window: {base.get('long_name', quantity)}"}


def _linear(scene: Scene, omega: np.ndarray, delta: np.ndarray, shape: tuple[int, ...]) -> dict[str, np.ndarray]:
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
        **_no_one_impact_orbit(shape),
        "impacts_per_period": np.zeros(shape),
        "converged": np.full(shape, -1, dtype=np.int8),
        "x1_rms": np.abs(response.x1) / np.sqrt(2.0) * np.ones(shape),
        "x2_rms": np.abs(response.x2) / np.sqrt(2.0) * np.ones(shape),
        "peak_acceleration": np.where(fits, 0.0, np.nan),
        "peak_contact_force": np.where(fits, 0.0, np.nan),
        "wall_time": np.full(shape, np.nan),
    }
    return {k: np.broadcast_to(v, shape) for k, v in values.items() if k in scene.quantities}


def _pgf(scene: Scene, variant: PgfVariant, omega: np.ndarray, delta: np.ndarray, r: np.ndarray, shape: tuple[int, ...]) -> dict[str, np.ndarray]:
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
    peaks = functools.cache(lambda: _peak_estimates(scene, solution, r))

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
    }
    return {q: makers[q]() for q in scene.quantities}


def _peak_estimates(scene: Scene, solution: OneImpactSolution, r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
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


def _no_one_impact_orbit(shape: tuple[int, ...]) -> dict[str, np.ndarray]:
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


def _simulated(scene: Scene, engine: str, shape: tuple[int, ...], jobs: int, cache_dir: Path | None, progress: bool) -> dict[str, np.ndarray]:
    """Steady states of a time-domain engine on the simulation grid; NaN at the other frequencies.

    Only ``compliant`` depends on the bumper: the rigid engines run once per (restitution, clearance).
    """
    assert scene.simulation is not None
    sim = scene.simulation
    columns = np.searchsorted(scene.all_frequencies, sim.frequency)
    bumpers = scene.bumper_frequency if engine == "compliant" and scene.bumper_frequency is not None else np.array([np.nan])
    losses = scene.loss_factors() if engine == "compliant" else np.full(scene.restitution.shape, np.nan)
    # a sweep is one chain; independent starts are split into chunks so that processes share the work evenly
    chunk = sim.frequency.size if sim.start in SWEEP_STARTS else CASE_CHUNK
    cases, places = [], []
    for i, restitution in enumerate(scene.restitution):
        for j, clearance in enumerate(scene.clearance):
            for k, bumper in enumerate(bumpers):
                for first in range(0, sim.frequency.size, chunk):
                    frequencies = tuple(float(f) for f in sim.frequency[first : first + chunk])
                    case = SimulationCase(engine, scene.system, scene.amplitude, float(restitution), float(clearance), frequencies, sim.start, sim.engine, sim.steady, float(bumper), float(losses[i]))
                    cases.append(case)
                    places.append((i, j, k, columns[first : first + chunk]))
    results = run_cases(cases, jobs=jobs, cache_dir=cache_dir, progress=progress)
    grid = (shape[0], shape[1], bumpers.size, 1, shape[4])
    fields = {name: np.full(grid, np.nan, dtype=complex if name in ("x1", "x2", "suspension_force", "contact_force") else float) for name in FIELDS}
    for (i, j, k, where), result in zip(places, results):
        for name in FIELDS:
            fields[name][i, j, k, 0, where] = result[name]
    computed = ~np.isnan(fields["converged"])
    converged = fields["converged"] == 1.0
    impacts = fields["impacts_per_period"]
    regime = np.full(grid, Regime.NOT_COMPUTED, dtype=np.int8)
    regime[computed & ~converged] = Regime.IRREGULAR
    regime[computed & converged] = Regime.PERIODIC_IMPACTS
    regime[computed & converged & (impacts == 0.0)] = Regime.LINEAR
    regime[computed & converged & (fields["multiplicity"] == 1.0) & (impacts == 1.0)] = Regime.ONE_IMPACT
    regime[fields["failed"] == 1.0] = Regime.FAILED
    force = fields["suspension_force"] + fields["contact_force"]
    values = {
        "x1_amplitude": np.abs(fields["x1"]),
        "x2_amplitude": np.abs(fields["x2"]),
        "force_amplitude": np.abs(force),
        "suspension_force_amplitude": np.abs(fields["suspension_force"]),
        "impulse": fields["impulse_per_period"],
        "phase": np.full(grid, np.nan),
        "regime": regime,
        **_no_one_impact_orbit(grid),
        "impacts_per_period": impacts,
        "converged": np.where(computed, converged, -1).astype(np.int8),
        "x1_rms": fields["x1_rms"],
        "x2_rms": fields["x2_rms"],
        "peak_acceleration": fields["peak_acceleration"],
        "peak_contact_force": fields["peak_contact_force"],
        "wall_time": fields["wall_time"],
    }
    return {q: values[q] for q in scene.quantities}


def _swept(scene: Scene, shape: tuple[int, ...], jobs: int, cache_dir: Path | None, progress: bool) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray], dict[str, np.ndarray]]:
    """Swept-sine tests of the compliant model: estimates on the frequency grid, running estimates against time, and
    the time axes (``time``, ``instantaneous_frequency`` per direction)."""
    assert scene.swept_sine is not None and scene.bumper_frequency is not None and scene.simulation is not None
    losses = scene.loss_factors()
    frequencies = tuple(float(f) for f in scene.all_frequencies)
    cases, places = [], []
    for i in range(scene.restitution.size):
        for j, clearance in enumerate(scene.clearance):
            for k, bumper in enumerate(scene.bumper_frequency):
                for d, direction in enumerate(scene.swept_sine.directions):
                    cases.append(SweepCase(scene.system, scene.amplitude, float(clearance), float(bumper), float(losses[i]), scene.swept_sine, direction, scene.simulation.engine, frequencies))
                    places.append((i, j, k, d))
    results = run_cases(cases, jobs=jobs, cache_dir=cache_dir, progress=progress)
    times = results[0]["time"]
    values = {name: np.full(shape, np.nan) for name in SWEEP_QUANTITIES}
    running = {f"running_{name}": np.full((*shape[:-1], times.size), np.nan) for name in SWEEP_QUANTITIES}
    stats = {name: np.full(shape[:-1], np.nan) for name in SWEEP_STATS}
    instantaneous = np.full((shape[3], times.size), np.nan)
    for (i, j, k, d), result in zip(places, results):
        for name in SWEEP_QUANTITIES:
            values[name][i, j, k, d] = result[name]
            running[f"running_{name}"][i, j, k, d] = result[f"running_{name}"]
        for name in stats:
            stats[name][i, j, k, d] = result[name]
        instantaneous[d] = result["instantaneous_frequency"]
    impacts = values["impacts_per_period"]
    regime = np.full(shape, Regime.NOT_COMPUTED, dtype=np.int8)
    regime[impacts == 0.0] = Regime.LINEAR
    regime[impacts > 0.0] = Regime.SWEPT_CONTACT
    regime[np.broadcast_to(stats["failed"][..., None] == 1.0, shape)] = Regime.FAILED
    values |= {
        "phase": np.full(shape, np.nan),
        "regime": regime,
        **_no_one_impact_orbit(shape),
        "converged": np.full(shape, -1, dtype=np.int8),
        "wall_time": np.broadcast_to(stats["wall_time"][..., None], shape),
    }
    running = {name: value for name, value in running.items() if name.removeprefix("running_") in scene.quantities}
    for name, value in stats.items():
        running[f"sweep_{name}"] = value  # one value per sweep: the run's cost
    return {q: values[q] for q in scene.quantities}, running, {"time": times, "instantaneous_frequency": instantaneous}


def _provenance() -> dict[str, str]:
    """What every dataset says about how it was made: the package version, its source and the conventions followed."""
    return {"vibroimpact_version": __version__, "vibroimpact_source_sha256": source_hash(), "Conventions": "CF-1.8"}


def _metadata(scene: Scene) -> dict[str, object]:
    system = scene.system
    fit = fit_modal_parameters(system) if "pgf_paper" in scene.solutions else None
    attrs: dict[str, object] = {
        "title": f"vibroimpact study '{scene.name}'",
        "scene_name": scene.name,
        "scene": scene.text,
        **_provenance(),
        "excitation_amplitude_N": scene.amplitude,
        "natural_frequencies_Hz": np.array(system.natural_frequencies()) / (2.0 * np.pi),
        "antiresonance_frequency_Hz": system.antiresonance_frequency() / (2.0 * np.pi),
        "method_pgf": "exact poles and residues of H22; exact chi22'(0-) from the derivative of eq. 12; stable (+) root of corrected eq. 16",
        "method_pgf_paper": "curve-fitted modal parameters of H22 (eq. 10, Omega fixed from eq. 11); chi22'(0-) = -1/(2 M2); stable (+) root of corrected eq. 16",
    }
    for key, value in system.as_dict().items():
        attrs[f"system_{key}"] = value
    for key, value in asdict(scene.admissibility).items():
        attrs[f"admissibility_{key}"] = value
    if scene.simulation is not None and scene.swept_sine is not None:
        for key, value in asdict(scene.swept_sine).items():
            attrs[f"swept_sine_{key}"] = np.array(value, dtype=str) if key == "directions" else value
        for key in ("rtol", "atol", "max_step"):
            attrs[f"simulation_engine_{key}"] = getattr(scene.simulation.engine, key)
    elif scene.simulation is not None:
        attrs["simulation_frequency_Hz"] = scene.simulation.frequency
        attrs["simulation_start"] = scene.simulation.start
        for key, value in asdict(scene.simulation.engine).items():
            attrs[f"simulation_engine_{key}"] = value
        for key, value in asdict(scene.simulation.steady).items():
            attrs[f"simulation_steady_{key}"] = value
        attrs["method_exact"] = "piecewise-exact propagation (eigenvectors + harmonic particular solution), contacts by guaranteed Taylor-bound root bracketing"
        attrs["method_momentary"] = "scikit-sundae CVODE with contact/release events and an apex event guarding grazing contacts"
        attrs["method_compliant"] = "Kelvin-Voigt bumper (eq. 25) through scikit-sundae IDA: one solver per contact mode, onset/release events, recorded force and deceleration peaks; atol of the displacements [m], other states scaled"
    if fit is not None:
        attrs["pgf_paper_form_factors_per_kg"] = np.real(fit.form_factor)
        attrs["pgf_paper_loss_factors"] = fit.loss_factor
    return attrs


def write_dataset(dataset: xr.Dataset, path: str | Path) -> Path:
    """Write ``dataset`` to netCDF atomically: a temporary file in the same folder, then a rename.

    A reader never sees a half-written file, and an interrupted run leaves the previous file intact.
    """
    path = Path(path)
    encoding: dict[str, dict[str, object]] = {name: {"zlib": True, "complevel": 4} for name in dataset.data_vars}
    # CF 2.5.1: coordinate variables carry no _FillValue (xarray adds one to every float variable unless told not to)
    encoding |= {name: {"_FillValue": None} for name in dataset.coords if dataset[name].dtype.kind == "f"}
    if not dataset.attrs.get("history"):
        stamp = datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
        dataset = dataset.assign_attrs(history=f"{stamp} vibroimpact {__version__}: {dataset.attrs.get('title', 'dataset')} written")
    with atomic_path(path) as temporary:
        dataset.to_netcdf(temporary, engine="netcdf4", format="NETCDF4", encoding=encoding)
    return path
