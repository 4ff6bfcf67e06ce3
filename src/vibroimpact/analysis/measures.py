"""The measure table: what a worst case judges, declared once (name, unit, long name), and how it is read from each
kind of result.

A measure is named as a scene's objective names it:

* ``<coordinate>_amplitude``: the fundamental-harmonic amplitude |X_k| of a coordinate's displacement [m]
  (``x1_amplitude`` the primary mass on the paper's layout);
* ``force_amplitude``: the fundamental-harmonic amplitude of the force transmitted to the base [N], through the
  springs and dashpots to the ground and the stops against the base (suspension plus impacts, eq. 23), by the one
  base-force formula (:func:`vibroimpact.analysis.linear.base_force`).

Each reads the fundamentals a method has: :meth:`Measure.of_harmonics` complex amplitudes of the coordinates [m] and
of the stops' contact forces [N] (a linear state, an engine's per-period moments), :meth:`Measure.of_orbit` a
closed-form impact orbit, :meth:`Measure.of_shot` a shot or continued orbit's measured fundamentals,
:meth:`Measure.of_state` one linear state. A measure is linear in the fundamentals, so a method may hand it unscaled
moments and scale the value after. Every band-maximum method (:data:`vibroimpact.measures.worst_case.METHODS`) reads
the measure it is handed.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from vibroimpact.analysis.linear import base_force
from vibroimpact.model.excitation import HarmonicForce

__all__ = ["Measure", "measure", "measure_names", "as_measure", "symbol_of", "AMPLITUDE", "BASE_FORCE"]

#: The form of a displacement-amplitude measure's name.
AMPLITUDE = re.compile(r"^(?P<coordinate>\w+)_amplitude$")
#: The name of the force transmitted to the base.
BASE_FORCE = "force_amplitude"


@dataclass(frozen=True)
class Measure:
    """One measure of a motion (module docstring).

    Attributes
    ----------
    name : str
        As a scene writes it (``x2_amplitude``, ``force_amplitude``).
    unit : str
        UDUNITS string.
    long_name : str
        What it is, for datasets and pages.
    coordinate : int or None
        The coordinate whose displacement it reads; None: the force transmitted to the base.
    """

    name: str
    unit: str
    long_name: str
    coordinate: int | None = None

    def __post_init__(self) -> None:
        if self.coordinate is not None and self.coordinate < 0:
            raise ValueError(f"measure {self.name!r}: coordinate = {self.coordinate!r} must be an index >= 0")

    @property
    def symbol(self) -> str:
        """How datasets and pages write it (:func:`symbol_of`): ``|X1|``, ``|F|``."""
        return symbol_of(self.name)

    def refusal(self, problem: Any) -> str | None:
        """Why this measure cannot be read on ``problem`` (None: it can): a coordinate the structure lacks; the base
        force of a base-motion load (the coordinates move with the base: the force it carries is not this one)."""
        if self.coordinate is not None:
            return None if self.coordinate < problem.size else f"measure {self.name!r}: coordinate {self.coordinate} is not one of the problem's {problem.size}"
        excitation = problem.excitation
        if isinstance(excitation, HarmonicForce) and excitation.base_motion:
            return f"measure {self.name!r}: the force to the base of a base-motion load is not defined by this measure (its coordinates move with the base)"
        return None

    def of_harmonics(self, problem: Any, omega: ArrayLike, x: ArrayLike, contact: ArrayLike | None = None) -> NDArray[np.float64]:
        """The measure from fundamentals: ``x`` (..., N) of the coordinates [m] and ``contact`` (..., K) of the stops'
        contact forces [N] (None: no contact) at angular frequencies ``omega`` [rad s-1] (broadcast with ``x``'s
        leading axes), or the same integrals unscaled (the measure is linear in them)."""
        if self.coordinate is not None:
            return np.abs(np.asarray(x)[..., self.coordinate])
        through = problem.normals().sum(axis=1) if contact is not None else None  # 1^T n_k: +1 upper, -1 lower, 0 relative
        return np.abs(base_force(problem.structure, omega, x, through, contact))

    def of_state(self, problem: Any, x: ArrayLike) -> float:
        """The measure of one contact-free (linear) steady state at ``problem``'s frequency: ``x`` (N,) its complex
        amplitudes [m] (no contact force); a Python float (the scalar complex modulus, as a single state's is taken
        everywhere else)."""
        if self.coordinate is not None:
            return abs(complex(np.asarray(x)[self.coordinate]))
        return abs(complex(base_force(problem.structure, problem.omega, x)))

    def of_shot(self, measured: Any) -> NDArray[np.float64]:
        """The measure of a shot orbit's :class:`~vibroimpact.orbits.orbit_measures.OrbitMeasures` (a float), or along a
        branch's :class:`~vibroimpact.orbits.orbit_measures.BranchMeasures` (one value per point)."""
        if self.coordinate is not None:
            return np.asarray(measured.amplitudes)[..., self.coordinate]
        return np.asarray(measured.base_force, dtype=float)

    def of_orbit(self, orbit: Any) -> NDArray[np.float64]:
        """The measure of a closed-form impact orbit (:class:`~vibroimpact.analysis.impact_orbit.ImpactOrbit`) at
        each of its points: |X_k| of its harmonics, or |F| of :meth:`~vibroimpact.analysis.impact_orbit.ImpactOrbit.
        base_force` (suspension plus the impulses' fundamental)."""
        if self.coordinate is not None:
            return np.abs(orbit.harmonics()[..., self.coordinate])
        return np.abs(orbit.base_force())


def symbol_of(name: str) -> str:
    """How datasets and pages write the measure ``name``: ``|F|`` for the force to the base, ``|X2|`` for
    ``x2_amplitude``, ``|<name>|`` for a general coordinate's (``|floor1|``).

    Raises
    ------
    ValueError
        A name that is neither ``force_amplitude`` nor ``<coordinate>_amplitude``.
    """
    if name == BASE_FORCE:
        return "|F|"
    match = AMPLITUDE.match(name)
    if match is None:
        raise ValueError(f"unknown measure {name!r}: allowed <coordinate>_amplitude or {BASE_FORCE}")
    digits = re.fullmatch(r"x(\d+)", match["coordinate"])
    return f"|X{digits[1]}|" if digits else f"|{match['coordinate']}|"


def measure_names(coordinates: Sequence[str]) -> tuple[str, ...]:
    """Every measure's name on a structure with these coordinates, in the table's order."""
    return (*(f"{name}_amplitude" for name in coordinates), BASE_FORCE)


def measure(name: str, coordinates: Sequence[str] = ("x1", "x2")) -> Measure:
    """The table's row of ``name`` on a structure with ``coordinates`` (default: the paper's x1, x2).

    Raises
    ------
    ValueError
        A name that is not a measure of this structure, naming the allowed ones.
    """
    if name == BASE_FORCE:
        return Measure(name, "N", "fundamental-harmonic amplitude of the force transmitted to the base (suspension plus impacts, eq. 23)")
    match = AMPLITUDE.match(name)
    if match is None or match["coordinate"] not in coordinates:
        raise ValueError(f"unknown measure {name!r}: allowed {', '.join(measure_names(coordinates))}")
    coordinate = match["coordinate"]
    return Measure(name, "m", f"fundamental-harmonic amplitude |X| of the displacement {coordinate}", tuple(coordinates).index(coordinate))


def as_measure(what: "int | Measure", problem: Any) -> Measure:
    """``what`` as a measure: a measure as it is, a coordinate index as its displacement amplitude on ``problem``."""
    if isinstance(what, Measure):
        return what
    names = tuple(problem.structure.coordinates)
    return measure(f"{names[int(what)]}_amplitude", names)
