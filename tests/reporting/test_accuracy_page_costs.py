"""The benchmark page's per-period table: exact against its floor, exact_python and momentary, one row per case."""

from __future__ import annotations

import re
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from vibroimpact.kinds.benchmark.study import run_benchmark
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import TwoDofSystem
from vibroimpact.kinds.benchmark.page import AccuracyPage, accuracy_tables, per_period_table
from vibroimpact.kinds.benchmark.scene import BenchmarkCase, BenchmarkSettings

from tests.conftest import PAPER_AMPLITUDE, PAPER_CLEARANCE
from tests.reporting.test_report_support import benchmark_dataset

TITLE = "Cost per period: the exact engine against its floor, the pure-Python loop and momentary"


def _cells(html: str) -> list[list[str]]:
    return [re.findall(r"<t[dh]>(.*?)</t[dh]>", row) for row in re.findall(r"<tr>(.*?)</tr>", html)]


def test_page_shows_the_per_period_table(system: TwoDofSystem, tmp_path: Path) -> None:
    cases = [BenchmarkCase(f"f{f:g}", ImpactProblem(system, RigidStop(PAPER_CLEARANCE, 0.2), HarmonicForce(PAPER_AMPLITUDE, f)), "rest", 8) for f in (25.0, 37.0)]
    settings = BenchmarkSettings(methods=("exact_python", "momentary_adams"), tolerances=(1e-6, 1e-8), repeats=1)
    data = run_benchmark(cases, settings, progress=False)
    sections = AccuracyPage(data).sections(tmp_path)
    plt.close("all")
    tables = {t.title: t.html for section in sections for t in section.tables}
    assert TITLE in tables and list(tables)[0] == TITLE
    rows = _cells(tables[TITLE])
    header, body = rows[0], rows[1:]
    assert [row[0] for row in body] == ["f25", "f37"]
    assert "exact_python / exact" in header and "exact / floor" in header and any("rtol 1e-08" in h for h in header)
    for row in body:
        assert all(cell for cell in row), row  # every cost and ratio measured
        assert row[-2].endswith("x") and row[-1].endswith("x")
        exact, floor = float(row[3]), float(row[4])
        ratio = float(row[-1].removesuffix("x"))  # printed to 0.01, from costs printed to 0.01 us
        assert abs(ratio - exact / floor) <= 0.006 + 0.005 * ratio
    assert "measured in one process run" in tables[TITLE]
    # an engine without a tolerance appears once among the points, with no rtol
    points = _cells(tables["Every point: f25"])
    assert [row[:2] for row in points if row[0] == "exact_python"] == [["exact_python", "none"]]


def test_old_datasets_have_no_per_period_table() -> None:
    """A benchmark dataset written before the per-period costs renders without the table; the table of a dataset
    without exact_python or a floor without moments leaves those cells empty."""
    titles = [table.title for table in accuracy_tables(benchmark_dataset())]
    assert TITLE not in titles and titles
    assert "<table>" in per_period_table(benchmark_dataset().assign(
        reference_time_per_period=("case", [1e-6, np.nan]), floor_time_per_period=("case", [5e-7, np.nan]), periods=("case", [10.0, np.nan]),
        time_per_period=(("case", "engine", "rtol"), np.full((2, 3, 4), 1e-5)),
    ))
