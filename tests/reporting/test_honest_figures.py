"""Honest figures and tables: regime maps draw unstable one-impact orbits distinctly (hatched over their colour,
counted in the caption, named in the legend; stable ones and other flags are not hatched), and table numbers carry no
bare trailing point."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Rectangle

from vibroimpact.analysis.stability import Regime
from vibroimpact.kinds.stepped.responses import regime_map


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
