"""Shooting on a bumper engine's compiled period (:class:`~vibroimpact.orbits.bumper_map.CompiledPeriodMap`) against
shooting on the general stroboscopic map (:class:`~vibroimpact.orbits.maps.ImpactMap`): one Newton loop
(:func:`vibroimpact.orbits.shooting.shoot`) on two evaluations of one map, so the same orbit in as many steps, and an
orbit that is the engine's own steady state."""

from __future__ import annotations

import numpy as np
import pytest

from vibroimpact.engines.compliant.exact import CompliantExactEngine
from vibroimpact.engines.registry import ENGINES
from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop, Stop, loss_factor_from_restitution
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.orbits.bumper_map import CompiledPeriodMap
from vibroimpact.orbits.bumper_screen import rigid_twin
from vibroimpact.orbits.maps import ImpactMap, closed_form_state
from vibroimpact.orbits.shooting import ShootingError, ShootingSettings, shoot


def bumper_problem(bumper: float, restitution: float, clearance: float, frequency: float) -> ImpactProblem:
    """The paper's absorber, q = 10 N, on a bumper of Omega_b / 2 pi = ``bumper`` [Hz]."""
    return ImpactProblem(PAPER_SYSTEM, KelvinVoigtBumper(clearance, bumper, loss_factor_from_restitution(restitution)), HarmonicForce(10.0, frequency))


@pytest.mark.parametrize(("bumper", "restitution", "clearance", "frequency"), [(250.0, 0.2, 3e-3, 25.0), (800.0, 0.6, 1.5e-3, 30.0), (120.0, 0.4, 5e-3, 22.0)])
def test_it_finds_the_general_map_s_orbit_in_as_many_steps(bumper: float, restitution: float, clearance: float, frequency: float) -> None:
    """From the rigid twin's closed-form orbit: the same residual history, state, contacts and Floquet multipliers
    (the compiled period is the general map's image and Jacobian, to 1e-12 of the scale at each iterate)."""
    problem = bumper_problem(bumper, restitution, clearance, frequency)
    system, fast_map = ImpactMap(problem), CompiledPeriodMap(problem)
    guess = closed_form_state(rigid_twin(problem))
    settings = ShootingSettings(tolerance=1e-10, max_iterations=20)
    general = shoot(system, guess, system.parameters, settings=settings)
    fast = shoot(fast_map, guess, fast_map.parameters, settings=settings)
    assert len(fast.residual_history) == len(general.residual_history)
    assert np.max(np.abs(fast.state - general.state) / system.state_scale) < 1e-12
    assert fast.impacts == general.impacts >= 1
    assert fast.floquet_modulus == pytest.approx(general.floquet_modulus, rel=1e-9)
    general_out, fast_out = system.evaluate(guess, system.parameters), fast_map.evaluate(guess, fast_map.parameters)
    assert np.max(np.abs(fast_out.image - general_out.image) / system.state_scale) < 1e-12
    assert np.max(np.abs(fast_out.jacobian - general_out.jacobian)) < 1e-9 * np.max(np.abs(general_out.jacobian))


def test_its_orbit_is_the_engine_s_own_steady_state() -> None:
    """Ten periods from the orbit's state come back to it (to 1e-9 of the scale) when it is stable, with one contact a
    period."""
    problem = bumper_problem(250.0, 0.2, 3e-3, 25.0)
    system = CompiledPeriodMap(problem)
    orbit = shoot(system, closed_form_state(rigid_twin(problem)), system.parameters, settings=ShootingSettings(tolerance=1e-11, max_iterations=20))
    assert orbit.floquet_modulus < 1.0 and orbit.impacts == 1
    trajectory = CompliantExactEngine().integrate(problem, orbit.state, 0.0, 10)
    assert np.max(np.abs(trajectory.strobe_states[-1] - orbit.state) / system.state_scale) < 1e-9
    assert trajectory.impact_times.size == 10


def test_a_state_without_an_image_is_nan_and_a_shot_that_cannot_converge_raises() -> None:
    """A non-finite state has no image (NaN, a failed step); two Newton steps from far away: no orbit, on either map."""
    problem = bumper_problem(250.0, 0.2, 3e-3, 25.0)
    fast_map = CompiledPeriodMap(problem)
    assert np.all(np.isnan(fast_map.evaluate(np.array([np.nan, 0.0, 0.0, 0.0]), fast_map.parameters).image))
    guess = np.array([0.02, -0.03, 5.0, -4.0])
    for system in (ImpactMap(problem), fast_map):
        with pytest.raises(ShootingError):
            shoot(system, guess, system.parameters, settings=ShootingSettings(tolerance=1e-10, max_iterations=2))


def test_only_the_bumper_reference_gives_its_compiled_period_and_it_refuses_rigid_stops() -> None:
    assert [name for name, spec in ENGINES.items() if spec.capabilities.compiled_period] == ["compliant_exact"]
    rigid = ImpactProblem(PAPER_SYSTEM, (Stop(RigidStop(3e-3, 0.2), coordinate=1),), HarmonicForce(10.0, 25.0))
    with pytest.raises(ValueError, match="compiled period"):
        CompiledPeriodMap(rigid)
    with pytest.raises((TypeError, ValueError)):
        CompliantExactEngine().compiled_period(rigid)
    with pytest.raises(ValueError, match="one period"):
        CompiledPeriodMap(bumper_problem(250.0, 0.2, 3e-3, 25.0), periods=2)
