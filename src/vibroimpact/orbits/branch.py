"""The vocabulary of the orbits layer: a parametrised map with its Jacobian, periodic orbits, special points, branches.

Everything in :mod:`vibroimpact.orbits` works on a :class:`ParametrisedMap`: ``y -> P(y; p)`` on R^n with a vector of
named parameters ``p``, returning the image, the exact Jacobian dP/dy and, when it has it cheaply, dP/dp. A map of a
hybrid (impacting) system adds a :class:`HybridInfo`: how many impacts the image's flight had, the slowest of them,
the closest approach of a free flight to the stop and the number of sticking phases. Smooth toy maps (logistic,
Henon, ...) leave it ``None``. A period-k orbit is a fixed point of ``Iterated(map, k)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "HybridInfo",
    "MapEvaluation",
    "ParametrisedMap",
    "Iterated",
    "PeriodicOrbit",
    "SpecialPoint",
    "Branch",
    "SPECIAL_POINT_KINDS",
    "lower_period_maps",
]

#: Kinds of special points, in the order of the CF flags of the output contract.
SPECIAL_POINT_KINDS = ("fold", "period_doubling", "neimark_sacker", "grazing")


@dataclass(frozen=True)
class HybridInfo:
    """What a hybrid map's flight did between its argument and its image.

    Attributes
    ----------
    impacts : int
        Impacts during the flight (all k periods of an iterated map).
    min_impact_velocity : float
        Slowest approach velocity of those impacts [m s-1]; +inf when there is none.
    closest_approach : float
        Largest X2 - Delta at an interior local maximum of a free flight [m] (<= 0); -inf when there is none.
    sticks : int
        Impacts that ended in sticking.
    length_scale : float
        Length that makes ``closest_approach`` dimensionless [m] (Delta + q |H12|).
    velocity_scale : float
        Velocity that makes ``min_impact_velocity`` dimensionless [m s-1] (w times ``length_scale``).
    onset_depth : float or None
        Compliant stops (bumpers): the smallest depth beyond the surface the free flight ending at a contact onset
        would have reached, v^2 / (2 max(-d'', 0)) with v the entry speed and d'' the flight's acceleration towards
        the surface there [m] (+inf without such an onset). A soft contact hardly deflects a flight that touches it
        slowly, so near tangency v grows as the square root of the distance to it and this depth linearly: the
        mirror of ``closest_approach`` across the tangency. None for rigid stops.
    """

    impacts: int
    min_impact_velocity: float
    closest_approach: float
    sticks: int = 0
    length_scale: float = 1.0
    velocity_scale: float = 1.0
    onset_depth: float | None = None

    def then(self, other: "HybridInfo") -> "HybridInfo":
        """The information of this flight followed by ``other`` (impacts and sticks add, extremes combine)."""
        return HybridInfo(
            self.impacts + other.impacts,
            min(self.min_impact_velocity, other.min_impact_velocity),
            max(self.closest_approach, other.closest_approach),
            self.sticks + other.sticks,
            self.length_scale,
            self.velocity_scale,
            None if self.onset_depth is None or other.onset_depth is None else min(self.onset_depth, other.onset_depth),
        )

    @property
    def speed_margin(self) -> float:
        """The contact side's scaled distance to grazing, >= 0: ``min_impact_velocity / velocity_scale`` (rigid stops),
        ``onset_depth / length_scale`` (bumpers)."""
        if self.onset_depth is None:
            return self.min_impact_velocity / self.velocity_scale
        return self.onset_depth / self.length_scale

    @property
    def signature(self) -> tuple[int, int]:
        """(impacts, sticks): what must stay constant along a smooth piece of a branch."""
        return (self.impacts, self.sticks)


@dataclass(frozen=True, eq=False)
class MapEvaluation:
    """One evaluation of a parametrised map.

    Attributes
    ----------
    image : ndarray, shape (n,)
        P(y; p).
    jacobian : ndarray, shape (n, n)
        dP/dy at (y, p), exact.
    parameter_jacobian : ndarray, shape (n, m) or None
        dP/dp for every parameter, or None when the map has no cheap derivative (then finite differences are used).
    hybrid : HybridInfo or None
        What the flight did (hybrid maps only).
    """

    image: NDArray[np.float64]
    jacobian: NDArray[np.float64]
    parameter_jacobian: NDArray[np.float64] | None = None
    hybrid: HybridInfo | None = None


@runtime_checkable
class ParametrisedMap(Protocol):
    """A map ``P(y; p)`` on R^n with m named parameters.

    Attributes
    ----------
    dimension : int
        n.
    parameter_names : tuple of str
        Names of the m parameters, in the order of ``p``.
    state_scale : ndarray, shape (n,)
        Typical size of each state component: continuation measures arclength in ``y / state_scale``.
    parameter_scale : ndarray, shape (m,)
        Typical change of each parameter over a branch, the same for ``p / parameter_scale``.
    """

    dimension: int
    parameter_names: tuple[str, ...]
    state_scale: NDArray[np.float64]
    parameter_scale: NDArray[np.float64]

    def evaluate(self, y: NDArray[np.float64], p: NDArray[np.float64]) -> MapEvaluation:
        """P(y; p), dP/dy, optionally dP/dp, and the hybrid information."""
        ...


class Iterated:
    """The k-th iterate ``P^k`` of a map, with the chain rule for its Jacobians (a period-k orbit is its fixed point).

    Parameters
    ----------
    base : ParametrisedMap
        The map P.
    times : int
        k >= 1.
    """

    def __init__(self, base: ParametrisedMap, times: int) -> None:
        if int(times) < 1:
            raise ValueError(f"times = {times!r} is out of range: allowed [1, inf)")
        while isinstance(base, Iterated):
            base, times = base.base, base.times * int(times)
        self.base, self.times = base, int(times)
        self.dimension = base.dimension
        self.parameter_names = base.parameter_names
        self.state_scale = base.state_scale
        self.parameter_scale = base.parameter_scale

    def evaluate(self, y: NDArray[np.float64], p: NDArray[np.float64]) -> MapEvaluation:
        """P^k(y; p) and its Jacobians by the chain rule."""
        out = self.base.evaluate(y, p)
        jacobian, dp, hybrid = out.jacobian, out.parameter_jacobian, out.hybrid
        for _ in range(self.times - 1):
            step = self.base.evaluate(out.image, p)
            if dp is not None and step.parameter_jacobian is not None:
                dp = step.jacobian @ dp + step.parameter_jacobian
            else:
                dp = None
            jacobian = step.jacobian @ jacobian
            hybrid = hybrid.then(step.hybrid) if hybrid is not None and step.hybrid is not None else hybrid
            out = step
        return MapEvaluation(out.image, jacobian, dp, hybrid)

    def linear_orbit(self, p: NDArray[np.float64]) -> tuple[NDArray[np.float64], float] | None:
        """The base map's contact-free orbit (a fixed point of every iterate), None when it has none in closed form."""
        closed = getattr(self.base, "linear_orbit", None)
        return None if closed is None else closed(p)

    def resectioned(self, y: NDArray[np.float64], p: NDArray[np.float64]) -> object | None:
        """The base map's ``resectioned`` over all k iterations (None when the base map cannot move its strobe)."""
        move = getattr(self.base, "resectioned", None)
        return None if move is None else move(y, p, self.times)


def lower_period_maps(system: ParametrisedMap) -> list[tuple[int, ParametrisedMap]]:
    """The maps over each proper divisor d of ``system``'s period, largest d first: (d, P^d).

    ``system`` is a map of K underlying periods: ``Iterated(P, t)`` (K = t, or t times P's own ``periods`` when P
    has a ``with_periods`` method, as :class:`vibroimpact.orbits.maps.ImpactMap`), or such a map P itself. A fixed
    point of P^K that is also one of P^d has the smaller period d. Empty when K = 1.
    """
    base, times = (system.base, system.times) if isinstance(system, Iterated) else (system, 1)
    unit = int(getattr(base, "periods", 1)) if hasattr(base, "with_periods") else 1
    total = times * unit
    out: list[tuple[int, ParametrisedMap]] = []
    for d in range(total // 2, 0, -1):
        if total % d:
            continue
        if hasattr(base, "with_periods"):
            out.append((d, base.with_periods(d)))
        elif d % unit == 0:
            out.append((d, Iterated(base, d // unit) if d // unit > 1 else base))
    return out


@dataclass(frozen=True, eq=False)
class PeriodicOrbit:
    """A fixed point of ``P^k``: a period-k orbit of the underlying system.

    Attributes
    ----------
    state : ndarray, shape (n,)
        y* with P^k(y*) = y*.
    parameters : ndarray, shape (m,)
        The parameter vector p.
    parameter_names : tuple of str
        Names of ``parameters``.
    period : int
        k: map iterations (excitation periods) per orbit period.
    monodromy : ndarray, shape (n, n)
        dP^k/dy at the orbit.
    multipliers : ndarray of complex, shape (n,)
        Floquet multipliers, eigenvalues of ``monodromy`` sorted by decreasing modulus.
    hybrid : HybridInfo or None
        Impacts per orbit period etc. (hybrid maps only).
    residual : float
        max |P^k(y*) - y*| / state_scale at the returned state [-].
    residual_history : tuple of float
        Scaled residual at each Newton iterate.
    """

    state: NDArray[np.float64]
    parameters: NDArray[np.float64]
    parameter_names: tuple[str, ...]
    period: int
    monodromy: NDArray[np.float64]
    multipliers: NDArray[np.complex128]
    hybrid: HybridInfo | None = None
    residual: float = 0.0
    residual_history: tuple[float, ...] = ()

    @property
    def floquet_modulus(self) -> float:
        """Largest |multiplier| [-]."""
        return float(np.max(np.abs(self.multipliers)))

    @property
    def stable(self) -> bool:
        """All multipliers strictly inside the unit circle."""
        return self.floquet_modulus < 1.0

    @property
    def impacts(self) -> int:
        """Impacts per orbit period (0 for a map without hybrid information)."""
        return self.hybrid.impacts if self.hybrid is not None else 0

    def parameter(self, name: str) -> float:
        """The value of the parameter called ``name``."""
        return float(self.parameters[self.parameter_names.index(name)])


@dataclass(frozen=True, eq=False)
class SpecialPoint:
    """A located bifurcation or grazing point on a branch.

    Attributes
    ----------
    kind : str
        One of :data:`SPECIAL_POINT_KINDS`.
    orbit : PeriodicOrbit
        The orbit at the point (its multipliers are the point's multipliers).
    parameter : str
        The continued parameter.
    value : float
        Its value at the point.
    test_value : float
        The test function at the returned point (ideally 0).
    note : str
        What happens there (e.g. 'a new impact is born; the branch continues with 2 impacts per period').
    continues : bool or None
        Grazing only: a periodic orbit with the new impact count continues the branch beyond the point.
    impacts_after : int or None
        Grazing only: impact count of the orbit found beyond the point, if any.
    eigenvector : ndarray or None
        Period doubling: the eigenvector of the multiplier -1 (for branch switching).
    induced_by : float or None
        A fold, period doubling or Neimark-Sacker point found within 1e-3 of a contact onset's grazing on the way to
        it: the onset's parameter value [its unit]. Its multipliers jump there, so it solves no smooth extended system.
    """

    kind: str
    orbit: PeriodicOrbit
    parameter: str
    value: float
    test_value: float
    note: str = ""
    continues: bool | None = None
    impacts_after: int | None = None
    eigenvector: NDArray[np.float64] | None = None
    induced_by: float | None = None


@dataclass(frozen=True, eq=False)
class Branch:
    """A branch of periodic orbits continued in one parameter.

    Attributes
    ----------
    parameter : str
        The continued parameter.
    orbits : tuple of PeriodicOrbit
        The points in order of arclength.
    special_points : tuple of SpecialPoint
        Located folds, period doublings, Neimark-Sacker and grazing points, in order of arclength.
    end : str
        Why the continuation stopped: 'bound', 'grazing', 'max_steps', 'closed' (the branch returned to its start),
        'step_too_small', 'parent' (a period-K branch reached the lower-period orbit it was born from: the period
        doubling of its period-K/2 parent, or a K/d-tupling of a period-d orbit), 'clear' (a contact-free stretch
        left every stop behind).
    """

    parameter: str
    orbits: tuple[PeriodicOrbit, ...]
    special_points: tuple[SpecialPoint, ...] = ()
    end: str = ""

    @property
    def values(self) -> NDArray[np.float64]:
        """The continued parameter at each point."""
        return np.array([o.parameter(self.parameter) for o in self.orbits])

    @property
    def states(self) -> NDArray[np.float64]:
        """Orbit states, shape (points, n)."""
        return np.array([o.state for o in self.orbits])

    @property
    def multipliers(self) -> NDArray[np.complex128]:
        """Floquet multipliers, shape (points, n)."""
        return np.array([o.multipliers for o in self.orbits])

    @property
    def floquet_modulus(self) -> NDArray[np.float64]:
        """Largest |multiplier| at each point."""
        return np.array([o.floquet_modulus for o in self.orbits])

    @property
    def stable(self) -> NDArray[np.bool_]:
        """Stability of each point."""
        return self.floquet_modulus < 1.0

    @property
    def impacts(self) -> NDArray[np.int_]:
        """Impacts per orbit period at each point."""
        return np.array([o.impacts for o in self.orbits], dtype=int)

    def special(self, kind: str) -> tuple[SpecialPoint, ...]:
        """The special points of one kind."""
        return tuple(s for s in self.special_points if s.kind == kind)
