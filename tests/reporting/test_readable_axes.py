"""Figures by rule (issue 51): no offset or multiplier text over a title, readable log axes, a log scale only over a
decade, and one y range for the design panels meant to be compared."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from vibroimpact.reporting.style import plain_log, readable_axes, readable_scale, thin_minor_log_ticks

GOLDEN = Path(__file__).resolve().parents[1] / "golden" / "data"


def _labels(axis: object) -> list[str]:
    figure = axis.axes.figure  # type: ignore[attr-defined]
    figure.canvas.draw()
    return [label.get_text() for label in axis.get_ticklabels(which="both") if label.get_text() and label.get_visible()]  # type: ignore[attr-defined]


def test_a_stiffness_axis_has_no_offset_text_over_the_title() -> None:
    figure, ax = plt.subplots()
    ax.plot([2.0e6, 2.5e6, 3.0e6], [1.0, 2.0, 3.0])
    ax.set_title("worst case over K_b")
    figure.canvas.draw()
    assert ax.xaxis.get_offset_text().get_text() != ""  # matplotlib's own: "1e6" at the axis' end
    readable_axes(figure)
    figure.canvas.draw()
    assert ax.xaxis.get_offset_text().get_text() == "" and "2e+06" in _labels(ax.xaxis)
    plt.close(figure)


def test_a_log_axis_over_a_decade_labels_more_than_one_tick() -> None:
    figure, ax = plt.subplots()
    ax.plot([22.0, 28.0], [0.4, 4.6])
    ax.set_yscale("log")
    ax.set_ylim(0.4, 4.6)
    plain_log(ax)
    thin_minor_log_ticks(figure)
    assert {"0.5", "1", "2"} <= set(_labels(ax.yaxis))
    plt.close(figure)


def test_a_log_scale_only_over_a_decade_or_more() -> None:
    assert readable_scale(2.3, 5.0) == "linear" and readable_scale(0.3, 5.0) == "log" and readable_scale(0.0, 5.0) == "linear"


def test_the_design_panels_meant_to_be_compared_share_one_y_range() -> None:
    from vibroimpact.kinds.design.figures import response_figure
    from vibroimpact.runs.run import read_dataset

    drawn = response_figure(read_dataset(GOLDEN / "design_rigid_stop.nc"))
    panels = [ax for ax in drawn.figure.axes if ax.get_title().startswith(("Recommended design", "The scene's design", "Best linear absorber"))]
    assert len(panels) == 3 and len({ax.get_ylim() for ax in panels}) == 1
    overlay = next(ax for ax in drawn.figure.axes if ax.get_title().startswith("Worst stable motion"))
    assert overlay.get_yscale() == "linear" and "the first panel on a linear scale, the others on a log scale" in drawn.caption
    plt.close(drawn.figure)
