"""The problem an engine solves: a linear system, a contact law and an excitation.

:class:`ImpactProblem` composes the three validated parts and answers what the engines ask of them (clearance,
excitation frequency and period, force, a typical velocity). Each part validates itself; the problem only checks
that each is of a kind it knows. The contact law (:mod:`.contact`) owns where and how the stop acts, so a problem
with another stop (another coordinate, a second side) changes the contact and the flow, not every engine.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TypeVar, Union

import numpy as np
from numpy.typing import NDArray

from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop
from vibroimpact.model.excitation import HarmonicForce, SweptSine
from vibroimpact.model.system import TwoDofSystem

__all__ = ["Contact", "Excitation", "ImpactProblem"]

#: The contact laws a problem may have.
Contact = Union[RigidStop, KelvinVoigtBumper]
#: The excitations a problem may have.
Excitation = Union[HarmonicForce, SweptSine]

_Kind = TypeVar("_Kind")


def _part_of_kind(name: str, value: object, kind: type[_Kind], why: str) -> _Kind:
    """``value`` if it is a ``kind``, else ``TypeError`` naming the part and saying ``why`` it must be one."""
    if not isinstance(value, kind):
        raise TypeError(f"{name} = {value!r} is not a {kind.__name__}: {why}")
    return value


_PARTS = {"system": (TwoDofSystem,), "contact": (RigidStop, KelvinVoigtBumper), "excitation": (HarmonicForce, SweptSine)}


@dataclass(frozen=True)
class ImpactProblem:
    """The system of eq. 1 with a contact on the absorber and a force on the primary mass.

    Parameters
    ----------
    system : TwoDofSystem
        Masses, springs and dashpots.
    contact : RigidStop or KelvinVoigtBumper
        The momentary-impact stop (clearance, restitution) or the compliant bumper (clearance, frequency, loss factor).
    excitation : HarmonicForce or SweptSine
        q cos(w t + phase), or the linear swept sine of the paper's Simulink test.
    """

    system: TwoDofSystem
    contact: Contact
    excitation: Excitation

    def __post_init__(self) -> None:
        for name, kinds in _PARTS.items():
            value = getattr(self, name)
            if not isinstance(value, kinds):
                allowed = " or ".join(kind.__name__ for kind in kinds)
                raise TypeError(f"{name} = {value!r} is not allowed: expected a {allowed}")

    # ------------------------------------------------------------------ contact
    @property
    def clearance(self) -> float:
        """Delta [m]: where the contact begins."""
        return self.contact.clearance

    @property
    def rigid_stop(self) -> RigidStop:
        """The contact, which must be a :class:`RigidStop` (``TypeError`` naming the contact otherwise)."""
        return _part_of_kind("contact", self.contact, RigidStop, "a momentary-impact engine solves a rigid stop only")

    @property
    def bumper(self) -> KelvinVoigtBumper:
        """The contact, which must be a :class:`KelvinVoigtBumper` (``TypeError`` naming the contact otherwise)."""
        return _part_of_kind("contact", self.contact, KelvinVoigtBumper, "a compliant engine solves a bumper only")

    @property
    def restitution(self) -> float:
        """R [-] of the rigid stop."""
        return self.rigid_stop.restitution

    def holding_force(self, x1: float | NDArray[np.float64], v1: float | NDArray[np.float64]) -> float | NDArray[np.float64]:
        """Force the rigid stop must exert to hold the absorber at rest on it [N] (see :meth:`RigidStop.holding_force`)."""
        return self.rigid_stop.holding_force(self.system, x1, v1)

    # --------------------------------------------------------------- excitation
    @property
    def harmonic(self) -> HarmonicForce:
        """The excitation, which must be a :class:`HarmonicForce` (``TypeError`` naming it otherwise)."""
        return _part_of_kind("excitation", self.excitation, HarmonicForce, "a frequency, phase or period needs a harmonic force")

    @property
    def sweep(self) -> SweptSine:
        """The excitation, which must be a :class:`SweptSine` (``TypeError`` naming it otherwise)."""
        return _part_of_kind("excitation", self.excitation, SweptSine, "a sweeping engine runs a swept sine only")

    @property
    def amplitude(self) -> float:
        """q [N]."""
        return self.excitation.amplitude

    @property
    def frequency(self) -> float:
        """Excitation frequency f [Hz] of the harmonic force."""
        return self.harmonic.frequency

    @property
    def phase(self) -> float:
        """Phase of the harmonic force at t = 0 [rad]."""
        return self.harmonic.phase

    @property
    def omega(self) -> float:
        """Angular frequency w [rad s-1] of the harmonic force."""
        return self.harmonic.omega

    @property
    def period(self) -> float:
        """T = 1 / f [s] of the harmonic force."""
        return self.harmonic.period

    def force(self, t: float | NDArray[np.float64]) -> NDArray[np.float64]:
        """External force on the primary mass [N]."""
        return self.excitation.force(t)

    def velocity_scale(self) -> float:
        """A velocity typical of the harmonic motion, w (Delta + q |H12|) [m s-1], for relative thresholds."""
        linear = self.amplitude * float(np.abs(self.system.receptances(self.omega).h12))
        return self.omega * (self.clearance + linear) + 1e-300
