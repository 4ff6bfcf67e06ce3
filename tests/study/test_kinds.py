"""The kinds of study are one table: every kind a scene can be has its scene section, its run and estimate and its
page, the precedence of kinds is the table's order, and the shipped scenes cover every kind."""

from __future__ import annotations

import pytest

from vibroimpact.runs.run import study_kind
from vibroimpact.scene import SceneError, load_scene, parse_scene
from vibroimpact.scene.kinds import KIND_NAMES, KINDS, Kind, kind_named, kind_of_document
from vibroimpact.scene.reader import shipped_studies_dir


def test_every_row_of_the_table_resolves_to_its_scene_parser_study_and_page() -> None:
    for kind in KINDS:
        study = kind.make_study()
        assert study.name == kind.name
        assert callable(study.run) and callable(study.estimate)
        for target in (kind.scene, kind.page):
            module, _, attribute = target.partition(":")
            assert callable(getattr(__import__(module, fromlist=[attribute]), attribute)), target
    assert [kind.section for kind in KINDS].count(None) == 1 and KINDS[-1].section is None  # the last row takes the rest
    assert len(set(KIND_NAMES)) == len(KINDS)


def test_each_shipped_scene_is_run_by_the_study_of_its_kind() -> None:
    seen = set()
    for path in sorted(shipped_studies_dir().rglob("*.yaml")):  # validation scenes live in studies/validation/
        scene = load_scene(path)
        assert type(study_kind(scene)) is type(kind_named(scene.kind).make_study())
        assert study_kind(scene).name == scene.kind
        seen.add(scene.kind)
    assert seen == set(KIND_NAMES), f"no shipped scene of kind {set(KIND_NAMES) - seen}"


def test_a_scene_is_a_header_plus_its_kinds_own_settings() -> None:
    """Every kind's settings live in its own folder (stepped and swept scenes share the grid grammar's), and the
    scene itself carries no field of any kind: only the header every kind shares."""
    from dataclasses import fields

    from vibroimpact.scene.schema import Scene

    header = {"name", "description", "layout", "amplitude", "kind", "settings", "report", "text", "cluster_scheduler"}
    assert {f.name for f in fields(Scene)} == header
    for path in sorted(shipped_studies_dir().rglob("*.yaml")):
        scene = load_scene(path)
        home = "vibroimpact.scene.grid" if scene.kind in ("stepped", "swept") else f"vibroimpact.kinds.{scene.kind}."  # the grid grammar is two kinds'
        assert type(scene.settings).__module__.startswith(home), (path.name, type(scene.settings))
    with pytest.raises(ValueError, match="settings"):
        Scene("s", "", scene.layout, 1.0, "stepped", None)


def test_the_precedence_of_kinds_is_the_table_order_for_documents_and_scenes() -> None:
    """A document with two kinds' sections is the earlier row's kind, when read and when asked of the scene: the one
    precedence, spelled once. The later section is then a key that kind does not take: an error naming it."""
    assert kind_of_document({"concepts": {}, "bifurcation": {}}).name == "concepts"
    assert kind_of_document({"swept_sine": {}}).name == "swept"
    assert kind_of_document({"name": "x"}).name == "stepped"
    base = {"name": "s", "system": {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0}, "excitation": {"amplitude": 10.0}, "stop": {"clearance": 0.003}}
    document = base | {"bifurcation": {"restitution": 0.2, "frequency": {"start": 20.0, "stop": 30.0}}, "swept_sine": {"rate": 1.0}}
    with pytest.raises(SceneError, match="swept_sine"):
        parse_scene(document)


def test_a_row_names_modules_of_the_kinds_package() -> None:
    with pytest.raises(ValueError, match="study"):
        Kind("x", "x", "vibroimpact.kinds.x.scene:parse", "vibroimpact.runs.run:run_study", "vibroimpact.kinds.x.page:page_for")
    with pytest.raises(KeyError, match="stepped"):
        kind_named("nonsense")


@pytest.mark.parametrize(
    ("extra", "kind", "owner"),
    [
        ({"sweep": {}}, "bifurcation", None),
        ({"simulation": {}}, "bifurcation", None),
        ({"concepts_typo": {}}, "bifurcation", None),
    ],
)
def test_a_key_the_kind_does_not_use_is_an_error_naming_the_kind(extra: dict, kind: str, owner: str | None) -> None:
    document = {"name": "s", "system": {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0}, "excitation": {"amplitude": 10.0}, "stop": {"clearance": 0.003},
                "bifurcation": {"restitution": [0.2], "frequency": {"start": 20.0, "stop": 30.0}}} | extra  # fmt: skip
    with pytest.raises(SceneError) as caught:
        parse_scene(document)
    key = next(iter(extra))
    assert f"{key}: unknown key: a {kind} scene does not use it (allowed: " in "\n".join(caught.value.problems)


def test_another_kinds_section_is_named_as_such() -> None:
    document = {"name": "v", "validation": {"case": "zeno"}, "concepts": {}}  # concepts comes first in the table
    with pytest.raises(SceneError) as caught:
        parse_scene(document)
    assert any(p.startswith("validation: unknown key: a concepts scene does not use it; it is the section of a validation scene") for p in caught.value.problems)


def test_a_kind_is_its_folder_one_row_one_shipped_scene_and_one_golden_scene() -> None:
    """Adding a kind touches its own folder, one row of the table, one shipped scene and one golden scene: the row
    names modules of the kind's folder only, no module outside that folder imports it (the table loads it by name),
    and a shipped scene and a golden scene of the kind exist (the golden suite then holds it bit for bit)."""
    import ast
    from pathlib import Path

    from tests.golden.golden import SCENES

    package = Path(__file__).resolve().parents[2] / "src" / "vibroimpact"
    for kind in KINDS:
        folder = package / "kinds" / kind.name
        assert {"scene.py", "study.py", "page.py"} <= {p.name for p in folder.glob("*.py")}, kind.name
        assert all(target.startswith(f"vibroimpact.kinds.{kind.name}.") for target in (kind.scene, kind.study, kind.page)), kind
    for path in package.rglob("*.py"):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        targets = [node.module or "" for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)]
        targets += [alias.name for node in ast.walk(tree) if isinstance(node, ast.Import) for alias in node.names]
        inside = path.relative_to(package).parts
        for target in targets:
            parts = target.split(".")
            if parts[:2] == ["vibroimpact", "kinds"] and len(parts) > 2:
                known = {(("kinds", "swept"), "stepped"), (("cli.py",), "benchmark")}  # the grid kinds; run-study sweep-cost
                assert inside[:2] == ("kinds", parts[2]) or (inside[:2], parts[2]) in known, f"{path.name} imports {target}"
    golden = {parse_scene_file(path).kind for path in SCENES.glob("*.yaml")}
    assert golden == set(KIND_NAMES), f"no golden scene of kind {set(KIND_NAMES) - golden}"


def parse_scene_file(path):  # type: ignore[no-untyped-def]
    """The checked scene of a YAML file."""
    return load_scene(path)

