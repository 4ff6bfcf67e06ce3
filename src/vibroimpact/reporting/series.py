"""How a solution's values are drawn, the same on every page, so that every finite value is visible.

* :func:`draw_curve` for closed-form solutions on the fine grid: solid where the orbit is stable, dashed (same colour,
  same weight) where it is unstable, gaps where there is no value, and a dot for a value with no finite neighbour
  (a line segment needs two points);
* :func:`draw_points` for simulations on their own grid: one marker per computed point, filled for a periodic steady
  state, hollow for irregular motion; a :class:`SimulationMarkers` records which were drawn, for the legend and the
  caption;
* the dataset lookups the pages share: where an orbit is unstable, where a simulation is periodic.

Every drawn artist carries the solution's name as its ``gid``: tests find each solution's data by it.
"""

from __future__ import annotations

from typing import Iterable

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.lines import Line2D

from vibroimpact.analysis.stability import Regime
from vibroimpact.reporting.style import ENGINE_MARKERS, LINEAR_STYLE, STABLE_STYLE, UNSTABLE_STYLE, solution_ref

__all__ = ["draw_curve", "draw_linear", "draw_points", "stability_keys", "closed_forms_whose", "marker_scales", "SimulationMarkers", "subset_points", "unstable_points", "periodic_points", "OVER_MARKERS_ZORDER"]

#: Drawing order of markers: smaller ones on top of larger ones [matplotlib zorder; lines are at 2].
MARKER_ZORDER = 2.5
#: Closed-form curves drawn over simulation markers, to compare the two [matplotlib zorder].
OVER_MARKERS_ZORDER = 3.0
#: The linear system's dotted curve, over the closed-form curves (at 2) and under the simulation markers [zorder].
LINEAR_ZORDER = 2.2
#: Dot for an isolated closed-form value (no finite neighbour, so no line segment) [pt].
ISOLATED_MARKER_SIZE = 3.0
_SHAPES = {"o": "circles", "D": "diamonds", "s": "squares", "^": "triangles"}


def draw_curve(ax: Axes, x: np.ndarray, y: np.ndarray, *, colour: str, label: str | None, gid: str, unstable: np.ndarray | None = None, coarse: bool = False, style: dict[str, object] | None = None, zorder: float = 2.0, width: float | None = None) -> tuple[bool, bool]:
    """Draw closed-form values: solid where stable, dashed where ``unstable``, gaps at NaN, dots at isolated values.

    Parameters
    ----------
    ax : Axes
        Panel to draw on.
    x, y : ndarray
        Abscissa and values (NaN where there is no value).
    colour : str
        Line colour.
    label : str or None
        Legend entry of the line (None: none).
    gid : str
        Identifier of the drawn artists (the solution's name): tests find each solution's data by it.
    unstable : ndarray of bool, optional
        Points on an unstable orbit.
    coarse : bool
        Also mark every value (a grid too coarse for a line alone).
    style : dict, optional
        Line style of the stable stretches instead of :data:`STABLE_STYLE`.
    zorder : float
        Drawing order (:data:`OVER_MARKERS_ZORDER` to draw over simulation markers).
    width : float, optional
        Line width [pt] of stable and unstable stretches alike (an ordered parameter's series:
        :func:`~vibroimpact.reporting.style.ordered_widths`).

    Returns
    -------
    (bool, bool)
        Whether any value was drawn, and whether any unstable stretch was.
    """
    y = np.asarray(y, dtype=float)
    finite = np.isfinite(y)
    flagged = np.zeros(y.shape, bool) if unstable is None else (np.asarray(unstable, bool) & finite)
    # solid and dashed stretches are not joined: where stability changes the value may jump to another branch, and a
    # joining segment would draw a motion that does not exist (the hole is one grid step wide)
    marker = {"marker": "o", "ms": ISOLATED_MARKER_SIZE} if coarse else {}
    stable_y = np.where(flagged, np.nan, y)
    unstable_y = np.where(flagged, y, np.nan)
    lw = {} if width is None else {"lw": width}
    ax.plot(x, stable_y, color=colour, label=label or "_nolegend_", gid=gid, zorder=zorder, **((style or STABLE_STYLE) | lw), **marker)
    if flagged.any():
        ax.plot(x, unstable_y, color=colour, label="_nolegend_", gid=gid, zorder=zorder, **(UNSTABLE_STYLE | lw), **marker)
    for values in (stable_y, unstable_y if flagged.any() else None):
        if values is not None and not coarse:
            _mark_isolated(ax, x, values, colour, gid, zorder)
    return bool(finite.any()), bool(flagged.any())


def _mark_isolated(ax: Axes, x: np.ndarray, y: np.ndarray, colour: str, gid: str, zorder: float = 2.0) -> None:
    """A dot at each finite value whose neighbours are both missing (a line draws nothing there)."""
    finite = np.isfinite(y)
    isolated = finite & ~np.r_[False, finite[:-1]] & ~np.r_[finite[1:], False]
    if isolated.any():
        ax.plot(np.asarray(x)[isolated], y[isolated], "o", color=colour, ms=ISOLATED_MARKER_SIZE, label="_nolegend_", gid=gid, zorder=zorder)


def draw_linear(ax: Axes, x: np.ndarray, y: np.ndarray, coarse: bool = False) -> bool:
    """The linear system's curve (dotted black, legend 'LIN'), over the closed-form curves (:data:`LINEAR_ZORDER`):
    where one of them is the linear motion the dots show on it; returns whether anything was drawn."""
    marker = {"marker": ".", "ms": 4} if coarse else {}
    ax.plot(x, y, label="LIN", gid="linear", zorder=LINEAR_ZORDER, **LINEAR_STYLE, **marker)
    _mark_isolated(ax, x, np.asarray(y, dtype=float), "k", "linear", LINEAR_ZORDER)
    return bool(np.isfinite(y).any())


def draw_points(ax: Axes, x: np.ndarray, y: np.ndarray, *, periodic: np.ndarray, solution: str, colour: str, label: str | None, scale: float = 1.0) -> tuple[bool, bool]:
    """Draw a simulation's values on its own grid: one marker per finite value, filled if periodic, hollow if not.

    Parameters
    ----------
    ax : Axes
        Panel to draw on.
    x, y : ndarray
        Abscissa and values; NaN where the solution was not computed.
    periodic : ndarray of bool
        The simulated steady state was periodic (its stroboscopic state repeated).
    solution : str
        The simulation's name: its marker shape, and the artists' gid.
    colour : str
        Marker colour.
    label : str or None
        Legend entry (", periodic" and ", not periodic" are appended; None: none).
    scale : float
        Factor on the marker's size (an ordered parameter's series: the first largest, :func:`marker_scales`).

    Returns
    -------
    (bool, bool)
        Whether periodic and whether irregular values were drawn.
    """
    y = np.asarray(y, dtype=float)
    x = np.asarray(x)
    finite = np.isfinite(y)
    periodic = np.asarray(periodic, bool) & finite
    irregular = finite & ~periodic
    marker, size = ENGINE_MARKERS.get(solution, ("s", 5.0))
    zorder = MARKER_ZORDER - size / 100.0
    size *= scale
    if periodic.any():
        ax.plot(x[periodic], y[periodic], marker, ls="none", color=colour, mfc=colour, ms=size, zorder=zorder, label=f"{label}, periodic" if label else "_nolegend_", gid=solution)
    if irregular.any():
        ax.plot(x[irregular], y[irregular], marker, ls="none", color=colour, mfc="none", mew=1.1, ms=size, zorder=zorder, label=f"{label}, not periodic" if label else "_nolegend_", gid=solution)
    return bool(periodic.any()), bool(irregular.any())


def marker_scales(count: int) -> list[float]:
    """Factors on the marker sizes of ``count`` series of an ordered parameter: the first 1.5 times, the last 0.9 times
    the engine's size, so that a marker under a later one at the same value still shows around it."""
    return [1.0] * count if count <= 1 else [1.5 - 0.6 * k / (count - 1) for k in range(count)]


def stability_keys(whose: str = "of the closed form") -> list[Line2D]:
    """Legend entries explaining solid and dashed closed-form curves (drawn in black, colours are per series), saying
    whose orbit it is: "stable orbit of 'pgf' (solid)"."""
    return [
        Line2D([], [], color="k", label=f"stable orbit {whose} (solid)", **STABLE_STYLE),
        Line2D([], [], color="k", label=f"unstable orbit {whose} (dashed)", **UNSTABLE_STYLE),
    ]


def closed_forms_whose(solutions: Iterable[str]) -> str:
    """Whose closed-form curves a legend explains: "of 'pgf'", "of 'pgf' and 'pgf_paper'"."""
    names = [solution_ref(s) for s in dict.fromkeys(solutions)]
    return "of the closed form" if not names else f"of {names[0] if len(names) == 1 else ', '.join(names[:-1]) + ' and ' + names[-1]}"


class SimulationMarkers:
    """Which simulations were drawn with periodic (filled) and irregular (hollow) markers: legend entries, caption."""

    def __init__(self, points: dict[str, int] | None = None) -> None:
        self.drawn: dict[str, tuple[bool, bool]] = {}
        #: Simulations run on a subset of the grid -> their number of points, said in their legend entries.
        self.points: dict[str, int] = dict(points or {})

    def name(self, solution: str) -> str:
        """How the legend names ``solution``: with its number of points where it ran on a subset."""
        n = self.points.get(solution)
        return solution_ref(solution) + (f" ({n} point{'s' if n != 1 else ''})" if n is not None else "")

    def add(self, solution: str, drawn: tuple[bool, bool]) -> None:
        """Record what :func:`draw_points` drew for ``solution``: (periodic, irregular)."""
        old = self.drawn.get(solution, (False, False))
        self.drawn[solution] = (old[0] or drawn[0], old[1] or drawn[1])

    def __bool__(self) -> bool:
        """Whether any marker was drawn."""
        return any(p or i for p, i in self.drawn.values())

    def _subset(self, solution: str) -> str:
        n = self.points.get(solution)
        return "" if n is None else f", on a subset of {n} point{'s' if n != 1 else ''} only"

    def keys(self) -> list[Line2D]:
        """Legend entries of the markers drawn, in black (colours are per series)."""
        keys = []
        for solution, (periodic, irregular) in self.drawn.items():
            marker, size = ENGINE_MARKERS.get(solution, ("s", 5.0))
            if periodic:
                keys.append(Line2D([], [], marker=marker, ls="none", color="k", ms=size, label=f"{self.name(solution)}, periodic"))
            if irregular:
                keys.append(Line2D([], [], marker=marker, ls="none", color="k", mfc="none", ms=size, label=f"{self.name(solution)}, not periodic"))
        return keys

    def phrase(
        self,
        periodic: str = "periodic steady state (the stroboscopic state repeated)",
        irregular: str = "not periodic (quasi-periodic, chaotic or undecided: the regime map says which), averaged over the measured periods",
        each: str = "one marker per simulated frequency",
    ) -> str:
        """Caption sentence: the simulations drawn, their shapes, what each marker is, and what filled and hollow mean
        (only what is drawn)."""
        if not self:
            return ""
        names = ", ".join(f"{solution_ref(s)} ({_SHAPES.get(ENGINE_MARKERS.get(s, ('s', 0.0))[0], 'markers')}{self._subset(s)})" for s, (p, i) in self.drawn.items() if p or i)
        kinds = ([f"filled: {periodic}"] if any(p for p, _ in self.drawn.values()) else []) + ([f"hollow: {irregular}"] if any(i for _, i in self.drawn.values()) else [])
        return f"Simulations {names}: {each} ({'; '.join(kinds)})."


def subset_points(data: xr.Dataset, solution: str) -> int:
    """How many points ``solution`` computed in ``data``: its regime flag says computed (failed included), else it has a
    finite |X1|."""
    if "regime" in data:
        return int(np.count_nonzero(data["regime"].sel(solution=solution).values != int(Regime.NOT_COMPUTED)))
    return int(np.count_nonzero(np.isfinite(data["x1_amplitude"].sel(solution=solution).values)))


def unstable_points(data: xr.Dataset, solution: str) -> np.ndarray | None:
    """Where ``solution``'s one-impact orbit exists but is unstable (None: stability not in ``data``)."""
    if "stable" not in data:
        return None
    return np.asarray(data["stable"].sel(solution=solution).values == 0)


def periodic_points(data: xr.Dataset, solution: str) -> np.ndarray:
    """Where a simulation converged to a periodic steady state (everywhere if ``data`` does not say)."""
    if "converged" not in data:
        return np.ones(data[next(iter(data.data_vars))].sel(solution=solution).shape, bool)
    return np.asarray(data["converged"].sel(solution=solution).values == 1)
