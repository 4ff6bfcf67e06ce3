"""Figures rendered in processes (``rendering(jobs)``): the page draws its next figures while earlier ones render, and
the files written as the context ends are the ones this process would have written."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from vibroimpact.reporting.page import DrawnFigure, rendering, saved
from vibroimpact.reporting.style import finish_axes, new_figure


def _drawn(name: str, slope: float) -> DrawnFigure:
    fig, axes = new_figure(2)
    x = np.linspace(1.0, 10.0, 200)
    for k, ax in enumerate(axes):
        ax.plot(x, np.exp(slope * (k + 1) * x), label=f"panel {k}")
        finish_axes(ax, "x [-]", "y [-]", f"panel {k}", log=True)
    return DrawnFigure(fig, name, f"figure {name}", "what is drawn")


def test_figures_handed_to_renderers_are_written_when_the_context_ends_as_drawn_here(tmp_path: Path) -> None:
    here, there = tmp_path / "here", tmp_path / "there"
    here.mkdir()
    there.mkdir()
    serial = saved([_drawn("a", 0.3), None, _drawn("b", -0.5)], here)
    with rendering(2):
        first = saved([_drawn("a", 0.3)], there)
        assert not (there / "a.png").exists()  # saved returned at once: the page goes on drawing
        second = saved([None, _drawn("b", -0.5)], there)
    records = first + second
    assert [record.path.name for record in records] == ["a.png", "b.png"] == [record.path.name for record in serial]
    assert [(record.title, record.caption) for record in records] == [(record.title, record.caption) for record in serial]
    for record in serial:
        assert (there / record.path.name).read_bytes() == record.path.read_bytes()


def test_log_axes_have_minor_ticks_at_2_and_5_per_decade() -> None:
    from vibroimpact.reporting.style import thin_minor_log_ticks

    drawn = _drawn("c", 0.3)
    thin_minor_log_ticks(drawn.figure)
    for ax in drawn.figure.axes:
        ax.set_ylim(1.0, 1e4)
        minor = ax.yaxis.get_minorticklocs()
        minor = minor[(minor >= 1.0) & (minor <= 1e4)]
        leading = np.round(minor / 10.0 ** np.floor(np.log10(minor)), 9)
        assert set(leading) == {2.0, 5.0} and minor.size == 8, minor  # 4 decades
        assert ax.xaxis.get_scale() == "linear" and ax.xaxis.get_minorticklocs().size == 0
