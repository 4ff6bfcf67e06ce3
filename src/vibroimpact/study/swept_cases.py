"""Swept-sine tests of the compliant model as cases of a study (the paper's Simulink runs, section 5).

One case is one sweep direction at one (restitution, clearance, bumper) grid point of any structure, load and stops:
the compliant engine integrates the whole sweep, then :func:`vibroimpact.simulation.swept.sweep_estimates` measures it
(running estimates on the study's frequency grid and on a uniform time grid, one per coordinate and per stop); the
case adds the run's cost, and a failed run is NaN and flagged.
"""

from __future__ import annotations

import sys
import time
from dataclasses import asdict, dataclass, replace

import numpy as np
from numpy.typing import NDArray

from vibroimpact.engines.registry import make_engine
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.model.excitation import SweptSine
from vibroimpact.model.problem import ImpactProblem, Structure
from vibroimpact.model.stops import Stop
from vibroimpact.scene.layout import LoadSpec
from vibroimpact.scene.schema import SweptSineSettings
from vibroimpact.simulation.layout import resting_state
from vibroimpact.simulation.swept import SWEEP_STOP_QUANTITIES, sweep_estimates, sweep_quantities, sweep_start_state
from vibroimpact.study.fingerprint import case_key
from vibroimpact.study.runner import ProgressReport

__all__ = ["SweepCase", "SWEEP_STATS", "run_sweep_case"]

#: Whole-run statistics of a sweep.
SWEEP_STATS = ("wall_time", "steps", "contacts", "rhs_calls", "linear_start", "failed")


@dataclass(frozen=True)
class SweepCase:
    """One swept-sine run of the compliant model and the frequencies and times its estimates are reported at.

    Attributes
    ----------
    system : Structure
        The linear structure: the paper's named system or matrices with named coordinates.
    amplitude : float
        q [N].
    stops : tuple of Stop
        Every stop, each with its :class:`~vibroimpact.model.contact.KelvinVoigtBumper` (clearance Delta [m],
        Omega_b / 2 pi [Hz], xi_b [-]).
    settings : SweptSineSettings
        The sweep (ends, rate, sampling, window).
    direction : str
        ``up`` or ``down``.
    engine_settings : EngineSettings
        IDA tolerances.
    frequencies : tuple of float
        Frequencies at which window-centred estimates are reported [Hz] (NaN outside the sweep or its windows).
    load : LoadSpec or None
        How q is distributed over the coordinates, and a constant force; None: all of q on the first coordinate.
    time_points : int
        Points of the uniform time grid of the running estimates.
    """

    system: Structure
    amplitude: float
    stops: tuple[Stop, ...]
    settings: SweptSineSettings
    direction: str
    engine_settings: EngineSettings
    frequencies: tuple[float, ...]
    load: LoadSpec | None = None
    time_points: int = 2001

    engine = "compliant_sweep"
    #: The registered engine that runs the sweep.
    engine_name = "compliant"
    progress_unit = "s simulated"

    def __post_init__(self) -> None:
        if not self.stops:
            raise ValueError("stops: a swept-sine run needs at least one stop")
        if self.load is not None and self.load.base_motion:
            raise ValueError("load: a swept-sine run drives a force; a swept base motion is not supported")

    @property
    def fields(self) -> tuple[str, ...]:
        """Names of the result's arrays: every estimate, on the frequency grid and running, the time axes and the
        run's statistics."""
        names = sweep_quantities(tuple(self.system.coordinates))
        return names + tuple(f"running_{q}" for q in names) + ("time", "instantaneous_frequency") + SWEEP_STATS

    @property
    def sweep(self) -> SweptSine:
        """The excitation: the settings' sweep in this direction, distributed as the load says."""
        sweep = self.settings.sweep(self.amplitude, self.direction)
        if self.load is None:
            return sweep
        return replace(sweep, weights=self.load.weights, static=self.load.static)

    def problem(self) -> ImpactProblem:
        """The structure, its bumpers and the sweep."""
        return ImpactProblem(self.system, self.stops, self.sweep)

    @property
    def progress_total(self) -> float:
        """The sweep's duration [s]: progress is counted in simulated time."""
        return self.sweep.duration

    def key(self) -> str:
        """A stable hash of everything that determines the result, the package version and its source code."""
        return case_key({"kind": type(self.system).__name__, **asdict(self)})

    def run(self, report: ProgressReport | None = None) -> dict[str, NDArray[np.generic]]:
        """Simulate the sweep and estimate (see :func:`run_sweep_case`)."""
        return run_sweep_case(self, report)


def run_sweep_case(case: SweepCase, report: ProgressReport | None = None) -> dict[str, NDArray[np.generic]]:
    """Run one sweep; estimates on ``case.frequencies`` and on the time grid, and the run's cost.

    The run starts on the linear steady state at its first frequency where the settings ask for it and that motion
    stays clear of every stop, else at rest (the static position, on the stops it would cross). ``report`` receives
    the simulated time reached [s] as the run goes on."""
    problem = case.problem()
    sweep = problem.sweep
    engine = make_engine(case.engine_name, case.engine_settings)
    started = time.perf_counter()
    linear = sweep_start_state(problem) if case.settings.initial_state == "linear" else None
    state = linear if linear is not None else resting_state(problem)
    times = np.linspace(0.0, sweep.duration, case.time_points)
    names = sweep_quantities(tuple(case.system.coordinates))
    count = len(case.stops)
    try:
        record = engine.sweep(problem, case.settings.sample_rate, state, report)
    except (RuntimeError, ValueError, ArithmeticError) as error:
        # a failing run must not cost the others: it stays NaN, flagged, and the study goes on
        print(f"compliant sweep {case.direction}: {case.stops} failed: {error}", file=sys.stderr)
        failed: dict[str, NDArray[np.generic]] = {}
        for name in names:
            per_stop = (count,) if name in SWEEP_STOP_QUANTITIES else ()
            failed[name] = np.full((*per_stop, len(case.frequencies)), np.nan)
            failed[f"running_{name}"] = np.full((*per_stop, times.size), np.nan)
        failed |= {"time": times, "instantaneous_frequency": sweep.frequency(times)}
        failed |= {name: np.array(np.nan) for name in SWEEP_STATS}
        failed["linear_start"] = np.array(float(linear is not None))
        failed["failed"] = np.array(1.0)
        return failed
    wall_time = time.perf_counter() - started
    out = sweep_estimates(record, sweep, case.frequencies, times, case.settings.window_cycles)
    stats = record.trajectory.stats
    out["wall_time"] = np.array(wall_time)
    for name in ("steps", "contacts", "rhs_calls"):
        out[name] = np.array(float(stats.get(name, np.nan)))
    out["linear_start"] = np.array(float(linear is not None))  # the linear start falls back to rest where it would reach a stop
    out["failed"] = np.array(0.0)
    return out
