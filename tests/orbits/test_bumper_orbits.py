"""Shooting, continuation and bifurcations of the compliant (Kelvin-Voigt bumper) model (issue 23, item 3).

The paper's system, Delta = 3 mm, q = 10 N, a bumper whose loss factor gives R = 0.2 (corrected eq. 26): an
:class:`ImpactMap` of it runs on the engine the registry offers for bumpers with exact Jacobians. Its shot one-contact
orbit must be the steady state the bumper engines march to (``compliant_exact`` and IDA), its exact monodromy the
finite differences of the map, its continued branch pass through marched steady states and end where the linear
orbit touches the bumper's surface (contact onset at tangency, q |H12| = Delta: no Omega_b in it), the closest
approach of a free flight be the linear orbit's distance to the surface, and (slow) the branch's fold and period
doubling converge to the rigid stop's at first order in 1/Omega_b.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from vibroimpact.analysis.linear import linear_amplitudes
from vibroimpact.engines.registry import BUMPER, make_engine
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop, loss_factor_from_restitution
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.orbits.continuation import ContinuationSettings, continue_branch
from vibroimpact.orbits.maps import ImpactMap, closed_form_state, section_phase
from vibroimpact.orbits.orbit_measures import orbit_measures
from vibroimpact.orbits.shooting import shoot
from vibroimpact.simulation.harmonics import linear_state
from vibroimpact.simulation.settings import SteadySettings
from vibroimpact.simulation.steady import steady_state

from tests.conftest import PAPER_AMPLITUDE, PAPER_CLEARANCE

R = 0.2
BAND = (15.0, 45.0)


def _phase() -> float:
    """A strobe away from the rigid stop's closed-form impacts over the band (the bumper's contacts are near them)."""
    rigid = ImpactProblem(PAPER_SYSTEM, RigidStop(PAPER_CLEARANCE, R), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    return section_phase(rigid, np.linspace(*BAND, 301))


PHASE = _phase()


def problem(frequency: float, bumper: float | None, phase: float = PHASE) -> ImpactProblem:
    """The paper's problem at ``frequency`` [Hz] with a bumper of ``bumper`` Hz (None: the rigid stop)."""
    law = RigidStop(PAPER_CLEARANCE, R) if bumper is None else KelvinVoigtBumper(PAPER_CLEARANCE, bumper, loss_factor_from_restitution(R))
    return ImpactProblem(PAPER_SYSTEM, law, HarmonicForce(PAPER_AMPLITUDE, frequency, phase))


def shot(frequency: float, bumper: float | None, bounds: dict | None = None) -> tuple[ImpactMap, object]:
    """The one-contact orbit of the bumper map, shot from the rigid stop's closed form (itself shot first)."""
    rigid = problem(frequency, None)
    start = shoot(ImpactMap(rigid), closed_form_state(rigid), ImpactMap(rigid).parameters)
    if bumper is None:
        return ImpactMap(rigid, bounds=bounds), start
    mapping = ImpactMap(problem(frequency, bumper), bounds=bounds)
    return mapping, shoot(mapping, start.state, mapping.parameters)


def test_a_bumper_map_runs_on_the_engine_the_registry_offers_for_bumpers() -> None:
    """Chosen by capabilities (bumper contact, exact Jacobians), and its restitution parameter is the bumper's R with
    Omega_b kept: another R sets the loss factor of the corrected eq. 26."""
    mapping = ImpactMap(problem(25.0, 250.0))
    assert mapping.engine.capabilities.contact == BUMPER and mapping.engine.capabilities.exact_jacobians
    assert mapping.parameters[1] == pytest.approx(R, rel=1e-12)
    law = mapping.problem_at(np.array([25.0, 0.5, 2e-3, 10.0, 0.0])).stops[0].law
    assert isinstance(law, KelvinVoigtBumper) and law.frequency == 250.0 and law.clearance == 2e-3  # exact: copied inputs
    assert law.restitution == pytest.approx(0.5, rel=1e-12)
    assert mapping.problem_at(mapping.parameters).stops[0].law.loss_factor == problem(25.0, 250.0).stops[0].law.loss_factor  # exact: its own, kept


def test_the_shot_orbit_is_the_steady_state_of_the_bumper_engines() -> None:
    """25 Hz, 250 Hz bumper: one contact per period; |X1|, |X2| of the shot orbit equal the exact engine's marched
    steady state to 1e-9 and IDA's (rtol 1e-10) to 1e-7; its multipliers are those of finite differences of the map."""
    mapping, orbit = shot(25.0, 250.0)
    assert orbit.impacts == 1 and orbit.hybrid.min_impact_velocity > 0.0 and orbit.stable
    measures = orbit_measures(mapping, orbit)
    marched = steady_state("compliant_exact", mapping.problem, "rest", SteadySettings(tolerance=1e-10))
    assert marched.converged
    np.testing.assert_allclose(measures.amplitudes, [abs(marched.measures.x1), abs(marched.measures.x2)], rtol=1e-9)
    assert measures.x1_amplitude == pytest.approx(3.0074e-3, rel=1e-4)  # the bumper's own, not the rigid stop's 2.748 mm
    ida = steady_state(make_engine("compliant", EngineSettings(rtol=1e-10, atol=1e-14)), mapping.problem, (0.0, orbit.state), SteadySettings(tolerance=1e-9))
    np.testing.assert_allclose(measures.amplitudes, [abs(ida.measures.x1), abs(ida.measures.x2)], rtol=1e-7)
    # the exact monodromy against central differences of the map
    y, p = orbit.state, orbit.parameters
    differences = np.empty((4, 4))
    for j in range(4):
        step = np.zeros(4)
        step[j] = 1e-6 * mapping.state_scale[j]
        differences[:, j] = (mapping.evaluate(y + step, p).image - mapping.evaluate(y - step, p).image) / (2.0 * step[j])
    np.testing.assert_allclose(orbit.monodromy, differences, rtol=0.0, atol=1e-6 * np.abs(orbit.monodromy).max())
    mu = np.sort_complex(np.linalg.eigvals(differences))
    np.testing.assert_allclose(np.sort_complex(orbit.multipliers), mu, rtol=0.0, atol=1e-6)


def test_closest_approach_of_a_free_flight_is_the_linear_orbits_distance_to_the_surface() -> None:
    """17 Hz, where the linear orbit stays below the bumper: no contact, and the closest approach is |X2| - Delta."""
    free = problem(17.0, 1000.0)
    linear = linear_state(free)
    assert linear.fits(free)
    out = ImpactMap(free).evaluate(linear.state(free.omega), ImpactMap(free).parameters)
    x2 = abs(linear_amplitudes(free, omega=free.omega).amplitudes[1])
    assert out.hybrid.impacts == 0 and math.isinf(out.hybrid.min_impact_velocity)
    assert out.hybrid.closest_approach == pytest.approx(x2 - PAPER_CLEARANCE, rel=1e-9)
    assert out.hybrid.closest_approach < 0.0


def _touch() -> float:
    """Where the linear orbit touches the surface, q |H12| = Delta, below the resonance [Hz]."""
    return brentq(lambda f: abs(linear_amplitudes(problem(f, None), omega=2.0 * np.pi * f).amplitudes[1]) - PAPER_CLEARANCE, 19.0, 21.0, xtol=1e-13)


def test_the_continued_branch_passes_through_steady_states_and_ends_at_contact_onset_at_tangency() -> None:
    """250 Hz bumper, continued over 19.5-23 Hz from 22 Hz: its stable points are the marched steady states (1e-8),
    and the branch ends at a contact onset at tangency where the entry speed goes to 0, at the linear orbit's touch
    of the surface (no Omega_b in it: the rigid stop's grazing point)."""
    settings = ContinuationSettings(lower=19.5, upper=23.0, max_steps=300, max_step=0.1, stop_at_grazing=True)
    mapping, orbit = shot(22.0, 250.0, bounds={"frequency": (10.0, 50.0)})
    branch = continue_branch(mapping, orbit, "frequency", settings)
    onsets = [point for point in branch.special_points if point.kind == "grazing"]
    assert len(onsets) == 1 and "depth goes to zero" in onsets[0].note
    assert onsets[0].value == pytest.approx(_touch(), rel=1e-12)  # the closed form (orbits.onsets)
    stable = [o for o in branch.orbits if o.stable and o.impacts == 1]
    picks = [stable[0], stable[len(stable) // 2], stable[-1]]
    assert max(o.parameter("frequency") for o in picks) - min(o.parameter("frequency") for o in picks) > 1.0
    for orbit in picks:
        at = mapping.problem_at(orbit.parameters)
        marched = steady_state("compliant_exact", at, (0.0, orbit.state + 1e-4 * mapping.state_scale), SteadySettings(tolerance=1e-11))
        np.testing.assert_allclose(orbit_measures(mapping, orbit).amplitudes, [abs(marched.measures.x1), abs(marched.measures.x2)], rtol=1e-8)


@pytest.mark.slow
def test_fold_and_period_doubling_converge_to_the_rigid_stops_at_first_order() -> None:
    """Bumpers of 250 Hz, 1 kHz and 4 kHz: the fold and the period doubling near 26.6 Hz move towards the rigid stop's
    by about 4x per 4x in Omega_b (observed order 0.9-1.1, first order in 1/Omega_b)."""
    settings = ContinuationSettings(lower=24.0, upper=28.0, max_steps=500, max_step=0.1, stop_at_grazing=True)
    found = {}
    for bumper in (None, 250.0, 1000.0, 4000.0):
        mapping, orbit = shot(25.0, bumper, bounds={"frequency": (10.0, 50.0)})
        branch = continue_branch(mapping, orbit, "frequency", settings)
        found[bumper] = {kind: [p.value for p in branch.special_points if p.kind == kind] for kind in ("fold", "period_doubling")}
    for kind in ("fold", "period_doubling"):
        rigid = found[None][kind][0]
        errors = np.array([abs(found[b][kind][0] - rigid) for b in (250.0, 1000.0, 4000.0)])
        orders = np.log(errors[:-1] / errors[1:]) / np.log(4.0)
        assert np.all((orders > 0.85) & (orders < 1.15)), (kind, errors, orders)


def test_resection_moves_the_strobe_between_contacts() -> None:
    """A bumper orbit strobed at t = 0 seen through the middle of the widest gap between its contacts: the moved
    state is a fixed point of the new problem's map (to 1e-9 of the scale), and no contact is under way there."""
    from vibroimpact.orbits.maps import resection

    mapping, orbit = shot(25.0, 250.0)
    moved, state = resection(mapping.problem, orbit.state, 1)
    assert abs(moved.phase - mapping.problem.phase) > 1e-3
    image = ImpactMap(moved).evaluate(state, ImpactMap(moved).parameters)
    np.testing.assert_allclose(image.image, state, rtol=0.0, atol=1e-9 * ImpactMap(moved).state_scale.max())
    assert image.hybrid.impacts == 1 and state[1] < PAPER_CLEARANCE  # the absorber below the bumper: free flight
