"""Every registered engine builds and runs a small problem of its contact law (and the sweeping ones a sweep)."""

from __future__ import annotations

import numpy as np
import pytest

from vibroimpact.engines.registry import BUMPER, CAPABILITIES, ENGINES, RIGID, engine_for, engine_names, engine_spec, make_engine
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
@pytest.mark.parametrize("name", [name for name, spec in ENGINES.items() if spec.capabilities.sweeps])
def test_every_sweeping_engine_sweeps(name: str) -> None:
    problem = ImpactProblem(PAPER_SYSTEM, KelvinVoigtBumper(PAPER_CLEARANCE, 1000.0, 0.3), SweptSine(PAPER_AMPLITUDE, 24.0, 24.2, 0.1))
    record = make_engine(name, SETTINGS).sweep(problem, 500.0)
    assert record.time.size == 1000 and record.trajectory.impact_times.size >= 40


@pytest.mark.parametrize("name", engine_names(BUMPER))
def test_bumper_engines_refuse_a_rigid_stop(name: str) -> None:
    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(PAPER_CLEARANCE, 0.4), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    with pytest.raises(TypeError, match="solves a KelvinVoigtBumper"):
        make_engine(name).integrate(problem, np.zeros(4), 0.0, 1)


def test_the_sweeping_bumper_engines_are_the_integrators() -> None:
    """A closed-form engine has no sweep (a chirp has no closed-form particular solution); every integrating bumper
    engine has one."""
    sweeping = {name for name, spec in ENGINES.items() if spec.capabilities.sweeps}
    assert sweeping == {name for name in engine_names(BUMPER) if not engine_spec(name).capabilities.exact_flow}
    assert "compliant_exact" in engine_names(BUMPER) and not hasattr(make_engine("compliant_exact"), "sweep")


def test_a_fixed_method_overrides_the_settings() -> None:
    assert make_engine("momentary_bdf", EngineSettings(method="adams")).settings.method == "bdf"
    assert make_engine("compliant_cvode_adams", EngineSettings(method="bdf")).name == "compliant_cvode_adams"


def test_an_unknown_name_lists_the_registered_ones() -> None:
    with pytest.raises(ValueError, match="engine 'adams' is unknown: use one of exact, exact_python, momentary"):
        make_engine("adams")


@pytest.mark.parametrize("contact", [RIGID, BUMPER])
@pytest.mark.parametrize("capability", CAPABILITIES)
def test_engine_for_is_the_first_registered_with_the_capability(contact: str, capability: str) -> None:
    """Whichever engine it names solves the contact law with the capability, and none registered before it does."""
    with_it = [name for name in engine_names(contact) if getattr(engine_spec(name).capabilities, capability)]
    if not with_it:
        with pytest.raises(ValueError, match=f"contact = '{contact}', capability = '{capability}': no registered engine"):
            engine_for(contact, capability)
        return
    assert engine_for(contact, capability) == with_it[0]


def test_engine_for_names_the_references_and_refuses_unknown_capabilities() -> None:
    assert (engine_for(RIGID, "exact_flow"), engine_for(BUMPER, "exact_flow")) == ("exact", "compliant_exact")
    assert engine_for(RIGID, "exact_jacobians") == "exact" and engine_for(BUMPER, "sweeps") == "compliant"
    with pytest.raises(ValueError, match="capability = 'jacobians': the capability is unknown: use one of exact_jacobians, exact_flow"):
        engine_for(RIGID, "jacobians")
    with pytest.raises(ValueError, match="contact = 'soft'.*contact laws 'rigid', 'bumper'"):
        engine_for("soft", "exact_flow")


@pytest.mark.parametrize("name", list(ENGINES))
def test_a_built_engine_carries_its_registry_rows_capabilities(name: str) -> None:
    engine = make_engine(name)
    assert engine.capabilities == engine_spec(name).capabilities
    assert engine.capabilities.contact == engine_spec(name).contact


@pytest.mark.parametrize("name", [name for name, spec in ENGINES.items() if spec.capabilities.exact_jacobians])
def test_an_engine_with_exact_jacobians_returns_one_per_period(name: str) -> None:
    contact = RigidStop(PAPER_CLEARANCE, 0.4) if engine_spec(name).contact == RIGID else KelvinVoigtBumper(PAPER_CLEARANCE, 1000.0, 0.3)
    problem = ImpactProblem(PAPER_SYSTEM, contact, HarmonicForce(PAPER_AMPLITUDE, 25.0))
    trajectory = make_engine(name).integrate(problem, np.zeros(4), 0.0, 3, jacobians=True)
    assert trajectory.strobe_jacobians.shape == (3, 4, 4) and np.all(np.isfinite(trajectory.strobe_jacobians))


def test_steady_states_ask_the_capability_not_the_name() -> None:
    """The exact engine registered under another name is measured on its shot orbit as ``exact`` is (the steady
    state asked its name once: a renamed twin marched from the orbit instead)."""
    from vibroimpact.engines.exact import ExactEngine
    from vibroimpact.simulation.steady import steady_state

    class Renamed(ExactEngine):
        name = "exact_under_another_name"

    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(PAPER_CLEARANCE, 0.2), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    reference = steady_state(make_engine("exact"), problem, "shooting")
    renamed = steady_state(Renamed(EngineSettings()), problem, "shooting")
    assert reference.converged and renamed.converged
    assert renamed.periods_used == reference.periods_used  # exact: a count
    assert renamed.measures.x1 == pytest.approx(reference.measures.x1, rel=1e-14, abs=0.0)


def test_every_stepped_solution_has_a_presentation_row() -> None:
    from vibroimpact.reporting.style import SOLUTION_LOOKS
    from vibroimpact.scene.schema import ENGINE_SOLUTIONS, SOLUTIONS

    assert set(SOLUTIONS) == set(SOLUTION_LOOKS)
    assert all(SOLUTION_LOOKS[name].marker is not None for name in ENGINE_SOLUTIONS)
    assert set(ENGINE_SOLUTIONS) == {name for name, spec in ENGINES.items() if spec.capabilities.stepped_solution}


def test_a_compiled_engine_prepares_its_kernels() -> None:
    """The engines with numba kernels (the rigid stop's and the bumper's closed-form engines) say so (capability
    ``compiled``) and find them in numba's cache (the test session compiled them first: preparing them again compiles
    nothing, 0 s). A cold cache compiles each once, before the workers: tests/test_first_run.py (slow tier)."""
    from vibroimpact.engines.registry import ENGINES, engine_for

    compiled = [name for name, spec in ENGINES.items() if spec.capabilities.compiled]
    assert sorted(compiled) == sorted({engine_for(RIGID, "exact_jacobians"), engine_for(BUMPER, "exact_jacobians")})
    for name in compiled:
        assert ENGINES[name].kernels_cached(), name
        assert ENGINES[name].prepare_kernels() == 0.0, name  # exact: cached, nothing compiled
