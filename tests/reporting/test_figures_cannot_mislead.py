"""Figures that cannot mislead (issue 33): a constant shared by several series drawn once and labelled, never as
stacked bands; a curve hidden under another's markers named in the caption; one colour-blind-safe palette for ordered
parameters with no series always on top; subset panels saying how many points; legends saying whose orbit."""

from __future__ import annotations

import itertools

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.colors import to_hex

from tests.reporting.test_report_regimes import _DEFICIENCIES, _lab
from tests.reporting.test_report_support import steady_dataset
from vibroimpact.analysis.stability import Regime

#: Smallest CIELAB difference (CIE76) of two series' colours of an ordered parameter, up to nine series, with normal
#: vision and under each simulated deficiency (the former matplotlib cycle: 4.5 between red and green, deuteranopia).
ORDERED_DISTINCT = 7.5


def _legend_texts(fig: plt.Figure) -> list[str]:
    return [text.get_text() for legend in fig.legends for text in legend.get_texts()] + [text.get_text() for ax in fig.axes if ax.get_legend() for text in ax.get_legend().get_texts()]


def _shared(ax: plt.Axes) -> list:
    return [line for line in ax.get_lines() if str(line.get_gid()).startswith("shared:")]


def _beneath(ax: plt.Axes) -> list:
    return [line for line in ax.get_lines() if str(line.get_gid()).startswith("beneath:")]


def test_nine_exact_zeros_are_one_labelled_line_not_nine_bands() -> None:
    """Nine restitution ratios all exactly 0 over a stretch: one dark line there, labelled with all nine, no band at
    0 (the former rule stacked eight bands into a stripe +-8 pt around 0 that read as data); elsewhere the curves keep
    their values, each reaching the line."""
    from vibroimpact.reporting.coincide import Shared, coincidence_phrase, reveal_coincident

    from vibroimpact.reporting.style import ordered_colours

    fig, ax = plt.subplots()
    try:
        x = np.linspace(15.0, 45.0, 301)
        names = [f"R = {r:g}" for r in np.round(np.arange(0.1, 1.0, 0.1), 1)]
        curves = []
        for k, name in enumerate(names):
            y = np.where((x > 20.0) & (x < 27.0), (k + 1) * 100.0 * np.sin(np.pi * (x - 20.0) / 7.0), 0.0)
            curves.append((name, ax.plot(x, y, color=ordered_colours(9)[k], gid="pgf")))
        ax.set_ylim(-50.0, 1000.0)
        found = reveal_coincident(ax, curves, zero="no impacts")
        shared = [c for c in found if isinstance(c, Shared)]
        assert len(_shared(ax)) == 1 and len(shared) == 1
        assert shared[0].label == "R = 0.1 ... 0.9 (all 9): exactly 0 (no impacts)"
        assert _shared(ax)[0].get_label() == shared[0].label
        line = np.asarray(_shared(ax)[0].get_ydata(), float)
        assert np.all(line[np.isfinite(line)] == 0.0)  # exact: the shared constant itself
        assert np.isfinite(line).sum() >= 0.7 * x.size
        for band in _beneath(ax):  # no band along the zero stretches
            y = np.asarray(band.get_ydata(), float)
            assert not np.any(np.abs(y[np.isfinite(y)]) < 1e-12)
        for _, (drawn,) in curves:  # each curve is left out on the shared stretches but for its ends
            y = np.asarray(drawn.get_ydata(), float)
            assert np.isfinite(y).sum() <= x.size * 0.3
        phrase = coincidence_phrase(found)
        assert "R = 0.1 ... 0.9 (all 9): exactly 0 (no impacts) over 15-20" in phrase and "Drawn once" in phrase
    finally:
        plt.close(fig)


def test_the_impulse_figure_draws_the_shared_zero_once_and_says_whose() -> None:
    """Two restitution ratios with no impact over most of the band: each closed-form panel draws one shared zero, the
    figure's legend names it, and the caption no longer calls the zeros coinciding curves."""
    from vibroimpact.kinds.stepped.responses import response_figure

    drawn = response_figure(steady_dataset(engines=(), restitution=(0.2, 0.6), step=0.5), "impulse", "impulse")
    assert drawn is not None
    try:
        ax = next(a for a in drawn.figure.axes if a.get_title().startswith("'pgf'"))
        assert len(_shared(ax)) == 1
        assert "R = 0.2, 0.6: exactly 0 (no impacts)" in _legend_texts(drawn.figure)
        assert "R = 0.2, 0.6: exactly 0 (no impacts) over" in drawn.caption
        for band in _beneath(ax):
            y = np.asarray(band.get_ydata(), float)
            assert np.count_nonzero(y[np.isfinite(y)] == 0.0) <= 2  # exact: no band along the zero, at most its ends
    finally:
        plt.close(drawn.figure)


def test_a_curve_under_another_ones_markers_is_named() -> None:
    """bumper_stiffness: the 24 Hz series 0.015 decade from the 25 Hz one (0.6 % of the panel: inside the markers,
    outside a line's width; the shipped study's 23 Hz lies 0.008-0.024 decade under its 25 Hz) is drawn as a band and
    named in the caption. The figure never asked which curves coincide, and a line's width was the only tolerance."""
    from tests.golden.golden import DATA, joined, read_back
    from vibroimpact.kinds.stepped.page import stiffness_figure
    from vibroimpact.reporting.record import study_setting

    dataset = joined(read_back(DATA / "bumper_stiffness.nc")).copy(deep=True)
    x1 = dataset["x1_amplitude"]
    ref = x1.sel(solution="exact")
    difference = np.abs(x1.sel(solution="compliant_exact", frequency=25.0) - ref.sel(frequency=25.0)) / ref.sel(frequency=25.0)
    x1.loc[{"solution": "compliant_exact", "frequency": 24.0}] = (ref.sel(frequency=24.0) * (1.0 + difference * 10.0**0.015)).values
    drawn = stiffness_figure(dataset, study_setting(dataset), "bumper_stiffness")
    assert drawn is not None
    try:
        assert "24 Hz lies under 25 Hz" in drawn.caption
        assert [line for line in drawn.figure.axes[0].get_lines() if str(line.get_gid()).startswith("beneath:")]
    finally:
        plt.close(drawn.figure)


def test_ordered_palette_is_colour_blind_safe_and_every_ordered_page_uses_it() -> None:
    """Up to nine series: pairwise distinct with any colour vision; the stepped pages colour R with it (not
    matplotlib's cycle), wide first and thin last, so that the last drawn hides none."""
    from vibroimpact.kinds.stepped.responses import response_figure
    from vibroimpact.reporting.style import ordered_colours, ordered_widths

    for count in range(2, 10):
        colours = ordered_colours(count)
        assert len(set(colours)) == count
        for deficiency in (None, *_DEFICIENCIES):
            for a, b in itertools.combinations(colours, 2):
                assert float(np.linalg.norm(_lab(a, deficiency) - _lab(b, deficiency))) > ORDERED_DISTINCT, (count, deficiency, a, b)
        widths = ordered_widths(count)
        assert all(w1 > w2 for w1, w2 in zip(widths, widths[1:]))
    drawn = response_figure(steady_dataset(engines=(), restitution=(0.2, 0.6), step=0.5), "x1_amplitude", "x1")
    assert drawn is not None
    try:
        ax = next(a for a in drawn.figure.axes if a.get_title().startswith("'pgf'"))
        lines = [line for line in ax.get_lines() if line.get_gid() == "pgf" and np.size(line.get_xdata()) > 1]
        colours = {to_hex(line.get_color()) for line in lines}
        assert colours == set(ordered_colours(2))
        first = [line.get_linewidth() for line in lines if to_hex(line.get_color()) == ordered_colours(2)[0]]
        last = [line.get_linewidth() for line in lines if to_hex(line.get_color()) == ordered_colours(2)[1]]
        assert min(first) > max(last)
    finally:
        plt.close(drawn.figure)


def test_subset_panels_say_how_many_points() -> None:
    """A simulation run on a subset of the grid: its panel's title and its legend entries say "n points"."""
    from vibroimpact.kinds.stepped.responses import response_figure

    ds = steady_dataset(restitution=(0.2, 0.6), step=0.5).copy(deep=True)
    engine = "momentary"
    for name in ds.data_vars:  # R = 0.2 not simulated
        if {"solution", "restitution"} <= set(ds[name].dims) and ds[name].dtype.kind == "f":
            ds[name].loc[{"solution": engine, "restitution": 0.2}] = np.nan
    ds["regime"].loc[{"solution": engine, "restitution": 0.2}] = int(Regime.NOT_COMPUTED)
    kept = int(np.count_nonzero(ds["regime"].sel(solution=engine).values != int(Regime.NOT_COMPUTED)))
    assert 0 < kept < np.isfinite(ds["x1_amplitude"].sel(solution="exact").values).sum()
    ds.attrs["simulation_subset_momentary"] = "restitution 0.6"
    drawn = response_figure(ds, "x1_amplitude", "x1")
    assert drawn is not None
    try:
        titles = [ax.get_title() for ax in drawn.figure.axes]
        assert any(t.startswith(f"'{engine}'") and f"(subset: {kept} points)" in t for t in titles), titles
        assert not any("subset" in t for t in titles if not t.startswith(f"'{engine}'"))
        assert any(text.startswith(f"'{engine}' ({kept} points)") for text in _legend_texts(drawn.figure))
    finally:
        plt.close(drawn.figure)


def test_stability_legends_say_whose_orbit() -> None:
    """"stable orbit" says whose: the closed form's, by name."""
    from vibroimpact.kinds.stepped.responses import response_figure

    ds = steady_dataset(engines=(), restitution=(0.2, 0.6), step=0.5)
    drawn = response_figure(ds, "x1_amplitude", "x1")
    assert drawn is not None
    try:
        texts = _legend_texts(drawn.figure)
        assert "stable orbit of 'pgf' and 'pgf_paper' (solid)" in texts and "unstable orbit of 'pgf' and 'pgf_paper' (dashed)" in texts
        assert "stable orbit (solid)" not in texts
    finally:
        plt.close(drawn.figure)


@pytest.mark.parametrize("name", ["bifurcation_bumper"])
def test_bumper_colours_and_special_point_colours_have_separate_legends(name: str) -> None:
    """bifurcation_bumper: the bumpers take the ordered palette, in a legend of their own under the left panel; the
    special points' colours are in the right panel's legend only; the diagrams' line styles say whose orbit."""
    from tests.golden.golden import DATA, joined, read_back
    from vibroimpact.kinds.bifurcation.bumper import bumper_figure, bumper_frequencies
    from vibroimpact.kinds.bifurcation.figures import diagram_figure
    from vibroimpact.reporting.style import ordered_colours

    dataset = joined(read_back(DATA / f"{name}.nc"))
    drawn = bumper_figure(dataset)
    try:
        left, right = drawn.figure.axes[:2]
        assert not drawn.figure.legends
        left_texts = [t.get_text() for t in left.get_legend().get_texts()]
        right_texts = [t.get_text() for t in right.get_legend().get_texts()]
        assert any(t.startswith("bumper ") for t in left_texts) and not any(t.startswith("bumper ") for t in right_texts)
        assert not any(" at " in t and "Hz" in t for t in left_texts)
        bumpers = bumper_frequencies(dataset)
        handles = {h.get_label(): to_hex(h.get_color()) for h in left.get_legend().legend_handles if h.get_label().startswith("bumper ")}
        assert sorted(handles.values()) == sorted(ordered_colours(len(bumpers)))
    finally:
        plt.close(drawn.figure)
    rigid = joined(read_back(DATA / "bifurcation.nc"))
    diagram = diagram_figure(rigid, float(rigid["restitution"].values[0]), 0)
    try:
        texts = _legend_texts(diagram.figure)
        assert "stable periodic orbit of the continuation (solid)" in texts and "stable" not in texts
    finally:
        plt.close(diagram.figure)
