"""The look every report page shares: figure size, colours, quantity labels, one number formatter, captions, layout.

A report is read in a browser about 1400 px wide. Figures are at most :data:`FIGURE_WIDTH` wide at :data:`DPI`, so
they are shown unscaled and their text (at least :data:`MIN_FONT_SIZE`) stays legible; panels come at most
:data:`MAX_COLUMNS` to a row; legends sit below the panels (:func:`figure_legend`), never on the data.

How a solution's values are drawn (curves, markers, stability) is :mod:`vibroimpact.reporting.series`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Iterable, Sequence, SupportsFloat

import matplotlib

matplotlib.use("Agg")  # reports are drawn without a display
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.axes import Axes  # noqa: E402
from matplotlib.colors import to_hex  # noqa: E402
from matplotlib.figure import Figure as MatplotlibFigure  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.ticker import FormatStrFormatter, FuncFormatter, LogFormatter, LogFormatterSciNotation, LogLocator, ScalarFormatter  # noqa: E402

from vibroimpact.analysis.stability import Regime  # noqa: E402
# every solution's row (colour, title, words), kept without matplotlib for the studies; re-exported for the pages
from vibroimpact.reporting.solutions import (  # noqa: E402
    ENGINE_MARKERS,
    GENERAL_SOLUTION_DESCRIPTIONS,
    SOLUTION_COLOURS,
    SOLUTION_DESCRIPTIONS,
    SOLUTION_LOOKS,
    SOLUTION_TITLES,
    SolutionLook,
)

__all__ = [
    "PlainLogFormatter",
    "plain_log",
    "DISPLACEMENT_SCALE",
    "DISPLACEMENT_UNITS",
    "DPI",
    "FIGURE_WIDTH",
    "MAX_COLUMNS",
    "MIN_FONT_SIZE",
    "PAGE_UNITS",
    "QUANTITIES",
    "REGIME_COLOURS",
    "SOLUTION_LOOKS",
    "SolutionLook",
    "SOLUTION_COLOURS",
    "SOLUTION_DESCRIPTIONS",
    "GENERAL_SOLUTION_DESCRIPTIONS",
    "SOLUTION_TITLES",
    "ENGINE_MARKERS",
    "LINEAR_STYLE",
    "RAW_STYLE",
    "STABLE_STYLE",
    "UNSTABLE_STYLE",
    "Caption",
    "Quantity",
    "REPORT_RC",
    "thin_minor_log_ticks",
    "readable_axes",
    "readable_scale",
    "drawn_scale",
    "linear_under_a_decade",
    "scale_phrase",
    "axis_label",
    "figure_legend",
    "fmt",
    "new_figure",
    "regime_label",
    "series_colour",
    "OKABE_ITO",
    "ORDERED_COLORMAP",
    "ORDERED_SPAN",
    "ORDERED_WIDTHS",
    "ordered_colours",
    "ordered_widths",
    "SHARED_STYLE",
    "ZERO_MEANINGS",
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

    @property
    def page_units(self) -> str:
        """Units on the page (:data:`PAGE_UNITS`): mm for a displacement, m/s² for an acceleration."""
        return PAGE_UNITS.get(self.units, (self.units, 1.0))[0]

    @property
    def scale(self) -> float:
        """Factor from the dataset's value to the page's (1e3 for a displacement: m -> mm)."""
        return PAGE_UNITS.get(self.units, (self.units, 1.0))[1]


#: One unit convention on every page: (units on the page, factor from the dataset's value) for each SI unit the
#: datasets use where the page writes another. Displacements in mm, accelerations in m/s², forces in N, frequencies in
#: Hz; the datasets keep SI (CF) units.
PAGE_UNITS: dict[str, tuple[str, float]] = {"m": ("mm", 1e3), "m s-2": ("m/s²", 1.0)}
#: Displacements on the page: units and factor from metres.
DISPLACEMENT_UNITS, DISPLACEMENT_SCALE = PAGE_UNITS["m"]


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
    "lyapunov_exponent": Quantity("largest Lyapunov exponent", "1/period", "largest Lyapunov exponent of the stroboscopic map, per excitation period", False),
}


def axis_label(quantity: str) -> str:
    """Axis label of ``quantity``: its short name and the page's units in brackets (values drawn times
    :attr:`Quantity.scale`)."""
    q = QUANTITIES[quantity]
    return f"{q.label} [{q.page_units}]"


# ----------------------------------------------------------------------------------------------- regimes
#: The one regime palette of every page (regime maps, markers coloured by regime), safe for
#: colour-blind readers: no two flags are told apart by red against green alone (every pair stays at least 10 CIELAB
#: units apart under simulated protanopia, deuteranopia and tritanopia; Okabe-Ito and Paul Tol colours). Pale yellows
#: and sand for the linear motion, blues for the one-impact orbit (indigo where it is unstable), vermillion and rose
#: where no steady state is known, orange where the linear motion crosses the clearance, teal, brown, olive and purple
#: for what simulations found, grey where nothing was computed, black where it failed.
REGIME_COLOURS: dict[Regime, str] = {
    Regime.NOT_COMPUTED: "#dddddd",
    Regime.LINEAR: "#ffee99",
    Regime.ONE_IMPACT: "#4477aa",
    Regime.ONE_IMPACT_COEXISTING_LINEAR: "#77aadd",
    Regime.LINEAR_WITH_INADMISSIBLE_ONE_IMPACT: "#ddcc77",
    Regime.NONE_INADMISSIBLE_ONE_IMPACT: "#cc6677",
    Regime.NONE: "#d55e00",
    Regime.LINEAR_EXCEEDS_CLEARANCE: "#e69f00",
    Regime.LINEAR_WITH_UNSTABLE_ONE_IMPACT: "#332288",
    Regime.PERIODIC_IMPACTS: "#44aa99",
    Regime.IRREGULAR: "#8c510a",
    Regime.SWEPT_CONTACT: "#88ccee",
    Regime.FAILED: "#000000",
    Regime.QUASI_PERIODIC: "#999933",
    Regime.CHAOTIC: "#aa3377",
    Regime.HELD_ON_STOP: "#663333",  # at least 15.2 CIELAB units from every other under simulated CVD
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
#: What a value of 0 of a quantity says, for the label of a 0 shared by several series (drawn once).
ZERO_MEANINGS = {"impulse": "no impacts", "impacts_per_period": "no impacts", "peak_acceleration": "no contact", "peak_contact_force": "no contact"}
#: A constant curve shared by several series (exactly 0 where none of them impacts), drawn once: dark grey, solid.
SHARED_STYLE = {"ls": "-", "lw": 2.0, "color": "#555555"}
#: Raw one-impact solution wherever eqs. 15-16 have a root, unchecked: thin and faint, behind everything.
RAW_STYLE = {"ls": "-", "lw": 0.7, "alpha": 0.35, "zorder": 1}


def series_colour(index: int) -> str:
    """Colour of the ``index``-th series of a figure whose series have no order (methods, coordinates: matplotlib's
    default cycle, ten colours); an ordered parameter's series take :func:`ordered_colours`."""
    return f"C{index % 10}"


#: Okabe-Ito's colours, told apart with any colour vision: the one qualitative palette of the pages (orbit classes and
#: special points of the bifurcation pages; the sweep directions are its vermillion and sky blue).
OKABE_ITO = ("#0072B2", "#E69F00", "#009E73", "#CC79A7", "#56B4E9", "#D55E00", "#F0E442", "#000000")
#: The one sequential palette of an ordered parameter's series on every page (restitution R, clearance Delta, bumper
#: frequency Omega_b, excitation frequency): viridis from its dark end to :data:`ORDERED_SPAN`'s top, short of the pale
#: yellow that vanishes on white. Nine values stay at least 8 CIELAB units apart pairwise, with normal vision and under
#: simulated protanopia, deuteranopia and tritanopia; matplotlib's default cycle had red beside green and brown beside
#: olive.
ORDERED_COLORMAP = "viridis"
#: The stretch of :data:`ORDERED_COLORMAP` the series share, [0, 1] of the colour map.
ORDERED_SPAN = (0.0, 0.9)
#: Line widths of an ordered parameter's series [pt]: the first widest, the last thinnest, so that where curves
#: coincide each earlier one shows around the later ones (no series is hidden under the last drawn).
ORDERED_WIDTHS = (2.8, 1.4)


def ordered_colours(count: int) -> list[str]:
    """The colours of ``count`` series of an ordered parameter, in its order (:data:`ORDERED_COLORMAP`)."""
    cmap = matplotlib.colormaps[ORDERED_COLORMAP]
    low, high = ORDERED_SPAN
    return [to_hex(cmap(low + (high - low) * k / max(count - 1, 1))) for k in range(count)]


def ordered_widths(count: int, single: float = 1.4) -> list[float]:
    """Line widths [pt] of ``count`` series of an ordered parameter (:data:`ORDERED_WIDTHS`, the first widest);
    ``single`` for one series."""
    if count <= 1:
        return [single] * count
    wide, thin = ORDERED_WIDTHS
    return [wide + (thin - wide) * k / (count - 1) for k in range(count)]


def solution_ref(solution: str) -> str:
    """How a caption names a solution."""
    return f"'{solution}'"


#: Sweep directions, one palette for every page: vermillion up, sky blue down (Okabe-Ito: told apart with any colour
#: vision, unlike red and green).
SWEEP_COLOURS = {"up": OKABE_ITO[5], "down": OKABE_ITO[4]}


def fmt(value: SupportsFloat | None, spec: str = ".3g", pattern: str = "{}") -> str:
    """The one number formatter of every report: ``value`` formatted with ``spec`` and put into ``pattern`` (its
    ``{}``, e.g. ``"{}x"`` or ``" ({} s)"``); empty for NaN, infinity or None (a table cell with nothing to show)."""
    if value is None:
        return ""
    number = float(value)
    if not math.isfinite(number):
        return ""
    text = format(number, spec)
    return pattern.format(text[:-1] if text.endswith(".") else text)  # '#' keeps trailing zeros, not a bare point: 1982, not 1982.


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


# ---------------------------------------------------------------------------------------------- layout
#: matplotlib settings while a page draws its figures (:func:`vibroimpact.reporting.page.write_report`): titles at the
#: top of their panel (no panel has ticks or labels above it) rather than placed by a search, which took ~20 % of a
#: figure's rendering.
REPORT_RC = {"axes.titley": 1.0}
#: Minor ticks (and grid lines) of a log axis: at 2 and 5 in each decade (matplotlib's 2, 3, ..., 9 made ~20 % of a
#: report's rendering time, in tick objects alone).
MINOR_LOG_TICKS = (2.0, 5.0)


def readable_scale(low: float, high: float) -> str:
    """``log`` for values spanning a decade or more (all above 0), else ``linear``: a log axis over less than a decade
    carries one or two labels (a panel of 2.3-5 mm was labelled "10" alone)."""
    return "log" if low > 0.0 and math.isfinite(high / low) and high / low >= 10.0 else "linear"


def drawn_scale(ax: Axes, which: str = "y") -> str:
    """The scale the ``which`` axis of ``ax`` is drawn on (:func:`linear_under_a_decade`): ``log`` where it is
    logarithmic and its view limits as they are now span a decade or more (:func:`readable_scale`), else ``linear``."""
    axis = ax.yaxis if which == "y" else ax.xaxis
    if axis.get_scale() != "log":
        return "linear"
    low, high = sorted(ax.get_ylim() if which == "y" else ax.get_xlim())
    return readable_scale(low, high)


def linear_under_a_decade(figure: MatplotlibFigure) -> None:
    """Every log axis of ``figure`` whose view spans less than a decade drawn linear instead (:func:`drawn_scale`): a
    log axis over 700-2000 m/s² or 2.3-3 mm reads as a linear one with crowded, uneven labels (``3 x 10^0``).
    Applied as figures are rendered, so that every page has it; a caption names the scale with :func:`scale_phrase`.
    A colorbar's axis keeps its scale (its norm sets it)."""
    for ax in figure.axes:
        if hasattr(ax, "_colorbar"):
            continue
        for which in ("x", "y"):
            axis = ax.yaxis if which == "y" else ax.xaxis
            if axis.get_scale() == "log" and drawn_scale(ax, which) == "linear":
                limits = ax.get_ylim() if which == "y" else ax.get_xlim()
                automatic = ax.get_autoscaley_on() if which == "y" else ax.get_autoscalex_on()
                (ax.set_yscale if which == "y" else ax.set_xscale)("linear")  # autoscaled again where it was
                if not automatic:  # limits the figure set stay
                    (ax.set_ylim if which == "y" else ax.set_xlim)(*limits)


def scale_phrase(axes: Sequence[Axes], which: str = "y") -> str:
    """How a caption names the scales of ``axes`` as drawn (:func:`drawn_scale`): ``log scale`` or ``linear scale``
    where they agree, else ``log scale, except panels 1, 2: linear, as they span less than a decade``, panels
    counted in ``axes``' order."""
    scales = [drawn_scale(ax, which) for ax in axes]
    if len(set(scales)) <= 1:
        return f"{scales[0] if scales else 'linear'} scale"
    linear = [str(k + 1) for k, scale in enumerate(scales) if scale == "linear"]
    many = len(linear) > 1
    return f"log scale, except panel{'s' if many else ''} {', '.join(linear)}: linear, as {'they span' if many else 'it spans'} less than a decade"


def _plain_number(value: float, _position: object = None) -> str:
    """A tick label as a plain number, six significant digits at most (2.5e+06, 0.003, 24.5): no offset or
    multiplier written apart at the axis' end, where it overprinted the panel's title ("1e6")."""
    return f"{value:.6g}"


def readable_axes(figure: MatplotlibFigure) -> None:
    """Every linear axis of ``figure`` (a colorbar's too) labelled with plain numbers (:func:`_plain_number`), never
    matplotlib's offset or ``1e6`` multiplier; every log axis still labelled by matplotlib's default (``10^0``,
    ``10^1`` alone over 0.5-50) labelled as :func:`plain_log` does (0.5, 1, 2, 5, 10, 20, 50). Applied as figures
    are rendered, so that every page has it."""
    for ax in figure.axes:
        for which, axis in (("x", ax.xaxis), ("y", ax.yaxis)):
            if axis.get_scale() == "linear" and type(axis.get_major_formatter()) is ScalarFormatter:
                axis.set_major_formatter(FuncFormatter(_plain_number))
            elif axis.get_scale() == "log" and type(axis.get_major_formatter()) is LogFormatterSciNotation and not hasattr(ax, "_colorbar"):
                plain_log(ax, which)


def thin_minor_log_ticks(figure: MatplotlibFigure) -> None:
    """Every log axis of ``figure`` with minor ticks at :data:`MINOR_LOG_TICKS` only (applied as figures are
    rendered, so every page has it, whichever way its panels were made logarithmic)."""
    for ax in figure.axes:
        for axis in (ax.xaxis, ax.yaxis):
            if axis.get_scale() == "log":
                axis.set_minor_locator(LogLocator(base=10.0, subs=MINOR_LOG_TICKS))


def new_figure(
    panels: int,
    panel_height: float = 3.6,
    columns: int = MAX_COLUMNS,
    sharex: bool = False,
    sharey: bool = False,
    legend_rows: int = 0,
    row_heights: Sequence[float] | None = None,
) -> tuple[MatplotlibFigure, list[Axes]]:
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
    row_heights : sequence of float, optional
        Height of each row [in] instead of ``panel_height`` for all.

    Returns
    -------
    (Figure, list of Axes)
        The figure and its panels in reading order.
    """
    columns = max(1, min(columns, MAX_COLUMNS, panels))
    rows = math.ceil(panels / columns)
    heights = list(row_heights) if row_heights is not None else [panel_height] * rows
    height = sum(heights) + 0.25 * legend_rows + (0.2 if legend_rows else 0.0)
    fig, grid = plt.subplots(
        rows, columns, figsize=(FIGURE_WIDTH, height), squeeze=False, sharex=sharex, sharey=sharey, layout="constrained", gridspec_kw={"height_ratios": heights}
    )
    axes = list(grid.flat)
    for ax in axes[panels:]:
        ax.remove()
    return fig, axes[:panels]


def figure_legend(fig: MatplotlibFigure, axes: Sequence[Axes], extra: Iterable[Line2D] = (), columns: int = 4) -> None:
    """One legend for the whole figure, below the panels (outside every axes, so it covers no data).

    Entries are the labelled artists of ``axes`` (each label once, in drawing order) followed by ``extra``, and the
    constants shared by several series of any panel, drawn once (gid ``shared:...``,
    :func:`~vibroimpact.reporting.coincide.reveal_coincident`): their label says whose they are.
    """
    entries: dict[str, object] = {}
    for ax in axes:
        for handle, label in zip(*ax.get_legend_handles_labels()):
            entries.setdefault(label, handle)
    for handle in extra:
        entries.setdefault(handle.get_label(), handle)
    for ax in fig.axes:
        for line in ax.get_lines():
            if str(line.get_gid()).startswith("shared:"):
                entries.setdefault(str(line.get_label()), line)
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


class PlainLogFormatter(LogFormatter):
    """matplotlib's choice of which log-axis ticks to label, written as plain numbers: 0.2, 3."""

    def _num_to_string(self, x: float, vmin: float, vmax: float) -> str:
        return f"{x:g}"


def plain_log(ax: Axes, which: str = "y") -> None:
    """Plain numbers on a log axis (0.5, 1, 2 rather than 5 x 10^-1). Over two decades or less (its limits as set
    now) every minor tick is labelled too, at 2 and 5 in each decade (:data:`MINOR_LOG_TICKS`, set as the figure is
    rendered): 0.2, 0.5, 1, 2, 5 rather than the one or two labels matplotlib's thinning leaves; wider, its thinning."""
    axis = ax.yaxis if which == "y" else ax.xaxis
    axis.set_major_formatter(FormatStrFormatter("%g"))
    low, high = sorted(ax.get_ylim() if which == "y" else ax.get_xlim())
    if low > 0.0 and high / low <= 100.0:
        axis.set_minor_formatter(FormatStrFormatter("%g"))
    else:
        axis.set_minor_formatter(PlainLogFormatter(labelOnlyBase=False, minor_thresholds=(1.0, 0.5)))
