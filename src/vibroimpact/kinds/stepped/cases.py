"""Steady states of the time-domain engines over a stepped study's grid: any structure, load and stops.

One case per (restitution, clearance, bumper) grid point and chunk of frequencies (a bumper engine runs once per
bumper, the rigid engines once per (restitution, clearance)); each stop's values come from itself or from the grid
(:func:`vibroimpact.model.layout.build_stops`). States are 2 N wide; the measured fundamentals are per coordinate and
the impulses, peaks and contact forces per stop. On a symmetric two-sided stop the flag ``one_impact`` means the
closed form's kind of orbit, one impact per period on each side (as ``pgf`` flags it there).
"""

from __future__ import annotations

import math
import sys
import time
from dataclasses import asdict, dataclass

import numpy as np
from numpy.typing import NDArray

from vibroimpact.analysis.layout import closed_form_refusal
from vibroimpact.analysis.stability import Regime
from vibroimpact.engines.registry import make_engine, BUMPER, engine_spec
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.grids.grid import no_one_impact_orbit
from vibroimpact.scene.subset import on_subset
from vibroimpact.grids.closed_forms import broadcast_quantities, coordinate_quantity
from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop, Stop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.structure import LinearStructure
from vibroimpact.runs.runner import CaseResult, ProgressReport, Runner
from vibroimpact.runs.fingerprints import case_key
from vibroimpact.model.layout import LoadSpec, build_stops
from vibroimpact.scene.schema import Scene
from vibroimpact.simulation.steady import linear_fits, pgf_guesses, steady_state
from vibroimpact.simulation.settings import SWEEP_STARTS, SteadySettings

__all__ = ["SimulationCase", "run_case", "general_simulated_values", "simulated_regime", "CASE_CHUNK"]


# --------------------------------------------------------------------------------------------------------------------
# Steady states of the time-domain engines over a study's grid: cases for :meth:`vibroimpact.runs.runner.Runner.map`.
# --------------------------------------------------------------------------------------------------------------------

#: Fields of a case result, one value per frequency (the coordinates' fundamentals and RMS are per coordinate:
#: :data:`COORDINATE_FIELDS`).
FIELDS = (
    "suspension_force",
    "contact_force",
    "impacts_per_period",
    "mean_impulse",
    "impulse_per_period",
    "peak_contact_force",
    "peak_acceleration",
    "converged",
    "multiplicity",
    "periods_used",
    "wall_time",
    "failed",
    "motion_regime",
    "lyapunov_exponent",
    "lyapunov_error",
    "rotation_number",
    "spectral_line_fraction",
)
#: Fields with one value per coordinate (shape (frequencies, N)) or per stop ((frequencies, K)).
COORDINATE_FIELDS = ("displacements", "rms")
STOP_FIELDS = ("stop_contact_force", "stop_impacts", "stop_impulse", "stop_peak_force", "stop_peak_acceleration")
#: Complex fields.
COMPLEX_FIELDS = ("suspension_force", "contact_force", "displacements", "stop_contact_force")


@dataclass(frozen=True)
class SimulationCase:
    """One engine (a name of :mod:`vibroimpact.engines.registry`) at one contact over its frequencies.

    Attributes
    ----------
    engine : str
        Registered engine name.
    system : LinearStructure
        The linear system.
    amplitude : float
        q [N] (a base motion's displacement [m]).
    contact : RigidStop, KelvinVoigtBumper or tuple of Stop
        The contact law the engine solves (a single law: the paper's stop), or every stop of a general layout.
    frequencies : tuple of float
        Excitation frequencies [Hz].
    start : str
        A start of :data:`~vibroimpact.simulation.settings.START_MODES` or of :data:`~vibroimpact.simulation.settings.SWEEP_STARTS`.
    engine_settings, steady_settings
        Numerical settings.
    orbit_stop : RigidStop, tuple of Stop, or None
        The rigid stop(s) whose one-impact orbit a ``pgf`` start follows (a bumper's study grid point); None: the
        contact's own (:func:`vibroimpact.simulation.steady.orbit_stop_of`).
    load : LoadSpec or None
        A general scene's load (weights, static force, base motion); None: the paper's force on the primary mass.
    """

    engine: str
    system: LinearStructure
    amplitude: float
    contact: RigidStop | KelvinVoigtBumper | tuple[Stop, ...]
    frequencies: tuple[float, ...]
    start: str
    engine_settings: EngineSettings
    steady_settings: SteadySettings
    orbit_stop: RigidStop | tuple[Stop, ...] | None = None
    load: LoadSpec | None = None

    fields = FIELDS + COORDINATE_FIELDS + STOP_FIELDS

    def problem(self, frequency: float, phase: float = 0.0) -> ImpactProblem:
        """The impact problem at ``frequency`` [Hz] with the force's phase at t = 0 [rad]."""
        force = HarmonicForce(self.amplitude, frequency, phase=phase) if self.load is None else self.load.force(self.amplitude, frequency, phase)
        return ImpactProblem(self.system, self.contact, force)

    progress_unit = "points"

    @property
    def progress_total(self) -> float:
        """Frequency points in the case (progress is counted in points)."""
        return float(len(self.frequencies))

    def run(self, report: ProgressReport | None = None) -> CaseResult:
        """Steady states of this case (see :func:`run_case`)."""
        return run_case(self, report)

    def key(self) -> str:
        """A stable hash of everything that determines the result, the package version and its source code."""
        return case_key(
            {
                "engine": self.engine,
                "system": {"kind": type(self.system).__name__, **asdict(self.system)},
                "amplitude": self.amplitude,
                "contact": _contact_key(self.contact),
                "orbit_stop": None if self.orbit_stop is None else _contact_key(self.orbit_stop),
                "load": None if self.load is None else asdict(self.load),
                "frequencies": list(self.frequencies),
                "start": self.start,
                "engine_settings": asdict(self.engine_settings),
                "steady_settings": asdict(self.steady_settings),
            }
        )


def _contact_key(contact: object) -> object:
    """The contact as plain data for a case key (the law's class named: a bumper's fields differ from a stop's)."""
    if isinstance(contact, tuple):
        return [{"law": type(stop.law).__name__, **asdict(stop)} for stop in contact]
    return {"law": type(contact).__name__, **asdict(contact)}  # type: ignore[call-overload]


def _contact_words(problem: ImpactProblem) -> str:
    """The problem's stops in words (the paper's stop: its law, as before)."""
    if not isinstance(problem.contact, tuple):
        return str(problem.contact)
    names = tuple(problem.structure.coordinates)
    return "; ".join(f"{stop.describe(names)} ({type(stop.law).__name__})" for stop in problem.contact)


def run_case(case: SimulationCase, report: ProgressReport | None = None) -> CaseResult:
    """Steady states of one case, in the order of ``case.frequencies``; ``report`` receives the points done."""
    engine = make_engine(case.engine, case.engine_settings)
    n = len(case.frequencies)
    first = case.problem(case.frequencies[0])
    widths = {**{name: first.size for name in COORDINATE_FIELDS}, **{name: len(first.stops) for name in STOP_FIELDS}}
    out: dict[str, NDArray[np.generic]] = {
        name: np.full((n, widths[name]) if name in widths else n, np.nan, dtype=complex if name in COMPLEX_FIELDS else float) for name in case.fields
    }
    order = range(n - 1, -1, -1) if case.start == "sweep_down" else range(n)
    previous = None
    guesses: list[tuple[float, NDArray[np.float64]] | None] | None = None
    if case.start in ("pgf", "shooting"):  # the closed-form orbits of the whole case in one vectorised solution
        guesses = pgf_guesses(first, case.frequencies, case.orbit_stop)
    for i in order:
        frequency = case.frequencies[i]
        problem = case.problem(frequency)
        start: str | tuple[float, NDArray[np.float64]] = case.start
        if case.start in SWEEP_STARTS:
            if previous is None or (previous[2] == 0.0 and linear_fits(problem)):
                start = "linear"  # a slow sweep without impacts follows the linear steady state
            else:
                old_problem, result, _impacts = previous
                # keep the force continuous: the new force at t = 0 continues the old one at its end time
                phase = (old_problem.omega * result.end_time + old_problem.phase) % (2.0 * math.pi)
                problem = case.problem(frequency, phase)
                start = (0.0, result.end_state)
        started = time.perf_counter()
        try:
            guess = guesses[i] if guesses is not None else "compute"
            result = steady_state(engine, problem, start, case.steady_settings, case.orbit_stop, guess)
        except (RuntimeError, ValueError, ArithmeticError, np.linalg.LinAlgError) as error:
            # one failing point must not cost the others: it stays NaN, flagged, and a sweep restarts after it
            print(f"{case.engine}: {_contact_words(problem)}, f = {frequency:g} Hz failed: {error}", file=sys.stderr)
            out["failed"][i] = 1.0
            previous = None
            continue
        m = result.measures
        motion = result.motion
        values = {
            "suspension_force": m.suspension_force,
            "contact_force": m.contact_force,
            "impacts_per_period": m.impacts_per_period,
            "mean_impulse": m.mean_impulse,
            "impulse_per_period": m.impulse_per_period,
            "peak_contact_force": m.peak_contact_force,
            "peak_acceleration": m.peak_acceleration,
            "converged": float(result.converged),
            "multiplicity": float(result.multiplicity),
            "periods_used": float(result.periods_used),
            "wall_time": time.perf_counter() - started,
            "failed": 0.0,
            "motion_regime": float(motion.regime) if motion is not None else math.nan,
            "lyapunov_exponent": motion.lyapunov_exponent if motion is not None else math.nan,
            "lyapunov_error": motion.lyapunov_error if motion is not None else math.nan,
            "rotation_number": motion.rotation_number if motion is not None and motion.rotation_regular else math.nan,
            "spectral_line_fraction": motion.spectral_line_fraction if motion is not None else math.nan,
            "displacements": np.array(m.displacements, dtype=complex),
            "rms": np.array(m.rms),
            "stop_contact_force": np.array(m.stop_contact_forces, dtype=complex),
            "stop_impacts": np.array(m.stop_impacts),
            "stop_impulse": np.array(m.stop_impulses),
            "stop_peak_force": np.array(m.stop_peak_forces),
            "stop_peak_acceleration": np.array(m.stop_peak_accelerations),
        }
        for name, value in values.items():
            out[name][i] = value
        previous = (problem, result, m.impacts_per_period)
        if report is not None:
            report(float(n - i if case.start == "sweep_down" else i + 1))
    return out

#: Frequencies per simulation case when points are independent (load balancing between processes).
CASE_CHUNK = 16


def simulated_regime(fields: dict[str, np.ndarray], one_impact_orbit: np.ndarray) -> np.ndarray:
    """The ``regime`` flag of simulated steady states from a case's measured fields (the arrays of the grid).

    Not computed, failed, or: not converged -> the motion's own classification (quasi-periodic, chaotic) else
    irregular; converged -> linear when there was neither an impact nor a contact force, held on the stop when there
    was a contact force but no impact (a preloading stop the force never lifts the structure from), one impact where
    ``one_impact_orbit`` (the closed form's kind of orbit: one impact per period, or one on each side of a symmetric
    two-sided stop) holds at multiplicity 1, else periodic impacts.
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
    regime[computed & converged & (fields["impacts_per_period"] == 0.0) & held] = Regime.HELD_ON_STOP
    regime[fields["failed"] == 1.0] = Regime.FAILED
    return regime


def _two_sided(scene: Scene) -> bool:
    """Is the layout a symmetric two-sided stop (two stops whose closed form is the two-impacts orbit)?"""
    if len(scene.layout.stops) != 2:
        return False
    problem = scene.layout.problem(scene.amplitude, float(scene.settings.all_frequencies[0]), float(scene.settings.restitution[0]), float(scene.settings.clearance[0]))
    return closed_form_refusal(problem) is None


def general_simulated_values(scene: Scene, engine: str, shape: tuple[int, ...], runner: Runner) -> dict[str, np.ndarray]:
    """Steady states of a time-domain engine on the simulation grid of ``scene``; NaN at the other frequencies."""
    assert scene.settings.simulation is not None
    sim = scene.settings.simulation
    simulated = sim.frequency[on_subset(sim.subset, engine, "frequency", sim.frequency)]  # all but an engine's subset
    columns = np.searchsorted(scene.settings.all_frequencies, simulated)
    on_bumper = engine_spec(engine).contact == BUMPER
    bumpers = scene.settings.bumper_frequency if on_bumper and scene.settings.bumper_frequency is not None else np.array([np.nan])
    losses = scene.settings.loss_factors() if on_bumper and scene.settings.bumper_loss_factor is not None else np.full(scene.settings.restitution.shape, np.nan)
    chunk = max(simulated.size, 1) if sim.start in SWEEP_STARTS else CASE_CHUNK
    specs = scene.layout.stops
    kept = [on_subset(sim.subset, engine, axis, values) for axis, values in (("restitution", scene.settings.restitution), ("clearance", scene.settings.clearance), ("bumper_frequency", bumpers))]
    cases, places = [], []
    for i, restitution in enumerate(scene.settings.restitution):
        for j, clearance in enumerate(scene.settings.clearance):
            for k, bumper in enumerate(bumpers):
                if not (kept[0][i] and kept[1][j] and (kept[2][k] or not on_bumper)):
                    continue  # outside the engine's subset: not computed
                rigid = build_stops(specs, False, float(restitution), float(clearance))
                contact = build_stops(specs, True, float(restitution), float(clearance), float(bumper), float(losses[i])) if on_bumper else rigid
                for first in range(0, simulated.size, chunk):
                    frequencies = tuple(float(f) for f in simulated[first : first + chunk])
                    case = SimulationCase(engine, scene.layout.structure, scene.amplitude, contact, frequencies, sim.start, sim.engine, sim.steady, rigid if on_bumper else None, scene.layout.load)
                    cases.append(case)
                    places.append((i, j, k, columns[first : first + chunk]))
    results = runner.map(cases)
    grid = (shape[0], shape[1], bumpers.size, 1, shape[4])
    size, count = scene.layout.size, len(specs)
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
