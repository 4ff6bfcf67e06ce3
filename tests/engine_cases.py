"""Shared builders and checks for engine tests: PGF orbit starts, linear starts, energy balance."""

from __future__ import annotations

import numpy as np

from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.engines.exact import ExactEngine

from vibroimpact.engines.base import Trajectory
from vibroimpact.engines.linear_flow import gauss_legendre
from vibroimpact.analysis.linear import paper_linear_response
from vibroimpact.analysis.impact_orbit import ImpactOrbit
from vibroimpact.analysis.pgf import solve_one_impact
from vibroimpact.model.system import PAPER_SYSTEM, TwoDofSystem

from tests.conftest import PAPER_AMPLITUDE, PAPER_CLEARANCE


def pgf_start(frequency: float, restitution: float, clearance: float = PAPER_CLEARANCE, system: TwoDofSystem = PAPER_SYSTEM) -> tuple[ImpactProblem, np.ndarray, float, ImpactOrbit]:
    """Problem whose force phase puts the PGF impacts at t = k T, and the orbit's state at t = T/2."""
    orbit = solve_one_impact(system, omega=np.array([2 * np.pi * frequency]), clearance=clearance, restitution=restitution, amplitude=PAPER_AMPLITUDE)
    assert orbit.exists[0]
    phase = float(orbit.phase[0] - np.angle(orbit.gap_response[0]))
    problem = ImpactProblem(system, RigidStop(clearance, restitution), HarmonicForce(PAPER_AMPLITUDE, frequency, phase=phase))
    half = np.array([[0.5 / frequency]])
    state = orbit.state(half)[0, 0]
    return problem, state, 0.5 / frequency, orbit


def named(problem: ImpactProblem) -> TwoDofSystem:
    """The paper's named system of a problem on the two-mass chain (its structure's named view)."""
    system = TwoDofSystem.of(problem.system)
    assert system is not None, "not the two-mass chain"
    return system


def orbit_force(system: TwoDofSystem, orbit: ImpactOrbit) -> np.ndarray:
    """Eq. 23: the fundamental of the force on the base of a one-impact orbit of the paper's layout, suspension
    (K1 + j w B1) X1 plus the impulse train's 2 J / T through the stop [N], time from the impact."""
    return (system.k1 + 1j * orbit.omega * system.b1) * orbit.harmonics()[..., 0] + 2.0 * orbit.impulse / orbit.period


def linear_state(problem: ImpactProblem, t: float = 0.0) -> np.ndarray:
    """The linear steady state (no stop) at time t under q cos(w t + phase)."""
    response = paper_linear_response(named(problem), omega=problem.omega, amplitude=problem.amplitude)
    rotation = np.exp(1j * (problem.omega * t + problem.phase))
    x = np.array([response.x1, response.x2]) * rotation
    return np.concatenate([x.real, (1j * problem.omega * x).real])


def mechanical_energy(system: TwoDofSystem, y: np.ndarray) -> np.ndarray:
    """Kinetic plus elastic energy [J] of states y (..., 4)."""
    x1, x2, v1, v2 = np.moveaxis(np.asarray(y), -1, 0)
    return 0.5 * (system.m1 * v1**2 + system.m2 * v2**2 + system.k1 * x1**2 + system.k2 * (x1 - x2) ** 2)


def energy_budget(trajectory: Trajectory) -> dict[str, float]:
    """Energy change, input work, viscous dissipation and impact loss over the trajectory [J].

    States inside segments come from the exact flow started at each recorded segment state, so for an
    integrator this checks its event states and its restitution map, not its step accuracy.
    """
    p, s = trajectory.problem, named(trajectory.problem)
    exact = ExactEngine()
    nodes, weights = gauss_legendre(64)
    work = dissipation = 0.0
    for (start, end, _mode) in trajectory.segments:
        for a, b in zip(np.linspace(start, end, 9)[:-1], np.linspace(start, end, 9)[1:]):
            times = a + (b - a) * nodes
            y = exact.dense(trajectory, times)
            w = (b - a) * weights
            work += w @ (p.force(times) * y[:, 2])
            dissipation += w @ (s.b1 * y[:, 2] ** 2 + s.b2 * (y[:, 2] - y[:, 3]) ** 2)
    before = trajectory.impact_velocities
    after = before - trajectory.impulses / s.m2  # -R v, or 0 for an impact that ends in sticking
    loss = float(np.sum(0.5 * s.m2 * (before**2 - after**2)))
    change = float(mechanical_energy(s, trajectory.strobe_states[-1]) - mechanical_energy(s, trajectory.strobe_states[0]))
    return {"change": change, "work": float(work), "dissipation": float(dissipation), "impact_loss": loss}
