"""What a design study answers, in words: the design to build and its worst case against the comparisons
(:func:`answer_text`), and what the reader must know before building it (:func:`warnings`), read from the dataset."""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from vibroimpact.kinds.design.scene import safe_name
from vibroimpact.reporting.style import fmt

__all__ = ["answer_text", "warnings", "variable_text", "mistuning_text"]

_SYMBOLS = {"clearance": "Delta", "restitution": "R"}


def _mm(value: float) -> str:
    return f"{fmt(1e3 * value, '.4g')} mm" if math.isfinite(value) else "not known"


def variable_text(dataset: xr.Dataset, design: int) -> str:
    """``Delta = 2.1 mm, R = 0.35, k2 = 4120 N/m`` of a compared design."""
    parts = []
    for name in str(dataset.attrs.get("variables", "")).split(", "):
        if not name:
            continue
        value = float(dataset[f"design_{safe_name(name)}"].values[design])
        if name == "clearance":
            parts.append(f"Delta = {fmt(1e3 * value, '.4g')} mm")
        else:
            unit = dataset[f"design_{safe_name(name)}"].attrs.get("units", "1")
            parts.append(f"{_SYMBOLS.get(name, name)} = {fmt(value, '.4g')}{'' if unit == '1' else ' ' + unit.replace(' m-1', '/m').replace('N s/m', 'N s/m')}")
    return ", ".join(parts)


def mistuning_text(dataset: xr.Dataset) -> str:
    """``+-5 % of k1 and +-0.2 mm of the clearance (32 samples)``, or empty."""
    parts = []
    for name in dataset.data_vars:
        if str(name).startswith("mistuning_"):
            v = dataset[name]
            spread = float(np.max(np.abs(v.values)))
            what = str(v.attrs.get("long_name", "")).split(" offset of ")[-1].split(" in each")[0]
            parts.append(f"+-{fmt(100 * spread, '.2g')} % of {what}" if v.attrs.get("units") == "1" and "relative" in v.attrs.get("long_name", "") else f"+-{fmt(1e3 * spread, '.2g')} mm of the {what}" if what == "clearance" else f"+-{fmt(spread, '.2g')} of {what}")
    return f"{' and '.join(parts)} ({dataset.sizes['sample'] - 1} samples)" if parts else ""


def answer_text(dataset: xr.Dataset) -> str:
    """The page's first sentence (module docstring)."""
    d = dataset
    low, high = fmt(d.attrs["band_low_Hz"], ".4g"), fmt(d.attrs["band_high_Hz"], ".4g")
    values = d["design_sample_value"].values
    worst = [float(np.nanmax(row)) if np.any(np.isfinite(row)) else math.nan for row in values]
    mistuned = mistuning_text(d)
    over = f"over {low}-{high} Hz" + (f" and {mistuned}" if mistuned else "")
    recommended = int(d.attrs.get("recommended_evaluation", -1))
    if recommended < 0:
        return f"No design could be recommended: no candidate had a finite worst case {over}."
    certified = float(d.attrs.get("recommended_certified_score_m", math.nan))
    head = f"Build {variable_text(d, 0)}: worst case |X1| = {_mm(max(worst[0], certified) if math.isfinite(certified) else worst[0])} {over}"
    limit = float(d.attrs.get("operating_limit_m", math.nan))
    operating = d["design_operating_amplitude"].values
    at = fmt(d.attrs.get("operating_frequency_Hz"), ".4g")

    def notch(k: int) -> str:
        if not math.isfinite(limit) or not math.isfinite(float(operating[k])):
            return ""
        return f", |X1| at {at} Hz {_mm(float(operating[k]))}" + ("" if operating[k] <= limit else f", above the allowed {_mm(limit)}")

    others = []
    if np.any(np.isfinite(values[2])):
        others.append(f"best linear absorber of the same mass: {_mm(worst[2])}{notch(2)}")
    others.append(f"the scene's design ({variable_text(d, 1)}): {_mm(worst[1])}{notch(1)}")
    return f"{head}{notch(0)} ({'; '.join(others)})."


def warnings(dataset: xr.Dataset) -> list[str]:
    """What got worse, what was not reached, what was not checked: each a sentence, worst first."""
    d = dataset
    out: list[str] = []
    recommended = int(d.attrs.get("recommended_evaluation", -1))
    values = d["design_sample_value"].values
    limit = float(d.attrs.get("operating_limit_m", math.nan))
    if np.any(np.isfinite(values[2])) and recommended >= 0 and np.nanmax(values[0]) >= np.nanmax(values[2]):
        linear_notch = float(d["design_operating_amplitude"].values[2])
        keeps = math.isfinite(limit) and math.isfinite(linear_notch) and linear_notch > limit
        cost = f", but it has no notch: |X1| at {fmt(d.attrs['operating_frequency_Hz'], '.4g')} Hz is {_mm(linear_notch)}, above the allowed {_mm(limit)}" if keeps else ""
        out.append(f"Over the band the stop does not pay: the best linear absorber of the same mass has the smaller worst case ({_mm(float(np.nanmax(values[2])))} against {_mm(float(np.nanmax(values[0])))}){cost}.")
    if math.isfinite(limit) and recommended >= 0:
        operating = float(d["operating_amplitude"].values[recommended])
        if not operating <= limit:
            out.append(f"No candidate keeps the notch: at {fmt(d.attrs['operating_frequency_Hz'], '.4g')} Hz |X1| reaches {_mm(operating)} against the allowed {_mm(limit)}; the recommendation is the least bad.")
    if recommended >= 0:
        uncovered = float(np.nanmax(d["sample_uncovered"].values[recommended]))
        if uncovered > 0.0:
            out.append(f"On {fmt(100 * uncovered, '.2g')} % of the band no period-1 motion of the recommended design is stable: there its motion is of a kind the closed forms do not know (more impacts, a longer period, or not periodic); the screen guessed its size from the unstable orbits; the certification found the motions there by brute force.")
        rows = np.flatnonzero(d["certificate_evaluation"].values == recommended)
        for r in rows:
            worst, screened = float(d["certificate_worst"].values[r]), float(d["certificate_screened"].values[r])
            if math.isfinite(worst) and worst > screened * (1.0 + 1e-6):
                out.append(f"The certification found a larger stable motion than the screen under sample {int(d['certificate_sample'].values[r])}: {_mm(worst)} ({d['certificate_motion'].values[r]} at {fmt(d['certificate_frequency'].values[r], '.4g')} Hz) against {_mm(screened)}.")
            error = str(d["certificate_error"].values[r])
            if error:
                out.append(f"The certification of sample {int(d['certificate_sample'].values[r])} failed: {error}")
    ridge = float(d.attrs.get("equal_peak_difference", math.nan))
    if math.isfinite(ridge) and ridge < 0.02:
        f1, f2 = (float(x) for x in np.atleast_1d(d.attrs["equal_peak_frequencies_Hz"]))
        out.append(f"The recommended design sits on an equal-peak ridge: its two largest band maxima ({fmt(f1, '.4g')} and {fmt(f2, '.4g')} Hz) differ by {fmt(100 * ridge, '.2g')} %; a small change of any variable raises one of them.")
    if d.sizes.get("certificate", 0):
        points = d.sizes.get("attractor_point", 0)
        out.append(f"What the certification can miss: an attractor whose basin none of its runs entered (sweeps both ways and two more starts at each of {points} frequencies), or one that lives only between those frequencies; "
                   + ("the search itself ranked candidates on closed forms (period-1 motions), which a design with a larger multi-impact or non-periodic motion can fool until it is certified."
                      if not np.any(d["sample_motion"].values == 3) else "the search itself ranked candidates by a coarse brute force (no closed form applies to this layout), whose grid and few starts a narrow or rarely reached motion escapes."))
    for failure in d.attrs.get("run_failures", []) if isinstance(d.attrs.get("run_failures"), list) else []:
        out.append(str(failure))
    return out
