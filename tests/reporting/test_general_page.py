"""The page of a general study: one curve per coordinate and per stop, captions that say which, the layout in words."""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
import pytest
import xarray as xr

from vibroimpact.reporting import page as page_module
from vibroimpact.reporting.general_figures import response_panels_figure, structure_figure
from vibroimpact.reporting.general_page import GeneralResponsePage
from vibroimpact.reporting.general_record import general_setting
from vibroimpact.reporting.report import page_for, write_report
from vibroimpact.scene import parse_scene
from vibroimpact.study.run import run_study

from tests.reporting.test_report_pages import quick_save

SCENE: dict[str, Any] = {
    "name": "relative_page",
    "system": {"mass": [[1.0, 0.0], [0.0, 0.1]], "stiffness": [[29300.0, -4300.0], [-4300.0, 4300.0]], "damping": [[0.88, -0.08], [-0.08, 0.08]], "coordinates": ["primary", "absorber"]},
    "excitation": {"amplitude": 10.0, "on": "primary"},
    "stops": [
        {"between": ["absorber", "primary"], "side": "upper", "clearance": 0.003, "restitution": 0.2},
        {"between": ["absorber", "primary"], "side": "lower", "clearance": 0.003, "restitution": 0.2},
    ],
    "sweep": {"frequency": {"start": 20.0, "stop": 40.0, "step": 0.5}},
    "solutions": ["linear", "pgf"],
}


@pytest.fixture(scope="module")
def dataset() -> xr.Dataset:
    return run_study(parse_scene(copy.deepcopy(SCENE)), progress=None)


def test_setting_is_rebuilt_from_the_attributes(dataset: xr.Dataset) -> None:
    """The structure, load and stops come back from the dataset alone."""
    setting = general_setting(dataset)
    assert setting.names == ("primary", "absorber")
    np.testing.assert_allclose(setting.structure.stiffness_matrix, SCENE["system"]["stiffness"], rtol=0)
    np.testing.assert_allclose(setting.normals, [[-1.0, 1.0], [1.0, -1.0]], rtol=0)
    assert setting.stops == ("absorber - primary <= 3 mm, R = 0.2", "absorber - primary >= -3 mm, R = 0.2")
    assert setting.load_text() == "harmonic force of amplitude 10 N on primary"


def test_one_panel_per_coordinate_and_per_stop(dataset: xr.Dataset) -> None:
    """Panels: each coordinate's amplitude, the force on the base, the impulse on each stop; titles say which."""
    drawn = response_panels_figure(dataset, general_setting(dataset), "responses")
    assert drawn is not None
    titles = [ax.get_title() for ax in drawn.figure.axes]
    assert titles == ["coordinate primary", "coordinate absorber", "force on the base", "impulse on stop 0: absorber - primary <= 3 mm", "impulse on stop 1: absorber - primary >= -3 mm"]
    assert "absorber - primary <= 3 mm, R = 0.2; absorber - primary >= -3 mm, R = 0.2" in drawn.caption
    for ax in drawn.figure.axes[:2]:
        assert {line.get_gid() for line in ax.get_lines()} >= {"linear", "pgf"}
    plt.close(drawn.figure)


def test_structure_figure_draws_every_coordinate_and_stop(dataset: xr.Dataset) -> None:
    """The linear figure has a curve per coordinate and per stop, and names the stops in its caption."""
    drawn = structure_figure(general_setting(dataset), dataset["frequency"].values, np.array([0.003]))
    gids = {line.get_gid() for ax in drawn.figure.axes for line in ax.get_lines()}
    assert {"linear:primary", "linear:absorber", "linear:stop0", "linear:stop1"} <= gids
    assert "absorber - primary >= -3 mm" in drawn.caption
    plt.close(drawn.figure)


def test_page_is_chosen_and_written(dataset: xr.Dataset, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A general dataset gets the general page; the HTML says the layout in words and has the tables."""
    monkeypatch.setattr(page_module, "save_figure", quick_save)
    page = page_for(dataset)
    assert isinstance(page, GeneralResponsePage)
    assert page.summary() == "solutions: linear, pgf; stops: absorber - primary <= 3 mm, R = 0.2; absorber - primary >= -3 mm, R = 0.2"
    titles = [s.title for s in page.sections(tmp_path)]
    assert titles == ["Structure and stops", "Responses, every coordinate and stop", "Largest responses"]
    html = write_report(dataset, tmp_path).read_text(encoding="utf-8")
    assert "absorber - primary &gt;= -3 mm, R = 0.2" in html
    assert "impulse on stop 1 [N s]" in html
