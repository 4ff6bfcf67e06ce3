"""Scenes: parsing and grids, one clear SceneError per kind of mistake, and the ``run-study`` command line."""

from __future__ import annotations

import copy
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from vibroimpact import cli
from vibroimpact.scene import SceneError, find_scene, load_scene, parse_scene, shipped_studies_dir
from vibroimpact.scene.schema import MAX_GRID_POINTS, QUANTITIES

#: The paper's system (eq. 24), as in studies/restitution.yaml.
PAPER_SYSTEM_SPEC = {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0, "b1": 0.8, "b2": 0.08}


# ----------------------------------------------------------------------------- helpers
def base_scene() -> dict[str, Any]:
    """A small valid scene document: paper system, R = 0.2 and Delta = 3 mm fixed, 20-26 Hz."""
    return {
        "name": "tiny",
        "description": "test scene",
        "system": dict(PAPER_SYSTEM_SPEC),
        "excitation": {"amplitude": 10.0},
        "stop": {"clearance": 0.003, "restitution": 0.2},
        "sweep": {"frequency": {"start": 20.0, "stop": 26.0, "step": 0.5}},
        "solutions": ["linear", "pgf"],
    }


def scene_with(change: Callable[[dict[str, Any]], Any] | None = None) -> dict[str, Any]:
    """A fresh copy of :func:`base_scene` with ``change`` applied to it in place."""
    document = copy.deepcopy(base_scene())
    if change is not None:
        change(document)
    return document


def problems_of(document: Any) -> list[str]:
    """The problems :func:`parse_scene` reports for ``document`` (fails if it is accepted)."""
    with pytest.raises(SceneError) as caught:
        parse_scene(document)
    return caught.value.problems


def write_yaml(path: Path, document: Any) -> Path:
    """Write ``document`` as YAML to ``path`` and return the path."""
    path.write_text(yaml.safe_dump(document, sort_keys=False), encoding="utf-8")
    return path


# setters used by the parametrized cases (each receives the document and edits it)
def _set(section: str, key: str, value: Any) -> Callable[[dict[str, Any]], None]:
    return lambda d: d[section].__setitem__(key, value)


def _top(key: str, value: Any) -> Callable[[dict[str, Any]], None]:
    return lambda d: d.__setitem__(key, value)


def _drop(section: str | None, key: str) -> Callable[[dict[str, Any]], None]:
    return lambda d: (d if section is None else d[section]).pop(key)


def _sweep_frequency(spec: Any) -> Callable[[dict[str, Any]], None]:
    return _set("sweep", "frequency", spec)


def _sweep_restitution(values: Any) -> Callable[[dict[str, Any]], None]:
    def change(d: dict[str, Any]) -> None:
        d["stop"].pop("restitution")
        d["sweep"]["restitution"] = values

    return change


# ----------------------------------------------------------------------------- valid scenes and grids
def test_minimal_scene_parses() -> None:
    """The base scene is accepted; unswept R and Delta come from ``stop`` and only frequency is swept."""
    scene = parse_scene(scene_with(lambda d: d.pop("description")))
    assert scene.name == "tiny"
    assert scene.description == ""
    assert (named := scene.layout.paper_view()) is not None and named.m1 == 1.0 and named.k2 == 4300.0 and named.b2 == 0.08  # exact: parsed input
    assert scene.amplitude == 10.0  # exact: parsed input
    np.testing.assert_array_equal(scene.settings.restitution, [0.2])
    np.testing.assert_array_equal(scene.settings.clearance, [0.003])
    assert scene.settings.swept == ("frequency",)
    assert scene.settings.solutions == ("linear", "pgf")
    assert scene.settings.quantities == QUANTITIES
    assert scene.report is True


def test_damping_is_optional() -> None:
    """b1 and b2 may be left out (undamped system)."""
    scene = parse_scene(scene_with(lambda d: (d["system"].pop("b1"), d["system"].pop("b2"))))
    assert (named := scene.layout.paper_view()) is not None and named.b1 == 0.0 and named.b2 == 0.0  # exact: parsed input


@pytest.mark.parametrize(
    ("spec", "expected"),
    [
        ({"start": 15, "stop": 16, "step": 0.25}, [15.0, 15.25, 15.5, 15.75, 16.0]),
        ({"start": 1, "stop": 2, "num": 3}, [1.0, 1.5, 2.0]),
        ({"start": 15, "stop": 16, "step": 0.3}, [15.0, 15.3, 15.6, 15.9]),
        ({"start": 15.0, "stop": 15.02, "step": 0.005}, [15.0, 15.005, 15.01, 15.015, 15.02]),
        ([30.0, 20.0, 25.0], [20.0, 25.0, 30.0]),
    ],
    ids=["step", "num", "step-not-dividing-range", "fine-decimal-step", "list-sorted"],
)
def test_frequency_grids(spec: Any, expected: list[float]) -> None:
    """Step grids include the stop (exact decimals), num grids are linspaces, lists are sorted."""
    scene = parse_scene(scene_with(_sweep_frequency(spec)))
    assert scene.settings.frequency.tolist() == expected


def test_swept_restitution_and_clearance_are_dimensions_with_frequency_last() -> None:
    """Swept parameters appear in ``swept`` in the order (restitution, clearance, frequency)."""

    def change(d: dict[str, Any]) -> None:
        d.pop("stop")
        d["sweep"] = {
            "frequency": {"start": 20, "stop": 21, "num": 2},
            "clearance": [0.004, 0.002],
            "restitution": [0.8, 0.0, 0.4],
        }

    scene = parse_scene(scene_with(change))
    assert scene.settings.swept == ("restitution", "clearance", "frequency")
    assert scene.settings.restitution.tolist() == [0.0, 0.4, 0.8]
    assert scene.settings.clearance.tolist() == [0.002, 0.004]
    assert scene.settings.frequency.tolist() == [20.0, 21.0]


def test_one_swept_parameter_other_from_stop() -> None:
    """Sweeping only restitution leaves clearance as a one-value array out of ``swept``."""
    scene = parse_scene(scene_with(_sweep_restitution([0.6, 0.2])))
    assert scene.settings.swept == ("restitution", "frequency")
    assert scene.settings.restitution.tolist() == [0.2, 0.6]
    assert scene.settings.clearance.tolist() == [0.003]


def test_regime_is_always_written_and_report_can_be_off() -> None:
    """``regime`` is appended to the requested quantities; ``report: false`` is kept."""
    scene = parse_scene(scene_with(lambda d: d.update(quantities=["x2_amplitude"], report=False)))
    assert scene.settings.quantities == ("x2_amplitude", "regime")
    assert scene.report is False


def test_grid_of_exactly_the_maximum_size_is_accepted() -> None:
    """MAX_GRID_POINTS points is allowed (the limit is inclusive)."""
    scene = parse_scene(scene_with(_sweep_frequency({"start": 1, "stop": 2, "num": MAX_GRID_POINTS})))
    assert scene.settings.frequency.size == MAX_GRID_POINTS


def test_shipped_restitution_scene_loads() -> None:
    """The shipped paper scene is valid and keeps its YAML text."""
    path = shipped_studies_dir() / "restitution.yaml"
    scene = load_scene(path)
    assert scene.name == "restitution"
    assert scene.settings.swept == ("restitution", "frequency")
    assert scene.settings.restitution.tolist() == [0.0, 0.2, 0.4, 0.6, 0.8]
    assert scene.settings.frequency[0] == 15.0 and scene.settings.frequency[-1] == 45.0 and scene.settings.frequency.size == 6001  # exact: grid ends are the inputs
    assert scene.text == path.read_text(encoding="utf-8")


# ----------------------------------------------------------------------------- one mistake, one clear message
# (case id, change to the base scene, fragments that must all appear in one reported problem)
MISTAKES = [
    ("unknown-top-key", _top("colour", "red"), ["colour: unknown key", "allowed:", "excitation", "sweep"]),
    ("unknown-system-key", _set("system", "m3", 1.0), ["system.m3: unknown key", "allowed: m1, m2, k1, k2, b1, b2"]),
    ("unknown-excitation-key", _set("excitation", "phase", 0.0), ["excitation.phase: unknown key", "allowed: amplitude"]),
    ("unknown-stop-key", _set("stop", "stiffness", 1.0), ["stop.stiffness: unknown key", "allowed: clearance, restitution"]),
    ("unknown-sweep-key", _set("sweep", "amplitude", [1.0]), ["sweep.amplitude: unknown key", "allowed: frequency, restitution, clearance, bumper_frequency, bumper_loss_factor, stop"]),
    ("string-mass", _set("system", "m1", "heavy"), ["system.m1: expected a number", "'heavy'", "(str)"]),
    ("bool-stiffness", _set("system", "k1", True), ["system.k1: expected a number", "True", "(bool)"]),
    ("list-amplitude", _set("excitation", "amplitude", [1.0, 2.0]), ["excitation.amplitude: expected a number", "(list)"]),
    ("null-damping", _set("system", "b1", None), ["system.b1: expected a number", "None"]),
    ("system-not-mapping", _top("system", [1.0, 0.1]), ["system: expected a mapping", "m1, m2, k1", "(list)"]),
    ("negative-m1", _set("system", "m1", -1.0), ["system.m1: -1.0 is out of range: allowed (0, inf"]),
    ("zero-k2", _set("system", "k2", 0), ["system.k2: 0 is out of range: allowed (0, inf"]),
    ("negative-b2", _set("system", "b2", -0.01), ["system.b2: -0.01 is out of range: allowed [0, inf"]),
    ("infinite-m1", _set("system", "m1", float("inf")), ["system.m1: inf is out of range"]),
    ("nan-m2", _set("system", "m2", float("nan")), ["system.m2: nan is out of range: allowed (0, inf"]),
    ("zero-amplitude", _set("excitation", "amplitude", 0.0), ["excitation.amplitude: 0.0 is out of range: allowed (0, inf"]),
    ("restitution-above-1", _set("stop", "restitution", 1.5), ["stop.restitution: 1.5 is out of range: allowed [0, 1]"]),
    ("restitution-negative", _set("stop", "restitution", -0.1), ["stop.restitution: -0.1 is out of range: allowed [0, 1]"]),
    ("restitution-sweep-item", _sweep_restitution([0.2, 1.2]), ["sweep.restitution[1]: 1.2 is out of range: allowed [0, 1]"]),
    ("restitution-sweep-string", _sweep_restitution([0.2, "x"]), ["sweep.restitution[1]: expected a number", "'x'"]),
    ("infinite-clearance", _set("stop", "clearance", float("inf")), ["stop.clearance: inf is out of range: allowed (-inf, inf)"]),
    ("zero-frequency-list", _sweep_frequency([0.0, 10.0]), ["sweep.frequency[0]: 0.0 is out of range: allowed (0, inf"]),
    ("negative-frequency-start", _sweep_frequency({"start": -5, "stop": 10, "step": 1}), ["sweep.frequency.start: -5 is out of range: allowed (0, inf"]),
    ("empty-grid", _sweep_frequency([]), ["sweep.frequency: empty grid: give at least one value"]),
    ("repeated-grid-values", _sweep_restitution([0.2, 0.2]), ["sweep.restitution: repeated values in the grid"]),
    ("stop-equals-start", _sweep_frequency({"start": 20, "stop": 20, "step": 0.5}), ["sweep.frequency.stop: 20 must be greater than start = 20"]),
    ("stop-below-start", _sweep_frequency({"start": 26, "stop": 20, "num": 5}), ["sweep.frequency.stop: 20 must be greater than start = 26"]),
    ("step-and-num", _sweep_frequency({"start": 20, "stop": 26, "step": 0.5, "num": 13}), ["sweep.frequency: give exactly one of 'step' or 'num'"]),
    ("neither-step-nor-num", _sweep_frequency({"start": 20, "stop": 26}), ["sweep.frequency: give exactly one of 'step' or 'num'"]),
    ("zero-step", _sweep_frequency({"start": 20, "stop": 26, "step": 0}), ["sweep.frequency.step: 0 is out of range: allowed (0, 6]"]),
    ("step-wider-than-range", _sweep_frequency({"start": 20, "stop": 26, "step": 7}), ["sweep.frequency.step: 7 is out of range: allowed (0, 6]"]),
    ("num-one", _sweep_frequency({"start": 20, "stop": 26, "num": 1}), ["sweep.frequency.num: 1 is out of range: allowed [2, 1000000]"]),
    ("num-float", _sweep_frequency({"start": 20, "stop": 26, "num": 3.0}), ["sweep.frequency.num: expected an integer", "3.0"]),
    ("unknown-grid-key", _sweep_frequency({"start": 20, "stop": 26, "num": 3, "end": 30}), ["sweep.frequency.end: unknown key", "allowed: num, start, step, stop"]),
    ("grid-not-list-or-mapping", _sweep_frequency(20.0), ["sweep.frequency: expected a list of values or a mapping {start, stop, step|num}", "float"]),
    ("too-many-points-step", _sweep_frequency({"start": 1, "stop": 2, "step": 1e-7}), ["sweep.frequency: 10000001 points is too many: allowed at most 1000000"]),
    ("too-many-points-num", _sweep_frequency({"start": 1, "stop": 2, "num": MAX_GRID_POINTS + 1}), ["sweep.frequency.num: 1000001 is out of range: allowed [2, 1000000]"]),
    ("missing-name", _drop(None, "name"), ["name: required key is missing"]),
    ("missing-system", _drop(None, "system"), ["system: required key is missing"]),
    ("missing-excitation", _drop(None, "excitation"), ["excitation: required key is missing"]),
    ("missing-sweep", _drop(None, "sweep"), ["sweep: required key is missing"]),
    ("missing-solutions", _drop(None, "solutions"), ["solutions: required key is missing"]),
    ("missing-sweep-frequency", _drop("sweep", "frequency"), ["sweep.frequency: required key is missing"]),
    ("missing-system-k2", _drop("system", "k2"), ["system.k2: required key is missing"]),
    ("missing-amplitude", _drop("excitation", "amplitude"), ["excitation.amplitude: required key is missing"]),
    ("restitution-nowhere", _drop("stop", "restitution"), ["stop.restitution: required unless swept (sweep.restitution)", "allowed range [0, 1]"]),
    ("clearance-nowhere", _drop("stop", "clearance"), ["stop.clearance: required unless swept (sweep.clearance)", "allowed range (-inf, inf)"]),
    ("restitution-in-stop-and-sweep", _set("sweep", "restitution", [0.2, 0.4]), ["stop.restitution: also swept in sweep.restitution: give it in one place only"]),
    ("clearance-in-stop-and-sweep", _set("sweep", "clearance", [0.003]), ["stop.clearance: also swept in sweep.clearance: give it in one place only"]),
    ("unknown-solution", _top("solutions", ["linear", "fem"]), ["solutions[1]: unknown name 'fem'", "allowed: linear, pgf, pgf_paper"]),
    ("solution-twice", _top("solutions", ["pgf", "linear", "pgf"]), ["solutions[2]: 'pgf' is listed twice"]),
    ("empty-solutions", _top("solutions", []), ["solutions: expected a non-empty list of names from ['linear', 'pgf', 'pgf_paper', 'exact', 'momentary', 'compliant', 'compliant_exact']"]),
    ("solutions-not-list", _top("solutions", "linear"), ["solutions: expected a non-empty list of names", "'linear'"]),
    ("unknown-quantity", _top("quantities", ["x2_amplitude", "velocity"]), ["quantities[1]: unknown name 'velocity'", "allowed: x1_amplitude", "floquet_modulus"]),
    ("quantity-twice", _top("quantities", ["impulse", "impulse"]), ["quantities[1]: 'impulse' is listed twice"]),
    ("report-not-bool", _top("report", "yes"), ["report: expected a boolean (true or false), got 'yes' (str); YAML 1.2 booleans are true and false"]),
    ("report-int", _top("report", 1), ["report: expected a boolean (true or false), got 1 (int)"]),
    ("bad-name", _top("name", "my scene/1"), ["name: expected a file-name-safe string", "'my scene/1'"]),
    ("description-not-string", _top("description", 3), ["description: expected a string, got 3 (int)"]),
    ("unknown-settings-key", _top("settings", {"tolerance": 1e-9}), ["settings.tolerance: unknown key", "allowed: admissibility"]),
    ("samples-too-few", _top("settings", {"admissibility": {"samples_per_period": 8}}), ["settings.admissibility.samples_per_period: 8 is out of range: allowed [16, 1000000]"]),
    ("tolerance-too-large", _top("settings", {"admissibility": {"relative_tolerance": 0.1}}), ["settings.admissibility.relative_tolerance: 0.1 is out of range: allowed [0, 0.01]"]),
]


@pytest.mark.parametrize(("change", "fragments"), [case[1:] for case in MISTAKES], ids=[case[0] for case in MISTAKES])
def test_each_mistake_is_reported_with_key_and_allowed_values(change: Callable[[dict[str, Any]], Any], fragments: list[str]) -> None:
    """The mistake gives a SceneError with one problem holding every fragment, and that text is in the message."""
    document = scene_with(change)
    with pytest.raises(SceneError) as caught:
        parse_scene(document)
    error = caught.value
    matching = [p for p in error.problems if all(fragment in p for fragment in fragments)]
    assert matching, f"no problem contains all of {fragments}: {error.problems}"
    assert matching[0] in str(error)
    assert str(error).startswith("invalid scene:\n  - ")


def test_a_single_mistake_gives_a_single_problem() -> None:
    """One bad value is reported once, without follow-on noise."""
    assert problems_of(scene_with(_set("system", "m1", -1.0))) == ["system.m1: -1.0 is out of range: allowed (0, inf)"]


def test_invalid_yaml_syntax(tmp_path: Path) -> None:
    """A file that is not YAML gives a SceneError naming the file and the YAML problem."""
    path = tmp_path / "broken.yaml"
    path.write_text("name: tiny\nsystem: {m1: 1.0, m2: [0.1\n", encoding="utf-8")
    with pytest.raises(SceneError) as caught:
        load_scene(path)
    assert len(caught.value.problems) == 1
    assert caught.value.problems[0].startswith("not valid YAML: ")
    assert str(caught.value).startswith(f"invalid {path}:")


def test_empty_file_is_an_error(tmp_path: Path) -> None:
    """An empty scene file is rejected: the top level must be a mapping."""
    path = tmp_path / "empty.yaml"
    path.write_text("", encoding="utf-8")
    with pytest.raises(SceneError) as caught:
        load_scene(path)
    assert len(caught.value.problems) == 1
    assert caught.value.problems[0].startswith("scene: expected a mapping of a scene's sections") and caught.value.problems[0].endswith("got an empty document")


def test_load_scene_names_the_file_and_keeps_the_text(tmp_path: Path) -> None:
    """A valid file loads; an invalid one names its path in the message."""
    good = write_yaml(tmp_path / "good.yaml", base_scene())
    assert load_scene(good).text == good.read_text(encoding="utf-8")
    bad = write_yaml(tmp_path / "bad.yaml", scene_with(_set("system", "m1", -1.0)))
    with pytest.raises(SceneError, match=r"system\.m1") as caught:
        load_scene(bad)
    assert str(caught.value).startswith(f"invalid {bad}:")


# ----------------------------------------------------------------------------- several mistakes at once
def test_all_mistakes_are_reported_together() -> None:
    """Mistakes in different sections all appear in one SceneError."""

    def change(d: dict[str, Any]) -> None:
        d["system"]["m1"] = -1.0
        d["system"]["k9"] = 2.0
        d["stop"]["restitution"] = 2.0
        d["sweep"]["frequency"] = {"start": 20, "stop": 10, "step": 1}
        d["solutions"] = ["linear", "linear"]
        d["report"] = "no"
        d.pop("name")

    problems = problems_of(scene_with(change))
    assert len(problems) >= 2
    keys = {p.split(": ", 1)[0] for p in problems}
    assert {
        "system.m1",
        "system.k9",
        "stop.restitution",
        "sweep.frequency.stop",
        "solutions[1]",
        "report",
        "name",
    } <= keys


def test_every_bad_item_of_a_list_is_reported() -> None:
    """Each out-of-range entry of a sweep list is reported with its own index."""
    problems = problems_of(scene_with(_sweep_restitution([-0.5, 0.3, 1.5])))
    assert len(problems) >= 2
    assert any(p.startswith("sweep.restitution[0]: -0.5 is out of range: allowed [0, 1]") for p in problems)
    assert any(p.startswith("sweep.restitution[2]: 1.5 is out of range: allowed [0, 1]") for p in problems)
    assert not any("sweep.restitution[1]" in p for p in problems)


# ----------------------------------------------------------------------------- the command line
BAD_FOR_CLI = [
    ("negative-mass", scene_with(_set("system", "m1", -1.0)), ["system.m1", "(0, inf"]),
    ("restitution-in-list", scene_with(_sweep_restitution([0.2, 1.2])), ["sweep.restitution[1]", "[0, 1]"]),
    ("unknown-key", scene_with(_top("colour", "red")), ["colour", "unknown key"]),
    ("missing-k2", scene_with(_drop("system", "k2")), ["system.k2", "required key is missing"]),
    ("too-many-points", scene_with(_sweep_frequency({"start": 1, "stop": 2, "step": 1e-7})), ["sweep.frequency", "at most 1000000"]),
]


@pytest.mark.parametrize(("document", "fragments"), [case[1:] for case in BAD_FOR_CLI], ids=[case[0] for case in BAD_FOR_CLI])
def test_cli_bad_scene_exits_2_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], document: dict[str, Any], fragments: list[str]
) -> None:
    """A bad scene: exit code 2, one error on stderr naming key and range, no output folder."""
    path = write_yaml(tmp_path / "bad.yaml", document)
    out = tmp_path / "out"
    assert cli.main([str(path), "--out", str(out)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.startswith("run-study: error: invalid ")
    assert captured.err.count("run-study: error:") == 1
    for fragment in fragments:
        assert fragment in captured.err
    assert not out.exists()


def test_cli_invalid_yaml_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """YAML syntax errors are bad input too."""
    path = tmp_path / "broken.yaml"
    path.write_text("name: [unclosed\n", encoding="utf-8")
    out = tmp_path / "out"
    assert cli.main([str(path), "--out", str(out)]) == 2
    assert "not valid YAML" in capsys.readouterr().err
    assert not out.exists()


def test_cli_empty_file_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """An empty scene file is bad input."""
    path = tmp_path / "empty.yaml"
    path.write_text("", encoding="utf-8")
    out = tmp_path / "out"
    assert cli.main([str(path), "--out", str(out)]) == 2
    assert "expected a mapping" in capsys.readouterr().err
    assert not out.exists()


def test_cli_existing_empty_out_stays_empty(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """An existing --out folder is left untouched by a bad scene."""
    path = write_yaml(tmp_path / "bad.yaml", scene_with(_set("stop", "clearance", float("inf"))))
    out = tmp_path / "out"
    out.mkdir()
    assert cli.main([str(path), "--out", str(out)]) == 2
    assert "stop.clearance" in capsys.readouterr().err
    assert list(out.iterdir()) == []


def test_cli_missing_scene_lists_where_it_looked(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A scene found nowhere: exit 2 and a message naming the path, ./studies/ and the shipped studies."""
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "out"
    assert cli.main(["no_such_scene.yaml", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("run-study: error: scene not found; looked at: no_such_scene.yaml, ")
    assert str(tmp_path / "studies" / "no_such_scene.yaml") in err
    assert str(shipped_studies_dir() / "no_such_scene.yaml") in err
    assert not out.exists()


def test_cli_missing_absolute_path(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """An absolute path that does not exist is looked for only there."""
    missing = tmp_path / "absent.yaml"
    assert cli.main([str(missing), "--out", str(tmp_path / "out")]) == 2
    assert capsys.readouterr().err.strip() == f"run-study: error: scene not found; looked at: {missing}"
    assert not (tmp_path / "out").exists()


def test_cli_non_utf8_file_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A scene file that is not UTF-8 text is bad input (exit 2), not a crash."""
    path = tmp_path / "binary.yaml"
    path.write_bytes(b"\xff\xfe\x00name: x\n")
    out = tmp_path / "out"
    assert cli.main([str(path), "--out", str(out)]) == 2
    assert str(path) in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.slow
def test_cli_runs_a_tiny_scene_end_to_end(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A valid scene: exit 0, the dataset and the report are written, no temporary file is left."""
    path = write_yaml(tmp_path / "tiny.yaml", base_scene())
    out = tmp_path / "o"
    assert cli.main([str(path), "--out", str(out)]) == 0
    dataset_path = out / "tiny.nc"
    assert dataset_path.is_file() and dataset_path.stat().st_size > 0
    assert (out / "report.html").is_file()
    assert [p.name for p in out.iterdir() if p.name.endswith(".tmp")] == []
    printed = capsys.readouterr().out
    assert f"wrote {dataset_path}" in printed
    assert f"wrote {out / 'report.html'}" in printed

    from vibroimpact.runs.run import read_dataset

    dataset = read_dataset(dataset_path)
    assert list(dataset["solution"].values) == ["linear", "pgf"]
    np.testing.assert_allclose(dataset["frequency"].values, np.arange(20.0, 26.0 + 0.25, 0.5))


@pytest.mark.slow
def test_cli_no_report_writes_only_the_dataset(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``report: false`` in the scene: only ``<name>.nc`` is written."""
    document = scene_with(lambda d: d.update(report=False, solutions=["linear"], sweep={"frequency": [20.0, 21.0]}))
    path = write_yaml(tmp_path / "tiny.yaml", document)
    out = tmp_path / "o"
    assert cli.main([str(path), "--out", str(out)]) == 0
    capsys.readouterr()
    assert sorted(p.name for p in out.iterdir()) == ["tiny.nc"]


# ----------------------------------------------------------------------------- finding a scene by name
def test_find_scene_in_local_studies(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A bare name is found in ./studies/ of the working directory."""
    (tmp_path / "studies").mkdir()
    local = write_yaml(tmp_path / "studies" / "foo.yaml", base_scene())
    monkeypatch.chdir(tmp_path)
    assert find_scene("foo.yaml").resolve() == local.resolve()


def test_find_scene_prefers_the_path_as_given(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A file at the given path wins over ./studies/ and the shipped studies."""
    (tmp_path / "studies").mkdir()
    write_yaml(tmp_path / "studies" / "restitution.yaml", base_scene())
    here = write_yaml(tmp_path / "restitution.yaml", base_scene())
    monkeypatch.chdir(tmp_path)
    assert find_scene("restitution.yaml").resolve() == here.resolve()


def test_find_scene_local_studies_before_shipped(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """./studies/<name> shadows the shipped scene of the same name."""
    (tmp_path / "studies").mkdir()
    local = write_yaml(tmp_path / "studies" / "restitution.yaml", base_scene())
    monkeypatch.chdir(tmp_path)
    assert find_scene("restitution.yaml").resolve() == local.resolve()


def test_find_scene_falls_back_to_shipped_studies(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """From a folder without studies/, a bare name finds the shipped scene."""
    monkeypatch.chdir(tmp_path)
    found = find_scene("restitution.yaml")
    assert found.resolve() == (shipped_studies_dir() / "restitution.yaml").resolve()
    assert load_scene(found).name == "restitution"


def test_find_scene_raises_naming_every_place(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Not found anywhere: FileNotFoundError listing the three candidates."""
    monkeypatch.chdir(tmp_path)
    with pytest.raises(FileNotFoundError) as caught:
        find_scene("nothing.yaml")
    message = str(caught.value)
    assert message == (
        "scene not found; looked at: nothing.yaml, "
        f"{tmp_path / 'studies' / 'nothing.yaml'}, {shipped_studies_dir() / 'nothing.yaml'}"
    )


def test_repeated_yaml_key_is_an_error(tmp_path: Path) -> None:
    """PyYAML keeps the last of two equal keys silently; a scene must not."""
    path = tmp_path / "twice.yaml"
    path.write_text("name: a\nname: b\n", encoding="utf-8")
    with pytest.raises(SceneError, match="key 'name' is repeated"):
        load_scene(path)


def test_cli_directory_as_scene_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A folder given as the scene is reported as such, not as 'not found'."""
    out = tmp_path / "out"
    assert cli.main([str(tmp_path), "--out", str(out)]) == 2
    assert "is a directory" in capsys.readouterr().err
    assert not out.exists()


def test_tiny_clearance_grid_keeps_its_values() -> None:
    """Grid rounding is relative to the grid's scale: a 1e-13 m step survives."""
    doc = base_scene()
    doc["stop"] = {"restitution": 0.2}
    doc["sweep"]["clearance"] = {"start": 1e-12, "stop": 2e-12, "num": 11}
    scene = parse_scene(doc)
    np.testing.assert_allclose(scene.settings.clearance, np.linspace(1e-12, 2e-12, 11), rtol=1e-12)


def test_infinite_upper_bound_is_printed_open() -> None:
    assert problems_of(scene_with(_set("system", "m1", float("inf")))) == ["system.m1: inf is out of range: allowed (0, inf)"]


def test_yaml_12_exponent_numbers_are_floats(tmp_path: Path) -> None:
    """`3e-3` and `2.5e4` are numbers (YAML 1.2), not strings as PyYAML's YAML 1.1 default would have it."""
    doc = yaml.safe_dump(base_scene()).replace("clearance: 0.003", "clearance: 3e-3").replace("k1: 25000.0", "k1: 2.5e4")
    assert "3e-3" in doc and "2.5e4" in doc
    path = tmp_path / "exp.yaml"
    path.write_text(doc, encoding="utf-8")
    scene = load_scene(path)
    assert scene.settings.clearance[0] == 0.003 and scene.layout.paper_view().k1 == 25000.0  # exact: parsed input


def test_total_grid_size_is_bounded() -> None:
    doc = base_scene()
    doc["stop"] = {}
    doc["sweep"] = {"restitution": {"start": 0, "stop": 1, "num": 1000}, "clearance": {"start": 0, "stop": 1, "num": 1000}, "frequency": {"start": 1, "stop": 2, "num": 1000}}
    assert problems_of(doc) == ["sweep: 1,000,000,000 points (product of the swept grids) is too many: allowed at most 10,000,000"]


def test_bare_name_without_extension(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    assert find_scene("restitution") == shipped_studies_dir() / "restitution.yaml"


def test_cli_out_is_an_existing_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = write_yaml(tmp_path / "tiny.yaml", base_scene())
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert cli.main([str(path), "--out", str(blocker)]) == 2
    assert "--out" in capsys.readouterr().err


def test_pgf_paper_needs_two_underdamped_modes() -> None:
    doc = base_scene()
    doc["system"]["b2"] = 200.0
    doc["solutions"] = ["pgf", "pgf_paper"]
    assert problems_of(doc) == ["solutions: pgf_paper needs two underdamped modes (the paper's eq. 10 fit); this system has 1"]


# ----------------------------------------------------------------------------- simulation and benchmark sections
def _with_engines(**simulation: Any) -> dict[str, Any]:
    doc = base_scene()
    doc["solutions"] = ["pgf", "momentary", "exact"]
    if simulation:
        doc["simulation"] = simulation
    return doc


def test_simulation_defaults_to_the_analytic_grid() -> None:
    scene = parse_scene(_with_engines())
    assert scene.settings.simulation is not None and scene.settings.simulation.start == "pgf"
    np.testing.assert_array_equal(scene.settings.simulation.frequency, scene.settings.frequency)


def test_simulation_grid_is_merged_into_the_frequency_axis() -> None:
    scene = parse_scene(_with_engines(frequency=[20.25, 21.0], start="sweep_up", rtol=1e-7, max_periods=50))
    assert 20.25 in scene.settings.all_frequencies and scene.settings.all_frequencies.size == scene.settings.frequency.size + 1
    assert scene.settings.simulation is not None and scene.settings.simulation.engine.rtol == 1e-7 and scene.settings.simulation.steady.max_periods == 50  # exact: parsed input


@pytest.mark.parametrize(
    ("simulation", "fragment"),
    [
        ({"start": "middle"}, "simulation.start: 'middle' is not allowed: allowed linear, pgf, rest, shooting, sweep_up, sweep_down"),
        ({"rtol": 5.0}, "simulation.rtol: 5.0 is out of range: allowed [1e-15, 0.1]"),
        ({"method": "rk4"}, "simulation.method: 'rk4' is not allowed: allowed adams, bdf"),
        ({"max_periods": 0}, "simulation.max_periods: 0 is out of range: allowed [1, 100000000]"),
        ({"frequency": [-1.0]}, "simulation.frequency[0]: -1.0 is out of range"),
        ({"colour": 1}, "simulation.colour: unknown key"),
    ],
)
def test_bad_simulation_settings(simulation: dict[str, Any], fragment: str) -> None:
    problems = problems_of(_with_engines(**simulation))
    assert any(p.startswith(fragment) for p in problems), problems


def test_simulation_without_engine_solutions_is_an_error() -> None:
    doc = base_scene()
    doc["simulation"] = {"start": "pgf"}
    assert problems_of(doc) == ["simulation: given, but no time-domain solution (exact, momentary, compliant, compliant_exact) is asked for"]


def test_shipped_engine_cost_scene_parses() -> None:
    scene = load_scene(shipped_studies_dir() / "engine_cost.yaml")
    assert scene.settings is not None and len(scene.settings.cases) == 4
    assert scene.settings.settings.tolerances[0] > scene.settings.settings.tolerances[-1]  # loose to tight


@pytest.mark.parametrize(
    ("change", "fragment"),
    [
        (lambda b: b.update(methods=["euler"]), "benchmark.methods[0]: unknown name 'euler'"),
        (lambda b: b["cases"][0].pop("start"), "benchmark.cases[0].start: required key is missing"),
        (lambda b: b["cases"][0].update(clearance=0.003), "benchmark.cases[0]: give exactly one of 'clearance' [m] or 'clearance_below_linear' [m]"),
        (lambda b: b.update(cases=[]), "benchmark.cases: expected a non-empty list"),
    ],
)
def test_bad_benchmark_scenes(change: Callable[[dict[str, Any]], Any], fragment: str) -> None:
    doc = yaml.safe_load((shipped_studies_dir() / "engine_cost.yaml").read_text())
    doc["benchmark"]["cases"] = doc["benchmark"]["cases"][2:]  # the grazing case: clearance_below_linear
    change(doc["benchmark"])
    with pytest.raises(SceneError) as caught:
        parse_scene(doc)
    assert any(p.startswith(fragment) for p in caught.value.problems), caught.value.problems


def test_benchmark_scene_checks_the_common_header() -> None:
    """Name, description, system, excitation and report are checked alike in benchmark scenes."""
    doc = yaml.safe_load((shipped_studies_dir() / "engine_cost.yaml").read_text())
    doc["report"] = "yes"
    doc["description"] = 3
    del doc["system"]
    with pytest.raises(SceneError) as caught:
        parse_scene(doc)
    assert caught.value.problems == [
        "system: required key is missing",
        "description: expected a string, got 3 (int)",
        "report: expected a boolean (true or false), got 'yes' (str); YAML 1.2 booleans are true and false",
    ]
