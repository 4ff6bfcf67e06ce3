"""The problem an engine solves: a linear system, a contact law and an excitation.

:class:`ImpactProblem` composes the three validated parts and answers what the engines ask of them (clearance,
excitation frequency and period, force, a typical velocity). Each part validates itself; the problem only checks
that each is of a kind it knows. The contact law (:mod:`~vibroimpact.model.contact`) owns where and how the stop acts, so a problem
with another stop (another coordinate, a second side) changes the contact and the flow, not every engine.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import TypeVar, Union

import numpy as np
from numpy.typing import NDArray

from vibroimpact.model.contact import BUMPER, RIGID, KelvinVoigtBumper, RigidStop, Stop, check_room
from vibroimpact.model.excitation import HarmonicForce, SweptSine, load_weights, static_load
from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.model.structure import LinearStructure
from vibroimpact.model.system import TwoDofSystem

__all__ = ["Contact", "Excitation", "System", "ImpactProblem", "ProblemLike", "problem_of"]

#: The contact laws a problem may have.
Contact = Union[RigidStop, KelvinVoigtBumper]
#: The excitations a problem may have.
Excitation = Union[HarmonicForce, SweptSine]
#: The structures a problem may have: any N-dof structure, or the paper's named system (m1 ... b2, taken as its
#: structure; :mod:`~vibroimpact.model.system`, a view of the paper's layout).
System = Union[LinearStructure, TwoDofSystem]

_Kind = TypeVar("_Kind")


def _part_of_kind(name: str, value: object, kind: type[_Kind], why: str) -> _Kind:
    """``value`` if it is a ``kind``, else ``TypeError`` naming the part and saying ``why`` it must be one."""
    if not isinstance(value, kind):
        raise TypeError(f"{name} = {value!r} is not a {kind.__name__}: {why}")
    return value


_PARTS = {"system": (TwoDofSystem, LinearStructure), "contact": (RigidStop, KelvinVoigtBumper, tuple), "excitation": (HarmonicForce, SweptSine)}


@suggest_keywords
@dataclass(frozen=True)
class ImpactProblem:
    """A linear structure with stops and a harmonic (or swept) load.

    Parameters
    ----------
    system : LinearStructure
        Masses, springs and dashpots of any N-dof structure; the paper's named :class:`TwoDofSystem` is taken as its
        structure (its matrices, coordinates x1, x2).
    contact : RigidStop, KelvinVoigtBumper or tuple of Stop
        A single contact law means the paper's stop: an upper stop of the absorber (coordinate 2) against the base.
        A tuple of :class:`Stop` gives any layout (any number, absolute or relative, upper or lower); a stop's
        coordinates given by name (``Stop(law, "x2")``) are resolved against the structure's names here.
    excitation : HarmonicForce or SweptSine
        q cos(w t + phase) distributed over the coordinates (plus a constant force), or the linear swept sine.
    """

    system: LinearStructure
    contact: Contact | tuple[Stop, ...]
    excitation: Excitation

    def __post_init__(self) -> None:
        if isinstance(self.system, TwoDofSystem):
            object.__setattr__(self, "system", self.system.structure)  # one kind of structure from here on
        for name, kinds in _PARTS.items():
            value = getattr(self, name)
            if not isinstance(value, kinds):
                allowed = " or ".join(kind.__name__ for kind in kinds)
                raise TypeError(f"{name} = {value!r} is not allowed: expected a {allowed}")
        if isinstance(self.contact, tuple):
            for stop in self.contact:
                if not isinstance(stop, Stop):
                    raise TypeError(f"contact: {stop!r} is not a Stop")
            if any(stop.named for stop in self.contact):  # coordinates by name, as in scenes: indices from here on
                object.__setattr__(self, "contact", tuple(stop.resolve(self.system.coordinates) for stop in self.contact))
            for stop in self.contact:
                stop.check_size(self.system.size)
            check_room([stop.place for stop in self.contact], [stop.clearance for stop in self.contact], self.system.coordinates)
        elif self.system.size < 2:
            raise ValueError("contact: a single contact law means the paper's stop on coordinate 2; give a tuple of Stop instead")
        size = self.system.size
        for key, vector in (("excitation.on", self.excitation.weights), ("excitation.static", self.excitation.static)):
            if vector is not None and len(vector) != size:
                raise ValueError(f"{key}: expected {size} values (one per coordinate), got {len(vector)}")

    # ----------------------------------------------------------------- structure
    @property
    def structure(self) -> LinearStructure:
        """The structure (matrices and coordinate names)."""
        return self.system

    @property
    def size(self) -> int:
        """N, the number of degrees of freedom (the state has 2 N entries: displacements, then velocities)."""
        return self.system.size

    def named_view(self) -> TwoDofSystem | None:
        """The structure's named view (m1 ... b2, :meth:`TwoDofSystem.of`) whatever the stops and load; None where the
        structure is not the paper's two-mass chain."""
        return TwoDofSystem.of(self.system)

    @property
    def stops(self) -> tuple[Stop, ...]:
        """Every stop of the problem (one upper stop on the absorber for a single contact law)."""
        if isinstance(self.contact, tuple):
            return self.contact
        return (Stop(self.contact, coordinate=1, other=None, side="upper"),)

    def normals(self) -> NDArray[np.float64]:
        """n of every stop, shape (K, N): gap_k = Delta_k - n_k . x."""
        return np.array([stop.normal(self.size) for stop in self.stops]).reshape(-1, self.size)

    def clearances(self) -> NDArray[np.float64]:
        """Delta of every stop [m], shape (K,)."""
        return np.array([stop.clearance for stop in self.stops])

    def load(self) -> tuple[NDArray[np.complex128], NDArray[np.float64]]:
        """(F, F0): the harmonic load Re(F e^{jwt}) and the constant load, per coordinate [N].

        For a swept sine, F is the distribution of q (the sweep's own signal multiplies it).
        """
        size = self.size
        excitation = self.excitation
        if isinstance(excitation, HarmonicForce):
            return excitation.load_vector(self.structure.mass_matrix), excitation.static_vector(size)
        return load_weights(excitation.weights, size).astype(complex) * excitation.amplitude, static_load(excitation.static, size)

    def first_order(self) -> tuple[NDArray[np.float64], NDArray[np.complex128], NDArray[np.float64]]:
        """(A, b, b0): the free flight as y' = A y + Re(b e^{jwt}) + b0 with y = (x, x') [SI]."""
        structure = self.structure
        size = self.size
        harmonic, static = self.load()
        minv = np.linalg.inv(structure.mass_matrix)
        b = np.concatenate([np.zeros(size, dtype=complex), minv @ harmonic])
        b0 = np.concatenate([np.zeros(size), minv @ static])
        return structure.state_matrix, b, b0

    def gap_amplitude(self, stop: int = 0) -> float:
        """|n . H(jw) F|: the amplitude of stop ``stop``'s coordinate in the linear motion without stops [m]."""
        return self.gap_amplitudes()[stop]

    def gap_amplitudes(self) -> list[float]:
        """|n_k . H(jw) F| of every stop [m] (the load and the receptance computed once)."""
        harmonic, _ = self.load()
        h = self.structure.receptance_matrix(self.omega)
        return [float(abs(stop.normal(self.size) @ h @ harmonic)) for stop in self.stops]

    def contact_holding(self, stop: int, state: NDArray[np.float64], t: float) -> float:
        """Force lambda [N] that stop ``stop`` must exert to hold its gap closed (g = 0, g' = 0) in ``state`` at t.

        lambda = n . M^-1 (f(t) - C x' - K x) / (n . M^-1 n); positive: the structure is pushed into the stop (it
        sticks); it leaves when lambda turns negative. Equals :meth:`RigidStop.holding_force` on the paper's layout.
        """
        structure = self.structure
        size = self.size
        harmonic, static = self.load()
        force = static + (harmonic * complex(np.cos(self.omega * t), np.sin(self.omega * t))).real
        x, v = np.asarray(state[:size], dtype=float), np.asarray(state[size : 2 * size], dtype=float)
        n = self.stops[stop].normal(size)
        minv_n = np.linalg.solve(structure.mass_matrix, n)
        return float(minv_n @ (force - structure.damping_matrix @ v - structure.stiffness_matrix @ x) / (n @ minv_n))

    # ------------------------------------------------------------------ contact
    @property
    def law(self) -> Contact:
        """The contact law of the problem's only stop (``ValueError`` if it has several: ask :attr:`stops`)."""
        stops = self.stops
        if len(stops) != 1:
            raise ValueError(f"contact: the problem has {len(stops)} stops; a single-stop quantity needs exactly one")
        return stops[0].law

    @property
    def contact_law(self) -> str:
        """:data:`~vibroimpact.model.contact.RIGID` if every stop is a rigid stop, else
        :data:`~vibroimpact.model.contact.BUMPER`: the contact law an engine must solve for this problem (an engine's
        ``capabilities.contact``)."""
        return RIGID if all(stop.rigid for stop in self.stops) else BUMPER

    @property
    def clearance(self) -> float:
        """Delta [m] of the only stop: where the contact begins."""
        return self.law.clearance

    @property
    def rigid_stop(self) -> RigidStop:
        """The only stop's law, which must be a :class:`RigidStop` (``TypeError`` naming the contact otherwise)."""
        return _part_of_kind("contact", self.law, RigidStop, "a momentary-impact engine solves a rigid stop only")

    @property
    def bumper(self) -> KelvinVoigtBumper:
        """The only stop's law, which must be a :class:`KelvinVoigtBumper` (``TypeError`` naming the contact otherwise)."""
        return _part_of_kind("contact", self.law, KelvinVoigtBumper, "a compliant engine solves a bumper only")

    @property
    def restitution(self) -> float:
        """R [-] of the rigid stop."""
        return self.rigid_stop.restitution

    def holding_force(self, x1: float | NDArray[np.float64], v1: float | NDArray[np.float64]) -> float | NDArray[np.float64]:
        """Force the rigid stop must exert to hold the absorber at rest on it [N] (see :meth:`RigidStop.holding_force`)."""
        named = self.named_view()
        if named is None:
            raise TypeError("holding_force: the absorber's holding force needs the paper's two-mass chain; ask contact_holding(stop, state, t)")
        return self.rigid_stop.holding_force(named, x1, v1)

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
        """A velocity typical of the harmonic motion [m s-1], for relative thresholds: w (Delta + q |H12|) on the
        paper's layout, and in general w times the largest |Delta_k| + |n_k . H F| over the stops (computed once per
        problem: a frozen value's)."""
        return self._velocity_scale

    @cached_property
    def _velocity_scale(self) -> float:
        _, static = self.load()
        minv_static = np.linalg.solve(self.structure.mass_matrix, static)
        # a static load's length: how far it moves a stop's coordinate in 1/w [s] (gravity on a free mass)
        sizes = [abs(stop.clearance) + linear + abs(stop.normal(self.size) @ minv_static) / self.omega**2 for stop, linear in zip(self.stops, self.gap_amplitudes())]
        return self.omega * max(sizes) + 1e-300

    def length_scale(self) -> float:
        """A displacement typical of the motion [m], for relative thresholds: Delta + q |H12| on the paper's layout, in
        general the largest |Delta_k| + |n_k . H F| over the stops (:meth:`velocity_scale` / w)."""
        return self.velocity_scale() / self.omega


#: What the closed forms and the linear response accept: a problem, or the paper's named system, a view of the
#: paper's layout whose values the caller gives (:func:`problem_of`).
ProblemLike = Union[ImpactProblem, TwoDofSystem]


def problem_of(system: ProblemLike, call: str, **values: object) -> ImpactProblem:
    """The problem ``system`` is: itself if it is an :class:`ImpactProblem`; the paper's named system is a view of the
    paper's layout (one rigid upper stop on x2, the force on x1) whose placeholders the caller's ``values`` replace
    (f or w, Delta, R, q: each must then be given, not None).

    Parameters
    ----------
    system : ImpactProblem or TwoDofSystem
        The problem, or the paper's named system.
    call : str
        The calling function's name, for the messages.
    **values
        The values the caller replaces the problem's with, by name (None: not given).

    Raises
    ------
    TypeError
        A ``system`` of another kind, or the named system with a value not given.
    """
    if isinstance(system, ImpactProblem):
        return system
    if not isinstance(system, TwoDofSystem):
        raise TypeError(f"{call}: system = {system!r} is not an ImpactProblem or the paper's TwoDofSystem")
    missing = [name for name, value in values.items() if value is None]
    if missing:
        raise TypeError(f"{call}(system, {', '.join(values)}): the paper's system needs {', '.join(missing)} (a problem carries its own)")
    return ImpactProblem(system, RigidStop(0.0, 0.0), HarmonicForce(1.0, 1.0))  # placeholders: the values given replace them
