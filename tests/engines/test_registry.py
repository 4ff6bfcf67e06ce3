"""Every registered engine builds and runs a small problem of its contact law (and the sweeping ones a sweep)."""

from __future__ import annotations

import numpy as np
import pytest

from vibroimpact.engines.registry import BUMPER, ENGINES, RIGID, engine_names, engine_spec, make_engine
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop
from vibroimpact.model.excitation import HarmonicForce, SweptSine
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM

from tests.conftest import PAPER_AMPLITUDE, PAPER_CLEARANCE

SETTINGS = EngineSettings(rtol=1e-7, atol=1e-11)


@pytest.mark.timeout(60)
@pytest.mark.parametrize("name", list(ENGINES))
def test_every_engine_integrates_a_problem_of_its_contact_law(name: str) -> None:
    contact = RigidStop(PAPER_CLEARANCE, 0.4) if engine_spec(name).contact == RIGID else KelvinVoigtBumper(PAPER_CLEARANCE, 1000.0, 0.3)
    problem = ImpactProblem(PAPER_SYSTEM, contact, HarmonicForce(PAPER_AMPLITUDE, 25.0))
    trajectory = make_engine(name, SETTINGS).integrate(problem, np.zeros(4), 0.0, 5, moments=True)
    assert trajectory.periods == 5 and trajectory.impact_times.size >= 2
    assert trajectory.moments.shape == (5, 5) and np.all(np.isfinite(trajectory.strobe_states))


@pytest.mark.timeout(60)
@pytest.mark.parametrize("name", engine_names(BUMPER))
def test_every_bumper_engine_sweeps(name: str) -> None:
    problem = ImpactProblem(PAPER_SYSTEM, KelvinVoigtBumper(PAPER_CLEARANCE, 1000.0, 0.3), SweptSine(PAPER_AMPLITUDE, 24.0, 24.2, 0.1))
    record = make_engine(name, SETTINGS).sweep(problem, 500.0)
    assert record.time.size == 1000 and record.trajectory.impact_times.size >= 40


@pytest.mark.parametrize("name", engine_names(BUMPER))
def test_bumper_engines_refuse_a_rigid_stop(name: str) -> None:
    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(PAPER_CLEARANCE, 0.4), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    with pytest.raises(TypeError, match="solves a KelvinVoigtBumper"):
        make_engine(name).integrate(problem, np.zeros(4), 0.0, 1)


def test_a_fixed_method_overrides_the_settings() -> None:
    assert make_engine("momentary_bdf", EngineSettings(method="adams")).settings.method == "bdf"
    assert make_engine("compliant_cvode_adams", EngineSettings(method="bdf")).name == "compliant_cvode_adams"


def test_an_unknown_name_lists_the_registered_ones() -> None:
    with pytest.raises(ValueError, match="engine 'adams' is unknown: use one of exact, exact_python, momentary"):
        make_engine("adams")
