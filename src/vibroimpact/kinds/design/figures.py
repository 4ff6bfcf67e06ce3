"""Figures of a design study, everything read from the dataset.

* :func:`search_figure`: the objective over two design variables (filled contours interpolated from the evaluated
  candidates on log-spaced levels up to a high percentile), the candidates, the search's path (the best design so
  far, in evaluation order), the recommended and the scene's designs; with more than two variables one panel per
  pair of the first three (projections: the other variables vary); with one, the objective against it.
* :func:`response_figure`: the compared designs' worst stable motion side by side, then each design with every
  coexisting motion (contact-free, both roots of the period-1 impact orbit, the continued branches), its worst case
  and the operating constraint.
* :func:`robustness_figure`: each compared design's worst case under every mistuning sample, as an empirical
  distribution.

Every value is the objective's measure (|X1|, |X2|, |F|: :mod:`vibroimpact.kinds.design.quantity`), in its page
unit, except the operating constraint's, which is its own measure.

Colours: one per compared design (:data:`DESIGN_COLOURS`, Okabe-Ito, safe for colour-blind readers); line styles
tell the motions apart, markers the special designs and points.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.colors import ListedColormap
from matplotlib.lines import Line2D
from matplotlib.ticker import FormatStrFormatter, LogFormatter
from matplotlib.tri import Triangulation, TriAnalyzer
from numpy.typing import NDArray

from vibroimpact.kinds.design.answer import design_evaluation, design_titles, design_text, mistuning_spreads, present_designs, screen_words, search_path, stage_counts, unit_text, variable_names
from vibroimpact.kinds.design.quantity import constraint_quantity, objective_quantity, operating_limit
from vibroimpact.kinds.design.scene import safe_name
from vibroimpact.reporting.page import DrawnFigure
from vibroimpact.reporting.style import STABLE_STYLE, UNSTABLE_STYLE, Caption, figure_legend, finish_axes, fmt, legend_rows, new_figure

import matplotlib.pyplot as plt  # after style: the Agg backend is selected

__all__ = ["design_figures", "search_figure", "response_figure", "robustness_figure", "worst_stable",
           "PlainLogFormatter", "DESIGN_COLOURS", "DESIGN_MARKERS", "PATH_COLOUR", "CERTIFIED_COLOUR", "LIMIT_COLOUR", "OBJECTIVE_PERCENTILE"]  # fmt: skip

#: The compared designs' colours (recommended, the scene's, the linear optimum): Okabe-Ito blue, orange, green.
DESIGN_COLOURS = ("#0072B2", "#E69F00", "#009E73")
#: The compared designs' markers on the search's map.
DESIGN_MARKERS = ("*", "s", "D")
#: The search's path (Okabe-Ito vermillion).
PATH_COLOUR = "#D55E00"
#: The certified worst case, the feasibility boundary (Okabe-Ito vermillion, reddish purple).
CERTIFIED_COLOUR, LIMIT_COLOUR = "#D55E00", "#CC79A7"
#: The objective's colour scale ends at this percentile of the candidates' values (worse ones share its top colour).
OBJECTIVE_PERCENTILE = 90.0
#: The objective's colours: light where it is small (good), never darker than mid-grey (the dots stay visible).
OBJECTIVE_MAP = ListedColormap(plt.get_cmap("Greys")(np.linspace(0.03, 0.7, 256)), name="design_objective")
_FREQUENCY = "excitation frequency [Hz]"
_OPERATING = {"color": "0.3", "lw": 1.0, "ls": (0, (6, 2, 1, 2))}


def design_figures(dataset: xr.Dataset) -> list[DrawnFigure]:
    """Every figure of the page, in order."""
    return [search_figure(dataset), response_figure(dataset), robustness_figure(dataset)]


def worst_stable(dataset: xr.Dataset, design: int) -> NDArray[np.float64]:
    """The largest objective's measure [m or N] of the stable closed-form motions of a compared design at each response frequency (NaN
    where none is stable)."""
    d = dataset
    curves = [np.where(d["response_linear_fits"].values[design] == 1, d["response_linear"].values[design], np.nan)]
    curves += [np.where(d[f"response_{n}_stable"].values[design] == 1, d[f"response_{n}"].values[design], np.nan) for n in ("impact_plus", "impact_minus")]
    return np.fmax.reduce(curves)


# ------------------------------------------------------------------------------------------------- the search
def _axis(dataset: xr.Dataset, name: str) -> tuple[float, str]:
    """(factor to the page's units, axis label) of a design variable."""
    if name == "clearance":
        return 1e3, "clearance Delta [mm]"
    if name == "restitution":
        return 1.0, "restitution R [-]"
    unit = unit_text(str(dataset[f"variable_{safe_name(name)}"].attrs.get("units", "1")))
    return 1.0, f"{name} [{unit or '-'}]"


def _limits(dataset: xr.Dataset, name: str) -> tuple[float, float]:
    """A variable's bounds, 3 % wider each side [its units]."""
    attrs = dataset[f"variable_{safe_name(name)}"].attrs
    low, high = float(attrs["valid_min"]), float(attrs["valid_max"])
    return low - 0.03 * (high - low), high + 0.03 * (high - low)


def _levels(objective: NDArray[np.float64]) -> NDArray[np.float64]:
    """log10 levels [log10 of the page's unit] from the least objective to :data:`OBJECTIVE_PERCENTILE` of them."""
    finite = objective[np.isfinite(objective) & (objective > 0.0)]
    low = float(np.min(finite))
    high = max(float(np.percentile(finite, OBJECTIVE_PERCENTILE)), 1.05 * low)
    return np.linspace(math.log10(low) - 1e-9, math.log10(high), 13)


def _triangulation(u: NDArray[np.float64], v: NDArray[np.float64], x: NDArray[np.float64], y: NDArray[np.float64]) -> Triangulation | None:
    """Delaunay triangles of the points (u, v) of the unit square (the bounds), on (x, y); flat border triangles
    masked; None where the points span no triangle."""
    try:
        unit = Triangulation(u, v)
    except (RuntimeError, ValueError):
        return None
    if unit.triangles.size == 0:
        return None
    mask = TriAnalyzer(unit).get_flat_tri_mask(0.02)
    if np.all(mask):
        return None
    out = Triangulation(x, y, unit.triangles)
    out.set_mask(mask)
    return out


def _map_panel(ax: Axes, d: xr.Dataset, pair: tuple[str, str], levels: NDArray[np.float64], projected: bool) -> object:
    """One panel of the search's map over ``pair``; the colour mapping drawn (for the colour bar)."""
    (sx, xlabel), (sy, ylabel) = _axis(d, pair[0]), _axis(d, pair[1])
    x, y = (d[f"variable_{safe_name(n)}"].values for n in pair)
    objective = objective_quantity(d).value(d["objective"].values)
    finite = np.isfinite(objective) & (objective > 0.0)
    feasible = d["feasible"].values == 1
    constrained = math.isfinite(operating_limit(d))
    (x0, x1), (y0, y1) = _limits(d, pair[0]), _limits(d, pair[1])
    mappable = None
    inside = (x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)  # the scene's design may lie outside the bounds
    if not projected:
        order = np.flatnonzero(finite & inside)[np.argsort(objective[finite & inside], kind="stable")]
        u, v = (x[order] - x0) / (x1 - x0), (y[order] - y0) / (y1 - y0)
        _, first = np.unique(np.round(np.c_[u, v], 9), axis=0, return_index=True)  # coincident candidates: the best one
        keep = order[np.sort(first)]
        tri = _triangulation((x[keep] - x0) / (x1 - x0), (y[keep] - y0) / (y1 - y0), x[keep] * sx, y[keep] * sy)
        if tri is not None:
            mappable = ax.tricontourf(tri, np.log10(objective[keep]), levels=levels, cmap=OBJECTIVE_MAP, extend="max", zorder=0)
            if constrained:
                _feasibility_line(ax, d, tri, keep)
        ax.plot(x[feasible & inside] * sx, y[feasible & inside] * sy, ".", color="0.1", ms=3.0, ls="none", label="evaluated candidate" + (", holds the operating limit" if constrained else ""))
        if constrained and np.any(~feasible & inside):
            ax.plot(x[~feasible & inside] * sx, y[~feasible & inside] * sy, "x", color="0.1", ms=3.5, mew=0.7, ls="none", label="evaluated candidate, violates the operating limit")
    if mappable is None:  # projections, or too few candidates to triangulate: the candidates coloured, the best on top
        order = np.flatnonzero(finite & inside)[np.argsort(-objective[finite & inside], kind="stable")]
        for subset, marker, what in ((order[feasible[order]], "o", ""), (order[~feasible[order]], "X", ", violates the operating limit")):
            if subset.size:
                mappable = ax.scatter(x[subset] * sx, y[subset] * sy, c=np.log10(objective[subset]), cmap=OBJECTIVE_MAP, vmin=levels[0], vmax=levels[-1],
                                      marker=marker, s=16, edgecolors="0.2", linewidths=0.4, zorder=2, label=f"evaluated candidate{what} (colour: worst case)")  # fmt: skip
    _path_and_designs(ax, d, pair, (x0, x1, y0, y1))
    ax.set_xlim(x0 * sx, x1 * sx)
    ax.set_ylim(y0 * sy, y1 * sy)
    finish_axes(ax, xlabel, ylabel, f"Worst case over {pair[0]} and {pair[1]}" + (" (projection)" if projected else ""))
    ax.grid(False)
    return mappable


def _feasibility_line(ax: Axes, d: xr.Dataset, tri: Triangulation, keep: NDArray[np.int64]) -> None:
    """Where the interpolated operating constraint's measure crosses its limit (when it does)."""
    ratio = d["operating_amplitude"].values[keep] / operating_limit(d)
    if not np.all(np.isfinite(ratio)) or not np.min(ratio) < 1.0 < np.max(ratio):
        return
    with plt.rc_context({"hatch.color": LIMIT_COLOUR, "hatch.linewidth": 0.7}):
        ax.tricontourf(tri, ratio, levels=[1.0, float(np.max(ratio)) * 1.01], colors="none", hatches=["////"], zorder=1)
    ax.tricontour(tri, ratio, levels=[1.0], colors=LIMIT_COLOUR, linewidths=1.8, zorder=3)
    ax.fill([], [], facecolor="none", edgecolor=LIMIT_COLOUR, hatch="////", lw=1.8, label=f"{constraint_quantity(d).symbol} at {fmt(d.attrs['operating_frequency_Hz'], '.4g')} Hz above its limit (interpolated)")


def _path_and_designs(ax: Axes, d: xr.Dataset, pair: tuple[str, ...], box: tuple[float, float, float, float]) -> None:
    """The search's path and the compared designs on a panel (values outside the bounds drawn at their edge)."""
    scales = [_axis(d, n)[0] for n in pair]
    columns = [np.clip(d[f"variable_{safe_name(n)}"].values, box[2 * k], box[2 * k + 1]) * scales[k] for k, n in enumerate(pair)]
    path = search_path(d)
    ax.plot(columns[0][path], columns[1][path], "-o", color=PATH_COLOUR, lw=1.3, ms=3.5, mec="white", mew=0.5, zorder=4, label="the search's path: best design so far, in evaluation order")
    for k in (2, 1, 0):
        values = [float(d[f"design_{safe_name(n)}"].values[k]) for n in pair]
        if all(math.isfinite(v) for v in values):
            shown = [min(max(v, box[2 * j]), box[2 * j + 1]) * scales[j] for j, v in enumerate(values)]
            ax.plot(*shown, marker=DESIGN_MARKERS[k], ms=16 if k == 0 else 10, color=DESIGN_COLOURS[k], mec="k", mew=0.9, ls="none", zorder=5, label=design_titles(d)[k])


def search_figure(dataset: xr.Dataset) -> DrawnFigure:
    """The objective over the design variables: a map over two, one panel per pair of the first three (projections),
    or the objective against the one (module docstring)."""
    d = dataset
    names = variable_names(d)
    if len(names) == 1:
        return _search_line(d, names[0])
    pairs = [(names[0], names[1])] if len(names) == 2 else [(names[i], names[j]) for i, j in ((0, 1), (0, 2), (1, 2))]
    projected = len(names) > 2
    q, c, limit = objective_quantity(d), constraint_quantity(d), operating_limit(d)
    objective = q.value(d["objective"].values)
    inside = np.all([(d[f"variable_{safe_name(n)}"].values >= _limits(d, n)[0]) & (d[f"variable_{safe_name(n)}"].values <= _limits(d, n)[1]) for n in names], axis=0)
    levels = _levels(np.where(inside, objective, np.nan))
    fig, axes = new_figure(len(pairs) + projected, panel_height=4.6 if not projected else 3.8, legend_rows=legend_rows(7, 3))
    mappables = [_map_panel(ax, d, pair, levels, projected) for ax, pair in zip(axes, pairs)]
    if projected:
        _progress_panel(axes[-1], d)
    mappable = next((m for m in mappables if m is not None), None)
    if mappable is not None:
        bar = fig.colorbar(mappable, ax=axes[: len(pairs)], extend="max", ticks=levels[::2], shrink=0.9)
        bar.ax.set_yticklabels([fmt(10**t, ".3g") for t in levels[::2]])
        bar.set_label(f"worst case {q.symbol} over the band and the samples [{q.unit}]")
    counts = stage_counts(d)
    caption = Caption(f"The search's {d.sizes['evaluation']} candidates over {' and '.join(names[:3]) if projected else ' and '.join(names)}: each candidate's worst case {q.symbol} over the band and the mistuning samples ({screen_words(d)} screen), in {q.unit}.")
    if projected:
        caption.add("projected", f"{len(names)} variables: each map is a projection, the other variables vary from point to point (a point's colour is its own worst case, the best drawn on top); the last panel is the worst case in evaluation order.")
    else:
        caption.add("fill", "The grey shading is interpolated linearly over triangles between the evaluated candidates (small dots), light where the worst case is small; where there are no candidates it is a guess.")
    caption.add("levels", f"The colour levels are log-spaced from the least worst case ({fmt(10 ** levels[0], '.3g')} {q.unit}) to the {OBJECTIVE_PERCENTILE:g}th percentile ({fmt(10 ** levels[-1], '.3g')} {q.unit}); worse candidates share the darkest grey.")
    caption.add("path", f"The vermillion line joins the best design so far (by the searched score) each time it improved: {len(search_path(d))} steps over {', '.join(f'{v} {k}' for k, v in counts.items() if v)} evaluations.")
    caption.add("designs", f"The blue star is the {design_titles(d)[0]}, the orange square the scene's own (drawn at the edge of the map when it lies outside the bounds).")
    if math.isfinite(limit):
        caption.add("limit", f"Crosses mark candidates whose {c.symbol} at {fmt(d.attrs['operating_frequency_Hz'], '.4g')} Hz exceeds the allowed {fmt(c.value(limit), '.3g')} {c.unit} (the search penalised them)"
                    + ("." if projected else f"; the hatched region bounded by the purple line is where that {c.symbol}, interpolated between the candidates, exceeds it."))  # fmt: skip
    figure_legend(fig, axes, columns=3)
    return DrawnFigure(fig, "design_search", "The objective over the design variables, and the search's path", caption.text())


def _progress_panel(ax: Axes, d: xr.Dataset) -> None:
    """Each candidate's worst case in evaluation order, and the best score so far."""
    q = objective_quantity(d)
    objective, score = q.value(d["objective"].values), q.value(d["score"].values)
    index = np.arange(objective.size)
    ax.plot(index, objective, ".", color="0.35", ms=4, ls="none")
    ax.step(index, np.minimum.accumulate(np.where(np.isfinite(score), score, np.inf)), where="post", color=PATH_COLOUR, lw=1.5)
    recommended = int(d.attrs.get("recommended_evaluation", -1))
    if recommended >= 0:
        ax.plot([recommended], [objective[recommended]], marker=DESIGN_MARKERS[0], ms=16, color=DESIGN_COLOURS[0], mec="k", mew=0.9, ls="none")
    finish_axes(ax, "evaluation (in the order evaluated)", f"worst case {q.label}", "Worst case in evaluation order (line: best score so far)", log=True)
    _plain_log(ax)


def _search_line(d: xr.Dataset, name: str) -> DrawnFigure:
    """The objective against the one design variable."""
    scale, label = _axis(d, name)
    q = objective_quantity(d)
    x, objective = d[f"variable_{safe_name(name)}"].values, q.value(d["objective"].values)
    low, high = _limits(d, name)
    fig, axes = new_figure(1, panel_height=3.8, legend_rows=legend_rows(5, 3))
    ax = axes[0]
    feasible = d["feasible"].values == 1
    ax.plot(x[feasible] * scale, objective[feasible], ".", color="0.2", ms=5, ls="none", label="evaluated candidate")
    if np.any(~feasible):
        ax.plot(x[~feasible] * scale, objective[~feasible], "x", color="0.2", ms=5, ls="none", label="evaluated candidate, violates the operating limit")
    path = search_path(d)
    ax.plot(np.clip(x[path], low, high) * scale, objective[path], "-o", color=PATH_COLOUR, lw=1.3, ms=4, mec="white", mew=0.5, label="the search's path: best design so far")
    for k in (1, 0):
        value, evaluation = float(d[f"design_{safe_name(name)}"].values[k]), design_evaluation(d, k)
        if math.isfinite(value) and evaluation >= 0:
            ax.plot([min(max(value, low), high) * scale], [objective[evaluation]], marker=DESIGN_MARKERS[k], ms=16 if k == 0 else 10, color=DESIGN_COLOURS[k], mec="k", mew=0.9, ls="none", label=design_titles(d)[k])
    ax.set_xlim(low * scale, high * scale)
    finish_axes(ax, label, f"worst case {q.label}", f"The search over {name}", log=True)
    _plain_log(ax)
    figure_legend(fig, axes, columns=3)
    caption = Caption(f"The worst case {q.symbol} over the band and the mistuning samples ({screen_words(d)} screen, {q.unit}, log scale) of each of the search's {d.sizes['evaluation']} candidates against {name}.")
    caption.add("path", f"The vermillion line joins the best design so far each time it improved; the blue star is the {design_titles(d)[0]}, the orange square the scene's own (at the edge when outside the bounds).")
    return DrawnFigure(fig, "design_search", "The objective over the design variable, and the search's path", caption.text())


class PlainLogFormatter(LogFormatter):
    """matplotlib's choice of which log-axis ticks to label, written as plain numbers: 0.2, 3."""

    def _num_to_string(self, x: float, vmin: float, vmax: float) -> str:
        return f"{x:g}"


def _plain_log(ax: Axes, which: str = "y") -> None:
    """Plain numbers on a log axis (0.5, 2), minor ticks labelled when it spans about a decade or less."""
    axis = ax.yaxis if which == "y" else ax.xaxis
    axis.set_major_formatter(FormatStrFormatter("%g"))
    axis.set_minor_formatter(PlainLogFormatter(labelOnlyBase=False, minor_thresholds=(1.0, 0.5)))


# ------------------------------------------------------------------------------------------ the responses
def _worst_point(d: xr.Dataset, k: int) -> tuple[float, float]:
    """(frequency [Hz], the objective's measure [m or N]) of a compared design's nominal worst case: the screen's, or the linear peak's."""
    value = float(d["design_sample_value"].values[k, 0])
    evaluation = design_evaluation(d, k)
    if evaluation >= 0:
        return float(d["sample_frequency"].values[evaluation, 0]), value
    curve = d["response_linear"].values[k]
    return (float(d["response_frequency"].values[int(np.nanargmax(curve))]), value) if np.any(np.isfinite(curve)) else (math.nan, math.nan)


def _operating(ax: Axes, d: xr.Dataset) -> None:
    """The operating frequency (vertical line) and the allowed value there (a bar, where the constraint limits the
    objective's measure: the axes' own), when the scene sets a limit."""
    at, limit, c = float(d.attrs.get("operating_frequency_Hz", math.nan)), operating_limit(d), constraint_quantity(d)
    if math.isfinite(at) and math.isfinite(limit):
        ax.axvline(at, **_OPERATING, zorder=1)
        if c.name == objective_quantity(d).name:
            ax.plot([at], [c.value(limit)], marker="_", ms=22, mew=2.5, color="k", ls="none", zorder=6)


def _design_panel(ax: Axes, d: xr.Dataset, k: int) -> tuple[list[float], set[str]]:
    """Every motion of compared design ``k`` (nominal): the values drawn [the page's unit] (for the axis limits) and which
    kinds of :data:`_LOOKS` were drawn (for the legend)."""
    f, colour, q = d["response_frequency"].values, DESIGN_COLOURS[k], objective_quantity(d)
    linear, fits = q.value(d["response_linear"].values[k]), d["response_linear_fits"].values[k] == 1
    ax.plot(f, np.where(fits, linear, np.nan), color=colour, **STABLE_STYLE)
    ax.plot(f, np.where(~fits, linear, np.nan), color="0.6", lw=0.8, ls=":")
    drawn, kinds = [linear[fits]], {"contact_free"} | ({"crossing"} if np.any(~fits & np.isfinite(linear)) else set())
    for name in ("impact_plus", "impact_minus"):
        x, state = q.value(d[f"response_{name}"].values[k]), d[f"response_{name}_stable"].values[k]
        ax.plot(f, np.where(state == 1, x, np.nan), color=colour, lw=2.4)
        ax.plot(f, np.where(state == 0, x, np.nan), color=colour, **UNSTABLE_STYLE)
        drawn.append(x[state >= 0])
        kinds |= {kind for kind, flag in (("impact_stable", 1), ("impact_unstable", 0)) if np.any(state == flag)}
    evaluation = design_evaluation(d, k)
    rows = np.flatnonzero((d["certificate_evaluation"].values == evaluation) & (d["certificate_sample"].values == 0)) if evaluation >= 0 else []
    for r in rows:
        bf, ba, bs = (d[f"branch_{n}"].values[r] for n in ("frequency", "amplitude", "stable"))
        for flag, kind, look in ((0, "branch_unstable", {"color": "0.65", "ms": 1.6, "zorder": 2}), (1, "branch_stable", {"color": "0.15", "ms": 2.2, "zorder": 3})):
            on = (bs == flag) & np.isfinite(ba)
            ax.plot(bf[on], q.value(ba[on]), ".", ls="none", **look)
            kinds |= {kind} if np.any(on) else set()
        drawn.append(q.value(ba[np.isfinite(ba)]))
        worst, where = float(d["certificate_worst"].values[r]), float(d["certificate_frequency"].values[r])
        if math.isfinite(worst):
            ax.plot([where], [q.value(worst)], marker="*", ms=14, color=CERTIFIED_COLOUR, mec="k", mew=0.6, ls="none", zorder=7)
            kinds.add("certified")
    where, value = _worst_point(d, k)
    ax.plot([where], [q.value(value)], marker="o", ms=12, mfc="none", mec="k", mew=1.4, ls="none", zorder=6)
    return [float(v) for part in drawn for v in np.asarray(part).ravel() if np.isfinite(v) and v > 0.0], kinds


#: The legend's entries for the motions and points, by the kind :func:`_design_panel` says it drew.
_LOOKS = {
    "contact_free": ({"color": "k", **STABLE_STYLE}, "contact-free motion, clears the stop"),
    "crossing": ({"color": "0.6", "lw": 0.8, "ls": ":"}, "contact-free motion crossing the stop (not a motion)"),
    "impact_stable": ({"color": "k", "lw": 2.4}, "period-1 impact orbit, stable (either root)"),
    "impact_unstable": ({"color": "k", **UNSTABLE_STYLE}, "period-1 impact orbit, unstable"),
    "branch_stable": ({"color": "0.15", "marker": ".", "ls": "none"}, "continued branch, stable"),
    "branch_unstable": ({"color": "0.65", "marker": ".", "ls": "none"}, "continued branch, unstable"),
    "worst": ({"marker": "o", "ms": 10, "mfc": "none", "mec": "k", "mew": 1.4, "ls": "none"}, "worst case over the band (screen)"),
    "certified": ({"marker": "*", "ms": 12, "color": CERTIFIED_COLOUR, "mec": "k", "mew": 0.6, "ls": "none"}, "certified worst case (continuation)"),
}


def response_figure(dataset: xr.Dataset) -> DrawnFigure:
    """The compared designs' worst stable motion (the objective's measure) side by side, then each one's every motion (module docstring)."""
    d = dataset
    f = d["response_frequency"].values
    present = present_designs(d)
    compare = len(present) > 1
    q, c, limit = objective_quantity(d), constraint_quantity(d), operating_limit(d)
    fig, axes = new_figure(len(present) + compare, panel_height=3.3, legend_rows=legend_rows(len(present) + len(_LOOKS) + 1, 3))
    if compare:
        ax = axes[0]
        for k in sorted(present, reverse=True):  # the recommended design on top, drawn narrower than the others
            ax.plot(f, q.value(worst_stable(d, k)), color=DESIGN_COLOURS[k], lw=1.8 if k == 0 else 3.2, zorder=3 - k)
            ax.plot(*(np.array(_worst_point(d, k)) * (1.0, q.scale)), marker="o", ms=12, mfc="none", mec="k", mew=1.4, ls="none", zorder=6)
        _operating(ax, d)
        ax.set_xlim(float(f[0]), float(f[-1]))
        finish_axes(ax, _FREQUENCY, q.label, "Worst stable motion of each design (no mistuning)", log=True)
        _plain_log(ax)
    kinds = {"worst"}
    for ax, k in zip(axes[int(compare) :], present):
        values, drawn = _design_panel(ax, d, k)
        kinds |= drawn
        _operating(ax, d)
        if values:
            ax.set_ylim(0.7 * min(values), 1.6 * max(values))
        ax.set_xlim(float(f[0]), float(f[-1]))
        finish_axes(ax, _FREQUENCY, q.label, f"{design_titles(d)[k][:1].upper()}{design_titles(d)[k][1:]}: {design_text(d, k)}", log=True)
        _plain_log(ax)
    entries = [Line2D([], [], color=DESIGN_COLOURS[k], lw=2.4, label=f"{design_titles(d)[k]}: {design_text(d, k)}") for k in present]
    entries += [Line2D([], [], **look, label=label) for kind, (look, label) in _LOOKS.items() if kind in kinds]
    caption = Caption(f"{q.symbol} ({q.description}, {q.unit}, log scale) of the compared designs without mistuning; colour: whose design.")
    if compare:
        caption.add("compare", f"The first panel overlays each design's worst stable motion at each frequency (gaps: no {screen_words(d)} period-1 motion is stable there); the others show every motion of one design.")
    roots = "the bumper orbits grown from both roots of the rigid twin's impulse equation, where its shots converged" if screen_words(d) == "bumper" else "both roots of the impulse equation, where admissible"
    caption.add("lines", f"Thin solid: the contact-free motion where it clears the stop; thick solid and dashed: the stable and unstable period-1 impact orbits ({roots}); dotted grey: the contact-free motion where it would cross the stop, not a motion.")
    if kinds & {"branch_stable", "branch_unstable"}:
        caption.add("branches", f"Dots: orbits of the branches continued from the {'bumper orbits shot from the rigid twin' + chr(39) + 's closed forms' if screen_words(d) == 'bumper' else 'closed-form ones'} (dark stable, light unstable).")
    if "certified" in kinds:
        caption.add("certified", "The vermillion star is the certified worst case over the band (continuation, no mistuning).")
    caption.add("worst", "The black ring is the worst case over the band without mistuning (the screen's value; the linear absorber's band peak).")
    if math.isfinite(limit):
        at = fmt(d.attrs["operating_frequency_Hz"], ".4g")
        allowed = f"{fmt(c.value(limit), '.3g')} {c.unit}"
        if c.name == q.name:
            entries.append(Line2D([], [], **_OPERATING, marker="_", ms=14, mew=2.5, mec="k", label=f"operating frequency {at} Hz and the allowed {c.symbol} there"))
            caption.add("operating", f"The dash-dotted line is the operating frequency, {at} Hz, and the black bar on it the allowed {c.symbol} there ({allowed}).")
        else:  # the constraint limits another measure than these axes show: its limit is not drawn on them
            entries.append(Line2D([], [], **_OPERATING, label=f"operating frequency {at} Hz (its constraint limits {c.symbol}, not drawn)"))
            caption.add("operating", f"The dash-dotted line is the operating frequency, {at} Hz, where the operating constraint limits {c.symbol} (allowed {allowed}), a measure these axes do not show.")
    figure_legend(fig, axes, extra=entries, columns=3)
    return DrawnFigure(fig, "design_response", "The compared designs' frequency responses: every coexisting motion", caption.text())


# ----------------------------------------------------------------------------------------- robustness
def _certified_above(d: xr.Dataset, k: int, screened: NDArray[np.float64]) -> list[tuple[int, float]]:
    """(sample, certified worst case [the page's unit]) of compared design ``k``'s certificates whose value is above
    the screen's (``screened`` [the page's unit] per sample)."""
    evaluation = design_evaluation(d, k)
    out = []
    for r in np.flatnonzero(d["certificate_evaluation"].values == evaluation) if evaluation >= 0 else ():
        sample, certified = int(d["certificate_sample"].values[r]), objective_quantity(d).value(float(d["certificate_worst"].values[r]))
        if math.isfinite(certified) and math.isfinite(float(screened[sample])) and certified > float(screened[sample]) * (1.0 + 1e-6):
            out.append((sample, certified))
    return out


def robustness_figure(dataset: xr.Dataset) -> DrawnFigure:
    """The worst case of each compared design under every mistuning sample, as an empirical distribution, the
    nominal sample marked."""
    d = dataset
    q = objective_quantity(d)
    values = q.value(d["design_sample_value"].values)
    samples = d.sizes["sample"]
    fig, axes = new_figure(1, panel_height=3.6, legend_rows=legend_rows(4, 2))
    ax = axes[0]
    constant, raised = [], []
    for k in range(values.shape[0]):
        row = np.sort(values[k][np.isfinite(values[k])])
        if not row.size:
            continue
        share = np.arange(row.size + 1) / row.size
        above = _certified_above(d, k, values[k])
        note = f" (screened; certified up to {fmt(max(c for _, c in above), '.3g')} {q.unit})" if above else ""
        ax.step(np.r_[row[0], row], share, where="post", color=DESIGN_COLOURS[k], lw=2.0,
                label=f"{design_titles(d)[k]}: worst {fmt(row[-1], '.3g')} {q.unit}, median {fmt(float(np.median(row)), '.3g')} {q.unit}{note}")  # fmt: skip
        nominal = float(values[k, 0])
        if math.isfinite(nominal):
            ax.plot([nominal], [np.searchsorted(row, nominal, side="right") / row.size], "o", ms=8, color=DESIGN_COLOURS[k], mec="k", mew=1.0, zorder=5)
        for sample, certified in above:  # the screen missed this sample's worst motion: the certified one, joined to it
            y = np.searchsorted(row, float(values[k, sample]), side="right") / row.size
            ax.plot([float(values[k, sample]), certified], [y, y], color=CERTIFIED_COLOUR, lw=1.0, ls=":", zorder=4)
            ax.plot([certified], [y], "*", ms=13, color=CERTIFIED_COLOUR, mec="k", mew=0.6, zorder=6)
            raised.append((design_titles(d)[k], sample, certified))
        if row[-1] - row[0] <= 1e-9 * row[-1] and row.size > 1:
            constant.append(design_titles(d)[k])
    ax.set_ylim(-0.03, 1.05)
    finite = np.r_[values[np.isfinite(values) & (values > 0.0)], [c for _, _, c in raised]]
    if finite.size and np.max(finite) > 4.0 * np.min(finite):  # a design far worse than the others: a log axis keeps both legible
        ax.set_xscale("log")
        _plain_log(ax, "x")
    finish_axes(ax, f"worst case {q.symbol} over the band [{q.unit}]", "share of samples at or below", "Worst case under mistuning: empirical distribution over the samples")
    nominal = Line2D([], [], marker="o", ms=8, color="0.7", mec="k", mew=1.0, ls="none", label="the nominal design (sample 0)")
    extra = [nominal] + ([Line2D([], [], marker="*", ms=13, color=CERTIFIED_COLOUR, mec="k", mew=0.6, ls=":", lw=1.0, label="certified worst case of a sample, where above the screen's")] if raised else [])
    figure_legend(fig, axes, extra=extra, columns=2)
    spreads = mistuning_spreads(d)
    if samples > 1 and spreads:
        drawn = f"{samples} samples: the nominal design and {samples - 1} of a Latin hypercube (seed {d.attrs.get('mistuning_seed', '?')}) over {' and '.join(s.text() for s in spreads)}"
    else:
        drawn = "one sample: no mistuning, the nominal design only"
    caption = Caption(f"Each compared design's largest stable {q.symbol} over the band under each mistuning sample, as the share of samples at or below a value (a step per sample); {drawn}.")
    caption.add("nominal", "Dots mark the nominal design's value on each curve.")
    if raised:
        which = "; ".join(f"{title}, sample {sample}: {fmt(value, '.4g')} {q.unit}" for title, sample, value in raised)
        screen = ("a coarse brute force: few frequencies and starts" if np.any(d["sample_motion"].values == 3) else
                  "period-1 bumper orbits" if d.attrs.get("screen") == "bumper_orbits" else "the closed forms: period-1 motions")  # fmt: skip
        caption.add("certified", f"The curves are the screen's values ({screen}). Vermillion stars mark where the certification (continuation and brute force) found a larger motion under a certified sample, joined to the screen's value ({which}): the distribution above the screen's values is not known for the other samples.")
    if constant:
        caption.add("constant", f"The same value under every sample for {' and '.join(t if t.startswith('the ') else 'the ' + t for t in constant)}: the mistuned scalars do not change it (a stop that is never reached, or none).")
    return DrawnFigure(fig, "design_robustness", "Worst case under mistuning", caption.text())
