"""The N-dof structure, the stops and the loads of the general model (issue 12 item 1)."""

from __future__ import annotations

import math

from dataclasses import astuple

import numpy as np
import pytest

from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.layout import Layout
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.contact import Stop
from vibroimpact.model.structure import LinearStructure
from vibroimpact.model.system import PAPER_SYSTEM

PAPER = PAPER_SYSTEM.structure


def test_the_paper_system_as_matrices_has_the_named_forms_receptances() -> None:
    omega = np.linspace(50.0, 300.0, 41)
    named = PAPER_SYSTEM.receptances(omega)
    h = PAPER.receptance_matrix(omega)
    np.testing.assert_allclose(h[:, 0, 0], named.h11, rtol=1e-12)
    np.testing.assert_allclose(h[:, 0, 1], named.h12, rtol=1e-12)
    np.testing.assert_allclose(h[:, 1, 0], named.h12, rtol=1e-12)
    np.testing.assert_allclose(h[:, 1, 1], named.h22, rtol=1e-12)
    np.testing.assert_allclose(PAPER.natural_angular_frequencies(), PAPER_SYSTEM.natural_angular_frequencies(), rtol=1e-12)
    assert PAPER.coordinates == ("x1", "x2") and PAPER.rigid_body_modes() == 0


def test_a_relative_receptance_is_the_difference_of_two() -> None:
    omega = np.array([120.0, 207.0])
    h = PAPER.receptance_matrix(omega)
    relative = PAPER.receptance(omega, [-1.0, 1.0], [1.0, 0.0])
    np.testing.assert_allclose(relative, h[:, 1, 0] - h[:, 0, 0], rtol=1e-12)


def test_a_free_mass_has_a_rigid_body_mode_and_the_receptance_of_a_mass() -> None:
    ball = LinearStructure([[2.0]], [[0.0]])
    assert ball.rigid_body_modes() == 1 and ball.coordinates == ("x1",)
    np.testing.assert_allclose(ball.receptance_matrix(np.array([3.0]))[0, 0, 0], -1.0 / (2.0 * 9.0), rtol=1e-14)
    np.testing.assert_allclose(ball.natural_angular_frequencies(), [0.0], atol=1e-12)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"mass": [[1.0, 0.0]], "stiffness": [[1.0]]}, "system.mass: expected a square matrix"),
        ({"mass": [[1.0]], "stiffness": [[1.0, 0.0], [0.0, 1.0]]}, "system.stiffness: expected 1 x 1 like system.mass"),
        ({"mass": [[1.0, 0.0], [0.0, 1.0]], "stiffness": [[2.0, -1.0], [-0.5, 1.0]]}, "system.stiffness: must be symmetric"),
        ({"mass": [[1.0, 0.0], [0.0, 0.0]], "stiffness": [[1.0, 0.0], [0.0, 1.0]]}, "system.mass: must be positive definite"),
        ({"mass": [[1.0]], "stiffness": [[-5.0]]}, "system.stiffness: must be positive semi-definite"),
        ({"mass": [[1.0]], "stiffness": [[1.0]], "damping": [[-0.1]]}, "system.damping: must be positive semi-definite"),
        ({"mass": [[1.0]], "stiffness": [[float("nan")]]}, "system.stiffness: every entry must be a finite number"),
        ({"mass": [[1.0, 0.0], [0.0, 1.0]], "stiffness": [[1.0, 0.0], [0.0, 1.0]], "coordinates": ("a",)}, "system.coordinates: expected 2 names"),
        ({"mass": [[1.0, 0.0], [0.0, 1.0]], "stiffness": [[1.0, 0.0], [0.0, 1.0]], "coordinates": ("a", "a")}, "names must be unique"),
        ({"mass": [[1.0]], "stiffness": [[1.0]], "coordinates": ("2x",)}, "is not a valid name"),
    ],
)
def test_every_matrix_is_checked_with_a_message_naming_its_key(kwargs: dict, message: str) -> None:
    with pytest.raises(ValueError, match=message.replace("(", r"\(")):
        LinearStructure(**kwargs)


def test_the_normal_and_effective_mass_of_each_kind_of_stop() -> None:
    law = RigidStop(0.003, 0.2)
    mass = PAPER.mass_matrix
    np.testing.assert_array_equal(Stop(law, 1).normal(2), [0.0, 1.0])
    np.testing.assert_array_equal(Stop(law, 1, side="lower").normal(2), [0.0, -1.0])
    np.testing.assert_array_equal(Stop(law, 1, other=0).normal(2), [-1.0, 1.0])
    np.testing.assert_array_equal(Stop(law, 1, other=0, side="lower").normal(2), [1.0, -1.0])
    assert Stop(law, 1).effective_mass(mass) == pytest.approx(0.1, rel=1e-14)
    # two bodies pressed together: the reduced mass m1 m2 / (m1 + m2)
    assert Stop(law, 1, other=0).effective_mass(mass) == pytest.approx(1.0 * 0.1 / 1.1, rel=1e-14)
    assert Stop(law, 1, other=0).describe(("x1", "x2")) == "x2 - x1 <= 3 mm"
    assert Stop(law, 0, side="lower").describe(("x1", "x2")) == "x1 >= -3 mm"


def test_a_stop_takes_its_coordinates_by_name_as_scenes_do() -> None:
    """``Stop(law, "x2")`` is the scene's ``coordinate: x2`` (index 1, not 2), on the structure's own names too; the
    problem holds the indices, so a named stop's problem equals the indexed one."""
    law = RigidStop(3e-3, 0.2)
    force = HarmonicForce(10.0, 25.0)
    named = ImpactProblem(PAPER, (Stop(law, "x2"), Stop(law, "x2", other="x1", side="lower")), force)
    indexed = ImpactProblem(PAPER, (Stop(law, 1), Stop(law, 1, other=0, side="lower")), force)
    assert named == indexed and [stop.place for stop in named.stops] == [(1, None, "upper"), (1, 0, "lower")]
    chain = LinearStructure(np.diag([1.0, 0.5, 0.1]), [[3.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]], coordinates=("base", "mid", "tip"))
    tip = ImpactProblem(chain, (Stop(law, "tip", other="base"),), HarmonicForce(1.0, 1.0))
    np.testing.assert_array_equal(tip.normals(), [[-1.0, 0.0, 1.0]])
    assert Stop(law, "tip", other="base").describe(("base", "mid", "tip")) == "tip - base <= 3 mm"
    assert Stop.bumper(np.diag([1.0, 0.1]), 1e-3, 4e4, loss_factor=0.2, coordinate="x2") == Stop.bumper(np.diag([1.0, 0.1]), 1e-3, 4e4, loss_factor=0.2, coordinate=1)


@pytest.mark.parametrize(
    ("build", "message"),
    [
        (lambda: Stop(RigidStop(0.0, 0.5), 0, side="left"), "stop side = 'left' is not allowed"),
        (lambda: Stop(RigidStop(0.0, 0.5), 1, other=1), "the two coordinates must differ"),
        (lambda: Stop(RigidStop(0.0, 0.5), -1), "expected a coordinate's name .* or a 0-based index >= 0"),
        (lambda: Stop(RigidStop(0.0, 0.5), "x2", other="x2"), "the two coordinates must differ"),
        (lambda: ImpactProblem(PAPER, (Stop(RigidStop(0.0, 0.5), "absorber"),), HarmonicForce(1.0, 1.0)), r"stop coordinate = 'absorber' is not a coordinate of the system: allowed \['x1', 'x2'\]"),
        (lambda: ImpactProblem(PAPER, (Stop(RigidStop(0.0, 0.5), "x2", other="x3"),), HarmonicForce(1.0, 1.0)), "second coordinate = 'x3' is not a coordinate"),
        (lambda: Stop(RigidStop(0.0, 0.5), "x2").normal(2), "a name is known only against a structure"),
        (lambda: ImpactProblem(LinearStructure([[1.0]], [[1.0]]), (Stop(RigidStop(0.0, 0.5), 1),), HarmonicForce(1.0, 1.0)), "coordinate index 1 is out of range"),
        (lambda: ImpactProblem(PAPER, (Stop(RigidStop(0.0, 0.5), 1),), HarmonicForce(1.0, 1.0, static=(1.0,))), "excitation.static: expected 2 values"),
        (lambda: HarmonicForce(1.0, 1.0, weights=(1.0,), base_motion=True), "give no 'on' weights"),
    ],
)
def test_bad_stops_and_loads_are_refused_naming_the_key(build, message: str) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ValueError, match=message):
        build()


def test_a_negative_clearance_is_allowed_and_preloads() -> None:
    assert RigidStop(-0.001, 0.5).clearance == -0.001  # exact: the stored input
    assert KelvinVoigtBumper(-0.001, 200.0, 0.3).clearance == -0.001  # exact: the stored input


def test_the_paper_layout_in_general_form_is_recognised_and_holds_like_the_named_one() -> None:
    named = ImpactProblem(PAPER_SYSTEM, RigidStop(0.003, 0.2), HarmonicForce(10.0, 25.0))
    general = ImpactProblem(PAPER, (Stop(RigidStop(0.003, 0.2), 1),), HarmonicForce(10.0, 25.0, weights=(1.0, 0.0)))
    for view in (Layout.of_problem(named).paper_view(), Layout.of_problem(general).paper_view()):
        assert view is not None and astuple(view) == pytest.approx(astuple(PAPER_SYSTEM), rel=1e-15)
    assert Layout.of_problem(ImpactProblem(PAPER, (Stop(RigidStop(0.003, 0.2), 1, side="lower"),), HarmonicForce(10.0, 25.0))).paper_view() is None
    assert general.velocity_scale() == pytest.approx(named.velocity_scale(), rel=1e-12)
    for x1, v1 in [(0.001, 0.2), (0.004, -0.3)]:
        state = np.array([x1, 0.003, v1, 0.0])
        assert general.contact_holding(0, state, 0.0) == pytest.approx(float(named.holding_force(x1, v1)), rel=1e-12)


def test_base_motion_loads_each_mass_with_its_inertia() -> None:
    omega = 2.0 * math.pi * 5.0
    force = HarmonicForce(0.002, 5.0, base_motion=True).load_vector(PAPER.mass_matrix)
    np.testing.assert_allclose(force, np.array([1.0, 0.1]) * 0.002 * omega**2, rtol=1e-14)


def test_the_holding_force_of_a_resting_ball_is_its_weight() -> None:
    ball = ImpactProblem(LinearStructure([[0.5]], [[0.0]]), (Stop(RigidStop(0.0, 0.5), 0, side="lower"),), HarmonicForce(0.0, 1.0, static=(-0.5 * 9.81,)))
    assert ball.contact_holding(0, np.array([0.0, 0.0]), 0.3) == pytest.approx(0.5 * 9.81, rel=1e-14)
    a, b, b0 = ball.first_order()
    np.testing.assert_array_equal(a, [[0.0, 1.0], [0.0, 0.0]])
    np.testing.assert_allclose(b0, [0.0, -9.81], rtol=1e-14)


def test_a_relative_stops_holding_force_keeps_the_two_bodies_together() -> None:
    """Held closed, x2 - x1 = Delta and x2' = x1': the pair then accelerates as one body, so n . x'' = 0."""
    problem = ImpactProblem(PAPER, (Stop(RigidStop(0.003, 0.2), 1, other=0),), HarmonicForce(10.0, 25.0))
    state = np.array([0.001, 0.004, 0.1, 0.1])
    holding = problem.contact_holding(0, state, 0.01)
    n = problem.normals()[0]
    force = 10.0 * math.cos(problem.omega * 0.01) * np.array([1.0, 0.0]) - PAPER.damping_matrix @ state[2:] - PAPER.stiffness_matrix @ state[:2] - n * holding
    acceleration = np.linalg.solve(PAPER.mass_matrix, force)
    assert abs(n @ acceleration) < 1e-12 * np.max(np.abs(acceleration))


def test_two_opposite_stops_must_leave_room() -> None:
    """x1 <= -2 mm and x1 >= -1 mm allow no position; x2 - x1 <= 1 mm with x1 - x2 <= -1 mm clamps the pair at one."""
    law = RigidStop
    with pytest.raises(ValueError, match=r"stop 0 \(x1 <= -2 mm\) and stop 1 \(x1 >= -1 mm\) leave no room"):
        ImpactProblem(LinearStructure([[1.0]], [[1.0]]), (Stop(law(-0.002, 0.5), 0), Stop(law(0.001, 0.5), 0, side="lower")), HarmonicForce(1.0, 1.0))
    with pytest.raises(ValueError, match="leave no room"):
        ImpactProblem(PAPER, (Stop(law(0.001, 0.5), 1, other=0), Stop(law(-0.001, 0.5), 0, other=1)), HarmonicForce(1.0, 1.0))
    # a preloading stop with room on the other side is fine
    problem = ImpactProblem(LinearStructure([[1.0]], [[1.0]]), (Stop(law(-0.001, 0.5), 0), Stop(law(0.002, 0.5), 0, side="lower")), HarmonicForce(1.0, 1.0))
    assert len(problem.stops) == 2
