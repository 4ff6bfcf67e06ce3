"""Workarounds for scikit-sundae 1.2.0 shared by the SUNDIALS engines (see ``../shared/NOTES.md``)."""

from __future__ import annotations

from typing import Any

__all__ = ["clear_event_records"]


def clear_event_records(events: Any) -> None:
    """Forget the roots recorded on a scikit-sundae event function.

    The records accumulate across ``init_step`` calls and every ``step`` rebuilds its result from all of them, so a
    long run gets slower step by step unless they are cleared after each event. They are private attributes in
    1.2.0 (``_i``, ``_t``, ``_y``, ``_i_cnt``, and for IDA ``_yp``, which alone made a 300 s compliant sweep 10x
    slower); if a later version renames them, this does nothing.
    """
    for name in ("_i", "_t", "_y", "_yp"):
        records = getattr(events, name, None)
        if records is not None:
            records.clear()
    counts = getattr(events, "_i_cnt", None)
    if counts is not None:
        counts[:] = 0
