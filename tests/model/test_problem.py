"""ImpactProblem: composition of a system, a contact law and an excitation, and its errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vibroimpact.model.contact import BUMPER as BUMPER_LAW, RIGID, KelvinVoigtBumper, RigidStop, Stop
from vibroimpact.model.excitation import HarmonicForce, SweptSine
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM

STOP = RigidStop(0.003, 0.2)
BUMPER = KelvinVoigtBumper(0.003, 250.0, 0.73)
FORCE = HarmonicForce(10.0, 25.0, 0.5)
SWEEP = SweptSine(10.0, 15.0, 45.0, 0.1)


def test_a_harmonic_problem_answers_from_its_parts() -> None:
    problem = ImpactProblem(PAPER_SYSTEM, STOP, FORCE)
    assert problem.clearance == STOP.clearance and problem.restitution == STOP.restitution  # exact: passed through
    assert problem.amplitude == FORCE.amplitude and problem.frequency == FORCE.frequency and problem.phase == FORCE.phase  # exact: passed through
    assert problem.omega == pytest.approx(2 * math.pi * 25.0, rel=1e-15)
    assert problem.period == pytest.approx(0.04, rel=1e-15)
    t = np.linspace(0.0, 0.1, 7)
    np.testing.assert_allclose(problem.force(t), 10.0 * np.cos(2 * math.pi * 25.0 * t + 0.5), rtol=1e-14, atol=1e-12)
    assert problem.rigid_stop is STOP
    assert problem.holding_force(0.004, 0.1) == pytest.approx(PAPER_SYSTEM.b2 * 0.1 + PAPER_SYSTEM.k2 * 0.001, rel=1e-15)
    linear = 10.0 * abs(complex(PAPER_SYSTEM.receptances(problem.omega).h12))
    assert problem.velocity_scale() == pytest.approx(problem.omega * (0.003 + linear), rel=1e-15)


def test_a_bumper_problem_with_a_sweep() -> None:
    problem = ImpactProblem(PAPER_SYSTEM, BUMPER, SWEEP)
    assert problem.bumper is BUMPER and problem.sweep is SWEEP and problem.clearance == BUMPER.clearance  # exact: passed through
    assert problem.amplitude == SWEEP.amplitude  # exact: passed through
    np.testing.assert_allclose(problem.force(np.array([0.0, 1.0])), SWEEP.force(np.array([0.0, 1.0])), rtol=1e-15)


@pytest.mark.parametrize("name", ["frequency", "phase", "omega", "period", "harmonic"])
def test_a_harmonic_property_of_a_sweep_names_the_excitation(name: str) -> None:
    problem = ImpactProblem(PAPER_SYSTEM, BUMPER, SWEEP)
    with pytest.raises(TypeError, match="excitation = SweptSine.*not a HarmonicForce"):
        getattr(problem, name)


def test_the_contact_law_is_rigid_only_when_every_stop_is() -> None:
    both = (Stop(STOP, coordinate=1, side="upper"), Stop(BUMPER, coordinate=1, side="lower"))
    assert ImpactProblem(PAPER_SYSTEM, STOP, FORCE).contact_law == RIGID
    assert ImpactProblem(PAPER_SYSTEM, (Stop(STOP), Stop(STOP, side="lower")), FORCE).contact_law == RIGID
    assert ImpactProblem(PAPER_SYSTEM, BUMPER, FORCE).contact_law == BUMPER_LAW
    assert ImpactProblem(PAPER_SYSTEM, both, FORCE).contact_law == BUMPER_LAW


def test_the_wrong_contact_law_is_named() -> None:
    with pytest.raises(TypeError, match="contact = KelvinVoigtBumper.*not a RigidStop"):
        ImpactProblem(PAPER_SYSTEM, BUMPER, FORCE).restitution  # noqa: B018
    with pytest.raises(TypeError, match="contact = RigidStop.*not a KelvinVoigtBumper"):
        ImpactProblem(PAPER_SYSTEM, STOP, FORCE).bumper  # noqa: B018
    with pytest.raises(TypeError, match="not a SweptSine"):
        ImpactProblem(PAPER_SYSTEM, STOP, FORCE).sweep  # noqa: B018


@pytest.mark.parametrize(
    ("parts", "key"),
    [((1.0, STOP, FORCE), "system"), ((PAPER_SYSTEM, 0.003, FORCE), "contact"), ((PAPER_SYSTEM, STOP, 10.0), "excitation")],
)
def test_a_part_of_the_wrong_kind_is_refused_by_its_key(parts: tuple, key: str) -> None:
    with pytest.raises(TypeError, match=f"^{key} = "):
        ImpactProblem(*parts)


def test_the_parts_validate_themselves() -> None:
    with pytest.raises(ValueError, match="restitution"):
        RigidStop(0.003, 1.5)
    with pytest.raises(ValueError, match="frequency"):
        HarmonicForce(10.0, 0.0)
