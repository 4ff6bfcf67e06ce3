"""The design page's first figure, the objective over the design variables (:func:`search_figure`): a grid search drawn
as the map it is (one cell per candidate, its own value), any other search as filled contours interpolated from the
evaluated candidates on log-spaced levels up to a high percentile, with the search's path (the best design so far, in
evaluation order); the recommended and the scene's designs; with more than two variables one panel per pair of the
first three (projections: the other variables vary); with one, the objective against it."""

from __future__ import annotations

import math

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.colors import BoundaryNorm
from matplotlib.tri import Triangulation, TriAnalyzer
from numpy.typing import NDArray

from vibroimpact.kinds.design.cautions import SYMBOLS
from vibroimpact.kinds.design.answer import design_evaluation, design_titles, screen_words, search_path, stage_counts, unit_text, variable_names
from vibroimpact.kinds.design.palette import DESIGN_COLOURS, DESIGN_MARKERS, LIMIT_COLOUR, OBJECTIVE_MAP, OBJECTIVE_PERCENTILE, PATH_COLOUR
from vibroimpact.kinds.design.quantity import constraint_quantity, objective_quantity, operating_limit
from vibroimpact.kinds.design.scene import safe_name
from vibroimpact.reporting.page import DrawnFigure
from vibroimpact.reporting.style import Caption, figure_legend, finish_axes, fmt, legend_rows, new_figure, plain_log

import matplotlib.pyplot as plt  # after style: the Agg backend is selected

#: A grid search's map (:func:`grid_cells`): the values of the two variables and the evaluation in each cell (y, x).
GridCells = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]

__all__ = ["search_figure", "grid_cells"]


def _axis(dataset: xr.Dataset, name: str) -> tuple[float, str]:
    """(factor to the page's units, axis label) of a design variable."""
    if name == "clearance":
        return 1e3, "clearance Delta [mm]"
    if name == "restitution":
        return 1.0, "restitution R [-]"
    unit = unit_text(str(dataset[f"variable_{safe_name(name)}"].attrs.get("units", "1")))
    return 1.0, f"{variable_words(name)} [{unit or '-'}]"


def variable_words(name: str) -> str:
    """A design variable as a page names it: its words and its symbol (``bumper stiffness K_b``, ``clearance Delta``),
    not the scene's key (``bumper_stiffness``); a layout scalar without a symbol keeps its key (``k2``, ``mass[x3]``)."""
    words = name.replace("_", " ")
    symbol = SYMBOLS.get(name)
    return f"{words} {symbol}" if symbol else words


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


def _map_panel(ax: Axes, d: xr.Dataset, pair: tuple[str, str], levels: NDArray[np.float64], projected: bool, cells: GridCells | None) -> object:
    """One panel of the search's map over ``pair`` (``cells``: the grid search's map of them, :func:`grid_cells`); the
    colour mapping drawn (for the colour bar)."""
    (sx, xlabel), (sy, ylabel) = _axis(d, pair[0]), _axis(d, pair[1])
    x, y = (d[f"variable_{safe_name(n)}"].values for n in pair)
    objective = objective_quantity(d).value(d["objective"].values)
    finite = np.isfinite(objective) & (objective > 0.0)
    feasible = d["feasible"].values == 1
    constrained = math.isfinite(operating_limit(d))
    (x0, x1), (y0, y1) = _limits(d, pair[0]), _limits(d, pair[1])
    mappable = None
    inside = (x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)  # the scene's design may lie outside the bounds
    if cells is not None:
        mappable = _cell_map(ax, d, cells, (sx, sy), levels)
    elif not projected:
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
    _path_and_designs(ax, d, pair, (x0, x1, y0, y1), path=cells is None)
    ax.set_xlim(x0 * sx, x1 * sx)
    ax.set_ylim(y0 * sy, y1 * sy)
    finish_axes(ax, xlabel, ylabel, f"Worst case over {variable_words(pair[0])} and {variable_words(pair[1])}" + (" (projection)" if projected else ""))
    ax.grid(False)
    return mappable


#: The gid of the region where the interpolated constraint breaks its limit (hatched).
HATCHED = "limit:hatched"


def _hatched(figure: object) -> bool:
    """Whether a panel of ``figure`` hatches the region where the constraint breaks its limit."""
    return any(collection.get_gid() == HATCHED for ax in figure.axes for collection in ax.collections)  # type: ignore[attr-defined]


def _feasibility_line(ax: Axes, d: xr.Dataset, tri: Triangulation, keep: NDArray[np.int64]) -> None:
    """Where the interpolated operating constraint's measure crosses its limit (when it does)."""
    ratio = d["operating_amplitude"].values[keep] / operating_limit(d)
    if not np.all(np.isfinite(ratio)) or not np.min(ratio) < 1.0 < np.max(ratio):
        return
    with plt.rc_context({"hatch.color": LIMIT_COLOUR, "hatch.linewidth": 0.7}):
        hatched = ax.tricontourf(tri, ratio, levels=[1.0, float(np.max(ratio)) * 1.01], colors="none", hatches=["////"], zorder=1)
    hatched.set_gid(HATCHED)  # the caption speaks of the hatched region only where it is drawn
    ax.tricontour(tri, ratio, levels=[1.0], colors=LIMIT_COLOUR, linewidths=1.8, zorder=3)
    ax.fill([], [], facecolor="none", edgecolor=LIMIT_COLOUR, hatch="////", lw=1.8, label=f"{constraint_quantity(d).symbol} at {fmt(d.attrs['operating_frequency_Hz'], '.4g')} Hz above its limit (interpolated)")


def grid_cells(d: xr.Dataset, pair: tuple[str, str]) -> GridCells | None:
    """The grid search's candidates over ``pair`` as a map: (x values, y values, evaluation index of each cell, shape
    (y, x)); None unless the dataset's grid stage evaluated every cell of a full grid over these two variables."""
    counts = stage_counts(d)
    if len(variable_names(d)) != 2 or counts.get("grid", 0) == 0:
        return None
    grid = np.flatnonzero(d["evaluation_stage"].values == list(counts).index("grid"))
    x, y = (d[f"variable_{safe_name(n)}"].values[grid] for n in pair)
    xs, ys = np.unique(x), np.unique(y)
    if xs.size < 2 or ys.size < 2 or xs.size * ys.size != grid.size:
        return None
    index = np.full((ys.size, xs.size), -1, dtype=np.int64)
    index[np.searchsorted(ys, y), np.searchsorted(xs, x)] = grid
    return (xs, ys, index) if np.all(index >= 0) else None


def _edges(centres: NDArray[np.float64]) -> NDArray[np.float64]:
    """Cell edges around grid values: half-way between neighbours, half a step beyond the ends."""
    middle = 0.5 * (centres[1:] + centres[:-1])
    return np.concatenate([[centres[0] - (middle[0] - centres[0])], middle, [centres[-1] + (centres[-1] - middle[-1])]])


def _cell_map(ax: Axes, d: xr.Dataset, cells: GridCells, scales: tuple[float, float], levels: NDArray[np.float64]) -> object:
    """A grid search drawn as the map it is: one cell per candidate, its own worst case (no interpolation); the cells
    that break the operating limit hatched and outlined."""
    xs, ys, index = cells
    objective = objective_quantity(d).value(d["objective"].values)[index]
    norm = BoundaryNorm(levels, OBJECTIVE_MAP.N, extend="max")
    with np.errstate(divide="ignore", invalid="ignore"):
        shown = np.where(np.isfinite(objective) & (objective > 0.0), np.log10(objective), np.nan)
    x_edges, y_edges = _edges(xs) * scales[0], _edges(ys) * scales[1]
    mappable = ax.pcolormesh(x_edges, y_edges, np.ma.masked_invalid(shown), cmap=OBJECTIVE_MAP, norm=norm, zorder=0)
    if math.isfinite(operating_limit(d)):
        broken = d["feasible"].values[index] != 1
        if np.any(broken):
            with plt.rc_context({"hatch.color": LIMIT_COLOUR, "hatch.linewidth": 0.7}):
                ax.pcolor(x_edges, y_edges, np.ma.masked_where(~broken, np.ones(broken.shape)), hatch="////", facecolor="none",
                          edgecolor=LIMIT_COLOUR, linewidth=0.0, zorder=1)  # fmt: skip
            ax.contour(xs * scales[0], ys * scales[1], broken.astype(float), levels=[0.5], colors=LIMIT_COLOUR, linewidths=1.8, zorder=3)
            ax.fill([], [], facecolor="none", edgecolor=LIMIT_COLOUR, hatch="////", lw=1.8, label=f"{constraint_quantity(d).symbol} at {fmt(d.attrs['operating_frequency_Hz'], '.4g')} Hz above its limit (the candidate's own value)")
    empty = ~np.isfinite(shown)
    if np.any(empty):
        ax.plot(xs[np.nonzero(empty)[1]] * scales[0], ys[np.nonzero(empty)[0]] * scales[1], "x", color="0.1", ms=5, ls="none", label="candidate without a value (no stable motion found)")
    return mappable


def _path_and_designs(ax: Axes, d: xr.Dataset, pair: tuple[str, ...], box: tuple[float, float, float, float], path: bool = True) -> None:
    """The search's path (``path``) and the compared designs on a panel (values outside the bounds drawn at their edge)."""
    scales = [_axis(d, n)[0] for n in pair]
    columns = [np.clip(d[f"variable_{safe_name(n)}"].values, box[2 * k], box[2 * k + 1]) * scales[k] for k, n in enumerate(pair)]
    if path:
        steps = search_path(d)
        ax.plot(columns[0][steps], columns[1][steps], "-o", color=PATH_COLOUR, lw=1.3, ms=3.5, mec="white", mew=0.5, zorder=4, label="the search's path: best design so far, in evaluation order")
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
    cells = None if projected else grid_cells(d, pairs[0])
    mappables = [_map_panel(ax, d, pair, levels, projected, cells) for ax, pair in zip(axes, pairs)]
    if projected:
        _progress_panel(axes[-1], d)
    mappable = next((m for m in mappables if m is not None), None)
    if mappable is not None:
        bar = fig.colorbar(mappable, ax=axes[: len(pairs)], extend="max", ticks=levels[::2], shrink=0.9)
        bar.ax.set_yticklabels([fmt(10**t, ".3g") for t in levels[::2]])
        bar.set_label(f"worst case {q.symbol} over the band and the samples [{q.unit}]")
    if cells is not None:
        caption = _grid_caption(d, cells, levels)
    else:
        counts = stage_counts(d)
        caption = Caption(f"The search's {d.sizes['evaluation']} candidates over {' and '.join(map(variable_words, names[:3] if projected else names))}: each candidate's worst case {q.symbol} over the band and the mistuning samples ({screen_words(d)} screen), in {q.unit}.")
        if projected:
            caption.add("projected", f"{len(names)} variables: each map is a projection, the other variables vary from point to point (a point's colour is its own worst case, the best drawn on top); the last panel is the worst case in evaluation order" + ("; there crosses break the operating limit and the line is the best so far of the others." if math.isfinite(limit) else ", the line the best so far."))
        else:
            caption.add("fill", "The grey shading is interpolated linearly over triangles between the evaluated candidates (small dots), light where the worst case is small; where there are no candidates it is a guess.")
        caption.add("levels", f"The colour levels are log-spaced from the least worst case ({fmt(10 ** levels[0], '.3g')} {q.unit}) to the {OBJECTIVE_PERCENTILE:g}th percentile ({fmt(10 ** levels[-1], '.3g')} {q.unit}); worse candidates share the darkest grey.")
        caption.add("path", f"The vermillion line joins the best design so far (by the searched score) each time it improved: {len(search_path(d))} steps over {', '.join(f'{v} {k}' for k, v in counts.items() if v)} evaluations.")
        caption.add("designs", f"The blue star is the {design_titles(d)[0]}, the orange square the scene's own (drawn at the edge of the map when it lies outside the bounds).")
        if math.isfinite(limit):
            caption.add("limit", f"Crosses mark candidates whose {c.symbol} at {fmt(d.attrs['operating_frequency_Hz'], '.4g')} Hz exceeds the allowed {fmt(c.value(limit), '.3g')} {c.unit} (the search penalised them)"
                        + (f"; the hatched region bounded by the purple line is where that {c.symbol}, interpolated between the candidates, exceeds it." if _hatched(fig) else
                           "; no candidate keeps it, so no region is hatched." if not np.any(d["operating_amplitude"].values <= limit) else "."))  # fmt: skip
    figure_legend(fig, axes, columns=3)
    if cells is not None:
        return DrawnFigure(fig, "design_search", "The map of the grid: the objective of every candidate", caption.text())
    return DrawnFigure(fig, "design_search", "The objective over the design variables, and the search's path", caption.text())


def _grid_caption(d: xr.Dataset, cells: GridCells, levels: NDArray[np.float64]) -> Caption:
    """What the grid's map draws."""
    xs, ys, index = cells
    q, c, limit = objective_quantity(d), constraint_quantity(d), operating_limit(d)
    names = variable_names(d)
    caption = Caption(f"The grid search's {index.size} candidates ({xs.size} values of {names[0]} x {ys.size} of {names[1]}, bounds included): each cell is one candidate, "
                      f"shaded by its own worst case {q.symbol} over the band and the mistuning samples ({screen_words(d)} screen, {q.unit}); nothing is interpolated.")  # fmt: skip
    caption.add("levels", f"The colour levels are log-spaced from the least worst case ({fmt(10 ** levels[0], '.3g')} {q.unit}) to the {OBJECTIVE_PERCENTILE:g}th percentile ({fmt(10 ** levels[-1], '.3g')} {q.unit}); worse candidates share the darkest grey, light is good.")
    caption.add("designs", f"The blue star is the {design_titles(d)[0]}, the orange square the scene's own (drawn at the edge of the map when it lies outside the bounds).")
    if math.isfinite(limit):
        broken = int(np.sum(d["feasible"].values[index] != 1))
        caption.add("limit", f"{broken} of the {index.size} candidates have a {c.symbol} at {fmt(d.attrs['operating_frequency_Hz'], '.4g')} Hz above the allowed {fmt(c.value(limit), '.3g')} {c.unit}"
                    + (": their cells are hatched, bounded by the purple line (the search penalised them)." if broken else "."))  # fmt: skip
    return caption


def _progress_panel(ax: Axes, d: xr.Dataset) -> None:
    """Each candidate's worst case in evaluation order, and the best so far among those that keep the operating limit
    (all, without one): a penalised score is no worst case, and drawn it stretched the axis to hundreds of mm."""
    q = objective_quantity(d)
    objective, score = q.value(d["objective"].values), q.value(d["score"].values)
    index = np.arange(objective.size)
    keeps = np.isfinite(score) & (d["feasible"].values == 1)
    ax.plot(index[keeps], objective[keeps], ".", color="0.35", ms=4, ls="none")
    ax.plot(index[~keeps], objective[~keeps], "x", color="0.35", ms=4, mew=0.8, ls="none")  # breaks the limit: no best
    best = np.minimum.accumulate(np.where(keeps, score, np.inf))
    if np.any(keeps):
        ax.step(index, np.where(np.isfinite(best), best, np.nan), where="post", color=PATH_COLOUR, lw=1.5)
    line = ("line: best so far" + (" keeping the limit" if math.isfinite(operating_limit(d)) else "")) if np.any(keeps) else "none keeps the limit"
    recommended = int(d.attrs.get("recommended_evaluation", -1))
    if recommended >= 0:
        ax.plot([recommended], [objective[recommended]], marker=DESIGN_MARKERS[0], ms=16, color=DESIGN_COLOURS[0], mec="k", mew=0.9, ls="none")
    finish_axes(ax, "evaluation (in the order evaluated)", f"worst case {q.label}", f"Worst case in evaluation order ({line})", log=True)
    plain_log(ax)


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
    finish_axes(ax, label, f"worst case {q.label}", f"The search over {variable_words(name)}", log=True)
    plain_log(ax)
    figure_legend(fig, axes, columns=3)
    caption = Caption(f"The worst case {q.symbol} over the band and the mistuning samples ({screen_words(d)} screen, {q.unit}, log scale) of each of the search's {d.sizes['evaluation']} candidates against {variable_words(name)}.")
    caption.add("path", f"The vermillion line joins the best design so far each time it improved; the blue star is the {design_titles(d)[0]}, the orange square the scene's own (at the edge when outside the bounds).")
    return DrawnFigure(fig, "design_search", "The objective over the design variable, and the search's path", caption.text())


# ------------------------------------------------------------------------------------------ the responses
