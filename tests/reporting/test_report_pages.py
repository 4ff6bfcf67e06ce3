"""Report pages: tables count only what a solution was asked to compute, every page has contents linking every
section, figure and table, and a page explains only the tables it shows."""

from __future__ import annotations

import html
import re
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pytest

from vibroimpact.kinds.stepped.tables import DEFINITION
from vibroimpact.analysis.stability import Regime
from vibroimpact.reporting import page as page_module
from vibroimpact.reporting.page import page_for
from vibroimpact.reporting.page import DrawnFigure, Figure, Section, Table, render_page, save_figure
from vibroimpact.reporting.record import general_setting
from vibroimpact.kinds.stepped.tables import reduction_tables

from tests.reporting.test_report_support import setting_of, steady_dataset, swept_dataset


def _rows(table_html: str) -> list[list[str]]:
    """Cells of each row of an HTML table (header first)."""
    return [re.findall(r"<t[hd]>(.*?)</t[hd]>", row) for row in re.findall(r"<tr>(.*?)</tr>", table_html)]


def _pair(cell: str) -> tuple[int, int]:
    first, second = cell.split(" / ")
    return int(first), int(second)


def test_undefined_points_are_computed_points_without_a_value() -> None:
    """Points a simulation never ran (regime not_computed, 90 % here) are not counted as undefined."""
    ds = steady_dataset()
    setting = setting_of(ds)
    split = setting.system.antiresonance_angular_frequency() / (2.0 * np.pi)
    bands = (ds["frequency"].values < split, ds["frequency"].values >= split)
    table = next(t for t in reduction_tables(ds, general_setting(ds), True) if "|X1|" in t.title)
    header, *rows = _rows(table.html)
    column = {name: i for i, name in enumerate(header)}
    checked = 0
    for row in rows:
        solution, r = row[column["solution"]], float(row[column["R"]])
        regime = ds["regime"].sel(solution=solution, restitution=r).values
        computed = regime != Regime.NOT_COMPUTED
        undefined = computed & np.isnan(ds["x1_amplitude"].sel(solution=solution, restitution=r).values)
        assert _pair(row[column["computed points 1 / 2"]]) == tuple(int(np.sum(computed & b)) for b in bands), (solution, r)
        assert _pair(row[column["undefined points 1 / 2"]]) == tuple(int(np.sum(undefined & b)) for b in bands), (solution, r)
        if solution == "momentary":
            assert _pair(row[column["undefined points 1 / 2"]]) == (1, 0)  # the one failed point, at 30 Hz
            checked += 1
    assert checked == ds.sizes["restitution"]


def test_contents_link_every_section_figure_and_table(tmp_path: Path) -> None:
    fig, ax = plt.subplots(figsize=(2, 1))
    ax.plot([0, 1], [0, 1])
    figure = save_figure(DrawnFigure(fig, "a_figure", "A figure", "Its caption."), tmp_path)
    sections = [Section("First part", figures=[figure], tables=[Table("A table", "<table></table>"), Table("A table", "<p>same title</p>")]), Section("Second part")]
    page = render_page("Title", ["intro"], sections, "name: x")
    nav = page.split("<nav id='contents'>")[1].split("</nav>")[0]
    links = re.findall(r"href='#([^']+)'", nav)
    ids = re.findall(r" id='([^']+)'", page.split("</nav>")[1])
    assert len(ids) == len(set(ids)), "anchors are unique"
    assert sorted(links) == sorted(ids), "every section, figure and table is in the contents, and every link lands"
    assert len(links) == 2 + 1 + 2 + 1  # two sections, a figure, two tables, the scene


def quick_save(drawn: DrawnFigure, out_dir: Path) -> Figure:
    """Stands in for the PNG writer where only the page's composition is tested (rendering PNGs takes seconds)."""
    plt.close(drawn.figure)
    path = Path(out_dir) / f"{drawn.name}.png"
    path.write_bytes(b"")
    return Figure(path, drawn.title, drawn.caption)


def test_sweep_page_has_contents_and_explains_only_what_it_shows(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(page_module, "save_figure", quick_save)
    ds = swept_dataset()
    sections = page_for(ds).sections(tmp_path)
    page = render_page("sweep", [], sections, ds.attrs["scene"])
    titles = [s.title for s in sections]
    assert titles == ["Contacts and the steady states", "Linear system", "Swept sine against the steady states"]
    assert "<nav id='contents'>" in page
    for name in ("sweep_displacements.png", "sweep_force_impulse.png", "sweep_regime.png", "sweep_time.png", "Cost of the swept-sine runs", "Swept sine against the stable pgf steady state"):
        assert name in page, name
    assert html.escape(DEFINITION[1:60]) not in page and "Reduction factors" not in page, "no reduction-factor table, so no explanation of one"


@pytest.mark.parametrize("name", ["relative_stop", "base_motion_frame", "restitution", "clearance_peaks"])
def test_the_general_setting_is_the_recorded_layout(name: str) -> None:
    """A page's setting takes the load and the stops' directions from the layout the dataset records (one reader,
    Layout.from_attributes): the recorded weights and constant force, and the normals a problem of that layout has."""
    import xarray as xr

    from vibroimpact.model.layout import Layout

    from tests.golden.golden import DATA

    with xr.open_dataset(DATA / f"{name}.nc") as dataset:
        setting = general_setting(dataset)
        attrs = dict(dataset.attrs)
    layout = Layout.from_attributes(attrs)
    if "excitation_weights" in attrs:
        np.testing.assert_array_equal(setting.weights, np.atleast_1d(attrs["excitation_weights"]))  # exact: read back as written
        np.testing.assert_array_equal(setting.static, np.atleast_1d(attrs["excitation_static_N"]))  # exact: read back as written
    np.testing.assert_array_equal(setting.normals, layout.problem(1.0, 10.0, 0.5, 0.003).normals())  # exact: signs
    assert setting.base_motion is (name == "base_motion_frame")
    if name == "base_motion_frame":  # the absorber's two-sided stop relative to floor2
        np.testing.assert_array_equal(setting.normals, [[0.0, -1.0, 1.0], [0.0, 1.0, -1.0]])  # exact: signs
