"""Figures of the stepped frequency-response pages (paper figures 5-8 and 21-24): responses of every solution, regime
maps, stability, and simulations against the closed form. What the stepped and swept pages share (the page's base
:class:`~vibroimpact.grids.sections.SolutionsPage`, the linear-system section, the regime map) is in
:mod:`vibroimpact.grids`.

Each builder returns a :class:`~vibroimpact.reporting.page.DrawnFigure` whose caption is put together from what was
drawn. Closed forms are drawn as curves on the dataset's grid, simulations as markers on their own grid
(:mod:`vibroimpact.reporting.series`).
"""

from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from vibroimpact.analysis.stability import Regime
from vibroimpact.grids.regime_map import regime_map
from vibroimpact.kinds.stepped.crosscheck import subset_solutions
from vibroimpact.reporting.coincide import coincidence_phrase, reveal_coincident
from vibroimpact.reporting.page import DrawnFigure
from vibroimpact.reporting.series import OVER_MARKERS_ZORDER, SimulationMarkers, closed_forms_whose, draw_curve, marker_scales, draw_linear, draw_points, periodic_points, stability_keys, subset_points, unstable_points
from vibroimpact.reporting.style import (
    LINEAR_STYLE,
    QUANTITIES,
    RAW_STYLE,
    SOLUTION_COLOURS,
    SOLUTION_DESCRIPTIONS,
    SOLUTION_TITLES,
    ZERO_MEANINGS,
    Caption,
    axis_label,
    figure_legend,
    finish_axes,
    fmt,
    legend_rows,
    new_figure,
    ordered_colours,
    ordered_widths,
    solution_ref,
)
from vibroimpact.scene.schema import ENGINE_SOLUTIONS

__all__ = ["response_figure", "regime_figure", "stability_figure", "simulation_figure", "series_by_restitution", "clearance_text", "subset_counts", "subset_title"]

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


def subset_counts(part: xr.Dataset) -> dict[str, int]:
    """The solutions of ``part`` run on a subset of the simulation grid -> how many points each computed."""
    return {solution: subset_points(part, solution) for solution in subset_solutions(part)}


def subset_title(title: str, solution: str, counts: dict[str, int]) -> str:
    """A panel's title, with "subset: n points" where ``solution`` ran on a subset (it looks like a full panel)."""
    n = counts.get(solution)
    return title if n is None else f"{title} (subset: {n} point{'s' if n != 1 else ''})"


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
    fig, axes = new_figure(len(panels), panel_height=3.7, sharey=True, legend_rows=legend_rows(len(lines) + 7, 3))
    counts = subset_counts(part)
    engines = SimulationMarkers(counts)
    colours, widths, scales = ordered_colours(len(lines)), ordered_widths(len(lines)), marker_scales(len(lines))
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
                engines.add(solution, draw_points(ax, f, values, periodic=periodic_points(line, solution), solution=solution, colour=colours[i], label=None, scale=scales[i]))
                continue
            before = len(ax.lines)
            _, unstable = draw_curve(ax, f, values, colour=colours[i], label=None, gid=solution, unstable=unstable_points(line, solution), coarse=coarse, width=widths[i])
            curves[-1].append((text, list(ax.lines[before:])))
            any_unstable |= unstable
            gaps |= bool(np.isnan(values).any())
            if raw_name in line and solution != "linear":
                raw_values = q.scale * line[raw_name].sel(solution=solution).values
                if np.isfinite(raw_values).any():
                    ax.plot(f, raw_values, color=colours[i], label="_nolegend_", gid=f"raw:{solution}", **RAW_STYLE)
                    raw = True
        finish_axes(ax, _FREQUENCY, axis_label(quantity), subset_title(f"{solution_ref(solution)}: {SOLUTION_TITLES.get(solution, solution)}", solution, counts), log=q.log)
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
    coincide = coincidence_phrase(found for ax, drawn in zip(axes, curves) for found in reveal_coincident(ax, drawn, zero=ZERO_MEANINGS.get(quantity, "")))
    keys = [Patch(color=colours[i], label=text) for i, (text, _) in enumerate(lines)]
    if with_linear:
        keys.append(Line2D([], [], label="LIN (linear system)", **LINEAR_STYLE))
    keys += stability_keys(closed_forms_whose(s for s in panels if s not in ENGINE_SOLUTIONS and s != "linear")) if any_unstable else []
    keys += [Line2D([], [], color="k", label="raw one-impact solution", **RAW_STYLE)] if raw else []
    figure_legend(fig, [], keys + engines.keys(), columns=3)
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
    panels, shown, idle = [], [], []
    for s in part["solution"].values:
        flags = np.array([line["regime"].sel(solution=s).values for _, line in lines], dtype=int)
        if np.all(flags == int(Regime.NOT_COMPUTED)):  # a solution run on a subset elsewhere: an empty panel says nothing
            idle.append(solution_ref(str(s)))
            continue
        unstable = np.array([line["stable"].sel(solution=s).values == 0 for _, line in lines]) if "stable" in part else None
        panels.append((f"{solution_ref(str(s))}: regime, {clearance_text(part)}", [text for text, _ in lines], flags, unstable))
        shown.append(solution_ref(str(s)))
    drawn = regime_map(panels, part["frequency"].values, name, f"Regime map, {clearance_text(part)}", f"Regime of each point of {', '.join(shown)}")
    if not idle:
        return drawn
    return DrawnFigure(drawn.figure, drawn.name, drawn.title, f"{drawn.caption} No panel for {', '.join(idle)}: {'it' if len(idle) == 1 else 'they'} computed no point at {clearance_text(part)}.")


def stability_figure(part: xr.Dataset, name: str) -> DrawnFigure:
    """Largest Floquet multiplier modulus of the pgf one-impact orbit against frequency."""
    lines = series_by_restitution(part)
    f = part["frequency"].values
    fig, axes = new_figure(1, panel_height=3.8, legend_rows=legend_rows(len(lines) + 1, 6))
    ax = axes[0]
    curves: list[tuple[str, list[Line2D]]] = []
    colours, widths = ordered_colours(len(lines)), ordered_widths(len(lines))
    for i, (text, line) in enumerate(lines):
        before = len(ax.lines)
        draw_curve(ax, f, line["floquet_modulus"].sel(solution="pgf").values, colour=colours[i], label=text, gid="pgf", coarse=f.size < COARSE_GRID_POINTS, width=widths[i])
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
    fig, axes = new_figure(len(lines), panel_height=3.5, sharey=True, legend_rows=legend_rows(2 + 2 * len(drawn) + 2, 3))  # the R panels compare: one y range
    markers = SimulationMarkers(subset_counts(part))
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
            markers.add(engine, draw_points(ax, f, values, periodic=periodic_points(line, engine), solution=engine, colour=SOLUTION_COLOURS[engine], label=markers.name(engine)))
        finish_axes(ax, _FREQUENCY, axis_label(quantity), text, log=q.log)
    if any_unstable:
        caption.add("unstable", f"{solution_ref(closed)} dashed: the one-impact orbit exists but is unstable (Floquet).")
    if gaps:
        caption.add("gaps", f"Gaps in {solution_ref(closed)}: no admissible one-impact regime while the linear motion would cross the stop.")
    caption.add("engines", markers.phrase())
    figure_legend(fig, axes, stability_keys(closed_forms_whose([closed] if closed else [])) if any_unstable else [], columns=3)
    return DrawnFigure(fig, name, f"Simulations against the closed form: {q.label}, {clearance_text(part)}", caption.text())
