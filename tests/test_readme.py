"""The README's promises: two set-up commands, CI running the second one, and a quick start that runs."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def readme_commands() -> list[str]:
    blocks = re.findall(r"```bash\n(.*?)```", (ROOT / "README.md").read_text(), flags=re.S)
    return [block.strip() for block in blocks]


def test_readme_starts_with_two_setup_commands() -> None:
    commands = readme_commands()
    assert len(commands) >= 2
    assert "run-study studies/restitution.yaml" in commands[0] and "pip install" in commands[0]
    assert "pytest" in commands[1] and "pip install" in commands[1]
    assert all("\n" not in command for command in commands[:2])


def test_ci_runs_the_readme_test_command() -> None:
    ci = (ROOT / ".ci" / "run").read_text().splitlines()
    assert readme_commands()[1] in ci


def test_readme_reduction_factors_are_what_the_study_gives() -> None:
    """The README's results table is recomputed here: change both together."""
    import yaml

    from vibroimpact.reporting.record import general_setting
    from vibroimpact.kinds.stepped.tables import reduction_factors
    from vibroimpact.scene import parse_scene
    from vibroimpact.runs.run import run_study

    document = yaml.safe_load((ROOT / "studies" / "restitution.yaml").read_text())
    document["solutions"] = [s for s in document["solutions"] if s in ("linear", "pgf", "pgf_paper")]  # the closed forms only
    document.pop("simulation")
    scene = parse_scene(document)
    dataset = run_study(scene, progress=None)
    readme = (ROOT / "README.md").read_text()

    def factors(quantity: str, solution: str) -> list[str]:
        row = next(r for r in reduction_factors(dataset, general_setting(dataset), quantity, solution) if r.restitution == 0.2)  # exact: a grid value
        return [f"{x:.1f}" for x in row.factor]

    for solution, label in (("pgf", "`pgf` (exact)"), ("pgf_paper", "`pgf_paper`")):
        expected = factors("x1_amplitude", solution) + factors("force_amplitude", solution)
        assert f"| {label} | {' | '.join(expected)} |" in readme


def test_every_file_and_test_the_readme_names_exists() -> None:
    """A path the README names (`simulation/steady.py`, `tests/model/test_system.py::test_x`) is there, and so is the
    test: after a move, the README cannot send a reader to a file that is gone."""
    text = (ROOT / "README.md").read_text()
    missing = []
    for path, test in re.findall(r"`([\w./-]+\.py)(?:::(\w+))?`", text):
        places = [ROOT / path] if path.startswith(("src/", "tests/")) else [ROOT / "src" / "vibroimpact" / path, ROOT / "tests" / path, ROOT / "tests" / "hard_cases" / path]
        found = next((place for place in places if place.is_file()), None)
        if found is None:
            missing.append(path)
        elif test and not re.search(rf"def {test}\(", found.read_text()):
            missing.append(f"{path}::{test}")
    assert not missing, f"the README names what is not there: {missing}"


def quick_start() -> tuple[int, str]:
    """The line number of the `## Quick start` heading and the first ```python block after it."""
    lines = (ROOT / "README.md").read_text().splitlines()
    heading = next(number for number, line in enumerate(lines, start=1) if line.strip() == "## Quick start")
    block = re.search(r"```python\n(.*?)```", "\n".join(lines[heading:]), flags=re.S)
    assert block is not None, "no ```python block after ## Quick start"
    return heading, block.group(1)


def test_readme_is_an_entry_not_a_manual() -> None:
    """A new user sees what it is, the set-up commands and the quick start on the first screens: the heading within
    the first 80 lines, one short example, and the whole README at most 500 lines."""
    heading, code = quick_start()
    assert heading <= 80, f"## Quick start is on line {heading}"
    lines = (ROOT / "README.md").read_text().splitlines()
    section = "\n".join(lines[heading:next((n for n, line in enumerate(lines[heading:], start=heading) if line.startswith("## ")), len(lines))])
    assert section.count("```python") == 1, "the quick start holds one python block"
    assert len(code.splitlines()) <= 25
    assert len((ROOT / "README.md").read_text().splitlines()) <= 500


@pytest.mark.timeout(600)
def test_quick_start_runs(tmp_path: Path) -> None:
    """The quick start's code runs as a user would paste it, in a fresh interpreter in an empty folder (the first run
    may compile the exact engine's numba core), and prints both of its results."""
    _, code = quick_start()
    env = {**os.environ, "MPLBACKEND": "Agg"}
    result = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=540)
    assert result.returncode == 0, result.stderr
    assert "closed form:" in result.stdout and "exact engine:" in result.stdout, result.stdout
    printed = result.stdout.splitlines()
    assert all(f"`{line}`" in (ROOT / "README.md").read_text(encoding="utf-8") for line in printed), printed  # what the README says it prints
    assert (tmp_path / "quick_start.png").stat().st_size > 10_000  # the time history's figure


def test_the_readme_ranges_are_the_checkers() -> None:
    """'Sweepable: `frequency` (required, > 0), `restitution` ([0, 1]), `clearance` (finite [m]; negative: a preload)':
    each stated range is what the scene checker accepts, at its edges."""
    from vibroimpact.scene import SceneError, parse_scene
    from tests.study.test_estimate import small_scene

    text = " ".join((ROOT / "README.md").read_text().split())
    assert "`frequency` (required, > 0), `restitution` ([0, 1]), `clearance` (finite [m]; negative: a preload)" in text

    def accepted(**sweep: object) -> bool:
        document = small_scene() | {"sweep": {"frequency": [25.0]} | sweep, "solutions": ["linear", "pgf"]}
        document["stop"] = {key: value for key, value in document["stop"].items() if key not in sweep}  # one place only
        document.pop("simulation", None)
        try:
            parse_scene(document)
        except SceneError:
            return False
        return True

    assert accepted(restitution=[0.0, 1.0]) and not accepted(restitution=[1.0001]) and not accepted(restitution=[-0.0001])
    assert accepted(frequency=[1e-3]) and not accepted(frequency=[0.0])
    assert accepted(clearance=[-0.001, 0.003]) and not accepted(clearance=[float("inf")])
