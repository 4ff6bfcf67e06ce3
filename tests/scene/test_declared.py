"""Declared scene keys (issue 50, :mod:`vibroimpact.scene.declared`): every declared key walked into the settings
the kind reads, every wrong type generated from the declaration and refused in one run naming each key (exit 2,
nothing written), a key one method never reads refused with the other, "did you mean" for a misspelt key, and the
Python settings refusing what the scene refuses."""

from __future__ import annotations

import copy
import math
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
import yaml

from vibroimpact.kinds.benchmark.scene import BENCHMARK, CASE_ROW, CASE_SWEEP, LADDER
from vibroimpact.kinds.bifurcation.scene import BIFURCATION_STOP, BIFURCATION, BRUTE_FORCE, CHART, CONTINUATION, BranchSettings, BruteForceSettings, ChartSettings
from vibroimpact.kinds.concepts.scene import CONCEPT_ABSORBER, CONCEPT_ROW, CONCEPTS_BUMPER, CONCEPTS_TOP, CONTINUATION as CONCEPTS_CONTINUATION
from vibroimpact.kinds.validation.settings import CASE_SECTIONS
from vibroimpact.kinds.design.scene import DESIGN_STOP, CERTIFY, CONSTRAINTS, DESIGN, OPERATING, ROBUST, SEARCH, SearchSettings
from vibroimpact.scene.checker import Checker, SceneError
from vibroimpact.scene.declared import DERIVED, OPTIONAL, REQUIRED, Band, Free, Grid, Key, Names, Rows, Section, Table
from vibroimpact.scene.grid import ADMISSIBILITY, GRID_SETTINGS, GRID_STOP, GRID_TOP, SWEEP, SWEPT_SINE
from vibroimpact.scene.bumper_parse import BUMPER
from vibroimpact.scene.header import CLUSTER, HEADER, declared_sections
from vibroimpact.scene.layout_parse import EXCITATION, MATRIX_SYSTEM, NAMED_SYSTEM, STOP_ROW
from vibroimpact.scene.simulation import SIMULATION
from vibroimpact.scene.reader import parse_scene, read_yaml

from tests.kinds.design.test_design_scene import SCENE

STUDIES = Path(__file__).resolve().parents[2] / "studies"


def _shipped(name: str) -> dict:
    return read_yaml((STUDIES / name).read_text(encoding="utf-8"))


def _id(section: Section) -> str:
    """A declared section's entry in :data:`PLACES`: its path, and its form where the path has more than one."""
    return f"{section.path}#{section.form}" if section.form else section.path


def _own_section(section: Section, key: Key) -> bool:
    """Whether ``key`` of ``section`` is a declared section of its own (a mapping, or a list of rows), walked as such."""
    paths = {place.partition("#")[0] for place in PLACES}  # a section of several forms: any of them
    return section.where(key.name) in paths or f"{section.where(key.name)}[k]" in paths


def _where(section: Section, name: str) -> str:
    """Where a problem of the key ``name`` is said: a stop row's in the walk's first stop."""
    return section.where(name).replace("[k]", "[0]")


def _swept_scene(stop: dict | None = None, sweep: dict | None = None) -> dict:
    """The paper's closed forms over a frequency grid, the stop's values fixed in ``stop`` or swept in ``sweep``."""
    document = {key: value for key, value in _analytic("restitution.yaml").items() if key != "stop"}
    return document | {"sweep": (sweep or {}) | {"frequency": {"start": 20.0, "stop": 30.0, "step": 0.5}}} | ({"stop": stop} if stop else {})


def _analytic(name: str) -> dict:
    """A shipped stepped scene with its closed forms alone (no simulation, no paper-only route), renamed."""
    document = {key: value for key, value in _shipped(name).items() if key != "simulation"}
    return document | {"name": f"{document['name']}_analytic", "solutions": ["linear", "pgf"]}


def _put(document: dict, path: str, values: dict[str, Any]) -> dict:
    """``document`` with the section at the dotted ``path`` set to ``values`` (``stops[k]``: the first stop)."""
    if not path:  # the top level: the shared header
        document.update(values)
        return document
    if path == CASE_ROW.path:  # the only case: the others' names and starts are not the walk's
        document["benchmark"]["cases"] = [values]
        return document
    *parents, leaf = path.split(".")
    place = document
    for parent in parents:  # a list of rows (concepts[k]): its first row
        place = place[parent[:-3]][0] if parent.endswith("[k]") else place.setdefault(parent, {})
    if leaf.endswith("[k]"):
        place[leaf[:-3]][0] = values
    else:
        place[leaf] = values
    return document


#: The swept-sine settings' names of its scene keys where they differ.
SWEPT_FIELDS = {"start": "start_frequency", "stop": "stop_frequency"}
#: Each declared section: a scene of its kind, and where each of its values lands in the kind's settings.
PLACES = {
    HEADER.path: (lambda: copy.deepcopy(SCENE), lambda scene, name: _header_value(scene, name)),
    _id(NAMED_SYSTEM): (lambda: _shipped("restitution.yaml"), lambda scene, name: getattr(scene.layout.paper_view(), name)),
    _id(MATRIX_SYSTEM): (lambda: _shipped("relative_stop.yaml"), None),  # every key a matrix or names: the structure's own checks
    EXCITATION.path: (lambda: _analytic("restitution.yaml"), lambda scene, name: scene.amplitude if name == "amplitude" else scene.layout.load.base_motion),
    STOP_ROW.path: (lambda: _shipped("relative_stop.yaml") | {"stops": [{"between": ["x2", "x1"], "clearance": 0.003, "restitution": 0.2}]}, None),
    BUMPER.path: (lambda: _shipped("bumper_sweep.yaml"), None),
    **{_id(section): (lambda name=name: _shipped(f"validation/{name}.yaml"), lambda scene, key: getattr(scene.settings.case, key)) for name, section in CASE_SECTIONS.items()},
    CLUSTER.path: (lambda: copy.deepcopy(SCENE) | {"cluster": {"scheduler": "tcp://head:8786"}}, lambda scene, name: scene.cluster_scheduler),
    DESIGN.path: (lambda: copy.deepcopy(SCENE), lambda scene, name: _design_value(scene.settings, name)),
    CONSTRAINTS.path: (lambda: copy.deepcopy(SCENE), lambda scene, name: scene.settings.operating),
    OPERATING.path: (lambda: copy.deepcopy(SCENE), lambda scene, name: scene.settings.operating[0]),
    ROBUST.path: (lambda: copy.deepcopy(SCENE), lambda scene, name: getattr(scene.settings, name)),
    SEARCH.path: (lambda: copy.deepcopy(SCENE), lambda scene, name: getattr(scene.settings.search, name)),
    CERTIFY.path: (lambda: copy.deepcopy(SCENE), lambda scene, name: scene.settings.certified),
    BIFURCATION.path: (lambda: _shipped("bifurcation.yaml"), lambda scene, name: _bifurcation_value(scene.settings, name)),
    BRUTE_FORCE.path: (lambda: _shipped("bifurcation.yaml"), lambda scene, name: getattr(scene.settings.brute_force, name)),
    CONTINUATION.path: (lambda: _shipped("bifurcation.yaml"), lambda scene, name: getattr(scene.settings.branches, name)),
    CHART.path: (lambda: _shipped("bifurcation.yaml"), lambda scene, name: getattr(scene.settings.chart, name)),
    CONCEPTS_CONTINUATION.path: (lambda: _shipped("absorber_concepts.yaml"),
                                 lambda scene, name: scene.settings.continuation_steps if name == "max_steps" else scene.settings.continuation_steps > 0),
    SWEPT_SINE.path: (lambda: _shipped("bumper_sweep.yaml"), lambda scene, name: getattr(scene.settings.swept_sine, SWEPT_FIELDS.get(name, name))),
    ADMISSIBILITY.path: (lambda: _shipped("restitution.yaml"), lambda scene, name: getattr(scene.settings.admissibility, name)),
    SIMULATION.path: (lambda: _shipped("restitution.yaml"), lambda scene, name: _simulation_value(scene.settings.simulation, name)),
    _id(DESIGN_STOP): (lambda: _put(copy.deepcopy(SCENE), "design.variables", {"clearance": [0.5e-3, 8e-3], "restitution": [0.05, 0.9]}), lambda scene, name: {"frequency": scene.settings.bumper_frequency} if name == "bumper" else getattr(scene.settings, name)),
    _id(BIFURCATION_STOP): (lambda: _shipped("bifurcation.yaml"), lambda scene, name: scene.settings.clearance),
    _id(CONCEPTS_TOP): (lambda: _shipped("absorber_concepts.yaml"), lambda scene, name: getattr(scene.settings, name) if name == "frequency" else [concept.name for concept in scene.settings.concepts]),
    _id(CONCEPTS_BUMPER): (lambda: _shipped("absorber_concepts.yaml"), lambda scene, name: scene.settings.bumper_frequency),
    CONCEPT_ROW.path: (lambda: _shipped("absorber_concepts.yaml"), lambda scene, name: _concept_value(scene.settings.concepts[0], name)),
    CONCEPT_ABSORBER.path: (lambda: _shipped("absorber_concepts.yaml"), None),  # each key a number or den_hartog: its parser's
    _id(GRID_TOP): (lambda: _analytic("restitution.yaml"), lambda scene, name: getattr(scene.settings, name)),
    SWEEP.path: (lambda: _swept_scene(sweep={"restitution": [0.0, 0.5], "clearance": [0.002, 0.003]}), lambda scene, name: getattr(scene.settings, name)),
    _id(GRID_STOP): (lambda: _swept_scene(stop={"clearance": 0.003, "restitution": 0.2}), lambda scene, name: float(getattr(scene.settings, name)[0])),
    GRID_SETTINGS.path: (lambda: _shipped("restitution.yaml"), None),
    BENCHMARK.path: (lambda: _shipped("engine_cost.yaml"), lambda scene, name: _benchmark_value(scene.settings, name)),
    CASE_ROW.path: (lambda: _shipped("engine_cost.yaml"), None),
    CASE_SWEEP.path: (lambda: _put(_shipped("engine_cost.yaml"), CASE_ROW.path, dict(SWEPT_CASE)), None),
    LADDER.path: (lambda: _put(_shipped("engine_cost.yaml"), "benchmark.ladder", dict(LADDER_POINT)), lambda scene, name: getattr(scene.settings.settings.ladder, name)),
}  # fmt: skip
#: A swept benchmark case (the walk's base for its sweep).
SWEPT_CASE = {"name": "swept", "restitution": 0.2, "clearance": 0.003, "bumper_frequency": 1000.0, "swept_sine": {"start": 20.0, "stop": 30.0, "rate": 10.0}}
#: A ladder on the paper's stop, which gives neither restitution nor clearance (both then needed).
LADDER_POINT = {"frequency": 25.0, "restitution": 0.2, "clearance": 0.003, "bumper_frequencies": [1000.0, 5000.0]}
#: Keys the kind derives but the walk's scene needs given (the paper's stop takes them from the ladder).
NEEDED = {"sweep.restitution", "sweep.clearance", "stop.clearance", "stop.restitution", "benchmark.cases[k].start", "benchmark.cases[k].frequency", "benchmark.cases[k].restitution", "benchmark.cases[k].clearance", "benchmark.ladder.restitution", "benchmark.ladder.clearance", "design.robust.samples", "bifurcation.restitution", "stops[k].between",
          "stops[k].clearance", "stops[k].restitution"}  # with a spread; the paper's stop
#: Keys that choose which form of their section is read (walked as each form).
FORM_KEYS = {"validation.case"}
#: A valid value, for the walk, of a key whose other values the declaration cannot tell (a name the layout makes).
OTHER_VALUES = {"frequency": [20.0, 30.0], "sweep.frequency": [20.0, 25.0], "design.objective": "force_amplitude", "validation.forcing_frequency": 2.75}  # the last: |1 / (1 - w^2)| stays above sigma's 0.14
#: Keys the walk gives beside a key that is read only with them (a reference needs bumpers).
CONTEXT = {"sweep.bumper_loss_factor": {"restitution": None}, "benchmark.cases[k].clearance_below_linear": {"clearance": None}, "benchmark.cases[k].swept_sine": {"frequency": None, "start": None},
           "bifurcation.reference": {"bumper": {"frequency": [100.0]}}, "bumper.loss_factor": {"frequency": 250.0}, "bumper.damping": {"stiffness": 2.5e5}}
#: A valid value, for the walk, of each key whose default the kind derives.
DERIVED_VALUES = {"concepts[k].stops": [{"coordinate": "x2", "side": "upper", "clearance": 0.003, "restitution": 0.2}], "stop.bumper": {"frequency": 300.0}, "concepts[k].label": "another label", "sweep.bumper_frequency": [100.0, 200.0], "sweep.bumper_loss_factor": [0.1, 0.2], "benchmark.cases[k].clearance_below_linear": 1e-5, "benchmark.cases[k].bumper_frequency": 500.0,
                  "benchmark.cases[k].swept_sine": {"start": 20.0, "stop": 30.0, "rate": 10.0}, "cluster": {"scheduler": "tcp://head:8786"}, "bumper.frequency": 300.0, "bumper.loss_factor": 0.1, "bumper.stiffness": 2.5e5,
                  "bumper.damping": 10.0, "stops[k].bumper": {"frequency": 300.0}, "bifurcation.restitution": [0.5], "bifurcation.bumper": {"frequency": [100.0]},
                  "bifurcation.brute_force": {}, "bifurcation.continuation": {}, "bifurcation.chart": {}, "simulation.frequency": [20.0, 30.0], "simulation.rtol": 1e-6, "simulation.atol": 1e-9, "simulation.subset": {"momentary": {"frequency": [25.0]}},
                  "benchmark.ladder": LADDER_POINT, "benchmark.ladder.restitution": 0.5, "benchmark.ladder.clearance": 0.002}


def _concept_value(concept: Any, name: str) -> Any:
    """Where a concept row's key ``name`` lands in its :class:`~vibroimpact.kinds.concepts.scene.Concept` (stops as
    the scene writes them)."""
    if name == "stops":
        return [{"coordinate": concept.system.coordinates[stop.coordinate], "side": stop.side, "clearance": stop.law.clearance, "restitution": stop.law.restitution} for stop in concept.stops]
    return getattr(concept, name)


def _design_value(settings: Any, name: str) -> Any:
    """Where the ``design`` section's key ``name`` lands in the design settings (the variables as the scene writes them)."""
    if name == "variables":
        return {variable.name: [variable.low, variable.high] for variable in settings.variables}
    return getattr(settings, name)


def _bifurcation_value(settings: Any, name: str) -> Any:
    """Where the ``bifurcation`` section's key ``name`` lands in the bifurcation settings."""
    if name == "frequency":
        return (settings.low, settings.high)
    if name == "bumper":
        return {"frequency": list(settings.bumper_frequencies)}
    return getattr(settings, name)


def _header_value(scene: Any, name: str) -> Any:
    """Where the shared header's key ``name`` lands in a scene."""
    return {"scheduler": scene.cluster_scheduler} if name == "cluster" else getattr(scene, name)


def _benchmark_value(scene: Any, name: str) -> Any:
    """Where the ``benchmark`` section's key ``name`` lands in a benchmark scene's settings (cases by name)."""
    if name == "duration":  # [s]: the first case's periods at its 25 Hz (engine_cost.yaml)
        return scene.cases[0].periods / 25.0
    if name == "cases":
        return [case.name for case in scene.cases]
    if name == "ladder":
        ladder = scene.settings.ladder
        return {key: getattr(ladder, key) for key in LADDER_POINT}
    return getattr(scene.settings, name)


def _same(found: Any, value: Any, key: Key) -> bool:
    """Whether a settings' value is the scene's: sequences and arrays as lists (a grid's sorted, as the settings sort
    it; names in their order), rows by their names, numbers to 1e-12."""
    def plain(item: Any) -> Any:
        if isinstance(item, dict):
            return {name: plain(entry) for name, entry in item.items()}
        if isinstance(item, (list, tuple)) or hasattr(item, "tolist"):
            items = [plain(entry) for entry in (item.tolist() if hasattr(item, "tolist") else item)]
            return sorted(items) if key.type is Grid else items
        return item

    if key.type is Rows:
        value = [row["name"] if "name" in row else row for row in value]
    if isinstance(value, float) and not isinstance(found, bool) and isinstance(found, (int, float)):
        return math.isclose(found, value, rel_tol=1e-12)
    return plain(found) == plain(value)


def _simulation_value(simulation: Any, name: str) -> Any:
    """Where the ``simulation`` section's key ``name`` lands in the scene's simulation settings (arrays as lists)."""
    if name == "frequency":
        return simulation.frequency.tolist()
    if name == "subset":
        return {solution: {axis: values.tolist() for axis, values in axes.items()} for solution, axes in simulation.subset.items()}
    if name in ("start",):
        return simulation.start
    return getattr(simulation.engine if name in ("method", "rtol", "atol", "max_step") else simulation.steady, name)
SECTIONS = list(declared_sections())


def _scene(section: Section | str, values: dict[str, Any]) -> dict:
    section = section if isinstance(section, Section) else next(s for s in SECTIONS if _id(s) == section)
    return _put(PLACES[_id(section)][0](), section.path, values)


def _required(section: Section) -> dict[str, Any]:
    """The values the section's shipped scene gives its required keys."""
    place = PLACES[_id(section)][0]()
    for part in section.path.split(".") if section.path else ():  # a list of rows (stops[k]): its first row
        place = place[part[:-3]][0] if part.endswith("[k]") else place.get(part, {})
    given = {key.name: place[key.name] for key in section.keys if key.default is REQUIRED or section.where(key.name) in NEEDED}
    return given | ({name: value for name, value in place.items() if name not in section.names} if section.others else {})  # a spread, a limit


def _other_value(key: Key, given: Any = None, section_path: str = "") -> Any:
    """A valid value of ``key`` other than its default (a required key's: other than ``given``, its scene's)."""
    if (where := f"{section_path}.{key.name}" if section_path else key.name) in OTHER_VALUES:
        return OTHER_VALUES[where]
    if key.default is REQUIRED and key.type is Band:
        return (given["start"], (given["start"] + given["stop"]) / 2.0)
    if key.default is REQUIRED and isinstance(given, dict):
        return dict(list(given.items())[:1])
    if key.type is str and key.choices and given is not None:
        return next(choice for choice in key.choices if choice != given)
    if key.default is REQUIRED or (key.default is DERIVED or key.default is OPTIONAL) and given is not None:
        return given[:1] if isinstance(given, list) else given + "2" if isinstance(given, str) else given * 1.01
    if key.default is DERIVED or key.default is OPTIONAL:
        return DERIVED_VALUES[f"{section_path}.{key.name}" if section_path else key.name]
    if key.type is bool:
        return not key.default
    if key.type is str:
        return next(choice for choice in key.choices if choice != key.default) if key.choices else f"{key.default}other"
    if key.type is Names:
        return key.default[:-1] if len(key.default) > 1 else tuple(choice for choice in key.choices if choice not in key.default)[:1]
    if key.type is Band:
        return (key.default[0], (key.default[0] + key.default[1]) / 2.0)
    if key.type is float:
        other = (key.default + key.high) / 2.0 if key.high < 10.0 else key.default * 1.5
        return other if other != key.default else (key.default + key.low) / 2.0 if math.isfinite(key.low) and key.low != key.default else 1.0  # exact: a walk value
    return key.default + 1 if key.default + 1 <= key.high else key.default - 1


def _wrong_values(key: Key) -> list[Any]:
    """Values of the wrong type for ``key``: a string for anything else, a float for an integer, a number for a name or
    a boolean, the YAML 1.1 spellings of a boolean, a bare name for a list of names, a list for a band."""
    if key.type is bool:
        return ["no", "false", 0, 1]
    if key.type is int:
        return [float(key.default) + 0.5, str(key.default), True]
    if key.type is float:
        return [f"~{key.default}", True]  # a string PyYAML writes bare ('1e-09') would read back as a YAML 1.2 number
    if key.type is Names:
        return [key.choices[0], True]
    if key.type is Band:
        return [[1.0, 2.0], 3]
    if key.type is Grid:
        return ["20 Hz", True]
    if key.type is Table:
        return [[1, 2], "momentary"]
    if key.type is Rows:
        return ["one_impact", 3]
    if key.type is Free:
        return []  # many forms: no value is wrong by its type alone
    return [3, True]


def _method_of(section: Section, key: Key) -> dict[str, Any]:
    """The other keys ``key`` needs to be read (its ``read_when``)."""
    return {key.read_when[0]: key.read_when[1]} if key.read_when else {}


def test_every_declared_section_of_every_kind_is_walked_here() -> None:
    assert sorted(_id(section) for section in SECTIONS) == sorted(PLACES)


@pytest.mark.parametrize("section", SECTIONS, ids=lambda s: s.path)
def test_every_declared_key_reaches_the_settings(section: Section) -> None:
    required, where = _required(section), PLACES[_id(section)][1]
    for key in section.keys:
        if _own_section(section, key) or key.type is Free or section.where(key.name) in FORM_KEYS:
            continue  # a declared section of its own, walked as such; a value of many forms, its parser's; the form itself
        value = _other_value(key, required.get(key.name), section.path)
        assert key.as_written(value) != key.as_written(required.get(key.name, key.default)), (key.name, "walked with the value it has anyway")
        given = required | _method_of(section, key) | CONTEXT.get(section.where(key.name), {}) | {key.name: key.as_written(value)}
        given = {name: item for name, item in given.items() if item is not None}  # a context's None: a key the walked one replaces
        scene = parse_scene(_scene(section, given))  # accepted (where None: what it sets is the model's to show)
        assert where is None or _same(where(scene, key.name), value, key), (key.name, value)


def test_search_settings_have_exactly_the_declared_keys() -> None:
    fields = set(SearchSettings.__dataclass_fields__)
    assert fields == set(SEARCH.names)
    assert all(getattr(SearchSettings(), key.name) == key.default for key in SEARCH.keys)


@pytest.mark.parametrize("section", SECTIONS, ids=lambda s: s.path)
def test_each_wrong_type_is_refused_naming_its_key(section: Section) -> None:
    required = _required(section)
    for key in section.keys:
        for wrong in _wrong_values(key):
            given = required | _method_of(section, key) | {key.name: wrong}
            with pytest.raises(SceneError) as caught:
                parse_scene(_scene(section, given))
            assert any(line.startswith(f"{_where(section, key.name)}: expected") for line in caught.value.problems), (key.name, wrong, caught.value.problems)


#: The declared sections grouped by the scene they are walked in (its name).
SCENES_OF = {name: [section for section in SECTIONS if PLACES[_id(section)][0]()["name"] == name] for name in sorted({PLACES[key][0]()["name"] for key in PLACES})}


@pytest.mark.parametrize("scene", sorted(SCENES_OF))
def test_a_scene_with_every_key_wrong_is_refused_at_once_with_exit_2_and_nothing_written(tmp_path: Path, scene: str, capsys: pytest.CaptureFixture[str]) -> None:
    """One run of run-study per scene, every declared key of its sections wrong in type: exit 2, each key named, nothing
    written. The design scene's runs as its own process (the exit status a shell sees); the others in this process
    (cli.main, the same code without an interpreter's start, ~3 s each)."""
    from vibroimpact import cli

    sections = [section for section in SCENES_OF[scene] if any(_wrong_values(key) for key in section.keys)]
    document = PLACES[_id(sections[0])][0]()
    for section in sections:
        kept = {name: value for name, value in _required(section).items() if section.where(name) in FORM_KEYS}  # which form is read
        _put(document, section.path, kept | {key.name: _wrong_values(key)[0] for key in section.keys if not _own_section(section, key) and section.where(key.name) not in FORM_KEYS
                                             and _wrong_values(key)})
    path = tmp_path / "wrong.yaml"
    path.write_text(yaml.safe_dump(document), encoding="utf-8")
    out = tmp_path / "out"
    if scene == SCENE["name"]:
        done = subprocess.run([sys.executable, "-m", "vibroimpact.cli", str(path), "--out", str(out)], capture_output=True, text=True, timeout=120)
        returncode, stderr = done.returncode, done.stderr
    else:
        returncode, stderr = cli.main([str(path), "--out", str(out)]), capsys.readouterr().err
    assert returncode == 2, stderr
    for section in sections:
        for key in section.keys:
            if not _own_section(section, key) and section.where(key.name) not in FORM_KEYS and _wrong_values(key):  # a section of its own: its keys are wrong instead
                assert f"{_where(section, key.name)}: expected" in stderr, (key.name, stderr)
    assert not out.exists() or not any(out.iterdir())


@pytest.mark.parametrize("spelt", ["no", "off", "false", "False", "yes", "on", "true"])
def test_a_boolean_is_a_yaml_1_2_boolean(spelt: str) -> None:
    text = yaml.safe_dump(_scene(SEARCH.path, {})).replace("search: {}", f"search: {{polish: {spelt}}}")
    assert f"polish: {spelt}" in text
    if spelt in ("true", "false", "False"):  # YAML 1.2's booleans
        assert parse_scene(read_yaml(text)).settings.search.polish is (spelt.lower() == "true")
        return
    with pytest.raises(SceneError) as caught:
        parse_scene(read_yaml(text))
    assert any(line.startswith("design.search.polish: expected a boolean") for line in caught.value.problems), caught.value.problems


@pytest.mark.parametrize(("given", "refused"), [({"method": "grid", "population": 8, "generations": 3}, ["population", "generations"]), ({"method": "grid", "polish": False}, ["polish"]), ({"points": 10}, ["points"])])
def test_a_key_the_chosen_method_never_reads_is_refused(given: dict, refused: list[str]) -> None:
    with pytest.raises(SceneError) as caught:
        parse_scene(_scene(SEARCH.path, given))
    for name in refused:
        assert any(line.startswith(f"design.search.{name}: not read with method") for line in caught.value.problems), caught.value.problems


def test_a_misspelt_key_or_name_gets_the_closest_declared_one() -> None:
    with pytest.raises(SceneError) as caught:
        parse_scene(_scene(SEARCH.path, {"polsh": True, "method": "grdi"}))
    problems = caught.value.problems
    assert any(line.startswith("design.search.polsh: unknown key") and "did you mean 'polish'?" in line for line in problems), problems
    assert any(line.startswith("design.search.method:") and "did you mean 'grid'?" in line for line in problems), problems
    document = copy.deepcopy(SCENE)
    document["stop"] = {"clearence": 0.003, "restitution": 0.2}  # a hand-checked section says it too
    with pytest.raises(SceneError) as caught:
        parse_scene(document)
    assert any(line.startswith("stop.clearence:") and "did you mean 'clearance'?" in line for line in caught.value.problems), caught.value.problems


@pytest.mark.parametrize(("values", "words"), [({"polish": "no"}, "polish: expected a boolean"), ({"population": 4.5}, "population: expected an integer"), ({"points": 1}, "points: 1 is out of range"), ({"method": "annealing"}, "method: 'annealing' is not allowed")])
def test_the_python_settings_refuse_what_the_scene_refuses(values: dict, words: str) -> None:
    with pytest.raises(ValueError, match=words):
        SearchSettings(**values)


def test_a_declaration_is_checked_when_it_is_made() -> None:
    with pytest.raises(ValueError, match="fails its own check"):
        Key("population", int, "members", 2, 4, 100)
    with pytest.raises(TypeError, match="for a str or Names key only"):
        Key("points", int, "points", 12, choices=("a",))
    with pytest.raises(ValueError, match="declared twice"):
        Section("s", (Key("a", int, "a", 1), Key("a", int, "a", 2)), "twice")
    with pytest.raises(ValueError, match="not one of its choices"):
        Section("s", (Key("method", str, "m", "x", choices=("x", "y")), Key("n", int, "n", 1, read_when=("method", "z"))), "bad")
    with pytest.raises(TypeError, match="is OPTIONAL"):  # a mapping left out is no value derived from others
        Key("robust", Table, "the mistuning", DERIVED)
    with pytest.raises(TypeError, match="is DERIVED"):
        Key("rtol", float, "the tolerance", OPTIONAL)


def test_a_required_key_is_named_with_what_it_takes_and_a_section_must_be_a_mapping() -> None:
    section = Section("demo", (Key("count", int, "how many", REQUIRED, 1, 9), Key("name", str, "what", "a")), "a demo")
    c = Checker()
    assert section.read(c, {"name": "b"}) is None
    assert c.problems == ["demo.count: required key is missing (how many; integer in [1, 9])"]
    c = Checker()
    assert section.read(c, {"count": 3}) == {"count": 3, "name": "a"}
    assert section.read(c, [1, 2]) is None and c.problems[-1].startswith("demo: expected a mapping with keys count, name")


def test_the_reference_lists_each_key_with_its_range_default_and_meaning() -> None:
    rows = SEARCH.reference()
    assert len(rows) == len(SEARCH.keys)
    assert "| `design.search.population` | integer in [4, 100] | 8 | members of each generation per design variable (read with method: differential_evolution) |" in rows
    assert any(row.startswith("| `design.search.polish` | boolean (true or false) | true |") for row in rows)
    design = DESIGN.reference()  # a section left out is optional; a value the kind works out is derived
    assert any(row.startswith("| `design.robust` | mapping | optional |") for row in design)
    assert any(row.startswith("| `simulation.rtol` | number in [1e-15, 0.1] | derived |") for row in SIMULATION.reference())


#: A shipped scene of each kind.
KIND_SCENES = {"stepped": "restitution.yaml", "swept": "bumper_sweep.yaml", "design": "design_rigid_stop.yaml", "benchmark": "engine_cost.yaml",
               "bifurcation": "bifurcation.yaml", "concepts": "absorber_concepts.yaml", "validation": "validation/zeno.yaml"}  # fmt: skip


@pytest.mark.parametrize("kind", sorted(KIND_SCENES))
def test_every_kind_reads_the_shared_header_s_cluster(kind: str) -> None:
    document = read_yaml((Path(__file__).resolve().parents[2] / "studies" / KIND_SCENES[kind]).read_text(encoding="utf-8"))
    assert parse_scene(copy.deepcopy(document)).kind == kind
    document["cluster"] = {"scheduler": "tcp://127.0.0.1:8786"}
    assert parse_scene(copy.deepcopy(document)).cluster_scheduler == "tcp://127.0.0.1:8786"  # honoured: the CLI runs there
    for wrong, words in ((42, "expected a mapping"), ({"schedular": "tcp://h:1"}, "did you mean 'scheduler'?"), ({"scheduler": "nowhere"}, "expected a scheduler address")):
        document["cluster"] = wrong
        with pytest.raises(SceneError) as caught:
            parse_scene(copy.deepcopy(document))
        assert any(line.startswith("cluster") and words in line for line in caught.value.problems), (kind, wrong, caught.value.problems)


@pytest.mark.parametrize(("make", "words"), [
    (lambda: BranchSettings(linear="yes"), "linear: expected a boolean"),  # before: any string was accepted as true
    (lambda: BruteForceSettings(directions=("up", "up")), r"directions\[1\]: 'up' is listed twice"),
    (lambda: BruteForceSettings(step=0.0), r"step: 0.0 is out of range: allowed \(0, inf\)"),
    (lambda: ChartSettings(clearance=(5e-3, 1e-3)), "clearance.stop: 0.001 must be greater than start = 0.005"),
    (lambda: ChartSettings(kinds=("fold", "cusp")), r"kinds\[1\]: unknown name 'cusp'"),
])  # fmt: skip
def test_the_bifurcation_settings_refuse_what_the_scene_refuses(make: Any, words: str) -> None:
    with pytest.raises(ValueError, match=words):
        make()


def test_names_and_bands_read_as_tuples_and_are_written_back_as_a_scene_writes_them() -> None:
    assert BRUTE_FORCE.read(Checker(), {"directions": ["down"]})["directions"] == ("down",)  # type: ignore[index]
    assert CHART.read(Checker(), {"clearance": {"start": 0.002, "stop": 0.004}})["clearance"] == (0.002, 0.004)  # type: ignore[index]
    assert CHART.key("clearance").allowed() == "band {start, stop} in (0, 1] [m]"
    rows = CHART.reference() + BRUTE_FORCE.reference()
    assert "| `bifurcation.chart.clearance` | band {start, stop} in (0, 1] [m] | {start: 0.001, stop: 0.006} | clearance range of the chart |" in rows
    assert "| `bifurcation.brute_force.directions` | list of names from up, down | [up, down] | which ways the frequency is stepped, the end state carried to the next |" in rows


def test_run_study_keys_prints_every_declared_key_of_every_kind_and_runs_nothing(tmp_path: Path) -> None:
    done = subprocess.run([sys.executable, "-m", "vibroimpact.cli", "--keys"], capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    rows = [line for line in done.stdout.splitlines() if line.startswith("| `")]
    assert rows == [row for section in SECTIONS for row in section.reference()]
    titles = [line for line in done.stdout.splitlines() if line.startswith("### ")]
    top = [line for line in titles if line.startswith("### the top level")]
    assert titles[0].startswith("### the top level: ") and len(top) == sum(not section.path for section in SECTIONS)  # the header, then each kind's own
    assert "### the top level (stepped and swept): " in "\n".join(top)
    assert {section.path for section in SECTIONS if section.path} == {line.split("`")[1] for line in titles if line not in top}
    assert not any(tmp_path.iterdir())


@pytest.mark.parametrize("option", ["--keys", "--list"])
def test_a_listing_read_only_in_part_ends_quietly(option: str) -> None:
    """``run-study --keys | head -1``: the reader closes the pipe after one line; run-study ends with 0 and no
    BrokenPipeError traceback (before: exit 1 and a traceback)."""
    run = subprocess.Popen([sys.executable, "-m", "vibroimpact.cli", option], stdout=subprocess.PIPE, stderr=subprocess.PIPE, bufsize=0)
    assert run.stdout is not None and run.stderr is not None
    assert run.stdout.read(1)
    run.stdout.close()
    error = run.stderr.read().decode()
    run.stderr.close()
    assert run.wait(timeout=120) == 0, error
    assert "Traceback" not in error and "BrokenPipeError" not in error, error


def test_review_mends_a_null_section_a_missing_name_a_misspelt_spread_and_a_section_that_is_no_mapping() -> None:
    """A section given as null is refused, not read as its defaults; a missing name is said once; a misspelt key of a
    section that takes other keys of its kind's (design.robust's spreads) gets did-you-mean instead of 'unknown design
    variable'; 'bifurcation: 5' is said as no mapping, without a restitution said missing beside it."""
    concepts = _shipped("absorber_concepts.yaml") | {"continuation": None}
    with pytest.raises(SceneError) as caught:
        parse_scene(concepts)
    assert any(line.startswith("continuation: expected a mapping") for line in caught.value.problems), caught.value.problems
    stepped = _shipped("restitution.yaml") | {"settings": {"admissibility": None}}
    with pytest.raises(SceneError) as caught:
        parse_scene(stepped)
    assert any(line.startswith("settings.admissibility: expected a mapping") for line in caught.value.problems), caught.value.problems
    nameless = copy.deepcopy(SCENE)
    del nameless["name"]
    with pytest.raises(SceneError) as caught:
        parse_scene(nameless)
    assert [line for line in caught.value.problems if line.startswith("name:")] == ["name: required key is missing"], caught.value.problems
    robust = copy.deepcopy(SCENE)
    robust["design"]["robust"] = {"k1": 0.05, "sample": 8, "quantil": 0.9}
    with pytest.raises(SceneError) as caught:
        parse_scene(robust)
    problems = caught.value.problems
    assert any(line.startswith("design.robust.sample: unknown key") and "did you mean 'samples'?" in line for line in problems), problems
    assert any(line.startswith("design.robust.quantil: unknown key") and "did you mean 'quantile'?" in line for line in problems), problems
    assert not any("unknown design variable" in line for line in problems), problems
    bifurcation = _shipped("bifurcation.yaml") | {"bifurcation": 5}
    with pytest.raises(SceneError) as caught:
        parse_scene(bifurcation)
    assert [line for line in caught.value.problems if line.startswith("bifurcation")] == [caught.value.problems[0]], caught.value.problems
    assert caught.value.problems[0].startswith("bifurcation: expected a mapping"), caught.value.problems


def _beyond(key: Key) -> list[Any]:
    """Values just outside a numeric key's declared range (an open end itself), none for an unbounded side."""
    outside: list[Any] = []
    if math.isfinite(key.low):
        outside.append(key.low if key.open_low else (key.low - 1 if key.type is int else key.low - max(abs(key.low), 1.0) * 1e-6))
    if math.isfinite(key.high):
        outside.append(key.high if key.open_high else key.high + 1 if key.type is int else key.high + max(abs(key.high), 1.0) * 1e-6)
    return outside


@pytest.mark.parametrize("section", SECTIONS, ids=_id)
def test_a_value_just_outside_each_declared_range_is_refused_naming_its_key_and_the_range(section: Section) -> None:
    """The declared range is the one the scene enforces: at each finite end, the nearest value outside (the open low
    end itself) is refused naming the key and the allowed range as the reference prints it."""
    required = _required(section)
    for key in section.keys:
        if key.type not in (int, float):
            continue
        for outside in _beyond(key):
            given = required | _method_of(section, key) | CONTEXT.get(section.where(key.name), {}) | {key.name: outside}
            with pytest.raises(SceneError) as caught:
                parse_scene(_scene(section, given))
            said = f"{_where(section, key.name)}: {outside!r} is out of range: allowed "
            assert any(line.startswith(said) for line in caught.value.problems), (key.name, outside, caught.value.problems)


@pytest.mark.parametrize("shipped, key", [("restitution.yaml", "simulation"), ("bumper_sweep.yaml", "swept_sine"), ("absorber_concepts.yaml", "bumper"),
                                          ("absorber_concepts.yaml", "simulation"), ("absorber_concepts.yaml", "continuation")])
def test_a_section_that_is_no_mapping_is_said_once(shipped: str, key: str) -> None:
    """The kind's top level checks a section's type, and the section itself is then not read again: 'bumper: 5' was
    said twice ('expected a mapping, got 5' by each reader)."""
    document = _shipped(shipped) | {key: 5}
    with pytest.raises(SceneError) as raised:
        parse_scene(document)
    said = [problem for problem in raised.value.problems if problem.startswith(f"{key}:")]
    assert len(said) == 1 and "expected a mapping" in said[0], said
