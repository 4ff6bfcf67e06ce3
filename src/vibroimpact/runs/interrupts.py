"""Ctrl-C in the processes a study spawns: the study's own process handles it, its workers ignore it.

Kept apart (standard library only) because a local cluster's worker runs :func:`ignore_interrupts_in_workers` as the
very first thing it imports, before the seconds of imports that a terminal's Ctrl-C (sent to every process of its
group) would otherwise interrupt with a traceback.
"""

from __future__ import annotations

import multiprocessing
import signal
import threading

__all__ = ["ignore_interrupts_in_workers"]


def ignore_interrupts_in_workers() -> None:
    """In a process spawned by ``multiprocessing`` (a local cluster's worker), ignore SIGINT from now on.

    Called by the package's ``__init__`` when ``VIBROIMPACT_WORKER=1`` (set by :mod:`vibroimpact.runs.cluster` for
    its workers): ``multiprocessing`` imports the parent's main module (``run-study``, which imports the package)
    first in a spawned child, while it is still inheriting from its parent, so this runs within ~0.1 s of its start.
    A process that merely inherited the variable (not a spawned child) keeps its Ctrl-C.
    """
    process = multiprocessing.current_process()
    spawned = getattr(process, "_inheriting", False) or multiprocessing.parent_process() is not None
    if spawned and threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
