"""The page of a design map: which restitution ratio R and clearance Delta to choose for the absorber.

First the answer in words and numbers (:mod:`vibroimpact.kinds.stepped.design_ranking` chooses it), with the table of
the best candidates and how they are judged; then the peak |X1| maps per band, the realisable-regime map, and the
frequency response of the recommended design (:mod:`vibroimpact.kinds.stepped.design_figures`). Everything is read from
the dataset (a stepped study whose attribute ``report_page`` is ``design_map``).
"""

from __future__ import annotations

import html
import math
from pathlib import Path

import numpy as np
import xarray as xr

from vibroimpact.kinds.stepped.design_figures import BAND_TITLES, peak_maps_figure, regime_map_figure, response_figure
from vibroimpact.kinds.stepped.design_metrics import BAND_NAMES, DESIGN_REGIME_LABELS, DesignRegime
from vibroimpact.kinds.stepped.design_ranking import TIER_TEXT, Candidate, DesignMap, design_map
from vibroimpact.kinds.stepped.operating import OperatingRow, WORSE_RATIO, operating_point, unreached_text, warnings_html
from vibroimpact.reporting.page import Section, Table, saved
from vibroimpact.reporting.style import fmt, solution_ref
from vibroimpact.scene.schema import ENGINE_SOLUTIONS

__all__ = ["DesignMapPage", "operating_html", "recommendation_text", "candidates_table", "frequency_ranges", "TOP_CANDIDATES"]

#: Rows of the candidates' table.
TOP_CANDIDATES = 5
#: Columns of the candidates' table whose text wraps (worst motion, irregular frequencies), and their width [em].
_WRAPPED_COLUMNS = {8: 9, 10: 14}


def frequency_ranges(values: tuple[float, ...] | np.ndarray, grid: np.ndarray) -> str:
    """``values`` [Hz] as ranges of consecutive points of ``grid``, 4 significant digits: '21.5, 34.5-35, 37.5-38' ('none' if empty)."""
    if len(values) == 0:
        return "none"
    index = np.searchsorted(grid, np.asarray(values, dtype=float))
    parts, start = [], index[0]
    for previous, current in zip(index, [*index[1:], None]):
        if current is None or current != previous + 1:
            low, high = grid[start], grid[previous]
            parts.append(fmt(low, ".4g") if start == previous else f"{fmt(low, '.4g')}-{fmt(high, '.4g')}")
            start = current
    return ", ".join(parts)


def _mm(value: float, bound: bool = False) -> str:
    return ("≥ " if bound else "") + fmt(1e3 * value, "#.3g", "{} mm") if math.isfinite(value) else "n/a"


def _design_name(design: Candidate) -> str:
    return f"R = {fmt(design.restitution, 'g')}, Delta = {fmt(1e3 * design.clearance, '.4g')} mm"


def _coexisting(design: Candidate, band: str) -> str:
    """Where a band's peak is the closed form's stable state rather than the simulated one, say so."""
    if not design.peak_from_closed_form.get(band, False):
        return ""
    return ", the closed form's stable steady state, which coexists there with the motion the simulation settled on"


def recommendation_text(dm: DesignMap) -> str:
    """The answer in words and numbers (HTML paragraphs)."""
    total = len(dm.designs)
    source = f"solution {solution_ref(dm.solution)} on {dm.frequency.size} frequencies"
    reach = fmt(1e3 * dm.working_clearance, ".3g")
    working = dm.bands.describe("working", dm.frequency)
    if dm.recommendation is None:
        largest = max(d.clearance for d in dm.designs)
        return (f"<p><b>No design of the grid keeps the working band ({working}) free of impacts</b> ({source}). Without a stop the absorber's |X2| "
                f"reaches {reach} mm there; the largest clearance of the grid is {fmt(1e3 * largest, '.3g')} mm. Widen the clearance range.</p>")  # fmt: skip
    rec = dm.recommendation
    best = rec.design
    lines = [f"<p><b>Recommended: {html.escape(_design_name(best))}</b> ({source}). Its working band ({working}) is free of impacts: |X1| there stays "
             f"at most {_mm(best.peaks['working'])}, as without a stop. "]  # fmt: skip
    for band in ("lower", "upper"):
        bound = best.unknown_points[band] > 0
        lines.append(f"In the {BAND_TITLES[band]} the peak |X1| falls from {_mm(best.no_stop[band])} without a stop to {_mm(best.peaks[band], bound)} "
                     f"at {fmt(best.peak_frequencies[band], '.2f')} Hz{_coexisting(best, band)} ({'at most ' if bound else ''}{fmt(best.reduction_dB[band], '.1f')} dB less). ")  # fmt: skip
    lines.append(f"It impacts at {fmt(100 * best.impact_fraction, '.0f')} % of the frequencies; its motion is {html.escape(DESIGN_REGIME_LABELS[best.worst_regime])} at worst")
    if best.irregular_frequencies:
        lines.append(f" (irregular at {frequency_ranges(best.irregular_frequencies, dm.frequency)} Hz)")
    lines.append(".</p>")
    lines.append(f"<p>Of the {total} designs, {rec.eligible} keep the working band free of impacts. ")
    if rec.tier == 1:
        lines.append("None of those is free of irregular motion at every frequency, so the recommendation is the best of those whose motion is known at every frequency. ")
    elif rec.tier == 2:
        lines.append(f"<b>Provisional</b>: every such design has frequencies where {solution_ref(dm.solution)} leaves the motion unresolved or not computed, "
                     f"so its peaks may be lower bounds ({best.unresolved_points + best.missing_points} such frequencies for this one); a time-domain study ('exact') settles them. ")  # fmt: skip
    else:
        lines.append("The recommended design's motion is regular at every frequency. ")
    smallest = min((d for d in dm.ranked[: rec.tied]), key=lambda d: d.objective)
    if rec.tied > 1:
        lines.append(f"Among them ({TIER_TEXT[rec.tier]}) the smallest larger resonance peak is {_mm(smallest.objective)}, at {html.escape(_design_name(smallest))}; "
                     f"{rec.tied} designs are within {fmt(100 * rec.tie_tolerance, 'g')} % of it, and among such near-ties the larger clearance wins, then the lower R: "
                     f"this one, {_mm(best.objective)}.</p>")  # fmt: skip
    else:
        lines.append(f"Among them ({TIER_TEXT[rec.tier]}) it has the smallest larger resonance peak, {_mm(best.objective)}.</p>")
    lines.append(_clearance_text(dm, best))
    return "".join(lines)


def _clearance_text(dm: DesignMap, best: Candidate) -> str:
    """Why this clearance: the no-stop reach of |X2| in the working band, whether R matters, and the trend above."""
    reach = fmt(1e3 * dm.working_clearance, ".3g")
    text = [f"<p>Why this clearance: without a stop the absorber's |X2| reaches {reach} mm in the working band, so a smaller clearance lets it strike the stop "
            "there, and impacts spoil the anti-resonance"]  # fmt: skip
    spoiled = [d.peaks["working"] for d in dm.designs if not d.working_impact_free and math.isfinite(d.peaks["working"])]
    if spoiled:
        text.append(f" (|X1| in the working band then up to {_mm(max(spoiled))}, against {_mm(best.peaks['working'])})")
    text.append(". ")
    below = [d for d in dm.designs if d.working_impact_free and not d.clears_working_band]
    if below:
        text.append(f"{len(below)} designs are free of impacts on the grid's frequencies but their clearance is below {reach} mm, so they would strike between them: excluded. ")
    if dm.restitution_dependent.size:
        where = ", ".join(fmt(1e3 * c, ".3g") for c in dm.restitution_dependent)
        text.append(f"Whether the working band impacts depends on Delta alone except at Delta = {where} mm, where it depends on R (an impacting orbit coexists with the linear one there). ")
    else:
        text.append("Whether the working band impacts depends on Delta alone, as it should: every R agrees at each clearance. ")
    same_r = sorted((d for d in dm.designs if d.restitution == best.restitution and d.eligible and math.isfinite(d.objective)), key=lambda d: d.clearance)
    if len(same_r) > 1:
        first, last = same_r[0], same_r[-1]
        trend = "grows" if last.objective > first.objective else "falls"
        text.append(f"Above that, at R = {fmt(best.restitution, 'g')} the larger resonance peak {trend} with the clearance, from {_mm(first.objective)} at Delta = "
                    f"{fmt(1e3 * first.clearance, '.4g')} mm to {_mm(last.objective)} at {fmt(1e3 * last.clearance, '.4g')} mm")  # fmt: skip
        text.append(": the smallest clearance above the reach wins." if trend == "grows" else ".")
        margin = best.clearance / dm.working_clearance - 1.0
        wider = [d for d in same_r if d.clearance > best.clearance]
        if math.isfinite(margin):
            text.append(f" The recommended clearance is {fmt(100 * margin, '.0f')} % above the reach")
            if wider:
                cost = 20.0 * math.log10(wider[0].objective / best.objective)
                text.append(f"; the next clearance of the grid, {fmt(1e3 * wider[0].clearance, '.4g')} mm ({fmt(100 * (wider[0].clearance / dm.working_clearance - 1.0), '.0f')} % "
                            f"above), raises the larger resonance peak to {_mm(wider[0].objective)} ({fmt(cost, '+.1f')} dB): the price of a margin for manufacturing tolerance and wear")  # fmt: skip
            text.append(".")
    text.append("</p>")
    return "".join(text)


def _is(row: OperatingRow, design: Candidate) -> bool:
    """Is ``row`` the design's (same R and Delta, as the rows write them)?"""
    return set(row.where.split(", ")) == {f"R = {fmt(design.restitution, 'g')}", f"Delta = {fmt(1e3 * design.clearance, 'g')} mm"}


def operating_html(dataset: xr.Dataset, dm: DesignMap) -> tuple[str, str]:
    """The page's first lines, before the recommendation: a warning where no design reaches the stop, or where the
    recommended design makes |X1| at the operating point (the anti-resonance) worse than without a stop; and the
    paragraph beside the recommendation: |X1| there without a stop, with the recommended design, and how many designs
    make it worse (HTML, each empty where there is nothing to say; :mod:`vibroimpact.kinds.stepped.operating`)."""
    warnings = [unreached_text(dataset)]
    point = operating_point(dataset)
    if point is None:
        return warnings_html([w for w in warnings if w]), ""
    rows = [r for r in point.rows if r.solution == dm.solution]
    if not rows:
        return warnings_html([w for w in warnings if w]), f"<p>At the absorber's operating point, its anti-resonance {fmt(point.frequency, '.5g')} Hz, {solution_ref(dm.solution)} has no value: it lies off its grid.</p>"
    first = rows[0]
    chosen = [r for r in rows if dm.recommendation is not None and _is(r, dm.recommendation.design)]
    worse = sorted((r for r in rows if r.ratio > WORSE_RATIO), key=lambda r: -r.ratio)
    ratio = lambda r: fmt(r.ratio, ".3g", "×{}")  # noqa: E731
    if chosen and chosen[0].ratio > WORSE_RATIO:
        warnings.append(f"The recommended design makes the absorber worse at its operating point: at {fmt(first.frequency, '.4g')} Hz (anti-resonance {fmt(point.frequency, '.5g')} Hz) "
                        f"|X1| is {_mm(first.linear)} without a stop against {_mm(chosen[0].stopped)} with it, {ratio(chosen[0])}.")  # fmt: skip
    text = [f"At the absorber's operating point, its anti-resonance {fmt(point.frequency, '.5g')} Hz (sqrt(k2/m2) / 2 pi), |X1| without a stop is {_mm(first.linear)} "
            f"at the grid's nearest frequency {fmt(first.frequency, '.4g')} Hz"]  # fmt: skip
    if chosen:
        text.append(f"; with the recommended design {_mm(chosen[0].stopped)} ({ratio(chosen[0])})" if math.isfinite(chosen[0].stopped) else "; the recommended design has no realisable value there")
    if worse:
        text.append(f"; {len(worse)} of the {len(rows)} designs make it worse (up to {_mm(worse[0].stopped)}, {ratio(worse[0])}, at {html.escape(worse[0].where)}): a clearance below the absorber's free motion there strikes the stop at the notch")
    else:
        text.append(f"; no design of the {len(rows)} makes it worse")
    return warnings_html([w for w in warnings if w]), f"<p>{''.join(text)}.</p>"


def candidates_table(dm: DesignMap) -> str:
    """The best :data:`TOP_CANDIDATES` eligible designs (the recommended one marked) and the absorber without a stop."""
    wrap = "style='white-space:normal'"
    head = ["rank", "R", "Delta [mm]", *(f"peak |X1|, {BAND_TITLES[b]} [mm]" for b in BAND_NAMES), "larger resonance peak [mm]",
            "change, lower / upper [dB]", "worst motion", "frequencies with impacts [%]", "irregular at [Hz]", "unknown points lower / working / upper"]  # fmt: skip
    rows = [f"<table><tr>{''.join(f'<th {wrap}>{html.escape(h)}</th>' for h in head)}</tr>"]
    recommended = dm.recommendation.design if dm.recommendation is not None else None
    simulated = dm.solution in ENGINE_SOLUTIONS
    for rank, design in enumerate(dm.ranked[:TOP_CANDIDATES], start=1):
        peaks = [_peak_cell(design, b) for b in BAND_NAMES]
        change = " / ".join(("≥ " if design.unknown_points[b] else "") + (fmt(-design.reduction_dB[b], "+.1f") or "n/a") for b in ("lower", "upper"))
        larger = ("≥ " if design.bounds_only else "") + (fmt(1e3 * design.objective, ".3g") or "n/a")
        irregular = frequency_ranges(design.irregular_frequencies, dm.frequency) if simulated else "not seen by a closed form"
        cells = [str(rank), fmt(design.restitution, "g"), fmt(1e3 * design.clearance, ".4g"), *peaks, larger, change,
                 html.escape(DESIGN_REGIME_LABELS[design.worst_regime]), fmt(100 * design.impact_fraction, ".0f"),
                 irregular, " / ".join(str(design.unknown_points[b]) for b in BAND_NAMES)]  # fmt: skip
        if design is recommended:
            cells[0] = f"<b>★ {cells[0]}</b>"
            cells[1:3] = [f"<b>{c}</b>" for c in cells[1:3]]
        rows.append("<tr>" + "".join(_cell(c, k) for k, c in enumerate(cells)) + "</tr>")
    no_stop = [f"{fmt(1e3 * dm.no_stop[b].value, '.3g')}<br><small>at {fmt(dm.no_stop[b].frequency, '.2f')} Hz</small>" for b in BAND_NAMES]
    larger = fmt(1e3 * max(dm.no_stop[b].value for b in ("lower", "upper")), ".3g")
    rows.append(f"<tr><td>no stop</td><td></td><td>∞</td>{''.join(f'<td>{c}</td>' for c in no_stop)}<td>{larger}</td><td>0 / 0</td><td>no impact</td><td>0</td><td>none</td><td></td></tr>")
    if not dm.ranked:
        rows.append(f"<tr><td colspan='{len(head)}'>no design keeps the working band free of impacts</td></tr>")
    rows.append("</table>")
    return "".join(rows)


def _cell(text: str, column: int) -> str:
    """A table cell; the columns of :data:`_WRAPPED_COLUMNS` wrap within their width."""
    if column in _WRAPPED_COLUMNS:
        width = _WRAPPED_COLUMNS[column]
        return f"<td style='white-space:normal;min-width:{width}em;max-width:{width + 4}em;text-align:left'>{text}</td>"
    return f"<td>{text}</td>"


def _peak_cell(design: Candidate, band: str) -> str:
    value = design.peaks[band]
    if not math.isfinite(value):
        return "n/a"
    bound = "≥ " if design.unknown_points[band] else ""
    mark = "†" if design.peak_from_closed_form.get(band, False) else ""
    return f"{bound}{fmt(1e3 * value, '.3g')}{mark}<br><small>at {fmt(design.peak_frequencies[band], '.2f')} Hz</small>"


def _definitions(dm: DesignMap) -> str:
    """How the designs are judged (HTML)."""
    bands = dm.bands
    f1, f2 = bands.natural_Hz
    order = " &lt; ".join(html.escape(DESIGN_REGIME_LABELS[k]) for k in DesignRegime)
    companion = (" and, since a simulation settles on one attractor, the closed form 'pgf''s stable state at the same frequency where it is larger "
                 "(the linear motion where it fits, or a stable one-impact orbit: coexisting steady states; † in the table)") if any(
        d.peak_from_closed_form.get(b, False) for d in dm.designs for b in BAND_NAMES) else ""  # fmt: skip
    return (
        f"<p><b>Bands</b>, from the natural frequencies f1 = {fmt(f1, '.2f')} Hz, f2 = {fmt(f2, '.2f')} Hz and the anti-resonance fa = {fmt(bands.antiresonance_Hz, '.2f')} Hz: "
        f"lower resonance band f &lt; (f1 + fa)/2 ({bands.describe('lower', dm.frequency)}); upper resonance band f &gt; (fa + f2)/2 ({bands.describe('upper', dm.frequency)}); "
        f"working band |f - fa| &le; {fmt(100 * bands.working_fraction, 'g')} % of fa ({bands.describe('working', dm.frequency)}). "
        f"<b>Peak |X1|</b>: the largest fundamental amplitude of the primary mass in the band over the motion that is realised "
        f"(no impact, a stable one-impact orbit, other periodic motion, irregular motion averaged over the measured periods), from {solution_ref(dm.solution)}"
        f"{companion}; "
        "an unstable orbit's value never counts, and a frequency without a realised value is counted ('unknown points'), its peak then a lower bound (≥). "
        "<b>Change</b>: 20 log10(peak / no-stop peak), negative where the stop lowers it; the no-stop resonance peaks are analytic, the working band's on the same grid. "
        f"<b>Worst motion</b>, in the order {order}. <b>Eligible</b>: no frequency of the working band impacts, none unknown, and Delta at least the no-stop "
        f"|X2| anywhere in the band ({fmt(1e3 * dm.working_clearance, '.3g')} mm). <b>Choice</b>: the eligible designs in tiers (regular motion everywhere; "
        "else irregular somewhere, every point known; else some unresolved), in the first non-empty tier the smallest larger resonance peak; designs within "
        "the tie tolerance of it are near-ties, of which the largest clearance (fewer and softer impacts, looser tolerances) and then the lowest R (a lossier, "
        "easier stop) is chosen. The table ranks the eligible designs that way.</p>"
    )


class DesignMapPage:
    """The page of a stepped design-map dataset (``report_page`` = ``design_map``)."""

    def __init__(self, dataset: xr.Dataset) -> None:
        self.dataset = dataset
        self.map = design_map(dataset)

    def summary(self) -> str:
        """Grid, solutions and the recommendation in one line."""
        d, dm = self.dataset, self.map
        solutions = ", ".join(str(s) for s in d["solution"].values)
        grid = f"design map over {d.sizes.get('restitution', 1)} restitution ratios x {d.sizes.get('clearance', 1)} clearances x {d.sizes['frequency']} frequencies"
        verdict = f"recommended {_design_name(dm.recommendation.design)}" if dm.recommendation is not None else "no design keeps the working band free of impacts"
        return f"{grid}; solutions: {solutions}; designs judged on {solution_ref(dm.solution)}; {verdict}"

    def sections(self, out: Path) -> list[Section]:
        """The answer with its table and definitions, then the maps and the recommended design's response."""
        dm = self.map
        peaks, regimes, *response = saved([peak_maps_figure(dm), regime_map_figure(dm), response_figure(self.dataset, dm)], out)
        first, operating = operating_html(self.dataset, dm)
        answer = Section("Which restitution and clearance", first + recommendation_text(dm) + operating, tables=[Table("Best candidate designs", candidates_table(dm) + _definitions(dm))])
        return [
            answer,
            Section("Peak |X1| per band over the designs", figures=[peaks]),
            Section("Realisable motion over the designs", figures=[regimes]),
            Section("The recommended design against frequency", figures=response) if response else Section("The recommended design against frequency", "<p>No design to show.</p>"),
        ]
