"""The trade-off of a design study between the worst case (the objective's measure: |X1|, |X2| or |F|) and the
impact: the candidates no other beats on both.

A rigid stop's contact force is a Dirac pulse; its measure is the impulse of one impact [N s], which the closed-form
screen reads off every stable period-1 impact orbit it scans (``sample_impulse``). :func:`~vibroimpact.kinds.design.search.pareto_front` marks the
feasible candidates that no other feasible candidate beats on both the objective and the worst impulse: the front of
what the search visited (searches constrained on the impulse would push it further). :func:`tradeoff_figure` draws
it, :func:`front_text` says it.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from numpy.typing import NDArray

from vibroimpact.kinds.design.answer import design_titles, ties
from vibroimpact.kinds.design.figures import DESIGN_COLOURS, DESIGN_MARKERS, PATH_COLOUR
from vibroimpact.kinds.design.quantity import constraint_quantity, objective_quantity, operating_limit
from vibroimpact.reporting.page import DrawnFigure
from vibroimpact.reporting.style import Caption, figure_legend, finish_axes, fmt, legend_rows, new_figure

__all__ = ["tradeoff_figure", "front_text", "FRONT_COLOUR"]

#: The front (Okabe-Ito vermillion, the search path's colour); the compared designs keep their page colours.
FRONT_COLOUR = PATH_COLOUR


def tradeoff_figure(dataset: xr.Dataset) -> DrawnFigure:
    """The worst case (the objective's measure) against the worst impulse of one impact of every candidate, the front joined, the recommended
    and the scene's designs marked, and the best linear absorber of the same mass (no stop: no impact) at 0 N s."""
    d = dataset
    q = objective_quantity(d)
    objective, impulse = q.value(d["objective"].values), d["impulse"].values
    feasible, front = d["feasible"].values == 1, d["pareto_front"].values == 1
    fig, axes = new_figure(1, panel_height=3.6, legend_rows=legend_rows(5, 2))
    ax = axes[0]
    shown = np.isfinite(objective) & np.isfinite(impulse)
    ax.plot(impulse[shown & feasible], objective[shown & feasible], "o", ms=3, color="0.55", label="a candidate (keeps the operating constraint)")
    if np.any(shown & ~feasible):
        ax.plot(impulse[shown & ~feasible], objective[shown & ~feasible], "x", ms=4, color="0.55", label="a candidate that violates the operating constraint")
    order = np.flatnonzero(front)[np.argsort(impulse[front])]
    if order.size:
        ax.step(impulse[order], objective[order], where="post", color=FRONT_COLOUR, lw=1.8, marker="o", ms=5, label=f"the front: {order.size} candidates no other beats on both")
    for k, evaluation in enumerate((int(d.attrs.get("recommended_evaluation", -1)), 0)):
        if evaluation >= 0 and shown[evaluation]:
            ax.plot([impulse[evaluation]], [objective[evaluation]], DESIGN_MARKERS[k], ms=13 if k == 0 else 9, color=DESIGN_COLOURS[k], mec="k", mew=0.8, zorder=6, label=design_titles(d)[k])
    linear = _linear_worst(d)
    if math.isfinite(linear):
        violation = _linear_violation(d)
        ax.plot([0.0], [q.value(linear)], DESIGN_MARKERS[2], ms=10, color=DESIGN_COLOURS[2] if not violation else "none", mec=DESIGN_COLOURS[2] if violation else "k", mew=1.6 if violation else 0.8, zorder=6,
                label=f"{design_titles(d)[2]} (no stop: no impact){'; violates the operating constraint' if violation else ''}")  # fmt: skip
    finish_axes(ax, "worst impulse of one impact over the band and the samples [N s]", f"worst case {q.label}", f"Worst {q.symbol} against the impact: the trade-off")
    outside = _zoom(ax, impulse, objective, front | np.isin(np.arange(impulse.size), [0, int(d.attrs.get("recommended_evaluation", -1))]), shown, q.value(linear))
    figure_legend(fig, axes, columns=2)
    bumpers = d.attrs.get("screen") == "bumper_orbits"
    caption = Caption(f"Each of the search's {int(np.count_nonzero(shown))} candidates with both values ({'bumper' if bumpers else 'closed-form'} screen): its worst case {q.symbol} over the band and the mistuning samples against "
                      f"the largest impulse of one {'contact (the integral of the bumper force over it)' if bumpers else 'impact'} of its stable period-1 impact orbits (scan frequencies, not refined; 0: only contact-free motions are stable). "
                      "Where a candidate's band is partly uncovered (motions the screen does not know) its impulse is a lower bound, and is not drawn where it would read 0.")  # fmt: skip
    if math.isfinite(linear):
        violation = _linear_violation(d)
        least = float(np.min(objective[front])) if np.any(front) else math.nan
        level = math.isfinite(least) and ties(q.value(linear), least)  # level with the front's least: no better for a stop either
        below = math.isfinite(least) and q.value(linear) < least and not level
        caption.add("linear", f"The green diamond at 0 N s is the {design_titles(d)[2]} of the same mass under the same mistuning ({fmt(q.value(linear), '.4g')} {q.unit}, exact band peaks): it has no stop, hence no impact"
                    + (f"; hollow: it violates the operating constraint ({violation})." if violation else
                       "; below the whole front, it is smaller on both." if below else "; level with the front's least, it is no larger on both." if level else f"; a design with a stop below it pays for its smaller {q.symbol} with impacts."))  # fmt: skip
    caption.add("front", f"The vermillion steps join the front: the feasible candidates no other feasible candidate beats on both ({order.size}); it is the front of what the search evaluated, not of a search constrained on the impulse.")
    if np.any(shown & ~feasible):
        caption.add("infeasible", "Crosses violate the operating constraint and are left off the front.")
    if outside:
        caption.add("zoom", f"Drawn around the front and the compared designs: {outside} candidates with a larger impulse or {q.symbol} lie beyond the axes.")
    missing = int(np.count_nonzero(~shown))
    if missing:
        caption.add("missing", f"{missing} candidates have no impulse (screened by brute force, or no value) and are not drawn.")
    return DrawnFigure(fig, "design_tradeoff", f"Worst {q.symbol} against the impact: the trade-off", caption.text())


def _zoom(ax: Axes, impulse: NDArray[np.float64], objective: NDArray[np.float64], keep: NDArray[np.bool_], shown: NDArray[np.bool_], linear: float = math.nan) -> int:
    """Limit the axes to 1.5 times the impulse and 1.3 times the worst case of the ``keep`` candidates (the front,
    the recommended and the scene's designs) and of the ``linear`` absorber [the page's unit] (NaN: none), so that far worse
    candidates do not squeeze the front into a corner; how many lie beyond."""
    kept = keep & shown
    if not np.any(kept):
        return 0
    right = 1.5 * max(float(np.max(impulse[kept])), 0.1 * float(np.max(impulse[shown])), 1e-12)
    top = 1.3 * float(np.nanmax([float(np.max(objective[kept])), linear]))
    bottom = 0.9 * float(np.nanmin([float(np.min(objective[shown])), linear]))
    ax.set_xlim(-0.02 * right, right)
    ax.set_ylim(bottom, top)
    return int(np.count_nonzero(shown & ((impulse > right) | (objective > top))))


def _linear_worst(dataset: xr.Dataset) -> float:
    """The best linear absorber's objective [m or N]: the same quantile of its samples' band peaks as the candidates'
    (NaN: not compared)."""
    row = dataset["design_sample_value"].values[2]
    return float(np.quantile(row, float(dataset.attrs.get("quantile", 1.0)), method="higher")) if np.all(np.isfinite(row)) else math.nan


def _linear_violation(dataset: xr.Dataset) -> str:
    """Where the best linear absorber violates the operating constraint, how (``|X1| = 0.62 mm at 33 Hz, allowed
    0.05 mm``, the constraint's measure); else empty."""
    d = dataset
    limit, notch, c = operating_limit(d), float(d["design_operating_amplitude"].values[2]), constraint_quantity(d)
    if not math.isfinite(limit) or not math.isfinite(notch) or notch <= limit:
        return ""
    return f"{c.symbol} = {fmt(c.value(notch), '.3g')} {c.unit} at {fmt(float(d.attrs['operating_frequency_Hz']), 'g')} Hz, allowed {fmt(c.value(limit), '.3g')} {c.unit}"


def front_text(dataset: xr.Dataset) -> str:
    """One sentence on the front: its span in impulse and worst case (the objective's measure), where the recommended design sits on it, and where
    the best linear absorber (no impact) stands against it."""
    d = dataset
    front = d["pareto_front"].values == 1
    if not np.any(front):
        return ""
    q = objective_quantity(d)
    impulse, objective = d["impulse"].values[front], q.value(d["objective"].values[front])
    recommended = int(d.attrs.get("recommended_evaluation", -1))
    titles = design_titles(d)
    where = ""
    if recommended >= 0 and math.isfinite(float(d["impulse"].values[recommended])):
        on = bool(d["pareto_front"].values[recommended] == 1)
        if impulse.size == 1:
            where = f"; it is the {titles[0]}" if on else f"; the {titles[0]} is off it"
        else:
            where = f"; the {titles[0]} ({fmt(float(d['impulse'].values[recommended]), '.3g')} N s) is {'on it' if on else 'off it (by the screen, another candidate is no worse on both)'}"
    linear = _linear_worst(d)
    if math.isfinite(linear):
        level = np.array([ties(float(value), q.value(linear)) for value in objective], dtype=bool)  # equal is no 'below'
        above = int(np.count_nonzero((objective >= q.value(linear)) & ~level))
        violation = _linear_violation(d)
        if violation:
            against = f"{'below' if above else 'above'} {'the whole front' if above in (0, objective.size) else f'{above} of the front candidates'}, but it violates the operating constraint ({violation})"
        else:
            tied = int(np.count_nonzero(level))
            against = ("below the whole front: no stop pays for its impacts" if above == objective.size else
                       f"level with the front's least {q.symbol} and below the rest: no stop pays for its impacts" if tied and above + tied == objective.size else
                       f"below {above} of the front's {objective.size} candidates" if above else "above the whole front (by the screen)")  # fmt: skip
        where += f"; the {titles[2]} has no impact, at {fmt(q.value(linear), '.4g')} {q.unit}, {against}"
    if impulse.size == 1:
        return f"The trade-off: one feasible candidate beats every other on both the worst {q.symbol} and the impulse ({fmt(float(objective[0]), '.4g')} {q.unit} at {fmt(float(impulse[0]), '.3g')} N s){where}."
    return (f"The trade-off: {int(np.count_nonzero(front))} candidates form the front, from {fmt(float(np.min(objective)), '.4g')} {q.unit} at "
            f"{fmt(float(impulse[np.argmin(objective)]), '.3g')} N s to {fmt(float(objective[np.argmin(impulse)]), '.4g')} {q.unit} at {fmt(float(np.min(impulse)), '.3g')} N s{where}.")  # fmt: skip
