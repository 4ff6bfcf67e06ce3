"""Frequencies are Hz at every public surface: 25.0 given to a public function that takes a frequency is 25 Hz (or a
clear error), angular frequencies go only under names that say so (``omega``, ``*_angular_*``), and a value out of
range is refused by name, never answered with a silent NaN."""

from __future__ import annotations

import inspect
import math

import numpy as np
import pytest

import vibroimpact
from vibroimpact import (
    PAPER_SYSTEM,
    HarmonicForce,
    ImpactProblem,
    RigidStop,
    Stop,
    linear_amplitudes,
    linear_response,
    load_scene,
    solve_impact_orbit,
    solve_one_impact,
)

#: The paper's example at 25 Hz: 10 N on the primary mass, a stop 3 mm above the absorber, R = 0.2.
PROBLEM = ImpactProblem(PAPER_SYSTEM, (Stop(RigidStop(3e-3, 0.2), coordinate=1),), HarmonicForce(10.0, 25.0))


def test_25_means_25_hz_in_the_closed_forms() -> None:
    """The paper's form at 25.0 is the problem's own closed form at 25 Hz (built from the named system's values rather
    than the problem's), and the angular spelling gives the same numbers."""
    named = solve_one_impact(PAPER_SYSTEM, 25.0, 3e-3, 0.2, 10.0)
    general = solve_one_impact(PROBLEM)
    angular = solve_one_impact(PAPER_SYSTEM, clearance=3e-3, restitution=0.2, amplitude=10.0, omega=2.0 * math.pi * 25.0)
    assert bool(named.exists) and bool(general.exists)
    np.testing.assert_allclose(named.impulse, general.impulse, rtol=1e-10)
    np.testing.assert_allclose(named.impulse, angular.impulse, rtol=1e-15)
    orbit = solve_impact_orbit(PROBLEM, 25.0)
    np.testing.assert_allclose(orbit.impulse, general.impulse, rtol=1e-15)
    np.testing.assert_allclose(orbit.omega, 2.0 * math.pi * 25.0, rtol=1e-15)


def test_25_means_25_hz_in_the_linear_response() -> None:
    """The paper's system is a view of its problem: the same amplitudes, reported at 25 Hz beside 50 pi rad/s."""
    from vibroimpact.analysis.linear import paper_linear_response

    paper = linear_response(PAPER_SYSTEM, 25.0, 10.0)
    general = linear_amplitudes(PROBLEM, 25.0)
    receptances = paper_linear_response(PAPER_SYSTEM, 25.0, 10.0)  # eqs. 4-5
    np.testing.assert_allclose(receptances.x1, general.coordinate("x1"), rtol=1e-12)
    np.testing.assert_allclose(receptances.x2, general.coordinate("x2"), rtol=1e-12)
    np.testing.assert_allclose(receptances.force, general.force, rtol=1e-12)
    np.testing.assert_allclose(paper.amplitudes, general.amplitudes, rtol=1e-15)
    np.testing.assert_allclose(linear_response(PROBLEM).amplitudes, general.amplitudes, rtol=1e-15)  # the problem's own 25 Hz
    assert paper.coordinates == ("x1", "x2") and float(paper.frequency) == pytest.approx(25.0, rel=1e-15)


def test_natural_frequencies_are_hz_and_angular_ones_say_so() -> None:
    """The paper's 23.02 / 36.07 Hz (eq. 11 corrected), from the named system and from its matrices."""
    low, high = PAPER_SYSTEM.natural_frequencies()
    assert low == pytest.approx(23.0221, abs=1e-4) and high == pytest.approx(36.0744, abs=1e-4)
    np.testing.assert_allclose(PAPER_SYSTEM.structure.natural_frequencies(), (low, high), rtol=1e-12)
    np.testing.assert_allclose(PAPER_SYSTEM.natural_angular_frequencies(), (2.0 * math.pi * low, 2.0 * math.pi * high), rtol=1e-15)
    assert PAPER_SYSTEM.antiresonance_frequency() == pytest.approx(math.sqrt(4300.0 / 0.1) / (2.0 * math.pi), rel=1e-15)


@pytest.mark.parametrize("bad", [0.0, -25.0, math.nan, math.inf])
def test_a_frequency_out_of_range_is_refused_by_name(bad: float) -> None:
    for call in (
        lambda: solve_one_impact(PAPER_SYSTEM, bad, 3e-3, 0.2, 10.0),
        lambda: solve_one_impact(PROBLEM, bad),
        lambda: solve_impact_orbit(PROBLEM, [20.0, bad]),
        lambda: linear_response(PAPER_SYSTEM, bad, 10.0),
        lambda: linear_amplitudes(PROBLEM, bad),
    ):
        with pytest.raises(ValueError, match=r"frequency: .* Hz is out of range: allowed \(0, inf\)"):
            call()


def test_other_inputs_out_of_range_are_refused_by_name() -> None:
    with pytest.raises(ValueError, match=r"restitution: 1\.5 is out of range: allowed \[0, 1\]"):
        solve_one_impact(PAPER_SYSTEM, 25.0, 3e-3, 1.5, 10.0)
    with pytest.raises(ValueError, match="clearance: nan is out of range"):
        solve_impact_orbit(PROBLEM, 25.0, clearance=math.nan)
    with pytest.raises(ValueError, match="amplitude: inf is out of range"):
        linear_response(PAPER_SYSTEM, 25.0, math.inf)
    with pytest.raises(TypeError, match="not both"):
        solve_impact_orbit(PROBLEM, 25.0, omega=157.0)


def test_no_public_function_takes_an_angular_frequency_by_position() -> None:
    """A positional number can only be a frequency in Hz: every public ``omega`` parameter is keyword-only."""
    checked = 0
    for name in vibroimpact.__all__:
        value = getattr(vibroimpact, name)
        if not inspect.isfunction(value):
            continue
        for parameter in inspect.signature(value).parameters.values():
            if parameter.name in ("omega", "w", "angular_frequency"):
                assert parameter.kind is inspect.Parameter.KEYWORD_ONLY, f"{name}({parameter.name}) can be given by position"
                checked += 1
    assert checked >= 5  # solve_one_impact, solve_impact_orbit, solve_two_impacts, linear_response, linear_amplitudes


def test_load_scene_finds_what_run_study_finds() -> None:
    """A shipped scene by its listed name, a subfolder's included; an unknown name names the places looked at."""
    assert load_scene("validation/zeno").kind == "validation"
    assert load_scene("restitution").name == "restitution"
    with pytest.raises(FileNotFoundError, match="no_such_scene"):
        load_scene("no_such_scene")
