"""The page of a design study: which absorber and stop to build, answered first, then what the reader must know
before building it; the figures (:mod:`vibroimpact.kinds.design.figures`: the objective over the variables with the
search's path, the compared designs' responses, their worst cases under mistuning); a table of the compared designs
(:func:`designs_table`); and how it was computed (:func:`method_text`, :func:`certificates_table`). Everything is read
from the dataset."""

from __future__ import annotations

import html
import math
from pathlib import Path

import numpy as np
import xarray as xr

from vibroimpact.kinds.design.answer import never_strikes, sample_name, answer_text, design_titles, linear_wins, certified_worst, design_evaluation, design_text, mistuning_spreads, present_designs, sample_counts, screen_words, stage_counts, unit_text, variable_names, warnings
from vibroimpact.kinds.design.figures import DESIGN_COLOURS, design_figures
from vibroimpact.kinds.design.consistency import contradictions
from vibroimpact.kinds.design.evaluate import CERTIFY_OPERATING_RUN, CERTIFY_OPERATING_STARTS, OPERATING_RUN, OPERATING_STARTS
from vibroimpact.kinds.design.operating import design_operating, operating_sentence, operating_warnings
from vibroimpact.kinds.design.quantity import constraint_quantity, objective_quantity, operating_limit
from vibroimpact.kinds.design.scene import safe_name
from vibroimpact.kinds.design.tradeoff import front_text, tradeoff_figure
from vibroimpact.reporting.page import Section, Table, saved
from vibroimpact.reporting.style import fmt

__all__ = ["DesignPage", "page_for", "designs_table", "certificates_table", "method_text", "best_marks"]

_WRAP = "style='white-space:normal'"


def best_marks(values: list[float]) -> list[bool]:
    """Which of ``values`` are the least (within 1e-9 relative); none when fewer than two are finite."""
    finite = [v for v in values if math.isfinite(v)]
    if len(finite) < 2:
        return [False] * len(values)
    least = min(finite)
    return [math.isfinite(v) and v <= least + 1e-9 * abs(least) for v in values]


def _variable_cell(d: xr.Dataset, name: str, k: int) -> str:
    value = float(d[f"design_{safe_name(name)}"].values[k])
    if not math.isfinite(value):
        return "no stop" if name in ("clearance", "restitution") else "n/a"
    return fmt(1e3 * value, ".4g") if name == "clearance" else fmt(value, ".4g")


def designs_table(dataset: xr.Dataset) -> str:
    """The compared designs (rows) with their variables, worst case over the samples, nominal worst case, certified
    worst case and the motion that sets it (the objective's measure), and the constraint's measure at the operating
    frequency; the least of each result column
    marked ★ bold."""
    d = dataset
    rows = present_designs(d) or [1]
    names = variable_names(d)
    values = d["design_sample_value"].values
    q, c, limit = objective_quantity(d), constraint_quantity(d), operating_limit(d)
    constrained = math.isfinite(limit)
    columns: dict[str, list[float]] = {
        "over": [float(np.nanmax(values[k])) if np.any(np.isfinite(values[k])) else math.nan for k in rows],
        "nominal": [float(values[k, 0]) for k in rows],
        "certified": [certified_worst(d, k)[0] for k in rows],
    }
    if constrained:
        columns["operating"] = [float(d["design_operating_amplitude"].values[k]) for k in rows]
    marks = {key: best_marks(column) for key, column in columns.items()}
    heads = [f"<th {_WRAP}>{html.escape(n)}{' [mm]' if n == 'clearance' else ('' if not unit_text(str(d[f'variable_{safe_name(n)}'].attrs.get('units', '1'))) else ' [' + unit_text(str(d[f'variable_{safe_name(n)}'].attrs.get('units'))) + ']')}</th>" for n in names]
    worst = "worst case" if q.name == "x1_amplitude" else f"worst case {q.symbol}"  # the paper's |X1| as the note says it
    heads += [f"<th {_WRAP}>{worst} over the {d.sizes['sample']} samples [{q.unit}]</th>", f"<th {_WRAP}>nominal {worst} [{q.unit}]</th>", f"<th {_WRAP}>certified {worst} [{q.unit}] and the motion that sets it</th>"]
    if constrained:
        heads.append(f"<th {_WRAP}>{c.symbol} at {fmt(d.attrs['operating_frequency_Hz'], '.4g')} Hz [{c.unit}] (allowed {c.number(limit)})</th>")
    lines = [f"<table><tr><th>design</th>{''.join(heads)}</tr>"]
    for j, k in enumerate(rows):
        evaluation = design_evaluation(d, k)
        swatch = f"<span style='color:{DESIGN_COLOURS[k]}'>■</span> "
        extra = f"<br><small>{html.escape(design_text(d, k))}</small>" if k == 2 else ""
        cells = [f"<td {_WRAP}>{swatch}{html.escape(design_titles(d)[k])}{extra}</td>"] + [f"<td>{_variable_cell(d, n, k)}</td>" for n in names]
        over = q.number(columns["over"][j])
        if evaluation >= 0 and np.any(np.isfinite(values[k])):
            s = int(np.nanargmax(values[k]))
            over += f"<br><small>sample {s}, {fmt(d['sample_frequency'].values[evaluation, s], '.4g')} Hz</small>"
        value, row = certified_worst(d, k)
        if row >= 0:
            certified = f"{q.number(value)}<br><small>{html.escape(str(d['certificate_motion'].values[row]))}, {sample_name(int(d['certificate_sample'].values[row]))}, {fmt(d['certificate_frequency'].values[row], '.4g')} Hz</small>"
        else:
            certified = "exact (no stop: the band peak in closed form)" if k == 2 else "not certified"
        texts = {"over": over, "nominal": q.number(columns["nominal"][j]), "certified": certified}
        if constrained:
            operating = columns["operating"][j]
            texts["operating"] = c.number(operating) + (" <small>(above the limit)</small>" if operating > limit else "")
        for key, text in texts.items():
            cells.append(f"<td {_WRAP if key == 'certified' else ''}>{'<b>★ ' + text + '</b>' if marks[key][j] else text}</td>")
        lines.append(f"<tr>{''.join(cells)}</tr>")
    lines.append("</table>")
    note = (f"<p><small>★ bold: the least value of the column. Worst case: the largest stable {q.symbol} over the band; over the samples: the largest "
            "under any mistuning sample (sample 0 is the nominal design); certified: the largest found by continuing every branch from the "
            f"{'bumper orbits shot from the rigid twin' + chr(39) + 's closed forms' if screen_words(d) == 'bumper' else 'closed-form orbits'} (nominal sample and the one that sets the objective).</small></p>")  # fmt: skip
    return "".join(lines) + note


def _who(dataset: xr.Dataset, evaluation: int) -> str:
    """How the page names an evaluated candidate."""
    if evaluation == int(dataset.attrs.get("recommended_evaluation", -1)):
        return f"the {design_titles(dataset)[0]}"
    return "the scene's design" if evaluation == 0 else f"candidate {evaluation}"


def certificates_table(dataset: xr.Dataset) -> str:
    """Each certification: the design and sample, the screen's and the continuation's worst case, where, the motion,
    and its wall time; empty when nothing was certified."""
    d = dataset
    if d.sizes["certificate"] == 0:
        return ""
    q = objective_quantity(d)
    worst = "worst case" if q.name == "x1_amplitude" else f"worst case {q.symbol}"
    lines = [f"<table><tr><th>design</th><th>sample</th><th {_WRAP}>screened {worst} [{q.unit}]</th><th {_WRAP}>certified {worst} [{q.unit}]</th><th>at [Hz]</th><th>motion</th><th>wall time [s]</th><th>error</th></tr>"]
    for r in range(d.sizes["certificate"]):
        who = _who(d, int(d["certificate_evaluation"].values[r]))
        lines.append(f"<tr><td>{who}</td><td>{sample_name(int(d['certificate_sample'].values[r])).removeprefix('sample ')}</td><td>{q.number(d['certificate_screened'].values[r])}</td><td>{q.number(d['certificate_worst'].values[r])}</td>"
                     f"<td>{fmt(d['certificate_frequency'].values[r], '.5g')}</td><td {_WRAP}>{html.escape(str(d['certificate_motion'].values[r]))}</td>"
                     f"<td>{fmt(d['certificate_wall_time'].values[r], '.3g')}</td><td {_WRAP}>{html.escape(str(d['certificate_error'].values[r])) or 'none'}</td></tr>")  # fmt: skip
    return "".join(lines) + "</table>"


def method_text(dataset: xr.Dataset) -> str:
    """How the page's numbers were computed (HTML paragraphs): the screen, the search and its evaluations by stage,
    the mistuning, the certification, with their wall times."""
    d = dataset
    n, samples = d.sizes["evaluation"], d.sizes["sample"]
    counts = stage_counts(d)
    search_time = float(d["search_wall_time"].values) if "search_wall_time" in d else math.nan
    certify_time = float(d["certification_wall_time"].values) if "certification_wall_time" in d else math.nan
    per = search_time / (n * samples) if n * samples else math.nan
    method = str(d.attrs.get("search_method", "?"))
    if method == "grid":
        how = f"A grid over the variables ({counts.get('grid', 0)} candidates)"
    else:
        polish = f", then a bounded Nelder-Mead polish from the best one ({counts.get('polish', 0)} evaluations)" if counts.get("polish") else ", no polish"
        how = f"Differential evolution (scipy, Latin-hypercube start, seeded; {counts.get('global', 0)} evaluations){polish}"
    stages = ", ".join(f"{name} {count}" for name, count in counts.items() if count)
    spreads = mistuning_spreads(d)
    corners, random = sample_counts(d)
    box = f", the {corners} corners of that box" if corners else ""
    box += f" and its worst point, sought by a bounded Nelder-Mead maximisation of the screen from the worst sample ({int(d.attrs['box_evaluations'])} evaluations)" if "box_worst_screened" in d.attrs else ""
    mistuned = (f"{random} samples of a seeded Latin hypercube (seed {d.attrs.get('mistuning_seed', '?')}) over {' and '.join(s.text() for s in spreads)}, plus the nominal design{box}"
                if spreads and samples > 1 else "the nominal design only (no mistuning)")  # fmt: skip
    quantile = float(d.attrs.get("quantile", 1.0))
    over = "the worst of them" if quantile >= 1.0 else f"their {fmt(quantile, '.3g')} quantile"
    q, c, limit = objective_quantity(d), constraint_quantity(d), operating_limit(d)
    if d.attrs.get("screen") == "bumper_orbits":
        screen = (f"<p><b>The screen (bumper orbits).</b> Each candidate's worst case is, under each mistuning sample, the largest {q.symbol} over "
                  f"{fmt(d.attrs['band_low_Hz'], '.4g')}-{fmt(d.attrs['band_high_Hz'], '.4g')} Hz of every stable motion it knows: the contact-free motion "
                  "(closed form) where it clears the stop, and the period-1 bumper orbit of each root of the rigid twin's closed form (the same stop, rigid), "
                  "shot on the bumper's exact map at each scan frequency from the orbit at the previous one, stability from its Floquet multipliers, "
                  "maxima refined in frequency; where no such motion is stable, a guess at the motion's size from the orbits that exist.")  # fmt: skip
    else:
        screen = (f"<p><b>The screen (closed forms).</b> Each candidate's worst case is, under each mistuning sample, the largest {q.symbol} over "
                  f"{fmt(d.attrs['band_low_Hz'], '.4g')}-{fmt(d.attrs['band_high_Hz'], '.4g')} Hz of every stable closed-form motion: the contact-free motion where "
                  "it clears the stop and both roots of the period-1 impact orbit where admissible and stable, maxima refined in frequency; where no such "
                  "motion is stable, a guess at the motion's size from the orbits that exist.")  # fmt: skip
    parts = [f"{screen} The objective is {over} over the samples: {mistuned}.</p>"]
    if math.isfinite(limit):
        contradicted = np.atleast_1d(d.attrs.get("recommended_contradicted", np.zeros(0, dtype=int)))
        returned = (f" {contradicted.size} candidate{'s' if contradicted.size != 1 else ''} the screen called feasible broke the limit when certified; each was scored on its certificate, "
                    "its neighbours passed over, and the next distinct candidate certified.") if contradicted.size else ""  # fmt: skip
        parts.append(f"<p><b>The operating constraint.</b> {c.symbol} at {fmt(d.attrs['operating_frequency_Hz'], '.4g')} Hz must stay at or below {c.text(limit)} on every motion "
                     f"found there, under every sample: the screen takes the largest of the stable closed-form motions and of every motion {OPERATING_STARTS} seeded runs settle on "
                     f"(the contact-free linear state, rest, and random states from 5 % to twice the motion's length; {OPERATING_RUN[0]} periods dropped, {OPERATING_RUN[1]} measured); "
                     f"the certification runs {CERTIFY_OPERATING_STARTS} more ({CERTIFY_OPERATING_RUN[0]} periods dropped, {CERTIFY_OPERATING_RUN[1]} measured), shoots every periodic motion "
                     "they reach (its orbit exact, its value the largest one-period fundamental over its period) and adds the brute force's attractors there. The search "
                     f"minimised the objective raised by 10 times the relative excess over the limit (a penalty, not a hard bound; {int(np.sum(d['feasible'].values == 1))} of {n} "
                     f"candidates keep it on the screen).{returned}</p>")  # fmt: skip
    jobs = d.attrs.get("run_jobs")
    workers = f" on {int(jobs)} worker{'s' if int(jobs) != 1 else ''}" if isinstance(jobs, (int, np.integer)) else ""
    parts.append(f"<p><b>The search.</b> {how}. {n} candidates in all, by stage: {stages} (the reference is the scene's own design); {n * samples} "
                 f"{screen_words(d)} problems in {fmt(search_time, '.3g')} s of wall time{workers}, {fmt(1e3 * per, '.3g')} ms a problem.</p>")  # fmt: skip
    certified = d.sizes["certificate"]
    if certified:
        total = float(np.nansum(d["certificate_wall_time"].values))
        which: dict[str, list[str]] = {}
        for r in range(certified):
            which.setdefault(_who(d, int(d["certificate_evaluation"].values[r])), []).append(str(int(d["certificate_sample"].values[r])) if int(d["certificate_sample"].values[r]) >= 0 else "the box's worst point")
        listed = "; ".join(f"{who} at sample{'s' if len(s) > 1 else ''} {' and '.join(s)}" for who, s in which.items())
        parts.append(f"<p><b>The certification (continuation and brute force).</b> {certified} problem{'s' if certified > 1 else ''} ({listed}; sample 0 is the nominal design), "
                     f"each continued in frequency along every branch started from its {'bumper orbits shot from the rigid twin' + chr(39) + 's' if d.attrs.get('screen') == 'bumper_orbits' else 'closed-form orbits'}, and swept by brute force (up and down, two more starts, "
                     f"{d.sizes.get('attractor_point', 0)} frequencies; a larger periodic attractor it finds is continued and its maximum located): {fmt(certify_time, '.3g')} s of wall time, "
                     f"{fmt(total, '.3g')} s summed over the problems. A certified worst case above the screen's raises the candidate's score; the "
                     "recommendation is the best certified candidate.</p>")  # fmt: skip
        parts.append(cost_text(d))
    else:
        parts.append("<p><b>The certification (continuation).</b> Nothing was certified: the worst cases are the screen's.</p>")
    return "".join(parts)


def cost_text(dataset: xr.Dataset) -> str:
    """What locating the worst case cost by continuation, and by the search's closed-form screen, against a stepped
    sweep reaching the same maximum to the same accuracy (measured in this run: the sweep's points from the branch's
    curvature, its cost from the brute force's measured time per point), for the recommended design's nominal
    certificate. The screen's cost is compared only where its maximum is the certified one."""
    d = dataset
    rows = np.flatnonzero((d["certificate_evaluation"].values == int(d.attrs.get("recommended_evaluation", -1))) & (d["certificate_sample"].values == 0))
    if not rows.size or "certificate_sweep_time" not in d:
        return ""
    r = int(rows[0])
    continuation = float(d["certificate_continuation_time"].values[r])
    screen = float(d["certificate_screen_time"].values[r]) if "certificate_screen_time" in d else math.nan
    worst, screened = float(d["certificate_worst"].values[r]), float(d["certificate_screened"].values[r])
    q = objective_quantity(d)
    same = math.isfinite(screen) and screen > 0.0 and abs(screened - worst) <= 1e-6 * worst  # the screen found the certified maximum
    cells, ratios, screen_ratios = [], [], []
    for a in range(d.sizes["accuracy"]):
        points, cost = float(d["certificate_sweep_points"].values[r, a]), float(d["certificate_sweep_time"].values[r, a])
        if math.isfinite(points) and math.isfinite(cost) and continuation > 0.0:
            ratio = cost / continuation
            ratios.append(ratio)
            verdict = f"{fmt(ratio, '.2g')}x the continuation's cost" if ratio >= 1.0 else f"{fmt(1.0 / ratio, '.2g')}x cheaper than the continuation"
            cells.append(f"to {fmt(d['sweep_accuracy'].values[a], '.0e')} relative, {fmt(points, '.3g')} frequencies, {fmt(cost, '.3g')} s: {verdict}")
            if same:
                gain = cost / screen
                to = f"that sweep to {fmt(d['sweep_accuracy'].values[a], '.0e')}"
                screen_ratios.append(f"{fmt(gain, '.2g')}x cheaper than {to}" if gain >= 1.0 else f"{fmt(1.0 / gain, '.2g')}x the cost of {to}")
    if not cells:
        return ""
    summary = ("At the accuracy a grid usually gives, brute force is cheaper than the continuation, which wins where the maximum must be exact."
               if ratios[0] < 1.0 else "The continuation is the cheaper at every accuracy shown.")
    bumpers = d.attrs.get("screen") == "bumper_orbits"
    if same:
        how = ("the bumper screen (each period-1 bumper orbit shot along the scan, its maxima refined by a bounded search)" if bumpers
               else "the closed-form screen (each period-1 branch's maxima refined to 1e-8 by zoomed closed-form scans)")  # fmt: skip
        screen_part = f" The search's own objective, {how}, found the same maximum in {fmt(screen, '.2g')} s: {' and '.join(screen_ratios)}."
    elif math.isfinite(screen):
        screen_part = (f" The search's own objective, the {'bumper' if bumpers else 'closed-form'} screen, took {fmt(screen, '.2g')} s on this problem but did not find its worst case "
                       f"({q.text(screened)} against the certified {q.text(worst)}): it knows only period-1 motions.")  # fmt: skip
    else:
        screen_part = ""
    return (f"<p><b>What the exact worst case costs.</b> The continuation located the {design_titles(d)[0]}'s maximum in {fmt(continuation, '.3g')} s (to its "
            f"tolerance, ~1e-10). A stepped brute-force sweep (one direction, its measured cost per point) reaching the same maximum would need "
            f"{'; '.join(cells)}. {summary}{screen_part}</p>")  # fmt: skip


class DesignPage:
    """The page of a ``design`` dataset."""

    def __init__(self, dataset: xr.Dataset) -> None:
        self.dataset = dataset

    def summary(self) -> str:
        """What was computed, for the page's heading."""
        d = self.dataset
        return (f"{d.sizes['evaluation']} candidate designs ({str(d.attrs.get('search_method', '?')).replace('_', ' ')} over {d.attrs.get('variables', '?')}), each under "
                f"{d.sizes['sample']} mistuning samples (the nominal design included); {d.sizes['certificate']} problems certified by continuation")  # fmt: skip

    def sections(self, out: Path) -> list[Section]:
        """The answer and the warnings, the figures, the compared designs, how it was computed."""
        d = self.dataset
        items = "".join(f"<li>{html.escape(w)}</li>" for w in warnings(d))
        point = design_operating(d)
        before = "".join(f"<p><b>Warning.</b> {html.escape(line)}</p>" for line in operating_warnings(point))  # before the recommendation's praise
        refused = contradictions(d)
        if refused:  # a certificate that a stored motion exceeds is never printed as one
            answer = (f"<p><b>No answer: what this study stored contradicts the recommendation's stated numbers, so they are not stated.</b> {html.escape('; '.join(refused[:4]))}"
                      f"{f' (and {len(refused) - 4} more)' if len(refused) > 4 else ''}.</p>")  # fmt: skip
        else:
            answer = f"<p><b>{html.escape(answer_text(d))}</b></p>" + operating_sentence(point, never_strikes(d))
        first = Section("Which design to build", before + answer + (f"<p>{'Before you build a stop' if linear_wins(d) else 'Before you build it'}:</p><ul>{items}</ul>" if items else ""))
        drawn = design_figures(d)
        trade = front_text(d) if "pareto_front" in d else ""
        if trade:  # only where the screen knew impulses (closed forms), so the panel has data
            drawn.append(tradeoff_figure(d))
        figures = Section("Figures", f"<p>{html.escape(trade)}</p>" if trade else "", figures=saved(drawn, out))
        table = Section("The compared designs", "", tables=[Table("Worst cases of the compared designs", designs_table(d))])
        certificates = certificates_table(d)
        method = Section("How this was computed", method_text(d), tables=[Table("The certificates", certificates)] if certificates else [])
        return [first, figures, table, method]


def page_for(dataset: xr.Dataset) -> DesignPage:
    """The page of a design dataset."""
    return DesignPage(dataset)
