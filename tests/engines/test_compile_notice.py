"""The first use of a compiled engine on a machine waits for numba (~30-60 s): a script on a terminal is told so in
one line, once per engine and process (issue 51: the first ``steady_state('compliant_exact', ...)`` waited 7 s
without a word), and the figure is the one the package states everywhere (FIRST_COMPILE_TIME)."""

from __future__ import annotations

import io

import pytest

from vibroimpact.engines import registry
from vibroimpact.engines.registry import FIRST_COMPILE_TIME, EngineSpec, compile_notice, make_engine


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


@pytest.mark.parametrize("cached, terminal, said", [(False, True, 1), (True, True, 0), (False, False, 0)])
def test_an_engine_compiled_on_first_use_says_so_once_on_a_terminal(monkeypatch: pytest.MonkeyPatch, cached: bool, terminal: bool, said: int) -> None:
    stream = _Terminal() if terminal else io.StringIO()
    monkeypatch.setattr(registry.sys, "stderr", stream)
    monkeypatch.setattr(registry, "_ANNOUNCED", set())
    monkeypatch.setattr(EngineSpec, "kernels_cached", lambda self, batched=False: cached)
    make_engine("exact")
    make_engine("exact")  # the second says nothing more
    make_engine("momentary")  # nothing to compile (CVODE)
    assert stream.getvalue().count("\n") == said
    if said:
        assert stream.getvalue() == compile_notice("exact") + "\n" and FIRST_COMPILE_TIME in stream.getvalue()


def test_the_readme_and_the_run_state_the_one_compile_time() -> None:
    from pathlib import Path

    readme = (Path(__file__).resolve().parents[2] / "README.md").read_text()
    assert f"compiles it ({FIRST_COMPILE_TIME} once" in " ".join(readme.split())
