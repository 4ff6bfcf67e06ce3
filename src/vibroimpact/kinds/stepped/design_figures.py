"""Figures of a design map: peak |X1| over (R, Delta) for each band, the realisable-regime map, and the frequency
response of the recommended design against the absorber without a stop.

Maps put the restitution ratio R across and the clearance Delta up, one cell per design of the grid. In every map
the recommended design's cell is framed, the designs whose working band impacts are hatched, the eligible region (working
band free of impacts) is outlined, and a dashed line marks the clearance the no-stop absorber's |X2| reaches in the
working band. Captions say what was drawn and from which solution.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr
from matplotlib import colormaps
from matplotlib.axes import Axes
from matplotlib.colors import BoundaryNorm, ListedColormap, LogNorm, Normalize, to_rgb
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Rectangle
from matplotlib.ticker import FormatStrFormatter, FuncFormatter

from vibroimpact.analysis.stability import Regime
from vibroimpact.kinds.stepped.design_metrics import BAND_NAMES, DESIGN_REGIME_LABELS, DesignRegime, no_stop_amplitude
from vibroimpact.kinds.stepped.design_ranking import DesignMap
from vibroimpact.reporting.page import DrawnFigure
from vibroimpact.reporting.series import OVER_MARKERS_ZORDER, SimulationMarkers, draw_curve, draw_points
from vibroimpact.reporting.style import MIN_FONT_SIZE, REGIME_COLOURS, SOLUTION_COLOURS, Caption, figure_legend, finish_axes, fmt, legend_rows, new_figure, solution_ref
from vibroimpact.scene.schema import ENGINE_SOLUTIONS

__all__ = ["BAND_TITLES", "REGIME_MAP_COLOURS", "peak_maps_figure", "regime_map_figure", "response_figure"]

#: Panel title of each band.
BAND_TITLES = {"lower": "lower resonance band", "working": "working band (anti-resonance)", "upper": "upper resonance band"}
#: Shading of each band in the frequency responses.
_BAND_SHADES = {"lower": "#fdeeee", "working": "#dff2d8", "upper": "#fdeeee"}
#: The regime flag each class of motion stands for: its colour is that flag's in the one regime palette.
_CLASS_FLAGS: dict[DesignRegime, Regime] = {
    DesignRegime.NO_IMPACT: Regime.LINEAR,
    DesignRegime.ONE_IMPACT: Regime.ONE_IMPACT,
    DesignRegime.PERIODIC_OTHER: Regime.PERIODIC_IMPACTS,
    DesignRegime.IRREGULAR: Regime.IRREGULAR,
    DesignRegime.UNRESOLVED: Regime.NONE,
    DesignRegime.NOT_COMPUTED: Regime.NOT_COMPUTED,
}
#: One colour per class of motion, all distinct, from :data:`~vibroimpact.reporting.style.REGIME_COLOURS`.
REGIME_MAP_COLOURS: dict[DesignRegime, str] = {k: REGIME_COLOURS[flag] for k, flag in _CLASS_FLAGS.items()}
#: Largest grid whose cells carry their value as text.
_ANNOTATED_CELLS = 120
#: Frequencies of the no-stop curve (its resonances are about 0.1 Hz wide).
_NO_STOP_POINTS = 8001
#: The recommended design's cell: a white frame inside a black one, visible on every colour and leaving its text readable.
_FRAME_OUTER = {"fill": False, "edgecolor": "k", "lw": 4.2, "zorder": 6}
_FRAME_INNER = {"fill": False, "edgecolor": "white", "lw": 1.8, "zorder": 6.1}
_REACH = {"color": "k", "ls": (0, (5, 3)), "lw": 1.2, "zorder": 5}
_OUTLINE = {"color": "k", "lw": 2.4, "zorder": 5, "solid_capstyle": "projecting"}
_HATCH = {"fill": False, "hatch": "///", "edgecolor": "0.35", "lw": 0.0, "zorder": 4}
_FREQUENCY = "excitation frequency [Hz]"
_R_LABEL = "restitution ratio R [-]"
_DELTA_LABEL = "clearance Delta [mm]"


def _edges(centres: np.ndarray) -> np.ndarray:
    """Cell edges around grid values: midpoints, the outer cells as wide as their neighbour; a single value gets a
    cell 20 % of its size wide (0.1 wide around zero)."""
    c = np.asarray(centres, dtype=float)
    if c.size == 1:
        half = 0.1 * abs(float(c[0])) or 0.05
        return np.array([c[0] - half, c[0] + half])
    mid = 0.5 * (c[1:] + c[:-1])
    return np.concatenate([[2 * c[0] - mid[0]], mid, [2 * c[-1] - mid[-1]]])


def _grid(dm: DesignMap) -> tuple[np.ndarray, np.ndarray]:
    """(R, Delta [mm]) of the designs."""
    return np.asarray(dm.regimes["restitution"].values, float), 1e3 * np.asarray(dm.regimes["clearance"].values, float)


def _eligible(dm: DesignMap) -> np.ndarray:
    """Eligibility per (R, Delta)."""
    r, c = _grid(dm)
    flags = np.zeros((r.size, c.size), bool)
    for k, design in enumerate(dm.designs):
        flags[k // c.size, k % c.size] = design.eligible
    return flags


def _overlay(ax: Axes, dm: DesignMap, annotate: np.ndarray | None = None, texts: np.ndarray | None = None, norm: Normalize | None = None, dark: np.ndarray | None = None) -> None:
    """Hatch the designs whose working band impacts, outline the eligible region, the reach of the no-stop |X2|, the
    recommended design, and (small grids) each cell's text: white on a dark cell (``dark``, or the lower part of
    ``norm``), black elsewhere."""
    r, c = _grid(dm)
    xe, ye = _edges(r), _edges(c)
    eligible = _eligible(dm)
    for i in range(r.size):
        for j in range(c.size):
            if not eligible[i, j]:
                ax.add_patch(Rectangle((xe[i], ye[j]), xe[i + 1] - xe[i], ye[j + 1] - ye[j], **_HATCH))
            for di, dj in ((1, 0), (-1, 0), (0, 1), (0, -1)):  # boundary of the eligible region
                ni, nj = i + di, j + dj
                outside = not (0 <= ni < r.size and 0 <= nj < c.size) or not eligible[ni, nj]
                if eligible[i, j] and outside:
                    x = [xe[i + (di > 0)]] * 2 if di else [xe[i], xe[i + 1]]
                    y = [ye[j + (dj > 0)]] * 2 if dj else [ye[j], ye[j + 1]]
                    ax.plot(x, y, **_OUTLINE)
            if texts is not None and annotate is not None and texts[i, j]:
                white = bool(dark[i, j]) if dark is not None else norm is not None and math.isfinite(annotate[i, j]) and norm(annotate[i, j]) < 0.45
                ax.text(r[i], c[j], texts[i, j], ha="center", va="center", fontsize=MIN_FONT_SIZE, color="white" if white else "black", zorder=7)
    if math.isfinite(dm.working_clearance) and ye[0] < 1e3 * dm.working_clearance < ye[-1]:
        ax.axhline(1e3 * dm.working_clearance, **_REACH)
    if dm.recommendation is not None:
        i = int(np.argmin(np.abs(r - dm.recommendation.design.restitution)))
        j = int(np.argmin(np.abs(c - 1e3 * dm.recommendation.design.clearance)))
        for style in (_FRAME_OUTER, _FRAME_INNER):
            ax.add_patch(Rectangle((xe[i], ye[j]), xe[i + 1] - xe[i], ye[j + 1] - ye[j], **style))
    ax.set_xlim(xe[0], xe[-1])
    ax.set_ylim(ye[0], ye[-1])
    ax.set_xlabel(_R_LABEL)
    ax.set_ylabel(_DELTA_LABEL)


def _keys(dm: DesignMap) -> list[Line2D | Patch]:
    """Legend entries of :func:`_overlay`."""
    keys: list[Line2D | Patch] = [Patch(facecolor="none", edgecolor="0.35", hatch="///", label="working band impacts: excluded"),
                                  Line2D([], [], label="edge of the impact-free working band", **_OUTLINE)]  # fmt: skip
    if math.isfinite(dm.working_clearance):
        keys.append(Line2D([], [], label=f"Delta = {fmt(1e3 * dm.working_clearance, '.3g')} mm: largest no-stop |X2| in the working band", **_REACH))
    if dm.recommendation is not None:
        keys.append(Patch(facecolor="none", edgecolor="k", lw=2.5, label="recommended design (framed cell)"))
    return keys


#: Relative luminance below which white text contrasts more than black (WCAG: (1 + 0.05) / (L + 0.05) > (L + 0.05) / 0.05).
_WHITE_TEXT_BELOW = 0.179


def _luminance(colour: str) -> float:
    """Relative luminance of ``colour`` (0 black, 1 white; WCAG): dark cells take white text."""
    linear = [c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4 for c in to_rgb(colour)]
    return 0.2126 * linear[0] + 0.7152 * linear[1] + 0.0722 * linear[2]


def _cell_text(values: np.ndarray, bounds: np.ndarray, spec: str) -> np.ndarray:
    """Text of each cell: the value (mm), '>=' before a lower bound, 'n/a' for NaN."""
    text = np.empty(values.shape, dtype=object)
    for index, value in np.ndenumerate(values):
        text[index] = ("≥" if bounds[index] else "") + fmt(value, spec) if math.isfinite(value) else "n/a"
    return text


def peak_maps_figure(dm: DesignMap) -> DrawnFigure:
    """Peak |X1| of the design solution over (R, Delta): one panel per band and one of the larger resonance peak
    (what the recommendation minimises), one logarithmic colour scale in mm."""
    r, c = _grid(dm)
    peaks = 1e3 * dm.peaks["peak_x1_amplitude"].transpose("band", "restitution", "clearance").values
    unknown = dm.peaks["unknown_points"].transpose("band", "restitution", "clearance").values > 0
    objective = np.fmax(peaks[0], peaks[2])
    objective[~np.isfinite(peaks[0]) | ~np.isfinite(peaks[2])] = np.nan
    panels = [(peaks[0], unknown[0], "lower"), (peaks[2], unknown[2], "upper"), (peaks[1], unknown[1], "working"), (objective, unknown[0] | unknown[2], None)]
    finite = np.concatenate([p[np.isfinite(p) & (p > 0)] for p, _, _ in panels])
    norm = LogNorm(vmin=float(finite.min()), vmax=float(finite.max())) if finite.size else LogNorm(1e-3, 1.0)
    annotate = r.size * c.size <= _ANNOTATED_CELLS
    fig, axes = new_figure(4, panel_height=4.3, legend_rows=legend_rows(4, 2))
    mesh = None
    for ax, (values, bounds, band) in zip(axes, panels):
        mesh = ax.pcolormesh(_edges(r), _edges(c), values.T, cmap=colormaps["viridis"].with_extremes(bad="#d9d9d9"), norm=norm, shading="flat")
        text = _cell_text(values, bounds, ".2g") if annotate else None
        if not annotate:
            _contours(ax, r, c, values)
        _overlay(ax, dm, values, text, norm)
        if band is None:
            title = "larger of the two resonance peaks (minimised)"
        else:
            nostop = dm.no_stop[band]
            title = f"{BAND_TITLES[band]} {dm.bands.describe(band, dm.frequency)}\nno stop: {fmt(1e3 * nostop.value, '.3g')} mm at {fmt(nostop.frequency, '.2f')} Hz"
        ax.set_title(title, fontsize=MIN_FONT_SIZE + 1)
    bar = fig.colorbar(mesh, ax=axes, label="peak |X1| [mm] (log scale)", shrink=0.9, pad=0.01)
    bar.ax.yaxis.set_major_formatter(FormatStrFormatter("%g"))
    bar.ax.yaxis.set_minor_formatter(FuncFormatter(lambda v, _: f"{v:g}" if round(v / 10 ** math.floor(math.log10(v)), 6) in (2.0, 5.0) else ""))
    figure_legend(fig, axes, _keys(dm), columns=2)
    caption = Caption(f"Peak of the fundamental |X1| of the primary mass over each band, for every design (R across, Delta up), from solution {solution_ref(dm.solution)} on its {dm.frequency.size} frequencies; one logarithmic colour scale for the four panels, in mm.")
    caption.add("realised", "A peak is taken over the motion that is realised: no impact, a stable one-impact orbit, other periodic motion or irregular motion (its fundamental over the measured periods); never an unstable orbit's value.")
    if not annotate:
        caption.add("contours", "White lines: contours of the panel's peak, labelled in mm.")
    if annotate:
        caption.add("text", "Each cell gives its value; '≥' marks a lower bound (some frequencies of the band have no realised value), grey cells 'n/a' none at all.")
    elif np.any(unknown):
        caption.add("bounds", "Grey cells have no realised value in the band.")
    caption.add("nostop", "Panel titles give the band and the peak of the same absorber without a stop (analytic for the resonance bands; in the working band on the same grid).")
    caption.add("overlay", "Hatched: designs whose working band impacts (excluded from the recommendation); thick black line: edge of the region whose working band is free of impacts; dashed: the clearance the no-stop absorber's |X2| reaches in the working band; framed cell: the recommended design.")
    return DrawnFigure(fig, "design_peaks", "Peak |X1| over restitution and clearance, per band", caption.text())


def _share_panel(ax: Axes, dm: DesignMap, share: np.ndarray, title: str, colours: str, full: bool = True) -> None:
    """A map of a share of the frequencies [%], its colour bar (0-100 %, or up to the next 10 % above the largest
    value unless ``full``) and (small grids) each cell's value."""
    r, c = _grid(dm)
    top = float(np.nanmax(share)) if np.any(np.isfinite(share)) else 100.0
    norm = Normalize(0.0, 100.0 if full else max(10.0, 10.0 * math.ceil(top / 10.0)))
    mesh = ax.pcolormesh(_edges(r), _edges(c), share.T, cmap=colormaps[colours].with_extremes(bad="#d9d9d9"), norm=norm, shading="flat")
    annotate = r.size * c.size <= _ANNOTATED_CELLS
    _overlay(ax, dm, norm.vmax - share, _cell_text(share, np.zeros(share.shape, bool), ".0f") if annotate else None, norm)
    ax.set_title(title, fontsize=MIN_FONT_SIZE + 1)
    ax.figure.colorbar(mesh, ax=ax, label="[% of frequencies]", pad=0.01)


def _contours(ax: Axes, r: np.ndarray, c: np.ndarray, values: np.ndarray) -> None:
    """Labelled contours of ``values`` [mm] at round levels (1, 2, 3, 5 per decade) within their range."""
    finite = values[np.isfinite(values) & (values > 0)]
    if finite.size < 4 or r.size < 3 or c.size < 3:
        return
    decades = range(int(math.floor(math.log10(finite.min()))), int(math.ceil(math.log10(finite.max()))) + 1)
    levels = [m * 10.0**d for d in decades for m in (1.0, 2.0, 3.0, 5.0) if finite.min() < m * 10.0**d < finite.max()]
    if levels:
        lines = ax.contour(r, c, np.ma.masked_invalid(values.T), levels=levels, colors="white", linewidths=0.9, zorder=3)
        ax.clabel(lines, fmt="%g", fontsize=MIN_FONT_SIZE, inline_spacing=2)


def regime_map_figure(dm: DesignMap) -> DrawnFigure:
    """For every design: the worst motion met over the frequency range (one colour per class), the share of the
    frequencies where the motion impacts, where it is irregular, and (if any) where it is unknown."""
    r, c = _grid(dm)
    regimes = dm.regimes.transpose("restitution", "clearance")
    worst = regimes["worst_regime"].values.astype(int)
    points = float(dm.frequency.size)
    irregular = 100.0 * regimes["count_irregular"].values / points
    unknown = 100.0 * (regimes["count_unresolved"].values + regimes["count_not_computed"].values) / points
    classes = list(DesignRegime)
    shares = [(100.0 * regimes["impact_fraction"].values, "frequencies with impacts [% of those known]", "Blues", True)]
    if dm.solution in ENGINE_SOLUTIONS:  # a closed form cannot see irregular motion: no panel of zeros
        shares.append((irregular, "frequencies of irregular motion [%]", "Purples", False))
    if np.any(unknown > 0):
        shares.append((unknown, "frequencies unresolved or not computed [%]", "Reds", False))
    panels = 1 + len(shares)
    fig, axes = new_figure(panels, panel_height=4.4, legend_rows=legend_rows(len(classes) + 4, 2))
    colours = ListedColormap([REGIME_MAP_COLOURS[k] for k in classes])
    categorical = BoundaryNorm(np.arange(len(classes) + 1) - 0.5, len(classes))
    axes[0].pcolormesh(_edges(r), _edges(c), worst.T, cmap=colours, norm=categorical, shading="flat")
    annotate = r.size * c.size <= _ANNOTATED_CELLS
    counts = np.zeros(worst.shape, dtype=object)
    for index, flag in np.ndenumerate(worst):
        counts[index] = str(int(regimes[f"count_{DesignRegime(flag).name.lower()}"].values[index]))
    dark = np.vectorize(lambda flag: _luminance(REGIME_MAP_COLOURS[DesignRegime(flag)]) < _WHITE_TEXT_BELOW)(worst)
    _overlay(axes[0], dm, worst.astype(float), counts if annotate else None, None, dark)
    axes[0].set_title("worst motion over the frequency range", fontsize=MIN_FONT_SIZE + 1)
    for ax, (share, title, colours, full) in zip(axes[1:], shares):
        _share_panel(ax, dm, share, title, colours, full)
    present = sorted(set(int(k) for k in np.unique(worst)))
    keys = [Patch(facecolor=REGIME_MAP_COLOURS[k], edgecolor="0.3", label=f"worst: {DESIGN_REGIME_LABELS[k]}") for k in classes if int(k) in present]
    figure_legend(fig, axes, keys + _keys(dm), columns=2)
    caption = Caption(f"For every design (R across, Delta up), what solution {solution_ref(dm.solution)} finds on its {dm.frequency.size} frequencies. First panel: the worst motion met, "
                      "in the order " + " < ".join(DESIGN_REGIME_LABELS[k] for k in classes) + ".")  # fmt: skip
    if annotate:
        caption.add("counts", "Each cell gives at how many frequencies that worst motion occurs.")
    caption.add("classes", "Unresolved: the closed form has no stable orbit there (none, inadmissible or unstable), so the motion is unknown and may be irregular; a simulation resolves it.")
    caption.add("impacts", "Next: the share of the frequencies whose motion impacts (where the linear motion crosses the stop every motion impacts, unresolved or not), among those where this is known.")
    caption.add("shares", "Then: " + "; ".join(title for _, title, _, _ in shares[1:]) + "." if len(shares) > 1 else "")
    if dm.solution not in ENGINE_SOLUTIONS:
        caption.add("closed", f"A closed form cannot tell irregular motion: only a simulation can, which is why {solution_ref(dm.solution)} leaves frequencies unresolved.")
    caption.add("overlay", "Hatched: the working band impacts; thick line: edge of the impact-free working band; dashed: the clearance the no-stop |X2| reaches in the working band; framed cell: the recommended design.")
    return DrawnFigure(fig, "design_regimes", "Realisable motion over restitution and clearance", caption.text())


def _shade_bands(ax: Axes, dm: DesignMap, f: np.ndarray, named: bool) -> None:
    """Shade the three bands; ``named``: write each band's name at the top of the panel."""
    for band in BAND_NAMES:
        low, high = max(dm.bands.limits(band)[0], float(f.min())), min(dm.bands.limits(band)[1], float(f.max()))
        ax.axvspan(low, high, color=_BAND_SHADES[band], zorder=0, lw=0)
        if named:
            ax.text(0.5 * (low + high), 0.97, "working\nband" if band == "working" else BAND_TITLES[band], transform=ax.get_xaxis_transform(), ha="center", va="top", fontsize=MIN_FONT_SIZE, color="0.3")


def response_figure(dataset: xr.Dataset, dm: DesignMap) -> DrawnFigure | None:
    """|X1| and |X2| against frequency at the recommended design: the absorber without a stop, the closed form
    ``pgf`` (solid stable, dashed unstable) and the simulations, the bands shaded and the design solution's band
    peaks marked."""
    if dm.recommendation is None:
        return None
    best = dm.recommendation.design
    at = {name: value for name, value in (("restitution", best.restitution), ("clearance", best.clearance)) if name in dataset.dims}
    part = dataset.sel(at, method="nearest") if at else dataset
    f = np.asarray(dataset["frequency"].values, float)
    names = [str(s) for s in dataset["solution"].values]
    fig, axes = new_figure(2, panel_height=4.2, columns=1, legend_rows=legend_rows(9, 3))
    caption = Caption(f"The recommended design, R = {fmt(best.restitution, 'g')}, Delta = {fmt(1e3 * best.clearance, '.4g')} mm: fundamental amplitudes against frequency, log scales.")
    markers = SimulationMarkers()
    for ax, quantity, symbol in ((axes[0], "x1", "|X1|"), (axes[1], "x2", "|X2|")):
        _shade_bands(ax, dm, f, named=quantity == "x1")
        _no_stop(ax, dataset, part, quantity, f, caption)
        if "pgf" in names:
            unstable = part["stable"].sel(solution="pgf").values == 0 if "stable" in part else None
            draw_curve(ax, f, 1e3 * part[f"{quantity}_amplitude"].sel(solution="pgf").values, colour=SOLUTION_COLOURS["pgf"], label="closed form 'pgf' (one impact per period)", gid="pgf", unstable=unstable, zorder=OVER_MARKERS_ZORDER)
            caption.add("pgf", "Blue: the one-impact closed form 'pgf' wherever its orbit is admissible, solid where stable (Floquet), dashed where unstable; linear where the motion clears the stop; gaps where it has no orbit.")
        for engine in (n for n in names if n not in ("linear", "pgf", "pgf_paper")):
            values = part[f"{quantity}_amplitude"].sel(solution=engine).values
            periodic = part["converged"].sel(solution=engine).values == 1 if "converged" in part else np.ones(f.shape, bool)
            markers.add(engine, draw_points(ax, f, 1e3 * values, periodic=periodic, solution=engine, colour=SOLUTION_COLOURS.get(engine, "C2"), label=solution_ref(engine)))
        finish_axes(ax, _FREQUENCY, f"{symbol} [mm]", f"{symbol}, {'primary mass' if quantity == 'x1' else 'absorber'}", log=True)
        ax.set_xlim(float(f.min()), float(f.max()))
    axes[1].axhline(1e3 * best.clearance, color="C3", lw=1.0, ls="-.", label="the clearance Delta")
    peaks = [(best.peak_frequencies[b], 1e3 * best.peaks[b]) for b in BAND_NAMES if math.isfinite(best.peaks[b])]
    axes[0].plot([p[0] for p in peaks], [p[1] for p in peaks], "v", ms=9, mfc="gold", mec="k", ls="none", zorder=8, label="band peaks (the table's numbers)")
    caption.add("markers", markers.phrase())
    companion = " and, where larger, the closed form's stable state coexisting with it" if any(best.peak_from_closed_form.values()) else ""
    caption.add("peaks", f"Gold triangles: the peak of each band taken from {solution_ref(dm.solution)}{companion} (the table's numbers). Shaded: the resonance bands (pale red) and the working band (green), named in the upper panel. Lower panel: the absorber's |X2| and the clearance (dash-dotted red).")
    figure_legend(fig, axes, columns=3)
    return DrawnFigure(fig, "design_response", "Frequency response of the recommended design", caption.text())


def _no_stop(ax: Axes, dataset: xr.Dataset, part: xr.Dataset, quantity: str, f: np.ndarray, caption: Caption) -> None:
    """The absorber without a stop: analytic on a fine grid where the dataset stores the system, else the ``linear``
    solution."""
    dense = np.linspace(float(f.min()), float(f.max()), _NO_STOP_POINTS)
    values = no_stop_amplitude(dataset, dense, quantity)
    if values is not None:
        ax.plot(dense, 1e3 * values, color="k", ls=":", lw=1.3, label="no stop (closed form 'linear')", gid="linear")
        caption.add("nostop", f"Dotted black: the same absorber without a stop (closed form 'linear', on {_NO_STOP_POINTS} frequencies: its resonances are about 0.1 Hz wide).")
    elif "linear" in part["solution"].values:
        ax.plot(f, 1e3 * part[f"{quantity}_amplitude"].sel(solution="linear").values, color="k", ls=":", lw=1.3, label="no stop (closed form 'linear')", gid="linear")
        caption.add("nostop", "Dotted black: the same absorber without a stop (closed form 'linear').")
