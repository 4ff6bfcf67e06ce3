"""Scenes bounded before they are read (issue 34, items 6 and 8): a "bytes bomb" (one long string repeated by
aliases, under the alias-count limit) is refused at once without formatting it, and a name too long for the files
a run writes is refused by the checker, not by the file system mid-run."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from tests.run_study_process import study_environment
from tests.scene.test_scene import PAPER_SYSTEM_SPEC
from vibroimpact.scene.header import MAX_NAME_LENGTH
from vibroimpact.scene.reader import MAX_EXPANDED_CHARACTERS, MAX_EXPANDED_NODES


def _run_study(scene: Path) -> subprocess.CompletedProcess[str]:
    """run-study on ``scene``; its deadline fails a test that hangs (before: a bytes bomb's MemoryError after 45-141 s)."""
    return subprocess.run([sys.executable, "-m", "vibroimpact.cli", str(scene), "--out", "out"], cwd=scene.parent, env=study_environment(),
                          capture_output=True, text=True, timeout=60)  # fmt: skip


@pytest.mark.faults
@pytest.mark.timeout(120)
@pytest.mark.parametrize("where", ["name: &a", "excitation: {amplitude: &a"])
def test_a_bytes_bomb_is_refused_at_once_in_one_short_message(tmp_path: Path, where: str) -> None:
    aliases = 90_000
    assert aliases < MAX_EXPANDED_NODES and aliases * 200_000 > 1000 * MAX_EXPANDED_CHARACTERS  # the alias count alone passes
    closing = "}" if "{" in where else ""
    scene = tmp_path / "bomb.yaml"
    scene.write_text(f"{where} {'7' * 200_000}{closing}\nextra: [{', '.join(['*a'] * aliases)}]\n", encoding="utf-8")
    done = _run_study(scene)
    assert done.returncode == 2, done.stderr[-2000:]
    assert f"more than {MAX_EXPANDED_CHARACTERS} characters once its aliases are expanded" in done.stderr
    assert len(done.stderr) < 1000 and "Traceback" not in done.stderr and "MemoryError" not in done.stderr
    assert not (tmp_path / "out").exists()


@pytest.mark.faults
@pytest.mark.timeout(120)
def test_a_name_too_long_for_the_run_s_files_is_refused_by_the_checker(tmp_path: Path) -> None:
    import yaml

    document = {"name": "a" * 300, "system": dict(PAPER_SYSTEM_SPEC), "excitation": {"amplitude": 10.0}, "stop": {"clearance": 0.003, "restitution": 0.5},
                "sweep": {"frequency": [20.0, 25.0]}, "solutions": ["linear", "pgf"], "report": False}  # fmt: skip
    scene = tmp_path / "long.yaml"
    scene.write_text(yaml.safe_dump(document), encoding="utf-8")
    done = _run_study(scene)
    assert done.returncode == 2, done.stderr
    assert f"name: expected a file-name-safe string of at most {MAX_NAME_LENGTH} characters" in done.stderr
    assert "Traceback" not in done.stderr and not (tmp_path / "out").exists()
    document["name"] = "a" * MAX_NAME_LENGTH  # the longest allowed name runs to its files
    scene.write_text(yaml.safe_dump(document), encoding="utf-8")
    done = _run_study(scene)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "out" / f"{'a' * MAX_NAME_LENGTH}.nc").is_file()
