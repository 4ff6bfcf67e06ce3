"""Steady-state cases of a study (kinds/stepped/cases.py): stepped sweeps from point to point, the resumable store, dask
workers against one process, and a failing point that costs only itself."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from vibroimpact.engines.settings import EngineSettings
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import TwoDofSystem
from vibroimpact.simulation.settings import SteadySettings
from vibroimpact.kinds.stepped import cases as study_cases
from vibroimpact.kinds.stepped.cases import SimulationCase
from vibroimpact.runs.runner import Runner
from vibroimpact.runs.store import StudyStore

from tests.conftest import PAPER_AMPLITUDE, PAPER_CLEARANCE
from tests.simulation.test_steady import pgf_values


def _case(system: TwoDofSystem, start: str, engine: str = "exact", frequencies: tuple[float, ...] = (24.0, 24.5, 25.0, 25.5)) -> SimulationCase:
    return SimulationCase(engine, system, PAPER_AMPLITUDE, RigidStop(PAPER_CLEARANCE, 0.2), frequencies, start, EngineSettings(), SteadySettings(tolerance=1e-9, max_periods=2000))


@pytest.mark.parametrize("start", ["sweep_up", "sweep_down"])
def test_stepped_sweep_lands_on_the_stable_orbits(system: TwoDofSystem, start: str) -> None:
    """A stepped sweep through a band of stable one-impact orbits ends on each of them."""
    case = _case(system, start)
    result = study_cases.run_case(case)
    for i, frequency in enumerate(case.frequencies):
        expected = pgf_values(system, frequency, 0.2)
        assert result["converged"][i] == 1.0 and result["impacts_per_period"][i] == 1.0  # exact: flags and counts
        assert abs(result["displacements"][i, 0]) == pytest.approx(expected["x1"], rel=1e-7)


def test_store_resumes_without_recomputing(system: TwoDofSystem, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    cases = [_case(system, "pgf", frequencies=(25.0,)), _case(system, "linear", frequencies=(30.0, 31.0))]
    store = tmp_path / "study.zarr"
    first = Runner(store=StudyStore(store, "fingerprint"), progress=False).map(cases)
    assert StudyStore(store, "fingerprint").case_count() == 2
    assert StudyStore(store, "another scene").case_count() == 0  # another fingerprint: started afresh
    first = Runner(store=StudyStore(store, "fingerprint"), progress=False).map(cases)

    def fail(case: SimulationCase, report: object = None) -> dict:
        raise AssertionError("a cached case was recomputed")

    monkeypatch.setattr(study_cases, "run_case", fail)
    second = Runner(store=StudyStore(store, "fingerprint"), progress=False).map(cases)
    for a, b in zip(first, second):
        for name in study_cases.FIELDS:
            if name != "wall_time":
                np.testing.assert_array_equal(a[name], b[name])


@pytest.mark.slow
def test_dask_workers_give_the_same_results(system: TwoDofSystem) -> None:
    cases = [_case(system, "pgf", frequencies=(25.0, 26.0)), _case(system, "pgf", engine="momentary", frequencies=(25.0,))]
    serial = Runner(jobs=1, progress=False).map(cases)
    with Runner(jobs=2, progress=False) as runner:
        parallel = runner.map(cases)
    for a, b in zip(serial, parallel):
        np.testing.assert_array_equal(a["displacements"], b["displacements"])


def test_a_failing_point_costs_only_itself(system: TwoDofSystem, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    """An engine failure at one frequency leaves NaN there, flagged, and the other points of the case are kept."""
    real = study_cases.steady_state

    def flaky(engine: object, problem: ImpactProblem, start: object, settings: SteadySettings, orbit_stop: object = None, guess: object = "compute") -> object:
        if problem.frequency == 25.0:  # exact: a grid value
            raise RuntimeError("CVODE failed (simulated)")
        return real(engine, problem, start, settings, orbit_stop, guess)  # type: ignore[arg-type]

    monkeypatch.setattr(study_cases, "steady_state", flaky)
    result = study_cases.run_case(_case(system, "sweep_up"))
    assert list(result["failed"]) == [0.0, 0.0, 1.0, 0.0]
    x1 = result["displacements"][:, 0]
    assert np.isnan(x1[2]) and np.all(np.isfinite(x1[[0, 1, 3]]))
    assert "f = 25 Hz failed: CVODE failed (simulated)" in capsys.readouterr().err
