"""Bumpers in physical units in scenes: {stiffness [N/m], damping [N s/m]} or {stiffness, loss_factor} beside
{frequency [Hz], loss_factor [-]}, converted with each stop's effective mass; each mistake named in the scene's units."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from vibroimpact import cli
from vibroimpact.model.contact import KelvinVoigtBumper
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.scene import parse_scene

from tests.scene.test_scene import problems_of, write_yaml
from tests.scene.test_scene_bumper import compliant_scene
from tests.scene.test_scene_layout import relative_scene

#: The twins' bumpers agree to round-off [-]: the stiffness form goes through sqrt(K / m_eff) / 2 pi (and m_eff
#: through 1 / (n . M^-1 n)), measured within a few ulp.
TWIN_RTOL = 1e-15
#: Omega_b / 2 pi [Hz] and xi_b [-] of the frequency-form twin.
FREQUENCY, LOSS = 250.0, 0.65


def physical(mass: float, frequency: float = FREQUENCY, loss: float = LOSS) -> dict[str, float]:
    """The bumper of ``frequency`` and ``loss`` on a stop of effective mass ``mass`` [kg], in N/m and N s/m."""
    law = KelvinVoigtBumper(0.0, frequency, loss)
    return {"stiffness": law.stiffness(mass), "damping": law.damping(mass)}


def bumper_problem(document: dict[str, Any]) -> ImpactProblem:
    """The compliant problem of ``document`` at its first grid point and 22 Hz."""
    scene = parse_scene(document)
    s = scene.settings
    fb = float(s.bumper_frequency[0]) if s.bumper_frequency is not None else math.nan
    return scene.layout.problem(scene.amplitude, 22.0, float(s.restitution[0]), float(s.clearance[0]), True, fb, float(s.loss_factors()[0]))


def assert_same_bumpers(problem: ImpactProblem, twin: ImpactProblem) -> None:
    """Same places and clearances; K, B, Omega_b and xi_b of every stop within :data:`TWIN_RTOL`."""
    assert [stop.place for stop in problem.stops] == [stop.place for stop in twin.stops]
    for stop, other in zip(problem.stops, twin.stops):
        mass = stop.effective_mass(problem.structure.mass_matrix)
        assert stop.clearance == other.clearance  # exact: parsed inputs
        got = [stop.law.frequency, stop.law.loss_factor, stop.law.stiffness(mass), stop.law.damping(mass)]
        want = [other.law.frequency, other.law.loss_factor, other.law.stiffness(mass), other.law.damping(mass)]
        np.testing.assert_allclose(got, want, rtol=TWIN_RTOL, atol=0.0)


def test_the_papers_stop_in_stiffness_and_damping_is_its_frequency_form_twin() -> None:
    """bumper: {stiffness: M2 Omega_b^2, damping: 2 M2 xi_b Omega_b} on the paper's stop (m_eff = M2 = 0.1 kg)."""
    frequency_form = compliant_scene(bumper={"frequency": FREQUENCY, "loss_factor": LOSS})
    twin = bumper_problem(compliant_scene(bumper=physical(0.1)))
    assert_same_bumpers(twin, bumper_problem(frequency_form))
    loss_form = bumper_problem(compliant_scene(bumper={"stiffness": physical(0.1)["stiffness"], "loss_factor": LOSS}))
    assert_same_bumpers(loss_form, bumper_problem(frequency_form))
    scene = parse_scene(compliant_scene(bumper=physical(0.1)))
    assert scene.layout.paper_view() is not None and scene.settings.swept == ("frequency",)
    words = scene.layout.attributes(scene.settings.restitution, scene.settings.clearance, scene.settings.bumper_frequency)["stop_layout"]
    assert words.startswith("x2 <= 3 mm, R = 0.2, bumper K_b = 246740 N/m, B_b = 204.204 N s/m (Omega_b / 2 pi = 250 Hz)"), words


def test_a_stops_own_bumper_converts_with_its_own_effective_mass() -> None:
    """Relative stops between x2 (0.1 kg) and x1 (1 kg) feel 0.1 / 1.1 kg; each writes its bumper in its own form."""
    relative_mass = 0.1 / 1.1

    def scene(bumpers: list[dict[str, float]]) -> dict[str, Any]:
        document = relative_scene()
        document["solutions"] = ["linear", "compliant"]
        for stop, bumper in zip(document["stops"], bumpers):
            stop["bumper"] = bumper
        return document

    frequency_form = scene([{"frequency": FREQUENCY, "loss_factor": LOSS}, {"frequency": 400.0, "loss_factor": 0.1}])
    twin = scene([physical(relative_mass), physical(relative_mass, 400.0, 0.1)])
    assert_same_bumpers(bumper_problem(twin), bumper_problem(frequency_form))


def test_the_scenes_bumper_gives_each_stop_its_own_frequency_on_its_own_mass() -> None:
    """One K_b and B_b for a stop on x2 (0.1 kg) and one between x2 and x1 (0.1 / 1.1 kg): two frequencies, kept per
    stop (the grid has none), as if each stop had written its own frequency form."""
    document = relative_scene()
    document["solutions"] = ["linear", "compliant"]
    document["stops"][0] = {"coordinate": "x2", "side": "upper", "clearance": 0.003, "restitution": 0.2}
    document["bumper"] = physical(0.1)
    problem = bumper_problem(document)
    omega = math.sqrt(document["bumper"]["stiffness"] / 0.1)
    expected = [(omega, LOSS), (omega * math.sqrt(1.1), LOSS * math.sqrt(1.1))]  # xi_b = B / (2 sqrt(K m_eff))
    got = [(stop.law.omega, stop.law.loss_factor) for stop in problem.stops]
    np.testing.assert_allclose(got, expected, rtol=4 * TWIN_RTOL, atol=0.0)
    scene = parse_scene(document)
    assert scene.settings.bumper_frequency is not None and np.isnan(scene.settings.bumper_frequency).all()
    assert [stop.bumper_stiffness for stop in scene.layout.stops] == [document["bumper"]["stiffness"]] * 2  # exact: as given


@pytest.mark.parametrize(
    ("bumper", "expected"),
    [
        ({"frequency": 250.0, "stiffness": 1e5}, "bumper: give the bumper either as frequency [Hz] (with loss_factor [-]) or as stiffness [N/m] (with damping [N s/m] or loss_factor [-]), not both: remove frequency or stiffness"),
        ({"stiffness": 1e5, "damping": 20.0, "loss_factor": 0.1}, "bumper: give damping [N s/m] or loss_factor [-], not both"),
        ({"damping": 20.0}, "bumper: damping [N s/m] needs stiffness [N/m] beside it"),
        ({"stiffness": -1e5}, "bumper.stiffness: -100000.0 is out of range: allowed (0, inf)"),
        ({"stiffness": 1e5, "damping": -1.0}, "bumper.damping: -1.0 is out of range: allowed [0, inf)"),
        ({"stiffness": 1e13, "damping": 1.0}, "bumper.stiffness: 1e+13 N/m is out of range: allowed (0, 3.948e+12] N/m on the stop (effective mass 0.1 kg, Omega_b / 2 pi <= 1e+06 Hz)"),
        ({"stiffness": 1e5, "damping": 1e7}, "bumper.damping: 1e+07 N s/m is out of range: allowed [0, 2e+05] N s/m with this stiffness on the stop (effective mass 0.1 kg, loss factor xi_b <= 1000)"),
        ({"stiffness": "stiff"}, "bumper.stiffness: expected a number, got 'stiff'"),
    ],
)
def test_scene_bumper_mistakes_name_the_keys_in_the_scenes_units(bumper: dict[str, Any], expected: str) -> None:
    problems = problems_of(compliant_scene(bumper=bumper))
    assert any(expected in p for p in problems), problems


@pytest.mark.parametrize(
    ("change", "expected"),
    [
        (lambda d: d["sweep"].update(bumper_frequency=[100.0, 200.0]), "bumper.stiffness: also swept in sweep.bumper_frequency"),
        (lambda d: d["sweep"].update(bumper_loss_factor=[0.1, 0.2]), "bumper.damping: also swept in sweep.bumper_loss_factor"),
    ],
)
def test_a_physical_bumper_is_not_also_swept(change: Any, expected: str) -> None:
    document = compliant_scene(bumper={"stiffness": 1e5, "damping": 20.0})
    change(document)
    assert any(expected in p for p in problems_of(document))


@pytest.mark.parametrize(
    ("bumper", "expected"),
    [
        ({"frequency": 250.0, "damping": 3.0}, "stops[0].bumper: give the bumper either as frequency [Hz]"),
        ({"stiffness": 1e5, "damping": 3.0, "loss_factor": 0.2}, "stops[0].bumper: give damping [N s/m] or loss_factor [-], not both"),
        ({"stiffness": 1e13}, "stops[0].bumper.stiffness: 1e+13 N/m is out of range: allowed (0, 3.589e+12] N/m on this stop (effective mass 0.0909091 kg"),
        ({"stiffness": 1e5, "mass": 1.0}, "stops[0].bumper.mass: unknown key (allowed: frequency, loss_factor, stiffness, damping)"),
    ],
)
def test_stop_bumper_mistakes(bumper: dict[str, Any], expected: str) -> None:
    document = relative_scene()
    document["solutions"] = ["linear", "compliant"]
    document["stops"][0]["bumper"] = bumper
    problems = problems_of(document)
    assert any(expected in p for p in problems), problems


def test_a_stops_own_stiffness_also_swept_is_named_as_written() -> None:
    document = relative_scene()
    document["solutions"] = ["linear", "compliant"]
    document["stops"][0]["bumper"] = {"stiffness": 1e5, "damping": 3.0}
    document["stops"][1]["bumper"] = {"frequency": 250.0}
    document["sweep"]["bumper_frequency"] = [100.0, 200.0]
    assert any("stops[0].bumper.stiffness: also swept in sweep.bumper_frequency" in p for p in problems_of(document))


def test_a_mixed_bumper_exits_2_before_any_work(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    path = write_yaml(tmp_path / "mixed.yaml", compliant_scene(bumper={"frequency": 250.0, "stiffness": 1e5}))
    assert cli.main([str(path), "--out", str(out)]) == 2
    assert "remove frequency or stiffness" in capsys.readouterr().err and not out.exists()
