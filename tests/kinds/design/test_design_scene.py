"""Design scenes (issue 32): what the ``design`` section says, and every mistake refused before any work, each naming
its key and the allowed range."""

from __future__ import annotations

import copy
import math

import pytest

from vibroimpact.kinds.design.scene import DesignSettings
from vibroimpact.scene.checker import SceneError
from vibroimpact.scene.reader import parse_scene

SCENE = {
    "name": "d",
    "system": {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0, "b1": 0.8, "b2": 0.08},
    "excitation": {"amplitude": 10.0},
    "stop": {"clearance": 0.003, "restitution": 0.2},
    "design": {
        "variables": {"clearance": [0.0005, 0.008], "restitution": [0.0, 0.9], "k2": [1000.0, 8000.0], "b2": [0.0, 20.0]},
        "band": {"start": 15.0, "stop": 45.0},
        "constraints": {"operating": {"frequency": 33.0, "x1_amplitude": 5e-5}},
        "robust": {"k1": 0.05, "clearance": 0.0002, "samples": 32, "seed": 3},
        "compare": "linear_optimum",
    },
}


def scene_with(**design) -> dict:
    document = copy.deepcopy(SCENE)
    document["design"].update(design)
    return document


def test_a_design_scene_reads_its_section() -> None:
    scene = parse_scene(copy.deepcopy(SCENE))
    settings: DesignSettings = scene.settings
    assert scene.kind == "design"
    assert settings.names == ("clearance", "restitution", "k2", "b2")
    assert [v.unit for v in settings.variables] == ["m", "1", "N m-1", "N s m-1"]
    assert settings.operating == (33.0, 5e-5) and settings.samples == 32 and settings.seed == 3
    assert [(m.name, m.relative) for m in settings.mistuning] == [("k1", True), ("clearance", False)]
    assert settings.clearance == 0.003 and settings.restitution == 0.2  # exact: the scene's own numbers
    assert settings.compare == "linear_optimum" and settings.search.method == "differential_evolution"


def test_any_row_of_the_parameter_table_is_a_design_variable() -> None:
    """A layout scalar the grammar names needs no code of the design kind: its unit and range are the parameter
    table's. A coupling entry of the stiffness matrix is negative (-k2 here), so its bounds may be; the design space
    sets it on the problem as the continuation's map does."""
    from vibroimpact.kinds.design.study import design_space
    from vibroimpact.model.parameters import layout_parameter

    scene = parse_scene(scene_with(variables={"stiffness[x1,x2]": [-5000.0, -3000.0], "mass[x2]": [0.05, 0.2]}, robust={}, compare="none"))
    settings: DesignSettings = scene.settings
    assert [(v.name, v.unit, v.low) for v in settings.variables] == [("stiffness[x1,x2]", "N m-1", -5000.0), ("mass[x2]", "kg", 0.05)]
    space = design_space(scene)
    problem = space.problem_at((-4000.0, 0.12))
    assert layout_parameter("stiffness[x1,x2]", problem).value(problem, (0,)) == pytest.approx(-4000.0, rel=1e-15)
    assert problem.structure.mass_matrix[1, 1] == pytest.approx(0.12, rel=1e-15)
    with pytest.raises(SceneError) as caught:  # a mass keeps its positive range
        parse_scene(scene_with(variables={"mass[x2]": [-0.1, 0.2]}))
    assert any(line.startswith("design.variables.mass[x2][0]:") and "(0, inf)" in line for line in caught.value.problems), caught.value.problems


def test_the_objective_and_the_constraint_are_rows_of_the_measure_table() -> None:
    """The objective may be |X| of any coordinate or the force to the base, and the operating constraint limits its
    own measure (|X1| by default, the primary's notch), whatever the objective."""
    force = parse_scene(scene_with(objective="force_amplitude", constraints={"operating": {"frequency": 33.0, "x1_amplitude": 5e-5}})).settings
    assert (force.measure.name, force.measure.unit, force.measure.coordinate, force.objective) == ("force_amplitude", "N", None, "force_amplitude")
    assert force.constraint is not None and (force.constraint.name, force.constraint.coordinate) == ("x1_amplitude", 0)
    absorber = parse_scene(scene_with(objective="x2_amplitude", compare="none", constraints={"operating": {"frequency": 33.0, "force_amplitude": 2.0}})).settings
    assert (absorber.measure.coordinate, absorber.measure.unit) == (1, "m")
    assert absorber.constraint is not None and (absorber.constraint.name, absorber.constraint.unit) == ("force_amplitude", "N")
    assert absorber.operating == (33.0, 2.0)  # exact: the scene's own numbers


def test_the_base_force_of_a_base_motion_is_refused() -> None:
    document = scene_with(objective="force_amplitude")
    document["excitation"] = {"amplitude": 1e-3, "base_motion": True}
    with pytest.raises(SceneError) as caught:
        parse_scene(document)
    assert any(line.startswith("design.objective:") and "base-motion" in line for line in caught.value.problems), caught.value.problems


@pytest.mark.parametrize(
    ("design", "key", "words"),
    [
        ({"variables": {"k9": [1.0, 2.0]}}, "design.variables.k9", "unknown design variable"),
        ({"variables": {"mass[x7]": [1.0, 2.0]}}, "design.variables.mass[x7]", "x7"),
        ({"variables": {"clearance": [0.004, 0.002]}}, "design.variables.clearance", "below"),
        ({"variables": {"restitution": [0.0, 1.5]}}, "design.variables.restitution[1]", "allowed"),
        ({"band": {"start": 45.0, "stop": 15.0}}, "design.band.stop", "greater"),
        ({"objective": "x3_amplitude"}, "design.objective", "x1_amplitude, x2_amplitude, force_amplitude"),
        ({"robust": {"k1": 0.05}}, "design.robust.samples", "required"),
        ({"robust": {"k1": 0.9, "samples": 4}}, "design.robust.k1", "allowed"),
        ({"compare": "den_hartog"}, "design.compare", "linear_optimum"),
        ({"search": {"method": "annealing"}}, "design.search.method", "differential_evolution"),
        ({"search": {"population": 1}}, "design.search.population", "allowed"),
        ({"certify": {"candidates": -1}}, "design.certify.candidates", "allowed"),
        ({"constraints": {"operating": {"frequency": 33.0}}}, "design.constraints.operating", "largest amplitude"),
        ({"constraints": {"impact_force": 150.0}}, "design.constraints.impact_force", "unknown key"),
    ],
)
def test_mistakes_are_refused_naming_their_key(design: dict, key: str, words: str) -> None:
    with pytest.raises(SceneError) as caught:
        parse_scene(scene_with(**design))
    assert any(line.startswith(f"{key}:") and words in line for line in caught.value.problems), caught.value.problems


def test_the_stop_must_give_the_scene_s_design() -> None:
    document = copy.deepcopy(SCENE)
    document["stop"] = {"clearance": 0.003}
    with pytest.raises(SceneError) as caught:
        parse_scene(document)
    assert any(line.startswith("stop.restitution:") for line in caught.value.problems)


def test_the_linear_optimum_needs_the_paper_s_two_masses() -> None:
    document = copy.deepcopy(SCENE)
    document["system"] = {"mass": [[1.0, 0.0], [0.0, 0.1]], "stiffness": [[29300, -4300], [-4300, 4300]], "damping": [[0.88, -0.08], [-0.08, 0.08]], "coordinates": ["a", "b"]}
    document["excitation"] = {"amplitude": 10.0, "on": "a"}
    document.pop("stop")
    document["stops"] = [{"coordinate": "b", "side": "upper", "clearance": 0.003, "restitution": 0.2}]
    document["design"]["variables"] = {"clearance": [0.001, 0.005]}
    document["design"].pop("constraints")
    document["design"]["robust"] = {}
    with pytest.raises(SceneError) as caught:
        parse_scene(document)
    assert any(line.startswith("design.compare:") and "paper's two masses" in line for line in caught.value.problems), caught.value.problems


def bumper_scene(bumper: object, variables: dict | None = None, restitution: float = 0.2) -> dict:
    """The scene on a Kelvin-Voigt bumper (``stop.bumper``), its variables ``variables`` (default: the three of
    ``design_paper``)."""
    document = copy.deepcopy(SCENE)
    document["stop"] = {"clearance": 0.003, "restitution": restitution, "bumper": bumper}
    document["design"]["variables"] = variables or {"clearance": [0.0005, 0.008], "restitution": [0.05, 0.9], "bumper_stiffness": [4e4, 4e6]}
    return document


def test_a_bumper_design_reads_its_stiffness_in_either_form() -> None:
    """A bumper given by frequency or by stiffness on m2 = 0.1 kg (K_b = m2 (2 pi 250)^2 = 246 740 N/m): the same
    250 Hz; ``bumper_stiffness`` is a variable in N/m, and the scene's design problem has a bumper of that frequency
    whose loss factor gives the restitution."""
    from vibroimpact.kinds.design.study import design_space
    from vibroimpact.model.contact import KelvinVoigtBumper

    for bumper in ({"frequency": 250.0}, {"stiffness": 0.1 * (2.0 * math.pi * 250.0) ** 2}):
        scene = parse_scene(bumper_scene(bumper))
        settings: DesignSettings = scene.settings
        assert settings.bumper_frequency == pytest.approx(250.0, rel=1e-12)
        assert [v.unit for v in settings.variables] == ["m", "1", "N m-1"]
        law = design_space(scene).problem.stops[0].law
        assert isinstance(law, KelvinVoigtBumper) and law.frequency == pytest.approx(250.0, rel=1e-12) and law.restitution == pytest.approx(0.2, rel=1e-9)


@pytest.mark.parametrize(
    ("document", "key", "words"),
    [
        (bumper_scene({"frequency": 250.0}, {"restitution": [0.0, 0.9]}), "design.variables.restitution[0]", "allowed"),
        (bumper_scene({"frequency": 250.0}, restitution=0.0), "stop.restitution", "infinite loss factor"),
        (bumper_scene({"frequency": 250.0, "loss_factor": 0.3}), "stop.bumper", "takes its loss from the restitution"),
        (scene_with(variables={"bumper_stiffness": [4e4, 4e6]}), "design.variables.bumper_stiffness", "the stops are rigid"),
        (bumper_scene({"frequency": 250.0}, {"bumper_stiffness": [0.0, 4e6]}), "design.variables.bumper_stiffness[0]", "allowed"),
    ],
)
def test_bumper_mistakes_are_refused_naming_their_key(document: dict, key: str, words: str) -> None:
    with pytest.raises(SceneError) as caught:
        parse_scene(document)
    assert any(line.startswith(f"{key}:") and words in line for line in caught.value.problems), caught.value.problems


def test_the_bumper_stiffness_variable_sets_the_bumper_of_every_problem() -> None:
    """A design's K_b = 1e6 N/m on m2 = 0.1 kg: every sample's problem has Omega_b / 2 pi = sqrt(K_b / m2) / 2 pi
    (503.3 Hz), and its loss factor still gives the design's R."""
    from vibroimpact.kinds.design.study import design_space

    space = design_space(parse_scene(bumper_scene({"frequency": 250.0})))
    for sample in range(space.samples):
        law = space.problem_at((0.002, 0.4, 1e6), sample).stops[0].law
        assert law.frequency == pytest.approx(math.sqrt(1e6 / 0.1) / (2.0 * math.pi), rel=1e-12)
    assert space.problem_at((0.002, 0.4, 1e6), 0).stops[0].law.restitution == pytest.approx(0.4, rel=1e-9)


def test_a_general_layout_s_bumpers_give_no_loss_of_their_own() -> None:
    """``stops:`` with bumpers: a frequency alone is read; a damping (or loss factor) of its own is refused, and so
    is R = 0."""
    document = copy.deepcopy(SCENE)
    del document["stop"]
    document["design"]["variables"] = {"clearance": [0.0005, 0.008], "bumper_stiffness": [4e4, 4e6]}
    stop = {"coordinate": "x2", "clearance": 0.003, "restitution": 0.2, "bumper": {"frequency": 250.0}}
    document["stops"] = [stop]
    assert parse_scene(copy.deepcopy(document)).settings.bumper_frequency == pytest.approx(250.0, rel=1e-12)
    for bumper, restitution in (({"stiffness": 2.5e5, "damping": 10.0}, 0.2), ({"frequency": 250.0}, 0.0)):
        document["stops"] = [stop | {"bumper": bumper, "restitution": restitution}]
        with pytest.raises(SceneError) as caught:
            parse_scene(copy.deepcopy(document))
        assert any(line.startswith("stops:") for line in caught.value.problems), caught.value.problems


def test_an_x2_objective_with_the_limit_on_x1_judges_the_limit_on_x1() -> None:
    """Issue 50: ``objective: x2_amplitude`` with the operating limit written on ``x1_amplitude`` evaluated the limit
    on x2 (2.323 mm against a 0.05 mm limit, every |X2| labelled |X1|). The design space the study searches judges the
    objective on x2 and the limit on x1, each its own row of the measure table."""
    from vibroimpact.kinds.design.study import design_space

    scene = parse_scene(scene_with(objective="x2_amplitude", compare="none"))  # the limit: x1_amplitude 5e-5 m at 33 Hz
    space = design_space(scene)
    assert not isinstance(space.objective, int) and (space.objective.name, space.objective.coordinate) == ("x2_amplitude", 1)
    assert not isinstance(space.constraint, int) and (space.constraint.name, space.constraint.coordinate, space.constraint.unit) == ("x1_amplitude", 0, "m")
    assert scene.settings.operating == (33.0, 5e-5)  # exact: the scene's own numbers
