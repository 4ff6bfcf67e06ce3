"""A long compiled call that Ctrl-C stops (issue 34, item 4).

A numba loop holds the interpreter while it runs: Python runs no signal handler until it returns, so a run of 10^6
periods (15 s of the ``exact`` engine on the paper's system) let Ctrl-C wait until its end. :func:`call_interruptibly`
runs such a loop (compiled ``nogil``, with a one-entry ``cancel`` flag it reads at every step) in a helper thread
while the calling thread waits in Python, where a KeyboardInterrupt (or any other signal handler's exception) is
raised at once: the flag is then set, the loop returns at its next step, and the exception goes on. The loop runs the
same machine code either way: no number changes. Short calls, and calls from a thread other than the main one
(where no signal handler runs), are made directly: a thread costs ~0.2 ms.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import TypeVar

import numpy as np
from numpy.typing import NDArray

__all__ = ["call_interruptibly", "THREADED_PERIODS"]

#: Periods from which a run is made in a helper thread [-]: at least ~3 ms of the fastest loop (~3 us a period on the
#: paper's system), against ~0.2 ms for the thread (measured: 0.70 ms inline, 0.87 ms threaded at 256 periods; at
#: 1024 and 10^4 periods the difference is below the run-to-run noise); fewer periods take over a second only with
#: over 1 ms (hundreds of events) a period.
THREADED_PERIODS = 1000

#: How often the waiting thread wakes [s] (a signal also wakes it at once on POSIX).
_POLL = 0.05

T = TypeVar("T")


def call_interruptibly(run: Callable[[NDArray[np.int64]], T], periods: int) -> T:
    """``run(cancel)`` (``cancel`` a fresh int64 array of one zero entry, which the loop reads), in a helper thread
    while this one waits interruptibly when ``periods`` >= :data:`THREADED_PERIODS` and this is the main thread; an
    exception raised while waiting (KeyboardInterrupt) sets ``cancel[0] = 1``, waits for the loop to return (at its
    next step) and is raised. ``run``'s own exception is raised here."""
    cancel = np.zeros(1, dtype=np.int64)
    if periods < THREADED_PERIODS or threading.current_thread() is not threading.main_thread():
        return run(cancel)
    outcome: dict[str, object] = {}

    def work() -> None:
        try:
            outcome["value"] = run(cancel)
        except BaseException as error:  # handed to the waiting thread
            outcome["error"] = error

    worker = threading.Thread(target=work, name="vibroimpact-compiled-loop", daemon=True)
    try:
        worker.start()  # a Ctrl-C inside start() too: the loop may have begun
        while worker.is_alive():
            worker.join(_POLL)
    except BaseException:
        cancel[0] = 1
        if worker.ident is not None:
            worker.join()  # within one step of the loop
        raise
    if "error" in outcome:
        raise outcome["error"]  # type: ignore[misc]
    return outcome["value"]  # type: ignore[return-value]
