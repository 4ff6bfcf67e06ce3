"""Steady states of the time-domain engines over a study's grid, as cases for :func:`vibroimpact.study.runner.run_cases`.

A *case* is one engine at one contact (a rigid stop, or a bumper) over its frequencies: independent points for the ``linear``,
``pgf`` and ``rest`` starts, a chain for the stepped sweeps (``sweep_up``, ``sweep_down``: each point starts from the
previous one's end state, with the force phase kept continuous).
"""

from __future__ import annotations

import math
import sys
import time
from dataclasses import asdict, dataclass

import numpy as np
from numpy.typing import NDArray

from vibroimpact.engines.registry import make_engine
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.stops import Stop
from vibroimpact.model.structure import LinearStructure
from vibroimpact.scene.layout import LoadSpec
from vibroimpact.study.fingerprint import case_key
from vibroimpact.study.runner import CaseResult, ProgressReport
from vibroimpact.simulation.steady import linear_fits, pgf_guesses, steady_state
from vibroimpact.simulation.settings import SWEEP_STARTS, SteadySettings
from vibroimpact.model.system import TwoDofSystem

__all__ = ["SimulationCase", "run_case"]

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
    system : TwoDofSystem or LinearStructure
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
    system: TwoDofSystem | LinearStructure
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
