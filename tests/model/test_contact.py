"""Kelvin-Voigt bumper (eq. 25): restitution and peak acceleration against one-collision simulations."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

from vibroimpact.model.contact import (
    KelvinVoigtBumper,
    RigidStop,
    Stop,
    loss_factor_from_restitution,
    paper_restitution,
    peak_acceleration_factor,
    place_effective_mass,
    release_time,
    restitution_from_loss_factor,
)

OMEGA = 2 * math.pi * 250.0  # the paper's bumper, Omega_b / 2 pi = 250 Hz [rad s-1]
V0 = 0.5  # entry speed [m s-1]
LOSS_FACTORS = [1e-4, 0.05, 0.2, 0.4, 0.45, 0.49, 0.5, 0.65, 0.8, 0.999, 1.0, 1.001, 1.5, 3.0, 10.0]


def collide(xi: float) -> tuple[float, float]:
    """One collision simulated: (restitution, peak |acceleration| / (Omega v0)).

    x'' = -2 xi Omega x' - Omega^2 x from x = 0, x' = v0, until the force M2 (Omega^2 x + 2 xi Omega x') falls to 0.
    """

    def rhs(t: float, y: np.ndarray) -> list[float]:
        return [y[1], -2 * xi * OMEGA * y[1] - OMEGA**2 * y[0]]

    def force(t: float, y: np.ndarray) -> float:
        return OMEGA**2 * y[0] + 2 * xi * OMEGA * y[1]

    force.terminal, force.direction = True, -1.0
    horizon = 20.0 / OMEGA * max(1.0, xi)
    run = solve_ivp(rhs, (0.0, horizon), [0.0, V0], method="DOP853", rtol=1e-13, atol=1e-16, events=force, dense_output=True, first_step=1e-9 / OMEGA)
    assert run.status == 1, "the bumper must release"
    release = run.t_events[0][0]
    restitution = -run.y_events[0][0][1] / V0

    def acceleration(t: float) -> float:
        x, v = run.sol(t)
        return abs(-2 * xi * OMEGA * v - OMEGA**2 * x)

    times = np.linspace(0.0, release, 4001)
    values = np.array([acceleration(t) for t in times])
    k = int(np.argmax(values))
    best = values[k]
    if 0 < k < times.size - 1:
        refined = minimize_scalar(lambda t: -acceleration(t), bounds=(times[k - 1], times[k + 1]), method="bounded", options={"xatol": 1e-15})
        best = max(best, -refined.fun)
    return restitution, best / (OMEGA * V0)


@pytest.mark.parametrize("xi", LOSS_FACTORS)
def test_restitution_and_peak_acceleration_match_one_collision(xi: float) -> None:
    """Closed forms against a simulated collision, to 1e-8, under-, critically and over-damped."""
    restitution, peak = collide(xi)
    assert restitution_from_loss_factor(xi) == pytest.approx(restitution, rel=1e-8)
    assert peak_acceleration_factor(xi) == pytest.approx(peak, rel=1e-8)


def test_restitution_limits_and_monotony() -> None:
    xi = np.linspace(0.0, 20.0, 4001)
    r = np.array([restitution_from_loss_factor(x) for x in xi])
    assert r[0] == 1.0 and np.all(np.diff(r) < 0)  # exact: R(0) = exp(0)
    assert restitution_from_loss_factor(1.0) == pytest.approx(math.exp(-2.0), rel=1e-15)
    # continuous through critical damping, from both sides
    assert restitution_from_loss_factor(1.0 - 1e-9) == pytest.approx(math.exp(-2.0), rel=1e-8)
    assert restitution_from_loss_factor(1.0 + 1e-9) == pytest.approx(math.exp(-2.0), rel=1e-8)
    # a very damped bumper: R ~ 1 / (4 xi^2)
    assert restitution_from_loss_factor(1e4) * 4e8 == pytest.approx(1.0, rel=1e-2)


@pytest.mark.parametrize("restitution", [0.9, 0.6, 0.2, math.exp(-2.0), 0.05, 1e-4])
def test_inverse(restitution: float) -> None:
    xi = loss_factor_from_restitution(restitution)
    assert restitution_from_loss_factor(xi) == pytest.approx(restitution, rel=1e-12)


def test_paper_loss_factor_does_not_give_r_02() -> None:
    """Erratum evidence: R = 0.2 needs xi_b = 0.731 (not the paper's 0.65, which gives 0.228); eq. 26 as printed is
    not a restitution at all there (3.3)."""
    assert loss_factor_from_restitution(0.2) == pytest.approx(0.7312, abs=1e-4)
    assert restitution_from_loss_factor(0.65) == pytest.approx(0.2284, abs=1e-4)
    assert paper_restitution(0.65) > 1.0


def test_bumper_force_law() -> None:
    """Eq. 25: no force before contact, K x + B v while pushing, never pulling."""
    bumper = KelvinVoigtBumper(clearance=3e-3, frequency=250.0, loss_factor=0.5)
    m2 = 0.1
    assert bumper.force(m2, 2.9e-3, 1.0) == 0.0  # exact: no contact: force set to 0
    assert bumper.force(m2, 3.1e-3, 0.2) == pytest.approx(bumper.stiffness(m2) * 1e-4 + bumper.damping(m2) * 0.2)
    assert bumper.force(m2, 3.0001e-3, -5.0) == 0.0  # exact: released: force set to 0
    assert bumper.stiffness(m2) == pytest.approx(m2 * (2 * math.pi * 250.0) ** 2)


@pytest.mark.parametrize(
    ("make", "fragment"),
    [
        (lambda: KelvinVoigtBumper(clearance=float("nan"), frequency=250.0, loss_factor=0.5), "clearance: expected a finite number"),
        (lambda: KelvinVoigtBumper(clearance=1e-3, frequency=0.0, loss_factor=0.5), "frequency = 0.0 is out of range"),
        (lambda: KelvinVoigtBumper(clearance=1e-3, frequency=250.0, loss_factor=-0.1), "loss_factor = -0.1 is out of range"),
        (lambda: RigidStop(clearance=1e-3, restitution=1.2), "restitution = 1.2 is out of range: allowed [0, 1]"),
        (lambda: loss_factor_from_restitution(0.0), "restitution = 0 needs an infinitely damped bumper"),
    ],
)
def test_validation(make: object, fragment: str) -> None:
    import re

    with pytest.raises(ValueError, match=re.escape(fragment)):
        make()  # type: ignore[operator]


# ----------------------------------------------------------------------------------------------- the rigid law
def test_rigid_impact_map_and_impulse() -> None:
    """An impact that does not chatter: X2' -> -R v, impulse M2 (1 + R) v; the sticking test is not even asked."""
    from vibroimpact.model.contact import RigidStop

    def never() -> bool:
        raise AssertionError("asked whether the stop pushes on an impact that does not chatter")

    impact = RigidStop(0.003, 0.4).impact(0.1, 2.0, False, never)
    assert not impact.sticks and impact.velocity == 2.0  # exact: passed through
    assert impact.after == pytest.approx(-0.8, rel=1e-15)
    assert impact.impulse == pytest.approx(0.1 * 2.0 * 1.4, rel=1e-15)


@pytest.mark.parametrize("pushed", [True, False])
def test_rigid_chattering_sticks_only_where_the_stop_pushes(pushed: bool) -> None:
    from vibroimpact.model.contact import RigidStop

    impact = RigidStop(0.003, 0.4).impact(0.1, 1e-9, True, lambda: pushed)
    assert impact.sticks is pushed
    assert impact.after == (0.0 if pushed else pytest.approx(-0.4e-9, rel=1e-15))
    assert impact.impulse == pytest.approx(0.1 * 1e-9 * (1.0 if pushed else 1.4), rel=1e-15)


def test_rigid_chattering_test() -> None:
    """Slow, too many in a period, or R = 0 chatter; anything else does not."""
    from vibroimpact.model.contact import RigidStop

    stop = RigidStop(0.003, 0.4)
    assert stop.chatters(1e-6, 1, 1e-6, 10)
    assert stop.chatters(1.0, 11, 1e-6, 10)
    assert not stop.chatters(1.0, 10, 1e-6, 10)
    assert RigidStop(0.003, 0.0).chatters(1.0, 1, 1e-6, 10)


def test_rigid_holding_force() -> None:
    from vibroimpact.model.contact import RigidStop
    from vibroimpact.model.system import PAPER_SYSTEM

    stop = RigidStop(0.003, 0.4)
    assert stop.holding_force(PAPER_SYSTEM, 0.005, -0.2) == pytest.approx(PAPER_SYSTEM.b2 * -0.2 + PAPER_SYSTEM.k2 * 0.002, rel=1e-15)
    np.testing.assert_allclose(stop.holding_force(PAPER_SYSTEM, np.array([0.003, 0.0]), np.zeros(2)), [0.0, -PAPER_SYSTEM.k2 * 0.003], atol=1e-15)


# --------------------------------------------------------------------------------------------------------------------
# The bumper in physical units: stiffness K_b [N/m] and damping B_b [N s/m] (or loss factor) on a stop's effective mass
# --------------------------------------------------------------------------------------------------------------------

#: Round-off of a conversion between the two forms [-]: the law keeps Omega_b / 2 pi, so K and B come back through a
#: square root and a division by 2 pi (measured at most 4.4e-16 over 2e4 random bumpers).
CONVERSION_RTOL = 1e-15


@pytest.mark.parametrize(("frequency", "xi", "mass"), [(250.0, 0.65, 0.1), (100.0, 0.3, 1.0), (3.7e4, 2.5, 17.0), (0.5, 0.0, 1e-3)])
def test_stiffness_form_and_frequency_form_are_the_same_law(frequency: float, xi: float, mass: float) -> None:
    """K = m Omega_b^2 and B = 2 m xi_b Omega_b give back the frequency form's law; either loss form gives the same."""
    law = KelvinVoigtBumper(0.003, frequency, xi)
    for twin in (
        KelvinVoigtBumper.from_stiffness(0.003, law.stiffness(mass), mass, damping=law.damping(mass)),
        KelvinVoigtBumper.from_stiffness(0.003, law.stiffness(mass), mass, loss_factor=xi),
    ):
        assert twin.clearance == law.clearance  # exact: passed through
        np.testing.assert_allclose([twin.frequency, twin.loss_factor], [frequency, xi], rtol=CONVERSION_RTOL, atol=0.0)
        np.testing.assert_allclose([twin.stiffness(mass), twin.damping(mass)], [law.stiffness(mass), law.damping(mass)], rtol=CONVERSION_RTOL, atol=0.0)


def test_from_stiffness_gives_back_the_physical_values() -> None:
    law = KelvinVoigtBumper.from_stiffness(1e-3, 1e5, 0.1, damping=20.0)
    np.testing.assert_allclose([law.stiffness(0.1), law.damping(0.1)], [1e5, 20.0], rtol=CONVERSION_RTOL)
    np.testing.assert_allclose([law.omega, law.loss_factor], [1e3, 20.0 / (2.0 * math.sqrt(1e5 * 0.1))], rtol=CONVERSION_RTOL)


@pytest.mark.parametrize(
    ("kwargs", "expected"),
    [
        ({"stiffness": -1.0, "effective_mass": 1.0, "damping": 1.0}, "stiffness = -1.0 is out of range: allowed (0, inf)"),
        ({"stiffness": 1e4, "effective_mass": 0.0, "damping": 1.0}, "effective_mass = 0.0 is out of range: allowed (0, inf)"),
        ({"stiffness": 1e4, "effective_mass": 1.0, "damping": -2.0}, "damping = -2.0 is out of range: allowed [0, inf)"),
        ({"stiffness": 1e4, "effective_mass": 1.0, "loss_factor": -0.1}, "loss_factor = -0.1 is out of range: allowed [0, inf)"),
        ({"stiffness": 1e4, "effective_mass": 1.0, "damping": 1.0, "loss_factor": 0.1}, "give exactly one, damping [N s/m] in [0, inf) or loss_factor"),
        ({"stiffness": 1e4, "effective_mass": 1.0}, "give exactly one, damping [N s/m] in [0, inf) or loss_factor"),
    ],
)
def test_from_stiffness_refusals_name_the_key_and_its_range(kwargs: dict[str, float], expected: str) -> None:
    with pytest.raises(ValueError, match=re.escape(expected)):
        KelvinVoigtBumper.from_stiffness(0.003, **kwargs)


def test_stop_bumper_converts_with_the_stops_own_effective_mass() -> None:
    """Between two free masses m_a, m_b the stop feels m_a m_b / (m_a + m_b); on x2 of a diagonal M, m2."""
    mass = np.diag([1.0, 0.25])
    between = Stop.bumper(mass, 0.002, 4e4, damping=8.0, coordinate=1, other=0, side="lower")
    assert (between.coordinate, between.other, between.side) == (1, 0, "lower")
    np.testing.assert_allclose(between.effective_mass(mass), 0.2, rtol=1e-15)
    np.testing.assert_allclose([between.law.stiffness(0.2), between.law.damping(0.2)], [4e4, 8.0], rtol=CONVERSION_RTOL)
    np.testing.assert_allclose(place_effective_mass((1, None, "upper"), mass), 0.25, rtol=1e-15)
    with pytest.raises(ValueError, match=re.escape("coordinate index 2 is out of range for a system of 2 coordinates: allowed [0, 1] (an int is a 0-based index: 0 is x1, 1 is x2; or give the name, 'x2')")):
        Stop.bumper(mass, 0.002, 4e4, damping=8.0, coordinate=2)


@pytest.mark.parametrize("damping", [0.0, 20.0, 300.0, 1500.0])
def test_one_collision_lasts_as_long_as_its_stiffness_damping_and_mass_say(damping: float) -> None:
    """A unit mass entering a bumper of K = 1e5 N/m and B [N s/m] (built from those numbers) leaves when the force
    K x + B x' falls to zero: after 2 arccos(xi) / w_d with w_d = sqrt(K/m - (B/2m)^2), xi = B / (2 sqrt(K m)); without
    damping, the half period pi / sqrt(K/m). The force is the law's own (its K and B through the effective mass)."""
    mass, stiffness, v0 = 1.0, 1e5, 0.3
    law = KelvinVoigtBumper.from_stiffness(0.0, stiffness, mass, damping=damping)

    def released(_t: float, y: np.ndarray) -> float:
        return stiffness * y[0] + damping * y[1] if _t > 0.0 else 1.0

    released.terminal, released.direction = True, -1  # type: ignore[attr-defined]

    def rhs(_t: float, y: np.ndarray) -> list[float]:
        return [y[1], -law.stiffness(mass) * y[0] / mass - law.damping(mass) * y[1] / mass]

    sol = solve_ivp(rhs, (0.0, 1.0), [0.0, v0], events=released, rtol=1e-12, atol=1e-16, max_step=1e-5, first_step=1e-9)
    duration = float(sol.t_events[0][0])
    xi = damping / (2.0 * math.sqrt(stiffness * mass))
    expected = release_time(xi) / law.omega
    if xi < 1.0:
        np.testing.assert_allclose(expected, 2.0 * math.acos(xi) / math.sqrt(stiffness / mass - (damping / (2.0 * mass)) ** 2), rtol=1e-14)
    if damping == 0.0:  # exact: a parametrized input
        np.testing.assert_allclose(expected, math.pi / math.sqrt(stiffness / mass), rtol=1e-14)
    np.testing.assert_allclose(duration, expected, rtol=1e-7)
    assert law.force(mass, 1e-4, 0.0) > 0.0 and law.force(mass, -1e-4, 0.0) == 0.0  # exact: no contact, force set to 0
