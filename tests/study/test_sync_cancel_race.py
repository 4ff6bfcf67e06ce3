"""The one tornado traceback a Ctrl-C can leave from distributed's own ``sync`` (a race in its cancel callback) is
dropped, and every other logged error still gets through."""

from __future__ import annotations

import logging
import os
import sys

from vibroimpact.runs.cluster import SyncCancelRace


def _record_of(source: str, filename: str) -> logging.LogRecord:
    """The log record tornado writes when the callback ``cancel`` compiled from ``source`` (as ``filename``) raises."""
    namespace: dict[str, object] = {}
    exec(compile(source, filename, "exec"), namespace)  # noqa: S102 - a fixed test snippet
    try:
        namespace["cancel"]()  # type: ignore[operator]
    except Exception:
        exc_info = sys.exc_info()
    return logging.LogRecord("tornado.application", logging.ERROR, __file__, 1, "Exception in callback", None, exc_info)


RACE = "def cancel():\n    if future is not None:\n        future.cancel()\n    future = None\n"


def test_the_race_in_distributeds_sync_is_dropped() -> None:
    record = _record_of(RACE, os.path.join("site-packages", "distributed", "utils.py"))
    assert isinstance(record.exc_info[1], NameError)  # type: ignore[index]
    assert not SyncCancelRace().filter(record)


def test_other_errors_get_through() -> None:
    elsewhere = _record_of(RACE, os.path.join("site-packages", "mypackage", "utils.py"))
    other = _record_of("def cancel():\n    raise ValueError('future')\n", os.path.join("site-packages", "distributed", "utils.py"))
    plain = logging.LogRecord("tornado.application", logging.ERROR, __file__, 1, "no exception", None, None)
    assert all(SyncCancelRace().filter(record) for record in (elsewhere, other, plain))
