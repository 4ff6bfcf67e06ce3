"""Honest figures and tables: regime maps draw unstable one-impact orbits distinctly (hatched over their colour,
counted in the caption, named in the legend; stable ones and other flags are not hatched), and table numbers carry no
bare trailing point."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import xarray as xr
from matplotlib.patches import Rectangle

from vibroimpact.analysis.stability import Regime
from vibroimpact.grids.regime_map import regime_map


def test_unstable_one_impact_cells_are_hatched_and_counted() -> None:
    f = np.arange(20.0, 30.0)
    flags = np.full((2, f.size), int(Regime.ONE_IMPACT))
    flags[:, :3] = Regime.LINEAR
    unstable = np.zeros(flags.shape, dtype=bool)
    unstable[0, 4:7] = True  # one run of three cells on the first row
    unstable[1, [5, 8]] = True  # two runs of one cell on the second row
    unstable[1, 0] = True  # a linear point: not a one-impact orbit, not hatched
    drawn = regime_map([("pgf", ["R = 0.2", "R = 0.8"], flags, unstable)], f, "regime", "Regime map", "Regime of each point")
    try:
        hatched = [p for p in drawn.figure.axes[0].patches if isinstance(p, Rectangle) and str(p.get_gid()).startswith("unstable:")]
        assert len(hatched) == 3 and all(p.get_hatch() == "////" for p in hatched)
        assert sorted(round(p.get_width(), 9) for p in hatched) == [1.0, 1.0, 3.0]  # cells 1 Hz wide
        assert "Hatched (5 points)" in drawn.caption
        labels = [t.get_text() for legend in drawn.figure.legends for t in legend.get_texts()]
        assert any("unstable" in label for label in labels), labels
    finally:
        plt.close(drawn.figure)


def test_without_unstable_points_nothing_is_hatched() -> None:
    f = np.arange(20.0, 25.0)
    flags = np.full((1, f.size), int(Regime.ONE_IMPACT))
    drawn = regime_map([("pgf", ["R = 0.2"], flags, np.zeros(flags.shape, dtype=bool))], f, "regime", "Regime map", "Regime")
    try:
        assert not [p for p in drawn.figure.axes[0].patches if str(p.get_gid()).startswith("unstable:")]
        assert "Hatched" not in drawn.caption
    finally:
        plt.close(drawn.figure)


def test_numbers_in_tables_carry_no_bare_trailing_point() -> None:
    """Significant figures kept ('#' format), but 1982 is printed as 1982, not '1982.'."""
    from vibroimpact.reporting.style import fmt

    assert fmt(1982.0, "#.4g") == "1982" and fmt(0.0793, "#.4g") == "0.07930" and fmt(289.6, "#.4g") == "289.6"
    assert fmt(float("nan")) == "" and fmt(12.0, ".3g", "{} Hz") == "12 Hz"


# ------------------------------------------------------------------------------------- coinciding curves
def _beneath(ax: object, gid: str) -> list:
    return [line for line in ax.get_lines() if line.get_gid() == f"beneath:{gid}"]  # type: ignore[attr-defined]


def test_a_curve_under_an_identical_one_shows_as_a_band_and_the_caption_says_so() -> None:
    """Two restitution ratios with the same |X1|: the first (drawn beneath) is drawn again as a band wider than the
    second by at least a point on each side, behind it, in its own colour, over every value; the caption names both."""
    from matplotlib.colors import to_hex

    from tests.reporting.test_report_support import steady_dataset
    from vibroimpact.kinds.stepped.responses import response_figure
    from vibroimpact.reporting.style import ordered_colours

    first, second = ordered_colours(2)
    ds = steady_dataset(engines=(), restitution=(0.2, 0.6), step=0.5)
    same = ds["x1_amplitude"].copy()
    same.loc[{"restitution": 0.2}] = same.sel(restitution=0.6).values
    drawn = response_figure(ds.assign(x1_amplitude=same, stable=xr.ones_like(ds["stable"])), "x1_amplitude", "x1")
    assert drawn is not None
    try:
        assert "R = 0.2 lies under R = 0.6" in drawn.caption
        ax = next(a for a in drawn.figure.axes if a.get_title().startswith("'pgf'"))
        top = [line for line in ax.get_lines() if line.get_gid() == "pgf" and to_hex(line.get_color()) == second and len(line.get_xdata()) > 1]
        bands = _beneath(ax, "pgf")
        assert top and bands
        assert all(to_hex(band.get_color()) == first for band in bands)  # R = 0.2's colour
        assert min(band.get_linewidth() for band in bands) >= max(line.get_linewidth() for line in top) + 2.0  # >= 1 pt each side
        assert max(band.get_zorder() for band in bands) < min(line.get_zorder() for line in top)
        values = 1e3 * same.sel(solution="pgf", restitution=0.2).values
        shown = np.concatenate([np.asarray(band.get_ydata(), float) for band in bands])
        assert np.isfinite(values).sum() <= np.isfinite(shown).sum()
    finally:
        plt.close(drawn.figure)


def test_curves_that_only_cross_are_not_called_coincident() -> None:
    from vibroimpact.reporting.coincide import coincidence_phrase, reveal_coincident

    fig, ax = plt.subplots()
    try:
        x = np.linspace(0.0, 10.0, 1001)
        rising, falling = ax.plot(x, x, gid="a"), ax.plot(x, 10.0 - x, gid="b")
        assert reveal_coincident(ax, [("a", rising), ("b", falling)]) == []
        assert not _beneath(ax, "a") and coincidence_phrase([]) == ""
        same = ax.plot(x, 10.0 - x, ls="--", gid="c")  # on b everywhere: b lies under c
        found = reveal_coincident(ax, [("b", falling), ("c", same)])
        assert [(c.lower, c.upper, c.everywhere) for c in found] == [("b", "c", True)]
        assert "b lies under c wherever both have values" in coincidence_phrase(found)
        assert _beneath(ax, "b") and not _beneath(ax, "c")
    finally:
        plt.close(fig)


def test_the_two_sided_relative_stop_draws_both_stops_coordinates() -> None:
    """|x2 - x1| of the upper and the lower stop are one curve: stop 0's shows as a band around stop 1's, and the
    caption says that they coincide."""
    import copy

    from tests.kinds.stepped.test_stepped_layouts_page import CHAIN
    from vibroimpact.grids.sections import structure_figure
    from vibroimpact.reporting.record import general_setting
    from vibroimpact.runs.run import run_study
    from vibroimpact.scene import parse_scene

    document = copy.deepcopy(CHAIN)
    document["stops"] = [{"between": ["x3", "x2"], "side": "upper", "clearance": 0.001, "restitution": 0.3}, {"between": ["x3", "x2"], "side": "lower", "clearance": 0.001, "restitution": 0.3}]
    data = run_study(parse_scene(document), progress=None)
    drawn = structure_figure(general_setting(data), data["frequency"].values)
    try:
        assert "stop 0 lies under stop 1 wherever both have values" in drawn.caption
        assert _beneath(drawn.figure.axes[1], "linear:stop0") and not _beneath(drawn.figure.axes[1], "linear:stop1")
    finally:
        plt.close(drawn.figure)


def test_nine_coinciding_curves_stack_no_more_than_three_bands() -> None:
    """Nine restitution ratios on one curve made the lowest band 8 steps wide (0.45-1.0 mm around 0.67 mm on a log
    axis, read as scatter); the bands stop at MAX_BANDS steps, and the caption still names every coincidence."""
    from vibroimpact.reporting.coincide import BAND_STEP, MAX_BANDS, coincidence_phrase, reveal_coincident

    figure, ax = plt.subplots()
    x = np.linspace(15.0, 45.0, 200)
    curves = []
    for k in range(9):
        (line,) = ax.plot(x, 0.67 + 0.0 * x, lw=1.4, gid=f"R{k}")
        curves.append((f"R = {k / 10:g}", [line]))
    found = reveal_coincident(ax, curves, share=False)
    try:
        widths = [line.get_linewidth() for line in ax.get_lines() if str(line.get_gid()).startswith("beneath:")]
        assert widths and max(widths) <= 1.4 + BAND_STEP * MAX_BANDS + 1e-9
        assert len(found) == 8 and "R = 0" in coincidence_phrase(found)
    finally:
        plt.close(figure)
