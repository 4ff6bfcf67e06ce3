"""No curve hidden under an identical one: where curves of a panel coincide, the ones beneath are drawn again as
wider bands of their own colour around the one on top, and the caption says which coincide where.

A figure draws its curves as usual, then hands each panel's curves to :func:`reveal_coincident` in drawing order
(the first beneath the others). Two curves coincide at a point where both have a value and they lie within
:data:`TOLERANCE` of the panel's height apart (on a log axis, in decades), the width of a line, or within the upper
curve's marker size where it has markers (a marker hides a curve a line's width away), over a stretch at
least :data:`MIN_STRETCH` of the axis wide (a crossing is not a coincidence). Each curve beneath n coinciding ones is
drawn again there, in its own colour and line style (solid, dashed or dotted as it is), n x :data:`BAND_STEP` wider
than the widest of them and behind them (n at most :data:`MAX_BANDS`: deeper ones share the widest band, and the
caption names them): every coinciding curve shows as a band around the next. Stable (solid) and
unstable (dashed) stay told apart, as the pages draw them. :func:`coincidence_phrase` is the caption's sentence.

A constant shared by several curves (exactly 0 where none of several restitution ratios impacts) is not a
coincidence to draw as stacked bands, which read as data: over every stretch where two or more curves take the same
constant value, the curves are left out and the constant is drawn once (:data:`~vibroimpact.reporting.style.SHARED_STYLE`),
labelled with whose it is ("R = 0.2 ... 0.9 (all 8): exactly 0 (no impacts)": the figure's legend shows it, whatever
entries the page gives it), and the caption says so (:class:`Shared`).

The bands carry the gid ``beneath:<gid of the curve>``, a shared constant ``shared:<gids of its curves, joined by +>``
(tests find them by it).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable, Sequence

import matplotlib as mpl
import numpy as np
from matplotlib.axes import Axes
from matplotlib.lines import Line2D

from vibroimpact.reporting.style import SHARED_STYLE, fmt

__all__ = ["Coincidence", "Shared", "reveal_coincident", "coincidence_phrase", "series_names", "TOLERANCE", "MIN_STRETCH", "BAND_STEP", "MAX_BANDS", "SAME"]

#: Largest distance of two coinciding curves, as a fraction of the panel's height (log axes: of its decades); about a
#: line's width on a panel of the pages.
TOLERANCE = 0.005
#: Shortest stretch of coincidence that counts, as a fraction of the axis' width; shorter ones are crossings.
MIN_STRETCH = 0.03
#: Largest relative difference of two values that are the same constant (round-off only).
SAME = 1e-9
#: Width each curve beneath adds to the band around the curves above it [pt] (1 pt, 1.5 px, on each side).
BAND_STEP = 2.0
#: Most bands stacked around a curve: deeper curves share the widest band (nine coinciding restitution ratios made a
#: band of 8 steps, 0.45-1.0 mm around one value of 0.67 mm on a log axis, read as scatter); the caption names them all.
MAX_BANDS = 3


@dataclass(frozen=True)
class Coincidence:
    """Curve ``lower`` lies under curve ``upper`` (the last drawn of those coinciding with it there) over
    ``stretches`` [(start, end) of the x axis]; ``everywhere``: wherever ``lower`` has values; ``axis``: the width of the
    x axis (gaps narrower than :data:`MIN_STRETCH` of it are joined in captions)."""

    lower: str
    upper: str
    stretches: tuple[tuple[float, float], ...]
    everywhere: bool
    axis: float


@dataclass(frozen=True)
class Shared:
    """Curves ``names`` (of ``total`` on the panel) all take the constant ``value`` over ``stretches`` [(start, end)
    of the x axis], where it is drawn once for all of them; ``meaning``: what the value says ("no impacts", for 0);
    ``axis``: the width of the x axis."""

    names: tuple[str, ...]
    value: float
    stretches: tuple[tuple[float, float], ...]
    total: int
    axis: float
    meaning: str = ""

    @property
    def label(self) -> str:
        """The panel's label of the shared line: whose it is and what it is."""
        value = "exactly 0" if self.value == 0.0 else f"constant {fmt(self.value, '.4g')}"  # exact: a zero is a zero
        return f"{series_names(self.names, self.total)}: {value}{f' ({self.meaning})' if self.meaning else ''}"


def series_names(names: Sequence[str], total: int) -> str:
    """Several series named at once: "R = 0.2, 0.6", "R = 0.1 ... 0.9 (all 9)" where they are all of the panel's and
    more than three, else each ("(b), (c) and (d)")."""
    parts = [name.split(" = ", 1) for name in names]
    if len(names) > 1 and all(len(p) == 2 for p in parts) and len({p[0] for p in parts}) == 1:
        values = [p[1] for p in parts]
        if len(values) > 3 and len(values) == total:
            return f"{parts[0][0]} = {values[0]} ... {values[-1]} (all {total})"
        return f"{parts[0][0]} = {', '.join(values)}"
    return _names(list(names))


def _share_constants(ax: Axes, drawn: list[tuple[str, Sequence[Line2D], tuple[np.ndarray, np.ndarray]]], x_span: float, min_stretch: float, meaning: str) -> list[Shared]:
    """Where two or more curves of ``drawn`` (on one grid) take the same constant over a stretch at least
    ``min_stretch`` of the axis wide: leave them out there and draw the constant once, labelled for the legend;
    return what was shared."""
    if len(drawn) < 2:
        return []
    x = drawn[0][2][0]
    same_grid = [k for k, (_, _, (xk, _)) in enumerate(drawn) if xk.shape == x.shape and np.array_equal(xk, x, equal_nan=True)]
    if len(same_grid) < 2:
        return []
    ys = np.array([drawn[k][2][1] for k in same_grid])
    finite = ys[np.isfinite(ys)]
    scale = float(np.max(np.abs(finite), initial=0.0)) or 1.0
    atol = SAME * scale
    with np.errstate(invalid="ignore"):
        flat = np.isfinite(ys[:, 1:]) & (np.abs(np.diff(ys, axis=1)) <= atol)
    levels: list[float] = []
    for value in np.sort(ys[:, :-1][flat]):
        if not levels or value - levels[-1] > atol:
            levels.append(float(value))
    found: list[Shared] = []
    for level in levels:
        with np.errstate(invalid="ignore"):
            at = np.isfinite(ys) & (np.abs(ys - level) <= atol)
        shared = np.zeros(x.shape, bool)
        for a, b in _runs(at.sum(axis=0) >= 2):
            if b > a and x[b] - x[a] >= min_stretch * x_span:
                shared[a : b + 1] = True
        if not shared.any():
            continue
        members = [row for row in range(len(same_grid)) if (at[row] & shared).any()]
        for row in members:
            hidden = at[row] & shared
            y_row = ys[row]
            for a, b in _runs(hidden):  # an end next to the curve's other values stays: the curve still reaches the line
                hidden[a] = hidden[a] and not (a > 0 and np.isfinite(y_row[a - 1]))
                hidden[b] = hidden[b] and not (b + 1 < y_row.size and np.isfinite(y_row[b + 1]))
            for line in drawn[same_grid[row]][1]:
                y = np.asarray(line.get_ydata(), dtype=float)
                if y.shape == x.shape:
                    line.set_ydata(np.where(hidden, np.nan, y))
        runs = tuple((float(x[a]), float(x[b])) for a, b in _runs(shared))
        entry = Shared(tuple(drawn[same_grid[row]][0] for row in members), level, runs, len(drawn), x_span, meaning)
        zorder = min((line.get_zorder() for _, lines, _ in drawn for line in lines), default=2.0) - 0.5
        gids = dict.fromkeys(str(line.get_gid()) for row in members for line in drawn[same_grid[row]][1] if line.get_gid())
        ax.plot(x, np.where(shared, level, np.nan), zorder=zorder, label=entry.label, gid="shared:" + "+".join(gids), **SHARED_STYLE)  # type: ignore[arg-type]
        found.append(entry)
    return found


def _values(lines: Sequence[Line2D]) -> tuple[np.ndarray, np.ndarray] | None:
    """The x and y of a curve drawn as several lines on one grid (stable and unstable parts, NaN elsewhere); lines on
    another grid (isolated dots) are left out. None if nothing is drawn."""
    full = [line for line in lines if np.size(line.get_xdata()) > 1]
    if not full:
        return None
    x = np.asarray(full[0].get_xdata(), dtype=float)
    y = np.full(x.shape, np.nan)
    for line in full:
        xl = np.asarray(line.get_xdata(), dtype=float)
        if xl.shape == x.shape and np.array_equal(xl, x, equal_nan=True):
            yl = np.asarray(line.get_ydata(), dtype=float)
            y = np.where(np.isfinite(yl), yl, y)
    return x, y


def _marker_size(lines: Sequence[Line2D]) -> float:
    """The largest marker drawn on ``lines`` [pt] (0 for lines alone)."""
    return max((float(line.get_markersize()) for line in lines if str(line.get_marker()) not in ("None", "", " ", "none")), default=0.0)


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) index of each run of True in ``mask``."""
    edges = np.flatnonzero(np.diff(np.concatenate(([0], mask.astype(int), [0]))))
    return [(int(a), int(b) - 1) for a, b in zip(edges[::2], edges[1::2])]


def _band(ax: Axes, line: Line2D, x: np.ndarray, mask: np.ndarray, beneath: np.ndarray, width: float, zorder: float) -> None:
    """Draw ``line`` again where ``mask``, ``width`` wide, its dash pattern (if any) as long as the line's so that
    dashes stay in step; a stretch reaches one point into a neighbouring one ``beneath`` another curve at another
    depth, so that the two join (never onto a point where the curve shows, as across a jump)."""
    y = np.asarray(line.get_ydata(), dtype=float)
    if y.shape != x.shape:
        return
    near = mask | (beneath & (np.r_[mask[1:], False] | np.r_[False, mask[:-1]]))
    shown = np.where(near, y, np.nan)
    if not np.isfinite(shown).any():
        return
    offset, dashes = getattr(line, "_unscaled_dash_pattern", (0.0, None))
    style: object = "-" if dashes is None else (offset * line.get_linewidth(), tuple(d * line.get_linewidth() for d in dashes))
    marker = line.get_marker()
    with mpl.rc_context({"lines.scale_dashes": False}):
        ax.plot(x, shown, color=line.get_color(), ls=style, lw=width, marker=marker, ms=line.get_markersize() + (width - line.get_linewidth()),
                solid_capstyle="butt", dash_capstyle="butt", zorder=zorder, label="_nolegend_", gid=f"beneath:{line.get_gid()}", transform=line.get_transform())  # fmt: skip


def reveal_coincident(ax: Axes, curves: Sequence[tuple[str, Sequence[Line2D]]], tolerance: float = TOLERANCE, min_stretch: float = MIN_STRETCH, zero: str = "", share: bool = True) -> list[Coincidence | Shared]:
    """Draw a constant shared by several curves of ``ax`` once, labelled, and every other curve lying under a
    coinciding one as a band around it; return what is shared and which coincide where.

    Parameters
    ----------
    ax : Axes
        The panel, its limits and scales final.
    curves : sequence of (str, sequence of Line2D)
        Each curve's name (as the caption names it) and the lines it was drawn with (one grid; parts on another grid
        are left out), in drawing order: the first beneath the others.
    tolerance, min_stretch : float
        :data:`TOLERANCE` and :data:`MIN_STRETCH`.
    zero : str
        What a shared 0 means, for its label ("no impacts").
    share : bool
        Draw a constant shared by several curves once (False: reference lines meant to be constant, such as each
        stop's clearance, stay as drawn).

    Returns
    -------
    list of Shared and Coincidence
        One per constant shared by several curves, then one per pair (lower, upper) that coincides somewhere else.
    """
    x_span = float(abs(np.subtract(*ax.get_xlim()))) or 1.0
    values = [(name, lines, _values(lines)) for name, lines in curves]
    shared = _share_constants(ax, [(name, lines, xy) for name, lines, xy in values if xy is not None], x_span, min_stretch, zero) if share else []
    values = [(name, lines, _values(lines)) for name, lines in curves] if shared else values
    drawn = [(name, lines, xy) for name, lines, xy in values if xy is not None]
    log = ax.get_yscale() == "log"
    low, high = (np.log10(v) if log else v for v in ax.get_ylim())
    span = abs(high - low) or 1.0

    # a marker covers more than a line's width: curves closer than the upper one's markers are hidden by them
    panel = ax.get_position().height * ax.get_figure().get_figheight() * 72.0 or 1.0  # type: ignore[union-attr]
    near = [max(tolerance, _marker_size(lines) / panel) for _, lines, _ in drawn]

    def height(y: np.ndarray) -> np.ndarray:
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.log10(np.where(y > 0, y, np.nan)) if log else y

    found: list[Coincidence | Shared] = list(shared)
    depth = [np.zeros(xy[0].shape, int) for _, _, xy in drawn]
    for i, (lower, _, (x, y)) in enumerate(drawn):
        yi = height(y)
        top = np.full(x.shape, -1)  # the last curve drawn over this one where they coincide
        for j in range(i + 1, len(drawn)):
            xu, yu = drawn[j][2]
            if xu.shape != x.shape or not np.array_equal(xu, x, equal_nan=True):
                continue
            yj = height(yu)
            with np.errstate(invalid="ignore"):
                close = np.isfinite(yi) & np.isfinite(yj) & (np.abs(yi - yj) <= near[j] * span)
            for a, b in _runs(close):
                if b > a and x[b] - x[a] >= min_stretch * x_span:
                    depth[i][a : b + 1] += 1
                    top[a : b + 1] = j
        for j in np.unique(top[top >= 0]):
            runs = [(float(x[a]), float(x[b])) for a, b in _runs(top == j)]
            found.append(Coincidence(lower, drawn[int(j)][0], tuple(runs), bool(np.all(top[np.isfinite(yi)] == j)), x_span))
    widest = max((line.get_linewidth() for _, lines, _ in drawn for line in lines), default=1.0)
    bottom = min((line.get_zorder() for _, lines, _ in drawn for line in lines), default=2.0)
    for (_, lines, (x, _)), d in zip(drawn, depth):
        d = np.minimum(d, MAX_BANDS)
        for level in range(1, int(d.max(initial=0)) + 1):
            for line in lines:
                _band(ax, line, x, d == level, d > 0, widest + BAND_STEP * level, bottom - 0.01 * level)
    return found


def _merge(stretches: Iterable[tuple[float, float]], gap: float = 0.0) -> list[tuple[float, float]]:
    """Stretches overlapping or less than ``gap`` apart joined, in order."""
    merged: list[tuple[float, float]] = []
    for a, b in sorted(stretches):
        if merged and a <= merged[-1][1] + gap:
            merged[-1] = (merged[-1][0], max(merged[-1][1], b))
        else:
            merged.append((a, b))
    return merged


def _names(names: Sequence[str]) -> str:
    return names[0] if len(names) == 1 else f"{', '.join(names[:-1])} and {names[-1]}"


def _where(stretches: Iterable[tuple[float, float]], axis: float, unit: str, spec: str, most: int) -> str:
    union = _merge(stretches, MIN_STRETCH * axis)
    extra = f" (and {len(union) - most} more stretches)" if len(union) > most else ""
    return f"{_names([f'{fmt(a, spec)}-{fmt(b, spec)}' for a, b in union[:most]])} {unit}{extra}"


def _shared_phrase(shared: list[Shared], unit: str, spec: str, most: int) -> str:
    """The caption's sentence on constants shared by several curves (empty if none): whose, which value, where."""
    labels: dict[str, list[Shared]] = {}
    for s in shared:
        labels.setdefault(s.label, []).append(s)
    parts = [f"{label} over {_where((r for s in group for r in s.stretches), max(s.axis for s in group), unit, spec, most)}" for label, group in labels.items()]
    return f"Drawn once (dark grey line, in the legend), not in the series' colours: {'; '.join(parts)}." if parts else ""


def coincidence_phrase(found: Iterable[Coincidence | Shared], unit: str = "Hz", spec: str = ".3g", most: int = 5) -> str:
    """The caption's sentences on constants shared by several curves (whose, which, where; drawn once) and on
    coinciding curves (empty if none): for each curve drawn on top, the curves lying under it and where (the union
    over them and over the panels: "parts of" where they do not all coincide over all of it), and how they are
    drawn."""
    found = list(found)
    shared = _shared_phrase([c for c in found if isinstance(c, Shared)], unit, spec, most)
    by_upper: dict[str, dict[str, list[Coincidence]]] = {}
    for c in found:
        if isinstance(c, Coincidence):
            by_upper.setdefault(c.upper, {}).setdefault(c.lower, []).append(c)
    if not by_upper:
        return shared
    sentences = []
    for upper, lowers in by_upper.items():
        every = [c for cs in lowers.values() for c in cs]
        gap = MIN_STRETCH * max(c.axis for c in every)
        union = _merge((s for c in every for s in c.stretches), gap)
        each = [_merge((s for c in cs for s in c.stretches), gap) for cs in lowers.values()]
        if all(c.everywhere for c in every):
            where = "wherever both have values"
        else:
            shown = _names([f"{fmt(a, spec)}-{fmt(b, spec)}" for a, b in union[:most]])
            extra = f" (and {len(union) - most} more stretches)" if len(union) > most else ""
            partly = "parts of " if any(e != union for e in each) else ""
            where = f"over {partly}{shown} {unit}{extra}"
        names = list(lowers)
        sentences.append(f"{_names(names)} {'lies' if len(names) == 1 else 'lie'} under {upper} {where}")
    coinciding = "Coinciding curves: " + "; ".join(sentences) + ". Each curve lying under another is drawn again there as a wider band of its own colour around it."
    return f"{shared} {coinciding}" if shared else coinciding
