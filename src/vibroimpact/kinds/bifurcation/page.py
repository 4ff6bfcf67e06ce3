"""Report page of bifurcation studies: the answer, bifurcation diagrams with brute force and continued branches, the
special points, the Floquet multipliers along the branches, and the two-parameter chart with its regime map (the
figures: :mod:`vibroimpact.kinds.bifurcation.figures`).

Dataset layout read here: see :mod:`vibroimpact.kinds.bifurcation.study` (``branch_point``, ``special_point``, the
``brute_*`` variables over (restitution, sweep, frequency, ...), ``chart_point`` and ``chart_regime``).
"""

from __future__ import annotations

import html
from pathlib import Path

import numpy as np
import xarray as xr

from vibroimpact.reporting.page import Section, Table, saved
from vibroimpact.reporting.style import fmt
from vibroimpact.kinds.bifurcation.figures import bifurcation_figures, first_coordinate, flags as _flags, orbit_class, orbit_colours, orbit_label as _orbit_label
from vibroimpact.kinds.bifurcation.scene import coordinate_label

__all__ = ["page_for", "BifurcationPage", "bifurcation_figures", "special_point_table", "orbit_class", "orbit_colours", "first_coordinate", "headline", "answer_text", "failure_text", "failure_details"]


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
    frequency = dataset["frequency"].values
    lines = []
    for i, r in enumerate(dataset["restitution"].values):
        amplitude, _regime, wild = _brute_facts(dataset, i)
        top = ""
        if np.isfinite(amplitude).any():
            _j, k = np.unravel_index(int(np.nanargmax(amplitude)), amplitude.shape)
            top = f"up to |{label}| = {fmt(amplitude[_j, k] * 1e3, '.3g')} mm (at {fmt(frequency[k], '.2f')} Hz), "
        lines.append(f"R = {fmt(r, 'g')}: {top}no periodic motion at {int(wild.sum())} of {frequency.size} frequencies")
    return "; ".join(lines)


def answer_text(dataset: xr.Dataset) -> str:
    """What the motion is, per restitution, in a few sentences: the largest amplitude the brute force settles on, where
    it settles on no periodic motion, where the two sweeps disagree (coexisting attractors), where the closed-form
    orbit is stable, and how many special points were located."""
    label = coordinate_label(first_coordinate(dataset))
    meanings = _flags(dataset["brute_regime"])
    frequency = dataset["frequency"].values
    step = float(np.median(np.diff(frequency))) if frequency.size > 1 else 1.0
    origins = _flags(dataset["branch_origin"])
    closed = [origins.index(k) for k in ("one_impact", "two_impacts") if k in origins]
    kinds = _flags(dataset["special_point_kind"])
    paragraphs = []
    for i, r in enumerate(dataset["restitution"].values):
        amplitude, regime, wild = _brute_facts(dataset, i)
        words = [f"<b>R = {fmt(r, 'g')}</b>:"]
        if np.isfinite(amplitude).any():
            j, k = np.unravel_index(int(np.nanargmax(amplitude)), amplitude.shape)
            kind = meanings[int(regime[j, k]) + 1].replace("_", " ")
            words.append(f"the brute force settles at most on |{label}| = {fmt(amplitude[j, k] * 1e3, '.3g')} mm ({fmt(frequency[k], '.2f')} Hz, "
                         f"sweeping {dataset['sweep'].values[j]}: {kind});")  # fmt: skip
        words.append(f"no periodic motion at {int(wild.sum())} of {frequency.size} frequencies{' (' + _ranges(frequency[wild], step) + ')' if wild.any() else ''};")
        if regime.shape[0] > 1:
            scale = np.nanmax(amplitude) if np.isfinite(amplitude).any() else 1.0
            differ = (regime != regime[:1]).any(axis=0) | (np.abs(np.nan_to_num(amplitude - amplitude[:1])) > 0.05 * scale).any(axis=0)
            words.append(f"the sweeps settle on different motions (coexisting attractors) at {int(differ.sum())} frequencies"
                         f"{' (' + _ranges(frequency[differ], step) + ')' if differ.any() else ''};")  # fmt: skip
        on_branch = np.isclose(dataset["branch_restitution"].values, r) & np.isin(dataset["branch_origin"].values, closed) & (dataset["stable"].values == 1)
        if on_branch.any():
            words.append(f"the closed-form orbit is stable over {_stable_bands(dataset, on_branch)};")
        elif not np.isin(dataset["branch_origin"].values[np.isclose(dataset["branch_restitution"].values, r)], closed).any():
            words.append("no branch from the closed form;")
        else:
            words.append("the closed-form orbit is nowhere stable;")
        mask = np.isclose(dataset["special_point_restitution"].values, r)
        counts = [f"{int(np.count_nonzero(dataset['special_point_kind'].values[mask] == code))} {kind.replace('_', '-')}" for code, kind in enumerate(kinds)]
        words.append(f"special points: {', '.join(counts)}.")
        paragraphs.append("<p>" + " ".join(words) + "</p>")
    return "".join(paragraphs)


def _stable_bands(dataset: xr.Dataset, chosen: np.ndarray) -> str:
    """The frequency bands [Hz] over which the chosen branch points are stable: each branch's runs of consecutive
    stable points, merged where they overlap."""
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
    parts = [f"{fmt(a, '.2f')}-{fmt(b, '.2f')}" for a, b in merged]
    return ", ".join(parts[:4]) + (f" and {len(parts) - 4} more" if len(parts) > 4 else "") + " Hz"


def _lines(dataset: xr.Dataset, key: str) -> list[str]:
    """A list-of-strings attribute as a list (netCDF gives one string back as a string), empty when absent."""
    value = dataset.attrs.get(key)
    if value is None:
        return []
    return [value] if isinstance(value, str) else [str(v) for v in np.atleast_1d(value)]


def failure_text(dataset: xr.Dataset) -> str:
    """What failed in the run (``run_failures``: what, how many, what it means for the results), as HTML; empty when
    nothing did."""
    lines = _lines(dataset, "run_failures")
    if not lines:
        return ""
    items = "".join(f"<li>{html.escape(line)}</li>" for line in lines)
    return f"<p><b>What failed in this run</b> (each line says what it means for the results; the raw messages are at the end of the page):</p><ul>{items}</ul>"


def failure_details(dataset: xr.Dataset) -> str:
    """The raw messages of what failed (``run_failure_details``), collapsed; empty when nothing failed."""
    details = _lines(dataset, "run_failure_details")
    if not details:
        return ""
    return f"<details><summary>The raw messages of what failed ({len(details)})</summary><pre>{html.escape(chr(10).join(details))}</pre></details>"


def _found_on(point: xr.Dataset) -> str:
    """The branches a special point was found on, ``3, 7`` (its own branch where the dataset lists no others)."""
    if "special_point_branches" in point:
        return ", ".join(str(point["special_point_branches"].values).split())
    return str(int(point["special_point_branch"]))


def special_point_table(dataset: xr.Dataset) -> Table:
    """Every located special point: kind, frequency, R, the orbit, its multipliers and what happens there."""
    kinds = _flags(dataset["special_point_kind"])
    rows = []
    order = np.lexsort((dataset["special_point_frequency"].values, dataset["special_point_restitution"].values))
    for k in order:
        point = dataset.isel(special_point=int(k))
        mu = point["special_point_multiplier_real"].values + 1j * point["special_point_multiplier_imag"].values
        multipliers = ", ".join(f"{m.real:.4f}{m.imag:+.4f}j" if abs(m.imag) > 1e-9 else f"{m.real:.4f}" for m in mu)
        key = orbit_class(float(point["special_point_impacts_per_period"]), int(point["special_point_period_multiplicity"]))
        cells = [
            kinds[int(point["special_point_kind"])].replace("_", "-"), fmt(float(point["special_point_frequency"]), ".5f"),
            fmt(float(point["special_point_restitution"]), "g"), _found_on(point), _orbit_label(key),
            html.escape(multipliers), fmt(float(point["special_point_floquet_modulus"]), ".4f"), html.escape(str(point["special_point_note"].values)),
        ]  # fmt: skip
        rows.append("<tr>" + "".join(f"<td>{c}</td>" for c in cells) + "</tr>")
    header = "".join(f"<th>{h}</th>" for h in ("kind", "frequency [Hz]", "R", "branch", "orbit", "Floquet multipliers", "max |mu|", "what happens there"))
    return Table("Special points", f"<table><tr>{header}</tr>{''.join(rows)}</table>")


class BifurcationPage:
    """The page of a bifurcation study's dataset."""

    def __init__(self, dataset: xr.Dataset) -> None:
        self.dataset = dataset

    def summary(self) -> str:
        """The answer (:func:`headline`), then what was computed."""
        d = self.dataset
        stops = f"; stops: {d.attrs['stop_layout']}" if "stop_layout" in d.attrs else ""
        return (f"{headline(d)}; {int(np.unique(d['branch'].values).size)} branches, {d.sizes['special_point']} special points, brute force at "
                f"{d.sizes['frequency']} frequencies x {d.sizes['sweep']} directions for R = {', '.join(fmt(r, 'g') for r in d['restitution'].values)}{stops}")  # fmt: skip

    def sections(self, out: Path) -> list[Section]:
        """The answer (and what failed, if anything did) with the diagrams, multipliers and special points per
        restitution, then the chart, then the continuation's logs and the raw messages of what failed, collapsed
        (what a reader checks, not what they read first)."""
        figures = saved(bifurcation_figures(self.dataset), out)
        chart = [f for f in figures if f.path.stem == "chart"]
        answer = answer_text(self.dataset) + failure_text(self.dataset)
        sections = [Section("Bifurcation diagrams", answer, [f for f in figures if f not in chart], [special_point_table(self.dataset)])]
        if chart:
            sections.append(Section("Two-parameter chart", "", chart))
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
