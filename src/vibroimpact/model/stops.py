"""Where a stop acts: on one coordinate against the base (absolute) or between two coordinates (relative), on the
upper or the lower side, with a contact law (:class:`RigidStop` or :class:`KelvinVoigtBumper`).

Every stop is described by a normal vector ``n`` over the coordinates and its clearance ``Delta`` [m]::

    gap g = Delta - n . x >= 0

* absolute upper stop on coordinate i:  n = e_i           (x_i <= Delta; the paper's stop, i = absorber)
* absolute lower stop on coordinate i:  n = -e_i          (x_i >= -Delta)
* relative upper stop ``between: [i, j]``: n = e_i - e_j  (x_i - x_j <= Delta; Ormondroyd & Den Hartog's 1928 stops)
* relative lower stop: n = e_j - e_i                      (x_i - x_j >= -Delta)

A negative clearance preloads the structure (the stop sits inside the unloaded position).

The contact force is ``-n lambda`` with ``lambda >= 0``: on a relative stop it acts on both bodies with opposite
signs, so their momentum is conserved. A rigid impact restitutes the gap velocity, n.x'(t+) = -R n.x'(t-), by the
impulse P = (1 + R) n.x'(t-) m_eff with the effective mass m_eff = 1 / (n^T M^-1 n); then x'(t+) = x'(t-) - M^-1 n P.
A bumper pushes with m_eff Omega_b^2 (-g) + 2 m_eff xi_b Omega_b (-g') while that is positive and the gap closed:
for the paper's layout m_eff = M2 and both laws are the paper's.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Union

import numpy as np
from numpy.typing import NDArray

from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop

__all__ = ["Stop", "SIDES", "ContactLaw"]

#: The contact laws a stop may have.
ContactLaw = Union[RigidStop, KelvinVoigtBumper]
#: Allowed sides.
SIDES = ("upper", "lower")


@dataclass(frozen=True)
class Stop:
    """One stop of the structure.

    Parameters
    ----------
    law : RigidStop or KelvinVoigtBumper
        Contact law; it carries the clearance Delta [m] (any finite number; negative preloads).
    coordinate : int
        Index of the stopped coordinate (0-based), >= 0.
    other : int or None
        For a relative stop, the index of the second coordinate: the gap is on x[coordinate] - x[other].
    side : {"upper", "lower"}
        ``upper``: x <= Delta; ``lower``: x >= -Delta.
    """

    law: ContactLaw
    coordinate: int = 1
    other: int | None = None
    side: str = "upper"

    def __post_init__(self) -> None:
        if not isinstance(self.law, (RigidStop, KelvinVoigtBumper)):
            raise TypeError(f"stop law = {self.law!r} is not allowed: expected a RigidStop or a KelvinVoigtBumper")
        if isinstance(self.coordinate, bool) or not isinstance(self.coordinate, int) or self.coordinate < 0:
            raise ValueError(f"stop coordinate = {self.coordinate!r}: expected an index >= 0")
        if self.other is not None:
            if isinstance(self.other, bool) or not isinstance(self.other, int) or self.other < 0:
                raise ValueError(f"stop between: second coordinate = {self.other!r}: expected an index >= 0")
            if self.other == self.coordinate:
                raise ValueError(f"stop between: the two coordinates must differ, got {self.coordinate} twice")
        if self.side not in SIDES:
            raise ValueError(f"stop side = {self.side!r} is not allowed: allowed {list(SIDES)}")

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
        """``ValueError`` naming ``key`` if a coordinate index is not below ``size``."""
        for index in (self.coordinate, self.other):
            if index is not None and index >= size:
                raise ValueError(f"{key}: coordinate index {index} is out of range for a system of {size} coordinates: allowed [0, {size - 1}]")

    def normal(self, size: int) -> NDArray[np.float64]:
        """n [-], shape (size,): the gap is Delta - n . x."""
        self.check_size(size)
        n = np.zeros(size)
        n[self.coordinate] = self.sign
        if self.other is not None:
            n[self.other] = -self.sign
        return n

    def selector(self, size: int) -> NDArray[np.float64]:
        """The stopped coordinate as weights: e_i, or e_i - e_j for a relative stop (sign of the upper side)."""
        return self.sign * self.normal(size)

    def effective_mass(self, mass_matrix: NDArray[np.float64]) -> float:
        """m_eff = 1 / (n^T M^-1 n) [kg]: the mass the stop feels (M2 for the paper's stop)."""
        n = self.normal(mass_matrix.shape[0])
        return float(1.0 / (n @ np.linalg.solve(mass_matrix, n)))

    def describe(self, names: tuple[str, ...]) -> str:
        """E.g. ``x2 <= 3 mm`` or ``x2 - x1 >= -3 mm``: the constraint in words."""
        self.check_size(len(names))
        target = names[self.coordinate] if self.other is None else f"{names[self.coordinate]} - {names[self.other]}"
        bound = self.clearance if self.side == "upper" else -self.clearance
        relation = "<=" if self.side == "upper" else ">="
        return f"{target} {relation} {bound * 1e3:g} mm"
