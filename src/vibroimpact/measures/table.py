"""The measure table: what a worst case judges, declared once (name, unit, long name), and which coordinate's motion
it reads.

A measure is named as a scene's objective names it: ``<coordinate>_amplitude``, the fundamental-harmonic amplitude
|X_k| of a coordinate's displacement [m] (``x1_amplitude`` the primary mass on the paper's layout). Every band-maximum
method (:data:`vibroimpact.measures.worst_case.METHODS`) reads the measure it is handed: the closed forms from the
orbit's harmonics, shot and continued orbits from their exact per-period moments, brute force from each run's
per-period moments, a linear state from its complex amplitudes.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

__all__ = ["Measure", "measure", "measure_names", "AMPLITUDE"]

#: The form of a displacement-amplitude measure's name.
AMPLITUDE = re.compile(r"^(?P<coordinate>\w+)_amplitude$")


@dataclass(frozen=True)
class Measure:
    """One measure of a motion (module docstring).

    Attributes
    ----------
    name : str
        As a scene writes it (``x2_amplitude``).
    unit : str
        UDUNITS string.
    long_name : str
        What it is, for datasets and pages.
    coordinate : int
        The coordinate (index into the structure's) whose motion it reads.
    """

    name: str
    unit: str
    long_name: str
    coordinate: int

    def __post_init__(self) -> None:
        if self.coordinate < 0:
            raise ValueError(f"measure {self.name!r}: coordinate = {self.coordinate!r} must be an index >= 0")


def measure_names(coordinates: Sequence[str]) -> tuple[str, ...]:
    """Every measure's name on a structure with these coordinates, in the table's order."""
    return tuple(f"{name}_amplitude" for name in coordinates)


def measure(name: str, coordinates: Sequence[str] = ("x1", "x2")) -> Measure:
    """The table's row of ``name`` on a structure with ``coordinates`` (default: the paper's x1, x2).

    Raises
    ------
    ValueError
        A name that is not a measure of this structure, naming the allowed ones.
    """
    match = AMPLITUDE.match(name)
    if match is None or match["coordinate"] not in coordinates:
        raise ValueError(f"unknown measure {name!r}: allowed {', '.join(measure_names(coordinates))}")
    coordinate = match["coordinate"]
    return Measure(name, "m", f"fundamental-harmonic amplitude |X| of the displacement {coordinate}", tuple(coordinates).index(coordinate))
