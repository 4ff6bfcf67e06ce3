"""What dask's calls cut off by a Ctrl-C leave behind (a coroutine made for the event loop, cancelled before it ever
ran) says nothing once a failing study leaves quietly, and every other warning still gets through (CI once saw that
warning print after the interrupted study's one line)."""

from __future__ import annotations

import asyncio
import gc
import warnings

from vibroimpact.runs.cluster import leave_quietly


async def _call() -> None:
    """A dask call's coroutine (``Client._close``, ``scheduler.identity``)."""


def _cut_off_call() -> None:
    """The path of distributed's ``sync`` with a timeout, interrupted: ``ensure_future(wait_for(call(), timeout))``,
    then cancelled (its ``cancel`` callback) before the task's first step."""

    async def interrupted() -> None:
        task = asyncio.ensure_future(asyncio.wait_for(_call(), 10.0))
        task.cancel()
        try:
            await task
        except asyncio.CancelledError:
            pass

    asyncio.run(interrupted())
    gc.collect()


def _never_awaited(caught: list[warnings.WarningMessage]) -> list[str]:
    return [str(w.message) for w in caught if issubclass(w.category, RuntimeWarning) and "was never awaited" in str(w.message)]


def test_a_cut_off_call_warns_unless_the_study_leaves_quietly() -> None:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        _cut_off_call()
    assert _never_awaited(caught) == ["coroutine '_call' was never awaited"]  # the warning CI saw, made here

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        leave_quietly()
        _cut_off_call()
        warnings.warn("a warning of the study's own", RuntimeWarning, stacklevel=1)
    assert _never_awaited(caught) == []
    assert [str(w.message) for w in caught] == ["a warning of the study's own"]
