"""What a concepts scene builds: the concepts and the settings of the study (dataclasses; they import nothing from the
scene layer, so that :mod:`.schema` can name them without a circle of imports; :mod:`.concepts` parses them)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from vibroimpact.engines.settings import EngineSettings
from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop, loss_factor_from_restitution
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.stops import Stop
from vibroimpact.model.system import TwoDofSystem
from vibroimpact.simulation.settings import SteadySettings

__all__ = ["Concept", "ConceptsSettings", "bumper_twin"]


@dataclass(frozen=True)
class Concept:
    """One absorber concept: the system it has and the stops it adds.

    Attributes
    ----------
    name : str
        Short, file-name-safe name (the dataset's ``concept`` coordinate).
    label : str
        What the report calls it.
    system : TwoDofSystem
        m1, k1, b1 and m2 of the scene, with this concept's k2 and b2.
    stops : tuple of Stop
        Rigid stops (none: the linear absorber).
    absorber : str
        How k2 and b2 were chosen, in words.
    """

    name: str
    label: str
    system: TwoDofSystem
    stops: tuple[Stop, ...] = ()
    absorber: str = ""

    def describe_stops(self) -> str:
        """E.g. ``x2 <= 3 mm, R = 0.2``; ``no stop``."""
        if not self.stops:
            return "no stop"
        return "; ".join(f"{stop.describe(self.system.coordinates)}, R = {stop.law.restitution:g}" for stop in self.stops if isinstance(stop.law, RigidStop))

    def problem(self, amplitude: float, frequency: float, phase: float = 0.0, bumper_frequency: float | None = None) -> ImpactProblem:
        """The concept's impact problem at ``frequency`` [Hz]: its rigid stops, or (``bumper_frequency`` [Hz]) each
        stop's Kelvin-Voigt twin of the same clearance whose loss factor gives its restitution; ``ValueError`` for a
        concept without a stop."""
        if not self.stops:
            raise ValueError(f"concept {self.name!r} has no stop: its steady state is the linear one")
        laws = [stop.law if bumper_frequency is None else bumper_twin(stop.law, bumper_frequency) for stop in self.stops]
        force = HarmonicForce(amplitude, frequency, phase)
        stops = tuple(Stop(law, stop.coordinate, stop.other, stop.side) for law, stop in zip(laws, self.stops))
        return ImpactProblem(self.system, stops, force)


def bumper_twin(law: Any, bumper_frequency: float) -> KelvinVoigtBumper:
    """The Kelvin-Voigt bumper of a rigid stop: same clearance, Omega_b / 2 pi = ``bumper_frequency`` [Hz], the loss
    factor whose one collision restitutes R (:func:`loss_factor_from_restitution`)."""
    if not isinstance(law, RigidStop):
        raise TypeError(f"expected a RigidStop, got {law!r}")
    return KelvinVoigtBumper(law.clearance, bumper_frequency, loss_factor_from_restitution(law.restitution))


@dataclass(frozen=True, eq=False)
class ConceptsSettings:
    """Everything a concepts study computes from.

    Attributes
    ----------
    system : TwoDofSystem
        The scene's system: the reference of the anti-resonance band and the base of every concept.
    amplitude : float
        q [N] on the primary mass.
    concepts : tuple of Concept
        In the order of the scene.
    frequency : ndarray
        Closed-form grid [Hz].
    simulation_frequency : ndarray
        Time-domain grid [Hz] (steady states of the exact engine and of the bumper twins).
    engine : EngineSettings
        Tolerances of the integrators (the bumper's IDA).
    steady : SteadySettings
        Convergence and measurement of the steady states.
    bumper_frequency : float
        Omega_b / 2 pi of every bumper twin [Hz]; NaN: no bumper runs.
    continuation_steps : int
        Most points per continued branch and direction; 0: no continuation.
    """

    system: TwoDofSystem
    amplitude: float
    concepts: tuple[Concept, ...]
    frequency: np.ndarray
    simulation_frequency: np.ndarray
    engine: EngineSettings = field(default_factory=EngineSettings)
    steady: SteadySettings = field(default_factory=SteadySettings)
    bumper_frequency: float = math.nan
    continuation_steps: int = 400

    @property
    def static_deflection(self) -> float:
        """q / k1 [m]: the primary's deflection under the force amplitude held still."""
        return self.amplitude / self.system.k1
