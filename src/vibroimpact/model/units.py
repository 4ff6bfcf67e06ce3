"""Lengths in words: the unit a text writes a length in, chosen from its magnitude (a 1 m clearance is "1 m", a 3 mm
one "3 mm", a 50 um one "50 µm"), so that a structure of any size reads in its own units.
"""

from __future__ import annotations

import math

__all__ = ["LENGTH_UNITS", "length_unit", "length_text"]

#: (unit, metres per unit, smallest magnitude written in it [m]), largest first: metres from 1 m, millimetres from
#: 0.1 mm (the paper's 0.5-6 mm clearances stay in mm), micrometres below.
LENGTH_UNITS: tuple[tuple[str, float, float], ...] = (("m", 1.0, 1.0), ("mm", 1e-3, 1e-4), ("µm", 1e-6, 0.0))


def length_unit(magnitude: float) -> tuple[str, float]:
    """The unit of a length of about ``magnitude`` [m] and the factor from metres to it: ("mm", 1e3) for 3e-3,
    ("m", 1.0) for 1.0; mm for 0 and non-finite values."""
    size = abs(float(magnitude))
    if not math.isfinite(size) or size == 0.0:  # exact: no magnitude to choose from
        return "mm", 1e3
    unit, metres, _smallest = next(entry for entry in LENGTH_UNITS if size >= entry[2])
    return unit, 1.0 / metres


def length_text(value: float, spec: str = "g", magnitude: float | None = None) -> str:
    """``value`` [m] in words with its unit, chosen from ``magnitude`` [m] (default: the value's own): "3 mm", "1 m"."""
    unit, factor = length_unit(value if magnitude is None else magnitude)
    return f"{value * factor + 0.0:{spec}} {unit}"  # + 0.0: no "-0 mm"
