"""Run simulation cases in processes: progress that advances inside each case, a resumable cache, a clean interrupt.

A *case* is a picklable piece of work with a stable key (:class:`Case`). Each finished case is saved to the cache
folder (written atomically), so an interrupted study picks up where it stopped; the key includes a hash of the
package's source, so results of other code are never reused. Workers ignore Ctrl-C: the main process alone
receives it, stops the workers and raises :class:`KeyboardInterrupt` with every finished case kept.
"""

from __future__ import annotations

import multiprocessing
import queue
import signal
import sys
import time
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from pathlib import Path
from typing import Callable, Protocol, Sequence

import numpy as np
from numpy.typing import NDArray

from vibroimpact.study.io import atomic_path

__all__ = ["Case", "CaseResult", "ProgressReport", "run_cases", "cached_case_count"]

CaseResult = dict[str, NDArray[np.generic]]
#: Called by a running case with the work it has done so far, in its ``progress_unit`` (0 ... ``progress_total``).
ProgressReport = Callable[[float], None]
#: Shortest interval between two progress messages of one worker [s].
REPORT_INTERVAL = 0.25
#: How often the main process looks at the workers' progress messages [s].
POLL_INTERVAL = 0.2


class Case(Protocol):
    """What :func:`run_cases` runs."""

    engine: str
    fields: tuple[str, ...]

    @property
    def progress_total(self) -> float:
        """The case's work in ``progress_unit`` (frequency points, simulated seconds)."""
        ...

    @property
    def progress_unit(self) -> str: ...

    def key(self) -> str: ...

    def run(self, report: ProgressReport | None = None) -> CaseResult: ...


def run_cases(cases: Sequence[Case], jobs: int = 1, cache_dir: Path | None = None, progress: bool = True) -> list[CaseResult]:
    """Run cases serially (``jobs = 1``) or in ``jobs`` processes, reusing and filling ``cache_dir``.

    Progress (work done, elapsed, estimated remaining) goes to stderr and advances while cases run.

    Raises
    ------
    KeyboardInterrupt
        On Ctrl-C, after the workers are stopped; finished cases stay in ``cache_dir``.
    """
    results: list[CaseResult | None] = [_load(cache_dir, case) if cache_dir is not None else None for case in cases]
    pending = [index for index, result in enumerate(results) if result is None]
    unit = cases[0].progress_unit if cases else "points"
    bar = _Progress([case.progress_total for case in cases], [index for index in range(len(cases)) if results[index] is not None], unit, progress)

    def finish(index: int, result: CaseResult) -> None:
        results[index] = result
        if cache_dir is not None:
            _save(cache_dir, cases[index], result)
        bar.finish(index)

    try:
        if jobs <= 1 or len(pending) <= 1:
            for index in pending:
                finish(index, cases[index].run(_Throttled(lambda done, index=index: bar.partial(index, done))))
        else:
            _run_in_processes(cases, pending, jobs, bar, finish)
    finally:
        bar.close()
    finished = [r for r in results if r is not None]
    if len(finished) != len(cases):  # cannot happen: every case either came from the cache or was run
        raise RuntimeError(f"{len(cases) - len(finished)} simulation cases have no result")
    return finished


def cached_case_count(cache_dir: Path) -> int:
    """Finished cases kept in ``cache_dir`` (not counting a temporary file being written, whose name starts with a dot)."""
    return sum(1 for path in cache_dir.glob("*.npz") if not path.name.startswith(".")) if cache_dir.is_dir() else 0


def _run_in_processes(cases: Sequence[Case], pending: list[int], jobs: int, bar: "_Progress", finish: Callable[[int, CaseResult], None]) -> None:
    context = multiprocessing.get_context()
    messages = context.Queue()
    pool = ProcessPoolExecutor(max_workers=jobs, mp_context=context, initializer=_start_worker, initargs=(messages,))
    try:
        futures: dict[Future[CaseResult], int] = {pool.submit(_run_in_worker, index, cases[index]): index for index in pending}
        waiting = set(futures)
        while waiting:
            done, waiting = wait(waiting, timeout=POLL_INTERVAL, return_when=FIRST_COMPLETED)
            _drain(messages, bar)
            for future in done:
                finish(futures[future], future.result())
    except BaseException:
        # Ctrl-C or a failed case: stop the workers now instead of letting them finish their cases
        for process in list(getattr(pool, "_processes", {}).values()):
            process.terminate()
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    else:
        pool.shutdown()
    finally:
        messages.close()
        messages.cancel_join_thread()


def _drain(messages: "multiprocessing.Queue[tuple[int, float]]", bar: "_Progress") -> None:
    while True:
        try:
            index, done = messages.get_nowait()
        except queue.Empty:
            return
        bar.partial(index, done)


_worker_messages: "multiprocessing.Queue[tuple[int, float]] | None" = None


def _start_worker(messages: "multiprocessing.Queue[tuple[int, float]]") -> None:
    """Worker set-up: Ctrl-C is the main process's to handle; progress goes to ``messages``."""
    global _worker_messages
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _worker_messages = messages


def _run_in_worker(index: int, case: Case) -> CaseResult:
    messages = _worker_messages
    report = _Throttled(lambda done: messages.put((index, done))) if messages is not None else None
    return case.run(report)


class _Throttled:
    """Passes a progress value on at most every :data:`REPORT_INTERVAL` seconds."""

    def __init__(self, send: ProgressReport) -> None:
        self.send, self.last = send, -np.inf

    def __call__(self, done: float) -> None:
        now = time.monotonic()
        if now - self.last >= REPORT_INTERVAL:
            self.last = now
            self.send(done)


class _Progress:
    """A one-line progress bar on stderr (a line per 10 % when stderr is not a terminal)."""

    def __init__(self, totals: list[float], finished: list[int], unit: str, enabled: bool) -> None:
        self.totals = totals
        self.total = max(sum(totals), 1e-300)
        self.done = {index: totals[index] for index in finished}
        self.unit = unit
        self.enabled = enabled and sum(totals) > 0
        self.started = time.perf_counter()
        self.first_done = sum(self.done.values())
        self.tty = sys.stderr.isatty()
        self.last_decile = -1
        self._show()

    def partial(self, index: int, done: float) -> None:
        self.done[index] = min(max(done, 0.0), self.totals[index])
        self._show()

    def finish(self, index: int) -> None:
        self.partial(index, self.totals[index])

    def _show(self) -> None:
        if not self.enabled:
            return
        done = sum(self.done.values())
        fraction = min(done / self.total, 1.0)
        elapsed = time.perf_counter() - self.started
        rate = (done - self.first_done) / elapsed if elapsed > 0 and done > self.first_done else 0.0
        remaining = f"{(self.total - done) / rate:.0f} s left" if rate > 0 else "..."
        filled = int(30 * fraction)
        line = f"simulating [{'#' * filled}{'.' * (30 - filled)}] {done:.0f}/{self.total:.0f} {self.unit}, {elapsed:.0f} s, {remaining}"
        if self.tty:
            print("\r" + line + "  ", end="", file=sys.stderr, flush=True)
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
