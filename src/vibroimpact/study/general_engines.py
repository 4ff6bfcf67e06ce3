"""Steady states of the time-domain engines over a stepped study's grid: any structure, load and stops.

One case per (restitution, clearance, bumper) grid point and chunk of frequencies (a bumper engine runs once per
bumper, the rigid engines once per (restitution, clearance)); each stop's values come from itself or from the grid
(:func:`vibroimpact.scene.layout.build_stops`). States are 2 N wide; the measured fundamentals are per coordinate and
the impulses, peaks and contact forces per stop. On a symmetric two-sided stop the flag ``one_impact`` means the
closed form's kind of orbit, one impact per period on each side (as ``pgf`` flags it there).
"""

from __future__ import annotations

import numpy as np

from vibroimpact.analysis.regime import Regime
from vibroimpact.engines.registry import BUMPER, engine_spec
from vibroimpact.scene.layout import build_stops
from vibroimpact.scene.schema import Scene
from vibroimpact.simulation.settings import SWEEP_STARTS
from vibroimpact.study.cases import COMPLEX_FIELDS, COORDINATE_FIELDS, FIELDS, STOP_FIELDS, SimulationCase
from vibroimpact.analysis.layout import closed_form_refusal
from vibroimpact.study.general_values import broadcast_quantities, coordinate_quantity, scene_problem
from vibroimpact.study.grid import no_one_impact_orbit
from vibroimpact.study.runner import Runner

__all__ = ["general_simulated_values", "simulated_regime", "CASE_CHUNK"]

#: Frequencies per simulation case when points are independent (load balancing between processes).
CASE_CHUNK = 16


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


def _two_sided(scene: Scene) -> bool:
    """Is the layout a symmetric two-sided stop (two stops whose closed form is the two-impacts orbit)?"""
    if len(scene.stop_specs) != 2:
        return False
    problem = scene_problem(scene, float(scene.all_frequencies[0]), float(scene.restitution[0]), float(scene.clearance[0]))
    return closed_form_refusal(problem) is None


def general_simulated_values(scene: Scene, engine: str, shape: tuple[int, ...], runner: Runner) -> dict[str, np.ndarray]:
    """Steady states of a time-domain engine on the simulation grid of ``scene``; NaN at the other frequencies."""
    assert scene.simulation is not None
    sim = scene.simulation
    columns = np.searchsorted(scene.all_frequencies, sim.frequency)
    on_bumper = engine_spec(engine).contact == BUMPER
    bumpers = scene.bumper_frequency if on_bumper and scene.bumper_frequency is not None else np.array([np.nan])
    losses = scene.loss_factors() if on_bumper and scene.bumper_loss_factor is not None else np.full(scene.restitution.shape, np.nan)
    chunk = sim.frequency.size if sim.start in SWEEP_STARTS else CASE_CHUNK
    specs = scene.stop_specs
    cases, places = [], []
    for i, restitution in enumerate(scene.restitution):
        for j, clearance in enumerate(scene.clearance):
            for k, bumper in enumerate(bumpers):
                rigid = build_stops(specs, False, float(restitution), float(clearance))
                contact = build_stops(specs, True, float(restitution), float(clearance), float(bumper), float(losses[i])) if on_bumper else rigid
                for first in range(0, sim.frequency.size, chunk):
                    frequencies = tuple(float(f) for f in sim.frequency[first : first + chunk])
                    case = SimulationCase(engine, scene.system, scene.amplitude, contact, frequencies, sim.start, sim.engine, sim.steady, rigid if on_bumper else None, scene.load)
                    cases.append(case)
                    places.append((i, j, k, columns[first : first + chunk]))
    results = runner.map(cases)
    grid = (shape[0], shape[1], bumpers.size, 1, shape[4])
    size, count = scene.system.size, len(specs)
    widths = {**{name: (size,) for name in COORDINATE_FIELDS}, **{name: (count,) for name in STOP_FIELDS}}
    fields = {name: np.full(grid + widths.get(name, ()), np.nan, dtype=complex if name in COMPLEX_FIELDS else float) for name in (*FIELDS, *COORDINATE_FIELDS, *STOP_FIELDS)}
    for (i, j, k, where), result in zip(places, results):
        for name in fields:
            fields[name][i, j, k, 0, where] = result[name]
    computed = ~np.isnan(fields["converged"])
    converged = fields["converged"] == 1.0
    impacts = fields["impacts_per_period"]
    # the closed form's kind of orbit: one impact per period, or one on each side of a symmetric two-sided stop
    one_impact_orbit = np.all(fields["stop_impacts"] == 1.0, axis=-1) if _two_sided(scene) else impacts == 1.0
    regime = simulated_regime(fields, one_impact_orbit)
    force = fields["suspension_force"] + fields["contact_force"]

    def stop_first(name: str) -> np.ndarray:
        return np.moveaxis(fields[name], -1, 0)  # (K, *grid)

    values = {
        "force_amplitude": np.abs(force),
        "suspension_force_amplitude": np.abs(fields["suspension_force"]),
        "impulse": stop_first("stop_impulse"),
        "phase": np.full(grid, np.nan),
        "regime": regime,
        **no_one_impact_orbit(grid),
        "one_impact_impulse": np.full((count, *grid), np.nan),
        "impacts_per_period": impacts,
        "converged": np.where(computed, converged, -1).astype(np.int8),
        "peak_acceleration": stop_first("stop_peak_acceleration"),
        "peak_contact_force": stop_first("stop_peak_force"),
        "wall_time": fields["wall_time"],
        "lyapunov_exponent": fields["lyapunov_exponent"],
        "lyapunov_error": fields["lyapunov_error"],
        "rotation_number": fields["rotation_number"],
        "spectral_line_fraction": fields["spectral_line_fraction"],
    }
    for c, name in enumerate(scene.coordinates):
        values[coordinate_quantity("x1_amplitude", name)] = np.abs(fields["displacements"][..., c])
        values[coordinate_quantity("x1_rms", name)] = fields["rms"][..., c]
        values[coordinate_quantity("one_impact_x1_amplitude", name)] = np.full(grid, np.nan)
    return broadcast_quantities(scene, values, grid)
