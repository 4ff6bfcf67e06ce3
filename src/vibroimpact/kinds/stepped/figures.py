"""Figures and tables of a general stepped study's page: one curve per coordinate and per stop, captions that say which
(its linear system, shared with the swept page: :mod:`vibroimpact.grids.sections`).

Closed forms are curves (the linear system dotted black, ``pgf`` solid where its orbit is stable and dashed where it
is not), simulations markers on their own grid (filled: periodic; hollow: not), as on the paper's pages.
"""

from __future__ import annotations

import html

import numpy as np
import xarray as xr
from matplotlib.lines import Line2D

from vibroimpact.grids.sections import stop_constraint
from vibroimpact.kinds.stepped.crosscheck import subset_solutions
from vibroimpact.reporting.coincide import Coincidence, coincidence_phrase, reveal_coincident
from vibroimpact.reporting.record import GeneralSetting, bumper_text
from vibroimpact.reporting.page import DrawnFigure, Table
from vibroimpact.reporting.series import SimulationMarkers, draw_curve, draw_linear, draw_points, periodic_points, stability_keys, unstable_points
from vibroimpact.reporting.style import DISPLACEMENT_SCALE, DISPLACEMENT_UNITS, GENERAL_SOLUTION_DESCRIPTIONS, SOLUTION_COLOURS, Caption, figure_legend, finish_axes, fmt, legend_rows, new_figure, solution_ref
from vibroimpact.scene.schema import ENGINE_SOLUTIONS

__all__ = ["response_panels_figure", "peaks_table", "where_text"]

_FREQUENCY = "frequency [Hz]"
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
        bits.append(bumper_text(part.attrs, float(part["bumper_frequency"])))  # in the scene's units
    return ", ".join(bits) if bits else "each stop's own values"


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
            panels.append(("impulse", "impulse per period [N s]", f"impulse on stop {k}: {stop_constraint(words)}", k if several else None, False, 1.0))
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
