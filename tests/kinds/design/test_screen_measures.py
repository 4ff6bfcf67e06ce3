"""What the design screen measures besides the worst case: the impulse of a bumper's contact (whole, wherever the
strobe falls) and the operating |X| where no motion the screen knows is stable there (its guess, not nothing)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vibroimpact.analysis.band_worst import closed_form_at, closed_form_worst
from vibroimpact.engines.compliant.exact import CompliantExactEngine
from vibroimpact.engines.compliant.model import MODE_CONTACT
from vibroimpact.analysis.measures import as_measure
from vibroimpact.kinds.design.evaluate import BRUTE, SCREEN_MOTIONS, SCREENS, _operating
from vibroimpact.simulation.band_attractors import band_attractors
from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop, loss_factor_from_restitution
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.orbits.branch import PeriodicOrbit
from vibroimpact.orbits.bumper_map import CompiledPeriodMap
from vibroimpact.orbits.bumper_screen import _measured, rigid_twin
from vibroimpact.orbits.maps import ImpactMap, closed_form_state
from vibroimpact.orbits.shooting import ShootingSettings, shoot

FREQUENCY = 25.0  # [Hz]


def bumper_problem(phase: float) -> ImpactProblem:
    """The paper's absorber on a soft bumper (120 Hz: a long contact), R = 0.3, forced with ``phase`` [rad]."""
    law = KelvinVoigtBumper(3e-3, 120.0, loss_factor_from_restitution(0.3))
    return ImpactProblem(PAPER_SYSTEM, law, HarmonicForce(10.0, FREQUENCY, phase=phase))


def _shot(problem: ImpactProblem, guess: np.ndarray) -> PeriodicOrbit:
    """The period-1 orbit near ``guess``, shot on the engine's compiled period."""
    system = CompiledPeriodMap(problem)
    return shoot(system, guess, system.parameters, settings=ShootingSettings(tolerance=1e-12, max_iterations=30))


def test_a_contact_under_way_at_the_strobe_is_counted_whole() -> None:
    """The same orbit seen from a strobe in the middle of its contact (the force's phase moved by w times the
    contact's middle): the screen's measure of it gives the whole contact's impulse, as from a strobe in free flight
    (to 1e-9), where one period from that strobe sees only the contact's two parts (each smaller), and the same |X1|."""
    problem = bumper_problem(0.0)
    engine = CompliantExactEngine()
    orbit = _shot(problem, closed_form_state(rigid_twin(problem)))
    assert orbit.impacts == 1 and orbit.floquet_modulus < 1.0
    whole = engine.integrate(problem, orbit.state, 0.0, 1)
    start, end = whole.segments[whole.segments[:, 2] == MODE_CONTACT][0, :2]
    middle = 0.5 * (float(start) + float(end))  # [s]
    shifted = bumper_problem(2.0 * math.pi * FREQUENCY * middle)
    _trajectory, sampled = engine.sample(problem, orbit.state, 0.0, 1, np.array([middle]))
    moved = _shot(shifted, np.asarray(sampled[0], dtype=float))
    assert moved.floquet_modulus < 1.0
    reference, straddled = _measured(ImpactMap(problem), problem, orbit, 0), _measured(ImpactMap(shifted), shifted, moved, 0)
    assert reference is not None and straddled is not None
    assert reference.impulse == pytest.approx(float(np.max(np.abs(whole.impulses))), rel=1e-12)
    assert straddled.impulse == pytest.approx(reference.impulse, rel=1e-9)
    assert straddled.amplitude == pytest.approx(reference.amplitude, rel=1e-9)
    parts = engine.integrate(shifted, moved.state, 0.0, 1).impulses  # the period from the strobe: the contact's end only
    assert float(np.max(np.abs(parts), initial=0.0)) < 0.9 * reference.impulse


def test_the_operating_point_without_a_stable_closed_form_takes_what_the_runs_settle_on() -> None:
    """The paper's rigid stop (3 mm, R = 0.2) at 21 Hz, where no closed-form motion is stable: the operating |X1| is
    the largest motion the screen's seeded runs settle on (no guess): the same as an independent sweep of runs from
    the brute force's own starts finds there, to its last periods' convergence."""
    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(3e-3, 0.2), HarmonicForce(10.0, 25.0))
    at = closed_form_at(problem, 21.0)
    assert at.uncovered == pytest.approx(1.0, abs=0.0) and at.amplitude == 0.0  # exact: nothing stable
    value, motion, period, impacts, reached = _operating(problem, 21.0, as_measure(0, problem), SCREENS[0])
    assert motion == SCREEN_MOTIONS.index(BRUTE) and reached >= 1
    brute = band_attractors(problem, (21.0 * (1 - 1e-9), 21.0 * (1 + 1e-9)), frequencies=2, starts=4, transient=400, strobes=64)
    assert math.isfinite(value) and value > 0.0
    assert value == pytest.approx(float(np.nanmax(brute.amplitude)), rel=2e-2)
