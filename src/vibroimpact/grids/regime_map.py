"""Regime flags drawn as coloured bands, one panel per solution or sweep (the frequency-grid study shared by the stepped
and swept kinds: the stepped page's regime maps and the swept page's map of the steady states and the sweeps).

A solution computed on a coarser grid (simulations) shows each point as a block reaching halfway to its neighbours
(:func:`block_edges`); an admissible one-impact orbit that is unstable is hatched over its flag's colour.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.colors import BoundaryNorm, ListedColormap
from matplotlib.patches import Patch, Rectangle

from vibroimpact.analysis.stability import Regime
from vibroimpact.reporting.page import DrawnFigure
from vibroimpact.reporting.style import REGIME_COLOURS, figure_legend, legend_rows, new_figure, regime_label

__all__ = ["regime_map", "block_edges"]

_FREQUENCY = "frequency [Hz]"


def _hatch_runs(ax: Any, edges: np.ndarray, marked: np.ndarray, gid: str) -> None:
    """Hatch every run of marked cells (rows x columns between ``edges`` [Hz]) over the colours drawn below."""
    for row, cells in enumerate(marked):
        padded = np.concatenate(([False], cells, [False])).astype(int)
        starts, ends = np.flatnonzero(np.diff(padded) == 1), np.flatnonzero(np.diff(padded) == -1)
        for a, b in zip(starts, ends):
            ax.add_patch(Rectangle((edges[a], row - 0.5), edges[b] - edges[a], 1.0, fill=False, hatch="////", edgecolor="0.15", linewidth=0.0, gid=gid))


#: Regime flags of an admissible one-impact orbit, the ones whose stability a hatch shows.
_ONE_IMPACT_FLAGS = (Regime.ONE_IMPACT, Regime.ONE_IMPACT_COEXISTING_LINEAR)


def regime_map(panels: list[tuple], f: np.ndarray, name: str, title: str, lead: str) -> DrawnFigure:
    """Regime flags as coloured bands, one colour per flag, the legend below the panels.

    Parameters
    ----------
    panels : list of (str, list of str, ndarray[, ndarray or None])
        Per panel: its title, its row labels, the flags, shape (rows, frequency), and optionally where the
        one-impact orbit is unstable (bool, same shape): those cells are hatched over their flag's colour.
    f : ndarray
        Frequency grid [Hz].
    name, title : str
        File name and heading of the figure.
    lead : str
        First sentence of the caption.
    """
    flags = sorted(REGIME_COLOURS)
    cmap = ListedColormap([REGIME_COLOURS[r] for r in flags])
    norm = BoundaryNorm(np.arange(len(flags) + 1) - 0.5, len(flags))
    heights = [0.95 + 0.3 * len(panel[1]) for panel in panels]
    fig, axes = new_figure(len(panels), columns=1, sharex=True, legend_rows=legend_rows(len(flags) + 1, 3), row_heights=heights)
    seen: set[int] = set()
    coarse = False
    hatched = 0
    for ax, (panel_title, labels, grid, *rest) in zip(axes, panels):
        unstable = rest[0] if rest and rest[0] is not None else None
        computed = np.any(grid != Regime.NOT_COMPUTED, axis=0)
        columns = f[computed]
        if columns.size:
            edges = block_edges(columns, f)
            rows = np.arange(len(labels) + 1) - 0.5
            ax.pcolormesh(edges, rows, np.searchsorted(flags, grid[:, computed]), cmap=cmap, norm=norm, shading="flat", gid=f"regime:{panel_title}")
            seen.update(int(v) for v in np.unique(grid[:, computed]))
            coarse |= bool(columns.size < f.size)
            if unstable is not None:
                marked = np.asarray(unstable, dtype=bool)[:, computed] & np.isin(grid[:, computed], _ONE_IMPACT_FLAGS)
                if marked.any():
                    hatched += int(marked.sum())
                    _hatch_runs(ax, edges, marked, f"unstable:{panel_title}")
        ax.set_ylim(len(labels) - 0.5, -0.5)
        ax.set_yticks(range(len(labels)), labels)
        ax.set_title(panel_title, fontsize=11)
    axes[-1].set_xlabel(_FREQUENCY)
    shown = [r for r in flags if int(r) in seen]
    handles = [Patch(color=REGIME_COLOURS[r], label=regime_label(r)) for r in shown]
    if hatched:
        handles.append(Patch(facecolor="white", edgecolor="0.15", hatch="////", label="hatched: the one-impact orbit is unstable"))
    figure_legend(fig, [], handles, columns=3)
    caption = f"{lead} (the dataset's regime flag, its value in brackets), one colour per flag."
    if hatched:
        caption += (
            f" Hatched ({hatched} points): an admissible one-impact orbit that is unstable (largest Floquet multiplier"
            " outside the unit circle); the motion settles elsewhere there (see the simulations), however its colour reads."
        )
    if coarse:
        caption += (
            " A solution computed on a coarser grid (simulations) shows each point as a block reaching halfway to its"
            " neighbours; blank: frequencies it was not asked to compute."
        )
    return DrawnFigure(fig, name, title, caption)


def block_edges(columns: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Edges of blocks around each computed frequency, halfway to its neighbours (coarse simulation grids show as
    blocks, not hairlines), the end blocks as wide as their neighbours' half spacing, within the frequency axis."""
    if columns.size == 1:
        half = 0.5 * float(np.min(np.diff(f))) if f.size > 1 else 0.5
        return np.array([columns[0] - half, columns[0] + half])
    middle = (columns[1:] + columns[:-1]) / 2.0
    first, last = columns[0] - (middle[0] - columns[0]), columns[-1] + (columns[-1] - middle[-1])
    return np.concatenate([[max(first, f[0])], middle, [min(last, f[-1])]])
