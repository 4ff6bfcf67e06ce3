"""Figures and tables of a general study's page: one curve per coordinate and per stop, captions that say which.

Closed forms are curves (the linear system dotted black, ``pgf`` solid where its orbit is stable and dashed where it
is not), simulations markers on their own grid (filled: periodic; hollow: not), as on the paper's pages.
"""

from __future__ import annotations

import html

import numpy as np
import xarray as xr
from matplotlib.lines import Line2D

from vibroimpact.analysis.linear import base_force
from vibroimpact.kinds.stepped.crosscheck import subset_solutions
from vibroimpact.model.modal import fit_modal_parameters, underdamped_mode_count
from vibroimpact.reporting.coincide import Coincidence, coincidence_phrase, reveal_coincident
from vibroimpact.reporting.record import GeneralSetting
from vibroimpact.reporting.page import DrawnFigure, Table
from vibroimpact.reporting.series import SimulationMarkers, draw_curve, draw_linear, draw_points, periodic_points, stability_keys, unstable_points
from vibroimpact.reporting.style import DISPLACEMENT_SCALE, DISPLACEMENT_UNITS, GENERAL_SOLUTION_DESCRIPTIONS, SOLUTION_COLOURS, Caption, figure_legend, finish_axes, fmt, legend_rows, new_figure, series_colour, solution_ref
from vibroimpact.scene.schema import ENGINE_SOLUTIONS

__all__ = ["structure_figure", "layout_tables", "response_panels_figure", "peaks_table", "where_text"]

_FREQUENCY = "frequency [Hz]"
#: Points of the linear figure's own grid.
_LINEAR_POINTS = 4001
#: Fewer grid points than this: closed-form curves also get a marker per value.
_COARSE = 30


def where_text(part: xr.Dataset) -> str:
    """Where a part of the dataset is: its clearance and restitution if they are single values of the grid."""
    bits = []
    if "clearance" in part.coords and part["clearance"].ndim == 0:
        bits.append(f"Delta = {fmt(float(part['clearance']) * 1e3, '.6g')} mm")
    if "restitution" in part.coords and part["restitution"].ndim == 0:
        bits.append(f"R = {fmt(float(part['restitution']), 'g')}")
    if "bumper_frequency" in part.coords and part["bumper_frequency"].ndim == 0 and np.isfinite(float(part["bumper_frequency"])):
        bits.append(f"bumper {fmt(float(part['bumper_frequency']), 'g')} Hz")
    return ", ".join(bits) if bits else "each stop's own values"


def structure_figure(setting: GeneralSetting, frequency: np.ndarray) -> DrawnFigure:
    """The linear system: |X| of every coordinate, |n_k . X| of every stop's coordinate (dashed) against the gap the
    static deflection leaves it, Delta_k - n_k . x_static (dotted, the stop's colour), the force on the base, and,
    where the structure has the named view, |H22| exact against the paper's curve fit (paper figures 2-4)."""
    f = np.union1d(frequency, np.linspace(frequency.min(), frequency.max(), _LINEAR_POINTS))
    w = 2.0 * np.pi * f
    x = setting.linear(w)
    named = setting.named
    fit = fit_modal_parameters(named) if named is not None and underdamped_mode_count(named) == 2 else None
    fig, axes = new_figure(3 if named is None else 4, panel_height=3.6, legend_rows=legend_rows(setting.structure.size + 2 * len(setting.stops) + 2))
    coordinates = [(f"|{name}|", axes[0].semilogy(f, DISPLACEMENT_SCALE * np.abs(x[:, i]), color=series_colour(i), lw=1.4, label=f"|{name}|", gid=f"linear:{name}")) for i, name in enumerate(setting.names)]
    finish_axes(axes[0], _FREQUENCY, f"amplitude [{DISPLACEMENT_UNITS}]", "Every coordinate, linear system (no stop)")
    static = setting.static_deflection()
    gaps = setting.clearances - (setting.normals @ static if static is not None else 0.0)
    stops: list[tuple[str, list[Line2D]]] = []
    lines: list[tuple[str, list[Line2D]]] = []
    for k, (normal, words) in enumerate(zip(setting.normals, setting.stops)):
        stops.append((f"stop {k}", axes[1].semilogy(f, DISPLACEMENT_SCALE * np.abs(x @ normal), color=series_colour(k), lw=1.4, ls="--", label=f"stop {k}: {_target(words)}", gid=f"linear:stop{k}")))
        if np.isfinite(gaps[k]) and gaps[k] > 0.0:  # drawn on the frequencies, as the curves it is compared with
            lines.append((f"the gap of stop {k}", axes[1].plot(f, np.full(f.shape, DISPLACEMENT_SCALE * gaps[k]), color=series_colour(k), lw=1.1, ls=":", label=f"stop {k}: gap {fmt(gaps[k] * 1e3, '.4g')} mm", gid=f"gap:stop{k}")))
    finish_axes(axes[1], _FREQUENCY, f"amplitude [{DISPLACEMENT_UNITS}]", "Each stop's coordinate, linear system")
    coincide = coincidence_phrase([*reveal_coincident(axes[0], coordinates), *reveal_coincident(axes[1], stops), *reveal_coincident(axes[1], lines)])
    axes[2].semilogy(f, np.abs(base_force(setting.structure, w, x)), color="C2", lw=1.4, label="|F| on the base", gid="linear:force")
    finish_axes(axes[2], _FREQUENCY, "|F| on the base [N]", "Linear force on the base (paper fig. 3)")
    if named is not None:
        axes[3].semilogy(f, np.abs(named.receptances(w).h22), label="|H22| exact (eq. 4)", color="k", lw=1.4)
        if fit is not None:
            step = max(1, f.size // 120)
            axes[3].semilogy(f[::step], np.abs(fit.receptance(w[::step])), "o", color="C3", mfc="none", ms=4.5, label="|H22| of eq. 10, the paper's fitted modes")
        finish_axes(axes[3], _FREQUENCY, "|H22| [m/N]", "Accuracy of the curve fit (paper fig. 4)")
    figure_legend(fig, axes)
    natural = ", ".join(fmt(v / (2 * np.pi), ".3f") for v in (named.natural_angular_frequencies() if named is not None else setting.structure.natural_angular_frequencies()))
    caption = (
        f"Linear steady state without stops under the {setting.load_text()}: the amplitude of every coordinate "
        f"({', '.join(setting.names)}); the amplitude of each stop's coordinate n . x (dashed) and, dotted in the "
        f"same colour, {_gap_words(setting, static, gaps)} The force on the base, 1^T (K + j w C) X."
    )
    if named is not None:
        fitted = "against the paper's curve fit (circles)" if fit is not None else "(the paper's fit needs two underdamped modes)"
        caption += f" |H22| exact {fitted}. Natural frequencies {natural} Hz, anti-resonance {fmt(named.antiresonance_angular_frequency() / (2 * np.pi), '.3f')} Hz."
    else:
        caption += f" Natural frequencies {natural} Hz."
    caption += f" Stops: {'; '.join(setting.stops)}." + (f" {coincide}" if coincide else "")
    return DrawnFigure(fig, "structure", "Linear responses, force on the base" + (", fit of H22" if named is not None else ""), caption)


def _gap_words(setting: GeneralSetting, static: np.ndarray | None, gaps: np.ndarray) -> str:
    """What the dotted lines of the structure figure are, and which stops have none."""
    if static is None:
        words = (
            "its clearance Delta: where the dashed curve is above, the linear motion would cross that stop if the "
            "structure stood at rest on its mean; the constant force shifts the mean (K is singular: no static "
            "deflection is drawn)."
        )
    elif np.any(setting.static):
        words = (
            "the gap the static deflection leaves it, Delta - n . x_static (x_static = K^-1 F0): where the dashed "
            "curve is above, the linear motion would cross that stop."
        )
    else:
        words = "its clearance Delta: where the dashed curve is above, the linear motion would cross that stop."
    swept = [str(k) for k in range(gaps.size) if not np.isfinite(gaps[k])]
    closed = [str(k) for k in range(gaps.size) if np.isfinite(gaps[k]) and gaps[k] <= 0.0]
    if swept:
        words += f" No line for stop {', '.join(swept)}: its clearance is swept (one value per section below)."
    if closed:
        words += f" No line for stop {', '.join(closed)}: the static deflection already closes it (gap <= 0)."
    return words


def _target(words: str) -> str:
    """The constraint part of a stop's description (``x2 - x1 <= 3 mm``)."""
    return words.split(",")[0]


def layout_tables(setting: GeneralSetting) -> list[Table]:
    """The structure's matrices and natural frequencies, and the stops in words."""
    names = setting.names

    def matrix(title: str, values: np.ndarray, units: str) -> str:
        head = "".join(f"<th>{html.escape(n)}</th>" for n in names)
        rows = "".join(f"<tr><th>{html.escape(n)}</th>" + "".join(f"<td>{fmt(v, '.6g')}</td>" for v in row) + "</tr>" for n, row in zip(names, values))
        return f"<p><b>{title}</b> [{units}]</p><table><tr><th></th>{head}</tr>{rows}</table>"

    s = setting.structure
    natural = ", ".join(fmt(v / (2 * np.pi), ".4f") for v in s.natural_angular_frequencies())
    matrices = matrix("mass M", s.mass_matrix, "kg") + matrix("stiffness K", s.stiffness_matrix, "N/m") + matrix("damping C", s.damping_matrix, "N s/m")
    matrices += f"<p>Natural frequencies (undamped): {natural} Hz; rigid-body modes: {s.rigid_body_modes()}.</p>"
    stops = "".join(f"<tr><td>{k}</td><td>{html.escape(words)}</td></tr>" for k, words in enumerate(setting.stops))
    stop_table = f"<table><tr><th>stop</th><th>constraint (gap Delta - n . x >= 0)</th></tr>{stops}</table><p>Load: {html.escape(setting.load_text())}.</p>"
    return [Table("Structure", matrices), Table("Stops and load", stop_table)]


def response_panels_figure(part: xr.Dataset, setting: GeneralSetting, name: str) -> DrawnFigure | None:
    """At one restitution and clearance: one panel per coordinate's amplitude, the force on the base, and the impulse
    on each stop; every solution in each panel. None if nothing is finite."""
    f = part["frequency"].values
    solutions = [str(s) for s in part["solution"].values]
    coarse = f.size < _COARSE
    # (quantity, axis label, title, stop, log scale, factor to the page's units)
    panels: list[tuple[str, str, str, int | None, bool, float]] = [
        (f"{c}_amplitude", f"|{c}| fundamental [{DISPLACEMENT_UNITS}]", f"coordinate {c}", None, True, DISPLACEMENT_SCALE) for c in setting.names if f"{c}_amplitude" in part
    ]
    if "force_amplitude" in part:
        panels.append(("force_amplitude", "|F| on the base [N]", "force on the base", None, True, 1.0))
    several = "stop" in part.dims
    if "impulse" in part:
        for k, words in enumerate(setting.stops if several else setting.stops[:1]):
            panels.append(("impulse", "impulse per period [N s]", f"impulse on stop {k}: {_target(words)}", k if several else None, False, 1.0))
    panels = [p for p in panels if np.isfinite(_values(part, p[0], p[3])).any()]
    if not panels:
        return None
    fig, axes = new_figure(len(panels), panel_height=3.4, legend_rows=legend_rows(len(solutions) + 4))
    markers = SimulationMarkers()
    any_unstable = False
    found: list[Coincidence] = []
    for ax, (quantity, label, title, stop, log, scale) in zip(axes, panels):
        curves: list[tuple[str, list[Line2D]]] = []
        for solution in solutions:
            values = scale * _values(part.sel(solution=solution), quantity, stop)
            if solution == "linear":
                if quantity != "impulse":
                    draw_linear(ax, f, values, coarse)
            elif solution in ENGINE_SOLUTIONS:
                markers.add(solution, draw_points(ax, f, values, periodic=periodic_points(part, solution), solution=solution, colour=SOLUTION_COLOURS.get(solution, "C5"), label=None))
            else:
                before = len(ax.lines)
                _, unstable = draw_curve(ax, f, values, colour=SOLUTION_COLOURS.get(solution, "C0"), label=solution_ref(solution), gid=solution, unstable=unstable_points(part, solution), coarse=coarse)
                curves.append((solution_ref(solution), list(ax.lines[before:])))
                any_unstable |= unstable
        finish_axes(ax, _FREQUENCY, label, title, log=log and bool(np.any(_values(part, quantity, stop) > 0.0)))
        found += reveal_coincident(ax, curves)
    keys = (stability_keys() if any_unstable else []) + markers.keys()
    figure_legend(fig, axes, keys)
    caption = Caption(
        f"Steady state against frequency, {where_text(part)}: one panel per coordinate ({', '.join(setting.names)}), the force "
        f"on the base, and the impulse per period on each stop ({'; '.join(setting.stops)}). Solutions: "
        + "; ".join(f"{solution_ref(s)}, {GENERAL_SOLUTION_DESCRIPTIONS.get(s, s)}" for s in solutions if s != "linear") + "."
    )
    if "linear" in solutions:
        caption.add("linear", "LIN (dotted black): the linear system without stops.")
    if any_unstable:
        caption.add("unstable", "Closed form dashed: its orbit exists but is unstable (Floquet): the real motion there is another one.")
    caption.add("engines", markers.phrase())
    caption.add("coincide", coincidence_phrase(found))
    return DrawnFigure(fig, name, f"Responses, {where_text(part)}", caption.text())


def _values(part: xr.Dataset, quantity: str, stop: int | None) -> np.ndarray:
    data = part[quantity]
    if stop is not None:
        data = data.sel(stop=stop)
    return np.asarray(data.values, dtype=float)


def peaks_table(dataset: xr.Dataset, setting: GeneralSetting) -> Table:
    """Largest value over frequency of each coordinate's amplitude, the force on the base and each stop's impulse,
    per solution (and swept parameter), with the frequency where it occurs."""
    columns = [(f"{c}_amplitude", f"|{c}| [mm]", 1e3, None) for c in setting.names if f"{c}_amplitude" in dataset]
    if "force_amplitude" in dataset:
        columns.append(("force_amplitude", "|F| on the base [N]", 1.0, None))
    if "impulse" in dataset:
        if "stop" in dataset.dims:
            columns += [("impulse", f"impulse on stop {k} [N s]", 1.0, k) for k in range(dataset.sizes["stop"])]
        else:
            columns.append(("impulse", "impulse [N s]", 1.0, None))
    others = [d for d in ("restitution", "clearance", "bumper_frequency") if d in dataset.dims]
    head = "".join(f"<th>{d}</th>" for d in others) + "<th>solution</th>" + "".join(f"<th>{html.escape(label)} (at Hz)</th>" for _, label, _, _ in columns)
    rows = []
    f = dataset["frequency"].values
    on_subset = subset_solutions(dataset)  # on a few points: their own section compares them
    for index in np.ndindex(*(dataset.sizes[d] for d in others)):
        part = dataset.isel(dict(zip(others, index)))
        for solution in (s for s in dataset["solution"].values if s not in on_subset):
            cells = []
            for quantity, _, scale, stop in columns:
                values = _values(part.sel(solution=solution), quantity, stop)
                if np.isfinite(values).any() and not (solution == "linear" and quantity == "impulse"):  # no stop, no impulse
                    k = int(np.nanargmax(values))
                    cells.append(f"<td>{fmt(values[k] * scale, '.4g')} ({fmt(f[k], '.4g')})</td>")
                else:
                    cells.append("<td></td>")
            labels = "".join(f"<td>{fmt(float(part[d]), 'g')}</td>" for d in others)
            rows.append(f"<tr>{labels}<td>{html.escape(str(solution))}</td>{''.join(cells)}</tr>")
    note = "<p>Largest value over the frequencies each solution computed (simulations: their own grid), and where it occurs. A closed form counts only where its orbit is admissible and stable or the motion linear." + (f" Not listed: {', '.join(on_subset)}, run on a subset of the points (see 'The same contact by two engines')." if on_subset else "") + "</p>"
    return Table("Largest value of every response, per solution", f"{note}<table><tr>{head}</tr>{''.join(rows)}</table>")
