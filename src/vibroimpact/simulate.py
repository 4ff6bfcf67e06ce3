"""Steady states of the time-domain engines over a study's grid: cases, parallel processes, progress, resumable cache.

A *case* is one engine at one (restitution, clearance) over its frequencies: independent points for the ``linear``,
``pgf`` and ``rest`` starts, a chain for the stepped sweeps (``sweep_up``, ``sweep_down``: each point starts from the
previous one's end state, with the force phase kept continuous). Each finished case is saved to the cache folder
(written atomically), so an interrupted study picks up where it stopped.
"""

from __future__ import annotations

import hashlib
import json
import math
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Callable, Protocol, Sequence

import numpy as np
from numpy.typing import NDArray

from . import __version__
from .atomic import atomic_path
from .engines import EngineSettings, ExactEngine, ImpactProblem
from .engines.base import Engine
from .engines.compliant import CompliantEngine
from .engines.momentary import MomentaryEngine
from .steady import SteadySettings, linear_fits, steady_state
from .system import TwoDofSystem

__all__ = ["ENGINES", "SWEEP_STARTS", "Case", "SimulationCase", "CaseResult", "run_cases", "make_engine"]

#: Time-domain solutions and their engines (the compliant one also needs its bumper, see :func:`make_engine`).
ENGINES: dict[str, Callable[..., Engine]] = {"exact": ExactEngine, "momentary": MomentaryEngine, "compliant": CompliantEngine}
SWEEP_STARTS = ("sweep_up", "sweep_down")
#: Fields of a case result, one value per frequency.
FIELDS = (
    "x1",
    "x2",
    "suspension_force",
    "contact_force",
    "x1_rms",
    "x2_rms",
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
)


def make_engine(name: str, settings: EngineSettings, bumper_frequency: float = math.nan, bumper_loss_factor: float = math.nan) -> Engine:
    """The engine registered under ``name``; ``compliant`` takes Omega_b / 2 pi [Hz] and xi_b [-] of its bumper."""
    if name not in ENGINES:
        raise ValueError(f"engine {name!r} is unknown: use one of {', '.join(ENGINES)}")
    if name == "compliant":
        return CompliantEngine(bumper_frequency, bumper_loss_factor, settings)
    return ENGINES[name](settings)


@dataclass(frozen=True)
class SimulationCase:
    """One engine at one (restitution, clearance) over its frequencies."""

    engine: str
    system: TwoDofSystem
    amplitude: float
    restitution: float
    clearance: float
    frequencies: tuple[float, ...]
    start: str
    engine_settings: EngineSettings
    steady_settings: SteadySettings
    bumper_frequency: float = math.nan
    bumper_loss_factor: float = math.nan

    fields = FIELDS

    @property
    def points(self) -> int:
        """Frequency points in the case (progress is counted in points)."""
        return len(self.frequencies)

    def run(self) -> "CaseResult":
        """Steady states of this case (see :func:`run_case`)."""
        return run_case(self)

    def key(self) -> str:
        """A stable hash of everything that determines the result (and of the package version)."""
        text = json.dumps(
            {
                "version": __version__,
                "engine": self.engine,
                "system": asdict(self.system),
                "amplitude": self.amplitude,
                "restitution": self.restitution,
                "clearance": self.clearance,
                "frequencies": list(self.frequencies),
                "start": self.start,
                "engine_settings": asdict(self.engine_settings),
                "steady_settings": asdict(self.steady_settings),
                "bumper": [self.bumper_frequency, self.bumper_loss_factor] if self.engine == "compliant" else None,
            },
            sort_keys=True,
        )
        return hashlib.sha256(text.encode()).hexdigest()[:24]


CaseResult = dict[str, NDArray[np.generic]]


def run_case(case: SimulationCase) -> CaseResult:
    """Steady states of one case, in the order of ``case.frequencies``."""
    engine = make_engine(case.engine, case.engine_settings, case.bumper_frequency, case.bumper_loss_factor)
    n = len(case.frequencies)
    out: dict[str, NDArray[np.generic]] = {name: np.full(n, np.nan, dtype=complex if name in ("x1", "x2", "suspension_force", "contact_force") else float) for name in FIELDS}
    order = range(n - 1, -1, -1) if case.start == "sweep_down" else range(n)
    previous = None
    for i in order:
        frequency = case.frequencies[i]
        problem = ImpactProblem(case.system, case.clearance, case.restitution, case.amplitude, frequency, phase=0.0)
        start: str | tuple[float, NDArray[np.float64]] = case.start
        if case.start in SWEEP_STARTS:
            if previous is None or (previous[2] == 0.0 and linear_fits(problem)):
                start = "linear"  # a slow sweep without impacts follows the linear steady state
            else:
                old_problem, result, _impacts = previous
                # keep the force continuous: the new force at t = 0 continues the old one at its end time
                phase = (old_problem.omega * result.end_time + old_problem.phase) % (2.0 * math.pi)
                problem = ImpactProblem(case.system, case.clearance, case.restitution, case.amplitude, frequency, phase=phase)
                start = (0.0, result.end_state)
        started = time.perf_counter()
        try:
            result = steady_state(engine, problem, start, case.steady_settings)
        except (RuntimeError, ValueError, ArithmeticError, np.linalg.LinAlgError) as error:
            # one failing point must not cost the others: it stays NaN, flagged, and a sweep restarts after it
            print(f"{case.engine}: R = {case.restitution:g}, Delta = {case.clearance:g} m, f = {frequency:g} Hz failed: {error}", file=sys.stderr)
            out["failed"][i] = 1.0
            previous = None
            continue
        m = result.measures
        values = {
            "x1": m.x1,
            "x2": m.x2,
            "suspension_force": m.suspension_force,
            "contact_force": m.contact_force,
            "x1_rms": m.x1_rms,
            "x2_rms": m.x2_rms,
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
        }
        for name, value in values.items():
            out[name][i] = value
        previous = (problem, result, m.impacts_per_period)
    return out


class Case(Protocol):
    """What :func:`run_cases` runs: a picklable piece of work with a stable key and a weight for progress."""

    engine: str
    fields: tuple[str, ...]

    @property
    def points(self) -> int: ...

    def key(self) -> str: ...

    def run(self) -> CaseResult: ...


def _run(case: Case) -> CaseResult:
    return case.run()


def run_cases(cases: Sequence[Case], jobs: int = 1, cache_dir: Path | None = None, progress: bool = True) -> list[CaseResult]:
    """Run cases serially (``jobs = 1``) or in ``jobs`` processes, reusing and filling ``cache_dir``.

    Progress (points done, elapsed, estimated remaining) goes to stderr.
    """
    results: list[CaseResult | None] = [None] * len(cases)
    pending = []
    for index, case in enumerate(cases):
        cached = _load(cache_dir, case) if cache_dir is not None else None
        if cached is not None:
            results[index] = cached
        else:
            pending.append(index)
    bar = _Progress(sum(c.points for c in cases), sum(cases[i].points for i in range(len(cases)) if results[i] is not None), progress)

    def finish(index: int, result: CaseResult) -> None:
        results[index] = result
        if cache_dir is not None:
            _save(cache_dir, cases[index], result)
        bar.advance(cases[index].points)

    if jobs <= 1 or len(pending) <= 1:
        for index in pending:
            finish(index, cases[index].run())
    else:
        with ProcessPoolExecutor(max_workers=jobs) as pool:
            futures = {pool.submit(_run, cases[index]): index for index in pending}
            for future in as_completed(futures):
                finish(futures[future], future.result())
    bar.close()
    finished = [r for r in results if r is not None]
    if len(finished) != len(cases):  # cannot happen: every case either came from the cache or was run
        raise RuntimeError(f"{len(cases) - len(finished)} simulation cases have no result")
    return finished


class _Progress:
    """A one-line progress bar on stderr (a line per 10 % when stderr is not a terminal)."""

    def __init__(self, total: int, done: int, enabled: bool) -> None:
        self.total, self.done, self.enabled = max(total, 1), done, enabled and total > 0
        self.started = time.perf_counter()
        self.first_done = done
        self.tty = sys.stderr.isatty()
        self.last_decile = -1
        self._show()

    def advance(self, points: int) -> None:
        self.done += points
        self._show()

    def _show(self) -> None:
        if not self.enabled:
            return
        fraction = self.done / self.total
        elapsed = time.perf_counter() - self.started
        rate = (self.done - self.first_done) / elapsed if elapsed > 0 and self.done > self.first_done else 0.0
        remaining = f"{(self.total - self.done) / rate:.0f} s left" if rate > 0 else "..."
        filled = int(30 * fraction)
        line = f"simulating [{'#' * filled}{'.' * (30 - filled)}] {self.done}/{self.total} points, {elapsed:.0f} s, {remaining}"
        if self.tty:
            print("\r" + line, end="", file=sys.stderr, flush=True)
        elif int(10 * fraction) > self.last_decile:
            self.last_decile = int(10 * fraction)
            print(line, file=sys.stderr, flush=True)

    def close(self) -> None:
        if self.enabled and self.tty:
            print(file=sys.stderr, flush=True)


def _cache_path(cache_dir: Path, case: Case) -> Path:
    return cache_dir / f"{case.engine}-{case.key()}.npz"


def _load(cache_dir: Path, case: Case) -> CaseResult | None:
    path = _cache_path(cache_dir, case)
    if not path.is_file():
        return None
    with np.load(path) as stored:
        if not set(case.fields) <= set(stored.files):
            return None  # written by an older version: run the case again
        return {name: stored[name] for name in case.fields}


def _save(cache_dir: Path, case: Case, result: CaseResult) -> None:
    with atomic_path(_cache_path(cache_dir, case), suffix=".npz") as temporary:
        np.savez(temporary, **result)  # type: ignore[arg-type]
