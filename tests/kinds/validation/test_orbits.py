"""Published closed forms located by continuation of periodic orbits on the exact engine's stroboscopic map
(studies/validation/budd_dux.yaml, bouncing_ball.yaml, grazing.yaml)."""

from __future__ import annotations

import numpy as np
import pytest

from vibroimpact.kinds.validation.settings import BouncingBallCase, BuddDuxCase, GrazingCase
from vibroimpact.kinds.validation.formulas import (
    ball_existence,
    ball_period_doubling,
    ball_period_doubling_high_bounce,
    budd_dux_period_doubling,
    budd_dux_residual,
    grazing_amplitude,
)
from vibroimpact.kinds.validation.orbits import run_bouncing_ball, run_budd_dux, run_grazing


def _failed(outcome) -> list[tuple[str, float, float]]:
    return [(c.quantity, c.relative_error, c.tolerance) for c in outcome.checks if not c.informative and not c.passed]


def _row(outcome, start: str):
    return next(c for c in outcome.checks if c.quantity.startswith(start))


def test_budd_dux_ellipse_and_period_doubling() -> None:
    """Budd & Dux, Phil. Trans. R. Soc. A 347 (1994) 365: x'' + x = cos(w t), x <= sigma, x' -> -r x' (w = 2.8,
    r = 0.8). Every continued point of the period-one orbit, sigma from -0.5 to 0.14 (negative included), has its
    impact velocity on (sigma + c V/2)^2 + ((1 - r) V/(2 w))^2 = gamma^2 to 1e-8; its period doubling, located by the
    continuation, is the closed form's sigma = -0.0685757 (derived from the impact map) to 1e-8; the stable side is
    sigma below it."""
    case = BuddDuxCase()
    outcome = run_budd_dux(case)
    assert not _failed(outcome)
    data = outcome.data
    sigma, velocity = data["clearance"].values, data["impact_velocity"].values
    assert sigma.min() == pytest.approx(-0.5, abs=1e-9) and sigma.max() == pytest.approx(0.14, abs=1e-9)
    assert np.max(np.abs(budd_dux_residual(sigma, velocity, case.forcing_frequency, case.restitution))) < 1e-8
    pd = budd_dux_period_doubling(case.forcing_frequency, case.restitution)[0]
    stable = data["stable"].values == 1
    assert np.all(sigma[stable] < pd + 1e-6) and np.all(sigma[~stable] > pd - 1e-6)
    assert _row(outcome, "sigma at the period doubling").relative_error < 1e-8


def test_bouncing_ball_existence_and_period_doubling() -> None:
    """Holmes, J. Sound Vib. 84 (1982) 173: the ball on a table A sin(w t) (e = 0.5, 10 Hz). The period-one orbit
    begins (a fold of the continued branch) at Gamma = pi (1 - e)/(1 + e) and doubles at the exact table's
    Gamma = sqrt((pi (1-e)/(1+e))^2 + (2 (1+e^2)/(1+e)^2)^2), both to 1e-8; Holmes' high-bounce map would double at
    sqrt((pi (1-e)/(1+e))^2 + 1), 5 % lower: that row is informative only. Along the branch the impact speed
    relative to the table is g T/(1 + e)."""
    case = BouncingBallCase()
    outcome = run_bouncing_ball(case, brute=False)
    assert not _failed(outcome)
    e = case.restitution
    assert _row(outcome, "Gamma where").computed == pytest.approx(ball_existence(e), rel=1e-8)
    assert _row(outcome, "Gamma of the period doubling").computed == pytest.approx(ball_period_doubling(e), rel=1e-8)
    holmes = _row(outcome, "Gamma of the period doubling in Holmes")
    assert holmes.informative and holmes.published == pytest.approx(ball_period_doubling_high_bounce(e))
    assert holmes.relative_error > 0.04


def test_bouncing_ball_brute_force_doubles_where_the_branch_does() -> None:
    """The brute-force sweep (each Gamma from the last end state) has one impact speed per period up to the period
    doubling, and two distinct ones just above it (period two)."""
    case = BouncingBallCase(acceleration=(1.1, 1.7), brute_step=0.02)
    from vibroimpact.kinds.validation.orbits import brute_force

    data = brute_force(case)
    gamma = data["brute_acceleration"].values
    speeds = data["brute_impact_speed"].values
    pd = ball_period_doubling(case.restitution)
    for g, row in zip(gamma, speeds):
        values = row[np.isfinite(row)]
        spread = np.ptp(values) / np.mean(values)
        if ball_existence(case.restitution) + 0.05 < g < pd - 0.03:
            assert spread < 1e-6, g
        elif pd + 0.03 < g < pd + 0.1:
            assert spread > 1e-3, g


@pytest.mark.slow
def test_grazing_boundary() -> None:
    """The forced oscillator m x'' + c x' + k x = A cos(w t) with a stop at d starts to impact at
    A = d sqrt((k - m w^2)^2 + (c w)^2) (the linear amplitude reaches the stop; e.g. Nordmark, J. Sound Vib. 145
    (1991) 279), located by continuation in A to 1e-8; below it the orbit is the linear steady state."""
    case = GrazingCase()
    outcome = run_grazing(case)
    assert not _failed(outcome)
    w = 2.0 * np.pi * case.frequency
    located = _row(outcome, "force amplitude A where impacts begin").computed
    assert located == pytest.approx(grazing_amplitude(case.clearance, case.mass, case.stiffness, case.damping, w), rel=1e-8)
