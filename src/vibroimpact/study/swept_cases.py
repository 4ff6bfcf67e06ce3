"""Swept-sine tests of the compliant model as cases of a study (the paper's Simulink runs, section 5).

One case is one sweep direction at one (restitution, clearance, bumper): the compliant engine integrates the whole
sweep, then :func:`vibroimpact.simulation.swept.sweep_estimates` measures it (running estimates on the study's
frequency grid and on a uniform time grid); the case adds the run's cost, and a failed run is NaN and flagged.
"""

from __future__ import annotations

import sys
import time
from dataclasses import asdict, dataclass

import numpy as np
from numpy.typing import NDArray

from vibroimpact.engines.settings import EngineSettings
from vibroimpact.engines.registry import make_engine
from vibroimpact.model.contact import KelvinVoigtBumper
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.study.fingerprint import case_key
from vibroimpact.simulation.swept import SWEEP_QUANTITIES, sweep_estimates, sweep_start_state
from vibroimpact.study.runner import ProgressReport
from vibroimpact.scene.schema import SweptSineSettings
from vibroimpact.model.system import TwoDofSystem

__all__ = ["SweepCase", "SWEEP_STATS", "SWEEP_FIELDS", "run_sweep_case"]

#: Whole-run statistics of a sweep.
SWEEP_STATS = ("wall_time", "steps", "contacts", "rhs_calls", "linear_start", "failed")
SWEEP_FIELDS = SWEEP_QUANTITIES + tuple(f"running_{q}" for q in SWEEP_QUANTITIES) + ("time", "instantaneous_frequency") + SWEEP_STATS


@dataclass(frozen=True)
class SweepCase:
    """One swept-sine run of the compliant model and the frequencies and times its estimates are reported at.

    Attributes
    ----------
    system : TwoDofSystem
        The linear system.
    amplitude : float
        q [N].
    bumper : KelvinVoigtBumper
        The contact: clearance Delta [m], Omega_b / 2 pi [Hz] and xi_b [-].
    settings : SweptSineSettings
        The sweep (ends, rate, sampling, window).
    direction : str
        ``up`` or ``down``.
    engine_settings : EngineSettings
        IDA tolerances.
    frequencies : tuple of float
        Frequencies at which window-centred estimates are reported [Hz] (NaN outside the sweep or its windows).
    time_points : int
        Points of the uniform time grid of the running estimates.
    """

    system: TwoDofSystem
    amplitude: float
    bumper: KelvinVoigtBumper
    settings: SweptSineSettings
    direction: str
    engine_settings: EngineSettings
    frequencies: tuple[float, ...]
    time_points: int = 2001

    engine = "compliant_sweep"
    #: The registered engine that runs the sweep.
    engine_name = "compliant"
    fields = SWEEP_FIELDS

    progress_unit = "s simulated"

    @property
    def progress_total(self) -> float:
        """The sweep's duration [s]: progress is counted in simulated time."""
        return self.settings.sweep(self.amplitude, self.direction).duration

    def key(self) -> str:
        """A stable hash of everything that determines the result, the package version and its source code."""
        return case_key(asdict(self))

    def run(self, report: ProgressReport | None = None) -> dict[str, NDArray[np.generic]]:
        """Simulate the sweep and estimate (see :func:`run_sweep_case`)."""
        return run_sweep_case(self, report)


def run_sweep_case(case: SweepCase, report: ProgressReport | None = None) -> dict[str, NDArray[np.generic]]:
    """Run one sweep; estimates on ``case.frequencies`` and on the time grid, and the run's cost.

    ``report`` receives the simulated time reached [s] as the run goes on."""
    sweep = case.settings.sweep(case.amplitude, case.direction)
    engine = make_engine(case.engine_name, case.engine_settings)
    started = time.perf_counter()
    state = sweep_start_state(case.system, sweep, case.bumper.clearance) if case.settings.initial_state == "linear" else None
    times = np.linspace(0.0, sweep.duration, case.time_points)
    try:
        record = engine.sweep(ImpactProblem(case.system, case.bumper, sweep), case.settings.sample_rate, state, report)
    except (RuntimeError, ValueError, ArithmeticError) as error:
        # a failing run must not cost the others: it stays NaN, flagged, and the study goes on
        print(f"compliant sweep {case.direction}: {case.bumper} failed: {error}", file=sys.stderr)
        failed: dict[str, NDArray[np.generic]] = {name: np.full(len(case.frequencies), np.nan) for name in SWEEP_QUANTITIES}
        failed |= {f"running_{name}": np.full(times.size, np.nan) for name in SWEEP_QUANTITIES}
        failed |= {"time": times, "instantaneous_frequency": sweep.frequency(times)}
        failed |= {name: np.array(np.nan) for name in SWEEP_STATS}
        failed["linear_start"] = np.array(float(state is not None))
        failed["failed"] = np.array(1.0)
        return failed
    wall_time = time.perf_counter() - started
    out = sweep_estimates(record, sweep, case.frequencies, times, case.settings.window_cycles)
    stats = record.trajectory.stats
    out["wall_time"] = np.array(wall_time)
    for name in ("steps", "contacts", "rhs_calls"):
        out[name] = np.array(float(stats.get(name, np.nan)))
    out["linear_start"] = np.array(float(state is not None))  # the linear start falls back to rest where it would cross the stop
    out["failed"] = np.array(0.0)
    return out
