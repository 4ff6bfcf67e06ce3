"""Contact laws: the rigid stop (:class:`RigidStop`) and the Kelvin-Voigt bumper of the seed paper's section 5 (eq. 25,
:class:`KelvinVoigtBumper`), and where a stop acts (:class:`Stop`).

One collision on a bumper (its restitution R(xi_b), its duration and its peak acceleration) is worked out in
:mod:`~vibroimpact.model.collision`, whose names are re-exported here.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Union

import numpy as np
from numpy.typing import NDArray

from vibroimpact.model.collision import (
    MAX_LOSS_FACTOR, MIN_BUMPER_RESTITUTION, loss_factor_from_restitution, paper_restitution, peak_acceleration_factor, release_time,
    restitution_from_loss_factor,
)  # fmt: skip
from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.model.units import length_text
from vibroimpact.model.structure import require_finite, require_in_range, require_non_negative, require_positive


if TYPE_CHECKING:
    from vibroimpact.model.system import TwoDofSystem

__all__ = [
    "RIGID",
    "BUMPER",
    "MAX_LOSS_FACTOR",
    "MIN_BUMPER_RESTITUTION",
    "Stop",
    "CoordinateRef",
    "default_coordinates",
    "SIDES",
    "check_room",
    "describe_place",
    "place_normal",
    "ContactLaw",
    "Impact",
    "KelvinVoigtBumper",
    "RigidStop",
    "place_effective_mass",
    "loss_factor_from_restitution",
    "paper_restitution",
    "peak_acceleration_factor",
    "release_time",
    "restitution_from_loss_factor",
]

#: The contact laws by name, the vocabulary of problems (:attr:`ImpactProblem.contact_law
#: <vibroimpact.model.problem.ImpactProblem.contact_law>`) and of the engines that solve them: the momentary-impact
#: stop (:class:`RigidStop`) and the Kelvin-Voigt bumper (:class:`KelvinVoigtBumper`).
RIGID, BUMPER = "rigid", "bumper"


@dataclass(frozen=True)
class Impact:
    """What one impact on a rigid stop does to the absorber.

    Attributes
    ----------
    velocity : float
        Approach speed X2'(t-) >= 0 [m s-1] (0: a touch, nothing is recorded).
    after : float
        X2'(t+) [m s-1]: -R X2'(t-), or 0 when the absorber sticks.
    sticks : bool
        The impact ends a chattering sequence: the absorber stays on the stop.
    impulse : float
        M2 (X2'(t-) - X2'(t+)) [N s]: M2 (1 + R) v, or M2 v when it sticks.
    """

    velocity: float
    after: float
    sticks: bool
    impulse: float


@suggest_keywords
@dataclass(frozen=True)
class RigidStop:
    """Momentary-impact stop: clearance Delta [m] (negative: a preloading stop) and restitution ratio R [-] in [0, 1].

    The stop bounds the absorber's displacement from above, X2 <= Delta. Its law, applied by every rigid-stop engine
    (the engines only find when the absorber reaches it and whether it pushes there):

    * an impact at approach speed v maps X2' to -R v, with impulse M2 (1 + R) v;
    * impacts slower than the sticking velocity, more of them than allowed in one period, or any impact with
      R = 0, are chattering: if the stop then pushes the absorber (holding force > 0), the absorber sticks, X2' = 0,
      impulse M2 v;
    * a stuck absorber is held by B2 X1' + K2 (X1 - Delta) and leaves when that force turns negative.
    """

    clearance: float = field(metadata={"units": "m"})
    restitution: float = field(metadata={"units": "1"})

    def __post_init__(self) -> None:
        require_finite("clearance", self.clearance)
        require_in_range("restitution", self.restitution, 0.0, 1.0)

    def holding_force(self, system: TwoDofSystem, x1: float | NDArray[np.float64], v1: float | NDArray[np.float64]) -> float | NDArray[np.float64]:
        """Force the stop must exert to hold the absorber at rest at X2 = Delta, B2 X1' + K2 (X1 - Delta) [N].

        Positive: the absorber is pushed into the stop (it sticks); it leaves when this turns negative.
        """
        return system.b2 * v1 + system.k2 * (x1 - self.clearance)

    def chatters(self, velocity: float, impacts: int, sticking_velocity: float, max_impacts: int) -> bool:
        """Is an impact at ``velocity`` [m s-1], the ``impacts``-th of its period, part of a chattering sequence?

        Slower than ``sticking_velocity`` [m s-1], more than ``max_impacts`` in the period, or R = 0.
        """
        return velocity <= sticking_velocity or impacts > max_impacts or self.restitution == 0.0

    def impact(self, mass: float, velocity: float, chattering: bool, pushed: Callable[[], bool]) -> Impact:
        """The impact of an absorber of ``mass`` M2 [kg] arriving at ``velocity`` >= 0 [m s-1].

        ``pushed()`` answers whether the stop must push to hold the absorber at rest here (the engine's own test:
        a root search on the exact flow, or the derivatives of the holding force); it is asked only when the impact
        is ``chattering`` (see :meth:`chatters`).
        """
        sticks = chattering and pushed()
        after = 0.0 if sticks else -self.restitution * velocity
        return Impact(velocity, after, sticks, mass * (velocity - after))


@suggest_keywords
@dataclass(frozen=True)
class KelvinVoigtBumper:
    """Visco-elastic bumper (eq. 25): clearance Delta [m], apparent natural frequency Omega_b / 2 pi [Hz] (:attr:`omega`
    is Omega_b [rad s-1]) and loss factor xi_b [-].

    Parameters
    ----------
    clearance : float
        Delta [m], >= 0.
    frequency : float
        Apparent natural frequency Omega_b / 2 pi [Hz], > 0.
    loss_factor : float
        xi_b [-], in [0, :data:`MAX_LOSS_FACTOR`] (overdamped bumpers, xi_b >= 1, are allowed).
    """

    clearance: float = field(metadata={"units": "m"})
    frequency: float = field(metadata={"units": "Hz"})
    loss_factor: float = field(metadata={"units": "1"})

    def __post_init__(self) -> None:
        require_finite("clearance", self.clearance)
        require_positive("frequency", self.frequency)
        if not require_non_negative("loss_factor", self.loss_factor) <= MAX_LOSS_FACTOR:
            raise ValueError(
                f"loss_factor = {self.loss_factor!r} is out of range: allowed [0, {MAX_LOSS_FACTOR:g}] (beyond it a bumper's slow "
                f"decay rate Omega_b / (2 xi_b) is lost to round-off beside its fast one, 2 xi_b Omega_b; its restitution is already "
                f"{restitution_from_loss_factor(MAX_LOSS_FACTOR):.2g} at {MAX_LOSS_FACTOR:g})")

    @classmethod
    def from_stiffness(
        cls, clearance: float, stiffness: float, effective_mass: float, damping: float | None = None, loss_factor: float | None = None
    ) -> KelvinVoigtBumper:
        """The bumper of stiffness K [N m-1] and damping B [N s m-1] (or loss factor xi_b [-]) on a stop of effective
        mass m_eff [kg] (:meth:`Stop.effective_mass`): Omega_b = sqrt(K / m_eff), xi_b = B / (2 m_eff Omega_b).

        The inverse of :meth:`stiffness` and :meth:`damping` at that mass, to round-off (a few ulp: the law keeps
        Omega_b / 2 pi, so K and B come back as m_eff (2 pi f)^2 and 2 m_eff xi_b (2 pi f)).

        Parameters
        ----------
        clearance : float
            Delta [m].
        stiffness : float
            K [N m-1], > 0.
        effective_mass : float
            m_eff [kg], > 0: the mass the stop feels, 1 / (n . M^-1 n) (M2 for the paper's stop).
        damping : float, optional
            B [N s m-1], >= 0. Give either ``damping`` or ``loss_factor``.
        loss_factor : float, optional
            xi_b [-], >= 0.

        Raises
        ------
        ValueError
            Naming the key out of range, or both (or neither) of ``damping`` and ``loss_factor``.
        """
        k = require_positive("stiffness", stiffness)
        mass = require_positive("effective_mass", effective_mass)
        if (damping is None) == (loss_factor is None):
            raise ValueError(f"damping = {damping!r}, loss_factor = {loss_factor!r}: give exactly one, damping [N s/m] in [0, inf) or loss_factor [-] in [0, inf)")
        frequency = math.sqrt(k / mass) / (2.0 * math.pi)
        if loss_factor is None:
            b = require_non_negative("damping", damping)
            loss_factor = b / (2.0 * mass * (2.0 * math.pi * frequency))  # the law's own Omega_b: damping(m) gives B back
        return cls(clearance, frequency, loss_factor)

    @property
    def omega(self) -> float:
        """Omega_b [rad s-1]."""
        return 2.0 * math.pi * self.frequency

    def stiffness(self, m2: float) -> float:
        """K = M2 Omega_b^2 [N m-1]."""
        return m2 * self.omega**2

    def damping(self, m2: float) -> float:
        """B = 2 M2 xi_b Omega_b [N s m-1]."""
        return 2.0 * m2 * self.loss_factor * self.omega

    def force(self, m2: float, x2: float, v2: float) -> float:
        """Contact force on the absorber (positive: pushing it back) [N]: eq. 25."""
        if x2 < self.clearance:
            return 0.0
        return max(self.stiffness(m2) * (x2 - self.clearance) + self.damping(m2) * v2, 0.0)

    @property
    def restitution(self) -> float:
        """Restitution ratio of one collision [-]."""
        return restitution_from_loss_factor(self.loss_factor)


# --------------------------------------------------------------------------------------------------------------------
# Where a stop acts: on one coordinate against the base (absolute) or between two coordinates (relative), on the
# upper or the lower side, with a contact law (:class:`RigidStop` or :class:`KelvinVoigtBumper`).
# --------------------------------------------------------------------------------------------------------------------

#: The contact laws a stop may have.
ContactLaw = Union[RigidStop, KelvinVoigtBumper]
#: Allowed sides.
SIDES = ("upper", "lower")


#: A coordinate as a :class:`Stop` takes it: its name (``"x2"``), or its 0-based index (an int).
CoordinateRef = Union[str, int]


def default_coordinates(size: int) -> tuple[str, ...]:
    """``x1, x2, ...``: the names of a structure's coordinates where it gives none (a bare mass matrix)."""
    return tuple(f"x{i + 1}" for i in range(size))


def _check_reference(key: str, value: object) -> None:
    if isinstance(value, str):
        if not value.isidentifier():
            raise ValueError(f"{key} = {value!r}: expected a coordinate's name (letters, digits and _, as 'x2') or a 0-based index >= 0")
    elif isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise ValueError(f"{key} = {value!r}: expected a coordinate's name (as 'x2') or a 0-based index >= 0")


def _resolve(key: str, value: CoordinateRef, names: tuple[str, ...]) -> int:
    if isinstance(value, str):
        if value not in names:
            raise ValueError(f"{key} = {value!r} is not a coordinate of the system: allowed {list(names)}")
        return names.index(value)
    return value


@suggest_keywords
@dataclass(frozen=True)
class Stop:
    """One stop of the structure.

    Parameters
    ----------
    law : RigidStop or KelvinVoigtBumper
        Contact law; it carries the clearance Delta [m] (any finite number; negative preloads).
    coordinate : str or int
        The stopped coordinate by name, as in scenes (``"x2"``: the structure's ``coordinates``, ``x1, x2, ...``
        unless it names them), or by its 0-based index where an int is given (``1`` is x2). A problem resolves a
        name against its structure (:meth:`resolve`; ``ValueError`` naming the allowed names).
    other : str, int or None
        For a relative stop, the second coordinate (name, or 0-based index): the gap is on x[coordinate] - x[other].
    side : {"upper", "lower"}
        ``upper``: x <= Delta; ``lower``: x >= -Delta.
    """

    law: ContactLaw
    coordinate: CoordinateRef = "x2"
    other: CoordinateRef | None = None
    side: str = "upper"

    def __post_init__(self) -> None:
        if not isinstance(self.law, (RigidStop, KelvinVoigtBumper)):
            raise TypeError(f"stop law = {self.law!r} is not allowed: expected a RigidStop or a KelvinVoigtBumper")
        _check_reference("stop coordinate", self.coordinate)
        if self.other is not None:
            _check_reference("stop between: second coordinate", self.other)
            if self.other == self.coordinate:  # exact: names or indices
                raise ValueError(f"stop between: the two coordinates must differ, got {self.coordinate!r} twice")
        if self.side not in SIDES:
            raise ValueError(f"stop side = {self.side!r} is not allowed: allowed {list(SIDES)}")

    @property
    def named(self) -> bool:
        """Is a coordinate given by name (not yet resolved to an index against a structure)?"""
        return isinstance(self.coordinate, str) or isinstance(self.other, str)

    def resolve(self, names: Sequence[str]) -> Stop:
        """The same stop with its coordinates as 0-based indices among ``names`` (the structure's coordinates);
        ``ValueError`` naming the allowed names for a name that is not one of them, or where the two coincide."""
        if not self.named:
            return self
        names = tuple(names)
        coordinate = _resolve("stop coordinate", self.coordinate, names)
        other = None if self.other is None else _resolve("stop between: second coordinate", self.other, names)
        return Stop(self.law, coordinate, other, self.side)

    def _indexed(self) -> Stop:
        if self.named:
            raise ValueError(f"stop coordinate = {self.coordinate!r}{'' if self.other is None else f', other = {self.other!r}'}: a name is known only "
                             "against a structure; ImpactProblem resolves it, or Stop.resolve(structure.coordinates)")  # fmt: skip
        return self

    @property
    def clearance(self) -> float:
        """Delta [m]."""
        return self.law.clearance

    @property
    def relative(self) -> bool:
        """Does the stop act between two coordinates?"""
        return self.other is not None

    @property
    def sign(self) -> float:
        """+1 for an upper stop, -1 for a lower one."""
        return 1.0 if self.side == "upper" else -1.0

    @property
    def rigid(self) -> bool:
        """Is the law a rigid (momentary-impact) stop?"""
        return isinstance(self.law, RigidStop)

    def check_size(self, size: int, key: str = "stops") -> None:
        """``ValueError`` naming ``key`` if a coordinate index is not below ``size`` (or a name is not resolved)."""
        for index in (self._indexed().coordinate, self.other):
            if index is not None and index >= size:
                raise ValueError(f"{key}: coordinate index {index} is out of range for a system of {size} coordinates: allowed [0, {size - 1}] "
                                 f"(an int is a 0-based index: 0 is x1, {size - 1} is x{size}; or give the name, 'x{size}')")

    @property
    def place(self) -> tuple[int, int | None, str]:
        """(coordinate, other, side) as 0-based indices: where the stop acts, without its law."""
        stop = self._indexed()
        return (stop.coordinate, stop.other, stop.side)  # type: ignore[return-value]

    def normal(self, size: int) -> NDArray[np.float64]:
        """n [-], shape (size,): the gap is Delta - n . x."""
        self.check_size(size)
        return place_normal(self.place, size)

    def selector(self, size: int) -> NDArray[np.float64]:
        """The stopped coordinate as weights: e_i, or e_i - e_j for a relative stop (sign of the upper side)."""
        return self.sign * self.normal(size)

    def effective_mass(self, mass_matrix: NDArray[np.float64]) -> float:
        """m_eff = 1 / (n^T M^-1 n) [kg]: the mass the stop feels (M2 for the paper's stop)."""
        self.check_size(mass_matrix.shape[0])
        return place_effective_mass(self.place, mass_matrix)

    @classmethod
    def bumper(
        cls, mass_matrix: NDArray[np.float64], clearance: float, stiffness: float, damping: float | None = None, loss_factor: float | None = None,
        coordinate: CoordinateRef = "x2", other: CoordinateRef | None = None, side: str = "upper", coordinates: Sequence[str] | None = None,
    ) -> Stop:  # fmt: skip
        """A stop with a Kelvin-Voigt bumper given in physical units on the structure of mass matrix M [kg]: stiffness
        K [N m-1] and damping B [N s m-1] (or loss factor xi_b [-]), converted with the stop's own effective mass
        (:meth:`KelvinVoigtBumper.from_stiffness`); ``coordinate``, ``other`` and ``side`` as for the class, names
        among ``coordinates`` (default ``x1, x2, ...``)."""
        names = default_coordinates(mass_matrix.shape[0]) if coordinates is None else tuple(coordinates)
        place = cls(RigidStop(clearance, 1.0), coordinate, other, side).resolve(names)  # validates where it acts
        place.check_size(mass_matrix.shape[0])
        coordinate, other = place.coordinate, place.other
        law = KelvinVoigtBumper.from_stiffness(clearance, stiffness, place.effective_mass(mass_matrix), damping, loss_factor)
        return cls(law, coordinate, other, side)

    def describe(self, names: tuple[str, ...]) -> str:
        """E.g. ``x2 <= 3 mm`` or ``x2 - x1 >= -3 mm``: the constraint in words, on coordinates called ``names``."""
        stop = self.resolve(names)
        stop.check_size(len(names))
        return describe_place(stop.place, self.clearance, names)


def place_normal(place: tuple[int, int | None, str], size: int) -> NDArray[np.float64]:
    """n [-], shape (size,), of a stop acting at ``place`` = (coordinate, other, side): e_i for an upper stop on x_i,
    e_i - e_j for an upper one on x_i - x_j, the opposite for a lower one; the gap is Delta - n . x."""
    coordinate, other, side = place
    sign = 1.0 if side == "upper" else -1.0
    n = np.zeros(size)
    n[coordinate] = sign
    if other is not None:
        n[other] = -sign
    return n


def place_effective_mass(place: tuple[int, int | None, str], mass_matrix: NDArray[np.float64]) -> float:
    """m_eff = 1 / (n^T M^-1 n) [kg] of a stop acting at ``place`` = (coordinate, other, side) on a structure of mass
    matrix M [kg]: the mass a bumper there pushes (M2 for the paper's stop, m_a m_b / (m_a + m_b) between two free
    masses of a diagonal M)."""
    n = place_normal(place, mass_matrix.shape[0])
    return float(1.0 / (n @ np.linalg.solve(mass_matrix, n)))


def describe_place(place: tuple[int, int | None, str], clearance: float, names: tuple[str, ...]) -> str:
    """E.g. ``x2 <= 3 mm`` or ``x2 - x1 >= -3 mm``: the constraint of a stop at ``place`` with clearance Delta [m]."""
    coordinate, other, side = place
    target = names[coordinate] if other is None else f"{names[coordinate]} - {names[other]}"
    bound = clearance if side == "upper" else -clearance
    relation = "<=" if side == "upper" else ">="
    return f"{target} {relation} {length_text(bound)}"  # in the clearance's own unit: "3 mm", "1 m"


def check_room(places: Sequence[tuple[int, int | None, str]], clearances: Sequence[float], names: tuple[str, ...]) -> None:
    """``ValueError`` if two stops on the same (relative) coordinate from opposite sides leave it no room: a question
    of where the stops act and of their clearances alone.

    Stop k allows n_k . x <= Delta_k; an opposite stop j (n_j = -c n_k, c > 0) allows n_k . x >= -Delta_j / c. The
    interval is empty, or a single point where the coordinate would be clamped by both at once, unless
    Delta_k + Delta_j / c > 0. A clearance that is not known (NaN) leaves its pairs unjudged.

    Parameters
    ----------
    places : sequence of (int, int or None, str)
        (coordinate, other, side) of every stop (:attr:`Stop.place`).
    clearances : sequence of float
        Delta of every stop [m].
    names : tuple of str
        The coordinates' names (the message describes the two stops with them).
    """
    size = len(names)
    for k, first in enumerate(places):
        nk = place_normal(first, size)
        for j in range(k + 1, len(places)):
            nj = place_normal(places[j], size)
            ratio = -float(nj @ nk) / float(nk @ nk)
            if ratio > 0.0 and np.allclose(nj, -ratio * nk, rtol=0.0, atol=1e-14) and clearances[k] + clearances[j] / ratio <= 0.0:
                raise ValueError(
                    f"stops: stop {k} ({describe_place(first, clearances[k], names)}) and stop {j} ({describe_place(places[j], clearances[j], names)}) "
                    "leave no room between them: two opposite stops need clearances whose sum is > 0"
                )
