"""A run's failures are said: one line per kind of failure on the page right after its answer, the raw messages
collapsed at its end, and one console line (vibroimpact.runs.failures)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr

from vibroimpact.reporting.page import Section, with_failures
from vibroimpact.runs.failures import console_line, failure_details, run_failures
from vibroimpact.runs.run import read_dataset

GOLDEN = Path(__file__).parents[1] / "golden" / "data"


def _with_failed_points(count: int) -> xr.Dataset:
    """The golden restitution dataset with ``count`` of the exact engine's simulated points marked failed."""
    dataset = read_dataset(GOLDEN / "restitution.nc")
    regime = dataset["regime"]
    meanings = regime.attrs["flag_meanings"].split()
    failed = regime.attrs["flag_values"][meanings.index("failed")]
    not_computed = regime.attrs["flag_values"][meanings.index("not_computed")]
    exact = regime.sel(solution="exact").values
    where = np.argwhere(exact != not_computed)[:count]
    values = regime.values.copy()
    position = list(dataset["solution"].values).index("exact")
    for r, f in where:
        values[position, r, f] = failed
    return dataset.assign(regime=regime.copy(data=values))


def test_failed_points_are_counted_per_solution_against_the_points_it_computed() -> None:
    clean = read_dataset(GOLDEN / "restitution.nc")
    assert run_failures(clean) == []
    dataset = _with_failed_points(3)
    exact = dataset["regime"].sel(solution="exact")
    computed = int((exact != -1).sum())
    lines = run_failures(dataset)
    assert len(lines) == 1
    assert f"exact: 3 of {computed} points failed (regime = failed)" in lines[0]
    assert "blank (NaN)" in lines[0] and "others are unaffected" in lines[0]
    assert "pgf" not in lines[0], "a solution without failures is not named"


def test_a_kinds_own_lines_and_details_come_first_and_survive_netcdf(tmp_path: Path) -> None:
    from vibroimpact.runs.run import write_dataset

    dataset = _with_failed_points(1).assign_attrs(
        run_failures=["shooting from 2 of 9 seeds failed; those branches are missing, the others are unaffected"],
        run_failure_details=["ShootingError: the map returned a non-finite state", "ShootingError: no convergence"],
    )
    read = read_dataset(write_dataset(dataset, tmp_path / "d.nc"))
    lines = run_failures(read)
    assert lines[0].startswith("shooting from 2 of 9 seeds failed") and "exact: 1 of" in lines[1]
    assert failure_details(read) == ["ShootingError: the map returned a non-finite state", "ShootingError: no convergence"]
    line = console_line(lines, "out/report.html")
    assert "\n" not in line and line.startswith("warning: the run finished with failures: shooting from 2 of 9")
    assert "(and 1 more kinds of failure)" in line and line.endswith("details in out/report.html")
    assert console_line([]) == ""


def test_the_page_says_what_failed_right_after_its_answer_and_collapses_the_details() -> None:
    sections = [Section("Answer"), Section("Figures"), Section("Logs")]
    assert with_failures(sections, [], ["x"]) == sections
    out = with_failures(sections, ["exact: 3 of 20 points failed"], ["RuntimeError: boom <b>"])
    assert [section.title for section in out] == ["Answer", "What failed in this run", "Figures", "Logs", "Failure details"]
    assert "exact: 3 of 20 points failed" in out[1].intro
    assert out[-1].intro.startswith("<details>") and "RuntimeError: boom &lt;b&gt;" in out[-1].intro
