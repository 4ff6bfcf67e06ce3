"""Layout scalars as parameters of an :class:`~vibroimpact.orbits.maps.ImpactMap`: any entry of the structure's
matrices, a spring or dashpot of it, the named system's m1 ... b2, and the bumpers' stiffness.

A name says which scalar (coordinates by name, e.g. ``x1``, or by index, e.g. ``0``)::

    mass[a]  mass[a,b]           M[a, a], M[a, b] = M[b, a]                       [kg]
    stiffness[a]  stiffness[a,b]  K[a, a], K[a, b] = K[b, a]                       [N m-1]
    damping[a]  damping[a,b]      C[a, a], C[a, b] = C[b, a]                       [N s m-1]
    spring[a,b]  dashpot[a,b]     the element between a and b: -K[a, b], -C[a, b]   [N m-1], [N s m-1]
    spring[a]  dashpot[a]         the element from a to the ground: sum_j K[a, j]   [N m-1], [N s m-1]
    m1 m2 k1 k2 b1 b2             the paper's named system (its own fields)
    bumper_stiffness              K_b = m_k Omega_b^2 of the selected stops' bumpers [N m-1]

Setting an entry sets its symmetric twin; setting an element by d changes the entries it occupies (K[a, a] and
K[b, b] by +d, K[a, b] and K[b, a] by -d; a ground element only K[a, a]), so that the other elements stay; m1 ... b2
are these elements of the paper's chain (:meth:`~vibroimpact.model.system.TwoDofSystem.of` is its named view). At a
parameter's own value the problem is the base problem, bit for bit.

A bumper is a part with a stiffness K_b [N m-1] and damping B_b [N s m-1] (the laws store Omega_b and xi_b with the
stop's effective mass m_k, K_b = m_k Omega_b^2, B_b = 2 m_k xi_b Omega_b): when a structural parameter changes m_k,
each bumper keeps its K_b and B_b. ``bumper_stiffness`` keeps the bumpers' loss factor, hence their restitution.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from vibroimpact.model.contact import KelvinVoigtBumper
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.structure import LinearStructure
from vibroimpact.model.system import TwoDofSystem

__all__ = ["LayoutParameter", "layout_parameter", "with_layout", "check_independent", "BUMPER_STIFFNESS", "NAMED_SYSTEM"]

#: The bumpers' stiffness K_b [N m-1].
BUMPER_STIFFNESS = "bumper_stiffness"
#: The paper's named parameters, as elements of the general grammar (their units follow).
NAMED_SYSTEM = {"m1": "mass[x1]", "m2": "mass[x2]", "k1": "spring[x1]", "k2": "spring[x1,x2]", "b1": "dashpot[x1]", "b2": "dashpot[x1,x2]"}
_MATRIX = {"mass": "mass", "stiffness": "stiffness", "damping": "damping", "spring": "stiffness", "dashpot": "damping"}
_UNITS = {"mass": "kg", "stiffness": "N m-1", "damping": "N s m-1"}
_GRAMMAR = re.compile(r"^(mass|stiffness|damping|spring|dashpot)\[\s*(\w+)\s*(?:,\s*(\w+)\s*)?\]$")
_FORMS = "mass[a], mass[a,b], stiffness[a(,b)], damping[a(,b)], spring[a(,b)], dashpot[a(,b)], m1 ... b2 (the named system), bumper_stiffness"


@dataclass(frozen=True)
class LayoutParameter:
    """One layout scalar (module docstring).

    Attributes
    ----------
    name : str
        As given (the map's parameter name).
    matrix : str
        ``mass``, ``stiffness``, ``damping``, or ``bumper`` for the bumpers' stiffness.
    element : bool
        A spring or dashpot (an element of the structure) rather than a matrix entry.
    indices : tuple of int
        (a, b) coordinates; (a, a) for a diagonal entry; (a,) for a ground element; () for the bumpers.
    unit : str
        [kg], [N m-1] or [N s m-1].
    """

    name: str
    matrix: str
    element: bool
    indices: tuple[int, ...]
    unit: str

    @property
    def structural(self) -> bool:
        """It changes the structure (not the bumpers)."""
        return self.matrix != "bumper"

    def value(self, problem: ImpactProblem, stops: Sequence[int]) -> float:
        """Its value in ``problem`` [its unit]; ``stops``: the bumpers ``bumper_stiffness`` belongs to."""
        if not self.structural:
            return _bumper_stiffness(problem, stops[0])
        matrix = _matrices(problem.system)[self.matrix]
        if not self.element:
            return float(matrix[self.indices[0], self.indices[-1]])
        return _element_value(self, matrix)


def layout_parameter(name: str, problem: ImpactProblem) -> LayoutParameter:
    """The layout scalar ``name`` of ``problem`` (module docstring for the grammar).

    Raises
    ------
    ValueError
        A name outside the grammar, a coordinate the structure does not have, an element of a coordinate with
        itself, ``bumper_stiffness`` on rigid stops, or m1 ... b2 on a structure that is not the paper's.
    """
    if name == BUMPER_STIFFNESS:
        if not all(isinstance(item.law, KelvinVoigtBumper) for item in problem.stops):
            raise ValueError(f"parameter {name!r}: the problem's stops are not Kelvin-Voigt bumpers")
        return LayoutParameter(name, "bumper", False, (), "N m-1")
    text = name
    if name in NAMED_SYSTEM:
        if TwoDofSystem.of(problem.structure) is None:
            raise ValueError(f"parameter {name!r} names a field of the paper's two-mass system; this structure is not one: use {_FORMS.split(', m1')[0]}")
        text = NAMED_SYSTEM[name]
    match = _GRAMMAR.match(text.replace(" ", ""))
    if match is None:
        raise ValueError(f"parameter {name!r} is not a layout scalar: allowed {_FORMS}")
    kind, first, second = match.groups()
    names = tuple(problem.structure.coordinates)
    indices = tuple(_coordinate(name, token, names) for token in (first, second) if token is not None)
    element = kind in ("spring", "dashpot")
    if element and len(indices) == 2 and indices[0] == indices[1]:
        raise ValueError(f"parameter {name!r}: an element joins two different coordinates (or one and the ground: {kind}[{first}])")
    if not element and len(indices) == 1:
        indices = (indices[0], indices[0])
    matrix = _MATRIX[kind]
    return LayoutParameter(name, matrix, element, indices, _UNITS[matrix])


def check_independent(parameters: Sequence[LayoutParameter]) -> None:
    """``ValueError`` naming two layout scalars that are not independent: one scalar named twice (``k2`` and
    ``spring[x1,x2]``), or a matrix entry that another parameter also sets (``stiffness[x1,x2]`` and ``k2``). Elements
    are independent of one another (``k1`` and ``k2`` share K[0, 0] as a sum)."""
    for i, first in enumerate(parameters):
        for second in parameters[:i]:
            same = first.matrix == second.matrix and (first.element, first.indices) == (second.element, second.indices)
            shared = first.matrix == second.matrix and not (first.element and second.element) and bool(_entries(first) & _entries(second))
            if same or shared:
                raise ValueError(f"layout: {second.name!r} and {first.name!r} set the same {first.matrix} entries; continue in one of them")


def _entries(item: LayoutParameter) -> set[tuple[int, int]]:
    """The matrix entries (upper triangle) a structural scalar sets."""
    if len(item.indices) == 1:
        return {(item.indices[0], item.indices[0])}
    if not item.indices:
        return set()
    a, b = sorted(item.indices)
    return {(a, a), (b, b), (a, b)} if item.element else {(a, b)}


def with_layout(problem: ImpactProblem, parameters: Sequence[LayoutParameter], values: NDArray[np.float64] | Sequence[float], stops: Sequence[int]) -> ImpactProblem:
    """``problem`` with each layout scalar at its value (the bumpers of ``stops`` for ``bumper_stiffness``).

    Raises
    ------
    ValueError
        A structure the model refuses (a non-positive mass, an indefinite matrix ...), a non-positive bumper stiffness.
    """
    values = [float(v) for v in values]
    structural = [(item, v) for item, v in zip(parameters, values) if item.structural and item.value(problem, stops) != v]  # exact: its own value keeps the problem bit for bit
    bumper = [v for item, v in zip(parameters, values) if not item.structural]
    result = problem
    if bumper and bumper[0] != _bumper_stiffness(problem, stops[0]):  # exact: likewise
        if not bumper[0] > 0.0:
            raise ValueError(f"{BUMPER_STIFFNESS} = {bumper[0]!r} N/m is out of range: allowed (0, inf)")
        result = _with_bumper_stiffness(result, bumper[0], stops)
    if structural:
        result = _with_structure(result, _structure(result.system, structural))
    return result


def _coordinate(name: str, token: str, names: tuple[str, ...]) -> int:
    if token in names:
        return names.index(token)
    if token.isdigit() and int(token) < len(names):
        return int(token)
    raise ValueError(f"parameter {name!r}: {token!r} is not a coordinate of the structure: allowed {', '.join(names)} or 0 ... {len(names) - 1}")


def _matrices(system: object) -> dict[str, NDArray[np.float64]]:
    return {"mass": system.mass_matrix, "stiffness": system.stiffness_matrix, "damping": system.damping_matrix}  # type: ignore[attr-defined]


def _structure(system: LinearStructure, changes: list[tuple[LayoutParameter, float]]) -> LinearStructure:
    """The structure with the changed scalars."""
    matrices = {key: np.array(value, dtype=float) for key, value in _matrices(system).items()}
    for item, v in changes:
        matrix = matrices[item.matrix]
        if not item.element:
            a, b = item.indices
            matrix[a, b] = matrix[b, a] = v
            continue
        d = v - _element_value(item, matrix)
        a = item.indices[0]
        matrix[a, a] += d
        if len(item.indices) == 2:
            b = item.indices[1]
            matrix[b, b] += d
            matrix[a, b] -= d
            matrix[b, a] -= d
    return LinearStructure(mass=matrices["mass"], stiffness=matrices["stiffness"], damping=matrices["damping"], coordinates=tuple(system.coordinates))


def _element_value(item: LayoutParameter, matrix: NDArray[np.float64]) -> float:
    if len(item.indices) == 1:
        return float(np.sum(matrix[item.indices[0]]))
    return -float(matrix[item.indices[0], item.indices[1]])


def _with_structure(problem: ImpactProblem, system: LinearStructure) -> ImpactProblem:
    """``problem`` on another structure of the same coordinates, each bumper keeping its K_b and B_b [SI]."""
    old, new = problem.structure.mass_matrix, system.mass_matrix
    stops = []
    for item in problem.stops:
        if isinstance(item.law, KelvinVoigtBumper):
            ratio = item.effective_mass(old) / item.effective_mass(new)  # m_k / m_k'
            law = KelvinVoigtBumper(item.law.clearance, item.law.frequency * math.sqrt(ratio), item.law.loss_factor * math.sqrt(ratio))
            item = dataclasses.replace(item, law=law)
        stops.append(item)
    return ImpactProblem(system, tuple(stops), problem.excitation)


def _bumper_stiffness(problem: ImpactProblem, stop: int) -> float:
    item = problem.stops[stop]
    return float(item.law.stiffness(item.effective_mass(problem.structure.mass_matrix)))  # type: ignore[union-attr]


def _with_bumper_stiffness(problem: ImpactProblem, stiffness: float, stops: Sequence[int]) -> ImpactProblem:
    """The bumpers of ``stops`` with K_b = ``stiffness`` [N m-1], their loss factors kept."""
    mass = problem.structure.mass_matrix
    changed = []
    for k, item in enumerate(problem.stops):
        if k in stops:
            frequency = math.sqrt(stiffness / item.effective_mass(mass)) / (2.0 * math.pi)
            item = dataclasses.replace(item, law=dataclasses.replace(item.law, frequency=frequency))
        changed.append(item)
    return ImpactProblem(problem.system, tuple(changed), problem.excitation)
