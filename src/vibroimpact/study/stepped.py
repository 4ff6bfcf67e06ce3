"""Stepped studies: steady states (closed forms and time-domain engines) at each point of the grid."""

from __future__ import annotations

from dataclasses import asdict

import numpy as np
import xarray as xr

from vibroimpact.engines.registry import BUMPER, engine_spec
from vibroimpact.scene.schema import ENGINE_SOLUTIONS, Scene
from vibroimpact.simulation.settings import SWEEP_STARTS
from vibroimpact.study.cost_model import Costs, EnginePart, Estimate, grid_estimate
from vibroimpact.study.grid import Progress, StudyGrid, finish_dataset
from vibroimpact.study.general_estimate import closed_form_scale, engine_scale, general_orbit_outlook
from vibroimpact.study.blocks import plan_blocks, run_grid
from vibroimpact.study.general_stepped import describe_stops, general_block, general_coordinates
from vibroimpact.study.runner import Runner

__all__ = ["SteppedStudy", "expected_periods", "SETTLING_PERIODS", "SHOOTING_PERIODS", "ESTIMATE_POINTS"]

#: Periods of a transient that settles on a stable orbit (two convergence chunks), before the measurement.
SETTLING_PERIODS = 40
#: Periods a ``shooting`` start integrates before measuring a stable orbit: 1-2 map evaluations and the 3-period check
#: of an integrator (measured on the restitution study: 1-4).
SHOOTING_PERIODS = 5
#: Largest number of simulated points whose closed form is solved for the estimate (a larger grid is subsampled).
ESTIMATE_POINTS = 20_000


class SteppedStudy:
    """Steady states over (restitution, clearance, bumper, frequency): dimension ``solution`` for every solution."""

    name = "stepped"

    def run(self, scene: Scene, progress: Progress | None, runner: Runner) -> xr.Dataset:
        """Every solution of ``scene`` over its grid (see :func:`vibroimpact.study.run.run_study`), solved block by
        block (:mod:`vibroimpact.study.blocks`) by :func:`~vibroimpact.study.general_stepped.general_block`, whichever
        way the scene writes its system; the variables are read lazily from the runner's store."""
        say = progress or (lambda _message: None)
        grid = StudyGrid.of(scene)
        solutions = list(scene.solutions)
        coords = general_coordinates(scene, grid)
        raw = run_grid(scene, runner, general_block, {"solution": len(solutions), "stop": len(scene.stop_specs)})
        dataset = describe_stops(raw.assign_coords(coords))
        say(f"{', '.join(solutions)}: done")
        return finish_dataset(dataset, scene, coords, self.simulation_attributes(scene))

    @staticmethod
    def simulation_attributes(scene: Scene) -> dict[str, object]:
        """What the dataset records of the time-domain solutions' settings and methods."""
        attrs: dict[str, object] = {}
        if scene.simulation is not None:
            attrs["simulation_frequency_Hz"] = scene.simulation.frequency
            attrs["simulation_start"] = scene.simulation.start
            for key, value in asdict(scene.simulation.engine).items():
                attrs[f"simulation_engine_{key}"] = value
            for key, value in asdict(scene.simulation.steady).items():
                attrs[f"simulation_steady_{key}"] = value
            attrs["method_exact"] = "piecewise-exact propagation (eigenvectors + harmonic particular solution), contacts by guaranteed Taylor-bound root bracketing"
            attrs["method_momentary"] = "scikit-sundae CVODE with contact/release events and an apex event guarding grazing contacts"
            attrs["method_compliant"] = "Kelvin-Voigt bumper (eq. 25) through scikit-sundae IDA: one solver per contact mode, onset/release events, recorded force and deceleration peaks; atol of the displacements [m], other states scaled"
        return attrs

    def estimate(self, scene: Scene, jobs: int, costs: Costs) -> Estimate:
        """Seconds per simulated period of each engine at its tolerance times the periods each point is predicted to
        integrate (:func:`expected_periods`), on the calibration machine."""
        bumpers = scene.bumper_frequency.size if scene.bumper_frequency is not None else 1
        # the same for every engine: solved once (the closed form over up to ESTIMATE_POINTS points)
        periods, scale = expected_periods(scene) if scene.simulation is not None else (np.zeros(0), 1.0)

        def engine_part(name: str, engine: str) -> EnginePart:
            assert scene.simulation is not None
            capabilities = engine_spec(name).capabilities
            copies = bumpers if capabilities.contact == BUMPER else 1  # a bumper engine runs once per bumper
            steady = scene.simulation.steady
            # where the motion may never settle, an engine without exact Jacobians also runs a perturbed copy of its
            # Lyapunov run
            wandering = np.count_nonzero(periods >= steady.max_periods + steady.lyapunov_periods) if not capabilities.exact_jacobians else 0
            total_periods = (float(periods.sum()) + wandering * steady.lyapunov_periods) * scale * copies
            seconds = costs.per_period_cost(engine, scene.simulation.engine.rtol) * engine_scale(scene) * total_periods
            integrated = int(np.count_nonzero(periods) * scale) * copies
            points = f"{scene.restitution.size * scene.clearance.size * scene.simulation.frequency.size * copies} points, ~{integrated} integrated, ~{total_periods:.0f} periods"
            serial = 0.0
            if scene.simulation.start in SWEEP_STARTS:  # one serial chain per (R, Delta, bumper)
                serial = seconds / (scene.restitution.size * scene.clearance.size * copies)
            return seconds, points, serial

        return grid_estimate(
            scene, jobs, costs, engine_part, report_figures(scene), closed_form_scale=lambda name: closed_form_scale(scene, name),
            blocks=lambda workers: plan_blocks(scene, workers).count,
        )  # fmt: skip


#: Figures of the design-map page (three band maps, the regime map, the response at the recommended design).
DESIGN_MAP_FIGURES = 5


def report_figures(scene: Scene) -> int:
    """Figures of the study's report page."""
    if scene.report == "design_map":
        return DESIGN_MAP_FIGURES
    per_clearance = 12 if any(s in ENGINE_SOLUTIONS for s in scene.solutions) else 7
    return 1 + per_clearance * scene.clearance.size + (2 if len(scene.swept) > 1 else 0)


def expected_periods(scene: Scene) -> tuple[np.ndarray, float]:
    """Periods each simulated (restitution, clearance, frequency) point is predicted to integrate, on the grid or on
    an evenly subsampled frequency grid, and the factor that scales its sum to the whole grid.

    As :func:`vibroimpact.simulation.steady.steady_state` and :func:`vibroimpact.study.cases.run_case` do: ``linear`` and stepped
    sweeps answer a point whose linear motion fits without integrating; ``pgf`` also needs no admissible one-impact
    orbit there; a stable orbit settles in a short transient; elsewhere the motion may never settle (``max_periods``
    plus the irregular measurement). From ``rest`` every point integrates, and the lightly damped transient of the
    linear modes (damping ratios ~1e-3) outlasts ``max_periods``.
    """
    assert scene.simulation is not None
    sim = scene.simulation
    per_line = max(1, ESTIMATE_POINTS // (scene.restitution.size * scene.clearance.size))
    frequencies = sim.frequency if sim.frequency.size <= per_line else sim.frequency[np.linspace(0, sim.frequency.size - 1, per_line).astype(int)]
    scale = sim.frequency.size / frequencies.size
    steady = sim.steady
    wander = steady.max_periods + steady.lyapunov_periods + steady.irregular_measure_periods
    shape = (scene.restitution.size, scene.clearance.size, frequencies.size)
    if sim.start == "rest":
        return np.full(shape, float(wander)), scale
    fits, admissible, stable, wandering = general_orbit_outlook(scene, frequencies)
    settle = (SHOOTING_PERIODS if sim.start == "shooting" else SETTLING_PERIODS) + steady.measure_periods
    if sim.start in SWEEP_STARTS:
        # a chain: a fitting point is answered linear unless the point before it impacted (then it integrates from
        # there, and keeps impacting where a one-impact orbit coexists with the linear motion)
        order = range(frequencies.size) if sim.start == "sweep_up" else range(frequencies.size - 1, -1, -1)
        no_integration = np.zeros(shape, dtype=bool)
        impacting = np.zeros(shape[:2], dtype=bool)
        for k in order:
            no_integration[..., k] = fits[..., k] & ~impacting
            impacting = ~fits[..., k] | (impacting & admissible[..., k])
    else:
        no_integration = fits & ~admissible if sim.start in ("pgf", "shooting") else fits
    unknown = settle + wandering * (wander - settle)  # no closed form: an assumed share never settles
    return np.where(no_integration, 0, np.where(stable, settle, unknown if wandering else wander)).astype(float), scale
