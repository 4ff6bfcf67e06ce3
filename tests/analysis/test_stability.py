"""Floquet stability of the one-impact orbit, checked against simulation of the same system."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from vibroimpact.analysis.impact_orbit import ImpactOrbit
from vibroimpact.analysis.pgf import solve_one_impact
from vibroimpact.analysis.stability import floquet_multipliers, is_stable
from vibroimpact.model.system import TwoDofSystem

from tests.conftest import PAPER_AMPLITUDE, PAPER_CLEARANCE


class ImpactSimulator:
    """DOP853 with exact impact events: an integrator independent of the closed form and of the monodromy."""

    def __init__(self, system: TwoDofSystem, orbit: ImpactOrbit) -> None:
        self.system, self.orbit = system, orbit
        self.period = float(orbit.period[0])
        self.omega = float(orbit.omega[0])
        self.forcing_phase = float(orbit.phase[0] - np.angle(orbit.gap_response[0]))
        self.minv = np.linalg.inv(system.mass_matrix)

    def rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        force = np.array([self.orbit.amplitude[0] * np.cos(self.omega * t + self.forcing_phase), 0.0])
        return np.concatenate([y[2:], self.minv @ (force - self.system.stiffness_matrix @ y[:2] - self.system.damping_matrix @ y[2:])])

    def run(self, y: np.ndarray, t0: float, t1: float) -> tuple[np.ndarray, list[float]]:
        """State at t1 and the impulses of the impacts on the way."""
        clearance, restitution = float(self.orbit.clearance[0]), float(self.orbit.restitution[0])

        def contact(t: float, state: np.ndarray) -> float:
            return state[1] - clearance

        contact.terminal, contact.direction = True, 1.0
        impulses: list[float] = []
        t, y = t0, y.copy()
        while True:
            run = solve_ivp(self.rhs, (t, t1), y, method="DOP853", rtol=1e-13, atol=1e-16, events=contact)
            if run.status != 1:
                return run.y[:, -1], impulses
            t, y = run.t_events[0][0], run.y_events[0][0].copy()
            impulses.append(self.system.m2 * (1 + restitution) * y[3])
            y[3] *= -restitution

    def orbit_state(self, fraction: float) -> np.ndarray:
        return self.orbit.state(np.array([[fraction * self.period]]))[0, 0]


def orbit(system: TwoDofSystem, frequency: float, restitution: float = 0.2) -> ImpactOrbit:
    return solve_one_impact(system, omega=np.array([2 * np.pi * frequency]), clearance=PAPER_CLEARANCE, restitution=restitution, amplitude=PAPER_AMPLITUDE)


@pytest.mark.parametrize("frequency", [21.0, 25.0, 38.0])
def test_multipliers_match_finite_difference_monodromy(system: TwoDofSystem, frequency: float) -> None:
    """Eigenvalues of S exp(A T) equal those of the Jacobian of the simulated mid-period stroboscopic map."""
    o = orbit(system, frequency)
    sim = ImpactSimulator(system, o)
    y0 = sim.orbit_state(0.5)
    scale = np.array([1e-3, 1e-3, 0.3, 0.3])
    jacobian = np.zeros((4, 4))
    for k in range(4):
        step = np.zeros(4)
        step[k] = 1e-6 * scale[k]
        plus, _ = sim.run(y0 + step, 0.5 * sim.period, 1.5 * sim.period)
        minus, _ = sim.run(y0 - step, 0.5 * sim.period, 1.5 * sim.period)
        jacobian[:, k] = (plus - minus) / (2 * step[k])
    expected = np.sort(np.abs(np.linalg.eigvals(jacobian)))
    np.testing.assert_allclose(np.sort(np.abs(floquet_multipliers(o)[0])), expected, rtol=1e-4)


@pytest.mark.parametrize("restitution", [0.0, 0.2, 0.7, 1.0])
def test_product_of_multipliers(system: TwoDofSystem, restitution: float) -> None:
    """det(monodromy) = det(S) det(exp(A T)) = R^2 exp(tr(A) T), analytically."""
    frequencies = np.array([22.0, 24.0, 26.0, 36.0, 38.0])
    o = solve_one_impact(system, omega=2 * np.pi * frequencies, clearance=PAPER_CLEARANCE, restitution=restitution, amplitude=PAPER_AMPLITUDE)
    assert o.exists.all()
    trace = np.trace(system.state_matrix)
    expected = restitution**2 * np.exp(trace * o.period)
    np.testing.assert_allclose(np.prod(floquet_multipliers(o), axis=-1).real, expected, rtol=1e-8, atol=1e-14)


@pytest.mark.slow
@pytest.mark.parametrize(("frequency", "stable"), [(25.0, True), (40.0, True), (38.0, False), (18.7, False)])
def test_simulation_leaves_unstable_orbits_and_returns_to_stable_ones(system: TwoDofSystem, frequency: float, stable: bool) -> None:
    """A 1e-6 perturbation of the orbit decays where the multipliers say stable and grows where they say unstable."""
    o = orbit(system, frequency)
    assert bool(is_stable(o)[0]) is stable
    sim = ImpactSimulator(system, o)
    y0 = sim.orbit_state(0.5) * (1 + 1e-6)
    periods = 150
    y, impulses = sim.run(y0, 0.5 * sim.period, (0.5 + periods) * sim.period)
    deviation = np.abs(y - sim.orbit_state(0.5)).max() / np.abs(sim.orbit_state(0.5)).max()
    if stable:
        assert deviation < 1e-8
        assert len(impulses) == periods
    else:
        assert deviation > 1e-3


def test_no_multipliers_without_a_solution(system: TwoDofSystem) -> None:
    o = orbit(system, 30.0)  # inside the impactless band
    assert not o.exists[0]
    assert np.isnan(floquet_multipliers(o)).all() and not is_stable(o)[0]
