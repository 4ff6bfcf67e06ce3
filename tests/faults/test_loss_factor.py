"""A bumper's loss factor beyond what double precision resolves is refused by the model itself, with the key, the
range and the reason (issue 34, item 8: ``loss_factor=1e9`` reached the engine and was called "loss factor 1"), and
the collision's closed forms stay finite and accurate for every loss factor (``release_time`` raised a math domain
error from 7e7 on)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.engines.test_compliant_exact import _free_mass
from vibroimpact.engines.registry import make_engine
from vibroimpact.model.contact import MAX_LOSS_FACTOR, KelvinVoigtBumper, loss_factor_from_restitution, release_time, restitution_from_loss_factor


@pytest.mark.faults
@pytest.mark.parametrize("loss_factor", [1e3 * (1 + 1e-12), 1e6, 1e9])
def test_a_bumper_beyond_the_loss_factor_limit_is_refused_by_the_model(loss_factor: float) -> None:
    with pytest.raises(ValueError, match=r"loss_factor = .* is out of range: allowed \[0, 1000\] \(beyond it a bumper's slow decay rate"):
        KelvinVoigtBumper(1e-3, 250.0, loss_factor)


@pytest.mark.faults
def test_the_most_damped_bumper_accepted_runs() -> None:
    """At the limit the engine still integrates a collision, and right: a free mass leaves at -R(xi) v0 (R 2.5e-7, to
    1e-6 of itself): the limit refuses nothing the engines do well."""
    v0 = 0.5
    run = make_engine("compliant_exact").integrate(_free_mass(MAX_LOSS_FACTOR), np.array([1e-3, v0]), 0.0, 1)
    assert run.stats["contacts"] == 1
    assert -run.final_state[1] / v0 == pytest.approx(restitution_from_loss_factor(MAX_LOSS_FACTOR), rel=1e-6)


@pytest.mark.faults
@pytest.mark.parametrize("xi", [1.0 + 1e-9, 2.0, 1e2, 1e4 * (1 - 1e-12), 1e4 * (1 + 1e-12), 1e7, 1e9, 1e12])
def test_the_overdamped_release_time_is_finite_and_accurate(xi: float) -> None:
    """2 atanh(s / xi) / s = 2 log(xi + s) / s (xi^2 - s^2 = 1); against the second form in extended precision."""
    s = np.sqrt(np.longdouble(xi) ** 2 - 1)
    expected = float(2 * np.log(np.longdouble(xi) + s) / s)
    assert release_time(xi) == pytest.approx(expected, rel=1e-9)


@pytest.mark.faults
def test_a_restitution_no_bumper_reaches_is_named() -> None:
    floor = restitution_from_loss_factor(MAX_LOSS_FACTOR)
    assert loss_factor_from_restitution(floor * 1.01) == pytest.approx(MAX_LOSS_FACTOR, rel=0.01)
    with pytest.raises(ValueError, match=r"restitution = 1e-09 is below what a bumper of loss factor up to 1000 reaches: allowed \[2.5e-07, 1\]"):
        loss_factor_from_restitution(1e-9)
    assert math.isclose(restitution_from_loss_factor(loss_factor_from_restitution(0.2)), 0.2, rel_tol=1e-12)


@pytest.mark.faults
@pytest.mark.parametrize("stops", [False, True])
def test_a_restitution_no_bumper_reaches_is_refused_by_the_scene(stops: bool) -> None:
    """R = 1e-8 with a bumper solution passed the scene's check (only R = 0 was refused) and failed at run time, after
    every block, on every rerun; now the scene names the key and the floor 2.5e-7, before any work."""
    from vibroimpact.scene.checker import SceneError
    from vibroimpact.scene.reader import parse_scene

    document = {
        "name": "floor", "system": {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0, "b1": 0.8, "b2": 0.08}, "excitation": {"amplitude": 10.0},
        "stop": {"clearance": 0.003}, "bumper": {"frequency": 250.0}, "sweep": {"restitution": [1e-8, 0.5], "frequency": [24.0]}, "solutions": ["compliant_exact"],
    }
    key = "stop.restitution"
    if stops:
        document.pop("stop")
        document["stops"] = [{"coordinate": "x2", "clearance": 0.003, "restitution": 1e-8}]
        document["sweep"] = {"frequency": [24.0]}
        key = r"stops\[0\].restitution"
    with pytest.raises(SceneError, match=rf"{key}: R = 1e-08 needs a bumper more damped than loss factor 1000 for the compliant solution: give .*bumper.loss_factor.*R >= 2.5e-07"):
        parse_scene(document)
