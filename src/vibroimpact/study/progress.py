"""Progress of a study's work: a one-line bar on stderr that advances while tasks run, fed from this process or,
through the dask scheduler's event log, from the workers."""

from __future__ import annotations

import sys
import threading
import time
from typing import Callable

import numpy as np

__all__ = ["ProgressReport", "Throttled", "ProgressBar", "REPORT_INTERVAL"]

#: Called by running work with what it has done so far, in its progress unit (points, simulated seconds).
ProgressReport = Callable[[float], None]
#: Shortest interval between two progress messages of one task [s].
REPORT_INTERVAL = 0.25


class Throttled:
    """Passes a progress value on at most every :data:`REPORT_INTERVAL` seconds."""

    def __init__(self, send: ProgressReport) -> None:
        self.send, self.last = send, -np.inf

    def __call__(self, done: float) -> None:
        now = time.monotonic()
        if now - self.last >= REPORT_INTERVAL:
            self.last = now
            self.send(done)


class ProgressBar:
    """A one-line progress bar on stderr (a line per 10 % when stderr is not a terminal).

    Thread-safe: the dask client delivers the workers' progress messages on its own thread.

    Parameters
    ----------
    totals : list of float
        The work of each task, in ``unit``.
    finished : list of int
        Tasks already done (taken from the store of an interrupted run).
    unit : str
        What the work is counted in (``points``, ``s``).
    enabled : bool
        False: print nothing.
    verb : str
        The bar's first word.
    done_before : float
        Work done before these tasks (cases an interrupted run finished), in ``unit``: counted as done.
    """

    def __init__(self, totals: list[float], finished: list[int], unit: str, enabled: bool, verb: str = "simulating", done_before: float = 0.0) -> None:
        self.totals = totals
        self.total = max(sum(totals) + done_before, 1e-300)
        self.done = {index: totals[index] for index in finished}
        self.finished = set(finished)
        self.done_sum = float(sum(self.done.values())) + done_before
        self.unit = unit
        self.verb = verb
        self.enabled = enabled and sum(totals) + done_before > 0
        self.started = time.perf_counter()
        self.first_done = self.done_sum
        self.tty = sys.stderr.isatty()
        self.last_decile = -1
        self.lock = threading.Lock()
        self._show()

    def partial(self, index: int, done: float) -> None:
        """Task ``index`` has done ``done`` of its work (a late message of a finished task changes nothing)."""
        with self.lock:
            if index in self.finished:
                return
            value = min(max(done, 0.0), self.totals[index])
            self.done_sum += value - self.done.get(index, 0.0)
            self.done[index] = value
            self._show()

    def finish(self, index: int) -> None:
        """Task ``index`` is done."""
        self.partial(index, self.totals[index])
        self.finished.add(index)

    def _show(self) -> None:
        if not self.enabled:
            return
        done = self.done_sum
        fraction = min(done / self.total, 1.0)
        elapsed = time.perf_counter() - self.started
        rate = (done - self.first_done) / elapsed if elapsed > 0 and done > self.first_done else 0.0
        remaining = f"{(self.total - done) / rate:.0f} s left" if rate > 0 else "..."
        filled = int(30 * fraction)
        line = f"{self.verb} [{'#' * filled}{'.' * (30 - filled)}] {done:.0f}/{self.total:.0f} {self.unit}, {elapsed:.0f} s, {remaining}"
        if self.tty:
            print("\r" + line + "  ", end="", file=sys.stderr, flush=True)
        elif int(10 * fraction) > self.last_decile:
            self.last_decile = int(10 * fraction)
            print(line, file=sys.stderr, flush=True)

    def close(self) -> None:
        """End the bar's line."""
        if self.enabled and self.tty:
            print(file=sys.stderr, flush=True)
