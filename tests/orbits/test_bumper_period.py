"""The compliant model's special points continued in the bumper's stiffness: :class:`BumperPeriodMap`, the map with
the bumper period T_b = 2 pi / Omega_b [s] as a parameter.

The paper's system, Delta = 3 mm, q = 10 N, R = 0.2 (the cases of ``test_bumper_orbits``). The fold of the one-contact
branch near 26.7 Hz, continued in (frequency, T_b) from the 4 kHz bumper's, must pass through the folds located
separately on the frequency branches of other bumpers (1 kHz, 250 Hz, 16 kHz), and end, as T_b -> 0, at the rigid
stop's fold at first order: the Richardson extrapolation of its two stiffest points lands on the rigid fold far
closer than either point.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.orbits.bumper_map import BUMPER_PERIOD, BumperPeriodMap
from vibroimpact.orbits.continuation import ContinuationSettings, continue_branch, continue_special_point
from vibroimpact.orbits.maps import ImpactMap
from vibroimpact.orbits.shooting import shoot

from tests.conftest import PAPER_AMPLITUDE, PAPER_CLEARANCE
from tests.orbits.test_bumper_orbits import R, problem, shot

#: The branches' window around the fold [Hz].
WINDOW = ContinuationSettings(step=0.2, max_steps=400, lower=24.0, upper=28.0, stop_at_grazing=True)
#: The fold curve's settings: the fold's test function det(M - I) is computed to ~1e-10 with stiff bumpers (16-32 kHz),
#: above the default corrector tolerance of 1e-11.
CURVE = ContinuationSettings(step=0.5, max_steps=400, tolerance=1e-9)
#: T_b from 1/64 kHz to 1/200 Hz [s].
PERIODS = (1.0 / 64000.0, 1.0 / 200.0)


def _fold(mapping: ImpactMap, orbit: object) -> object:
    """The first fold of the one-contact branch through ``orbit`` between 24 and 28 Hz."""
    branch = continue_branch(mapping, orbit, "frequency", WINDOW)  # type: ignore[arg-type]
    folds = [point for point in branch.special_points if point.kind == "fold"]
    assert folds, branch.end
    return folds[0]


def test_the_bumper_period_is_the_last_parameter_and_keeps_the_restitution() -> None:
    """T_b = 1 / (Omega_b / 2 pi); setting it changes Omega_b alone (the loss factor, hence R, kept); T_b <= 0 has no
    image; a rigid stop is refused with the reason."""
    mapping = BumperPeriodMap(problem(25.0, 1000.0), bounds={BUMPER_PERIOD: PERIODS})
    assert mapping.parameter_names[-1] == BUMPER_PERIOD and mapping.parameters.shape == (6,)
    assert mapping.parameters[-1] == pytest.approx(1e-3, rel=1e-15)
    p = mapping.parameters.copy()
    p[-1] = 1.0 / 4000.0
    law = mapping.problem_at(p).stops[0].law
    assert isinstance(law, KelvinVoigtBumper) and law.frequency == pytest.approx(4000.0, rel=1e-15)
    assert law.restitution == pytest.approx(R, rel=1e-12) and law.clearance == PAPER_CLEARANCE  # exact: copied input
    y = shot(25.0, 1000.0)[1].state  # type: ignore[attr-defined]
    for bad in (0.0, -1e-3, 1e-2):  # not positive; outside the bounds
        q = mapping.parameters.copy()
        q[-1] = bad
        assert np.all(np.isnan(mapping.evaluate(y, q).image)), bad
    assert isinstance(mapping.with_periods(2), BumperPeriodMap) and mapping.with_periods(2).parameters.shape == (6,)
    rigid = ImpactProblem(PAPER_SYSTEM, RigidStop(PAPER_CLEARANCE, R), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    with pytest.raises(ValueError, match="needs Kelvin-Voigt bumpers on every selected stop"):
        BumperPeriodMap(rigid)
    with pytest.raises(ValueError, match=r"expected 6 positive numbers \(frequency, restitution, clearance, amplitude, phase, bumper_period\)"):
        BumperPeriodMap(problem(25.0, 1000.0), parameter_scale=(1.0, 0.1, 1e-3, 1.0, 1.0))


@pytest.mark.slow
def test_the_fold_continued_in_the_bumper_period_joins_the_bumpers_folds_and_the_rigid_one() -> None:
    """The 4 kHz bumper's fold continued in (frequency, T_b) over 200 Hz - 64 kHz: at 250 Hz, 1 kHz and 16 kHz the
    curve (a cubic spline through its 38 points) is at the fold located on that bumper's own frequency branch to
    1e-7 Hz (measured 2e-9); towards the rigid stop it is first order in T_b: 2 f(T) - f(2T) at the curve's stiffest
    point (64 kHz) is within 1e-5 Hz of the rigid stop's fold (measured 1.3e-6), while f(T) itself is 1.2e-3 Hz
    away."""
    mapping, orbit = shot(25.0, 4000.0)
    stiff = BumperPeriodMap(problem(25.0, 4000.0), bounds={"frequency": (15.0, 45.0), BUMPER_PERIOD: PERIODS})
    fold = _fold(stiff, shoot(stiff, orbit.state, stiff.parameters))  # type: ignore[attr-defined]
    curve = continue_special_point(stiff, fold, BUMPER_PERIOD, CURVE, bounds={BUMPER_PERIOD: PERIODS, "frequency": (15.0, 45.0)})  # type: ignore[arg-type]
    periods = np.array([o.parameter(BUMPER_PERIOD) for o in curve.orbits])
    frequencies = np.array([o.parameters[0] for o in curve.orbits])
    assert periods.min() < 1.05 / 64000.0 and periods.max() > 0.95 / 200.0, curve.end  # the whole range
    assert all(o.residual < 1e-11 and abs(np.linalg.det(o.monodromy - np.eye(4))) < 1e-8 for o in curve.orbits)  # measured 2e-12, 9e-10
    order = np.argsort(periods)
    spline = CubicSpline(periods[order], frequencies[order])
    for bumper in (250.0, 1000.0, 16000.0):
        located = _fold(*shot(25.0, bumper)).value  # type: ignore[attr-defined]
        assert float(spline(1.0 / bumper)) == pytest.approx(located, abs=1e-7), bumper
    rigid_map, rigid_orbit = shot(25.0, None)
    rigid = _fold(rigid_map, rigid_orbit).value  # type: ignore[attr-defined]
    t = periods.min()
    near, twice = float(spline(t)), float(spline(2.0 * t))
    assert abs(near - rigid) > 1e-3  # the stiffest bumper's fold is still visibly off the rigid one ...
    assert abs(2.0 * near - twice - rigid) < 1e-5  # ... by a first-order term: Richardson's extrapolation removes it
    assert math.isclose(rigid, 26.7027, abs_tol=1e-4)  # the rigid fold of the README's convergence table
