"""One swept-sine run's physics: its linear start and what is measured from it (:mod:`vibroimpact.simulation.swept`)."""

from __future__ import annotations

import numpy as np
import pytest

from vibroimpact.analysis.linear import linear_response
from vibroimpact.engines.registry import make_engine
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.model.contact import KelvinVoigtBumper
from vibroimpact.model.excitation import SweptSine
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.simulation.swept import SWEEP_QUANTITIES, sweep_estimates, sweep_start_state


def test_linear_start_state_is_the_steady_response_to_the_sine() -> None:
    sweep = SweptSine(10.0, 15.0, 45.0, 0.1)
    state = sweep_start_state(PAPER_SYSTEM, sweep, 0.003)
    # independently: (K - w^2 M + j w B) X = F with F = q exp(-j pi / 2) on the primary mass (q sin = Re(-j q e^{jwt}))
    s = PAPER_SYSTEM
    w = 2 * np.pi * 15.0
    dynamic = np.array([[s.k1 + s.k2, -s.k2], [-s.k2, s.k2]]) - w**2 * np.diag([s.m1, s.m2]) + 1j * w * np.array([[s.b1 + s.b2, -s.b2], [-s.b2, s.b2]])
    x = np.linalg.solve(dynamic, np.array([-10.0j, 0.0]))
    assert state is not None
    np.testing.assert_allclose(state, np.concatenate([x.real, (1j * w * x).real]), rtol=1e-12, atol=1e-15)
    assert sweep_start_state(PAPER_SYSTEM, SweptSine(10.0, 23.0, 45.0, 0.1), 0.003) is None  # at resonance it would cross the stop


@pytest.mark.timeout(60)
def test_estimates_of_a_slow_sweep_without_contact_are_the_linear_steady_state() -> None:
    """Far from the stop a slow sweep started on the linear state stays on it: the window-centred fundamentals are the
    linear response at each frequency, no impacts; frequencies the sweep never reaches (or whose window it leaves) are NaN."""
    sweep = SweptSine(10.0, 15.0, 16.0, 0.25)
    bumper = KelvinVoigtBumper(1.0, 1000.0, 0.1)  # 1 m: never touched
    state = sweep_start_state(PAPER_SYSTEM, sweep, bumper.clearance)
    record = make_engine("compliant", EngineSettings(rtol=1e-8, atol=1e-12)).sweep(ImpactProblem(PAPER_SYSTEM, bumper, sweep), 2000.0, state)
    times = np.linspace(0.0, sweep.duration, 5)
    out = sweep_estimates(record, sweep, (14.0, 15.5, 17.0), times, 8)
    assert set(SWEEP_QUANTITIES) | {f"running_{q}" for q in SWEEP_QUANTITIES} | {"time", "instantaneous_frequency"} == set(out)
    assert np.isnan(out["x1_amplitude"][[0, 2]]).all() and np.isfinite(out["x1_amplitude"][1])
    linear = linear_response(PAPER_SYSTEM, np.array([2.0 * np.pi * 15.5]), 10.0)
    assert out["x1_amplitude"][1] == pytest.approx(abs(linear.x1[0]), rel=1e-2)
    assert out["x2_amplitude"][1] == pytest.approx(abs(linear.x2[0]), rel=1e-2)
    assert out["impacts_per_period"][1] == 0.0 and out["peak_contact_force"][1] == 0.0  # exact: no contact counted
    np.testing.assert_allclose(out["instantaneous_frequency"], 15.0 + 0.25 * times)
    assert np.isnan(out["running_x1_amplitude"][0]) and np.isfinite(out["running_x1_amplitude"][2])  # the first window leaves the run
