"""The bumper screen (issue 32): the design search's objective where the stops are Kelvin-Voigt bumpers.

Its worst case must be the steady state a bumper engine marches to (IDA, an independent integrator), the maximum that
continuation locates along the same branch (to the continuation's tolerance), and tend to the rigid stop's closed-form
worst case at first order in the bumper's period as the bumper stiffens (its rigid twin)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from vibroimpact.analysis.band_worst import closed_form_worst
from vibroimpact.analysis.scan_grid import scan_frequencies
from vibroimpact.engines.registry import make_engine
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop, loss_factor_from_restitution
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.orbits.bumper_screen import BUMPER_SCAN, BUMPER_SPACING, bumper_at, bumper_curves, bumper_screen_refusal, bumper_worst, rigid_twin
from vibroimpact.orbits.worst_case import worst_response
from vibroimpact.simulation.settings import SteadySettings
from vibroimpact.simulation.steady import steady_state

BAND = (15.0, 45.0)


def bumper_problem(bumper: float, restitution: float = 0.2, clearance: float = 3e-3, frequency: float = 25.0) -> ImpactProblem:
    """The paper's absorber, q = 10 N, a bumper of Omega_b / 2 pi = ``bumper`` [Hz] whose loss factor gives R."""
    law = KelvinVoigtBumper(clearance, bumper, loss_factor_from_restitution(restitution))
    return ImpactProblem(PAPER_SYSTEM, law, HarmonicForce(10.0, frequency))


def test_the_rigid_twin_has_the_bumper_s_clearance_and_restitution() -> None:
    problem = bumper_problem(250.0, restitution=0.35, clearance=2e-3)
    twin = rigid_twin(problem)
    assert isinstance(twin.stops[0].law, RigidStop) and twin.stops[0].law.clearance == pytest.approx(2e-3, rel=1e-15)
    assert twin.stops[0].law.restitution == pytest.approx(0.35, rel=1e-12)
    assert bumper_screen_refusal(problem) is None and bumper_screen_refusal(twin) is not None  # a rigid stop is the closed forms' own


def test_the_screen_s_worst_case_is_the_steady_state_ida_marches_to() -> None:
    """250 Hz bumper, R = 0.2: at the screen's worst frequency, IDA (rtol 1e-10) from rest settles on a motion whose
    |X1| is the screen's to 1e-7, the 3.01 mm of one contact per period (the rigid stop's is 2.75 mm)."""
    problem = bumper_problem(250.0)
    found = bumper_worst(problem, BAND)
    assert found.motion == "impacting, period 1" and found.impacts == 1
    assert found.amplitude == pytest.approx(3.0085e-3, rel=1e-4) and 24.0 < found.frequency < 26.0
    at = dataclasses.replace(problem, excitation=dataclasses.replace(problem.harmonic, frequency=found.frequency))
    ida = steady_state(make_engine("compliant", EngineSettings(rtol=1e-10, atol=1e-14)), at, "rest", SteadySettings(tolerance=1e-9))
    assert ida.converged and abs(ida.measures.x1) == pytest.approx(found.amplitude, rel=1e-7)


@pytest.mark.slow
def test_the_screen_s_maximum_is_the_one_continuation_locates() -> None:
    """The same bumper: continuation of every branch grown from the rigid twin's closed forms locates the band's
    maximum at the screen's value and frequency (both refine the same stable stretch's interior maximum)."""
    problem = bumper_problem(250.0)
    screened, continued = bumper_worst(problem, BAND), worst_response(problem, BAND)
    assert continued.amplitude == pytest.approx(screened.amplitude, rel=1e-9)
    assert continued.frequency == pytest.approx(screened.frequency, rel=1e-6)


@pytest.mark.slow
@pytest.mark.parametrize(("bumper", "restitution", "clearance", "same"), [(120.0, 0.5, 2e-3, True), (1000.0, 0.05, 4e-3, True), (400.0, 0.8, 1e-3, False)])
def test_the_screen_agrees_with_continuation_on_other_designs(bumper: float, restitution: float, clearance: float, same: bool) -> None:
    """Three more designs (soft and stiff bumpers, small and large R and clearance): on the first two both find the
    same one-contact orbit's maximum (to 1e-9); on the third continuation finds a larger two-contact orbit (9.95 mm
    against the screen's 7.38 mm): the screen sees period-1 one-contact orbits only, never more than continuation."""
    problem = bumper_problem(bumper, restitution, clearance)
    screened, continued = bumper_worst(problem, BAND), worst_response(problem, BAND)
    assert screened.amplitude <= continued.amplitude * (1.0 + 1e-9)
    assert continued.motion.startswith("1 impact per period") is same
    if same:
        assert screened.amplitude == pytest.approx(continued.amplitude, rel=1e-9)
    else:
        assert screened.amplitude < 0.8 * continued.amplitude


def test_a_stiffening_bumper_tends_to_the_rigid_stop_at_first_order() -> None:
    """|X1|max(Omega_b) - |X1|max(rigid) shrinks as 1 / Omega_b (the bumper's period): the differences at 1000, 2000
    and 4000 Hz halve with each doubling, to 10 %, toward the rigid twin's closed-form worst case."""
    rigid = closed_form_worst(rigid_twin(bumper_problem(1000.0)), BAND).amplitude
    gaps = [bumper_worst(bumper_problem(fb), BAND).amplitude - rigid for fb in (1000.0, 2000.0, 4000.0)]
    assert all(g > 0.0 for g in gaps)
    assert gaps[0] / gaps[1] == pytest.approx(2.0, rel=0.1) and gaps[1] / gaps[2] == pytest.approx(2.0, rel=0.1)


def test_the_curves_and_the_operating_point_are_the_screen_s() -> None:
    """The response curves the page draws hold the screen's maximum (to the scan's resolution), and the operating
    point at 33 Hz (the absorber's notch) is the contact-free motion, as for the rigid stop."""
    problem = bumper_problem(250.0)
    f = np.linspace(*BAND, 97)  # not the screen's scan: its points fall between the screen's
    curves = bumper_curves(problem, f)
    stable = np.fmax.reduce([np.where(state == 1, x, np.nan) for x, state in curves.values()])
    assert np.nanmax(stable) <= bumper_worst(problem, BAND).amplitude * (1.0 + 1e-12)
    assert np.nanmax(stable) == pytest.approx(bumper_worst(problem, BAND).amplitude, rel=1e-3)
    notch = bumper_at(problem, 33.0)
    assert notch.motion == "contact-free" and notch.amplitude < 2e-5


def test_the_screen_finds_the_bumper_s_resonance_over_a_wide_band() -> None:
    """250 Hz bumper, R = 0.2: over 15-4500 Hz the screen's 61 evenly spaced shots step 75 Hz, over the whole
    resonance; the points added around the structure's free, locked and bumper-engaged modes find the same 3.0085 mm
    of one contact per period near 24.93 Hz as over 15-45 Hz (to 1e-6 relative), where the scan is the evenly spaced
    one."""
    problem = bumper_problem(250.0)
    narrow, wide = bumper_worst(problem, BAND), bumper_worst(problem, (15.0, 4500.0))
    assert narrow.amplitude == pytest.approx(3.0085e-3, rel=1e-4)
    assert wide.motion == "impacting, period 1" and wide.amplitude == pytest.approx(narrow.amplitude, rel=1e-6)
    assert wide.frequency == pytest.approx(narrow.frequency, rel=1e-5)
    np.testing.assert_array_equal(scan_frequencies(BAND, BUMPER_SCAN, problem, spacing=BUMPER_SPACING), np.linspace(*BAND, BUMPER_SCAN))
