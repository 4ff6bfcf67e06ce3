"""The bifurcation page renders every figure and the special points' table."""

from __future__ import annotations

from pathlib import Path

import pytest
import xarray as xr

from vibroimpact.reporting.bifurcation_page import BifurcationPage
from vibroimpact.reporting.report import page_for, write_report
from vibroimpact.scene import parse_scene
from vibroimpact.study.run import run_study
from tests.study.test_bifurcation import SMALL


@pytest.fixture(scope="module")
def dataset() -> xr.Dataset:
    return run_study(parse_scene(SMALL), progress=None)


def test_the_report_has_every_figure(dataset: xr.Dataset, tmp_path: Path) -> None:
    assert isinstance(page_for(dataset), BifurcationPage)
    html = write_report(dataset, tmp_path).read_text(encoding="utf-8")
    names = {p.stem for p in tmp_path.glob("*.png")}
    assert names == {"bifurcation_R0", "multipliers_R0", "chart"}
    assert html.count("<figure") == 3 and "Special points" in html and "neimark-sacker" in html
    assert "Two-parameter chart" in html and "brute-force" in html
