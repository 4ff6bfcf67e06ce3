"""The design page states the recommended design at the absorber's operating point against the same absorber
without its stop, and warns first where the stop makes it worse or the absorber's free motion there does not fit."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from vibroimpact.analysis.linear import linear_response
from vibroimpact.kinds.design.operating import design_operating, operating_warnings
from vibroimpact.kinds.design.page import DesignPage
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.reporting.style import fmt

from tests.golden.golden import DATA
from tests.reporting.test_report_pages import quick_save


@pytest.fixture(scope="module")
def dataset() -> xr.Dataset:
    with xr.open_dataset(DATA / "design_rigid_stop.nc") as data:
        return data.load()


def test_the_declared_operating_point_against_the_same_absorber_without_its_stop(dataset: xr.Dataset) -> None:
    """33 Hz is declared: with the stop, the search's worst coexisting |X1| there; without, |q H11| of the paper's
    absorber (the design varies only the stop); the recommended clearance holds the free motion |q H12|."""
    point = design_operating(dataset)
    assert point is not None and point.declared and point.frequency == pytest.approx(33.0, rel=1e-12)
    linear = linear_response(PAPER_SYSTEM, 33.0, 10.0)
    assert point.linear == pytest.approx(float(np.abs(linear.coordinate("x1"))), rel=1e-12)
    assert point.free == pytest.approx(float(np.abs(linear.coordinate("x2"))), rel=1e-12)
    assert point.stopped == pytest.approx(float(dataset["design_operating_amplitude"].values[0]), rel=1e-12)
    assert operating_warnings(point) == []


def test_a_stop_that_destroys_the_notch_is_said_before_the_recommendation(dataset: xr.Dataset, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A recommended 1 mm stop whose |X1| at 33 Hz is 100 times the linear absorber's: the page's first lines say so
    with the two numbers and the factor, and that the 2.32 mm free motion does not fit in 1 mm."""
    worse = dataset.copy(deep=True)
    worse["design_operating_amplitude"].values[0] *= 100.0
    worse["design_clearance"].values[0] = 0.001
    point = design_operating(worse)
    assert point is not None and point.ratio == pytest.approx(100.0, rel=1e-9)
    monkeypatch.setattr("vibroimpact.reporting.page.save_figure", quick_save)
    for name in ("design_figures", "method_text", "certificates_table"):  # the golden file keeps no wall times: only the answer is read here
        monkeypatch.setattr(f"vibroimpact.kinds.design.page.{name}", lambda _d, empty=([] if name == "design_figures" else ""): empty)
    intro = DesignPage(worse).sections(tmp_path)[0].intro
    first, second = intro.split("</p>")[:2]
    assert first.startswith("<p><b>Warning.</b> The recommended stop makes the absorber worse at its operating point")
    assert f"{fmt(1e3 * point.linear, '.4g')} mm without the stop" in first and f"{fmt(1e3 * point.stopped, '.4g')} mm with it, ×100" in first
    assert "does not fit in the recommended gap" in second and "against a clearance of 1 mm" in second
    assert intro.index("No design found in these bounds keeps the operating limit") > intro.index("Warning.")  # 100 x 0.009 mm breaks the 0.05 mm limit
    assert math.isfinite(point.free) and point.free > 0.002


def test_the_design_and_stepped_pages_judge_worse_alike() -> None:
    from vibroimpact.kinds.design import operating as design
    from vibroimpact.kinds.stepped import operating as stepped

    from vibroimpact.measures import figures_of_merit

    for kind in (design, stepped):  # one declaration, read by both kinds: not copies held equal
        assert kind.WORSE_RATIO is figures_of_merit.WORSE_RATIO and kind.NEAREST is figures_of_merit.NEAREST


def test_a_design_above_the_operating_limit_is_never_called_recommended(dataset: xr.Dataset) -> None:
    """Issue 51: with no design keeping the notch, the search map's and the trade-off's star marked a design 'the
    recommended design' that the answer calls only the best found (the least penalised score). The title, read by
    every legend, table and figure title, now says what the answer says."""
    from vibroimpact.kinds.design.answer import answer_text, design_titles
    from vibroimpact.kinds.design.quantity import operating_limit

    assert design_titles(dataset)[0] == "recommended design"  # the golden design keeps its 0.05 mm limit
    worse = dataset.copy(deep=True)
    worse["design_operating_amplitude"].values[0] = 2.0 * operating_limit(dataset)
    assert design_titles(worse)[0] == "best found (above the operating limit)"
    assert answer_text(worse).startswith("No design found in these bounds keeps the operating limit") and "the best found" in answer_text(worse)
