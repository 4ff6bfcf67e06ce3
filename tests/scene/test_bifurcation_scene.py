"""Bifurcation scenes: the shipped one parses, and every mistake is reported naming its key."""

from __future__ import annotations

import copy
from typing import Any

import pytest

from vibroimpact.scene import SceneError, find_scene, load_scene, parse_scene

PAPER_SYSTEM_SPEC = {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0, "b1": 0.8, "b2": 0.08}


def document(**changes: Any) -> dict[str, Any]:
    """A small valid bifurcation scene with ``bifurcation`` entries replaced by ``changes``."""
    doc = {
        "name": "bif",
        "system": dict(PAPER_SYSTEM_SPEC),
        "excitation": {"amplitude": 10.0},
        "stop": {"clearance": 0.003},
        "bifurcation": {"frequency": {"start": 20.0, "stop": 27.0}, "restitution": [0.8], "brute_force": {"step": 0.5}},
    }
    doc["bifurcation"].update(copy.deepcopy(changes))
    return doc


def problems(doc: dict[str, Any]) -> list[str]:
    with pytest.raises(SceneError) as caught:
        parse_scene(doc)
    return caught.value.problems


def test_the_shipped_study_is_a_bifurcation_scene() -> None:
    scene = load_scene(find_scene("bifurcation"))
    assert scene.kind == "bifurcation"
    settings = scene.bifurcation
    assert (settings.low, settings.high) == (15.0, 45.0) and settings.restitution == (0.2, 0.8)
    assert scene.frequency.size == 601 and scene.frequency[-1] == pytest.approx(45.0)
    assert settings.chart is not None and settings.chart.restitution == 0.2 and float(scene.clearance[0]) == pytest.approx(3e-3)  # exact: parsed inputs


def test_a_small_scene_parses_with_defaults() -> None:
    scene = parse_scene(document())
    assert scene.kind == "bifurcation" and scene.bifurcation.chart is None
    assert scene.bifurcation.brute_force.directions == ("up", "down") and scene.frequency.size == 15


@pytest.mark.parametrize(
    ("change", "key"),
    [
        ({"colour": 1}, "bifurcation.colour"),
        ({"restitution": [1.5]}, "bifurcation.restitution[0]"),
        ({"frequency": {"start": 30.0, "stop": 20.0}}, "bifurcation.frequency.stop"),
        ({"brute_force": {"step": 0.5, "strobes": 0}}, "bifurcation.brute_force.strobes"),
        ({"brute_force": {"step": 50.0}}, "bifurcation.brute_force.step"),
        ({"brute_force": {"directions": ["sideways"]}}, "bifurcation.brute_force.directions[0]"),
        ({"continuation": {"linear": "yes"}}, "bifurcation.continuation.linear"),
        ({"continuation": {"max_step": 5.0}}, "bifurcation.continuation.max_step"),
        ({"chart": {"strobes": 10}}, "bifurcation.chart.strobes"),
        ({"chart": {"kinds": ["cusp"]}}, "bifurcation.chart.kinds[0]"),
        ({"chart": {"clearance": {"start": 0.004, "stop": 0.002}}}, "bifurcation.chart.clearance.stop"),
        ({"chart": {"restitution": -0.1}}, "bifurcation.chart.restitution"),
    ],
)
def test_each_mistake_names_its_key(change: dict[str, Any], key: str) -> None:
    found = problems(document(**change))
    assert any(p.startswith(key + ":") for p in found), found


def test_all_problems_at_once_and_the_stop_is_required() -> None:
    doc = document(restitution=[2.0], chart={"strobes": 1})
    del doc["stop"]
    found = problems(doc)
    assert any(p.startswith("stop:") for p in found)
    assert any(p.startswith("bifurcation.restitution[0]") for p in found) and any(p.startswith("bifurcation.chart.strobes") for p in found)


def test_the_settings_default_directions_are_the_sweep_directions() -> None:
    """bifurcation_settings imports nothing from the scene layer (no circle with schema): its default is a copy."""
    from vibroimpact.scene.bifurcation_settings import BruteForceSettings
    from vibroimpact.scene.schema import SWEEP_DIRECTIONS

    assert BruteForceSettings.__dataclass_fields__["directions"].default == SWEEP_DIRECTIONS
