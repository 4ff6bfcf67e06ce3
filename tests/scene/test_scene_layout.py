"""The general scene format: matrices, loads on any coordinate, any stops; every mistake named by its key."""

from __future__ import annotations

import copy
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from vibroimpact.model.structure import LinearStructure
from vibroimpact.scene import SceneError, parse_scene, read_yaml
from vibroimpact.model.layout import build_stops
from vibroimpact.scene.schema import QUANTITIES

#: The paper's system (eq. 24) as matrices: K = [[k1 + k2, -k2], [-k2, k2]], C likewise.
PAPER_MATRICES = {
    "mass": [[1.0, 0.0], [0.0, 0.1]],
    "stiffness": [[29300.0, -4300.0], [-4300.0, 4300.0]],
    "damping": [[0.88, -0.08], [-0.08, 0.08]],
}


def relative_scene() -> dict[str, Any]:
    """The paper's masses with the 1928 relative stop, both sides."""
    return {
        "name": "relative",
        "system": copy.deepcopy(PAPER_MATRICES),
        "excitation": {"amplitude": 10.0, "on": "x1"},
        "stops": [
            {"between": ["x2", "x1"], "side": "upper", "clearance": 0.003, "restitution": 0.2},
            {"between": ["x2", "x1"], "side": "lower", "clearance": 0.003, "restitution": 0.2},
        ],
        "sweep": {"frequency": {"start": 20.0, "stop": 26.0, "step": 0.5}},
        "solutions": ["linear", "pgf"],
    }


def with_change(change: Callable[[dict[str, Any]], Any]) -> dict[str, Any]:
    document = relative_scene()
    change(document)
    return document


def problems_of(document: Any) -> list[str]:
    with pytest.raises(SceneError) as caught:
        parse_scene(document)
    return caught.value.problems


def test_relative_scene_parses_to_general_layout() -> None:
    """Matrices give a LinearStructure; each stop its place; values shared by every stop become the grid's."""
    scene = parse_scene(relative_scene())
    assert scene.layout.paper_view() is None
    assert isinstance(scene.layout.structure, LinearStructure)
    assert scene.coordinates == ("x1", "x2")
    assert [(s.coordinate, s.other, s.side) for s in scene.layout.stops] == [(1, 0, "upper"), (1, 0, "lower")]
    np.testing.assert_allclose(scene.settings.restitution, [0.2], rtol=0, atol=0)
    np.testing.assert_allclose(scene.settings.clearance, [0.003], rtol=0, atol=0)
    assert scene.layout.load.weights == (1.0, 0.0)
    assert scene.settings.quantities == QUANTITIES  # default names x1, x2: the paper's quantity names


def test_named_scene_is_not_general() -> None:
    """The paper's named form keeps its old meaning: one upper stop on x2, force on x1, not general."""
    document = {
        "name": "named",
        "system": {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0},
        "excitation": {"amplitude": 10.0},
        "stop": {"clearance": 0.003, "restitution": 0.2},
        "sweep": {"frequency": [20.0, 21.0]},
        "solutions": ["linear"],
    }
    scene = parse_scene(document)
    assert scene.layout.paper_view() is not None
    assert [(s.coordinate, s.other, s.side) for s in scene.layout.stops] == [(1, None, "upper")]


def test_on_is_a_key_not_a_boolean() -> None:
    """YAML 1.1 reads ``on`` as true; the scene reader keeps it a key (YAML 1.2 booleans)."""
    assert read_yaml("on: x1\nflag: yes\nother: true") == {"on": "x1", "flag": "yes", "other": True}


def test_coordinate_names_name_the_outputs() -> None:
    """Named coordinates give <name>_amplitude, <name>_rms, one_impact_<name>_amplitude."""
    scene = parse_scene(with_change(lambda d: (d["system"].update(coordinates=["body", "tmd"]), d["excitation"].update(on="body"),
                                              [s.update(between=["tmd", "body"]) for s in d["stops"]])))  # fmt: skip
    assert {"body_amplitude", "tmd_amplitude", "body_rms", "tmd_rms", "one_impact_tmd_amplitude"} <= set(scene.settings.quantities)
    assert "x1_amplitude" not in scene.settings.quantities


def test_different_stop_values_stay_with_the_stops() -> None:
    """Unswept values that differ between stops stay with each stop; the grid holds NaN (no scalar coordinate)."""
    scene = parse_scene(with_change(lambda d: (d["stops"][1].update(clearance=0.002, restitution=0.5), d.update(solutions=["linear"]))))
    assert np.isnan(scene.settings.clearance[0]) and np.isnan(scene.settings.restitution[0])
    stops = build_stops(scene.layout.stops, False, float(scene.settings.restitution[0]), float(scene.settings.clearance[0]))
    np.testing.assert_allclose([s.clearance for s in stops], [0.003, 0.002], rtol=0, atol=0)
    np.testing.assert_allclose([s.law.restitution for s in stops], [0.2, 0.5], rtol=0, atol=0)


def test_sweep_applies_to_the_named_stop_only() -> None:
    """``sweep.stop`` names the stop a swept value applies to; the other keeps its own."""

    def change(d: dict[str, Any]) -> None:
        d["stops"][0].pop("restitution")
        d["sweep"].update(restitution=[0.1, 0.9], stop=0)
        d["solutions"] = ["linear", "exact"]  # an unequal pair has no closed form

    scene = parse_scene(change_scene := with_change(change))
    assert scene.settings.sweep_stops == (0,)
    stops = build_stops(scene.layout.stops, False, 0.9, float(scene.settings.clearance[0]))
    np.testing.assert_allclose([s.law.restitution for s in stops], [0.9, 0.2], rtol=0, atol=0)
    assert change_scene["sweep"]["stop"] == 0


def test_negative_clearance_preloads() -> None:
    """A clearance may be negative (the stop preloads the structure)."""
    scene = parse_scene(with_change(lambda d: [s.update(clearance=-0.001) for s in d["stops"][:1]] and d["stops"].pop()))
    np.testing.assert_allclose(scene.settings.clearance, [-0.001], rtol=0, atol=0)


def test_three_dof_base_motion_with_static_force() -> None:
    """A 3-dof chain moved by its base, with a constant force, and a lower stop on the last mass."""
    document = {
        "name": "chain3",
        "system": {"mass": [[1.0, 0, 0], [0, 0.5, 0], [0, 0, 0.1]], "stiffness": [[2e4, -1e4, 0], [-1e4, 1.5e4, -5e3], [0, -5e3, 5e3]], "coordinates": ["a", "b", "c"]},
        "excitation": {"amplitude": 1e-4, "base_motion": True, "static": [0.0, 0.0, -0.981]},
        "stops": [{"coordinate": "c", "side": "lower", "clearance": 0.002, "restitution": 0.5}],
        "sweep": {"frequency": [10.0, 20.0]},
        "solutions": ["linear", "exact"],
    }
    scene = parse_scene(document)
    assert scene.layout.load.base_motion and scene.layout.load.static == (0.0, 0.0, -0.981)
    assert {"a_amplitude", "b_amplitude", "c_amplitude"} <= set(scene.settings.quantities)


# (case id, change, fragments that must all appear in one reported problem)
MISTAKES = [
    ("bad-shape", lambda d: d["system"].update(stiffness=[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]), ["system.stiffness:", "2 x 2"]),
    ("ragged", lambda d: d["system"].update(damping=[[0.1], [0.0, 0.1]]), ["system.damping:", "square matrix"]),
    ("asymmetric", lambda d: d["system"].update(stiffness=[[29300.0, -4300.0], [-4000.0, 4300.0]]), ["system.stiffness:", "symmetric"]),
    ("not-definite-mass", lambda d: d["system"].update(mass=[[1.0, 0.0], [0.0, 0.0]]), ["system.mass:", "positive definite"]),
    ("negative-stiffness", lambda d: d["system"].update(stiffness=[[-1.0, 0.0], [0.0, 1.0]]), ["system.stiffness:", "semi-definite"]),
    ("named-and-matrices", lambda d: d["system"].update(m1=1.0), ["system:", "not both", "m1"]),
    ("unknown-system-key", lambda d: d["system"].update(inertia=1.0), ["system.inertia: unknown key", "mass, stiffness"]),
    ("coordinates-count", lambda d: d["system"].update(coordinates=["a"]), ["system.coordinates:", "2 names"]),
    ("coordinate-clash", lambda d: d["system"].update(coordinates=["force", "x2"]), ["system.coordinates:", "force_amplitude"]),
    ("unknown-on", lambda d: d["excitation"].update(on="x3"), ["excitation.on: 'x3' is not a coordinate", "allowed x1, x2"]),
    ("weights-length", lambda d: d["excitation"].update(on=[1.0, 0.0, 0.0]), ["excitation.on: expected 2 values"]),
    ("static-length", lambda d: d["excitation"].update(static=[0.0]), ["excitation.static: expected 2 values", "x1, x2"]),
    ("static-not-numbers", lambda d: d["excitation"].update(static=["g", 0.0]), ["excitation.static: expected a list of finite numbers"]),
    ("base-motion-and-on", lambda d: d["excitation"].update(base_motion=True), ["excitation.on:", "base motion"]),
    ("unknown-between", lambda d: d["stops"][0].update(between=["x2", "x9"]), ["stops[0].between[1]: 'x9' is not a coordinate", "allowed x1, x2"]),
    ("unknown-coordinate", lambda d: d["stops"][1].update(coordinate="x7") or d["stops"][1].pop("between"), ["stops[1].coordinate: 'x7' is not a coordinate"]),
    ("both-places", lambda d: d["stops"][0].update(coordinate="x2"), ["stops[0]:", "exactly one of 'coordinate"]),
    ("bad-side", lambda d: d["stops"][0].update(side="left"), ["stops[0].side: 'left' is not allowed", "upper", "lower"]),
    ("same-pair", lambda d: d["stops"][0].update(between=["x1", "x1"]), ["stops[0].between:", "must differ"]),
    ("restitution-range", lambda d: d["stops"][0].update(restitution=1.5), ["stops[0].restitution: 1.5 is out of range: allowed [0, 1]"]),
    ("clearance-missing", lambda d: [s.pop("clearance") for s in d["stops"]], ["stops[0].clearance: required unless swept"]),
    ("swept-and-given", lambda d: d["sweep"].update(clearance=[0.002, 0.003]), ["stops[0].clearance: also swept in sweep.clearance"]),
    ("sweep-stop-range", lambda d: d["sweep"].update(stop=5, restitution=[0.1, 0.2]), ["sweep.stop: 5 is out of range: allowed [0, 1]"]),
    ("duplicate-stop", lambda d: d["stops"][1].update(side="upper"), ["stops[1]:", "same coordinates and side"]),
    ("stop-and-stops", lambda d: d.update(stop={"clearance": 0.003}), ["stop:", "not both"]),
    ("pgf-paper", lambda d: d.update(solutions=["pgf_paper"]), ["solutions:", "pgf_paper", "use pgf"]),
    ("design-map-moved", lambda d: d.update(report="design_map"), ["report: the design map is the design kind's grid search", "method: grid"]),
    ("pgf-unequal-pair", lambda d: d["stops"][1].update(clearance=0.002), ["solutions: pgf does not apply", "symmetric"]),
    ("swept-base-motion", lambda d: d.update(swept_sine={"start": 20.0, "stop": 26.0, "rate": 0.5}, solutions=["compliant"], bumper={"frequency": 250.0}, excitation={"amplitude": 0.001, "base_motion": True}), ["excitation.base_motion:", "swept base motion is not supported"]),
    ("compliant-no-bumper", lambda d: d.update(solutions=["compliant"]), ["stops[0].bumper.frequency: required unless swept"]),
]


@pytest.mark.parametrize(("change", "fragments"), [case[1:] for case in MISTAKES], ids=[case[0] for case in MISTAKES])
def test_each_general_mistake_names_its_key(change: Callable[[dict[str, Any]], Any], fragments: list[str]) -> None:
    """One SceneError, one problem holding every fragment (the key and the allowed values)."""
    problems = problems_of(with_change(change))
    assert any(all(fragment in problem for fragment in fragments) for problem in problems), problems


def test_free_mass_refuses_pgf_with_the_reason() -> None:
    """A structure with a rigid-body mode has no periodic Green function: pgf is refused, saying why."""

    def change(d: dict[str, Any]) -> None:
        d["system"] = {"mass": [[1.0]], "stiffness": [[0.0]]}
        d["excitation"] = {"amplitude": 1.0, "on": "x1"}
        d["stops"] = [{"coordinate": "x1", "side": "lower", "clearance": 0.0, "restitution": 0.5}]

    problems = problems_of(with_change(change))
    assert any("pgf does not apply" in p and "rigid-body" in p for p in problems), problems


def test_gravity_on_a_free_mass_refuses_linear() -> None:
    """A static force along a rigid-body mode has no steady state without the stops: linear is refused."""

    def change(d: dict[str, Any]) -> None:
        d["system"] = {"mass": [[1.0]], "stiffness": [[0.0]]}
        d["excitation"] = {"amplitude": 1.0, "on": "x1", "static": [-9.81]}
        d["stops"] = [{"coordinate": "x1", "side": "lower", "clearance": 0.0, "restitution": 0.5}]
        d["solutions"] = ["linear", "exact"]

    problems = problems_of(with_change(change))
    assert any(p.startswith("solutions: linear does not apply") for p in problems), problems


def test_a_bumper_instead_of_a_restitution() -> None:
    """A stop with its own bumper (and loss factor) needs no restitution: R is the bumper's one-collision R(xi_b);
    the compliant solution builds the stop's own bumper."""
    from vibroimpact.model.contact import KelvinVoigtBumper, restitution_from_loss_factor

    def change(d: dict[str, Any]) -> None:
        d["stops"] = [{"between": ["x2", "x1"], "side": "upper", "clearance": 0.003, "bumper": {"frequency": 300.0, "loss_factor": 0.3}}]
        d["solutions"] = ["linear", "pgf", "compliant"]

    scene = parse_scene(with_change(change))
    np.testing.assert_allclose(scene.settings.restitution, [restitution_from_loss_factor(0.3)], rtol=1e-15)
    (stop,) = build_stops(scene.layout.stops, True, float(scene.settings.restitution[0]), float(scene.settings.clearance[0]), float(scene.settings.bumper_frequency[0]))
    assert isinstance(stop.law, KelvinVoigtBumper)
    np.testing.assert_allclose([stop.law.frequency, stop.law.loss_factor, stop.clearance], [300.0, 0.3, 0.003], rtol=1e-15)


def test_opposite_stops_without_room_are_refused_before_any_work() -> None:
    text = """
name: infeasible
description: x
system: {mass: [[1.0]], stiffness: [[1000.0]], damping: [[0.1]]}
excitation: {amplitude: 1.0, on: x1}
stops:
  - {coordinate: x1, side: upper, clearance: -0.002, restitution: 0.5}
  - {coordinate: x1, side: lower, clearance: 0.001, restitution: 0.5}
sweep:
  frequency: {start: 2.0, stop: 8.0, step: 1.0}
solutions: [linear, exact]
simulation:
  frequency: {start: 2.0, stop: 8.0, step: 1.0}
"""
    with pytest.raises(SceneError, match=r"stops: stop 0 \(x1 <= -2 mm\) and stop 1 \(x1 >= -1 mm\) leave no room") as caught:
        parse_scene(read_yaml(text), text)
    assert len(caught.value.problems) == 1, caught.value.problems


def test_a_swept_clearance_without_room_at_one_corner_is_refused_there() -> None:
    """The upper stop takes the swept Delta, the lower one gives -2 mm: at Delta = 1 mm the relative coordinate has no
    room (1 - 2 <= 0), at 3 mm it has; the layout says so from its geometry, naming the grid's clearance, and pgf is
    refused for the same reason."""

    def change(d: dict[str, Any]) -> None:
        d["stops"][0].pop("clearance")
        d["stops"][1]["clearance"] = -0.002
        d["sweep"].update(clearance=[0.001, 0.003], stop=0)

    problems = problems_of(with_change(change))
    room = "stop 0 (x2 - x1 <= 1 mm) and stop 1 (x2 - x1 >= 2 mm) leave no room between them: two opposite stops need clearances whose sum is > 0"
    assert f"stops: {room} (at clearance 0.001 m of the grid)" in problems, problems
    assert f"solutions: pgf does not apply to this layout: stops: {room}" in problems, problems


#: (id, change of the relative scene, whether pgf applies): the layout's refusal at the grid's corners.
PGF_LAYOUTS = [
    ("symmetric", lambda d: None, True),
    ("swept-both", lambda d: [s.pop(k) for s in d["stops"] for k in ("clearance", "restitution")] and d["sweep"].update(clearance=[0.002, 0.004], restitution=[0.1, 0.9]), True),
    ("swept-one-side", lambda d: d["stops"][0].pop("clearance") and d["sweep"].update(clearance=[0.002, 0.003], stop=0), False),
    ("one-stop", lambda d: d["stops"].pop(), True),
    ("written-reversed", lambda d: d["stops"][1].update(between=["x1", "x2"], side="upper"), True),  # x1 - x2 <= Delta: the lower side
    ("other-coordinate", lambda d: d["stops"][1].pop("between") and d["stops"][1].update(coordinate="x1"), False),
    ("static-on-pair", lambda d: d["excitation"].update(static=[0.0, -0.981]), False),
]


@pytest.mark.parametrize(("change", "applies"), [case[1:] for case in PGF_LAYOUTS], ids=[case[0] for case in PGF_LAYOUTS])
def test_pgf_refusal_is_a_problem_s_at_every_corner_of_the_grid(change: Callable[[dict[str, Any]], Any], applies: bool) -> None:
    """pgf_refusal asks the layout (no problem built): its answer is that of the problems the study builds at the
    corners of its R and Delta grids, the first refusal in the corners' order."""
    from vibroimpact.analysis.layout import closed_form_refusal
    from vibroimpact.scene.layout_parse import pgf_refusal

    document = with_change(change)
    document["solutions"] = ["linear"]
    scene = parse_scene(document)
    r_grid, d_grid = scene.settings.restitution, scene.settings.clearance
    corners = sorted({(float(r), float(d)) for r in (r_grid[0], r_grid[-1]) for d in (d_grid[0], d_grid[-1])})
    reasons = [closed_form_refusal(scene.layout.problem(10.0, f, r, d)) for r, d in corners for f in (20.0, 26.0)]
    expected = next((reason for reason in reasons if reason is not None), None)
    assert pgf_refusal(scene.layout, r_grid, d_grid) == expected
    assert (expected is None) is applies, expected
