"""The impact problems of the validation cases: each published system written in the project's general model.

* Budd & Dux: a 1-dof :class:`LinearStructure` M = [[1]], K = [[1]], C = [[0]], the force cos(w t) (amplitude 1,
  frequency w / 2 pi), an upper stop at sigma with restitution r.
* The bouncing ball in table coordinates z = y - s (height above the table s(t) = A sin(w t)): a free mass
  (K = [[0]]), gravity as the static force -m g, the table's inertia as the harmonic force m A w^2 sin(w t), a lower
  stop at z = 0 with restitution e (it restitutes the relative velocity z', as the ball's impact law does). The
  problem's time is shifted by half a period (force phase +pi/2, table A sin(w t + pi)), so that the strobes
  (t = 0 mod T) fall half a period from the period-one orbit's impacts (theta in [-pi/2, pi/2]); see
  :data:`BALL_TIME_SHIFT`.
* The Zeno ball: the same free mass with gravity, no table motion (a zero harmonic force; its frequency only sets
  the engines' period).
* The grazing oscillator: m x'' + c x' + k x = A cos(w t + phase) with an upper stop at d; the phase puts the linear
  orbit's maximum (where it grazes) half a period from the strobes.
* Ormondroyd & Den Hartog's relative stop: the paper's two masses (as a general structure), the force on the primary
  mass, a stop between absorber and primary mass, x2 - x1 <= Delta.
"""

from __future__ import annotations

import cmath
import math

from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.stops import Stop
from vibroimpact.model.structure import LinearStructure
from vibroimpact.model.system import TwoDofSystem
from vibroimpact.scene.validation_settings import BouncingBallCase, BuddDuxCase, GrazingCase, RelativeStopCase, ValidationCase, ZenoCase

__all__ = ["BALL_TIME_SHIFT", "case_structure", "budd_dux_problem", "ball_problem", "ball_amplitude", "zeno_problem", "grazing_problem", "grazing_phase", "relative_stop_problem"]

#: The ball problem's time t is the table's time t + T/2 ... as a phase: the table is A sin(w t + BALL_TIME_SHIFT).
BALL_TIME_SHIFT = math.pi


def case_structure(case: ValidationCase) -> LinearStructure:
    """The structure of a case."""
    if isinstance(case, BuddDuxCase):
        return LinearStructure([[1.0]], [[1.0]], [[0.0]], ("x",))
    if isinstance(case, (BouncingBallCase, ZenoCase)):
        return LinearStructure([[case.mass]], [[0.0]], [[0.0]], ("z",))
    if isinstance(case, GrazingCase):
        return LinearStructure([[case.mass]], [[case.stiffness]], [[case.damping]], ("x",))
    named = TwoDofSystem(case.m1, case.m2, case.k1, case.k2, case.b1, case.b2)
    return named.structure


def budd_dux_problem(case: BuddDuxCase, clearance: float) -> ImpactProblem:
    """x'' + x = cos(w t), x <= ``clearance`` (sigma), x' -> -r x'."""
    w = case.forcing_frequency
    stop = Stop(RigidStop(clearance, case.restitution), coordinate=0, side="upper")
    return ImpactProblem(case_structure(case), (stop,), HarmonicForce(1.0, w / (2.0 * math.pi), 0.0, weights=(1.0,)))


def ball_amplitude(case: BouncingBallCase, gamma: float) -> float:
    """The harmonic force m A w^2 [N] of the table acceleration Gamma = A w^2 / g."""
    return case.mass * gamma * case.gravity


def ball_problem(case: BouncingBallCase, gamma: float) -> ImpactProblem:
    """The ball in table coordinates at Gamma = A w^2 / g (module docstring; force m A w^2 cos(w t + pi/2))."""
    stop = Stop(RigidStop(0.0, case.restitution), coordinate=0, side="lower")
    force = HarmonicForce(ball_amplitude(case, gamma), case.frequency, BALL_TIME_SHIFT - 0.5 * math.pi, weights=(1.0,), static=(-case.mass * case.gravity,))
    return ImpactProblem(case_structure(case), (stop,), force)


def zeno_problem(case: ZenoCase) -> ImpactProblem:
    """A free mass with gravity above a fixed table z >= 0 (no harmonic force)."""
    stop = Stop(RigidStop(0.0, case.restitution), coordinate=0, side="lower")
    return ImpactProblem(case_structure(case), (stop,), HarmonicForce(0.0, case.frequency, 0.0, weights=(1.0,), static=(-case.mass * case.gravity,)))


def grazing_phase(case: GrazingCase) -> float:
    """Force phase [rad] that puts the linear orbit's maximum at t = T/2: x = |H| A cos(w t + phase + arg H)."""
    w = 2.0 * math.pi * case.frequency
    h = 1.0 / complex(case.stiffness - case.mass * w * w, case.damping * w)
    return (-math.pi - cmath.phase(h)) % (2.0 * math.pi)


def grazing_problem(case: GrazingCase, amplitude: float) -> ImpactProblem:
    """m x'' + c x' + k x = A cos(w t + phase), x <= d."""
    stop = Stop(RigidStop(case.clearance, case.restitution), coordinate=0, side="upper")
    return ImpactProblem(case_structure(case), (stop,), HarmonicForce(amplitude, case.frequency, grazing_phase(case), weights=(1.0,)))


def relative_stop_problem(case: RelativeStopCase) -> ImpactProblem:
    """The paper's masses with a stop between absorber and primary mass, x2 - x1 <= Delta."""
    stop = Stop(RigidStop(case.clearance, case.restitution), coordinate=1, other=0, side="upper")
    return ImpactProblem(case_structure(case), (stop,), HarmonicForce(case.amplitude, case.frequency, 0.0, weights=(1.0, 0.0)))
