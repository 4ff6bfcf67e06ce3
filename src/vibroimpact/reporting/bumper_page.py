"""Report figures and tables of the compliant-bumper studies (paper section 5 and figures 25-28).

* resonance peaks of |X1| against the restitution ratio or the clearance (figures 25-26);
* peak contact deceleration and force against frequency, simulation against the PGF-based estimate (figure 28);
* convergence of the compliant model to the rigid-stop one as the bumper stiffens, and what it costs.

The peak figures are part of the frequency-response page (:mod:`vibroimpact.reporting.stepped_page`); a study along
the bumper frequency has a page of its own, :class:`BumperStiffnessPage`. The swept-sine page is
:mod:`vibroimpact.reporting.sweep_page`.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.ticker import NullFormatter

from vibroimpact.analysis.regime import Regime
from vibroimpact.reporting.page import DrawnFigure, Section, Table, saved
from vibroimpact.reporting.record import StudySetting
from vibroimpact.reporting.responses import SolutionsPage, clearance_text, linear_section, series_by_restitution
from vibroimpact.reporting.series import OVER_MARKERS_ZORDER, SimulationMarkers, draw_curve, draw_points, periodic_points, stability_keys, unstable_points
from vibroimpact.reporting.style import QUANTITIES, SOLUTION_COLOURS, Caption, axis_label, figure_legend, finish_axes, fmt, legend_rows, new_figure, series_colour, solution_ref
from vibroimpact.scene.schema import ENGINE_SOLUTIONS

__all__ = ["BumperStiffnessPage", "peak_figure", "peak_tables", "peak_acceleration_figure", "stiffness_figure", "stiffness_tables", "band_peaks"]


# ---------------------------------------------------------------------------------------------- peaks
def band_peaks(values: np.ndarray, f: np.ndarray, split: float) -> tuple[tuple[float, float], tuple[float, float]]:
    """Largest finite value below and above ``split`` [Hz] and where it is: ((peak 1, f 1), (peak 2, f 2))."""
    result = []
    for mask in (f < split, f >= split):
        v = np.where(mask & np.isfinite(values), values, -np.inf)
        i = int(np.argmax(v)) if v.size else 0
        result.append((float(v[i]), float(f[i])) if v.size and np.isfinite(v[i]) else (math.nan, math.nan))
    return result[0], result[1]


#: (label, solution, parameter value, band-1 (peak, f), band-2 (peak, f), band-1 periodic, band-2 periodic)
PeakRow = tuple[str, str, float, tuple[float, float], tuple[float, float], bool, bool]


def _peak_rows(dataset: xr.Dataset, setting: StudySetting, parameter: str) -> list[PeakRow]:
    """Peaks of |X1| per solution and ``parameter`` value; pgf also with stable orbits only and on the simulation grid."""
    f = dataset["frequency"].values
    split = setting.split_frequency
    sim_f = setting.simulation_frequency
    rows: list[PeakRow] = []
    for value in dataset[parameter].values:
        point = dataset.sel({parameter: value})
        for solution in (str(s) for s in dataset["solution"].values if s != "linear"):
            values = point["x1_amplitude"].sel(solution=solution).values
            if solution in ENGINE_SOLUTIONS:
                converged = periodic_points(point, solution)
                peaks = band_peaks(values, f, split)
                periodic = [bool(np.any(converged & np.isclose(f, at, rtol=0.0, atol=1e-9))) for _, at in peaks]
                rows.append((solution, solution, float(value), *peaks, *periodic))
                continue
            rows.append((solution, solution, float(value), *band_peaks(values, f, split), True, True))
            if solution == "pgf" and "stable" in point and "regime" in point:
                impact = np.isin(point["regime"].sel(solution=solution).values, (Regime.ONE_IMPACT, Regime.ONE_IMPACT_COEXISTING_LINEAR))
                stable = impact & (point["stable"].sel(solution=solution).values == 1)
                rows.append(("pgf, stable one-impact orbits only", solution, float(value), *band_peaks(np.where(stable, values, np.nan), f, split), True, True))
            if sim_f.size:
                on = np.isin(f, sim_f)
                rows.append((f"{solution} on the simulation grid", solution, float(value), *band_peaks(values[on], f[on], split), True, True))
    return rows


#: Variants of a closed-form peak curve (label suffix): line style, width, and what the caption says of them; wide
#: solid lines under thinner ones, so that equal curves all show.
_PEAK_VARIANTS = {
    "": ("-", 3.0, "wide solid: the closed form on its fine grid, the largest realisable steady state (where the linear motion fits beside an unstable one-impact orbit, the linear one)"),
    ", stable one-impact orbits only": (":", 1.8, "dotted: stable one-impact orbits only, the curve the paper draws"),
    " on the simulation grid": ("-.", 1.4, "dash-dot: the closed form on the simulated frequencies only, a like-for-like comparison with the markers"),
}


def _variant(label: str, solution: str) -> str:
    """The variant of a closed-form peak row: its label after the solution's name (a key of ``_PEAK_VARIANTS``)."""
    return label[len(solution) :]


def peak_figure(dataset: xr.Dataset, setting: StudySetting, parameter: str, name: str) -> DrawnFigure:
    """Peak |X1| of each resonance band against ``parameter`` (``restitution`` or ``clearance``): figures 25-26."""
    rows = _peak_rows(dataset, setting, parameter)
    scale, unit = (1e3, "mm") if parameter == "clearance" else (1.0, "-")
    labels = list(dict.fromkeys(r[0] for r in rows))
    fig, axes = new_figure(2, panel_height=3.9, legend_rows=legend_rows(len(labels) + 2, 3))
    caption = Caption(f"Largest {QUANTITIES['x1_amplitude'].label} in each resonance band against the {parameter} (paper figures 25-26); one colour per solution.")
    engines = SimulationMarkers()
    for band, ax in enumerate(axes):
        for label in labels:
            chosen = [r for r in rows if r[0] == label]
            solution = chosen[0][1]
            x = np.array([r[2] for r in chosen]) * scale
            y = np.array([r[3 + band][0] for r in chosen])
            colour = SOLUTION_COLOURS.get(solution, "C5")
            if solution in ENGINE_SOLUTIONS:
                ax.plot(x, y, color=colour, lw=0.8, label="_nolegend_", gid=solution)
                engines.add(solution, draw_points(ax, x, y, periodic=np.array([r[5 + band] for r in chosen]), solution=solution, colour=colour, label=solution_ref(solution)))
                continue
            variant = _variant(label, solution)
            ls, width, phrase = _PEAK_VARIANTS[variant]
            ax.plot(x, y, ls=ls, lw=width, marker="o", ms=3.0 + width, color=colour, alpha=0.55 if not variant else 1.0, label=f"{solution_ref(solution)}{variant}", gid=solution)
            caption.add(f"variant{variant}", f"Closed forms ({', '.join(solution_ref(s) for s in dict.fromkeys(r[1] for r in rows if r[1] not in ENGINE_SOLUTIONS))}), {phrase}." if not variant else f"{phrase[0].upper()}{phrase[1:]}.")
        finish_axes(ax, f"{parameter} [{unit}]", f"peak {axis_label('x1_amplitude')}", f"Resonance band {band + 1} ({'below' if band == 0 else 'above'} the anti-resonance)")
    figure_legend(fig, axes, columns=3)
    if engines:
        caption.add("engines", engines.phrase("the peak is a periodic steady state", "the peak is an irregular motion's average", each="the largest value on the simulated frequencies"))
        caption.add("coexist", "Where motions coexist, a simulation settles on one of them depending on where it starts (here: near the one-impact orbit).")
    return DrawnFigure(fig, name, f"Resonance peaks of |X1| against the {parameter}", caption.text())


def peak_tables(dataset: xr.Dataset, setting: StudySetting, parameter: str) -> list[Table]:
    """The values of :func:`peak_figure`."""
    unit, scale = ("mm", 1e3) if parameter == "clearance" else ("-", 1.0)
    header = f"<tr><th>solution</th><th>{parameter} [{unit}]</th><th>peak 1 [mm]</th><th>at [Hz]</th><th>peak 2 [mm]</th><th>at [Hz]</th></tr>"
    body = [
        f"<tr><td>{label}</td><td>{fmt(value * scale, 'g')}</td><td>{fmt(p1[0] * 1e3, '#.4g')}</td><td>{fmt(p1[1], '.3f')}</td><td>{fmt(p2[0] * 1e3, '#.4g')}</td><td>{fmt(p2[1], '.3f')}</td></tr>"
        for label, _, value, p1, p2, _, _ in _peak_rows(dataset, setting, parameter)
    ]
    return [Table(f"Resonance peaks of |X1| against the {parameter}: values", f"<table>{header}{''.join(body)}</table>")]


# -------------------------------------------------------------------------------------- peak acceleration
def peak_acceleration_figure(part: xr.Dataset, name: str) -> DrawnFigure | None:
    """Peak contact deceleration and force against frequency at one clearance: the compliant simulation against the
    PGF-based estimate (figure 28). None if neither quantity is in ``part``."""
    quantities = [q for q in ("peak_acceleration", "peak_contact_force") if q in part]
    if not quantities:
        return None
    f = part["frequency"].values
    lines = series_by_restitution(part)
    present = [str(s) for s in part["solution"].values]
    fig, axes = new_figure(len(quantities), panel_height=3.9, legend_rows=legend_rows(len(lines) + 4))
    caption = Caption(
        f"{' and '.join(QUANTITIES[q].label for q in quantities)} per steady state against frequency, {clearance_text(part)}, one colour per restitution ratio."
    )
    any_unstable = False
    engines = SimulationMarkers()
    for ax, quantity in zip(axes, quantities):
        for i, (_, line) in enumerate(lines):
            if "pgf" in present:
                drawn, unstable = draw_curve(ax, f, line[quantity].sel(solution="pgf").values, colour=series_colour(i), label=None, gid="pgf", unstable=unstable_points(line, "pgf"), zorder=OVER_MARKERS_ZORDER)
                any_unstable |= unstable
                if drawn:
                    caption.add("pgf", f"Lines: the estimate from {solution_ref('pgf')}, Gamma(xi_b) Omega_b J / (1 + R) for the force (section 6.3 with the corrected factor Gamma; the deceleration less the absorber spring's pull): the rigid-stop impulse J gives the entry speed, the one-collision solution of the bumper gives the peak.")
            if "compliant" in present:
                engines.add("compliant", draw_points(ax, f, line[quantity].sel(solution="compliant").values, periodic=periodic_points(line, "compliant"), solution="compliant", colour=series_colour(i), label=None))
        finish_axes(ax, "frequency [Hz]", axis_label(quantity), QUANTITIES[quantity].label)
    if any_unstable:
        caption.add("unstable", "Dashed: the estimate on a one-impact orbit that exists but is unstable.")
    if engines:
        caption.add("compliant", engines.phrase(irregular="irregular motion, the largest over the measured window"))
    keys: list[Line2D | Patch] = [Patch(color=series_colour(i), label=text) for i, (text, _) in enumerate(lines)]
    figure_legend(fig, [], keys + (stability_keys() if any_unstable else []) + engines.keys())
    return DrawnFigure(fig, name, f"Peak contact deceleration and force, {clearance_text(part)}", caption.text())


# ------------------------------------------------------------------------------------------- stiffness
class BumperStiffnessPage(SolutionsPage):
    """The page of a stepped study along the bumper frequency (dimensions ``solution``, ``bumper_frequency``,
    ``frequency``): the compliant bumper against the rigid stop."""

    def sections(self, out: Path) -> list[Section]:
        """Linear system, then the convergence of the compliant bumper and its cost."""
        figure = stiffness_figure(self.dataset, self.setting, "bumper_stiffness")
        convergence = Section("Compliant bumper against the rigid stop", figures=saved([figure], out), tables=stiffness_tables(self.dataset, self.setting))
        return [linear_section(self.setting, out), convergence]


def _stiffness_reference(dataset: xr.Dataset) -> str | None:
    """The rigid-stop simulation the compliant one is compared with (exact if present), or None."""
    for name in ("exact", "momentary"):
        if name in dataset["solution"].values:
            return name
    return None


def stiffness_figure(dataset: xr.Dataset, setting: StudySetting, name: str) -> DrawnFigure | None:
    """Difference of the compliant |X1| from the rigid-stop one against Omega_b, and the wall time per point."""
    reference = _stiffness_reference(dataset)
    if reference is None or "compliant" not in dataset["solution"].values:
        return None
    bumper = dataset["bumper_frequency"].values
    f = setting.simulation_frequency if setting.simulation_frequency.size else dataset["frequency"].values
    panels = 2 if "wall_time" in dataset else 1
    fig, axes = new_figure(panels, panel_height=4.0, legend_rows=legend_rows(f.size + 2, 6))
    ax = axes[0]
    for k, frequency in enumerate(f):
        point = dataset.sel(frequency=frequency)
        sim = point["x1_amplitude"].sel(solution="compliant").values
        ref = point["x1_amplitude"].sel(solution=reference).values
        ax.loglog(bumper, np.abs(sim - ref) / ref, "o-", color=series_colour(k), ms=4, label=f"{fmt(frequency, 'g')} Hz", gid="compliant")
    ax.loglog(bumper, 0.1 * bumper[0] / bumper, "k--", lw=0.9, label="slope -1")
    finish_axes(ax, "bumper frequency Omega_b / 2 pi [Hz]", f"relative difference of {QUANTITIES['x1_amplitude'].label} [1]", "Convergence to the rigid stop")
    caption = Caption(
        f"Left: relative difference of the steady-state {QUANTITIES['x1_amplitude'].label} of {solution_ref('compliant')} (restitution-matched "
        f"loss factor) from the rigid-stop simulation {solution_ref(reference)} as the bumper stiffens, one colour per excitation frequency; the dashed line has slope -1."
    )
    if panels == 2:
        ax = axes[1]
        for k, frequency in enumerate(f):
            ax.loglog(bumper, dataset["wall_time"].sel(solution="compliant", frequency=frequency).values, "o-", color=series_colour(k), ms=4, label=f"{fmt(frequency, 'g')} Hz", gid="compliant")
        rigid = float(np.nanmedian(dataset["wall_time"].sel(solution=reference).values))
        ax.axhline(rigid, color="k", ls=":", lw=1.2, label=f"{reference} (median)", gid=reference)
        finish_axes(ax, "bumper frequency Omega_b / 2 pi [Hz]", "wall time per steady state [s]", "Cost of the compliant model")
        caption.add("cost", f"Right: the wall time of each steady state of {solution_ref('compliant')} (transient plus measurement, one process); dotted: the median of {solution_ref(reference)}.")
    for ax in axes:
        # ticks at the bumpers computed: read off directly, and no crowded minor-tick labels on a short log axis
        ax.set_xticks(bumper, [fmt(b, "g") for b in bumper])
        ax.xaxis.set_minor_formatter(NullFormatter())
    figure_legend(fig, axes, columns=6)
    return DrawnFigure(fig, name, "Compliant bumper against the rigid stop", caption.text())


def stiffness_tables(dataset: xr.Dataset, setting: StudySetting) -> list[Table]:
    """Per bumper frequency: median and largest difference from the rigid stop, fitted order, median wall time."""
    reference = _stiffness_reference(dataset)
    if reference is None or "compliant" not in dataset["solution"].values or not setting.simulation_frequency.size:
        return []
    bumper = dataset["bumper_frequency"].values
    data = dataset.sel(frequency=setting.simulation_frequency)
    sim = data["x1_amplitude"].sel(solution="compliant").transpose("bumper_frequency", "frequency").values
    ref = data["x1_amplitude"].sel(solution=reference).values
    difference = np.abs(sim - ref) / ref
    wall = data["wall_time"].sel(solution="compliant").transpose("bumper_frequency", "frequency").values if "wall_time" in data else np.full(sim.shape, np.nan)
    rows = ["<tr><th>Omega_b/2pi [Hz]</th><th>median rel. diff. |X1|</th><th>largest</th><th>observed order (median)</th><th>median wall time [s]</th></tr>"]
    for i, b in enumerate(bumper):
        order = math.nan
        if i > 0:
            with np.errstate(invalid="ignore", divide="ignore"):
                orders = np.log(difference[i - 1] / difference[i]) / np.log(b / bumper[i - 1])
            if np.isfinite(orders).any():
                order = float(np.nanmedian(orders))
        rows.append(f"<tr><td>{fmt(b, 'g')}</td><td>{fmt(np.nanmedian(difference[i]), '.2e')}</td><td>{fmt(np.nanmax(difference[i]), '.2e')}</td><td>{fmt(order, '.2f')}</td><td>{fmt(np.nanmedian(wall[i]), '.3f')}</td></tr>")
    return [Table(f"compliant against {reference}: convergence and cost", "<table>" + "".join(rows) + "</table>")]
