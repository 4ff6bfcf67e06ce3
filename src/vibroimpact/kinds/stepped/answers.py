"""What a stepped study's page says first: its result in numbers, computed from the dataset (never written in).

* :func:`answer_text`: the largest response of every solution against the linear system's;
* :func:`contact_text`: the largest contact deceleration and force on a compliant bumper against the closed-form
  estimate, and how the two compare where both are steady one-impact motions (paper figure 28);
* :func:`peaks_text`: the resonance peaks against a swept restitution or clearance (figures 25-26), from
  :func:`peak_rows`;
* :func:`reduction_text`: the reduction factors of |X1| by the closed form;
* :func:`convergence_text`: the compliant bumper's convergence to the rigid stop, from :func:`convergence_rows`.

Units as on every page: displacements in mm, accelerations in m/s², forces in N, frequencies in Hz.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import xarray as xr

from vibroimpact.analysis.stability import Regime
from vibroimpact.kinds.stepped.crosscheck import subset_solutions
from vibroimpact.kinds.stepped.tables import computed_part, reduction_factors
from vibroimpact.reporting.record import GeneralSetting, StudySetting
from vibroimpact.reporting.series import periodic_points
from vibroimpact.reporting.style import DISPLACEMENT_SCALE, QUANTITIES, fmt
from vibroimpact.scene.schema import ENGINE_SOLUTIONS

__all__ = ["answer_text", "contact_text", "band_peaks", "PeakRow", "peak_rows", "peaks_text", "reduction_text", "Convergence", "convergence_rows", "convergence_text", "STANDARD_GRAVITY"]

#: Standard gravity [m/s²], to state a deceleration in g.
STANDARD_GRAVITY = 9.80665
#: Regime flags of an admissible one-impact orbit.
_ONE_IMPACT = (Regime.ONE_IMPACT, Regime.ONE_IMPACT_COEXISTING_LINEAR)


def _where(data: xr.DataArray, index: tuple[int, ...], skip: tuple[str, ...] = ()) -> list[str]:
    """The point ``index`` of ``data`` in words: its frequency, restitution ratio, clearance, bumper and stop."""
    words = []
    for dim, i in zip(data.dims, index):
        value = data[dim].values[i] if dim in data.coords else i
        if dim in skip:
            continue
        if dim == "frequency":
            words.insert(0, f"{fmt(float(value), '.4g')} Hz")
        elif dim == "restitution":
            words.append(f"R = {fmt(float(value), 'g')}")
        elif dim == "clearance":
            words.append(f"Delta = {fmt(float(value) * DISPLACEMENT_SCALE, 'g')} mm")
        elif dim == "bumper_frequency":
            words.append(f"bumper {fmt(float(value), 'g')} Hz")
        elif dim == "stop":
            words.append(f"stop {int(i)}")
    return words


def answer_text(dataset: xr.Dataset, layout: GeneralSetting) -> str:
    """The largest fundamental of the first coordinate of every solution over the frequencies it computed (the
    largest over the swept parameters, and where), against the linear system's: the page's answer in one sentence."""
    quantity = f"{layout.names[0]}_amplitude"
    if quantity not in dataset:
        return "The largest value of each response over the frequencies every solution computed, and where it occurs."
    f = dataset["frequency"].values
    parts = []
    on_subset = subset_solutions(dataset)  # on a few points: the cross-check says how they compare
    for solution in (str(s) for s in dataset["solution"].values if s not in on_subset):
        data = dataset[quantity].sel(solution=solution)
        values = np.asarray(data.values, dtype=float)
        if not np.isfinite(values).any():
            continue
        index = np.unravel_index(int(np.nanargmax(values)), values.shape)
        at = {dim: data[dim].values[i] for dim, i in zip(data.dims, index) if dim in data.coords}
        where = [f"{fmt(float(f[index[data.dims.index('frequency')]]), '.4g')} Hz"]
        where += [f"{'R' if dim == 'restitution' else dim} = {fmt(float(at[dim]) * (DISPLACEMENT_SCALE if dim == 'clearance' else 1.0), 'g')}{' mm' if dim == 'clearance' else ''}" for dim in data.dims if dim not in ("frequency", "stop") and solution != "linear"]
        label = "linear system (no stop)" if solution == "linear" else solution
        parts.append(f"{label} {fmt(float(values[index]) * DISPLACEMENT_SCALE, '.4g')} mm at {', '.join(where)}")
    return f"Largest |{layout.names[0]}| over the frequencies each solution computed: " + "; ".join(parts) + ". The table gives every response per solution and swept value."


# ------------------------------------------------------------------------------------------ contact peaks
def contact_text(dataset: xr.Dataset) -> str:
    """The largest contact deceleration of each simulation that measured one, in m/s² and g, with the contact force
    there and each closed-form estimate at the same point; then the simulation against the estimate where the
    estimate's one-impact orbit is stable and the simulation periodic (median, range and where). Empty if the dataset
    has no contact peaks."""
    if "peak_acceleration" not in dataset:
        return ""
    acceleration, force = dataset["peak_acceleration"], dataset.get("peak_contact_force")
    solutions = [str(s) for s in dataset["solution"].values]
    on_subset = subset_solutions(dataset)  # the cross-check says how they compare
    measured = [s for s in solutions if s in ENGINE_SOLUTIONS and s not in on_subset and np.nanmax(acceleration.sel(solution=s).values, initial=0.0) > 0.0]
    estimates = [s for s in solutions if s not in ENGINE_SOLUTIONS and np.nanmax(acceleration.sel(solution=s).values, initial=0.0) > 0.0]
    sentences = []
    for solution in measured:
        data = acceleration.sel(solution=solution)
        values = np.asarray(data.values, dtype=float)
        index = np.unravel_index(int(np.nanargmax(values)), values.shape)
        at = dict(zip(data.dims, index))
        peak = float(values[index])
        text = f"Largest contact deceleration: {solution} {fmt(peak, '.4g')} m/s² ({fmt(peak / STANDARD_GRAVITY, '.3g')} g) at {', '.join(_where(data, index))}"
        if force is not None:
            text += f", contact force {fmt(float(force.sel(solution=solution).isel(at).values), '.3g')} N"
        for estimate in estimates:
            there = float(acceleration.sel(solution=estimate).isel(at).values)
            if math.isfinite(there):
                text += f"; the {estimate} estimate there {fmt(there, '.4g')} m/s²"
                text += f" ({fmt(float(force.sel(solution=estimate).isel(at).values), '.3g')} N)" if force is not None else ""
        sentences.append(text + ".")
        for estimate in estimates:
            sentences.append(_against_estimate(dataset, solution, estimate))
    return " ".join(s for s in sentences if s)


def _against_estimate(dataset: xr.Dataset, simulation: str, estimate: str) -> str:
    """The simulation's contact deceleration against the estimate where both are steady one-impact motions (the
    largest over the stops where there are several)."""
    acceleration = dataset["peak_acceleration"]
    if "stop" in acceleration.dims:
        acceleration = acceleration.max("stop")
    measured_data = acceleration.sel(solution=simulation)
    dims = measured_data.dims
    measured = np.asarray(measured_data.values, dtype=float)
    estimated = np.asarray(acceleration.sel(solution=estimate).transpose(*dims).values, dtype=float)
    usable = np.isfinite(measured) & (measured > 0.0) & np.isfinite(estimated) & (estimated > 0.0)
    if "converged" in dataset:
        usable &= dataset["converged"].sel(solution=simulation).transpose(*dims).values == 1
    if "regime" in dataset:
        usable &= np.isin(dataset["regime"].sel(solution=estimate).transpose(*dims).values, _ONE_IMPACT)
    if "stable" in dataset:
        usable &= dataset["stable"].sel(solution=estimate).transpose(*dims).values == 1
    if not usable.any():
        return ""
    difference = (measured[usable] - estimated[usable]) / estimated[usable]
    points = np.argwhere(usable)
    low, high = (", ".join(_where(measured_data, tuple(points[k]))) for k in (int(np.argmin(difference)), int(np.argmax(difference))))
    median = float(np.median(difference))
    return (
        f"On the {int(usable.sum())} points where the {estimate} orbit is a stable one impact per period and {simulation} is periodic, "
        f"{simulation} is {fmt(100.0 * abs(median), '.2g')} % {'above' if median >= 0 else 'below'} the estimate "
        f"(median; from {fmt(100.0 * float(difference.min()), '+.2g')} % at {low} to {fmt(100.0 * float(difference.max()), '+.2g')} % at {high})."
    )


# ------------------------------------------------------------------------------------------------- peaks
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


def peak_rows(dataset: xr.Dataset, setting: StudySetting, parameter: str) -> list[PeakRow]:
    """Peaks of |X1| per solution and ``parameter`` value; pgf also with stable orbits only and on the simulation grid."""
    f = dataset["frequency"].values
    split = setting.split_frequency
    sim_f = setting.simulation_frequency
    rows: list[PeakRow] = []
    on_subset = subset_solutions(dataset)  # their peaks would be over other frequencies: the cross-check shows them
    for value in dataset[parameter].values:
        point = dataset.sel({parameter: value})
        for solution in (str(s) for s in dataset["solution"].values if s != "linear" and s not in on_subset):
            values = point["x1_amplitude"].sel(solution=solution).values
            if solution in ENGINE_SOLUTIONS:
                converged = periodic_points(point, solution)
                peaks = band_peaks(values, f, split)
                periodic = [bool(np.any(converged & np.isclose(f, at, rtol=0.0, atol=1e-9))) for _, at in peaks]
                rows.append((solution, solution, float(value), *peaks, *periodic))
                continue
            rows.append((solution, solution, float(value), *band_peaks(values, f, split), True, True))
            if solution == "pgf" and "stable" in point and "regime" in point:
                impact = np.isin(point["regime"].sel(solution=solution).values, _ONE_IMPACT)
                stable = impact & (point["stable"].sel(solution=solution).values == 1)
                rows.append(("pgf, stable one-impact orbits only", solution, float(value), *band_peaks(np.where(stable, values, np.nan), f, split), True, True))
            if sim_f.size:
                on = np.isin(f, sim_f)
                rows.append((f"{solution} on the simulation grid", solution, float(value), *band_peaks(values[on], f[on], split), True, True))
    return rows


def peaks_text(dataset: xr.Dataset, setting: StudySetting, parameter: str) -> str:
    """The largest |X1| of each resonance band against ``parameter`` for every solution (its own grid), in mm."""
    rows = [r for r in peak_rows(dataset, setting, parameter) if r[0] == r[1]]
    if not rows:
        return ""
    scale, unit, name = (DISPLACEMENT_SCALE, " mm", "Delta") if parameter == "clearance" else (1.0, "", "R")
    values = list(dict.fromkeys(r[2] for r in rows))
    bands = []
    for band, words in ((0, f"band 1, below the anti-resonance at {fmt(setting.split_frequency, '.4g')} Hz"), (1, "band 2, above it")):
        per = "; ".join(f"{solution} " + ", ".join(fmt(r[3 + band][0] * DISPLACEMENT_SCALE, '.3g') or "n/a" for r in rows if r[1] == solution) for solution in dict.fromkeys(r[1] for r in rows))
        bands.append(f"{words}: {per}")
    return f"Resonance peaks of |X1| [mm] at {name} = {', '.join(fmt(v * scale, 'g') for v in values)}{unit} (in that order; n/a: no value in the band), " + "; ".join(bands) + "."


# ------------------------------------------------------------------------------------------- reduction
def reduction_text(dataset: xr.Dataset, layout: GeneralSetting) -> str:
    """The reduction factors of |X1| of the first closed form (its own fine grid) at each swept point."""
    closed = [str(s) for s in dataset["solution"].values if s != "linear" and s not in ENGINE_SOLUTIONS]
    if layout.named is None or not closed or "x1_amplitude" not in dataset:
        return ""
    solution = closed[0]
    rows = reduction_factors(computed_part(dataset, solution), layout, "x1_amplitude", solution)
    swept = [d for d in ("restitution", "clearance") if d in dataset.dims]
    parts = []
    for row in rows:
        where = [f"R = {fmt(row.restitution, 'g')}" if "restitution" in swept else "", f"Delta = {fmt(row.clearance * DISPLACEMENT_SCALE, 'g')} mm" if "clearance" in swept else ""]
        factors = f"{fmt(row.factor[0], '.3g')} and {fmt(row.factor[1], '.3g')}"
        parts.append(f"{factors} at {', '.join(w for w in where if w)}" if any(where) else factors)
    return f"Reduction factors: the stop divides the resonant |X1| of {solution} (linear peak / largest realisable response, first and second resonance) by {'; '.join(parts)}."


# ----------------------------------------------------------------------------------------- convergence
@dataclass(frozen=True)
class Convergence:
    """The compliant steady state against the rigid-stop one at one bumper frequency.

    Attributes
    ----------
    bumper_frequency : float
        Omega_b / 2 pi [Hz].
    median, largest : float
        Median and largest relative difference of |X1| over the simulated frequencies [1].
    order : float
        Median observed order in 1 / Omega_b from the previous bumper frequency (NaN for the first).
    wall_time : float
        Median wall time of a compliant steady state [s] (NaN if not measured).
    """

    bumper_frequency: float
    median: float
    largest: float
    order: float
    wall_time: float


def convergence_rows(dataset: xr.Dataset, setting: StudySetting, reference: str, compliant: str) -> list[Convergence]:
    """:class:`Convergence` of the bumper solution ``compliant`` to the rigid ``reference`` at each bumper frequency of
    ``dataset``."""
    bumper = dataset["bumper_frequency"].values
    data = dataset.sel(frequency=setting.simulation_frequency)
    sim = data["x1_amplitude"].sel(solution=compliant).transpose("bumper_frequency", "frequency").values
    ref = data["x1_amplitude"].sel(solution=reference).values
    difference = np.abs(sim - ref) / ref
    wall = data["wall_time"].sel(solution=compliant).transpose("bumper_frequency", "frequency").values if "wall_time" in data else np.full(sim.shape, np.nan)
    rows = []
    for i, b in enumerate(bumper):
        order = math.nan
        if i > 0:
            with np.errstate(invalid="ignore", divide="ignore"):
                orders = np.log(difference[i - 1] / difference[i]) / np.log(b / bumper[i - 1])
            if np.isfinite(orders).any():
                order = float(np.nanmedian(orders))
        with np.errstate(invalid="ignore"):
            rows.append(Convergence(float(b), float(np.nanmedian(difference[i])), float(np.nanmax(difference[i])), order, float(np.nanmedian(wall[i])) if np.isfinite(wall[i]).any() else math.nan))
    return rows


def convergence_text(dataset: xr.Dataset, setting: StudySetting, reference: str, compliant: str) -> str:
    """The bumper solution ``compliant``'s |X1| against the rigid stop's at each bumper frequency, the observed order,
    and the cost."""
    rows = convergence_rows(dataset, setting, reference, compliant)
    if not rows:
        return ""
    f = setting.simulation_frequency
    text = (
        f"The compliant bumper's steady-state {QUANTITIES['x1_amplitude'].label} differs from the rigid stop's ({reference}) by "
        + ", ".join(f"{fmt(100.0 * r.median, '.2g')} %" for r in rows)
        + f" at Omega_b / 2 pi = {', '.join(fmt(r.bumper_frequency, 'g') for r in rows)} Hz (median over the {f.size} simulated frequencies, {fmt(f.min(), 'g')}-{fmt(f.max(), 'g')} Hz)"
    )
    orders = [r.order for r in rows if math.isfinite(r.order)]
    if orders:
        text += f": observed order {fmt(min(orders), '.2f')}-{fmt(max(orders), '.2f')} in 1 / Omega_b"
    walls = [r.wall_time for r in rows if math.isfinite(r.wall_time)]
    if walls and "wall_time" in dataset:
        rigid = float(np.nanmedian(dataset["wall_time"].sel(solution=reference).values))
        text += f". A {compliant} steady state costs {fmt(min(walls), '.2g')}-{fmt(max(walls), '.2g')} s (median per bumper)"
        text += f", {fmt(float(np.median(walls)) / rigid, '.3g')} times {reference}'s" if rigid > 0 else ""
    return text + "."
