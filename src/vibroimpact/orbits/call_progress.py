"""A line on a terminal for a Python call that runs for seconds (the continuation of a branch: 11.6 s for the
README's recipe, 70 s for a whole branch, said nothing while it ran): after :data:`QUIET` seconds, how far it got,
rewritten at most every :data:`INTERVAL` seconds on the same line; nothing where the output is no terminal (a script
piped to a file, a test), nor within a study (:func:`quiet_calls`: its own progress bar says how it goes, and its
workers, ``VIBROIMPACT_WORKER``, never write one), and a finished call leaves its last line."""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TextIO

__all__ = ["CallProgress", "QUIET", "INTERVAL", "quiet_calls"]

#: A call quieter than this says nothing [s].
QUIET = 2.0
#: Shortest interval between two lines [s].
INTERVAL = 1.0
_QUIETED = [0]


@contextmanager
def quiet_calls() -> Iterator[None]:
    """No call within the block writes its line (a study runs them: its own bar says how far it got)."""
    _QUIETED[0] += 1
    try:
        yield
    finally:
        _QUIETED[0] -= 1


class CallProgress:
    """How far a long call got, on a terminal (module docstring).

    Parameters
    ----------
    what : str
        What the call does (``continuing in frequency``).
    stream : text stream, optional
        Where the line goes (default ``sys.stderr``); nothing is written unless it is a terminal.
    """

    def __init__(self, what: str, stream: TextIO | None = None) -> None:
        self.what = what
        self.stream = stream if stream is not None else sys.stderr
        isatty = getattr(self.stream, "isatty", None)
        self.enabled = bool(isatty()) if callable(isatty) and not _QUIETED[0] and os.environ.get("VIBROIMPACT_WORKER") != "1" else False
        self.started = self.last = time.perf_counter()
        self.shown = False

    def update(self, done: str) -> None:
        """Say ``done`` (``120 points, frequency = 24.31``) if the call has run for :data:`QUIET` seconds and the
        last line is :data:`INTERVAL` seconds old."""
        if not self.enabled:
            return
        now = time.perf_counter()
        if now - self.started < QUIET or (self.shown and now - self.last < INTERVAL):
            return
        self.last, self.shown = now, True
        self.stream.write(f"\r{self.what}: {done}, {now - self.started:.0f} s\x1b[K")
        self.stream.flush()

    def close(self, done: str = "") -> None:
        """End the line (with ``done``, what the call found) where one was written."""
        if self.shown:
            self.stream.write(f"\r{self.what}: {done or 'done'}, {time.perf_counter() - self.started:.0f} s\x1b[K\n")
            self.stream.flush()
            self.shown = False
