"""Report pages of benchmark scenes: work-precision diagrams, tolerance guidance, and what accuracy costs.

Every figure and table reads the dataset of :func:`vibroimpact.kinds.benchmark.study.run_benchmark` (dimensions case, engine,
rtol), and the model-cost ladder when the scene asked for one. Wall times are medians of several runs, all measured
in one process run: read ratios, not seconds. Engines without a tolerance (the dataset's ``tolerance_free_engines``)
were run once per case and are shown once. Errors are of the fundamental of the structure's first coordinate: X1 on
the paper's layout, a general scene's first coordinate by its name (its dataset records the layout, which the page
states).
"""

from __future__ import annotations

import html
import math
import re
from pathlib import Path

import numpy as np
import xarray as xr

from vibroimpact.kinds.benchmark.study import REFERENCES, equal_error_speedup, loosest_tolerance, measured_names
from vibroimpact.engines.registry import BUMPER, engine_spec
from vibroimpact.engines.settings import STEPPED_TOLERANCES
from vibroimpact.reporting.record import general_setting, is_general
from vibroimpact.reporting.page import DrawnFigure, Section, Table, saved
from vibroimpact.reporting.style import DISPLACEMENT_SCALE, DISPLACEMENT_UNITS, Caption, figure_legend, finish_axes, fmt, legend_rows, new_figure, series_colour

__all__ = ["page_for", "AccuracyPage", "accuracy_figures", "accuracy_tables", "per_period_table", "bumper_answer", "bumper_table", "TARGETS"]

#: X1-fundamental accuracies the guidance is given for [-].
TARGETS = (1e-3, 1e-6)
#: What each reference is (rigid stop and bumper: their closed forms; the bumper under a swept sine, which has none:
#: CVODE Adams at a far tighter tolerance), by :data:`~vibroimpact.kinds.benchmark.study.REFERENCES` key: legend text,
#: caption text, line colour and style.
_REFERENCES = {
    "rigid": (f"reference: {REFERENCES['rigid']}", f"{REFERENCES['rigid']}, the rigid stop in closed form (rigid-stop methods)", "k", ":"),
    "bumper": (f"reference: {REFERENCES['bumper']}", f"{REFERENCES['bumper']}, the bumper in closed form (compliant methods on stepped cases)", "k", "-."),
    "swept": ("reference: CVODE Adams 1e-13", "CVODE Adams at rtol 1e-13 (compliant model under the swept sine: no closed form)", "0.5", ":"),
}
_IMPACT_ERROR = ("impact_time_error", "largest impact-time error [s]")
#: The integrator shown in the per-period table, at the default rtol of stepped steady states.
_INTEGRATOR = "momentary_adams"


def _measured(dataset: xr.Dataset) -> tuple[dict[str, str], str]:
    """The measured coordinate's variable names (``x1_error`` ... on the paper's layout) and its label (X1)."""
    coordinate = str(dataset.attrs["system_coordinates"]).split()[0] if is_general(dataset) else "x1"
    return measured_names(coordinate), coordinate.upper() if re.fullmatch(r"x[0-9]+", coordinate) else coordinate


def _tolerance_free(dataset: xr.Dataset) -> set[str]:
    """Methods run once per case (no tolerance), their one run stored at every rtol."""
    return set(str(dataset.attrs.get("tolerance_free_engines", "")).split())


class AccuracyPage:
    """The page of a benchmark study: work-precision diagrams, tolerance guidance, the ladder and every point.

    Parameters
    ----------
    dataset : xarray.Dataset
        The benchmark's dataset (dimensions ``case``, ``engine``, ``rtol``).
    """

    def __init__(self, dataset: xr.Dataset) -> None:
        self.dataset = dataset

    def summary(self) -> str:
        """The methods measured."""
        return f"methods: {', '.join(map(str, self.dataset['engine'].values))}"

    def sections(self, out: Path) -> list[Section]:
        """One section: the work-precision diagrams and every table (a general scene's layout in words first)."""
        intro = ""
        if is_general(self.dataset):
            setting = general_setting(self.dataset)
            label = _measured(self.dataset)[1]
            intro = f"<p>Structure: {', '.join(setting.names)}. Stops: {html.escape('; '.join(setting.stops))}. Load: {html.escape(setting.load_text())}. Errors are of the {html.escape(label)} fundamental.</p>"
        return [Section("Work-precision", intro=answer_text(self.dataset) + bumper_answer(self.dataset) + intro, figures=saved(accuracy_figures(self.dataset), out), tables=accuracy_tables(self.dataset))]


def answer_text(dataset: xr.Dataset) -> str:
    """The page's answer, first (HTML): per case, the cheapest way to the tightest target against solve_ivp's, and
    what the exact engine costs (the tables below give every target and tolerance)."""
    target = min(TARGETS)
    label = _measured(dataset)[1]
    methods = [str(m) for m in dataset["engine"].values]
    ivp = [m for m in methods if m.startswith("solve_ivp")]
    parts = []
    for case in map(str, dataset["case"].values):
        exact = float(dataset["reference_wall_time"].sel(case=case, reference="exact"))
        ours = [m for m in methods if _is_bumper(m) == math.isnan(exact) and m not in ivp and m not in _tolerance_free(dataset)]
        name, rtol, wall = _cheapest(dataset, case, target, ours)
        other, other_rtol, other_wall = _cheapest(dataset, case, target, ivp)
        text = f"<b>{html.escape(case)}</b>: " + (f"{html.escape(name)} at rtol {fmt(rtol, 'g')} in {fmt(wall)} s" if name else "no integrator of ours reaches it")
        if other:
            text += f" against {html.escape(other)} at rtol {fmt(other_rtol, 'g')} in {fmt(other_wall)} s" + (f" ({fmt(other_wall / wall, '.1f')}x)" if name else "")
        if math.isfinite(exact):
            text += f"; the exact engine, without error, in {fmt(exact)} s"
        parts.append(text)
    return f"<p>Cheapest run within {fmt(target, 'g')} of the {html.escape(label)} fundamental, per case: {'; '.join(parts)}.</p>"


def _is_bumper(method: str) -> bool:
    """Does ``method`` solve the bumper (the compliant model)?"""
    return engine_spec(method).contact == BUMPER


def _bumper_cases(dataset: xr.Dataset) -> list[str]:
    """The cases whose compliant methods were measured against the bumper's closed form."""
    reference = REFERENCES["bumper"]
    if reference not in dataset["reference"].values:
        return []
    return [str(c) for c in dataset["case"].values if np.isfinite(float(dataset["reference_wall_time"].sel(case=c, reference=reference)))]


def _closed_form_per_period(dataset: xr.Dataset, case: str) -> float:
    """Wall time per period [s] of the bumper's closed form on ``case``: its row among the methods where it has one
    (timed as the integrators are), else its run as the reference."""
    reference = REFERENCES["bumper"]
    if reference in dataset["engine"].values:
        value = float(dataset["time_per_period"].sel(case=case, engine=reference).isel(rtol=0))
        if math.isfinite(value):
            return value
    return float(dataset["reference_wall_time"].sel(case=case, reference=reference)) / float(dataset["periods"].sel(case=case))


def _times(ratio: float) -> str:
    """A ratio as ``277x`` (two significant digits below 10: ``0.5x``, ``2.5x``)."""
    return fmt(ratio, ".0f" if ratio >= 10.0 else ".2g", "{}x")


def _bumper_label(dataset: xr.Dataset, case: str) -> str:
    """``case`` with its bumpers' Omega_b / 2 pi, as words (HTML)."""
    frequencies = str(dataset.attrs.get(f"case_{case}_bumper_frequency_Hz", "")).split()
    return f"<b>{html.escape(case)}</b>" + (f" (Omega_b / 2 pi = {', '.join(frequencies)} Hz)" if frequencies else "")


def bumper_answer(dataset: xr.Dataset) -> str:
    """The bumper's measured tolerance guidance (HTML; empty without a bumper case): per case, the loosest rtol at which
    each compliant integrator is within the tightest target of the closed form's fundamental, its cost per period
    there, and the closed form's cost per period with how many times cheaper it is than the cheapest of them."""
    cases = _bumper_cases(dataset)
    if not cases:
        return ""
    target = min(TARGETS)
    label = _measured(dataset)[1]
    free = _tolerance_free(dataset)
    integrators = [str(m) for m in dataset["engine"].values if _is_bumper(str(m)) and str(m) not in free]
    parts = []
    for case in cases:
        periods = float(dataset["periods"].sel(case=case))
        closed = _closed_form_per_period(dataset, case)
        reached, cheapest = [], math.inf
        for method in integrators:
            rtol, wall = loosest_tolerance(dataset, case, method, target)
            if math.isfinite(wall):
                reached.append(f"{html.escape(method)} from rtol {fmt(rtol, 'g')} at {fmt(1e3 * wall / periods, '.3g')} ms per period")
                cheapest = min(cheapest, wall / periods)
            elif np.isfinite(dataset["wall_time"].sel(case=case, engine=method).values).any():
                reached.append(f"{html.escape(method)} at no rtol measured")
        text = f"{_bumper_label(dataset, case)}: {', '.join(reached) or 'no integrator measured'}; {html.escape(REFERENCES['bumper'])}, without tolerance, {fmt(1e6 * closed, '.3g')} us per period"
        if math.isfinite(cheapest):  # a factor below 1 is no saving: said the other way round
            text += f", {_times(cheapest / closed)} cheaper than the cheapest of them" if cheapest >= closed else f", {_times(closed / cheapest)} the cost of the cheapest of them"
        parts.append(text)
    return (
        f"<p>The bumper, against its closed form ({html.escape(REFERENCES['bumper'])}): the loosest rtol within {fmt(target, 'g')} (relative) of "
        f"the {html.escape(label)} fundamental, with every tighter rtol measured and no contact missed, per case: {'; '.join(parts)}.</p>"
    )


def bumper_table(dataset: xr.Dataset) -> str:
    """Per bumper case and rtol: each compliant integrator's error of the measured fundamental against the closed form
    and its cost per period [ms]; per case, the closed form's cost per period [us] (HTML)."""
    names, label = _measured(dataset)
    tolerances = [float(t) for t in np.sort(np.asarray(dataset["rtol"].values, dtype=float))[::-1]]
    free = _tolerance_free(dataset)
    integrators = [str(m) for m in dataset["engine"].values if _is_bumper(str(m)) and str(m) not in free]
    rows = [
        "<tr><th rowspan='2'>case</th><th rowspan='2'>rtol</th>" + "".join(f"<th colspan='2'>{m}</th>" for m in integrators) + "</tr>",
        "<tr>" + f"<th>{html.escape(label)} error</th><th>ms / period</th>" * len(integrators) + "</tr>",
    ]
    for case in _bumper_cases(dataset):
        for rtol in tolerances:
            cells = []
            for method in integrators:
                point = dataset.sel(case=case, engine=method, rtol=rtol)
                flag = " *" if float(point["missed_impacts"]) + float(point["extra_impacts"]) > 0 else ""
                cells.append(f"<td>{fmt(point[names['x1_error']], '.1e')}{flag}</td><td>{fmt(1e3 * float(point['time_per_period']), '.3g')}</td>")
            rows.append(f"<tr><td>{case}</td><td>{fmt(rtol, 'g')}</td>{''.join(cells)}</tr>")
        closed = fmt(1e6 * _closed_form_per_period(dataset, case), ".3g")
        rows.append(f"<tr><td>{case}</td><td>{REFERENCES['bumper']}</td><td colspan='{2 * len(integrators)}'>the reference, no tolerance: {closed} us per period</td></tr>")
    note = (
        f"<p>The relative error of the {html.escape(label)} fundamental over the run against {REFERENCES['bumper']} (the bumper's flow in "
        "closed form, switches found by guaranteed root bracketing: no tolerance), and the wall time per excitation period "
        "(median of the repeats, all in one process run: read ratios). *: contacts missed or extra against the reference. "
        "atol = rtol x the scene's atol_ratio. Empty: not run (a method stops after a run over the scene's time limit).</p>"
    )
    return "<table>" + "".join(rows) + "</table>" + note


def accuracy_figures(dataset: xr.Dataset) -> list[DrawnFigure]:
    """Work-precision diagrams: the measured fundamental's error (X1's) and impact-time error against wall time, one
    row of two panels per case."""
    names, label = _measured(dataset)
    errors = ((names["x1_error"], f"relative error of the {label} fundamental [1]"), _IMPACT_ERROR)
    cases = [str(c) for c in dataset["case"].values]
    methods = [str(m) for m in dataset["engine"].values]
    fig, axes = new_figure(2 * len(cases), panel_height=3.6, legend_rows=legend_rows(len(methods) + 4))
    tolerances = np.sort(np.asarray(dataset["rtol"].values, dtype=float))[::-1]
    caption = Caption(
        f"Work-precision, one row per case: one point per tolerance (rtol {fmt(tolerances[0], '.0e')} ... {fmt(tolerances[-1], '.0e')} from right to "
        "left), error against the reference, wall time the median of repeated runs in one process (read ratios, not seconds)."
    )
    for j, case in enumerate(cases):
        for column, (quantity, axis) in enumerate(errors):
            ax = axes[2 * j + column]
            for k, method in enumerate(methods):
                line = dataset.sel(case=case, engine=method)
                if method in _tolerance_free(dataset):
                    line = line.isel(rtol=[0])
                    caption.add("free", f"{', '.join(sorted(_tolerance_free(dataset)))}: no tolerance, one run (one point).")
                wall, error = line["wall_time"].values, line[quantity].values
                if not np.isfinite(wall).any():
                    continue
                missed = line["missed_impacts"].values > 0
                floor = np.maximum(error, 1e-17)  # an exact zero still gets a point
                ivp = method.startswith("solve_ivp")
                ax.loglog(wall, np.where(missed, np.nan, floor), "s--" if ivp else "o-", color=series_colour(k), ms=4, lw=1.2, label=method, gid=method)
                caption.add("ivp" if ivp else "sundials", "Dashed with squares: scipy's solve_ivp." if ivp else "Solid with circles: SUNDIALS engines.")
                if missed.any():
                    ax.loglog(wall[missed], floor[missed], "x", color=series_colour(k), ms=9, mew=2, label="_nolegend_", gid=method)
                    caption.add("missed", "Crosses: runs that missed impacts of the reference (errors floored at 1e-17 where zero).")
            for model, reference in REFERENCES.items():
                if reference not in dataset["reference"].values:
                    continue  # a dataset of an older version
                value = float(dataset["reference_wall_time"].sel(case=case, reference=reference))
                if math.isfinite(value):
                    legend, text, colour, style = _REFERENCES[model]
                    ax.axvline(value, color=colour, ls=style, lw=1.3, label=legend)
                    line = "Dash-dotted" if style == "-." else "Dotted"
                    caption.add(f"reference {model}", f"{line} vertical{' (grey)' if colour != 'k' else ''}: the wall time of the reference, {text}.")
            if quantity == names["x1_error"]:
                for target in TARGETS:
                    ax.axhline(target, color="k", lw=0.6, alpha=0.5)
                caption.add("targets", f"Thin horizontal lines: the {' and '.join(fmt(t, '.0e') for t in TARGETS)} targets.")
            finish_axes(ax, "wall time [s] (median)", axis, case)
    figure_legend(fig, axes, columns=4)
    return [DrawnFigure(fig, "work_precision", "Work-precision diagrams", caption.text())]


def accuracy_tables(dataset: xr.Dataset) -> list[Table]:
    """The answer (cheapest way to each target), tolerance guidance, the ladder, and every measured point."""
    label = _measured(dataset)[1]
    tables = [Table(f"Cheapest way to the {label} fundamental within a target", _answer_table(dataset)), Table("Tolerance guidance: loosest rtol meeting each target", _guidance_table(dataset))]
    if _bumper_cases(dataset):
        tables.insert(0, Table(f"The bumper against its closed form ({REFERENCES['bumper']}): {label} error and cost per period at each rtol", bumper_table(dataset)))
    if "floor_time_per_period" in dataset:
        tables.insert(0, Table("Cost per period: the exact engine against its floor, the pure-Python loop and momentary", per_period_table(dataset)))
    if "momentary_adams" in dataset["engine"].values:
        tables.append(Table("momentary (Adams) against exact and against solve_ivp at equal impact-time error", _equal_error_table(dataset)))
    if "model" in dataset.dims:
        tables.append(Table("Model cost ladder: one steady state per model", _ladder_table(dataset)))
    tables.append(Table("run-study --estimate against measured runs of the shipped studies", _estimate_table()))
    for case in dataset["case"].values:
        tables.append(Table(f"Every point: {case}", _points_table(dataset, str(case))))
    return tables


def _cheapest(dataset: xr.Dataset, case: str, target: float, methods: list[str]) -> tuple[str, float, float]:
    """(method, rtol, wall) of the fastest method meeting ``target`` at its loosest sufficient tolerance."""
    best = ("", math.nan, math.inf)
    for method in methods:
        rtol, wall = loosest_tolerance(dataset, case, method, target)
        if math.isfinite(wall) and wall < best[2]:
            best = (method, rtol, wall)
    return best


def _answer_table(dataset: xr.Dataset) -> str:
    """Per case and target: the cheapest of our integrators against the cheapest solve_ivp method (HTML)."""
    methods = [str(m) for m in dataset["engine"].values]
    ivp = [m for m in methods if m.startswith("solve_ivp")]
    rows = [
        "<tr><th>case</th><th>target</th><th>cheapest integrator</th><th>its rtol</th><th>wall [s]</th><th>fastest solve_ivp</th><th>its rtol</th>"
        "<th>wall [s]</th><th>speed-up</th><th>exact engine (rigid stop, error 0) [s]</th></tr>"
    ]
    for case in dataset["case"].values:
        exact = float(dataset["reference_wall_time"].sel(case=case, reference="exact"))
        # one model per comparison: the rigid stop on stepped cases (compliant runs answer another question), the
        # compliant model on swept ones
        swept = math.isnan(exact)
        ours = [m for m in methods if _is_bumper(m) == swept and not m.startswith("solve_ivp") and m not in _tolerance_free(dataset)]
        for target in TARGETS:
            name, rtol, wall = _cheapest(dataset, str(case), target, ours)
            other, other_rtol, other_wall = _cheapest(dataset, str(case), target, ivp)
            speedup = other_wall / wall if name and other else math.nan
            rows.append(
                f"<tr><td>{case}</td><td>{fmt(target, 'g')}</td><td>{name or 'none reaches it'}</td><td>{fmt(rtol, 'g')}</td><td>{fmt(wall)}</td>"
                f"<td>{other or 'none reaches it'}</td><td>{fmt(other_rtol, 'g')}</td><td>{fmt(other_wall)}</td><td>{fmt(speedup, '.1f', '{}x')}</td>"
                f"<td>{fmt(exact)}</td></tr>"
            )
    note = (
        f"<p>For each method the loosest tolerance whose {_measured(dataset)[1]} fundamental is within the target (and every tighter one run, "
        "without a missed impact), and the wall time of a run at it; the cheapest of our integrators against the cheapest "
        "solve_ivp method, within one model: the rigid stop on stepped cases, the compliant model on the swept one (whose "
        "reference is CVODE Adams at rtol 1e-13: a swept sine has no closed form, so CVODE Adams there is measured against "
        f"its own integrator at a far tighter tolerance; the bumper on stepped cases is measured against {REFERENCES['bumper']}, "
        "its closed form: see its own table). For the rigid stop the exact engine needs no tolerance and is cheaper still. Irregular motion "
        "has no converged trajectory: its errors grow with the run's length (trajectories diverge), so its figures hold for "
        "runs of the length measured here only.</p>"
    )
    return "<table>" + "".join(rows) + "</table>" + note


def _guidance_table(dataset: xr.Dataset) -> str:
    """Per method: the loosest rtol meeting each target in each case, and its wall time [s] (HTML)."""
    header = "<tr><th>engine</th>" + "".join(f"<th>{case}: rtol for {fmt(t, 'g')}</th>" for case in dataset["case"].values for t in TARGETS) + "</tr>"
    rows = [header]
    free = _tolerance_free(dataset)
    for method in dataset["engine"].values:
        cells = []
        for case in dataset["case"].values:
            for target in TARGETS:
                rtol, wall = loosest_tolerance(dataset, str(case), str(method), target)
                text = ("none needed" if math.isfinite(rtol) else "") if method in free else fmt(rtol, "g")
                cells.append(f"<td>{text}{fmt(wall, '.3g', ' ({} s)')}</td>")
        rows.append(f"<tr><td>{method}</td>{''.join(cells)}</tr>")
    return "<table>" + "".join(rows) + "</table>"


def _equal_error_table(dataset: xr.Dataset) -> str:
    """Per rigid-stop case and tolerance: momentary's wall time, its ratio to exact's, and the fastest solve_ivp method's
    wall time at the same impact-time error (interpolated, :func:`vibroimpact.kinds.benchmark.study.equal_error_speedup`)."""
    ivp = [str(m) for m in dataset["engine"].values if str(m).startswith("solve_ivp")]
    rows = ["<tr><th>case</th><th>rtol</th><th>momentary_adams [s]</th><th>exact [s]</th><th>momentary / exact</th><th>best solve_ivp at equal error</th><th>its time / momentary's</th></tr>"]
    for case in dataset["case"].values:
        exact = float(dataset["reference_wall_time"].sel(case=case, reference="exact"))
        if not math.isfinite(exact):
            continue
        for tolerance in dataset["rtol"].values:
            wall = float(dataset["wall_time"].sel(case=case, engine="momentary_adams", rtol=tolerance))
            if not math.isfinite(wall):
                continue
            ratio, other = equal_error_speedup(dataset, str(case), "momentary_adams", float(tolerance), ivp)
            rows.append(
                f"<tr><td>{case}</td><td>{fmt(tolerance, 'g')}</td><td>{fmt(wall, '.4f')}</td><td>{fmt(exact, '.4f')}</td><td>{fmt(wall / exact, '.1f')}</td>"
                f"<td>{other}</td><td>{fmt(ratio, '.2f')}</td></tr>"
            )
    return "<table>" + "".join(rows) + "</table>"


def _ladder_table(dataset: xr.Dataset) -> str:
    """One steady state through each model: wall time [s], |X1| [mm] (the measured coordinate's), difference from exact
    and relative cost (HTML)."""
    names, label = _measured(dataset)
    rows = [f"<tr><th>model</th><th>wall time per frequency point [s]</th><th>|{label}| [{DISPLACEMENT_UNITS}]</th><th>relative difference from exact</th><th>cost / exact</th></tr>"]
    exact_wall = float(dataset["ladder_wall_time"].sel(model="exact"))
    for model in dataset["model"].values:
        point = dataset.sel(model=model)
        wall = float(point["ladder_wall_time"])
        rows.append(
            f"<tr><td>{model}</td><td>{fmt(wall)}</td><td>{fmt(DISPLACEMENT_SCALE * float(point[names['ladder_x1_amplitude']]), '#.7g')}</td>"
            f"<td>{fmt(point[names['ladder_x1_difference']], '.2e')}</td><td>{fmt(wall / exact_wall)}</td></tr>"
        )
    return "<table>" + "".join(rows) + "</table>" + f"<p>{dataset.attrs.get('ladder_description', '')}</p>"


def _estimate_table(results: Path = Path("results")) -> str:
    """Predicted wall time (without the report) of each shipped study against its last run in ``results/``."""
    from vibroimpact.runs.estimate import estimate_scene
    from vibroimpact.scene import SceneError, load_scene, shipped_studies_dir

    rows = ["<tr><th>study</th><th>predicted [s]</th><th>measured [s]</th><th>measured / predicted</th><th>processes</th></tr>"]
    for path in sorted(shipped_studies_dir().glob("*.yaml")):
        try:
            scene = load_scene(path)
        except SceneError as error:  # a shipped study being edited: this page is about another one
            rows.append(f"<tr><td>{path.stem}</td><td></td><td>invalid scene ({len(error.problems)} problems)</td><td></td><td></td></tr>")
            continue
        output = results / scene.name / f"{scene.name}.nc"
        measured, jobs = math.nan, 0
        if output.is_file():
            with xr.open_dataset(output) as done:
                measured, jobs = float(done.attrs.get("run_wall_time_s", math.nan)), int(done.attrs.get("run_jobs", 0))
        if not jobs:
            rows.append(f"<tr><td>{scene.name}</td><td></td><td>not run with this version</td><td></td><td></td></tr>")
            continue
        estimate = estimate_scene(scene, jobs=jobs)
        predicted = estimate.wall_time - estimate.parts.get("report", 0.0)
        rows.append(f"<tr><td>{scene.name}</td><td>{fmt(predicted, '.0f')}</td><td>{fmt(measured, '.0f')}</td><td>{fmt(measured / predicted, '.2f')}</td><td>{jobs}</td></tr>")
    note = "<p>Measured: the run_wall_time_s of results/NAME/NAME.nc (dataset written, report excluded) from this machine's last run of each study.</p>"
    return "<table>" + "".join(rows) + "</table>" + note


def _points_table(dataset: xr.Dataset, case: str) -> str:
    """Every measured point of ``case``: cost, impacts found and missed, errors (HTML)."""
    names, label = _measured(dataset)
    rows = [f"<tr><th>method</th><th>rtol</th><th>wall [s]</th><th>steps</th><th>rhs calls</th><th>impacts</th><th>missed</th><th>extra</th><th>{label} error</th><th>impact-time error [s]</th><th>impulse error</th></tr>"]
    free = _tolerance_free(dataset)
    for method in dataset["engine"].values:
        for tolerance in dataset["rtol"].values[:1] if method in free else dataset["rtol"].values:
            p = dataset.sel(case=case, engine=method, rtol=tolerance)
            if not np.isfinite(float(p["wall_time"])):
                continue
            rows.append(
                f"<tr><td>{method}</td><td>{'none' if method in free else fmt(tolerance, 'g')}</td><td>{fmt(p['wall_time'], '.4f')}</td><td>{fmt(p['steps'], '.0f')}</td><td>{fmt(p['rhs_calls'], '.0f')}</td>"
                f"<td>{fmt(p['impacts'], '.0f')}</td><td>{fmt(p['missed_impacts'], '.0f')}</td><td>{fmt(p['extra_impacts'], '.0f')}</td><td>{fmt(p[names['x1_error']], '.2e')}</td>"
                f"<td>{fmt(p['impact_time_error'], '.2e')}</td><td>{fmt(p['impulse_error'], '.2e')}</td></tr>"
            )
    for reference in dataset["reference"].values:
        wall = float(dataset["reference_wall_time"].sel(case=case, reference=reference))
        if math.isfinite(wall):
            rows.append(f"<tr><td>reference: {reference}</td><td></td><td>{fmt(wall, '.4f')}</td><td></td><td></td><td>{fmt(dataset['reference_impacts'].sel(case=case, reference=reference), '.0f')}</td><td>0</td><td>0</td><td>0</td><td>0</td><td>0</td></tr>")
    return "<table>" + "".join(rows) + "</table>"


def per_period_table(dataset: xr.Dataset) -> str:
    """Per stepped case: microseconds per excitation period of the exact engine, of its floor (the compiled kernel
    alone, with and without the moments), of ``exact_python`` and of ``momentary_adams`` at the default rtol, and the
    ratios exact_python / exact and exact / floor (HTML)."""
    rtol = STEPPED_TOLERANCES[0]
    rows = [
        "<tr><th>case</th><th>frequency [Hz]</th><th>periods</th><th>exact (compiled) [us/period]</th><th>floor: its kernel alone [us/period]</th>"
        "<th>kernel without moments [us/period]</th><th>exact_python [us/period]</th>"
        f"<th>{_INTEGRATOR} at rtol {fmt(rtol, 'g')} [us/period]</th><th>exact_python / exact</th><th>exact / floor</th></tr>"
    ]
    engines = [str(m) for m in dataset["engine"].values]

    def engine_cost(case: str, method: str) -> float:
        if method not in engines or not any(np.isclose(float(r), rtol, rtol=1e-9, atol=0.0) for r in dataset["rtol"].values):
            return math.nan
        return 1e6 * float(dataset["time_per_period"].sel(case=case, engine=method).sel(rtol=rtol, method="nearest"))

    for case in dataset["case"].values:
        exact, floor = 1e6 * float(dataset["reference_time_per_period"].sel(case=case)), 1e6 * float(dataset["floor_time_per_period"].sel(case=case))
        if not math.isfinite(exact):
            continue  # a swept case: no exact reference
        bare = 1e6 * float(dataset["floor_no_moments_time_per_period"].sel(case=case)) if "floor_no_moments_time_per_period" in dataset else math.nan
        python, integrator = engine_cost(str(case), "exact_python"), engine_cost(str(case), _INTEGRATOR)
        frequency = dataset.attrs.get(f"case_{case}_frequency_Hz", math.nan)
        rows.append(
            f"<tr><td>{case}</td><td>{fmt(frequency, 'g')}</td><td>{fmt(dataset['periods'].sel(case=case), '.0f')}</td><td>{fmt(exact, '.2f')}</td>"
            f"<td>{fmt(floor, '.2f')}</td><td>{fmt(bare, '.2f')}</td><td>{fmt(python, '.1f')}</td><td>{fmt(integrator, '.1f')}</td>"
            f"<td>{fmt(python / exact, '.0f', '{}x')}</td><td>{fmt(exact / floor, '.2f', '{}x')}</td></tr>"
        )
    note = (
        "<p>Wall time of one run of the case divided by its periods, in microseconds; every number, and so every ratio, "
        "measured in one process run (median of the repeated runs; shared machines are noisy: read the ratios, not the "
        "microseconds). exact: the compiled engine as studies call it (its Python face included), with the per-period "
        f"Fourier moments the benchmark's {_measured(dataset)[1]} needs. Floor: its compiled kernel (exact_core.run_periods) alone on the same "
        "run with the arguments the engine prepares, prepared once and untimed, its runs taken in turn with the exact ones so that a change of the machine's load falls on both; "
        "exact / floor is what the Python face adds. "
        "Without moments: the kernel computing strobes, impacts and segments only. exact_python: the same algorithm in "
        "pure Python (it has no tolerance: one run).</p>"
    )
    return "<table>" + "".join(rows) + "</table>" + note


def page_for(dataset: xr.Dataset) -> AccuracyPage:
    """The page of a benchmark dataset."""
    return AccuracyPage(dataset)
