"""Grazing points followed in (frequency, clearance) by repeated location, against the closed form q |H12(f)| = Delta."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from vibroimpact.engines.exact import ExactEngine
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.orbits.continuation import ContinuationSettings, continue_branch
from vibroimpact.orbits.grazing_curve import trace_grazing
from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.analysis.pgf import solve_one_impact
from vibroimpact.orbits.maps import ImpactMap, closed_form_state, section_phase, with_impulse
from vibroimpact.orbits.shooting import ShootingError, shoot

pytestmark = pytest.mark.skipif(not hasattr(ExactEngine, "strobe_map"), reason="needs the compiled exact core (ExactEngine.strobe_map)")

Q = 10.0


def _gap(f: float, delta: float) -> float:
    return Q * abs(complex(PAPER_SYSTEM.receptances(2.0 * np.pi * f).h12)) - delta


def test_the_linear_orbit_grazes_where_q_h12_equals_the_clearance() -> None:
    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(3e-3, 0.2), HarmonicForce(Q, 28.0))
    h, w = PAPER_SYSTEM.receptances(problem.omega), problem.omega
    x1, x2 = Q * complex(h.h11), Q * complex(h.h12)
    system = ImpactMap(problem, bounds={"frequency": (1.0, 100.0)})
    orbit = shoot(system, [x1.real, x2.real, (1j * w * x1).real, (1j * w * x2).real], system.parameters)
    assert orbit.impacts == 0
    curve = trace_grazing(system, orbit, "clearance", {"clearance": (2e-3, 4e-3)}, first="frequency")
    f, d = curve.values("frequency"), curve.values("clearance")
    assert curve.end == "bound, bound" and d.min() == pytest.approx(2e-3) and d.max() == pytest.approx(4e-3) and f.size > 10
    exact = np.array([brentq(_gap, fi - 0.05, fi + 0.05, args=(di,), xtol=1e-14, rtol=1e-15) for fi, di in zip(f, d)])
    assert np.max(np.abs(f - exact) / exact) < 1e-8
    assert curve.measure == "tangency" and all(o.impacts == 0 for o in curve.orbits)


@pytest.mark.slow
def test_the_one_impact_orbits_own_tangency_is_followed() -> None:
    """R = 0.2, 3 mm: the one-impact branch of the narrow band near 18.5 Hz ends where a free flight touches the stop
    (the extended system of the two-parameter continuation has no Jacobian there); along the traced curve the orbit
    keeps one impact, its closest approach is zero and just past it the orbit has another impact count."""
    base = ImpactProblem(PAPER_SYSTEM, RigidStop(3e-3, 0.2), HarmonicForce(Q, 18.5))
    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(3e-3, 0.2), HarmonicForce(Q, 18.5, section_phase(base, np.linspace(18.2, 18.8, 61))))
    system = ImpactMap(problem, bounds={"frequency": (5.0, 90.0)})
    sol = solve_one_impact(PAPER_SYSTEM, omega=problem.omega, clearance=3e-3, restitution=0.2, amplitude=Q)
    c = (1.0 / (PAPER_SYSTEM.m2 * 1.2) + sol.chi_rate_before) / sol.omega
    a, quad_a = Q * np.abs(PAPER_SYSTEM.receptances(sol.omega).h12), c**2 + sol.chi0**2
    smaller = (-3e-3 * sol.chi0 - np.sqrt(quad_a * a**2 - (c * 3e-3) ** 2)) / quad_a  # the admissible root of eq. 16 here
    orbit = shoot(system, closed_form_state(problem, with_impulse(solve_impact_orbit(problem), float(smaller))), system.parameters)
    assert orbit.impacts == 1
    branch = continue_branch(system, orbit, "frequency", ContinuationSettings(lower=15.0, upper=45.0, max_step=0.1, stop_at_grazing=True))
    touching = [p for p in branch.special("grazing") if "touches" in p.note]
    assert touching
    curve = trace_grazing(system, touching[0], "clearance", {"clearance": (2.5e-3, 3.2e-3)}, direction=-1)
    d = curve.values("clearance")
    assert d.min() == pytest.approx(2.5e-3) and len(curve.points) > 5
    for point in curve.points[:: max(1, len(curve.points) // 4)]:
        assert point.orbit.impacts == 1 and point.margin < 1e-6
        assert abs(point.value - point.orbit.parameter("frequency")) < 1e-5
        beyond = point.orbit.parameters.copy()
        beyond[0] = point.value - point.side * 1e-3
        try:
            past = shoot(system, point.orbit.state, beyond)
        except ShootingError:
            continue
        assert past.impacts != 1 or past.hybrid.closest_approach > -1e-12 * past.hybrid.length_scale
