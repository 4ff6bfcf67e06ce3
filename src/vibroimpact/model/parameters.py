"""The parameter table: every scalar a study may vary, declared once (name, unit, long name, allowed range, how a
mistuning spreads it), and any layout scalar as a value one can read from and set on a problem.

Scene sweeps (:data:`vibroimpact.scene.schema.SWEEPABLE`), the datasets' coordinates, the impact map's parameters
(:data:`vibroimpact.orbits.maps.PARAMETERS`), design variables and mistuning read :data:`PARAMETERS` and
:func:`parameter`; a new kind of scalar is one row here. The named scalars::

    frequency           f of the harmonic force                              [Hz]     (0, inf)
    amplitude           its amplitude q                                      [N]      (-inf, inf)
    phase               its phase                                            [rad]    (-inf, inf)
    restitution         the stops' restitution R                             [1]      [0, 1]
    clearance           the stops' clearance Delta                           [m]      (-inf, inf)
    bumper_frequency    a bumper's Omega_b / 2 pi                            [Hz]     (0, 1e6]
    bumper_loss_factor  a bumper's xi_b                                      [1]      [0, 1e3]
    bumper_stiffness    K_b = m_k Omega_b^2 of the selected stops' bumpers   [N m-1]  (0, inf)

and every layout scalar of the structure's matrices, by the grammar below (its unit follows its matrix, its range
(0, inf), a dashpot's [0, inf)). A mistuning spreads a structural scalar (and a bumper's stiffness or frequency)
relatively, at most +-50 %, and the stops' clearance and restitution absolutely.

A layout scalar's name says which scalar (coordinates by name, e.g. ``x1``, or by index, e.g. ``0``)::

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

from vibroimpact.model.contact import MAX_LOSS_FACTOR, KelvinVoigtBumper
from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.structure import LinearStructure
from vibroimpact.model.system import TwoDofSystem

__all__ = ["Parameter", "PARAMETERS", "parameter", "MAX_RELATIVE_SPREAD", "MAX_BUMPER_FREQUENCY", "LayoutParameter", "layout_parameter",
           "with_layout", "check_independent", "BUMPER_STIFFNESS", "NAMED_SYSTEM", "LAYOUT_FORMS"]

#: The bumpers' stiffness K_b [N m-1].
BUMPER_STIFFNESS = "bumper_stiffness"
#: Largest relative mistuning of a scalar (0.5: +-50 %) [-].
MAX_RELATIVE_SPREAD = 0.5
#: Stiffest bumper a scene may ask for [Hz] (tested to 100 kHz; contact then lasts microseconds). A structure may
#: refuse a softer one: :func:`vibroimpact.model.bumper_limit.bumper_refusal`.
MAX_BUMPER_FREQUENCY = 1e6


@suggest_keywords
@dataclass(frozen=True)
class Parameter:
    """One scalar a study may vary: a row of the parameter table (module docstring).

    Attributes
    ----------
    name : str
        Its name in scenes, datasets and maps.
    unit : str
        UDUNITS string.
    long_name : str
        What it is, for datasets and pages.
    low, high : float
        Its allowed range [unit].
    low_inclusive, high_inclusive : bool
        Whether ``low`` and ``high`` are allowed.
    relative_spread : bool
        A mistuning spreads it relatively (a fraction of its value, at most :data:`MAX_RELATIVE_SPREAD`), else by an
        absolute offset [unit] (at most the width of its range).
    """

    name: str
    unit: str
    long_name: str
    low: float
    high: float
    low_inclusive: bool = False
    high_inclusive: bool = True
    relative_spread: bool = True

    def __post_init__(self) -> None:
        if not self.low < self.high:
            raise ValueError(f"parameter {self.name!r}: its range [{self.low!r}, {self.high!r}] must have low < high")

    @property
    def spread_limit(self) -> float:
        """The largest mistuning spread: relative [-] or absolute [unit]."""
        return MAX_RELATIVE_SPREAD if self.relative_spread else self.high - self.low

    def allows(self, value: float) -> bool:
        """``value`` is in the parameter's range."""
        above = value >= self.low if self.low_inclusive else value > self.low
        below = value <= self.high if self.high_inclusive else value < self.high
        return bool(above and below)

    def clip(self, value: float) -> float:
        """``value`` brought into the closed range [low, high]."""
        return min(max(value, self.low), self.high)


_MATRIX_NAMES = {"mass": "mass", "stiffness": "stiffness", "damping": "damping", "spring": "stiffness", "dashpot": "damping"}
#: The named scalars (module docstring); a layout scalar's row is made by :func:`parameter`.
PARAMETERS: dict[str, Parameter] = {
    item.name: item
    for item in (
        Parameter("frequency", "Hz", "excitation frequency", 0.0, math.inf, high_inclusive=False),
        Parameter("amplitude", "N", "amplitude of the harmonic force", -math.inf, math.inf, high_inclusive=False),
        Parameter("phase", "rad", "phase of the harmonic force", -math.inf, math.inf, high_inclusive=False, relative_spread=False),
        Parameter("restitution", "1", "restitution ratio R", 0.0, 1.0, low_inclusive=True, relative_spread=False),
        Parameter("clearance", "m", "clearance Delta between absorber and stop", -math.inf, math.inf, high_inclusive=False, relative_spread=False),
        Parameter("bumper_frequency", "Hz", "apparent natural frequency Omega_b / 2 pi of the compliant bumper", 0.0, MAX_BUMPER_FREQUENCY),
        Parameter("bumper_loss_factor", "1", "loss factor xi_b of the compliant bumper", 0.0, MAX_LOSS_FACTOR, low_inclusive=True),
        Parameter(BUMPER_STIFFNESS, "N m-1", "stiffness K_b = m_k Omega_b^2 of the compliant bumpers", 0.0, math.inf, high_inclusive=False),
    )
}


@suggest_keywords
def parameter(name: str, problem: ImpactProblem | None = None) -> Parameter:
    """The table's row of ``name``: a named scalar, or a layout scalar by the grammar (module docstring).

    Parameters
    ----------
    name : str
        A name of :data:`PARAMETERS` or a layout scalar (``k2``, ``spring[x1,x2]``, ``mass[x3]`` ...).
    problem : ImpactProblem, optional
        Resolves a layout scalar's coordinates (and checks that the structure has them); without it only the form of
        the name is checked.

    Raises
    ------
    ValueError
        A name that is neither, naming the allowed forms; a layout scalar the problem's structure does not have.
    """
    if name in PARAMETERS:
        return PARAMETERS[name]
    text = NAMED_SYSTEM.get(name, name).replace(" ", "")
    match = _GRAMMAR.match(text)
    if match is None:
        raise ValueError(f"unknown parameter {name!r}: allowed {', '.join(PARAMETERS)}, or a layout scalar ({_FORMS})")
    if problem is not None:
        layout_parameter(name, problem)
    kind, first, second = match.groups()
    matrix = _MATRIX_NAMES[kind]
    off_diagonal = kind in ("mass", "stiffness", "damping") and second is not None and second != first
    damping = matrix == "damping"
    low = -math.inf if off_diagonal else 0.0
    return Parameter(name, _UNITS[matrix], f"layout scalar {name}" + (f" = {text}" if name != text else ""), low, math.inf, low_inclusive=damping and not off_diagonal, high_inclusive=False)
#: The paper's named parameters, as elements of the general grammar (their units follow).
NAMED_SYSTEM = {"m1": "mass[x1]", "m2": "mass[x2]", "k1": "spring[x1]", "k2": "spring[x1,x2]", "b1": "dashpot[x1]", "b2": "dashpot[x1,x2]"}
_UNITS = {"mass": "kg", "stiffness": "N m-1", "damping": "N s m-1"}
_GRAMMAR = re.compile(r"^(mass|stiffness|damping|spring|dashpot)\[\s*(\w+)\s*(?:,\s*(\w+)\s*)?\]$")
#: A layout scalar's name, as a scene writes it (spaces allowed): the grammar's forms and the named system's.
LAYOUT_FORMS = re.compile(r"^(m1|m2|k1|k2|b1|b2|(mass|stiffness|damping|spring|dashpot)\[\s*\w+\s*(,\s*\w+\s*)?\])$")
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
    matrix = _MATRIX_NAMES[kind]
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
