"""Figures by rule, as the pages' review found them: a log axis only over a decade (switched as figures are rendered),
plain log labels, panels meant to be compared on one y range, no empty panel, legends and captions that name only what
is drawn. Each test draws a figure from a golden dataset (or a small one) and checks its matplotlib objects."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from vibroimpact.reporting.style import drawn_scale, linear_under_a_decade, readable_axes, scale_phrase, thin_minor_log_ticks
from vibroimpact.runs.run import read_dataset

GOLDEN = Path(__file__).resolve().parents[1] / "golden" / "data"


def _labels(axis: object) -> list[str]:
    figure = axis.axes.figure  # type: ignore[attr-defined]
    figure.canvas.draw()
    return [label.get_text() for label in axis.get_ticklabels(which="both") if label.get_text() and label.get_visible()]  # type: ignore[attr-defined]


def _rendered(figure: plt.Figure) -> None:
    """What :func:`vibroimpact.reporting.page._png` does to a figure before writing it."""
    linear_under_a_decade(figure)
    thin_minor_log_ticks(figure)
    readable_axes(figure)


def test_a_log_axis_under_a_decade_is_drawn_linear_and_its_bars_start_at_zero() -> None:
    figure, (narrow, wide) = plt.subplots(1, 2)
    narrow.bar([0, 1], [1.6e-7, 3.3e-7])
    narrow.set_yscale("log")
    wide.plot([1.0, 2.0], [0.5, 50.0])
    wide.set_yscale("log")
    assert drawn_scale(narrow) == "linear" and drawn_scale(wide) == "log"
    assert scale_phrase([narrow, wide]) == "log scale, except panel 1: linear, as it spans less than a decade"
    _rendered(figure)
    assert narrow.get_yscale() == "linear" and narrow.get_ylim()[0] <= 0.0 and wide.get_yscale() == "log"
    assert not any("times" in text or "^" in text for text in _labels(narrow.yaxis))
    plt.close(figure)


def test_a_log_axis_keeps_the_limits_a_figure_set() -> None:
    figure, ax = plt.subplots()
    ax.plot([1.0, 2.0], [2.4, 3.0])
    ax.set_yscale("log")
    ax.set_ylim(2.3, 3.1)
    _rendered(figure)
    assert ax.get_yscale() == "linear" and np.allclose(ax.get_ylim(), (2.3, 3.1))
    plt.close(figure)


def test_a_default_log_axis_gets_plain_labels_between_its_decades() -> None:
    figure, ax = plt.subplots()
    ax.plot([20.0, 40.0], [0.5, 50.0])
    ax.set_yscale("log")
    ax.set_ylim(0.5, 50.0)
    assert not {"1", "2", "5"} & set(_labels(ax.yaxis))  # matplotlib's own: 10^0 and 10^1 alone in the range
    _rendered(figure)
    assert {"1", "2", "5", "10", "20"} <= set(_labels(ax.yaxis))
    plt.close(figure)


def test_the_running_amplitude_of_a_sweep_over_less_than_a_decade_is_drawn_linear() -> None:
    from vibroimpact.kinds.swept.page import _first_point, sweep_figures, swept_sine_run

    dataset = read_dataset(GOLDEN / "bumper_sweep.nc")
    part, _ = _first_point(dataset)
    drawn = next(f for f in sweep_figures(part, swept_sine_run(dataset)) if f.name == "sweep_time")
    _rendered(drawn.figure)
    (ax,) = drawn.figure.axes
    assert ax.get_yscale() == "linear" and ax.yaxis.get_offset_text().get_text() == ""
    plt.close(drawn.figure)


def test_the_concepts_impact_caption_names_the_scales_drawn() -> None:
    from vibroimpact.kinds.concepts.page import impact_figure

    drawn = impact_figure(read_dataset(GOLDEN / "absorber_concepts.nc"))
    assert drawn is not None
    scales = [drawn_scale(ax) for ax in drawn.figure.axes[:3]]
    assert scales == ["linear", "linear", "log"]
    assert "log scale, except panels 1, 2: linear, as they span less than a decade" in drawn.caption and "(log scales;" not in drawn.caption
    plt.close(drawn.figure)


def test_the_lyapunov_panels_of_each_restitution_share_one_y_range_and_name_only_drawn_kinds() -> None:
    from vibroimpact.kinds.stepped.page import lyapunov_figure

    dataset = read_dataset(GOLDEN / "restitution.nc")
    drawn = lyapunov_figure(dataset, ["momentary", "exact"], "lyapunov")
    assert drawn is not None
    panels = [ax for ax in drawn.figure.axes if ax.get_title().startswith("R = ")]
    assert len(panels) == 2 and np.allclose(panels[0].get_ylim(), panels[1].get_ylim())
    legend = [text.get_text() for text in drawn.figure.legends[0].get_texts()]
    assert "chaotic" in legend and "irregular" in legend and "quasi_periodic" not in legend  # no quasi-periodic point is drawn
    plt.close(drawn.figure)


def test_the_simulation_panels_of_each_restitution_share_one_y_range() -> None:
    from vibroimpact.kinds.stepped.responses import simulation_figure

    drawn = simulation_figure(read_dataset(GOLDEN / "restitution.nc"), "impulse", ["momentary", "exact"], "simulation_impulse")
    assert drawn is not None
    panels = [ax for ax in drawn.figure.axes if ax.get_title().startswith("R = ")]
    assert len(panels) == 2 and np.allclose(panels[0].get_ylim(), panels[1].get_ylim())
    plt.close(drawn.figure)


def test_a_regime_map_draws_no_panel_for_a_solution_that_computed_nothing_there() -> None:
    from vibroimpact.kinds.stepped.responses import regime_figure

    part = read_dataset(GOLDEN / "clearance_peaks.nc").isel(clearance=1)  # 'momentary' and 'compliant' ran at 2 mm only
    drawn = regime_figure(part, "regime")
    titles = [ax.get_title() for ax in drawn.figure.axes]
    assert not any(title.startswith(("'momentary'", "'compliant':")) for title in titles) and len(titles) == 4
    assert all(ax.collections for ax in drawn.figure.axes)  # every panel shows its flags
    assert "of 'linear', 'pgf', 'exact', 'compliant_exact' (" in drawn.caption
    assert "No panel for 'momentary', 'compliant': they computed no point at Delta = 3 mm." in drawn.caption
    plt.close(drawn.figure)


def test_the_chart_legend_names_only_the_classes_it_colours() -> None:
    from vibroimpact.kinds.bifurcation.figures import chart_figure

    drawn = chart_figure(read_dataset(GOLDEN / "bifurcation.nc"))
    legend = [text.get_text() for text in drawn.figure.legends[0].get_texts()]
    assert {"linear", "one impact", "other periodic", "irregular"} <= set(legend)
    assert "chaotic" not in legend and "quasi periodic" not in legend  # no cell of the golden chart is either
    plt.close(drawn.figure)


def test_an_operating_frequency_outside_the_band_is_neither_drawn_nor_said_to_be() -> None:
    from vibroimpact.kinds.design.figures import response_figure

    drawn = response_figure(read_dataset(GOLDEN / "design_rigid_stop.nc"))  # band 22-28 Hz, operating point 33 Hz
    legend = [text.get_text() for text in drawn.figure.legends[0].get_texts()]
    assert not any(text.startswith("operating frequency") for text in legend)
    assert "dash-dotted" not in drawn.caption
    assert "The operating frequency, 33 Hz, lies outside the band drawn (22-28 Hz): its allowed |X1| (0.05 mm) is not drawn." in drawn.caption
    plt.close(drawn.figure)


def test_an_operating_frequency_inside_the_band_is_drawn_and_said() -> None:
    from vibroimpact.kinds.design.figures import response_figure

    drawn = response_figure(read_dataset(GOLDEN / "design_map.nc"))  # band 15-45 Hz, operating point 33 Hz
    legend = [text.get_text() for text in drawn.figure.legends[0].get_texts()]
    assert any(text.startswith("operating frequency 33 Hz") for text in legend) and "The dash-dotted line is the operating frequency, 33 Hz" in drawn.caption
    plt.close(drawn.figure)


def test_the_zeno_caption_gives_the_dotted_bound_in_the_units_it_is_drawn_in() -> None:
    from vibroimpact.kinds.validation.page import validation_figure

    dataset = read_dataset(GOLDEN / "validation_zeno.nc")
    drawn = validation_figure(dataset)
    bound = float(dataset.attrs["deficit_high_s"]) / float(dataset.attrs["zeno_time_s"])
    dotted = [line for line in drawn.figure.axes[1].get_lines() if line.get_linestyle() == ":"]
    assert dotted and np.allclose(dotted[0].get_ydata(), bound)  # a relative error, as the axis
    assert f"drawn as {bound:.2e} of the Zeno time" in drawn.caption
    plt.close(drawn.figure)
