"""Steady states of the time-domain engines: against the PGF closed form, sweeps, cache and processes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.study import cases as simulate
from vibroimpact.engines.exact import ExactEngine

from vibroimpact.engines.settings import EngineSettings
from vibroimpact.engines.momentary import MomentaryEngine
from vibroimpact.analysis.linear import linear_response
from vibroimpact.analysis.pgf import solve_one_impact
from vibroimpact.study.runner import run_cases
from vibroimpact.study.cases import SimulationCase
from vibroimpact.simulation.steady import steady_state
from vibroimpact.simulation.settings import SteadySettings
from vibroimpact.model.system import TwoDofSystem

from tests.conftest import PAPER_AMPLITUDE, PAPER_CLEARANCE


def pgf_values(system: TwoDofSystem, frequency: float, restitution: float) -> dict[str, float]:
    orbit = solve_one_impact(system, np.array([2 * np.pi * frequency]), PAPER_CLEARANCE, restitution, PAPER_AMPLITUDE)
    return {
        "x1": abs(orbit.x1_harmonic()[0]),
        "x2": abs(orbit.x2_harmonic()[0]),
        "force": abs(orbit.force_harmonic()[0]),
        "impulse": float(orbit.impulse[0]),
    }


@pytest.mark.parametrize(("frequency", "restitution"), [(25.0, 0.2), (26.0, 0.6), (40.0, 0.2), (22.0, 0.0)])
def test_exact_steady_state_equals_pgf(system: TwoDofSystem, frequency: float, restitution: float) -> None:
    """At stable points the exact engine's measured steady state is the closed-form solution to ~1e-9."""
    problem = ImpactProblem(system, RigidStop(PAPER_CLEARANCE, restitution), HarmonicForce(PAPER_AMPLITUDE, frequency))
    result = steady_state(ExactEngine(), problem, "pgf", SteadySettings(tolerance=1e-11, max_periods=3000))
    expected = pgf_values(system, frequency, restitution)
    m = result.measures
    assert result.converged and result.multiplicity == 1 and m.impacts_per_period == 1.0  # exact: a count per period
    assert abs(m.x1) == pytest.approx(expected["x1"], rel=1e-9)
    assert abs(m.x2) == pytest.approx(expected["x2"], rel=1e-9)
    assert abs(m.force) == pytest.approx(expected["force"], rel=1e-9)
    assert m.mean_impulse == pytest.approx(expected["impulse"], rel=1e-9)


def test_momentary_steady_state_equals_pgf_to_its_tolerance(system: TwoDofSystem) -> None:
    problem = ImpactProblem(system, RigidStop(PAPER_CLEARANCE, 0.2), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    result = steady_state(MomentaryEngine(EngineSettings(rtol=1e-10, atol=1e-14)), problem, "pgf", SteadySettings(tolerance=1e-9))
    expected = pgf_values(system, 25.0, 0.2)
    assert result.converged
    assert abs(result.measures.x1) == pytest.approx(expected["x1"], rel=1e-7)
    assert result.measures.mean_impulse == pytest.approx(expected["impulse"], rel=1e-7)


def test_linear_point_is_answered_without_integrating(system: TwoDofSystem) -> None:
    problem = ImpactProblem(system, RigidStop(PAPER_CLEARANCE, 0.2), HarmonicForce(PAPER_AMPLITUDE, 30.0))
    result = steady_state(ExactEngine(), problem, "linear")
    assert not result.integrated and result.periods_used == 0
    assert abs(result.measures.x1) == pytest.approx(abs(linear_response(system, problem.omega, PAPER_AMPLITUDE).x1), rel=1e-15)


def test_measured_linear_motion_has_exact_harmonics_and_rms(system: TwoDofSystem) -> None:
    """Integrating the linear steady state (no contact) measures its amplitude and RMS = amplitude / sqrt 2 exactly."""
    problem = ImpactProblem(system, RigidStop(1.0, 0.2), HarmonicForce(PAPER_AMPLITUDE, 30.0))
    response = linear_response(system, problem.omega, PAPER_AMPLITUDE)
    state = np.array([response.x1.real, response.x2.real, (1j * problem.omega * response.x1).real, (1j * problem.omega * response.x2).real])
    result = steady_state(ExactEngine(), problem, (0.0, state), SteadySettings(tolerance=1e-10))
    m = result.measures
    assert result.integrated and m.impacts_per_period == 0.0  # exact: a count per period
    assert m.x1 == pytest.approx(complex(response.x1), rel=1e-11)
    assert m.x2_rms == pytest.approx(abs(response.x2) / np.sqrt(2), rel=1e-11)
    assert abs(m.force) == pytest.approx(abs(response.force), rel=1e-11)


@pytest.mark.parametrize("engine", [ExactEngine(), MomentaryEngine()])
def test_unstable_pgf_orbit_is_left(system: TwoDofSystem, engine: object) -> None:
    """At 38 Hz (R = 0.2, Floquet modulus 1.108) a start next to the orbit does not stay on it."""
    problem = ImpactProblem(system, RigidStop(PAPER_CLEARANCE, 0.2), HarmonicForce(PAPER_AMPLITUDE, 38.0))
    result = steady_state(engine, problem, "pgf", SteadySettings(max_periods=300))  # type: ignore[arg-type]
    expected = pgf_values(system, 38.0, 0.2)
    assert not (result.converged and abs(abs(result.measures.x1) - expected["x1"]) < 1e-3 * expected["x1"])


def _case(system: TwoDofSystem, start: str, engine: str = "exact", frequencies: tuple[float, ...] = (24.0, 24.5, 25.0, 25.5)) -> SimulationCase:
    return SimulationCase(engine, system, PAPER_AMPLITUDE, RigidStop(PAPER_CLEARANCE, 0.2), frequencies, start, EngineSettings(), SteadySettings(tolerance=1e-9, max_periods=2000))


@pytest.mark.parametrize("start", ["sweep_up", "sweep_down"])
def test_stepped_sweep_lands_on_the_stable_orbits(system: TwoDofSystem, start: str) -> None:
    """A stepped sweep through a band of stable one-impact orbits ends on each of them."""
    case = _case(system, start)
    result = simulate.run_case(case)
    for i, frequency in enumerate(case.frequencies):
        expected = pgf_values(system, frequency, 0.2)
        assert result["converged"][i] == 1.0 and result["impacts_per_period"][i] == 1.0  # exact: flags and counts
        assert abs(result["x1"][i]) == pytest.approx(expected["x1"], rel=1e-7)


def test_cache_resumes_without_recomputing(system: TwoDofSystem, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    cases = [_case(system, "pgf", frequencies=(25.0,)), _case(system, "linear", frequencies=(30.0, 31.0))]
    first = run_cases(cases, cache_dir=tmp_path, progress=False)
    assert len(list(tmp_path.glob("*.npz"))) == 2

    def fail(case: SimulationCase, report: object = None) -> dict:
        raise AssertionError("a cached case was recomputed")

    monkeypatch.setattr(simulate, "run_case", fail)
    second = run_cases(cases, cache_dir=tmp_path, progress=False)
    for a, b in zip(first, second):
        for name in simulate.FIELDS:
            if name != "wall_time":
                np.testing.assert_array_equal(a[name], b[name])


def test_processes_give_the_same_results(system: TwoDofSystem) -> None:
    cases = [_case(system, "pgf", frequencies=(25.0, 26.0)), _case(system, "pgf", engine="momentary", frequencies=(25.0,))]
    serial = run_cases(cases, jobs=1, progress=False)
    parallel = run_cases(cases, jobs=2, progress=False)
    for a, b in zip(serial, parallel):
        np.testing.assert_array_equal(a["x1"], b["x1"])


def test_a_failing_point_costs_only_itself(system: TwoDofSystem, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    """An engine failure at one frequency leaves NaN there, flagged, and the other points of the case are kept."""
    real = simulate.steady_state

    def flaky(engine: object, problem: ImpactProblem, start: object, settings: SteadySettings, orbit_stop: object = None) -> object:
        if problem.frequency == 25.0:  # exact: a grid value
            raise RuntimeError("CVODE failed (simulated)")
        return real(engine, problem, start, settings, orbit_stop)  # type: ignore[arg-type]

    monkeypatch.setattr(simulate, "steady_state", flaky)
    result = simulate.run_case(_case(system, "sweep_up"))
    assert list(result["failed"]) == [0.0, 0.0, 1.0, 0.0]
    assert np.isnan(result["x1"][2]) and np.all(np.isfinite(result["x1"][[0, 1, 3]]))
    assert "f = 25 Hz failed: CVODE failed (simulated)" in capsys.readouterr().err
