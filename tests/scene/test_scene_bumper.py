"""Scenes with a compliant bumper and swept-sine tests: what is accepted, what each mistake reports."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from vibroimpact.model.contact import loss_factor_from_restitution, restitution_from_loss_factor
from vibroimpact.scene import parse_scene

from tests.scene.test_scene import problems_of, scene_with


def compliant_scene(**changes: Any) -> dict[str, Any]:
    document = scene_with()
    document["solutions"] = ["pgf", "compliant"]
    document["bumper"] = {"frequency": 250.0}
    document.update(changes)
    return document


def test_loss_factor_defaults_to_the_exact_inverse_of_each_restitution() -> None:
    document = compliant_scene()
    document["stop"] = {"clearance": 0.003}
    document["sweep"]["restitution"] = [0.2, 0.5]
    scene = parse_scene(document)
    np.testing.assert_allclose([restitution_from_loss_factor(x) for x in scene.settings.loss_factors()], [0.2, 0.5], rtol=1e-13)
    assert scene.settings.bumper_frequency is not None and scene.settings.bumper_frequency.tolist() == [250.0]


def test_given_loss_factor_is_kept_apart_from_the_rigid_restitution() -> None:
    """The paper's own choice: xi_b = 0.65 for the bumper while the rigid-stop solutions use R = 0.2."""
    scene = parse_scene(compliant_scene(bumper={"frequency": 250.0, "loss_factor": 0.65}))
    assert scene.settings.restitution.tolist() == [0.2] and scene.settings.loss_factors().tolist() == [0.65]


def test_swept_loss_factor_sets_the_restitution() -> None:
    document = compliant_scene()
    document["stop"] = {"clearance": 0.003}
    document["bumper"] = {"frequency": 500.0}
    document["sweep"]["bumper_loss_factor"] = [0.1, 0.7, 1.5]
    scene = parse_scene(document)
    assert scene.settings.swept == ("bumper_loss_factor", "frequency")
    np.testing.assert_allclose(scene.settings.restitution, [restitution_from_loss_factor(x) for x in (0.1, 0.7, 1.5)])
    np.testing.assert_allclose(scene.settings.loss_factors(), [0.1, 0.7, 1.5])


@pytest.mark.parametrize(
    ("change", "expected"),
    [
        (lambda d: d.pop("bumper"), "bumper: required by the compliant solution"),
        (lambda d: d.update(bumper={"loss_factor": 0.5}), "bumper.frequency: required unless swept"),
        (lambda d: d.update(bumper={"frequency": -1.0}), "bumper.frequency: -1.0 is out of range: allowed (0, 1e+06]"),
        (lambda d: d.update(bumper={"frequency": 250.0, "loss_factor": -0.1}), "bumper.loss_factor: -0.1 is out of range: allowed [0, 1000]"),
        (lambda d: d.update(bumper={"frequency": 250.0, "damping": 1.0}), "bumper: give the bumper either as frequency [Hz] (with loss_factor [-]) or as stiffness [N/m]"),
        (lambda d: d.update(bumper={"frequency": 250.0, "mass": 1.0}), "bumper.mass: unknown key (allowed: frequency, loss_factor, stiffness, damping)"),
        (lambda d: d["sweep"].update(bumper_frequency=[100.0, 200.0]), "bumper.frequency: also swept in sweep.bumper_frequency"),
        (lambda d: d["sweep"].update(bumper_loss_factor=[0.5, 1.0]), "sweep.bumper_loss_factor: sweeping the bumper's loss factor sets the restitution"),
        (lambda d: d["stop"].update(restitution=0.0), "stop.restitution: R = 0 needs an infinitely damped bumper"),
    ],
)
def test_bumper_mistakes(change: Any, expected: str) -> None:
    document = compliant_scene()
    change(document)
    problems = problems_of(document)
    assert any(expected in p for p in problems), problems


def sweep_scene(**swept_sine: Any) -> dict[str, Any]:
    document = compliant_scene()
    document["swept_sine"] = {"start": 20.0, "stop": 26.0, "rate": 0.5, **swept_sine}
    return document


def test_swept_sine_settings() -> None:
    scene = parse_scene(sweep_scene(directions=["down"], window_cycles=4))
    assert scene.settings.swept_sine is not None and scene.settings.sweep_directions == ("down",)
    sweep = scene.settings.swept_sine.sweep(10.0, "down")
    assert (sweep.start_frequency, sweep.stop_frequency, sweep.alpha, sweep.duration) == (26.0, 20.0, -0.5, 12.0)
    assert scene.settings.swept_sine.window_cycles == 4 and scene.settings.swept_sine.sample_rate == 1000.0  # exact: parsed input


@pytest.mark.parametrize(
    ("spec", "solutions", "simulation", "expected"),
    [
        ({"start": 20.0, "stop": 26.0}, None, None, "swept_sine.rate: required key is missing"),
        ({"start": 30.0, "stop": 26.0, "rate": 0.1}, None, None, "swept_sine.stop: 26 must be greater than start = 30"),
        ({"start": 20.0, "stop": 26.0, "rate": 0.1, "sample_rate": 100.0}, None, None, "swept_sine.sample_rate: 100 Hz is too coarse for 26 Hz: allowed [520, 1e+07]"),
        ({"start": 20.0, "stop": 26.0, "rate": 0.1, "directions": ["sideways"]}, None, None, "swept_sine.directions[0]: unknown name 'sideways' (allowed: up, down)"),
        ({"start": 20.0, "stop": 26.0, "rate": 0.1}, ["pgf", "momentary"], None, "solutions: a swept-sine test runs the compliant solution only"),
        ({"start": 20.0, "stop": 26.0, "rate": 0.1}, None, {"max_periods": 10}, "simulation.max_periods: not used by a swept-sine test"),
        ({"start": 20.0, "stop": 26.0, "rate": 1e-6}, None, None, "swept_sine.rate: 6e+06 s at 1000 samples/s is 6e+09 samples per run: allowed at most 1e+07"),
        ({"start": 20.0, "stop": 26.0, "rate": 100.0}, None, None, "swept_sine.rate: the sweep lasts 0.06 s, shorter than two 8-cycle estimator windows at 20 Hz (0.8 s)"),
        ({"start": 30.0, "stop": 31.0, "rate": 0.1}, None, None, "sweep.frequency: no frequency of the grid lies in the swept band [30, 31] Hz"),
    ],
)
def test_swept_sine_mistakes(spec: dict[str, Any], solutions: list[str] | None, simulation: dict[str, Any] | None, expected: str) -> None:
    document = compliant_scene(swept_sine=spec)
    if solutions is not None:
        document["solutions"] = solutions
    if simulation is not None:
        document["simulation"] = simulation
    problems = problems_of(document)
    assert any(expected in p for p in problems), problems


def test_shipped_bumper_studies_parse() -> None:
    from vibroimpact.scene import load_scene, shipped_studies_dir

    for name in ("bumper_sweep", "bumper_stiffness", "restitution_peaks", "clearance_peaks", "peak_acceleration"):
        scene = load_scene(shipped_studies_dir() / f"{name}.yaml")
        assert "compliant" in scene.settings.solutions and scene.settings.bumper_frequency is not None, name
        assert np.all(np.isfinite(scene.settings.loss_factors()) & (scene.settings.loss_factors() > 0.0)), name
    sweep = load_scene(shipped_studies_dir() / "bumper_sweep.yaml")
    assert sweep.settings.loss_factors()[0] == pytest.approx(loss_factor_from_restitution(0.2)) and math.isclose(sweep.settings.loss_factors()[0], 0.7312, abs_tol=5e-5)


def test_every_swept_sine_problem_is_reported_at_once() -> None:
    problems = problems_of(compliant_scene(swept_sine={"start": 20.0, "stop": 26.0, "rate": 0.1, "initial_state": "bench", "sample_rate": 100.0}))
    assert any("swept_sine.initial_state: 'bench' is not allowed" in p for p in problems), problems
    assert any("swept_sine.sample_rate: 100 Hz is too coarse" in p for p in problems), problems


def test_default_tolerances_follow_the_guidance() -> None:
    """Without rtol/atol: stepped steady states 1e-8 / 1e-12 m, swept sines 1e-7 / 1e-11 m (README, tolerance
    guidance); given values win, and an rtol alone brings atol = rtol x 1e-4 m."""
    from vibroimpact.engines.settings import STEPPED_TOLERANCES, SWEPT_TOLERANCES

    stepped = parse_scene(compliant_scene())
    assert stepped.settings.simulation is not None and (stepped.settings.simulation.engine.rtol, stepped.settings.simulation.engine.atol) == STEPPED_TOLERANCES == (1e-8, 1e-12)
    swept = parse_scene(sweep_scene())
    assert swept.settings.simulation is not None and (swept.settings.simulation.engine.rtol, swept.settings.simulation.engine.atol) == SWEPT_TOLERANCES == (1e-7, 1e-11)
    given = parse_scene(sweep_scene() | {"simulation": {"rtol": 1e-6}})  # atol follows: rtol x 1e-4 m, as measured
    assert given.settings.simulation is not None and given.settings.simulation.engine.rtol == 1e-6 and given.settings.simulation.engine.atol == pytest.approx(1e-10)  # exact: parsed input
