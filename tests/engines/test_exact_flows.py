"""The exact engines' flows (exact_flows): rigid-body modes as polynomials, held flows on a stop's surface, the
holding force against the model's formula, and the refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vibroimpact.engines.exact import ExactEngine
from vibroimpact.engines.exact_flows import decompose, mechanical_null_basis
from vibroimpact.engines.exact_python import PythonExactEngine
from vibroimpact.engines.linear_flow import HarmonicLinearFlow
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.contact import Stop
from vibroimpact.model.structure import LinearStructure
from vibroimpact.model.system import PAPER_SYSTEM


def test_a_free_mass_under_gravity_and_a_harmonic_force_is_a_polynomial_plus_a_harmonic() -> None:
    """x'' = -g + F cos(w t): x(t) = x0 + v0 t - g t^2 / 2 + F (1 - cos w t) / w^2 (from rest in the harmonic part at
    t = 0), the state matrix a Jordan block of size 2 (no eigenvalue kept, the projector the identity); to 1e-12."""
    g, force, omega = 9.81, 3.0, 5.0
    flow = HarmonicLinearFlow(np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([0.0, force], dtype=complex), np.array([0.0, -g]), omega)
    assert flow.eigenvalues.size == 0
    np.testing.assert_allclose(flow.flow.projector, np.eye(2), atol=1e-15)
    x0, v0 = 0.3, 1.2
    piece = flow.start(0.0, np.array([x0, v0]))
    t = np.linspace(0.0, 3.0, 31)
    exact_x = x0 + v0 * t - g * t**2 / 2 + force * (1 - np.cos(omega * t)) / omega**2
    exact_v = v0 - g * t + force * np.sin(omega * t) / omega
    states = piece.state(t)
    np.testing.assert_allclose(states[:, 0], exact_x, rtol=0, atol=1e-12 * np.max(np.abs(exact_x)))
    np.testing.assert_allclose(states[:, 1], exact_v, rtol=0, atol=1e-12 * np.max(np.abs(exact_v)))


def test_a_damped_free_mass_keeps_its_decay_and_one_rigid_mode() -> None:
    """m x'' + c x' = 0: the position is a rigid mode (one null vector, no Jordan chain: the dashpot resists the
    motion), the velocity decays at -c/m."""
    basis = mechanical_null_basis(np.array([[2.0]]), np.array([[0.0]]), np.array([[0.5]]))
    np.testing.assert_allclose(basis, [[1.0], [0.0]])
    flow = decompose(np.array([[0.0, 1.0], [0.0, -0.25]]), np.zeros(2, dtype=complex), np.zeros(2), 1.0, basis)
    np.testing.assert_allclose(flow.eigenvalues, [-0.25], rtol=1e-14)
    np.testing.assert_allclose(flow.nilpotent, 0.0, atol=1e-15)


def test_a_jordan_block_longer_than_two_is_refused() -> None:
    chain = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.0]])
    with pytest.raises(ValueError, match="Jordan block at zero longer than 2"):
        decompose(chain, np.zeros(3, dtype=complex), np.zeros(3), 1.0)


@pytest.mark.parametrize("side", ["upper", "lower"])
def test_the_held_flow_stays_on_a_relative_stop_and_its_holding_force_is_the_models(side: str) -> None:
    """Held on x2 - x1 = +-Delta (a relative stop, static loads on both masses and a harmonic force): the lifted flow
    keeps n.x = Delta and n.x' = 0 (1e-15), and minus the watched observable equals
    ImpactProblem.contact_holding (1e-12 of the loads)."""
    problem = ImpactProblem(
        PAPER_SYSTEM.structure, (Stop(RigidStop(0.001, 0.3), 1, other=0, side=side),), HarmonicForce(10.0, 20.0, 0.3, static=(2.0, -1.0))
    )
    model = ExactEngine().model(problem)
    held = HarmonicLinearFlow.from_flow(model.stuck[0])
    normal = problem.normals()[0]
    start = np.array([0.002, 0.002 + normal[1] * 0.001, 0.1, 0.1])  # on the surface, moving together
    piece = held.start(0.05, start)
    times = np.linspace(0.05, 0.2, 40)
    states = piece.state(times)
    np.testing.assert_allclose(states[:, :2] @ normal, 0.001, rtol=0, atol=1e-15)
    np.testing.assert_allclose(states[:, 2:] @ normal, 0.0, atol=1e-15)
    release = piece.observable(model.hold_weights[0], float(model.hold_offsets[0]), complex(model.hold_harmonics[0]))
    engine_force = -np.array([release.derivatives(t, 1)[0] for t in times])
    model_force = np.array([problem.contact_holding(0, state, t) for state, t in zip(states, times)])
    np.testing.assert_allclose(engine_force, model_force, rtol=0, atol=1e-12 * 12.0)


def test_impacts_on_one_stop_free_the_structure_held_on_another() -> None:
    """The chain of test_exact_layouts at 3 Hz under 60 N: the top mass sticks on its stop (R = 0) while the relative
    stop between m1 and m2 (0.5 mm) is hit; such an impact frees the held stop. Compiled and Python loops agree
    (impact times 1e-8 of a period, strobes 1e-9 of the motion)."""
    k1, k2, k3 = 2e4, 8e3, 3e3
    stiffness = np.array([[k1 + k2, -k2, 0.0], [-k2, k2 + k3, -k3], [0.0, -k3, k3]])
    mass = np.diag([1.0, 0.5, 0.2])
    stops = (Stop(RigidStop(0.002, 0.0), 2), Stop(RigidStop(0.0005, 0.5), 1, other=0, side="lower"))
    problem = ImpactProblem(LinearStructure(mass, stiffness, 2e-5 * stiffness + 0.3 * mass), stops, HarmonicForce(60.0, 3.0, 0.2))
    compiled = ExactEngine().integrate(problem, np.zeros(6), 0.0, 15)
    python = PythonExactEngine().integrate(problem, np.zeros(6), 0.0, 15)
    segment = np.searchsorted(compiled.segments[:, 0], compiled.impact_times, side="left") - 1
    held = compiled.segment_stops[segment]
    assert np.sum((held >= 0) & (held != compiled.impact_stops)) >= 3
    assert compiled.impact_times.size == python.impact_times.size and compiled.stats["sticks"] == python.stats["sticks"]
    np.testing.assert_allclose(compiled.impact_times, python.impact_times, rtol=0, atol=1e-8 * problem.period)
    scale = np.max(np.abs(python.strobe_states), axis=0) + 1e-3 * np.array([1, 1, 1, 20, 20, 20])
    assert np.max(np.abs(compiled.strobe_states - python.strobe_states) / scale) <= 1e-9


def test_base_motion_is_the_inertial_load() -> None:
    """A base moving as Y cos(w t) under a 1-dof oscillator (coordinates relative to the base): far from its stop the
    strobes are the linear steady state X = m Y w^2 / (k - m w^2 + j c w) (1e-12)."""
    m, k, c, amplitude, frequency = 2.0, 800.0, 1.5, 1e-3, 5.0
    problem = ImpactProblem(LinearStructure([[m]], [[k]], [[c]]), (Stop(RigidStop(1.0, 0.5), 0),), HarmonicForce(amplitude, frequency, base_motion=True))
    omega = 2 * math.pi * frequency
    x = m * amplitude * omega**2 / (k - m * omega**2 + 1j * c * omega)
    start = np.array([x.real, (1j * omega * x).real])
    run = ExactEngine().integrate(problem, start, 0.0, 20)
    assert run.impact_times.size == 0
    np.testing.assert_allclose(run.strobe_states, np.broadcast_to(start, run.strobe_states.shape), rtol=0, atol=1e-12 * abs(x) * omega)
