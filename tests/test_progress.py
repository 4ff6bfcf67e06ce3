"""The progress bar never falls silent: while no work arrives (workers starting, a long first task) it is shown again
with its elapsed time and what the run is doing, at least every ``heartbeat`` seconds."""

from __future__ import annotations

import time

import pytest

from vibroimpact.runs.cluster import HEARTBEAT, ProgressBar


def test_a_silent_run_is_shown_again_with_what_it_waits_for(capsys: pytest.CaptureFixture[str]) -> None:
    bar = ProgressBar([10.0, 10.0], [], "points", enabled=True, heartbeat=0.3)
    bar.set_status("starting 2 worker processes")
    time.sleep(1.0)  # nothing arrives: ~3 heartbeats
    bar.partial(0, 5.0)
    bar.close()
    closed = capsys.readouterr().err.splitlines()
    time.sleep(0.4)
    assert capsys.readouterr().err == "", "the heartbeat stops with the bar"
    waiting = [line for line in closed if "starting 2 worker processes" in line]
    assert len(waiting) >= 3, closed  # the set_status line, then one per heartbeat
    assert closed[-1].startswith("simulating [") and "5/20 points" in closed[-1]
    assert "starting" not in closed[-1], "the status is dropped once work arrives"


def test_a_quiet_bar_prints_no_heartbeat(capsys: pytest.CaptureFixture[str]) -> None:
    bar = ProgressBar([10.0], [], "points", enabled=False, heartbeat=0.1)
    time.sleep(0.3)
    bar.close()
    assert capsys.readouterr().err == ""
    assert HEARTBEAT <= 10.0  # the bound on a silent progress line
