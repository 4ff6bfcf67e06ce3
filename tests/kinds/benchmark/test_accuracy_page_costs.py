"""The benchmark page's per-period tables: exact against its floor, exact_python and momentary, one row per case; the
bumper's integrators against its closed form, and the tolerance guidance the page opens with."""

from __future__ import annotations

import re
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import xarray as xr

from vibroimpact.kinds.benchmark.study import run_benchmark
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import TwoDofSystem
from vibroimpact.kinds.benchmark.page import AccuracyPage, accuracy_tables, bumper_answer, bumper_table, per_period_table
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


def _bumper_dataset() -> xr.Dataset:
    """A benchmark of the bumper (made up): two integrators and the closed form on one case of 50 periods."""
    engines, rtol = ["compliant_ida", "compliant_cvode_adams", "compliant_exact"], [1e-4, 1e-6, 1e-8, 1e-10]
    dims = ("case", "engine", "rtol")
    error = np.array([[[1e-3, 1e-5, 4e-7, 1e-9], [1e-4, 9e-7, 2e-7, 1e-9], [0.0] * 4]])
    wall = np.array([[[0.1, 0.2, 0.4, 0.8], [0.05, 0.1, 0.2, 0.4], [1e-3] * 4]])
    missed = np.zeros_like(wall)
    missed[0, 1, 1] = 1.0  # CVODE Adams at 1e-6 misses a contact: its guidance is 1e-8
    periods = np.array([50.0])
    return xr.Dataset(
        {
            "wall_time": (dims, wall), "x1_error": (dims, error), "missed_impacts": (dims, missed), "extra_impacts": (dims, np.zeros_like(wall)),
            "time_per_period": (dims, wall / 50.0), "periods": ("case", periods),
            "reference_wall_time": (("case", "reference"), np.array([[0.05, 2e-3, np.nan]])),
        },
        coords={"case": ["bump"], "engine": engines, "rtol": rtol, "reference": ["exact", "compliant_exact", "compliant_cvode_adams"]},
        attrs={"tolerance_free_engines": "compliant_exact", "case_bump_bumper_frequency_Hz": "1000"},
    )


def test_page_states_the_bumper_tolerance_guidance() -> None:
    """The page's answer for the bumper: each integrator's loosest rtol within 1e-6 of the closed form (every tighter
    one too, no contact missed), its cost per period there, and the closed form's, with the ratio to the cheapest."""
    text = bumper_answer(_bumper_dataset())
    assert "bump</b> (Omega_b / 2 pi = 1000 Hz)" in text
    assert "compliant_ida from rtol 1e-08 at 8 ms per period" in text  # 0.4 s / 50 periods; 1e-6 is 1e-5 off
    assert "compliant_cvode_adams from rtol 1e-08 at 4 ms per period" in text  # 1e-6 missed a contact
    # the closed form's own row (1 ms / 50 periods = 20 us), 200x cheaper than CVODE Adams's 4 ms
    assert "compliant_exact, without tolerance, 20 us per period, 200x cheaper than the cheapest of them" in text
    table = bumper_table(_bumper_dataset())
    assert "<td>4.0e-07</td><td>8</td>" in table and "<td>9.0e-07 *</td>" in table and "*: contacts missed or extra" in table
    assert "the reference, no tolerance: 20 us per period" in table
    assert bumper_answer(benchmark_dataset()) == ""  # a dataset without the bumper's closed form: no claim


def test_a_closed_form_dearer_than_an_integrator_is_not_called_cheaper() -> None:
    """The golden accuracy_cost page said '4e+03 us per period, 0.025x cheaper than the cheapest of them' (a factor
    below 1 called a saving): a closed form 40 times dearer is said the other way round."""
    data = _bumper_dataset()
    data["wall_time"].loc[{"engine": "compliant_exact"}] = 8.0
    data["time_per_period"].loc[{"engine": "compliant_exact"}] = 8.0 / 50.0  # 160 ms per period against CVODE Adams's 4 ms
    text = bumper_answer(data)
    assert "compliant_exact, without tolerance, 1.6e+05 us per period, 40x the cost of the cheapest of them" in text and "cheaper" not in text
