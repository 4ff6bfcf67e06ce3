"""Figures of the frequency-response pages (paper figures 2-8 and 21-24): linear system, responses of every solution,
regime maps, stability, and simulations against the closed form; the linear-system section the swept-sine and bumper
pages open with, and what those pages share (:class:`SolutionsPage`; the stepped page draws its linear system for any
layout, :func:`vibroimpact.kinds.stepped.figures.structure_figure`).

Each builder returns a :class:`~vibroimpact.reporting.page.DrawnFigure` whose caption is put together from what was
drawn. Closed forms are drawn as curves on the dataset's grid, simulations as markers on their own grid
(:mod:`vibroimpact.reporting.series`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr
from matplotlib.colors import BoundaryNorm, ListedColormap
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Rectangle

from vibroimpact.analysis.linear import linear_response
from vibroimpact.model.modal import fit_modal_parameters, underdamped_mode_count
from vibroimpact.analysis.stability import Regime
from vibroimpact.reporting.coincide import coincidence_phrase, reveal_coincident
from vibroimpact.reporting.page import DrawnFigure, Section, saved
from vibroimpact.reporting.record import StudySetting
from vibroimpact.reporting.series import OVER_MARKERS_ZORDER, SimulationMarkers, draw_curve, draw_linear, draw_points, periodic_points, stability_keys, unstable_points
from vibroimpact.reporting.style import (
    DISPLACEMENT_SCALE,
    DISPLACEMENT_UNITS,
    LINEAR_STYLE,
    QUANTITIES,
    RAW_STYLE,
    REGIME_COLOURS,
    SOLUTION_COLOURS,
    SOLUTION_DESCRIPTIONS,
    SOLUTION_TITLES,
    Caption,
    axis_label,
    figure_legend,
    finish_axes,
    fmt,
    legend_rows,
    new_figure,
    regime_label,
    series_colour,
    solution_ref,
)
from vibroimpact.kinds.stepped.tables import modal_table
from vibroimpact.scene.schema import ENGINE_SOLUTIONS

__all__ = ["SolutionsPage", "linear_section", "linear_figure", "response_figure", "regime_figure", "regime_map", "block_edges", "stability_figure", "simulation_figure", "series_by_restitution", "clearance_text"]

#: Frequencies of the linear system's figure (0.0075 Hz over 15-45 Hz: the resonances are about 0.1 Hz wide).
LINEAR_FIGURE_POINTS = 4001
#: Fewer grid points than this: closed-form curves also get a marker per value.
COARSE_GRID_POINTS = 30
_FREQUENCY = "frequency [Hz]"


def clearance_text(part: xr.Dataset) -> str:
    """Delta of a dataset at one clearance, in mm (a general layout whose stops have their own clearances: its stops
    in words)."""
    if "clearance" not in part.coords:
        return f"stops {part.attrs.get('stop_layout', '')}"
    return f"Delta = {fmt(float(part['clearance']) * 1e3, '.6g')} mm"


def series_by_restitution(part: xr.Dataset) -> list[tuple[str, xr.Dataset]]:
    """(legend text, dataset) for each restitution ratio of ``part`` (one series, "each stop's R", where the stops of
    a general layout have their own)."""
    if "restitution" in part.dims:
        return [(f"R = {fmt(r, 'g')}", part.sel(restitution=r)) for r in part["restitution"].values]
    if "restitution" not in part.coords:
        return [("each stop's R", part)]
    return [(f"R = {fmt(part['restitution'], 'g')}", part)]


class SolutionsPage:
    """What the pages of stepped and swept studies share: the dataset, what it says of its study, and the summary
    naming the solutions; each page gives its own sections.

    Parameters
    ----------
    dataset : xarray.Dataset
        The study's dataset.
    setting : StudySetting
        What the dataset says of its system, excitation and grids.
    """

    def __init__(self, dataset: xr.Dataset, setting: StudySetting) -> None:
        self.dataset = dataset
        self.setting = setting

    def summary(self) -> str:
        """The solutions of the study."""
        return f"solutions: {', '.join(self.setting.solutions)}"


def linear_section(setting: StudySetting, out: Path) -> Section:
    """The section the swept-sine and bumper pages open with: the linear system and the modal parameters of H22."""
    return Section("Linear system", figures=saved([linear_figure(setting)], out), tables=[modal_table(setting.system)])


def linear_figure(setting: StudySetting) -> DrawnFigure:
    """Linear responses, force on the base and the curve fit of H22 (paper figures 2-4)."""
    system = setting.system
    # the closed form is cheap: a fine grid over the study's range (its own grid may be a handful of points)
    f = np.union1d(setting.frequency, np.linspace(setting.frequency.min(), setting.frequency.max(), LINEAR_FIGURE_POINTS))
    w = 2.0 * np.pi * f
    response = linear_response(system, omega=w, amplitude=setting.amplitude)
    fit = fit_modal_parameters(system) if underdamped_mode_count(system) == 2 else None
    fig, axes = new_figure(3, panel_height=3.6, legend_rows=2)
    ax = axes[0]
    ax.semilogy(f, DISPLACEMENT_SCALE * np.abs(response.x1), label="|X1| primary", color="C0", lw=1.4, gid="linear")
    ax.semilogy(f, DISPLACEMENT_SCALE * np.abs(response.x2), label="|X2| absorber", color="C1", lw=1.4, gid="linear")
    for delta in setting.clearance:
        ax.axhline(DISPLACEMENT_SCALE * delta, color="k", lw=0.9, ls="--")
    finish_axes(ax, _FREQUENCY, f"amplitude [{DISPLACEMENT_UNITS}]", "Linear responses (paper fig. 2)")
    ax = axes[1]
    ax.semilogy(f, np.abs(response.force), color="C2", lw=1.4, gid="linear")
    finish_axes(ax, _FREQUENCY, "|F| on the base [N]", "Linear force on the base (paper fig. 3)")
    ax = axes[2]
    ax.semilogy(f, np.abs(system.receptances(w).h22), label="|H22| exact (eq. 4)", color="k", lw=1.4)
    if fit is not None:
        step = max(1, f.size // 120)
        ax.semilogy(f[::step], np.abs(fit.receptance(w[::step])), "o", color="C3", mfc="none", ms=4.5, label="|H22| of eq. 10, the paper's fitted modes")
    finish_axes(ax, _FREQUENCY, "|H22| [m/N]", "Accuracy of the curve fit (paper fig. 4)")
    figure_legend(fig, axes, [Line2D([], [], color="k", lw=0.9, ls="--", label="clearance Delta")])
    natural = ", ".join(fmt(x / (2 * np.pi), ".3f") for x in system.natural_angular_frequencies())
    caption = (
        f"Linear system (Delta -> infinity): |X1| and |X2| (dashed: the clearance), the force on the base, and |H22| exact "
        f"{'against the paper' + chr(39) + 's curve fit (circles)' if fit is not None else '(the paper' + chr(39) + 's fit needs two underdamped modes)'}. "
        f"Natural frequencies {natural} Hz, anti-resonance {fmt(system.antiresonance_angular_frequency() / (2 * np.pi), '.3f')} Hz."
    )
    return DrawnFigure(fig, "linear", "Linear responses, force on the base, fit of H22", caption)


def response_figure(part: xr.Dataset, quantity: str, name: str) -> DrawnFigure | None:
    """One panel per solution with values of ``quantity``: closed forms as curves, simulations as markers, one colour
    per restitution ratio, the linear system dotted (paper figures 5-8). None if nothing has a finite value."""
    q = QUANTITIES[quantity]
    present = [str(s) for s in part["solution"].values]
    candidates = [s for s in present if s != "linear"] or ["linear"]
    panels = [s for s in candidates if np.isfinite(part[quantity].sel(solution=s).values).any()]
    if not panels:
        return None
    lines = series_by_restitution(part)
    f = part["frequency"].values
    coarse = f.size < COARSE_GRID_POINTS
    with_linear = "linear" in present and quantity != "impulse"
    raw_name = f"one_impact_{quantity}"
    caption = Caption(
        f"{q.label} ({q.meaning}) against frequency, {clearance_text(part)}, one colour per restitution ratio; one panel "
        f"per solution: {'; '.join(f'{solution_ref(s)}, {SOLUTION_DESCRIPTIONS.get(s, s)}' for s in panels)}."
    )
    fig, axes = new_figure(len(panels), panel_height=3.7, sharey=True, legend_rows=legend_rows(len(lines) + 6))
    engines = SimulationMarkers()
    any_unstable = gaps = raw = False
    curves: list[list[tuple[str, list[Line2D]]]] = []
    for ax, solution in zip(axes, panels):
        curves.append([])
        if with_linear or solution == "linear":
            draw_linear(ax, f, q.scale * part[quantity].sel(solution="linear").isel(_first(part)).values, coarse)
            caption.add("linear", "LIN (dotted black): the linear system (no stop).")
        for i, (text, line) in enumerate(lines if solution != "linear" else []):
            values = q.scale * line[quantity].sel(solution=solution).values
            if solution in ENGINE_SOLUTIONS:
                engines.add(solution, draw_points(ax, f, values, periodic=periodic_points(line, solution), solution=solution, colour=series_colour(i), label=None))
                continue
            before = len(ax.lines)
            _, unstable = draw_curve(ax, f, values, colour=series_colour(i), label=None, gid=solution, unstable=unstable_points(line, solution), coarse=coarse)
            curves[-1].append((text, list(ax.lines[before:])))
            any_unstable |= unstable
            gaps |= bool(np.isnan(values).any())
            if raw_name in line and solution != "linear":
                raw_values = q.scale * line[raw_name].sel(solution=solution).values
                if np.isfinite(raw_values).any():
                    ax.plot(f, raw_values, color=series_colour(i), label="_nolegend_", gid=f"raw:{solution}", **RAW_STYLE)
                    raw = True
        finish_axes(ax, _FREQUENCY, axis_label(quantity), f"{solution_ref(solution)}: {SOLUTION_TITLES.get(solution, solution)}", log=q.log)
    if any_unstable:
        caption.add("unstable", "Curves: solid where the one-impact orbit is stable (or the motion linear), dashed where it exists but is unstable (Floquet): the real motion there is another one.")
    if gaps:
        caption.add("gaps", "Gaps in a curve: no admissible one-impact regime while the linear motion would cross the stop.")
    if raw:
        caption.add("raw", "Faint thin lines: the raw one-impact solution wherever eqs. 15-16 have a root, unchecked (admissible or not, stable or not): what the paper plots, spikes included.")
    if engines:
        caption.add("engines", engines.phrase())
    finite = q.scale * part[quantity].sel(solution=[*panels, *(["linear"] if with_linear else [])]).values
    top = float(np.max(finite[np.isfinite(finite)], initial=0.0))
    if top > 0.0:
        axes[0].set_ylim(top=3.0 * top if q.log else 1.1 * top)
    coincide = coincidence_phrase(found for ax, drawn in zip(axes, curves) for found in reveal_coincident(ax, drawn))
    keys = [Patch(color=series_colour(i), label=text) for i, (text, _) in enumerate(lines)]
    if with_linear:
        keys.append(Line2D([], [], label="LIN (linear system)", **LINEAR_STYLE))
    keys += stability_keys() if any_unstable else []
    keys += [Line2D([], [], color="k", label="raw one-impact solution", **RAW_STYLE)] if raw else []
    figure_legend(fig, [], keys + engines.keys())
    caption.add("coincide", coincide)
    missing = [s for s in candidates if s not in panels]
    tail = f"No finite values, not drawn: {', '.join(solution_ref(s) for s in missing)}." if missing else ""
    return DrawnFigure(fig, name, f"{q.label[:1].upper()}{q.label[1:]}, {clearance_text(part)}", caption.text(tail))


def _first(part: xr.Dataset) -> dict[str, int]:
    """Index the first restitution value (the linear response does not depend on it)."""
    return {"restitution": 0} if "restitution" in part.dims else {}


def regime_figure(part: xr.Dataset, name: str) -> DrawnFigure:
    """Regime flag of every point: one panel per solution, one row per restitution ratio, one colour per flag; the
    closed-form one-impact orbits that are unstable (``stable`` = 0) hatched over their colour."""
    lines = series_by_restitution(part)
    panels = []
    for s in part["solution"].values:
        flags = np.array([line["regime"].sel(solution=s).values for _, line in lines], dtype=int)
        unstable = np.array([line["stable"].sel(solution=s).values == 0 for _, line in lines]) if "stable" in part else None
        panels.append((f"{solution_ref(str(s))}: regime, {clearance_text(part)}", [text for text, _ in lines], flags, unstable))
    solutions = ", ".join(solution_ref(str(s)) for s in part["solution"].values)
    return regime_map(panels, part["frequency"].values, name, f"Regime map, {clearance_text(part)}", f"Regime of each point of {solutions}")


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


def stability_figure(part: xr.Dataset, name: str) -> DrawnFigure:
    """Largest Floquet multiplier modulus of the pgf one-impact orbit against frequency."""
    lines = series_by_restitution(part)
    f = part["frequency"].values
    fig, axes = new_figure(1, panel_height=3.8, legend_rows=legend_rows(len(lines) + 1, 6))
    ax = axes[0]
    curves: list[tuple[str, list[Line2D]]] = []
    for i, (text, line) in enumerate(lines):
        before = len(ax.lines)
        draw_curve(ax, f, line["floquet_modulus"].sel(solution="pgf").values, colour=series_colour(i), label=text, gid="pgf", coarse=f.size < COARSE_GRID_POINTS)
        curves.append((text, list(ax.lines[before:])))
    ax.axhline(1.0, color="k", lw=1.0, label="stability limit 1")
    finish_axes(ax, _FREQUENCY, axis_label("floquet_modulus"), f"{solution_ref('pgf')}: stability of the one-impact orbit, {clearance_text(part)}", log=True)
    coincide = coincidence_phrase(reveal_coincident(ax, curves))
    figure_legend(fig, axes, columns=6)
    caption = (
        f"{QUANTITIES['floquet_modulus'].label} of the exact one-impact orbit of {solution_ref('pgf')} (monodromy = impact "
        "saltation matrix x exact flow over the period), one colour per restitution ratio. Above 1 the orbit exists but "
        "is unstable: a simulation started on it leaves it." + (f" {coincide}" if coincide else "")
    )
    return DrawnFigure(fig, name, f"Stability of the one-impact orbit, {clearance_text(part)}", caption)


def simulation_figure(part: xr.Dataset, quantity: str, engines: list[str], name: str) -> DrawnFigure | None:
    """Simulations against the closed form, one panel per restitution ratio (paper figures 21-24)."""
    q = QUANTITIES[quantity]
    lines = series_by_restitution(part)
    present = [str(s) for s in part["solution"].values]
    f = part["frequency"].values
    drawn = [e for e in engines if np.isfinite(part[quantity].sel(solution=e).values).any()]
    if not drawn:
        return None
    closed = "pgf" if "pgf" in present else None
    coarse = f.size < COARSE_GRID_POINTS
    panels = "one panel per restitution ratio" if len(lines) > 1 else lines[0][0]
    caption = Caption(f"{q.label} ({q.meaning}) against frequency, {clearance_text(part)}: {panels}.")
    fig, axes = new_figure(len(lines), panel_height=3.5, legend_rows=legend_rows(2 + 2 * len(drawn) + 2))
    markers = SimulationMarkers()
    any_unstable = gaps = False
    for ax, (text, line) in zip(axes, lines):
        if "linear" in present and quantity != "impulse":
            draw_linear(ax, f, q.scale * line[quantity].sel(solution="linear").values, coarse)
            caption.add("linear", "LIN (dotted black): the linear system (no stop).")
        if closed is not None:
            values = q.scale * line[quantity].sel(solution=closed).values
            _, unstable = draw_curve(ax, f, values, colour=SOLUTION_COLOURS[closed], label=solution_ref(closed), gid=closed, unstable=unstable_points(line, closed), coarse=coarse, zorder=OVER_MARKERS_ZORDER)
            any_unstable |= unstable
            gaps |= bool(np.isnan(values).any())
            caption.add("closed", f"{solution_ref(closed)} (blue line): the {SOLUTION_DESCRIPTIONS[closed]}.")
        for engine in drawn:
            values = q.scale * line[quantity].sel(solution=engine).values
            markers.add(engine, draw_points(ax, f, values, periodic=periodic_points(line, engine), solution=engine, colour=SOLUTION_COLOURS[engine], label=solution_ref(engine)))
        finish_axes(ax, _FREQUENCY, axis_label(quantity), text, log=q.log)
    if any_unstable:
        caption.add("unstable", f"{solution_ref(closed)} dashed: the one-impact orbit exists but is unstable (Floquet).")
    if gaps:
        caption.add("gaps", f"Gaps in {solution_ref(closed)}: no admissible one-impact regime while the linear motion would cross the stop.")
    caption.add("engines", markers.phrase())
    figure_legend(fig, axes, stability_keys() if any_unstable else [])
    return DrawnFigure(fig, name, f"Simulations against the closed form: {q.label}, {clearance_text(part)}", caption.text())
