"""The look every report page shares: figure size, colours, quantity labels, one number formatter, drawing helpers.

A report is read in a browser about 1400 px wide. Figures are at most :data:`FIGURE_WIDTH` wide at :data:`DPI`, so
they are shown unscaled and their text (at least :data:`MIN_FONT_SIZE`) stays legible; panels come at most
:data:`MAX_COLUMNS` to a row; legends sit below the panels (:func:`figure_legend`), never on the data.

The drawing helpers make each kind of data look the same on every page and keep every finite value visible:

* :func:`draw_curve` for closed-form solutions on the fine grid: solid where the orbit is stable, dashed (same colour,
  same weight) where it is unstable, gaps where there is no value, and a dot for a value with no finite neighbour
  (a line segment needs two points);
* :func:`draw_points` for simulations on their own grid: one marker per computed point, filled for a periodic steady
  state, hollow for irregular motion.

Captions are put together by a :class:`Caption` from what the helpers actually drew. Solutions are named in
captions as ``'name'`` (:func:`solution_ref`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Iterable, Sequence, SupportsFloat

import matplotlib

matplotlib.use("Agg")  # reports are drawn without a display
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.axes import Axes  # noqa: E402
from matplotlib.figure import Figure as MatplotlibFigure  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

from .regime import Regime  # noqa: E402

__all__ = [
    "DPI",
    "FIGURE_WIDTH",
    "MAX_COLUMNS",
    "OVER_MARKERS_ZORDER",
    "MIN_FONT_SIZE",
    "QUANTITIES",
    "REGIME_COLOURS",
    "SOLUTION_COLOURS",
    "SOLUTION_DESCRIPTIONS",
    "SOLUTION_TITLES",
    "STABLE_STYLE",
    "UNSTABLE_STYLE",
    "Caption",
    "Quantity",
    "axis_label",
    "draw_curve",
    "draw_points",
    "figure_legend",
    "fmt",
    "new_figure",
    "regime_label",
    "series_colour",
    "solution_ref",
]

#: Resolution of the PNG figures [dots per inch].
DPI = 110
#: Width of every figure [in]: 1320 px at :data:`DPI`, shown unscaled in a 1400 px browser window.
FIGURE_WIDTH = 12.0
#: Smallest font of any text in a figure [pt] (14 px at :data:`DPI`).
MIN_FONT_SIZE = 9.0
#: Panels per row at most.
MAX_COLUMNS = 2


@dataclass(frozen=True)
class Quantity:
    """How a dataset quantity is named on an axis and in a caption.

    Attributes
    ----------
    label : str
        Short name on the axis and in captions; no label is part of another.
    units : str
        Units as in the dataset's ``units`` attribute.
    meaning : str
        What the value is, for captions.
    log : bool
        Drawn on a logarithmic axis.
    """

    label: str
    units: str
    meaning: str
    log: bool


QUANTITIES: dict[str, Quantity] = {
    "x1_amplitude": Quantity("|X1| fundamental", "m", "fundamental-harmonic amplitude of the primary mass's displacement", True),
    "x2_amplitude": Quantity("|X2| fundamental", "m", "fundamental-harmonic amplitude of the absorber's displacement", True),
    "force_amplitude": Quantity("|F| on the base", "N", "fundamental of the force on the base through suspension and impacts (eq. 23)", True),
    "suspension_force_amplitude": Quantity("|F| through the suspension", "N", "fundamental of the force through the suspension alone (eq. 21)", True),
    "impulse": Quantity("impulse per period", "N s", "total impulse of the impacts in one excitation period", False),
    "impacts_per_period": Quantity("contacts per period", "1", "contacts per excitation period", False),
    "peak_acceleration": Quantity("peak contact deceleration", "m s-2", "largest deceleration of the absorber on the bumper", False),
    "peak_contact_force": Quantity("peak contact force", "N", "largest bumper force", False),
    "floquet_modulus": Quantity("largest |Floquet multiplier|", "1", "largest modulus of the Floquet multipliers of the one-impact orbit", True),
}


def axis_label(quantity: str) -> str:
    """Axis label of ``quantity``: its short name and units in brackets."""
    q = QUANTITIES[quantity]
    return f"{q.label} [{q.units}]"


# ----------------------------------------------------------------------------------------------- regimes
#: One colour per regime flag, all distinct: blues for the one-impact motion, greens for the linear motion, reds where
#: no steady state is known, oranges and browns for what simulations found, grey where nothing was computed.
REGIME_COLOURS: dict[Regime, str] = {
    Regime.NOT_COMPUTED: "#d9d9d9",
    Regime.LINEAR: "#b2df8a",
    Regime.ONE_IMPACT: "#1f78b4",
    Regime.ONE_IMPACT_COEXISTING_LINEAR: "#a6cee3",
    Regime.LINEAR_WITH_INADMISSIBLE_ONE_IMPACT: "#33a02c",
    Regime.NONE_INADMISSIBLE_ONE_IMPACT: "#fb9a99",
    Regime.NONE: "#e31a1c",
    Regime.LINEAR_EXCEEDS_CLEARANCE: "#fdbf6f",
    Regime.LINEAR_WITH_UNSTABLE_ONE_IMPACT: "#6a3d9a",
    Regime.PERIODIC_IMPACTS: "#ff7f00",
    Regime.IRREGULAR: "#b15928",
    Regime.SWEPT_CONTACT: "#cab2d6",
    Regime.FAILED: "#000000",
}


def regime_label(regime: Regime) -> str:
    """Legend text of a regime flag: its CF flag meaning and value, as in the dataset."""
    return f"{regime.name.lower()} ({int(regime)})"


# ------------------------------------------------------------------------------------------ line styles
#: Closed-form values on a stable (or linear) orbit.
STABLE_STYLE = {"ls": "-", "lw": 1.4}
#: Closed-form values on an orbit that exists but is unstable: same colour and weight as stable, dashed.
UNSTABLE_STYLE = {"ls": (0, (5, 2.5)), "lw": 1.4}
#: The linear system (no stop).
LINEAR_STYLE = {"ls": ":", "lw": 1.3, "color": "k"}
#: Raw one-impact solution wherever eqs. 15-16 have a root, unchecked: thin and faint, behind everything.
RAW_STYLE = {"ls": "-", "lw": 0.7, "alpha": 0.35, "zorder": 1}
#: Simulation markers (fillable shapes: filled means periodic) and sizes [pt]; exact's larger diamonds show under
#: momentary's circles where both agree.
ENGINE_MARKERS: dict[str, tuple[str, float]] = {"momentary": ("o", 3.5), "exact": ("D", 5.0), "compliant": ("s", 4.0)}
#: Drawing order of markers: smaller ones on top of larger ones [matplotlib zorder; lines are at 2].
MARKER_ZORDER = 2.5
#: Closed-form curves drawn over simulation markers, to compare the two [matplotlib zorder].
OVER_MARKERS_ZORDER = 3.0
#: Dot for an isolated closed-form value (no finite neighbour, so no line segment) [pt].
ISOLATED_MARKER_SIZE = 3.0


#: Colour of each solution where a figure distinguishes solutions (not restitution ratios).
SOLUTION_COLOURS: dict[str, str] = {"linear": "k", "pgf": "C0", "pgf_paper": "C4", "momentary": "C1", "exact": "C2", "compliant": "C3"}
#: Short name of each solution for panel titles (half a figure wide).
SOLUTION_TITLES: dict[str, str] = {
    "linear": "linear system",
    "pgf": "closed form, exact modes",
    "pgf_paper": "closed form, paper's fitted modes",
    "exact": "exact engine, rigid stop",
    "momentary": "CVODE, rigid stop",
    "compliant": "IDA, compliant bumper",
}
#: What each solution is, for captions.
SOLUTION_DESCRIPTIONS: dict[str, str] = {
    "linear": "linear system, no stop",
    "pgf": "one-impact closed form, exact poles/residues and exact chi22'(0-)",
    "pgf_paper": "one-impact closed form, the paper's fitted modes and constant chi22'(0-)",
    "exact": "piecewise-exact simulation, rigid stop",
    "momentary": "CVODE simulation, rigid stop",
    "compliant": "IDA simulation, Kelvin-Voigt bumper (eq. 25)",
}


def series_colour(index: int) -> str:
    """Colour of the ``index``-th series of a figure (matplotlib's default cycle, ten colours)."""
    return f"C{index % 10}"


def solution_ref(solution: str) -> str:
    """How a caption names a solution."""
    return f"'{solution}'"


def fmt(value: SupportsFloat | None, spec: str = ".3g") -> str:
    """``value`` formatted with ``spec``; empty for NaN, infinity or None (a table cell with nothing to show)."""
    if value is None:
        return ""
    number = float(value)
    return "" if not math.isfinite(number) else format(number, spec)


# ---------------------------------------------------------------------------------------------- captions
class Caption:
    """Caption phrases collected while drawing, each once, in drawing order."""

    def __init__(self, lead: str) -> None:
        self.lead = lead
        self._phrases: dict[str, str] = {}

    def add(self, key: str, phrase: str) -> None:
        """Add ``phrase`` under ``key`` unless that key has one already."""
        self._phrases.setdefault(key, phrase)

    def text(self, tail: str = "") -> str:
        """The caption: lead, phrases, tail; its first letter a capital."""
        text = " ".join(part for part in (self.lead, *self._phrases.values(), tail) if part)
        return text[:1].upper() + text[1:]


# ---------------------------------------------------------------------------------------------- drawing
def draw_curve(ax: Axes, x: np.ndarray, y: np.ndarray, *, colour: str, label: str | None, gid: str, unstable: np.ndarray | None = None, coarse: bool = False, style: dict[str, object] | None = None, zorder: float = 2.0) -> tuple[bool, bool]:
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
    ax.plot(x, stable_y, color=colour, label=label or "_nolegend_", gid=gid, zorder=zorder, **(style or STABLE_STYLE), **marker)
    if flagged.any():
        ax.plot(x, unstable_y, color=colour, label="_nolegend_", gid=gid, zorder=zorder, **UNSTABLE_STYLE, **marker)
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
    """The linear system's curve (dotted black, legend 'LIN'); returns whether anything was drawn."""
    marker = {"marker": ".", "ms": 4} if coarse else {}
    ax.plot(x, y, label="LIN", gid="linear", **LINEAR_STYLE, **marker)
    _mark_isolated(ax, x, np.asarray(y, dtype=float), "k", "linear")
    return bool(np.isfinite(y).any())


def draw_points(ax: Axes, x: np.ndarray, y: np.ndarray, *, periodic: np.ndarray, solution: str, colour: str, label: str | None) -> tuple[bool, bool]:
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
        Legend entry (", periodic" and ", irregular" are appended; None: none).

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
    if periodic.any():
        ax.plot(x[periodic], y[periodic], marker, ls="none", color=colour, mfc=colour, ms=size, zorder=zorder, label=f"{label}, periodic" if label else "_nolegend_", gid=solution)
    if irregular.any():
        ax.plot(x[irregular], y[irregular], marker, ls="none", color=colour, mfc="none", mew=1.1, ms=size, zorder=zorder, label=f"{label}, irregular" if label else "_nolegend_", gid=solution)
    return bool(periodic.any()), bool(irregular.any())


def stability_keys() -> list[Line2D]:
    """Legend entries explaining solid and dashed closed-form curves (drawn in black, colours are per series)."""
    return [Line2D([], [], color="k", label="stable orbit (solid)", **STABLE_STYLE), Line2D([], [], color="k", label="unstable orbit (dashed)", **UNSTABLE_STYLE)]


# ---------------------------------------------------------------------------------------------- layout
def new_figure(panels: int, panel_height: float = 3.6, columns: int = MAX_COLUMNS, sharex: bool = False, sharey: bool = False, legend_rows: int = 0) -> tuple[MatplotlibFigure, list[Axes]]:
    """A figure :data:`FIGURE_WIDTH` wide with ``panels`` panels, at most ``columns`` to a row, constrained layout.

    Parameters
    ----------
    panels : int
        Number of panels; unused cells of the last row are removed.
    panel_height : float
        Height of one row of panels [in].
    columns : int
        Panels per row at most (capped at :data:`MAX_COLUMNS`).
    sharex, sharey : bool
        Share the axes between panels.
    legend_rows : int
        Rows of legend entries expected below the panels (adds height for them).

    Returns
    -------
    (Figure, list of Axes)
        The figure and its panels in reading order.
    """
    columns = max(1, min(columns, MAX_COLUMNS, panels))
    rows = math.ceil(panels / columns)
    height = rows * panel_height + 0.25 * legend_rows + (0.2 if legend_rows else 0.0)
    fig, grid = plt.subplots(rows, columns, figsize=(FIGURE_WIDTH, height), squeeze=False, sharex=sharex, sharey=sharey, layout="constrained")
    axes = list(grid.flat)
    for ax in axes[panels:]:
        ax.remove()
    return fig, axes[:panels]


def figure_legend(fig: MatplotlibFigure, axes: Sequence[Axes], extra: Iterable[Line2D] = (), columns: int = 4) -> None:
    """One legend for the whole figure, below the panels (outside every axes, so it covers no data).

    Entries are the labelled artists of ``axes`` (each label once, in drawing order) followed by ``extra``.
    """
    entries: dict[str, object] = {}
    for ax in axes:
        for handle, label in zip(*ax.get_legend_handles_labels()):
            entries.setdefault(label, handle)
    for handle in extra:
        entries.setdefault(handle.get_label(), handle)
    if entries:
        fig.legend(list(entries.values()), list(entries.keys()), loc="outside lower center", ncols=min(columns, len(entries)), fontsize=MIN_FONT_SIZE + 1)


def legend_rows(entries: int, columns: int = 4) -> int:
    """Rows a :func:`figure_legend` of ``entries`` entries takes."""
    return math.ceil(entries / columns) if entries else 0


def finish_axes(ax: Axes, xlabel: str, ylabel: str, title: str, log: bool = False) -> None:
    """Labels, title, grid and scale of a panel."""
    if log:
        ax.set_yscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=MIN_FONT_SIZE + 2)
    ax.grid(True, which="both", alpha=0.3)
