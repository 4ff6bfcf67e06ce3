"""What a designer must know of a design study's recommended design before building it, beyond its worst case: a
variable on a bound of its range (the best may lie beyond it), a mistuning cut off by a physical limit (the tolerance
box one-sided there), and an impacting motion that coexists close to the operating frequency (a small drift of the
machine's speed lands on it). Read from the dataset; each a sentence of the page's warnings
(:func:`~vibroimpact.kinds.design.answer.warnings`) and of :func:`~vibroimpact.kinds.design.result.design_answer`.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from vibroimpact.kinds.design.quantity import constraint_quantity, objective_quantity, operating_limit
from vibroimpact.kinds.design.scene import safe_name
from vibroimpact.measures.figures_of_merit import NEAR_OPERATING
from vibroimpact.model.collision import MIN_BUMPER_RESTITUTION
from vibroimpact.reporting.style import fmt

__all__ = ["SYMBOLS", "variable_names", "at_bounds", "cautions"]

#: How the page writes the design variables that have a symbol.
SYMBOLS = {"clearance": "Delta", "restitution": "R", "bumper_stiffness": "K_b"}


def variable_names(dataset: xr.Dataset) -> list[str]:
    """The design variables, in the order of the scene (attribute ``variables``)."""
    return [name for name in str(dataset.attrs.get("variables", "")).split(", ") if name]


def _shown(name: str, value: float) -> str:
    return f"Delta = {fmt(1e3 * value, '.4g')} mm" if name == "clearance" else f"{SYMBOLS.get(name, name)} = {fmt(value, '.4g')}"


def at_bounds(dataset: xr.Dataset, design: int = 0) -> str:
    """`` (R = 0 is the lower bound of its range)`` for the compared design's variables that sit on a bound of their
    range (within 1e-9 of the range), "" where none does."""
    parts = []
    for name in variable_names(dataset):
        key = f"variable_{safe_name(name)}"
        if key not in dataset or f"design_{safe_name(name)}" not in dataset:
            continue
        low, high = (float(dataset[key].attrs.get(k, math.nan)) for k in ("valid_min", "valid_max"))
        value = float(dataset[f"design_{safe_name(name)}"].values[design])
        if not (math.isfinite(low) and math.isfinite(high) and math.isfinite(value)):
            continue
        for bound, word in ((low, "lower"), (high, "upper")):
            if abs(value - bound) <= 1e-9 * (high - low):
                parts.append(f"{_shown(name, value)} is the {word} bound of its range")
    return f" ({'; '.join(parts)})" if parts else ""


def _design_value(dataset: xr.Dataset, name: str) -> float:
    """The recommended design's value of ``name``: its design variable, else the scene's stop (a design scene's
    attributes ``stop_clearance_m`` and ``stop_restitution``); NaN where neither says."""
    if f"design_{safe_name(name)}" in dataset:
        return float(dataset[f"design_{safe_name(name)}"].values[0])
    return float(dataset.attrs.get(f"stop_{name}_m" if name == "clearance" else f"stop_{name}", math.nan))


def _clipped(dataset: xr.Dataset) -> list[str]:
    """Each mistuned restitution or clearance whose offsets the model cut off at its physical limit for the
    recommended design (R in [0, 1], above 0 with bumpers; a clearance above 0)."""
    out = []
    bumpers = dataset.attrs.get("screen") == "bumper_orbits"
    for name, low, high in (("restitution", MIN_BUMPER_RESTITUTION if bumpers else 0.0, 1.0), ("clearance", 0.0, math.inf)):
        key = f"mistuning_{name}"
        value = _design_value(dataset, name)
        if key not in dataset or not math.isfinite(value):
            continue
        offsets = np.asarray(dataset[key].values, dtype=float)
        below, above = value + float(np.min(offsets)), value + float(np.max(offsets))
        cut = [(limit, word) for limit, word, beyond in ((low, "lowest", below < low), (high, "highest", above > high)) if beyond]
        for limit, word in cut:
            limit_text = f"{fmt(1e3 * limit, '.4g')} mm" if name == "clearance" else fmt(limit, ".4g")
            out.append(f"The {name}'s mistuning is cut off at {limit_text}, its {word} physical value, for the recommended design ({_shown(name, value)}): "
                       f"the tolerance box is one-sided there: its samples stop at {limit_text}, short of the offset the scene states.")
    return out


def _nearby_impacts(dataset: xr.Dataset) -> str:
    """A stable impacting motion of the recommended design within :data:`~vibroimpact.measures.figures_of_merit.NEAR_OPERATING` of the operating
    frequency, above the allowed value (the constraint's measure is the responses'), in one sentence; "" where none."""
    limit, at = operating_limit(dataset), float(dataset.attrs.get("operating_frequency_Hz", math.nan))
    q, c = objective_quantity(dataset), constraint_quantity(dataset)
    if not (math.isfinite(limit) and math.isfinite(at)) or c.name != q.name or "response_frequency" not in dataset:
        return ""
    f = np.asarray(dataset["response_frequency"].values, dtype=float)
    near = np.abs(f - at) <= NEAR_OPERATING * at
    if not np.any(near):
        return ""
    impacting = np.full(f.shape, np.nan)
    for root in ("plus", "minus"):
        values = np.asarray(dataset[f"response_impact_{root}"].values[0], dtype=float)
        stable = np.asarray(dataset[f"response_impact_{root}_stable"].values[0]) == 1
        impacting = np.fmax(impacting, np.where(stable, values, np.nan))
    over = near & (impacting > limit)
    if not np.any(over):
        return ""
    i = int(np.flatnonzero(over)[np.argmax(impacting[over])])
    share = 100.0 * (f[i] - at) / at
    return (f"At {fmt(f[i], '.4g')} Hz, {fmt(abs(share), '.2g')} % {'below' if share < 0 else 'above'} the operating frequency, a stable impacting motion of the recommended design "
            f"reaches {c.text(float(impacting[i]))} against the allowed {c.text(limit)}: a drift of the operating speed by that much can land on it.")


def cautions(dataset: xr.Dataset) -> list[str]:
    """The recommended design's cautions (module docstring), each a sentence; empty where it has none (or the
    study recommended nothing)."""
    if int(dataset.attrs.get("recommended_evaluation", -1)) < 0:
        return []
    out = []
    bounds = at_bounds(dataset)
    if bounds:
        out.append(f"The recommended design sits on a bound of the range searched{bounds}: the best design may lie beyond it; widen the range to know.")
    out += _clipped(dataset)
    nearby = _nearby_impacts(dataset)
    if nearby:
        out.append(nearby)
    return out
