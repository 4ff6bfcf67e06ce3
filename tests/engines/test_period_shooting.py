"""Newton on the compiled bumper period (``compliant_exact``'s ``shoot_period``) against the general shooter on the
stroboscopic map (:func:`vibroimpact.orbits.shooting.shoot`): the same iteration, so the same orbit in as many steps,
and an orbit that is the engine's own steady state."""

from __future__ import annotations

import numpy as np
import pytest

from vibroimpact.engines.compliant.exact import CompliantExactEngine
from vibroimpact.engines.registry import ENGINES
from vibroimpact.model.contact import KelvinVoigtBumper, Stop, loss_factor_from_restitution
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.orbits.maps import ImpactMap, closed_form_state
from vibroimpact.orbits.bumper_screen import rigid_twin
from vibroimpact.orbits.shooting import ShootingError, ShootingSettings, shoot


def bumper_problem(bumper: float, restitution: float, clearance: float, frequency: float) -> ImpactProblem:
    """The paper's absorber, q = 10 N, on a bumper of Omega_b / 2 pi = ``bumper`` [Hz]."""
    return ImpactProblem(PAPER_SYSTEM, KelvinVoigtBumper(clearance, bumper, loss_factor_from_restitution(restitution)), HarmonicForce(10.0, frequency))


@pytest.mark.parametrize(("bumper", "restitution", "clearance", "frequency"), [(250.0, 0.2, 3e-3, 25.0), (800.0, 0.6, 1.5e-3, 30.0), (120.0, 0.4, 5e-3, 22.0)])
def test_it_finds_the_general_shooter_s_orbit_in_as_many_steps(bumper: float, restitution: float, clearance: float, frequency: float) -> None:
    """From the rigid twin's closed-form orbit: the same state to 1e-12 of the map's scale, the same number of Newton
    steps and contacts, Floquet multipliers to 1e-9."""
    problem = bumper_problem(bumper, restitution, clearance, frequency)
    system = ImpactMap(problem)
    guess = closed_form_state(rigid_twin(problem))
    settings = ShootingSettings(tolerance=1e-10, max_iterations=20)
    general = shoot(system, guess, system.parameters, settings=settings)
    fast = CompliantExactEngine().shoot_period(problem, guess, system.state_scale, settings.tolerance, settings.max_iterations, settings.min_damping)
    assert fast is not None and fast.iterations == len(general.residual_history) - 1
    assert np.max(np.abs(fast.state - general.state) / system.state_scale) < 1e-12
    assert fast.contacts == general.impacts >= 1
    assert fast.floquet_modulus == pytest.approx(general.floquet_modulus, rel=1e-9)


def test_its_orbit_is_the_engine_s_own_steady_state() -> None:
    """Ten periods from the orbit's state come back to it (to 1e-9 of the scale) when it is stable, with one contact a
    period."""
    problem = bumper_problem(250.0, 0.2, 3e-3, 25.0)
    system = ImpactMap(problem)
    engine = CompliantExactEngine()
    orbit = engine.shoot_period(problem, closed_form_state(rigid_twin(problem)), system.state_scale, 1e-11, 20)
    assert orbit is not None and orbit.floquet_modulus < 1.0
    trajectory = engine.integrate(problem, orbit.state, 0.0, 10)
    assert np.max(np.abs(trajectory.strobe_states[-1] - orbit.state) / system.state_scale) < 1e-9
    assert trajectory.impact_times.size == 10


def test_a_shot_that_cannot_converge_gives_none_where_the_general_shooter_raises() -> None:
    """Two Newton steps from far away: no orbit (the general shooter says why)."""
    problem = bumper_problem(250.0, 0.2, 3e-3, 25.0)
    system = ImpactMap(problem)
    guess = np.array([0.02, -0.03, 5.0, -4.0])
    with pytest.raises(ShootingError):
        shoot(system, guess, system.parameters, settings=ShootingSettings(tolerance=1e-10, max_iterations=2))
    assert CompliantExactEngine().shoot_period(problem, guess, system.state_scale, 1e-10, 2) is None


def test_only_the_bumper_reference_says_it_shoots_periods_and_it_refuses_rigid_stops() -> None:
    assert [name for name, spec in ENGINES.items() if spec.capabilities.period_shooting] == ["compliant_exact"]
    from vibroimpact.model.contact import RigidStop

    rigid = ImpactProblem(PAPER_SYSTEM, (Stop(RigidStop(3e-3, 0.2), coordinate=1),), HarmonicForce(10.0, 25.0))
    with pytest.raises((TypeError, ValueError)):
        CompliantExactEngine().shoot_period(rigid, np.zeros(4), np.ones(4), 1e-10, 5)
