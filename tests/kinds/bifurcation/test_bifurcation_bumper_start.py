"""A bumper's branch starts from the rigid stop's orbit continued in the bumper's stiffness, and its brute force
integrates the bumper: the shipped ``bifurcation_bumper`` system (Delta = 3 mm, q = 10 N, R = 0.2)."""

from __future__ import annotations

import numpy as np
import pytest

from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.kinds.bifurcation.branches import map_bounds, problem_at, rigid_twin
from vibroimpact.kinds.bifurcation.bumper_start import BumperStart, bumper_start
from vibroimpact.kinds.bifurcation.cases import MOTION_CLASSES, SweepCase
from vibroimpact.kinds.bifurcation.study import diagram_problem
from vibroimpact.engines.registry import BUMPER, engine_for
from vibroimpact.orbits.maps import ImpactMap, closed_form_state, section_phase
from vibroimpact.orbits.orbit_measures import orbit_measures
from vibroimpact.orbits.shooting import shoot
from vibroimpact.scene import find_scene, load_scene


def _start(frequency: float, bumper: float, root: str) -> tuple[BumperStart, ImpactMap, ImpactMap]:
    """The start at ``frequency`` [Hz] of the ``bumper`` Hz bumper's branch from the rigid orbit of ``root``, with the
    bumper's map and the rigid twin's."""
    problem = diagram_problem(load_scene(find_scene("bifurcation_bumper")), 0.2, bumper_frequency=bumper)
    reference = rigid_twin(problem)
    phase = section_phase(problem_at(reference, frequency), np.array([frequency - 0.05, frequency + 0.05]))
    twin = ImpactMap(problem_at(reference, frequency, phase=phase), bounds=map_bounds(15.0, 45.0))
    rigid = shoot(twin, closed_form_state(twin.problem, solve_impact_orbit(twin.problem, root=root)), twin.parameters)
    mapping = ImpactMap(problem_at(problem, frequency, phase=phase), bounds=map_bounds(15.0, 45.0))
    return bumper_start(mapping, rigid), mapping, twin


def test_the_rigid_orbit_continued_to_a_bumper_is_that_bumpers_orbit_near_the_rigid_one() -> None:
    """At 25 Hz the 1 kHz bumper's one-contact orbit: a fixed point of its own map, with one contact per period, and
    its X1 within a few per cent of the rigid stop's (first order in 1 / Omega_b: the 4 kHz bumper is 4 times nearer)."""
    start, mapping, twin = _start(25.0, 1000.0, "+")
    assert start.orbit is not None and start.why == "" and start.softest == pytest.approx(1000.0, rel=1e-9)
    assert start.orbit.residual < 1e-9 and start.orbit.impacts == 1
    rigid = orbit_measures(twin, shoot(twin, start.orbit.state, twin.parameters)).amplitudes[0]
    mine = orbit_measures(mapping, start.orbit).amplitudes[0]
    stiffer, stiff_map, _ = _start(25.0, 4000.0, "+")
    assert stiffer.orbit is not None
    near = orbit_measures(stiff_map, stiffer.orbit).amplitudes[0]
    assert 0.0 < abs(near - rigid) < 0.5 * abs(mine - rigid) < 0.05 * rigid


def test_a_rigid_orbit_with_no_counterpart_at_the_bumper_says_where_it_vanishes() -> None:
    """At 18.70 Hz the rigid stop's orbit exists only with bumpers stiffer than about 15 kHz: followed in the bumper's
    stiffness it turns back there (a fold in T_b), an answer instead of a failed start."""
    start, _mapping, _twin = _start(18.70, 1000.0, "+")
    assert start.orbit is None and "turns back at Omega_b / 2 pi = 1.5" in start.why and "fold in T_b" in start.why
    assert start.softest == pytest.approx(15077.0, rel=2e-3)


def test_the_brute_force_of_a_bumper_integrates_the_bumper() -> None:
    """A bumper diagram's sweep runs the bumper's engine (the registry's, by capability) and settles, at 25 Hz, on one
    contact per period with the X1 of the bumper's orbit (not the rigid stop's)."""
    problem = diagram_problem(load_scene(find_scene("bifurcation_bumper")), 0.2, bumper_frequency=250.0)
    engine = engine_for(BUMPER, "exact_jacobians")
    out = SweepCase(problem, "up", (25.0,), 200, 64, engine=engine).run()
    assert MOTION_CLASSES[int(out["regime"][0])] == "one_impact" and out["impacts"][0] == pytest.approx(1.0)
    start, mapping, twin = _start(25.0, 250.0, "+")
    assert start.orbit is not None
    bumper = orbit_measures(mapping, start.orbit).amplitudes[0]
    rigid = orbit_measures(twin, shoot(twin, start.orbit.state, twin.parameters)).amplitudes[0]
    assert np.nanmax(out["amplitude"][0]) == pytest.approx(bumper, rel=1e-6) and abs(bumper - rigid) > 1e-3 * rigid


def test_the_linear_orbit_is_sampled_as_a_curve_on_a_narrow_band() -> None:
    """A band 600 times narrower than the paper's still gets the contact-free orbit at >= 400 frequencies (its
    closed form), not three points drawn as two straight lines; the paper's band keeps its 0.02 Hz step."""
    from vibroimpact.kinds.bifurcation.branches import linear_segments

    problem = diagram_problem(load_scene(find_scene("bifurcation_bumper")), 0.2)
    (narrow,) = linear_segments(problem, 16.0, 16.05)
    assert narrow.size >= 400 and narrow[0] == 16.0 and narrow[-1] == pytest.approx(16.05)  # exact: the band's start
    wide = linear_segments(problem, 15.0, 45.0)
    assert np.diff(wide[0][1:-1]).max() == pytest.approx(0.02)
