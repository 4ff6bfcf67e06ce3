"""Report page of bifurcation studies: the answer, bifurcation diagrams with brute force and continued branches, the
special points, the Floquet multipliers along the branches, and the two-parameter chart with its regime map (the
figures: :mod:`vibroimpact.kinds.bifurcation.figures`).

Dataset layout read here: see :mod:`vibroimpact.kinds.bifurcation.study` (``branch_point``, ``special_point``, the
``brute_*`` variables over (restitution, sweep, frequency, ...), ``chart_point`` and ``chart_regime``).
"""

from __future__ import annotations

import html
import math
import re
from pathlib import Path

import numpy as np
import xarray as xr

from vibroimpact.reporting.page import Section, Table, saved
from vibroimpact.reporting.style import fmt
from vibroimpact.runs.failures import as_lines
from vibroimpact.kinds.bifurcation.bumper import absent_text, bumper_answer, bumper_figure, convergence_table, diagram_models, has_bumpers, has_rigid, model_view
from vibroimpact.kinds.bifurcation.figures import KIND_NAMES, bifurcation_figures, branch_class, first_coordinate, flags as _flags, length_of, orbit_class, orbit_label as _orbit_label
from vibroimpact.kinds.bifurcation.scene import coordinate_label
from vibroimpact.kinds.bifurcation.seed_report import slow_seed_text

__all__ = ["page_for", "BifurcationPage", "bifurcation_figures", "special_point_table", "orbit_class", "first_coordinate", "headline", "answer_text", "failure_text", "failure_details"]


#: The brute-force classes that are no periodic motion.
_NON_PERIODIC = ("quasi_periodic", "chaotic", "irregular")


def _ranges(values: np.ndarray, step: float) -> str:
    """Sorted frequencies [Hz] as ranges ``a-b`` (a gap wider than 1.5 ``step`` starts a new one), at most four."""
    if values.size == 0:
        return ""
    values = np.sort(values)
    breaks = np.flatnonzero(np.diff(values) > 1.5 * step)
    starts, ends = np.r_[values[0], values[breaks + 1]], np.r_[values[breaks], values[-1]]
    parts = [f"{fmt(a, '.2f')}-{fmt(b, '.2f')}" if b > a else fmt(a, ".2f") for a, b in zip(starts, ends)]
    return ", ".join(parts[:4]) + (f" and {len(parts) - 4} more" if len(parts) > 4 else "") + " Hz"


def _brute_facts(dataset: xr.Dataset, index: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Of the brute force at restitution ``index``: the largest amplitude of the first coordinate per (sweep,
    frequency) [m], the regime flags per (sweep, frequency), and where either sweep settles on no periodic motion."""
    brute = dataset.isel(restitution=index)
    amplitude = np.nanmax(brute[f"brute_{first_coordinate(dataset)}_amplitude"].values, axis=-1)
    regime = brute["brute_regime"].values
    meanings = _flags(dataset["brute_regime"])
    codes = [meanings.index(m) - 1 for m in _NON_PERIODIC if m in meanings]
    return amplitude, regime, np.isin(regime, codes).any(axis=0)


def headline(dataset: xr.Dataset) -> str:
    """The answer in one line per restitution: the largest amplitude the brute force settles on, and at how many
    frequencies it settles on no periodic motion."""
    label = coordinate_label(first_coordinate(dataset))
    unit, scale = length_of(dataset)
    frequency = dataset["frequency"].values
    lines = []
    for i, r in enumerate(dataset["restitution"].values):
        amplitude, _regime, wild = _brute_facts(dataset, i)
        top = ""
        if np.isfinite(amplitude).any():
            _j, k = np.unravel_index(int(np.nanargmax(amplitude)), amplitude.shape)
            top = f"up to |{label}| = {fmt(amplitude[_j, k] * scale, '.3g')} {unit} (at {fmt(frequency[k], '.2f')} Hz), "
        lines.append(f"R = {fmt(r, 'g')}: {top}no periodic motion at {int(wild.sum())} of {frequency.size} frequencies")
    return "; ".join(lines)


#: Table cells of text, which may wrap (the global style keeps cells on one line, right-aligned).
_TEXT = "white-space:normal;text-align:left"
#: ... with a minimum width that keeps them readable [em].
_WRAP = _TEXT + ";min-width:{}em"
#: The kinds of special point where a branch's stability changes (columns of the orbits' table).
STABILITY_KINDS = ("fold", "period_doubling", "neimark_sacker")


def _bands(dataset: xr.Dataset, chosen: np.ndarray) -> list[tuple[float, float]]:
    """The frequency bands [Hz] of the chosen branch points: each branch's runs of consecutive chosen points, merged
    where they overlap."""
    bands: list[list[float]] = []
    branch, f = dataset["branch"].values, dataset["branch_frequency"].values
    for label in np.unique(branch[chosen]):
        index = np.flatnonzero(branch == label)
        runs = np.split(index, np.flatnonzero(~chosen[index][1:] | ~chosen[index][:-1]) + 1)
        bands += [[float(f[run].min()), float(f[run].max())] for run in runs if run.size and chosen[run].all()]
    merged: list[list[float]] = []
    for low, high in sorted(bands):
        if merged and low <= merged[-1][1]:
            merged[-1][1] = max(merged[-1][1], high)
        else:
            merged.append([low, high])
    return [(a, b) for a, b in merged]


def _band_text(bands: list[tuple[float, float]], most: int = 4) -> str:
    """Bands as ``a-b, c-d and 2 more`` [Hz] (a band of one point as ``a``), without the unit; empty for none."""
    parts = [f"{fmt(a, '.2f')}-{fmt(b, '.2f')}" if b - a >= 0.005 else fmt(a, ".2f") for a, b in bands]
    return ", ".join(parts[:most]) + (f" and {len(parts) - most} more" if len(parts) > most else "")


def _at(values: np.ndarray, most: int = 4) -> str:
    """Frequencies [Hz] as ``21.21, 26.58``, in order, at most ``most`` and how many more; without the unit."""
    parts = [fmt(f, ".2f") for f in np.sort(values)]
    return ", ".join(parts[:most]) + (f" and {len(parts) - most} more" if len(parts) > most else "")


def _branch_classes(dataset: xr.Dataset) -> np.ndarray:
    """The class of each branch point's branch (:func:`branch_class`), shape (branch_point, 2)."""
    out = np.zeros((dataset.sizes["branch_point"], 2), dtype=int)
    labels = dataset["branch"].values
    for label in np.unique(labels):
        mask = labels == label
        out[mask] = branch_class(dataset["impacts_per_period"].values[mask], dataset["period_multiplicity"].values[mask])
    return out


def orbit_rows(dataset: xr.Dataset, restitution: float) -> list[dict[str, object]]:
    """Every class of periodic orbit continued at one restitution, in order of period and impacts: its name, branches,
    the bands [Hz] where it exists and where it is stable, and the frequencies [Hz] of its special points by kind (each
    at the class of the branch it was found on; not those a contact onset induces: the special points' table lists
    them with their onset)."""
    at_r = np.isclose(dataset["branch_restitution"].values, restitution)
    classes = _branch_classes(dataset)
    kinds = _flags(dataset["special_point_kind"])
    branch_of = {int(b): tuple(c) for b, c in zip(dataset["branch"].values, classes)}
    sp_at_r = np.isclose(dataset["special_point_restitution"].values, restitution)
    if "special_point_induced_by" in dataset:  # a point an onset induces is the onset's (its grazing note), not one more
        sp_at_r &= ~np.isfinite(dataset["special_point_induced_by"].values)
    rows = []
    for key in sorted({tuple(c) for c in classes[at_r]}, key=lambda k: (k[1], k[0])):
        chosen = at_r & (classes == key).all(axis=1)
        points = np.array([branch_of.get(int(b)) == key for b in dataset["special_point_branch"].values], dtype=bool) & sp_at_r
        special = {kind: dataset["special_point_frequency"].values[points & (dataset["special_point_kind"].values == code)] for code, kind in enumerate(kinds)}
        rows.append({
            "key": key, "name": _orbit_label(key), "branches": np.unique(dataset["branch"].values[chosen]).tolist(),
            "exists": _bands(dataset, chosen), "stable": _bands(dataset, chosen & (dataset["stable"].values == 1)), "special": special,
        })  # fmt: skip
    return rows


def orbit_table(dataset: xr.Dataset, restitution: float) -> str:
    """The orbits of one restitution (:func:`orbit_rows`) as an HTML table: where each exists, where it is stable,
    where it folds and where its stability changes otherwise [Hz]."""
    head = ["orbit", "branches", "exists over [Hz]", "stable over [Hz]", "folds at [Hz]", "period doublings at [Hz]", "Neimark-Sacker points at [Hz]"]
    body = []
    for row in orbit_rows(dataset, restitution):
        special = row["special"]
        cells = [row["name"], ", ".join(map(str, row["branches"])), _band_text(row["exists"], 6), _band_text(row["stable"], 6) or "nowhere",
                 *(_at(special.get(k, np.zeros(0)), 6) for k in STABILITY_KINDS)]  # fmt: skip
        body.append("<tr>" + "".join(f"<td style='{_WRAP.format(10) if n == 0 else _TEXT}'>{html.escape(c)}</td>" for n, c in enumerate(cells)) + "</tr>")
    caption = f"<caption style='{_TEXT};caption-side:top'>Every kind of periodic orbit continued at R = {fmt(restitution, 'g')}</caption>"
    header = "".join(f"<th style='{_TEXT}'>{h}</th>" for h in head)
    return f"<table>{caption}<tr>{header}</tr>{''.join(body)}</table>"


def _main_orbit(dataset: xr.Dataset, restitution: float, rows: list[dict[str, object]]) -> str:
    """The closed-form orbit's class of one restitution in a sentence: where it exists, where it is stable, where it
    folds and where its stability changes otherwise; the other classes counted."""
    origins = _flags(dataset["branch_origin"])
    closed = [origins.index(k) for k in ("one_impact", "two_impacts") if k in origins]
    at_r = np.isclose(dataset["branch_restitution"].values, restitution) & np.isin(dataset["branch_origin"].values, closed)
    impacting = [row for row in rows if row["key"][0]]
    if not at_r.any():
        return f"no branch from the closed form; {len(impacting)} kind{'s' if len(impacting) != 1 else ''} of impacting periodic orbit (table below);"
    key = tuple(_branch_classes(dataset)[np.flatnonzero(at_r)[0]])
    row = next(r for r in rows if r["key"] == key)
    special = row["special"]
    words = f"the closed-form orbit ({row['name']}) exists over {_band_text(row['exists'])} Hz and is " + (f"stable over {_band_text(row['stable'])} Hz" if row["stable"] else "nowhere stable")
    changes = [f"{KIND_NAMES[k]} at {_at(special[k])} Hz" for k in STABILITY_KINDS if special.get(k, np.zeros(0)).size]
    others = len(impacting) - 1
    return f"{words}{' (' + '; '.join(changes) + ')' if changes else ''}; {others} other kind{'s' if others != 1 else ''} of impacting periodic orbit (table below);"


def answer_text(dataset: xr.Dataset) -> str:
    """The answer, per restitution: the closed-form orbit (where it exists, is stable, folds and changes stability,
    in Hz), how many other kinds of periodic orbit (:func:`orbit_table`), what the brute force settles on (its largest
    amplitude, where on no periodic motion, where the two sweeps disagree: coexisting attractors), how many special
    points."""
    label = coordinate_label(first_coordinate(dataset))
    unit, scale = length_of(dataset)
    meanings = _flags(dataset["brute_regime"])
    frequency = dataset["frequency"].values
    step = float(np.median(np.diff(frequency))) if frequency.size > 1 else 1.0
    kinds = _flags(dataset["special_point_kind"])
    parts = []
    for i, r in enumerate(dataset["restitution"].values):
        amplitude, regime, wild = _brute_facts(dataset, i)
        words = [f"<b>R = {fmt(r, 'g')}</b>:", html.escape(_main_orbit(dataset, float(r), orbit_rows(dataset, float(r))))]
        if np.isfinite(amplitude).any():
            j, k = np.unravel_index(int(np.nanargmax(amplitude)), amplitude.shape)
            kind = meanings[int(regime[j, k]) + 1].replace("_", " ")
            words.append(f"the brute force settles at most on |{label}| = {fmt(amplitude[j, k] * scale, '.3g')} {unit} ({fmt(frequency[k], '.2f')} Hz, "
                         f"sweeping {dataset['sweep'].values[j]}: {kind});")  # fmt: skip
        words.append(f"no periodic motion at {int(wild.sum())} of {frequency.size} frequencies{' (' + _ranges(frequency[wild], step) + ')' if wild.any() else ''};")
        if regime.shape[0] > 1:
            scale = np.nanmax(amplitude) if np.isfinite(amplitude).any() else 1.0
            differ = (regime != regime[:1]).any(axis=0) | (np.abs(np.nan_to_num(amplitude - amplitude[:1])) > 0.05 * scale).any(axis=0)
            words.append(f"the sweeps settle on different motions (coexisting attractors) at {int(differ.sum())} frequencies"
                         f"{' (' + _ranges(frequency[differ], step) + ')' if differ.any() else ''};")  # fmt: skip
        mask = np.isclose(dataset["special_point_restitution"].values, r)
        counts = [f"{int(np.count_nonzero(dataset['special_point_kind'].values[mask] == code))} {KIND_NAMES.get(kind, kind)}" for code, kind in enumerate(kinds)]
        words.append(f"special points: {', '.join(counts)}.")
        parts.append("<p>" + " ".join(words) + "</p>")
    return "".join(parts)


def failure_text(dataset: xr.Dataset) -> str:
    """What failed in the run (``run_failures``: what, how many, what it means for the results), as HTML; empty when
    nothing did."""
    lines = as_lines(dataset.attrs.get("run_failures"))
    if not lines:
        return ""
    items = "".join(f"<li>{html.escape(line)}</li>" for line in lines)
    return f"<p><b>What failed in this run</b> (each line says what it means for the results; the raw messages are at the end of the page):</p><ul>{items}</ul>"


def failure_details(dataset: xr.Dataset) -> str:
    """The raw messages of what failed (``run_failure_details``), collapsed; empty when nothing failed."""
    details = as_lines(dataset.attrs.get("run_failure_details"))
    if not details:
        return ""
    return f"<details><summary>The raw messages of what failed ({len(details)})</summary><pre>{html.escape(chr(10).join(details))}</pre></details>"


def _found_on(point: xr.Dataset) -> str:
    """The branches a special point was found on, ``3, 7`` (its own branch where the dataset lists no others)."""
    if "special_point_branches" in point:
        return ", ".join(str(point["special_point_branches"].values).split())
    return str(int(point["special_point_branch"]))


def _multipliers(mu: np.ndarray) -> str:
    """Floquet multipliers in a few characters each: a complex pair once, ``0.739±0.655i``; real ones to 4 digits."""
    parts = []
    for m in mu:
        if abs(m.imag) <= 1e-9 * max(abs(m), 1e-300):
            parts.append(fmt(m.real, ".4g"))
        elif m.imag > 0:
            parts.append(f"{fmt(m.real, '.3f')}±{fmt(m.imag, '.3f')}i")
    return ", ".join(parts)




def special_point_table(dataset: xr.Dataset) -> Table:
    """Every located special point, once (in order of R and frequency): kind, frequency, R, the branches it was found
    on, the orbit there, its largest multiplier modulus and multipliers, and what happens there; fits a 1400 px page
    (the multipliers and the note wrap)."""
    kinds = _flags(dataset["special_point_kind"])
    rows = []
    order = np.lexsort((dataset["special_point_frequency"].values, dataset["special_point_restitution"].values))
    for k in order:
        point = dataset.isel(special_point=int(k))
        mu = point["special_point_multiplier_real"].values + 1j * point["special_point_multiplier_imag"].values
        key = orbit_class(float(point["special_point_impacts_per_period"]), int(point["special_point_period_multiplicity"]))
        kind = kinds[int(point["special_point_kind"])]
        cells = [
            (KIND_NAMES.get(kind, kind), ""), (fmt(float(point["special_point_frequency"]), ".4f"), ""), (fmt(float(point["special_point_restitution"]), "g"), ""),
            (_found_on(point), ""), (_orbit_label(key), _WRAP.format(8)), (fmt(float(point["special_point_floquet_modulus"]), ".4g"), ""),
            (_multipliers(mu), _WRAP.format(11)), (str(point["special_point_note"].values), _WRAP.format(18)),
        ]  # fmt: skip
        rows.append("<tr>" + "".join(f"<td style='{style}'>{html.escape(c)}</td>" if style else f"<td>{html.escape(c)}</td>" for c, style in cells) + "</tr>")
    heads = ("kind", "frequency [Hz]", "R", "branches", "orbit", "max |mu|", "Floquet multipliers (a complex pair once)", "what happens there")
    header = "".join(f"<th style='{_TEXT}'>{h}</th>" if h in ("orbit", "Floquet multipliers (a complex pair once)", "what happens there") else f"<th>{h}</th>" for h in heads)
    return Table("Special points", f"<table><tr>{header}</tr>{''.join(rows)}</table>")


class BifurcationPage:
    """The page of a bifurcation study's dataset."""

    #: It says the run's failures itself, after its answer's paragraphs and before its tables (write_report does not).
    states_failures = True

    def __init__(self, dataset: xr.Dataset) -> None:
        self.full = dataset
        self.bumpers = has_bumpers(dataset)
        self.reference = not self.bumpers or has_rigid(dataset)
        #: every diagram, shaped as a rigid scene's dataset: the bumpers' by frequency, then the rigid stop's
        self.views = [model_view(dataset, fb) for fb in diagram_models(dataset)] if self.bumpers else [dataset]
        self.dataset = self.views[-1]  # the rigid stop's where it ran (its chart, its logs: the attributes are shared)

    def summary(self) -> str:
        """The answer (:func:`headline` per diagram; with the rigid stop as the bumpers' reference, how their special
        points converge first), then what was computed."""
        d = self.dataset
        stops = f"; stops: {d.attrs['stop_layout']}" if "stop_layout" in d.attrs else ""
        first = ""
        if self.bumpers and self.reference:
            first = html.unescape(re.sub(r"<[^>]+>", "", bumper_answer(self.full))) + " "
        if not self.bumpers:
            return (f"{first}{headline(d)}; {int(np.unique(d['branch'].values).size)} branches, {d.sizes['special_point']} special points, brute force at "
                    f"{d.sizes['frequency']} frequencies x {d.sizes['sweep']} directions for R = {', '.join(fmt(r, 'g') for r in d['restitution'].values)}{stops}")  # fmt: skip
        each = "; ".join(f"{view.attrs['diagram_label']}: {headline(view)}" for view in self.views)
        return (f"{first}{each}; {int(np.unique(self.full['branch'].values).size)} branches, {self.full.sizes['special_point']} special points, brute force of "
                f"each diagram at {d.sizes['frequency']} frequencies x {d.sizes['sweep']} directions for R = {', '.join(fmt(r, 'g') for r in d['restitution'].values)}{stops}")  # fmt: skip

    def sections(self, out: Path) -> list[Section]:
        """The answer (and what failed, if anything did) with the diagrams, multipliers and special points per
        restitution (per contact model with bumpers: the bumpers', then the rigid stop's as their reference), then the
        chart, then the continuation's logs and the raw messages of what failed, collapsed (what a reader checks, not
        what they read first)."""
        sections = []
        for n, view in enumerate(self.views):
            figures = saved(bifurcation_figures(view), out)
            chart = [f for f in figures if f.path.stem == "chart"]
            tables = "".join(orbit_table(view, float(r)) for r in view["restitution"].values)
            seeded = slow_seed_text(view) if not self.bumpers or math.isinf(diagram_models(self.full)[n]) else ""  # the rigid stop's brute force only
            answer = answer_text(view) + ("" if self.bumpers else failure_text(view)) + seeded + tables  # what failed right after the answer
            title = "Bifurcation diagrams" + (f": {view.attrs['diagram_label']}" + (", the reference" if math.isinf(diagram_models(self.full)[n]) else "") if self.bumpers else "")
            sections.append(Section(title, answer, [f for f in figures if f not in chart], [special_point_table(view)]))
            if chart:
                sections.append(Section("Two-parameter chart", "", chart))
        if self.bumpers:  # the page opens with what failed, then the bumpers' answer
            words = failure_text(self.full) + absent_text(self.full)
            if self.reference:
                words += bumper_answer(self.full) + "<p>The bumpers' bifurcation diagrams, brute force and special points follow below, then the rigid stop's, the reference.</p>"
                sections.insert(0, Section("Bumpers against the rigid stop", words, saved([bumper_figure(self.full)], out), [convergence_table(self.full)]))
            else:
                sections[0] = Section(sections[0].title, words + sections[0].intro, sections[0].figures, sections[0].tables)
        logs = [
            (title, str(self.dataset.attrs.get(key, "")))
            for key, title in (("continuation_notes", "Every branch found by continuation: how it was started and where it ends"), ("chart_notes", "The chart's curves: how each was traced"))
        ]
        shown = "".join(
            f"<details><summary>{html.escape(title)} ({len(text.splitlines())} lines)</summary><pre>{html.escape(text)}</pre></details>" for title, text in logs if text
        )
        if shown:
            sections.append(Section("Continuation logs", shown))
        if failure_details(self.dataset):
            sections.append(Section("What failed, in detail", failure_details(self.dataset)))
        return sections


def page_for(dataset: xr.Dataset) -> BifurcationPage:
    """The page of a bifurcation dataset."""
    return BifurcationPage(dataset)
