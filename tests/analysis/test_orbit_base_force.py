"""The force an impact orbit passes to the base (:meth:`ImpactOrbit.base_force`): one formula, which the concepts kind
and the grid study of the stepped and swept kinds (:mod:`vibroimpact.grids.closed_forms`) both call.

Hand derivation (Newton's third law on the whole structure): M x'' + C x' + K x = f(t) - n lambda(t) summed over the
coordinates gives 1^T (K x + C x') + (1^T n) lambda = 1^T f - 1^T M x''; the fundamental of the left side is the base
force, so with X the orbit's harmonics (time from the impact, where the load is F e^{j(phi - theta)}) it equals
1^T F e^{j(phi - theta)} + w^2 1^T M X, computed without the base force's own formula.
"""

from __future__ import annotations

import numpy as np
import pytest

from vibroimpact.analysis.impact_orbit import ImpactOrbit, solve_impact_orbit
from vibroimpact.analysis.linear import base_force
from vibroimpact.model.contact import RigidStop, Stop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.structure import LinearStructure
from vibroimpact.model.system import PAPER_SYSTEM

FREQUENCIES = np.linspace(18.0, 42.0, 241)
#: One mass on a spring and dashpot to the base, its stop against the base: F_base = q e^{j(phi - theta)} + m w^2 X.
ONE_MASS = LinearStructure(mass=[[2.0]], stiffness=[[8.0e4]], damping=[[3.0]])
LAYOUTS = {
    "upper": (PAPER_SYSTEM.structure, (Stop(RigidStop(3e-3, 0.6), 1),)),
    "lower": (PAPER_SYSTEM.structure, (Stop(RigidStop(3e-3, 0.6), 1, side="lower"),)),
    "relative": (PAPER_SYSTEM.structure, (Stop(RigidStop(3e-3, 0.6), 1, other=0),)),
    "two_sided": (PAPER_SYSTEM.structure, (Stop(RigidStop(3e-3, 0.6), 1), Stop(RigidStop(3e-3, 0.6), 1, side="lower"))),
    "one_mass": (ONE_MASS, (Stop(RigidStop(1e-4, 0.5), 0),)),
}


def orbit_of(layout: str) -> ImpactOrbit:
    structure, stops = LAYOUTS[layout]
    problem = ImpactProblem(structure, stops, HarmonicForce(10.0, float(FREQUENCIES[0]), 0.3))
    return solve_impact_orbit(problem, omega=2.0 * np.pi * FREQUENCIES)


@pytest.mark.parametrize("layout", list(LAYOUTS))
def test_the_base_force_is_the_load_less_the_inertia(layout: str) -> None:
    """Where the orbit exists: base force = 1^T F e^{j(phi - theta)} + w^2 1^T M X (module docstring), to 1e-11 of
    the larger of the load and the inertia."""
    orbit = orbit_of(layout)
    e = orbit.exists
    assert e.sum() > 20
    structure = orbit.layout.structure
    rotation = np.exp(1j * (orbit.phase - np.angle(orbit.gap_response)))
    load = orbit.load.sum(axis=-1) * rotation
    inertia = orbit.omega**2 * (orbit.harmonics() @ structure.mass_matrix.sum(axis=0))
    scale = np.abs(load) + np.abs(inertia)
    assert np.max(np.abs(orbit.base_force() - (load + inertia))[e] / scale[e]) < 1e-11


@pytest.mark.parametrize(("layout", "through", "per_period"), [("upper", 1.0, 2.0), ("lower", -1.0, 2.0), ("relative", 0.0, 2.0), ("two_sided", 1.0, 4.0)])
def test_the_stops_part_is_their_impulse_trains_fundamental(layout: str, through: float, per_period: float) -> None:
    """Suspension alone: 1^T (K + j w C) X of the orbit's harmonics; the rest (1^T n) k J / T, k = 2 for one impact per
    period (J at t = 0), 4 for the two-sided stop (J at 0, -J at T/2): nothing for a stop between the masses."""
    orbit = orbit_of(layout)
    e = orbit.exists
    suspension = orbit.base_force(suspension_only=True)
    np.testing.assert_allclose(suspension[e], base_force(orbit.layout.structure, orbit.omega, orbit.harmonics())[e], rtol=1e-15)
    stops = orbit.base_force() - suspension
    expected = through * per_period * orbit.impulse / orbit.period
    np.testing.assert_allclose(stops[e], expected[e], rtol=1e-12, atol=1e-12 * float(np.max(np.abs(suspension[e]))))


def test_the_concepts_kind_reports_the_orbits_base_force() -> None:
    """The concepts' closed form of a stop concept is |ImpactOrbit.base_force| where the orbit is admissible."""
    from vibroimpact.kinds.concepts.scene import Concept
    from vibroimpact.kinds.concepts.study import closed_forms

    stops = LAYOUTS["upper"][1]
    concept = Concept("stop", "a stop on x2", PAPER_SYSTEM, stops)
    forms = closed_forms(concept, 10.0, FREQUENCIES)
    orbit = solve_impact_orbit(concept.problem(10.0, float(FREQUENCIES[0])), omega=2.0 * np.pi * FREQUENCIES)
    admissible = orbit.admissible()
    assert admissible.sum() > 20
    np.testing.assert_allclose(forms.impact_base_force[admissible], np.abs(orbit.base_force())[admissible], rtol=1e-15)
    assert np.all(np.isnan(forms.impact_base_force[~admissible]))
