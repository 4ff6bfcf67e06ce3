"""The page of a stepped study (paper figures 2-8, 21-26 and any layout's responses), chosen by what its dataset holds,
never by how its scene was written.

First the answer in numbers (:mod:`~vibroimpact.kinds.stepped.answers`: the resonance peaks against a swept R or
Delta, the largest contact deceleration on a bumper, the largest responses of every solution against the linear
system's, the reduction factors), then the linear system (every coordinate, each stop's coordinate against its gap,
the force on the base; the structure, stops and load in tables), then the detail per clearance, then the tables. Where the structure has the named view (the paper's two-mass
chain: ``system_m1`` ... ``system_b2``) the paper's extras join: the fit of H22 and the modal table, resonance peaks
against a swept parameter, the agreement by band and the reduction factors, both bands split at the anti-resonance.
With one stop on the named view the responses are the paper's figures (one figure per quantity, one panel per
solution, one colour per restitution ratio); with several stops, or another structure, one figure per restitution
ratio with a panel per coordinate, the force on the base and the impulse on each stop.
"""

from __future__ import annotations

import html
from pathlib import Path
from typing import Collection, Iterator

import numpy as np
import xarray as xr
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.ticker import NullFormatter

from vibroimpact.analysis.stability import Regime
from vibroimpact.engines.registry import BUMPER, RIGID
from vibroimpact.kinds.stepped.answers import answer_text, band_peaks, contact_text, convergence_rows, convergence_text, peak_rows, peaks_text, reduction_text
from vibroimpact.kinds.stepped.crosscheck import cross_check_section, cross_check_text, cross_checks
from vibroimpact.kinds.stepped.figures import peaks_table, response_panels_figure, where_text
from vibroimpact.kinds.stepped.operating import operating_point, operating_text, warning_lines, warnings_html
from vibroimpact.kinds.stepped.responses import clearance_text, series_by_restitution, regime_figure, response_figure, simulation_figure, stability_figure, subset_counts
from vibroimpact.kinds.stepped.tables import agreement_table, reduction_intro, reduction_tables
from vibroimpact.grids.sections import SolutionsPage, layout_tables, linear_section, modal_table, paper_study, structure_figure
from vibroimpact.orbits.motion import MotionThresholds
from vibroimpact.reporting.coincide import Coincidence, Shared, coincidence_phrase, reveal_coincident
from vibroimpact.reporting.page import DrawnFigure, Section, Table, saved, StudyPage
from vibroimpact.reporting.record import StudySetting, GeneralSetting, general_setting, named_layout, study_setting
from vibroimpact.reporting.series import OVER_MARKERS_ZORDER, SimulationMarkers, closed_forms_whose, draw_curve, draw_points, marker_scales, periodic_points, stability_keys, unstable_points
from vibroimpact.reporting.style import DISPLACEMENT_SCALE, QUANTITIES, SOLUTION_COLOURS, SOLUTION_DESCRIPTIONS, Caption, axis_label, figure_legend, finish_axes, fmt, legend_rows, new_figure, ordered_colours, ordered_widths, solution_ref, ENGINE_MARKERS, REGIME_COLOURS, ZERO_MEANINGS
from vibroimpact.scene.schema import ENGINE_SOLUTIONS, contact_solutions

__all__ = ["page_for", "BumperStiffnessPage", "peak_figure", "peak_tables", "peak_acceleration_figure", "stiffness_figure", "stiffness_tables", "band_peaks", "lyapunov_figure", "FrequencyResponsePage", "RESPONSE_QUANTITIES", "SIMULATION_QUANTITIES", "unswept_restitution", "answer_text"]


# --------------------------------------------------------------------------------------------------------------------
# Report figures and tables of the compliant-bumper studies (paper section 5 and figures 25-28).
# --------------------------------------------------------------------------------------------------------------------

# ---------------------------------------------------------------------------------------------- peaks
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
    """Peak |X1| of each resonance band against ``parameter`` (``restitution`` or ``clearance``): figures 25-26 (the
    caption cites them for the paper's own study only, :func:`~vibroimpact.grids.sections.paper_study`)."""
    rows = peak_rows(dataset, setting, parameter)
    scale, unit = (1e3, "mm") if parameter == "clearance" else (1.0, "-")
    labels = list(dict.fromkeys(r[0] for r in rows))
    fig, axes = new_figure(2, panel_height=3.9, legend_rows=legend_rows(len(labels) + 2, 3))
    caption = Caption(f"Largest {QUANTITIES['x1_amplitude'].label} in each resonance band against the {parameter}{' (paper figures 25-26)' if paper_study(dataset) else ''}; one colour per solution.")
    engines = SimulationMarkers()
    for band, ax in enumerate(axes):
        for label in labels:
            chosen = [r for r in rows if r[0] == label]
            solution = chosen[0][1]
            x = np.array([r[2] for r in chosen]) * scale
            y = DISPLACEMENT_SCALE * np.array([r[3 + band][0] for r in chosen])
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
        for label, _, value, p1, p2, _, _ in peak_rows(dataset, setting, parameter)
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
    fig, axes = new_figure(len(quantities), panel_height=3.9, legend_rows=legend_rows(len(lines) + 5, 3))
    caption = Caption(
        f"{' and '.join(QUANTITIES[q].label for q in quantities)} per steady state against frequency, {clearance_text(part)}, one colour per restitution ratio."
    )
    any_unstable = False
    engines = SimulationMarkers(subset_counts(part))
    colours, widths, scales = ordered_colours(len(lines)), ordered_widths(len(lines)), marker_scales(len(lines))
    found: list[Coincidence | Shared] = []
    for ax, quantity in zip(axes, quantities):
        curves: list[tuple[str, list[Line2D]]] = []
        for i, (text, line) in enumerate(lines):
            if "pgf" in present:
                before = len(ax.lines)
                drawn, unstable = draw_curve(ax, f, QUANTITIES[quantity].scale * line[quantity].sel(solution="pgf").values, colour=colours[i], label=None, gid="pgf", unstable=unstable_points(line, "pgf"), zorder=OVER_MARKERS_ZORDER, width=widths[i])
                curves.append((text, list(ax.lines[before:])))
                any_unstable |= unstable
                if drawn:
                    caption.add("pgf", f"Lines: the estimate from {solution_ref('pgf')}, Gamma(xi_b) Omega_b J / (1 + R) for the force (section 6.3 with the corrected factor Gamma; the deceleration less the absorber spring's pull): the rigid-stop impulse J gives the entry speed, the one-collision solution of the bumper gives the peak.")
            for bumper in contact_solutions(present, BUMPER):
                engines.add(bumper, draw_points(ax, f, QUANTITIES[quantity].scale * line[quantity].sel(solution=bumper).values, periodic=periodic_points(line, bumper), solution=bumper, colour=colours[i], label=None, scale=scales[i]))
        finish_axes(ax, "frequency [Hz]", axis_label(quantity), QUANTITIES[quantity].label)
        found += reveal_coincident(ax, curves, zero=ZERO_MEANINGS.get(quantity, ""))
    if any_unstable:
        caption.add("unstable", "Dashed: the estimate on a one-impact orbit that exists but is unstable.")
    if engines:
        caption.add("bumper", engines.phrase(irregular="irregular motion, the largest over the measured window", each="one marker per simulated point"))
    caption.add("coincide", coincidence_phrase(found))
    keys: list[Line2D | Patch] = [Patch(color=colours[i], label=text) for i, (text, _) in enumerate(lines)]
    figure_legend(fig, [], keys + (stability_keys(f"under the estimate from {solution_ref('pgf')}") if any_unstable else []) + engines.keys(), columns=3)
    return DrawnFigure(fig, name, f"Peak contact deceleration and force, {clearance_text(part)}", caption.text())


# ------------------------------------------------------------------------------------------- stiffness
class BumperStiffnessPage(SolutionsPage):
    """The page of a stepped study along the bumper frequency (dimensions ``solution``, ``bumper_frequency``,
    ``frequency``): the compliant bumper against the rigid stop."""

    def sections(self, out: Path) -> list[Section]:
        """The convergence of the compliant bumper and its cost (the answer), then the linear system."""
        figure = stiffness_figure(self.dataset, self.setting, "bumper_stiffness")
        reference = _stiffness_reference(self.dataset)
        bumpers = contact_solutions([str(s) for s in self.dataset["solution"].values], BUMPER)
        answer = convergence_text(self.dataset, self.setting, reference, bumpers[0]) if reference is not None and bumpers and self.setting.simulation_frequency.size else ""
        checks = cross_checks(self.dataset)
        operating = operating_text(operating_point(self.dataset))
        intro = warnings_html(warning_lines(self.dataset)) + "".join(f"<p>{html.escape(text)}</p>" for text in [answer] + [cross_check_text(c) for c in checks] + [operating] if text)
        convergence = Section("Compliant bumper against the rigid stop", intro=intro, figures=saved([figure], out), tables=stiffness_tables(self.dataset, self.setting))
        check = cross_check_section(checks)
        return [convergence, *([check] if check is not None else []), linear_section(self.setting, out, paper_study(self.dataset))]


def _stiffness_reference(dataset: xr.Dataset) -> str | None:
    """The rigid-stop simulation the bumper is compared with (one with an exact flow first), or None."""
    rigid = contact_solutions([str(s) for s in dataset["solution"].values], RIGID)
    return rigid[0] if rigid else None


def stiffness_figure(dataset: xr.Dataset, setting: StudySetting, name: str) -> DrawnFigure | None:
    """Difference of the compliant |X1| from the rigid-stop one against Omega_b, and the wall time per point."""
    reference = _stiffness_reference(dataset)
    bumpers = contact_solutions([str(s) for s in dataset["solution"].values], BUMPER)
    if reference is None or not bumpers:
        return None
    compliant = bumpers[0]  # the one computed everywhere: the exact flow where the scene has it
    bumper = dataset["bumper_frequency"].values
    f = setting.simulation_frequency if setting.simulation_frequency.size else dataset["frequency"].values
    panels = 2 if "wall_time" in dataset else 1
    fig, axes = new_figure(panels, panel_height=4.0, legend_rows=legend_rows(f.size + 2, 6))
    ax = axes[0]
    colours, widths = ordered_colours(f.size), ordered_widths(f.size)
    curves: list[tuple[str, list[Line2D]]] = []
    for k, frequency in enumerate(f):
        point = dataset.sel(frequency=frequency)
        sim = point["x1_amplitude"].sel(solution=compliant).values
        ref = point["x1_amplitude"].sel(solution=reference).values
        curves.append((f"{fmt(frequency, 'g')} Hz", ax.loglog(bumper, np.abs(sim - ref) / ref, "o-", color=colours[k], lw=widths[k], ms=2.0 + 1.5 * widths[k], label=f"{fmt(frequency, 'g')} Hz", gid=compliant)))
    ax.loglog(bumper, 0.1 * bumper[0] / bumper, "k--", lw=0.9, label="slope -1")
    finish_axes(ax, "bumper frequency Omega_b / 2 pi [Hz]", f"relative difference of {QUANTITIES['x1_amplitude'].label} [1]", "Convergence to the rigid stop")
    caption = Caption(
        f"Left: relative difference of the steady-state {QUANTITIES['x1_amplitude'].label} of {solution_ref(compliant)}, {SOLUTION_DESCRIPTIONS[compliant]} (restitution-matched "
        f"loss factor) from the rigid-stop simulation {solution_ref(reference)} as the bumper stiffens, one colour per excitation frequency; the dashed line has slope -1."
    )
    coincide = coincidence_phrase(reveal_coincident(ax, curves), unit="Hz of Omega_b / 2 pi", spec=".4g")
    if panels == 2:
        ax = axes[1]
        if len(bumpers) == 1:
            for k, frequency in enumerate(f):
                ax.loglog(bumper, dataset["wall_time"].sel(solution=compliant, frequency=frequency).values, "o-", color=colours[k], ms=4, label=f"{fmt(frequency, 'g')} Hz", gid=compliant)
            cost = f"Right: the wall time of each steady state of {solution_ref(compliant)} (transient plus measurement, one process)"
        else:
            for engine in bumpers:
                walls = dataset["wall_time"].sel(solution=engine, frequency=f).transpose("bumper_frequency", "frequency").values
                with np.errstate(all="ignore"):
                    median = np.array([np.nanmedian(w) if np.isfinite(w).any() else np.nan for w in walls])
                marker = ENGINE_MARKERS.get(engine, ("o", 4.0))[0]
                run = np.isfinite(median)  # an engine on a subset of the bumpers: its line joins those it ran
                subset = f", {int(run.sum())} of {bumper.size} bumpers" if run.sum() < bumper.size else ""
                ax.loglog(bumper[run], median[run], f"{marker}-", color=SOLUTION_COLOURS[engine], ms=6, lw=1.6, label=f"{solution_ref(engine)} (median{subset})", gid=engine)
            cost = ("Right: the median wall time of a steady state over the simulated frequencies (transient plus measurement, one process) of " + " and of ".join(f"{solution_ref(e)}, {SOLUTION_DESCRIPTIONS[e]}" for e in bumpers) + ", in the same run")
        rigid = float(np.nanmedian(dataset["wall_time"].sel(solution=reference).values))
        ax.axhline(rigid, color="k", ls=":", lw=1.2, label=f"{reference} (median)", gid=reference)
        finish_axes(ax, "bumper frequency Omega_b / 2 pi [Hz]", "wall time per steady state [s]", "Cost of the compliant model")
        caption.add("cost", f"{cost}; dotted: the median of {solution_ref(reference)}.")
    caption.add("coincide", coincide)
    for ax in axes:
        # ticks at the bumpers computed: read off directly, and no crowded minor-tick labels on a short log axis
        ax.set_xticks(bumper, [fmt(b, "g") for b in bumper])
        ax.xaxis.set_minor_formatter(NullFormatter())
    figure_legend(fig, axes, columns=6)
    return DrawnFigure(fig, name, "Compliant bumper against the rigid stop", caption.text())


def stiffness_tables(dataset: xr.Dataset, setting: StudySetting) -> list[Table]:
    """Per bumper frequency: median and largest difference from the rigid stop, fitted order, median wall time."""
    reference = _stiffness_reference(dataset)
    bumpers = contact_solutions([str(s) for s in dataset["solution"].values], BUMPER)
    if reference is None or not bumpers or not setting.simulation_frequency.size:
        return []
    rows = ["<tr><th>Omega_b/2pi [Hz]</th><th>median rel. diff. |X1|</th><th>largest</th><th>observed order (median)</th><th>median wall time [s]</th></tr>"]
    for r in convergence_rows(dataset, setting, reference, bumpers[0]):
        rows.append(f"<tr><td>{fmt(r.bumper_frequency, 'g')}</td><td>{fmt(r.median, '.2e')}</td><td>{fmt(r.largest, '.2e')}</td><td>{fmt(r.order, '.2f')}</td><td>{fmt(r.wall_time, '.3f')}</td></tr>")
    return [Table(f"{bumpers[0]} against {reference}: convergence and cost", "<table>" + "".join(rows) + "</table>")]


# --------------------------------------------------------------------------------------------------------------------
# What the simulated motion is where it is not periodic: the largest Lyapunov exponent of each engine's motion
# against frequency, with the band the classification calls zero, one panel per restitution ratio.
# --------------------------------------------------------------------------------------------------------------------

#: How each kind of motion is drawn: the regime map's colour, filled markers.
_KINDS = (Regime.CHAOTIC, Regime.QUASI_PERIODIC, Regime.IRREGULAR)


def lyapunov_figure(part: xr.Dataset, engines: list[str], name: str) -> DrawnFigure | None:
    """The largest Lyapunov exponent of every non-periodic simulated point, coloured by the regime it decided;
    None where no engine has one."""
    if "lyapunov_exponent" not in part or "regime" not in part:
        return None
    drawn = [e for e in engines if np.isfinite(part["lyapunov_exponent"].sel(solution=e).values).any()]
    if not drawn:
        return None
    band = MotionThresholds()
    lines = series_by_restitution(part)
    f = part["frequency"].values
    fig, axes = new_figure(len(lines), panel_height=3.0, sharey=True, legend_rows=legend_rows(len(_KINDS) + len(drawn) + 1))  # the R panels compare: one y range
    decided: set[Regime] = set()
    for ax, (text, line) in zip(axes, lines):
        ax.axhspan(-band.zero_band, band.zero_band, color="#dddddd", zorder=0)
        ax.axhline(0.0, color="k", lw=0.8)
        for engine in drawn:
            marker, size = ENGINE_MARKERS.get(engine, ("s", 5.0))
            exponent = line["lyapunov_exponent"].sel(solution=engine).values
            error = line["lyapunov_error"].sel(solution=engine).values if "lyapunov_error" in line else np.zeros_like(exponent)
            regime = line["regime"].sel(solution=engine).values
            for kind in _KINDS:
                chosen = np.isfinite(exponent) & (regime == int(kind))
                if chosen.any():
                    decided.add(kind)
                    ax.errorbar(f[chosen], exponent[chosen], yerr=error[chosen], fmt=marker, ms=size, color=REGIME_COLOURS[kind], mec="k", mew=0.5, ecolor="0.4", elinewidth=0.8, ls="none", gid=engine)
        finish_axes(ax, "frequency [Hz]", axis_label("lyapunov_exponent"), text)
        ax.set_xlim(f[0], f[-1])  # the study's band, as in the other figures
    keys = [_key("o", REGIME_COLOURS[kind], kind.name.lower()) for kind in _KINDS if kind in decided]  # the colours drawn, no other
    keys += [_key(ENGINE_MARKERS.get(e, ("s", 5.0))[0], "white", solution_ref(e)) for e in drawn]
    figure_legend(fig, axes, keys)
    caption = Caption(
        f"Largest Lyapunov exponent of the stroboscopic map per excitation period where the simulated motion did not "
        f"become periodic, {clearance_text(part)}: one panel per restitution ratio, one marker shape per engine "
        f"({', '.join(solution_ref(e) for e in drawn)}), coloured by what it decided (the regime map's colours), bars: "
        "the standard error of block averages. 'exact' takes the exponent from its exact Jacobians (flow x saltation "
        "matrices, renormalised); an integrator from a copy of its own run perturbed by 1e-6 of the motion's scale, "
        f"renormalised every 32 periods. Chaotic: exponent above {band.chaotic_exponent:g} and {band.margin:g} errors; "
        f"quasi-periodic: within the grey band (|exponent| and error <= {band.zero_band:g}) with a line spectrum or a "
        "regular rotation of the strobe points; irregular: the evidence does not decide."
    )
    return DrawnFigure(fig, name, f"What the motion is where it is not periodic, {clearance_text(part)}", caption.text())


def _key(marker: str, colour: str, label: str) -> Line2D:
    return Line2D([], [], marker=marker, ls="none", color=colour, mec="k", mew=0.5, ms=6, label=label)

#: Quantities drawn as frequency responses, in page order.
RESPONSE_QUANTITIES = ("x2_amplitude", "x1_amplitude", "force_amplitude", "suspension_force_amplitude", "impulse")
#: Quantities drawn as simulations against the closed form.
SIMULATION_QUANTITIES = ("x1_amplitude", "x2_amplitude", "force_amplitude", "impulse")
#: Swept parameters whose resonance peaks get a figure of their own.
PEAK_PARAMETERS = ("restitution", "clearance")
#: The row, series or panel label the shared figures give a layout whose stops have their own R.
_OWN_R = "each stop's R"
#: Caption phrases of the shared figures that assume a swept R, and what they say where it is not swept.
_SWEPT_R_WORDS = {": one panel per restitution ratio, ": ": ", "), one colour per restitution ratio. ": "). "}


class FrequencyResponsePage:
    """The page of a stepped study of steady states along frequency (dimension ``solution``, swept parameters,
    ``frequency``, and ``stop`` where the layout has several stops)."""

    def __init__(self, dataset: xr.Dataset) -> None:
        self.dataset = dataset
        self.layout: GeneralSetting = general_setting(dataset)
        #: the paper's view of the study, where its structure has the named view (its extras need it)
        self.setting: StudySetting | None = study_setting(dataset) if self.layout.named is not None else None

    def summary(self) -> str:
        """The solutions and the stops in words."""
        return f"solutions: {', '.join(self.layout.solutions)}; stops: {'; '.join(self.layout.stops)}"

    def sections(self, out: Path) -> list[Section]:
        """The answer (resonance peaks against a swept R or Delta, contact peaks, largest responses, reduction factors,
        in numbers), the resonance peaks, the reduction factors, the linear system, per clearance the responses and
        simulations, agreement."""
        dataset, layout, setting = self.dataset, self.layout, self.setting
        engines = [str(s) for s in dataset["solution"].values if s in ENGINE_SOLUTIONS]
        peaks = [p for p in PEAK_PARAMETERS if p in dataset.dims] if setting is not None and "x1_amplitude" in dataset and engines else []
        checks = cross_checks(dataset)
        answers = [peaks_text(dataset, setting, p) for p in peaks if setting is not None] + [contact_text(dataset)] + [cross_check_text(c) for c in checks] + [answer_text(dataset, layout)]
        if setting is not None and any(s != "linear" for s in dataset["solution"].values):
            answers.append(reduction_text(dataset, layout))
        answers.append(operating_text(operating_point(dataset, layout)))  # beside the reduction factors
        first = warnings_html(warning_lines(dataset, layout))  # before any praise
        sections = [Section("Largest responses", intro=first + "".join(f"<p>{html.escape(a)}</p>" for a in answers if a), tables=[peaks_table(dataset, layout)])]
        if (check := cross_check_section(checks)) is not None:
            sections.append(check)
        for parameter in peaks:
            assert setting is not None
            figure = peak_figure(dataset, setting, parameter, f"peaks_vs_{parameter}")
            sections.append(Section(f"Resonance peaks against the {parameter}", figures=saved([figure], out), tables=peak_tables(dataset, setting, parameter)))
        if setting is not None and any(s != "linear" for s in dataset["solution"].values):
            sections.append(Section("Reduction factors", intro=reduction_intro(), tables=reduction_tables(dataset, layout, paper_study(dataset))))
        intro = f"<p>Stops: {html.escape('; '.join(layout.stops))}. Load: {html.escape(layout.load_text())}.</p>"
        tables = ([modal_table(layout.named)] if layout.named is not None else []) + layout_tables(layout)
        sections.append(Section("Linear system", intro=intro, figures=saved([structure_figure(layout, dataset["frequency"].values, paper_study(dataset))], out), tables=tables))
        if setting is not None and "stop" not in dataset.dims:
            sections += _paper_response_sections(dataset, out)
        else:
            sections += _panel_sections(dataset, layout, out)
        if setting is not None:
            agreement = agreement_table(dataset, setting.split_frequency)
            if agreement is not None:
                sections.append(Section("Simulation against the closed form: agreement by band", tables=[agreement]))
        return sections


def _paper_response_sections(dataset: xr.Dataset, out: Path) -> list[Section]:
    """Per clearance: the frequency responses, regimes, stability and peak contact values, then the simulations (one
    stop on the named view: the paper's figures 5-8 and 21-24). Where one restitution ratio is drawn, a quantity the
    simulation figure holds whole (:func:`_held_by_simulations`) is drawn once, there, in one section per clearance."""
    sections = []
    several = "clearance" in dataset.dims
    for index in range(dataset.sizes.get("clearance", 1)):
        part = dataset.isel(clearance=index) if several else dataset
        tag = f"_clearance{index}" if several else ""
        where = f", {clearance_text(part)}"
        engines = [str(name) for name in part["solution"].values if name in ENGINE_SOLUTIONS]
        held = _held_by_simulations(part, engines)
        simulations = [simulation_figure(part, quantity, engines, f"simulation_{quantity}{tag}") for quantity in SIMULATION_QUANTITIES if quantity in part] if engines else []
        lyapunov = [lyapunov_figure(part, engines, f"lyapunov{tag}")] if engines else []
        if held:
            sections.append(Section(f"Frequency responses and simulations{where}", figures=saved([*simulations, *_response_figures(part, tag, held), *lyapunov], out)))
            continue
        sections.append(Section(f"Frequency responses{where}", figures=saved(_response_figures(part, tag), out)))
        if engines:
            sections.append(Section(f"Simulations against the closed form{where}", figures=saved(simulations + lyapunov, out)))
    return sections


def _held_by_simulations(part: xr.Dataset, engines: list[str]) -> set[str]:
    """The quantities whose simulation figure draws everything their response figure would: one restitution ratio
    (the response figure's panels per solution then hold one series each), no closed form but the linear system and
    ``pgf``, no raw one-impact values, and a simulation with values (else there is no simulation figure)."""
    if not engines or len(series_by_restitution(part)) != 1:
        return set()
    others = [str(s) for s in part["solution"].values if s not in ENGINE_SOLUTIONS and s not in ("linear", "pgf")]
    held = set()
    for quantity in SIMULATION_QUANTITIES:
        if quantity not in part:
            continue
        values = part[quantity]
        raw = f"one_impact_{quantity}"
        if any(np.isfinite(values.sel(solution=s).values).any() for s in others) or (raw in part and np.isfinite(part[raw].values).any()):
            continue
        if any(np.isfinite(values.sel(solution=e).values).any() for e in engines):
            held.add(quantity)
    return held


def _response_figures(part: xr.Dataset, tag: str, held: Collection[str] = ()) -> Iterator[DrawnFigure | None]:
    """Frequency responses (but the quantities ``held`` by the simulation figures), regime map, stability and peak
    contact values at one clearance, one at a time."""
    for quantity in RESPONSE_QUANTITIES:
        if quantity in part and quantity not in held:
            yield response_figure(part, quantity, f"{quantity}{tag}")
    if "regime" in part:
        yield regime_figure(part, f"regime{tag}")
    if "floquet_modulus" in part and "pgf" in part["solution"].values:
        yield stability_figure(part, f"stability{tag}")
    if contact_solutions([str(s) for s in part["solution"].values], BUMPER):
        yield peak_acceleration_figure(part, f"peak_acceleration{tag}")


def _panel_sections(dataset: xr.Dataset, layout: GeneralSetting, out: Path) -> list[Section]:
    """Per clearance and bumper: per restitution ratio one panel per coordinate, the force on the base and each
    stop's impulse; the regime map, the closed form's stability, what the simulated motion is."""
    sections = []
    outer = [d for d in ("clearance", "bumper_frequency") if d in dataset.dims]
    for index in np.ndindex(*(dataset.sizes[d] for d in outer)):
        part = dataset.isel(dict(zip(outer, index)))
        tag = "".join(f"_{d}{i}" for d, i in zip(outer, index))
        figures: list[DrawnFigure | None] = []
        for r in range(part.sizes.get("restitution", 1)):
            line = part.isel(restitution=r) if "restitution" in part.dims else part
            figures.append(response_panels_figure(line, layout, f"responses{tag}_r{r}" if "restitution" in part.dims else f"responses{tag}"))
        if "regime" in part:
            figures.append(unswept_restitution(regime_figure(part, f"regime{tag}"), part))
        if "floquet_modulus" in part and "pgf" in part["solution"].values and np.isfinite(part["floquet_modulus"].sel(solution="pgf").values).any():
            figures.append(unswept_restitution(stability_figure(part, f"stability{tag}"), part))
        engines = [str(s) for s in part["solution"].values if s in ENGINE_SOLUTIONS]
        if engines:
            figures.append(unswept_restitution(lyapunov_figure(part, engines, f"lyapunov{tag}"), part))
        sections.append(Section(f"Responses, {where_text(part) if outer else 'every coordinate and stop'}", figures=saved(figures, out)))
    return sections


def unswept_restitution(drawn: DrawnFigure | None, part: xr.Dataset) -> DrawnFigure | None:
    """Where ``part`` does not sweep R, the shared regime, stability and Lyapunov figures' wording of one series per
    restitution ratio becomes what was drawn: a single series, labelled by R only where one R is shared."""
    if drawn is None or "restitution" in part.dims:
        return drawn
    shared = f"R = {fmt(float(part['restitution']), 'g')}" if "restitution" in part.coords else None
    for ax in drawn.figure.axes:
        if ax.get_title() == _OWN_R:
            ax.set_title(shared or "every simulated point")
        ticks = [t.get_text() for t in ax.get_yticklabels()]
        if _OWN_R in ticks:
            ax.set_yticks(ax.get_yticks(), [(shared or "") if t == _OWN_R else t for t in ticks])
    for legend in drawn.figure.legends:
        for text in legend.get_texts():
            if text.get_text() == _OWN_R:
                text.set_text(shared or "largest modulus")
    caption = drawn.caption
    for swept, single in _SWEPT_R_WORDS.items():
        caption = caption.replace(swept, single)
    return DrawnFigure(drawn.figure, drawn.name, drawn.title, caption)


def page_for(dataset: xr.Dataset) -> StudyPage:
    """The page of a stepped dataset: the bumper's convergence to the rigid stop for the paper's layout with a swept
    bumper frequency, the frequency-response page otherwise."""
    if "bumper_frequency" in dataset.dims and named_layout(dataset) is not None:
        return BumperStiffnessPage(dataset, study_setting(dataset))
    return FrequencyResponsePage(dataset)
