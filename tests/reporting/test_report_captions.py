"""Captions say what is drawn: every solution, quantity and description they name is in the figure, filled and
hollow markers mean what the caption says, and the impulse is called what the data hold."""

from __future__ import annotations

import re

import matplotlib.pyplot as plt
import numpy as np
import pytest

from vibroimpact.analysis.stability import Regime
from vibroimpact.reporting.style import QUANTITIES, SOLUTION_DESCRIPTIONS, SOLUTION_TITLES
from vibroimpact.scene.schema import ENGINE_SOLUTIONS, SOLUTIONS
from vibroimpact.scene.variables import VARIABLE_ATTRIBUTES

from tests.reporting.test_report_support import FIGURE_KINDS, build, drawn_gids, steady_dataset, visible

#: Words by which a caption names a solution without its name.
IMPLICIT_NAMES = {"pgf_paper": ("fitted modes",)}


def _drawn_solutions(fig: plt.Figure) -> set[str]:
    """Solutions with visible data in ``fig``: artists' gids, and the solutions regime-map panels are titled with."""
    drawn = set()
    for gid in drawn_gids(fig):
        drawn.update(re.findall(r"'(\w+)'", gid) if gid.startswith("regime:") else [gid])
    return drawn


def _axis_texts(fig: plt.Figure) -> str:
    return " ".join(t for ax in fig.axes for t in (ax.get_ylabel(), ax.get_xlabel(), ax.get_title()))


@pytest.mark.parametrize("kind", FIGURE_KINDS)
def test_caption_names_only_what_is_drawn(kind: str) -> None:
    for drawn in build(kind):
        fig, caption = drawn.figure, drawn.caption
        solutions = _drawn_solutions(fig)
        named = {name for name in re.findall(r"'(\w+)'", caption) if name in SOLUTIONS}
        assert named <= solutions, f"{drawn.name}: caption names {named - solutions}, not drawn"
        # compared in lower case: a caption starts with a capital
        words = caption.lower()
        titles = " ".join(ax.get_title() for ax in fig.axes).lower()
        for solution in SOLUTIONS:
            for text in (SOLUTION_DESCRIPTIONS[solution].lower(), SOLUTION_TITLES[solution].lower(), *IMPLICIT_NAMES.get(solution, ())):
                if text in words or text in titles:
                    assert solution in solutions, f"{drawn.name}: describes {solution} ({text!r}), which it does not draw"
        axes_text = _axis_texts(fig).lower()
        for quantity in QUANTITIES.values():
            if quantity.label.lower() in words:
                assert quantity.label.lower() in axes_text, f"{drawn.name}: caption names {quantity.label!r}, no panel shows it"
        plt.close(fig)


def test_filled_markers_are_periodic_and_hollow_ones_irregular() -> None:
    ds = steady_dataset()
    (drawn,) = build("simulation_x1")
    f = ds["frequency"].values
    kinds = set()
    for ax, r in zip(drawn.figure.axes, ds["restitution"].values):
        for line in ax.get_lines():
            if line.get_gid() not in ENGINE_SOLUTIONS or line.get_linestyle() != "None":
                continue
            converged = ds["converged"].sel(solution=line.get_gid(), restitution=r).values
            at = np.searchsorted(f, np.asarray(line.get_xdata())[visible(line)])
            filled = line.get_markerfacecolor() != "none"
            kinds.add(filled)
            assert np.all(converged[at] == (1 if filled else 0)), (line.get_gid(), r, filled)
    assert kinds == {True, False}
    assert "filled: periodic" in drawn.caption and "hollow: not periodic" in drawn.caption
    plt.close(drawn.figure)


@pytest.mark.parametrize("kind", ["response_impulse", "simulation_impulse"])
def test_impulse_is_called_what_the_data_hold(kind: str) -> None:
    """The dataset's impulse is the total per excitation period (simulations too), not a mean per impact."""
    assert "per period" in VARIABLE_ATTRIBUTES["impulse"]["long_name"] and "per period" in QUANTITIES["impulse"].label
    for drawn in build(kind):
        assert QUANTITIES["impulse"].label in drawn.caption.lower()
        assert "per impact" not in drawn.caption
        assert all("impulse per period" in ax.get_ylabel() for ax in drawn.figure.axes)
        plt.close(drawn.figure)


def test_lyapunov_figure_draws_every_non_periodic_point_in_the_colour_of_its_kind() -> None:
    """Each engine's chaotic and quasi-periodic points, one marker each, coloured as on the regime map; the caption
    says how the exponent was estimated and what the thresholds are."""
    from matplotlib.colors import to_hex

    from vibroimpact.kinds.stepped.page import lyapunov_figure
    from vibroimpact.reporting.style import REGIME_COLOURS


    dataset = steady_dataset()
    drawn = lyapunov_figure(dataset, ["momentary", "exact"], "lyapunov")
    assert drawn is not None
    try:
        for ax, restitution in zip(drawn.figure.axes, dataset["restitution"].values):
            for engine in ("momentary", "exact"):
                regime = dataset["regime"].sel(solution=engine, restitution=restitution).values
                for kind in (Regime.CHAOTIC, Regime.QUASI_PERIODIC):
                    points = [
                        len(line.get_xdata())
                        for line in ax.get_lines()
                        if line.get_gid() == engine and line.get_marker() not in (None, "None", "") and to_hex(line.get_color()) == REGIME_COLOURS[kind]
                    ]
                    assert sum(points) == int(np.sum(regime == int(kind))) > 0
        assert "exact Jacobians" in drawn.caption and "perturbed" in drawn.caption and "0.01" in drawn.caption
    finally:
        plt.close(drawn.figure)


def test_agreement_table_counts_each_kind_of_non_periodic_motion() -> None:
    """The fake simulations are chaotic over 34-36 Hz and quasi-periodic over 36-38 Hz (band 2): the table counts them."""
    import html as html_module

    from vibroimpact.reporting.record import study_setting
    from vibroimpact.kinds.stepped.tables import agreement_table

    dataset = steady_dataset()
    split = study_setting(dataset).split_frequency
    table = agreement_table(dataset, split)
    assert table is not None
    rows = [[html_module.unescape(re.sub("<[^>]+>", "", c)).strip() for c in re.findall(r"<t[dh][^>]*>(.*?)</t[dh]>", r, re.S)] for r in re.findall(r"<tr>(.*?)</tr>", table.html, re.S)]
    header, body = rows[0], rows[1:]
    quasi, chaotic = header.index("simulation quasi-periodic"), header.index("chaotic")
    for row in body:
        engine, r, band = row[0], float(row[2]), row[3]
        regime = dataset["regime"].sel(solution=engine, restitution=r).values
        in_band = (dataset["frequency"].values >= split) if band == "2" else (dataset["frequency"].values < split)
        assert int(row[quasi]) == int(np.sum((regime == int(Regime.QUASI_PERIODIC)) & in_band))
        assert int(row[chaotic]) == int(np.sum((regime == int(Regime.CHAOTIC)) & in_band))
    assert any(int(row[chaotic]) > 0 for row in body) and any(int(row[quasi]) > 0 for row in body)
