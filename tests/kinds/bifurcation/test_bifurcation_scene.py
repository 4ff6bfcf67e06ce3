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
    settings = scene.settings
    assert (settings.low, settings.high) == (15.0, 45.0) and settings.restitution == (0.2, 0.8)
    assert scene.settings.frequency.size == 601 and scene.settings.frequency[-1] == pytest.approx(45.0)
    assert settings.chart is not None and settings.chart.restitution == 0.2 and scene.settings.clearance == pytest.approx(3e-3)  # exact: parsed inputs


def test_the_shipped_bumper_study_has_three_bumpers_beside_the_rigid_stop() -> None:
    scene = load_scene(find_scene("bifurcation_bumper"))
    settings = scene.settings
    assert scene.kind == "bifurcation" and settings.restitution == (0.2,) and settings.chart is None
    assert settings.bumper_frequencies == (250.0, 1000.0, 4000.0) and (settings.low, settings.high) == (15.0, 45.0)
    assert settings.reference == "rigid" and settings.models == (None, 250.0, 1000.0, 4000.0)  # it asks for the rigid stop as the reference
    assert parse_scene(document()).settings.bumper_frequencies == ()


def test_a_bumper_scene_runs_its_bumpers_alone_unless_it_asks_for_the_rigid_reference() -> None:
    """The rigid stop's diagram runs for a scene of rigid stops, or with ``reference: rigid``; a bumper scene without
    it is its bumpers' alone."""
    alone = parse_scene(document(bumper={"frequency": [1000.0]})).settings
    assert alone.reference == "none" and not alone.rigid and alone.models == (1000.0,)
    both = parse_scene(document(bumper={"frequency": [1000.0]}, reference="rigid")).settings
    assert both.rigid and both.models == (None, 1000.0)
    assert parse_scene(document()).settings.models == (None,)


@pytest.mark.parametrize(
    ("change", "words"),
    [
        ({"bumper": {"frequency": [1000.0]}, "reference": "rigid stop"}, "'rigid stop' is not allowed: allowed rigid, none; did you mean 'rigid'?"),
        ({"bumper": {"frequency": [1000.0]}, "reference": True}, "expected a string, got True (bool)"),
        ({"reference": "rigid"}, "a reference needs bifurcation.bumper"),
    ],
)
def test_a_wrong_reference_names_its_key_and_the_allowed_values(change: dict[str, Any], words: str) -> None:
    found = problems(document(**change))
    assert any(p.startswith("bifurcation.reference") and words in p for p in found), found


def test_a_small_scene_parses_with_defaults() -> None:
    scene = parse_scene(document())
    assert scene.kind == "bifurcation" and scene.settings.chart is None
    assert scene.settings.brute_force.directions == ("up", "down") and scene.settings.frequency.size == 15


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
        ({"bumper": {"frequency": [0.0]}}, "bifurcation.bumper.frequency[0]"),
        ({"bumper": {"stiffness": 1.0}}, "bifurcation.bumper.stiffness"),
        ({"bumper": {"frequency": [250.0]}, "chart": {}}, "bifurcation.chart"),
        ({"bumper": {"frequency": [250.0]}, "restitution": [0.0]}, "bifurcation.restitution"),
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
    from vibroimpact.kinds.bifurcation.scene import BruteForceSettings
    from vibroimpact.scene.schema import SWEEP_DIRECTIONS

    assert BruteForceSettings.__dataclass_fields__["directions"].default == SWEEP_DIRECTIONS


#: The paper's system written with matrices (the general form), force on x1.
MATRIX_SYSTEM_SPEC = {"mass": [[1.0, 0.0], [0.0, 0.1]], "stiffness": [[29300.0, -4300.0], [-4300.0, 4300.0]], "damping": [[0.88, -0.08], [-0.08, 0.08]], "coordinates": ["x1", "x2"]}


def general(stops: list[dict[str, Any]], **changes: Any) -> dict[str, Any]:
    """The small scene in the general form: matrices, a force on x1, ``stops``."""
    doc = document(**changes)
    doc["system"] = copy.deepcopy(MATRIX_SYSTEM_SPEC)
    doc["excitation"] = {"amplitude": 10.0, "on": "x1"}
    del doc["stop"]
    doc["stops"] = copy.deepcopy(stops)
    return doc


RELATIVE_PAIR = [{"between": ["x2", "x1"], "side": "upper", "clearance": 0.003}, {"between": ["x2", "x1"], "side": "lower", "clearance": 0.003}]


def test_the_shipped_relative_stop_study_is_a_general_bifurcation_scene() -> None:
    scene = load_scene(find_scene("bifurcation_relative_stop"))
    assert scene.kind == "bifurcation" and scene.layout.paper_view() is None and scene.settings.restitution == (0.2,)
    assert [(s.coordinate, s.other, s.side) for s in scene.layout.stops] == [(1, 0, "upper"), (1, 0, "lower")]
    assert scene.settings.clearance == pytest.approx(3e-3) and scene.layout.load.weights == (1.0, 0.0)


def test_the_general_form_takes_its_restitution_from_the_stops_or_the_diagrams() -> None:
    doc = general([{"coordinate": "x2", "clearance": 0.003, "restitution": 0.5}])
    del doc["bifurcation"]["restitution"]
    from_stops = parse_scene(doc)
    assert from_stops.settings.restitution == (0.5,) and from_stops.layout.stops[0].restitution is None  # the study's value
    from_diagrams = parse_scene(general(RELATIVE_PAIR, restitution=[0.2, 0.6]))
    assert from_diagrams.settings.restitution == (0.2, 0.6) and len(from_diagrams.layout.stops) == 2
    differ = general([{"coordinate": "x2", "clearance": 0.003, "restitution": 0.2}, {"coordinate": "x1", "clearance": 0.003, "restitution": 0.5}])
    del differ["bifurcation"]["restitution"]
    assert any(p.startswith("stops[1].restitution:") and "differs" in p for p in problems(differ))


@pytest.mark.parametrize(
    ("stops", "key"),
    [
        ([{**RELATIVE_PAIR[0], "restitution": 0.2}, RELATIVE_PAIR[1]], "stops[0].restitution"),  # also in bifurcation.restitution
        ([RELATIVE_PAIR[0], {**RELATIVE_PAIR[1], "clearance": 0.002}], "stops[1].clearance"),  # one clearance for every stop
        ([{"coordinate": "x2"}], "stops[0].clearance"),  # required
        ([{"coordinate": "x2", "clearance": -0.001}], "stops[0].clearance"),  # (0, inf)
        ([{"coordinate": "x2", "clearance": 0.003, "bumper": {"frequency": 100.0}}], "stops[0].bumper"),  # rigid only
        ([{"coordinate": "x3", "clearance": 0.003}], "stops[0].coordinate"),  # the stepped parser's own check
    ],
)
def test_each_mistake_of_the_general_form_names_its_key(stops: list[dict[str, Any]], key: str) -> None:
    found = problems(general(stops))
    assert any(p.startswith(key + ":") for p in found), found


def test_the_general_form_reports_the_load_and_the_missing_restitution() -> None:
    doc = general([{"coordinate": "x2", "clearance": 0.003}])
    doc["excitation"]["on"] = "x9"
    del doc["bifurcation"]["restitution"]
    found = problems(doc)
    assert any(p.startswith("excitation.on:") and "x9" in p for p in found), found
    assert any(p.startswith("bifurcation.restitution:") for p in found) and any(p.startswith("stops[0].restitution:") for p in found), found
    both = general([{"coordinate": "x2", "clearance": 0.003}])
    both["stop"] = {"clearance": 0.003}
    assert any(p.startswith("stop:") for p in problems(both))


def test_bumpers_given_by_stiffness_are_the_frequency_form_on_each_stops_mass() -> None:
    """``bumper: {stiffness: [N/m]}``: Omega_b = sqrt(K_b / m_eff) with the stop's effective mass, M2 = 0.1 kg on the
    paper's stop, m1 m2 / (m1 + m2) on a relative pair of a diagonal M (1e-15 relative); the stiffnesses are kept."""
    paper = parse_scene(document(bumper={"stiffness": [1e5, 0.1 * (2.0 * 3.141592653589793 * 250.0) ** 2]})).settings
    assert paper.bumper_frequencies == pytest.approx(((1e5 / 0.1) ** 0.5 / (2.0 * 3.141592653589793), 250.0), rel=1e-15)
    assert paper.bumper_stiffnesses == pytest.approx((1e5, 0.1 * (2.0 * 3.141592653589793 * 250.0) ** 2), rel=1e-15)
    relative = parse_scene(general(RELATIVE_PAIR, bumper={"stiffness": [1e5]})).settings
    mass = 1.0 * 0.1 / 1.1
    assert relative.bumper_frequencies == pytest.approx(((1e5 / mass) ** 0.5 / (2.0 * 3.141592653589793),), rel=1e-15)
    assert parse_scene(document(bumper={"frequency": [250.0]})).settings.bumper_stiffnesses == ()


@pytest.mark.parametrize(
    ("doc", "words"),
    [
        (document(bumper={"stiffness": [1e5], "frequency": [250.0]}), "give exactly one of frequency (Omega_b / 2 pi [Hz]) or stiffness (K_b [N/m])"),
        (document(bumper={}), "give exactly one of frequency"),
        (document(bumper={"stiffness": [-1.0]}), "bifurcation.bumper.stiffness"),
        (general([{"coordinate": "x1", "side": "upper", "clearance": 0.003}, {"coordinate": "x2", "side": "upper", "clearance": 0.003}], bumper={"stiffness": [1e5]}),
         "the stops push different effective masses (1, 0.1 kg)"),
    ],
)
def test_a_wrong_bumper_stiffness_names_its_key(doc: dict[str, Any], words: str) -> None:
    found = problems(doc)
    assert any(p.startswith("bifurcation.bumper") and words in p for p in found), found


def test_a_bumper_given_by_stiffness_is_named_by_it_on_the_page() -> None:
    import math

    import numpy as np
    import xarray as xr

    from vibroimpact.kinds.bifurcation.bumper import bumper_name

    given = xr.Dataset(attrs={"bumper_frequencies_Hz": np.array([159.15494309189535, 250.0]), "bumper_stiffnesses_N_per_m": np.array([1e5, 246740.11002723395])})
    assert bumper_name(given, 250.0) == "K_b = 2.467e+05 N/m (250 Hz)"
    assert "K_b" not in bumper_name(given, math.inf)
    assert bumper_name(xr.Dataset(attrs={"bumper_frequencies_Hz": np.array([250.0])}), 250.0) == "250 Hz"
