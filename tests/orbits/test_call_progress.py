"""A continuation of seconds says how far it got on a terminal (issue 51: the README's recipe was silent for 11.6 s,
a whole branch for 70 s), and nothing where the output is no terminal, within a study, or in a study's worker."""

from __future__ import annotations

import io

import pytest

from tests.orbits.toy_maps import FoldMap
from vibroimpact.orbits import call_progress
from vibroimpact.orbits.call_progress import quiet_calls
from vibroimpact.orbits.continuation import ContinuationSettings, continue_branch
from vibroimpact.orbits.shooting import shoot


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def _continued(monkeypatch: pytest.MonkeyPatch, stream: io.StringIO) -> str:
    monkeypatch.setattr(call_progress.sys, "stderr", stream)
    monkeypatch.setattr(call_progress, "QUIET", 0.0)  # the toy branch takes milliseconds: say it at once
    monkeypatch.setattr(call_progress, "INTERVAL", 0.0)
    continue_branch(FoldMap(), shoot(FoldMap(), [0.6], [0.25]), "p", ContinuationSettings(lower=-1.0, upper=1.5))
    return stream.getvalue()


def test_a_continuation_on_a_terminal_says_how_far_it_got_and_ends_its_line(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("VIBROIMPACT_WORKER", raising=False)
    said = _continued(monkeypatch, _Terminal())
    lines = said.split("\r")
    assert any(line.startswith("continuing in p: 1 points, p = ") for line in lines), said[:300]
    assert said.endswith("\n") and lines[-1].startswith("continuing in p: ") and " points, " in lines[-1]


def test_nothing_is_said_off_a_terminal_within_a_study_or_in_a_worker(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("VIBROIMPACT_WORKER", raising=False)
    assert _continued(monkeypatch, io.StringIO()) == ""
    with quiet_calls():
        assert _continued(monkeypatch, _Terminal()) == ""
    monkeypatch.setenv("VIBROIMPACT_WORKER", "1")
    assert _continued(monkeypatch, _Terminal()) == ""
