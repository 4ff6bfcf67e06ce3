"""Nothing a design study stored may exceed a number its answer states (:mod:`vibroimpact.kinds.design.consistency`):
every shipped design dataset is held to it, and a dataset made to contradict its answer gets a page that refuses it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from vibroimpact.kinds.design.answer import design_worst
from vibroimpact.kinds.design.consistency import contradictions
from vibroimpact.kinds.design.page import DesignPage

from tests.golden.golden import DATA
from tests.reporting.test_report_pages import quick_save

DESIGNS = ("design_rigid_stop", "design_paper", "design_vs_linear", "impact_damper")


@pytest.fixture(scope="module", params=DESIGNS)
def shipped(request: pytest.FixtureRequest) -> xr.Dataset:
    with xr.open_dataset(DATA / f"{request.param}.nc") as data:
        return data.load()


def test_no_stored_motion_exceeds_what_the_shipped_answers_state(shipped: xr.Dataset) -> None:
    assert contradictions(shipped, 0) == []
    assert contradictions(shipped, 1) == []  # the scene's own design, as the answer states it


def test_a_stored_motion_above_the_answer_refuses_it(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    with xr.open_dataset(DATA / "design_rigid_stop.nc") as data:
        d = data.load()
    recommended = int(d.attrs["recommended_evaluation"])
    rows = np.flatnonzero(d["certificate_evaluation"].values == recommended)
    assert rows.size
    stated = design_worst(d, 0)
    d["attractor_amplitude"].values[rows[0], 3] = 1.5 * stated  # a motion the brute force stored, above the answer
    found = contradictions(d)
    assert len(found) == 1 and "an attractor the brute force of sample" in found[0] and "exceeds the stated worst case" in found[0]
    operating = float(d["design_operating_amplitude"].values[0])
    d["sample_operating"].values[recommended, -1] = 2.0 * operating
    assert any("at the operating frequency under sample" in f for f in contradictions(d))
    monkeypatch.setattr("vibroimpact.reporting.page.save_figure", quick_save)
    for name in ("design_figures", "method_text", "certificates_table"):
        monkeypatch.setattr(f"vibroimpact.kinds.design.page.{name}", lambda _d, empty=([] if name == "design_figures" else ""): empty)
    intro = DesignPage(d).sections(tmp_path)[0].intro
    assert "No answer: what this study stored contradicts" in intro and "Build " not in intro
