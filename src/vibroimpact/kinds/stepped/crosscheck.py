"""One contact law by two engines in the same run: a solution run on a subset of the grid (``simulation.subset``,
e.g. IDA) against the one with an exact flow computed everywhere (e.g. the closed-form bumper), where both computed.

The page says how far apart they are (the largest relative difference of each steady-state quantity over the points
both found periodic: an irregular motion's values are window averages, which two engines need not share) and what
the exact flow saves (the median ratio of the two wall times per steady state over the points both integrated, in
the same run, so on the same machine under the same load).
"""

from __future__ import annotations

import html
import math
from dataclasses import dataclass

import numpy as np
import xarray as xr

from vibroimpact.analysis.stability import Regime
from vibroimpact.engines.registry import BUMPER, RIGID
from vibroimpact.reporting.page import Section, Table
from vibroimpact.reporting.style import DISPLACEMENT_SCALE, PAGE_UNITS, QUANTITIES, SOLUTION_DESCRIPTIONS, fmt, solution_ref
from vibroimpact.scene.schema import contact_solutions

__all__ = ["subset_solutions", "CrossCheck", "cross_checks", "cross_check_text", "cross_check_section", "COMPARED"]

#: Quantities compared, where the dataset has them (the contact peaks only where both engines measure one).
COMPARED = ("x1_amplitude", "x2_amplitude", "force_amplitude", "impulse", "peak_acceleration", "peak_contact_force")
#: Regimes of a point without integration (the linear motion fits): no cost to compare.
_NOT_INTEGRATED = (Regime.LINEAR, Regime.NOT_COMPUTED, Regime.FAILED)


def subset_solutions(dataset: xr.Dataset) -> dict[str, str]:
    """Solutions the study ran on a subset of its simulation grid -> that subset in words, in the page's units
    (the dataset's attributes, :func:`page_unit_words`)."""
    prefix = "simulation_subset_"
    return {key[len(prefix) :]: page_unit_words(str(value)) for key, value in dataset.attrs.items() if key.startswith(prefix) and key[len(prefix) :] in dataset["solution"].values}


def page_unit_words(text: str) -> str:
    """A subset in words as the dataset stores it, in SI (``frequency 26, 30 Hz; clearance 0.002 m``,
    :func:`vibroimpact.scene.subset.subset_text`), in the page's units (:data:`PAGE_UNITS`: ``clearance 2 mm``),
    as every other clearance on the page."""
    parts = []
    for part in text.split("; "):
        head, _, unit = part.rpartition(" ")
        axis, _, values = head.partition(" ")
        if unit in PAGE_UNITS and values:
            page_unit, factor = PAGE_UNITS[unit]
            try:
                part = f"{axis} {', '.join(fmt(float(v) * factor, 'g') for v in values.split(', '))} {page_unit}"
            except ValueError:  # not a list of numbers: kept as it is
                pass
        parts.append(part)
    return "; ".join(parts)


@dataclass(frozen=True)
class CrossCheck:
    """A subset solution against its contact law's reference over the points both computed.

    Attributes
    ----------
    checked, reference : str
        The solution on a subset, and the one computed everywhere.
    subset : str
        The subset in words.
    points : int
        Points both computed.
    periodic : int
        Of those, points both found periodic (compared).
    largest : dict
        Quantity -> largest relative difference over the compared points [1].
    worst : str
        Where |X1| differs most, in words.
    cost_ratio : float
        Median of checked / reference wall time per steady state over the points both integrated [1] (NaN unknown).
    walls : tuple of float
        Median wall time per steady state of (checked, reference) at those points [s].
    rows : list of tuple
        Per point: (where, regime checked, regime reference, |X1| checked [m], |X1| reference [m], relative difference,
        wall checked [s], wall reference [s]).
    """

    checked: str
    reference: str
    subset: str
    points: int
    periodic: int
    largest: dict[str, float]
    worst: str
    cost_ratio: float
    walls: tuple[float, float]
    rows: list[tuple[str, str, str, float, float, float, float, float]]


def _flat(dataset: xr.Dataset, quantity: str, solution: str) -> np.ndarray:
    data = dataset[quantity].sel(solution=solution)
    if "stop" in data.dims:
        data = data.max("stop")
    return np.asarray(data.transpose(*_dims(dataset)).values, dtype=float).ravel()


def _dims(dataset: xr.Dataset) -> list[str]:
    return [d for d in ("restitution", "clearance", "bumper_frequency", "frequency") if d in dataset["x1_amplitude"].dims]


def _where(dataset: xr.Dataset, flat: int) -> str:
    dims = _dims(dataset)
    index = np.unravel_index(flat, tuple(dataset.sizes[d] for d in dims))
    words = []
    for dim, i in zip(dims, index):
        value = float(dataset[dim].values[i])
        words.append({"frequency": f"{fmt(value, '.4g')} Hz", "restitution": f"R = {fmt(value, 'g')}", "clearance": f"Delta = {fmt(value * DISPLACEMENT_SCALE, 'g')} mm", "bumper_frequency": f"bumper {fmt(value, 'g')} Hz"}[dim])
    return ", ".join(words)


def cross_checks(dataset: xr.Dataset) -> list[CrossCheck]:
    """Every subset solution against the reference of its contact law (the first with an exact flow, not itself on a
    subset); none where the dataset has no ``x1_amplitude`` or ``regime``."""
    if "x1_amplitude" not in dataset or "regime" not in dataset:
        return []
    subsets = subset_solutions(dataset)
    present = [str(s) for s in dataset["solution"].values]
    checks = []
    for contact in (RIGID, BUMPER):
        engines = contact_solutions(present, contact)
        references = [e for e in engines if e not in subsets]
        if not references:
            continue
        for checked in (e for e in engines if e in subsets):
            checks.append(_cross_check(dataset, checked, references[0], subsets[checked]))
    return checks


def _cross_check(dataset: xr.Dataset, checked: str, reference: str, subset: str) -> CrossCheck:
    regime = {s: _flat(dataset, "regime", s).astype(int) for s in (checked, reference)}
    both = (regime[checked] != Regime.NOT_COMPUTED) & (regime[reference] != Regime.NOT_COMPUTED)
    periodic = both.copy()
    if "converged" in dataset:
        periodic &= (_flat(dataset, "converged", checked) == 1) & (_flat(dataset, "converged", reference) == 1)
    largest: dict[str, float] = {}
    for quantity in (q for q in COMPARED if q in dataset):
        a, b = _flat(dataset, quantity, checked), _flat(dataset, quantity, reference)
        usable = periodic & np.isfinite(a) & np.isfinite(b) & (np.abs(b) > 0.0)
        if usable.any():
            largest[quantity] = float(np.max(np.abs(a[usable] - b[usable]) / np.abs(b[usable])))
    x_checked, x_reference = _flat(dataset, "x1_amplitude", checked), _flat(dataset, "x1_amplitude", reference)
    with np.errstate(invalid="ignore", divide="ignore"):
        difference = np.abs(x_checked - x_reference) / np.abs(x_reference)
    compared = periodic & np.isfinite(difference)
    worst = _where(dataset, int(np.flatnonzero(compared)[np.argmax(difference[compared])])) if compared.any() else ""
    walls = {s: _flat(dataset, "wall_time", s) if "wall_time" in dataset else np.full(both.shape, np.nan) for s in (checked, reference)}
    integrated = both & ~np.isin(regime[checked], _NOT_INTEGRATED) & ~np.isin(regime[reference], _NOT_INTEGRATED) & (walls[reference] > 0.0)
    ratio = float(np.median(walls[checked][integrated] / walls[reference][integrated])) if integrated.any() else math.nan
    medians = tuple(float(np.median(walls[s][integrated])) if integrated.any() else math.nan for s in (checked, reference))
    rows = [
        (_where(dataset, int(k)), Regime(regime[checked][k]).name.lower(), Regime(regime[reference][k]).name.lower(), float(x_checked[k]), float(x_reference[k]), float(difference[k]) if compared[k] else math.nan, float(walls[checked][k]), float(walls[reference][k]))
        for k in np.flatnonzero(both)
    ]  # fmt: skip
    return CrossCheck(checked, reference, subset, int(both.sum()), int(periodic.sum()), largest, worst, ratio, (medians[0], medians[1]), rows)


def cross_check_text(check: CrossCheck) -> str:
    """The agreement and the cost ratio of one cross-check in a sentence or two: the page's answer on it."""
    x1 = check.largest.get("x1_amplitude", math.nan)
    others = ", ".join(f"{QUANTITIES[q].label} {fmt(v, '.1e')}" for q, v in check.largest.items() if q != "x1_amplitude")
    text = (
        f"{solution_ref(check.checked)} ({SOLUTION_DESCRIPTIONS.get(check.checked, check.checked)}), run on {check.subset}, against {solution_ref(check.reference)} "
        f"({SOLUTION_DESCRIPTIONS.get(check.reference, check.reference)}) on the {check.points} points both computed: "
    )
    if check.periodic:
        text += f"largest relative difference of {QUANTITIES['x1_amplitude'].label} {fmt(x1, '.1e')} (at {check.worst}) over the {check.periodic} point{'s' if check.periodic > 1 else ''} both found periodic"
        text += f" ({others})" if others else ""
    else:
        text += "no point both found periodic"
    irregular = check.points - check.periodic
    if irregular:
        text += f"; {irregular} not compared (not periodic in one or both: their values are averages over a measured window)"
    text += "."
    if math.isfinite(check.cost_ratio):
        text += (
            f" A steady state of {solution_ref(check.reference)} {cost_words(check.cost_ratio)} one of {solution_ref(check.checked)} "
            f"(median ratio of their wall times at the points both integrated, in this run: {fmt(check.walls[0] * 1e3, '.4g')} ms against {fmt(check.walls[1] * 1e3, '.3g')} ms)."
        )
    return text


def cost_words(ratio: float) -> str:
    """How a steady state of the reference compares in cost with one of the checked solution, ``ratio`` = checked /
    reference: ``costs 1/2.11 of`` (the reference cheaper), ``costs 2.14 times`` (dearer; not ``1/0.467``), ``costs
    as much as``."""
    if fmt(ratio, ".3g") == "1":  # exact: the ratio as written
        return "costs as much as"
    return f"costs 1/{fmt(ratio, '.3g')} of" if ratio > 1.0 else f"costs {fmt(1.0 / ratio, '.3g')} times"


def cross_check_section(checks: list[CrossCheck]) -> Section | None:
    """The point-by-point table of every cross-check, under its sentence; None without one."""
    if not checks:
        return None
    tables = []
    for check in checks:
        header = "<tr><th>point</th><th>regime</th><th>regime (reference)</th><th>|X1| [mm]</th><th>|X1| reference [mm]</th><th>rel. difference</th><th>wall time [ms]</th><th>reference [ms]</th></tr>"
        body = "".join(
            f"<tr><td>{html.escape(where)}</td><td>{a}</td><td>{b}</td><td>{fmt(x * DISPLACEMENT_SCALE, '.6g')}</td><td>{fmt(y * DISPLACEMENT_SCALE, '.6g')}</td><td>{fmt(d, '.1e') or 'not compared'}</td><td>{fmt(w * 1e3, '.3g')}</td><td>{fmt(v * 1e3, '.3g')}</td></tr>"
            for where, a, b, x, y, d, w, v in check.rows
        )
        tables.append(Table(f"{check.checked} against {check.reference}, point by point", f"<table>{header}{body}</table>"))
    names = "; ".join(f"{solution_ref(c.checked)} against {solution_ref(c.reference)}" for c in checks)
    intro = (
        f"<p>Point by point ({html.escape(names)}): the regime each engine found, |X1| and its relative difference where both are periodic, "
        "and each steady state's wall time in this run (transient plus measurement, one process; no compile or load of a compiled engine: each worker loads them before its first point). "
        "The page's first section sums them up.</p>"
    )
    return Section("The same contact by two engines", intro=intro, tables=tables)
