"""One swept-sine run's physics: its linear start and what is measured from it (:mod:`vibroimpact.simulation.swept`)."""

from __future__ import annotations

import numpy as np
import pytest

from vibroimpact.analysis.linear import paper_linear_response
from vibroimpact.engines.registry import make_engine
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.model.contact import KelvinVoigtBumper
from vibroimpact.model.excitation import SweptSine
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.contact import Stop
from vibroimpact.model.structure import LinearStructure
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.simulation.swept import SWEEP_STOP_QUANTITIES, sweep_estimates, sweep_quantities, sweep_start_state

BUMPER = KelvinVoigtBumper(0.003, 250.0, 0.73)


def test_linear_start_state_is_the_steady_response_to_the_sine() -> None:
    sweep = SweptSine(10.0, 15.0, 45.0, 0.1)
    state = sweep_start_state(ImpactProblem(PAPER_SYSTEM, BUMPER, sweep))
    # independently: (K - w^2 M + j w B) X = F with F = q exp(-j pi / 2) on the primary mass (q sin = Re(-j q e^{jwt}))
    s = PAPER_SYSTEM
    w = 2 * np.pi * 15.0
    dynamic = np.array([[s.k1 + s.k2, -s.k2], [-s.k2, s.k2]]) - w**2 * np.diag([s.m1, s.m2]) + 1j * w * np.array([[s.b1 + s.b2, -s.b2], [-s.b2, s.b2]])
    x = np.linalg.solve(dynamic, np.array([-10.0j, 0.0]))
    assert state is not None
    np.testing.assert_allclose(state, np.concatenate([x.real, (1j * w * x).real]), rtol=1e-12, atol=1e-15)
    assert sweep_start_state(ImpactProblem(PAPER_SYSTEM, BUMPER, SweptSine(10.0, 23.0, 45.0, 0.1))) is None  # at resonance it would cross the stop


def test_linear_start_of_a_general_layout_takes_its_load_static_force_and_every_stop() -> None:
    """Three masses in a chain, the sine on the middle one (weights 0, 1, 0), gravity-like static forces, a relative
    stop x3 - x2 <= Delta: the start is x0 + Re(-j X) with (K - w^2 M + j w C) X = q e_2 and K x0 = F0 (solved here
    directly), and None once Delta is below the reach n . x0 + |n . X| of the relative coordinate."""
    mass, stiffness, damping = np.diag([1.0, 0.5, 0.2]), np.array([[3e4, -1e4, 0.0], [-1e4, 2e4, -1e4], [0.0, -1e4, 1e4]]), np.diag([1.0, 1.0, 1.0]) * 0.5
    structure = LinearStructure(mass=mass.tolist(), stiffness=stiffness.tolist(), damping=damping.tolist(), coordinates=("a", "b", "c"))
    sweep = SweptSine(5.0, 12.0, 20.0, 1.0, weights=(0.0, 1.0, 0.0), static=(-9.81, -4.9, -1.96))
    w = 2 * np.pi * 12.0
    x = np.linalg.solve(stiffness - w**2 * mass + 1j * w * damping, np.array([0.0, -5.0j, 0.0]))
    x0 = np.linalg.solve(stiffness, np.array([-9.81, -4.9, -1.96]))
    reach = (x0[2] - x0[1]) + abs(x[2] - x[1])
    state = sweep_start_state(ImpactProblem(structure, (Stop(KelvinVoigtBumper(1.01 * reach, 250.0, 0.5), coordinate=2, other=1),), sweep))
    assert state is not None
    np.testing.assert_allclose(state, np.concatenate([x0 + x.real, (1j * w * x).real]), rtol=1e-12, atol=1e-15)
    assert sweep_start_state(ImpactProblem(structure, (Stop(KelvinVoigtBumper(0.99 * reach, 250.0, 0.5), coordinate=2, other=1),), sweep)) is None


@pytest.mark.timeout(60)
def test_estimates_of_a_slow_sweep_without_contact_are_the_linear_steady_state() -> None:
    """Far from the stop a slow sweep started on the linear state stays on it: the window-centred fundamentals are the
    linear response at each frequency, no impacts; frequencies the sweep never reaches (or whose window it leaves) are NaN."""
    sweep = SweptSine(10.0, 15.0, 16.0, 0.25)
    bumper = KelvinVoigtBumper(1.0, 1000.0, 0.1)  # 1 m: never touched
    problem = ImpactProblem(PAPER_SYSTEM, bumper, sweep)
    state = sweep_start_state(problem)
    record = make_engine("compliant", EngineSettings(rtol=1e-8, atol=1e-12)).sweep(problem, 2000.0, state)
    times = np.linspace(0.0, sweep.duration, 5)
    out = sweep_estimates(record, sweep, (14.0, 15.5, 17.0), times, 8)
    names = sweep_quantities(("x1", "x2"))
    assert names == ("x1_amplitude", "x2_amplitude", "force_amplitude", "suspension_force_amplitude", "impulse", "impacts_per_period", "x1_rms", "x2_rms", "peak_acceleration", "peak_contact_force")
    assert set(names) | {f"running_{q}" for q in names} | {"time", "instantaneous_frequency"} == set(out)
    assert all(out[q].shape == (1, 3) for q in SWEEP_STOP_QUANTITIES)  # one stop
    assert np.isnan(out["x1_amplitude"][[0, 2]]).all() and np.isfinite(out["x1_amplitude"][1])
    linear = paper_linear_response(PAPER_SYSTEM, omega=np.array([2.0 * np.pi * 15.5]), amplitude=10.0)
    assert out["x1_amplitude"][1] == pytest.approx(abs(linear.x1[0]), rel=1e-2)
    assert out["x2_amplitude"][1] == pytest.approx(abs(linear.x2[0]), rel=1e-2)
    assert out["impacts_per_period"][1] == 0.0 and out["peak_contact_force"][0, 1] == 0.0  # exact: no contact counted
    np.testing.assert_allclose(out["instantaneous_frequency"], 15.0 + 0.25 * times)
    assert np.isnan(out["running_x1_amplitude"][0]) and np.isfinite(out["running_x1_amplitude"][2])  # the first window leaves the run
