"""The stepped page on layouts other than the paper's: one curve per coordinate and per stop, captions that say
which, the layout in words."""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
import pytest
import xarray as xr

from vibroimpact.reporting import page as page_module
from vibroimpact.grids.sections import structure_figure
from vibroimpact.kinds.stepped.figures import response_panels_figure
from vibroimpact.kinds.stepped.page import FrequencyResponsePage, unswept_restitution
from vibroimpact.reporting.record import general_setting
from vibroimpact.reporting.page import page_for, write_report
from vibroimpact.kinds.stepped.responses import regime_figure
from vibroimpact.scene import parse_scene
from vibroimpact.runs.run import run_study

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
    drawn = structure_figure(general_setting(dataset), dataset["frequency"].values)
    gids = {line.get_gid() for ax in drawn.figure.axes for line in ax.get_lines()}
    assert {"linear:primary", "linear:absorber", "linear:stop0", "linear:stop1"} <= gids
    assert "absorber - primary >= -3 mm" in drawn.caption
    plt.close(drawn.figure)


def test_page_is_chosen_and_written(dataset: xr.Dataset, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A layout with two stops gets a panel per stop; the HTML says the layout in words and has the tables."""
    monkeypatch.setattr(page_module, "save_figure", quick_save)
    page = page_for(dataset)
    assert isinstance(page, FrequencyResponsePage)
    assert page.summary() == "solutions: linear, pgf; stops: absorber - primary <= 3 mm, R = 0.2; absorber - primary >= -3 mm, R = 0.2"
    titles = [s.title for s in page.sections(tmp_path)]
    assert titles == ["Largest responses", "Linear system", "Responses, every coordinate and stop"], "the primary/absorber chain has no named view"
    html = write_report(dataset, tmp_path).read_text(encoding="utf-8")
    assert "absorber - primary &gt;= -3 mm, R = 0.2" in html
    assert "impulse on stop 1 [N s]" in html


#: The 3-dof chain of the review: a lower absolute stop on x1 and a relative upper stop x3 - x2, their own clearances
#: and restitutions, a constant force that moves the static equilibrium.
CHAIN: dict[str, Any] = {
    "name": "chain_page",
    "system": {
        "mass": [[1.0, 0.0, 0.0], [0.0, 0.5, 0.0], [0.0, 0.0, 0.2]],
        "stiffness": [[3000.0, -1500.0, 0.0], [-1500.0, 3000.0, -1500.0], [0.0, -1500.0, 1500.0]],
        "damping": [[0.6, -0.2, 0.0], [-0.2, 0.6, -0.2], [0.0, -0.2, 0.2]],
        "coordinates": ["x1", "x2", "x3"],
    },
    "excitation": {"amplitude": 1.0, "on": "x2", "static": [0.0, 0.0, 0.6]},
    "stops": [
        {"coordinate": "x1", "side": "lower", "clearance": 0.002, "restitution": 0.5},
        {"between": ["x3", "x2"], "side": "upper", "clearance": 0.001, "restitution": 0.3},
    ],
    "sweep": {"frequency": {"start": 2.0, "stop": 15.0, "step": 0.5}},
    "solutions": ["linear"],
}


def test_one_gap_line_per_stop_at_the_static_gap() -> None:
    """Each stop gets a dotted line in its colour at Delta_k - n_k . x_static, x_static = K^-1 F0 solved by hand: the
    chain is three 1500 N/m springs in series from the ground, so 0.6 N on x3 stretches each by 0.6 / 1500 m
    (n_0 . x = -x1, n_1 . x = x3 - x2)."""
    data = run_study(parse_scene(copy.deepcopy(CHAIN)), progress=None)
    setting = general_setting(data)
    np.testing.assert_allclose(setting.clearances, [0.002, 0.001], rtol=1e-12)
    # springs in series: x1 = F/k1 with k1 = 1500 (ground to x1), x2 = x1 + F/1500, x3 = x2 + F/1500
    x_static = 0.6 / 1500.0 * np.array([1.0, 2.0, 3.0])
    expected = {"gap:stop0": 0.002 + x_static[0], "gap:stop1": 0.001 - (x_static[2] - x_static[1])}
    drawn = structure_figure(setting, data["frequency"].values)
    lines = {line.get_gid(): line for line in drawn.figure.axes[1].get_lines() if str(line.get_gid()).startswith("gap:")}
    assert set(lines) == set(expected)
    for gid, gap in expected.items():
        assert abs(float(lines[gid].get_ydata()[0]) - 1e3 * gap) < 1e-9  # drawn in mm
        assert lines[gid].get_linestyle() == ":"
    colours = {line.get_gid(): line.get_color() for line in drawn.figure.axes[1].get_lines()}
    assert colours["gap:stop0"] == colours["linear:stop0"] and colours["gap:stop1"] == colours["linear:stop1"]
    assert "Delta - n . x_static (x_static = K^-1 F0)" in drawn.caption
    plt.close(drawn.figure)


def test_swept_clearance_has_no_line_and_says_so() -> None:
    """A stop whose clearance the grid sweeps gets no line; the other keeps its own; the caption names the first."""
    scene = copy.deepcopy(CHAIN)
    del scene["stops"][1]["clearance"]
    scene["excitation"].pop("static")
    scene["sweep"].update({"clearance": [0.001, 0.0015], "stop": 1})
    data = run_study(parse_scene(scene), progress=None)
    drawn = structure_figure(general_setting(data), data["frequency"].values)
    gids = [line.get_gid() for line in drawn.figure.axes[1].get_lines() if str(line.get_gid()).startswith("gap:")]
    assert gids == ["gap:stop0"]
    assert "No line for stop 1: its clearance is swept" in drawn.caption
    plt.close(drawn.figure)


def test_unswept_restitution_is_not_named(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Stops with their own R, none swept: no figure or caption of the page speaks of one series per R."""
    monkeypatch.setattr(page_module, "save_figure", quick_save)
    data = run_study(parse_scene(copy.deepcopy(CHAIN)), progress=None)
    assert "restitution" not in data.coords
    page = FrequencyResponsePage(data)
    for section in page.sections(tmp_path):
        for figure in section.figures:
            assert "per restitution ratio" not in figure.caption
    shared = regime_figure(data, "regime")
    assert "each stop's R" in [t.get_text() for t in shared.figure.axes[0].get_yticklabels()]
    drawn = unswept_restitution(shared, data)
    assert drawn is not None
    texts = [t.get_text() for ax in drawn.figure.axes for t in [ax.title, *ax.get_yticklabels()]]
    assert "each stop's R" not in texts
    plt.close(drawn.figure)
