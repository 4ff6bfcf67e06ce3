"""The kinds of study are one vocabulary: every kind a scene can be has its run and estimate, and the shipped
scenes cover every kind."""

from __future__ import annotations

from vibroimpact.scene import load_scene
from vibroimpact.scene.locate import shipped_studies_dir
from vibroimpact.scene.schema import STUDY_KINDS
from vibroimpact.study.kinds import KINDS, study_kind


def test_every_kind_a_scene_can_be_has_a_study_type() -> None:
    assert tuple(KINDS) == STUDY_KINDS
    assert all(KINDS[name].name == name for name in KINDS)


def test_each_shipped_scene_is_run_by_the_type_of_its_kind() -> None:
    seen = set()
    for path in sorted(shipped_studies_dir().rglob("*.yaml")):  # validation scenes live in studies/validation/
        scene = load_scene(path)
        assert study_kind(scene) is KINDS[scene.kind]
        seen.add(scene.kind)
    assert seen == set(STUDY_KINDS), f"no shipped scene of kind {set(STUDY_KINDS) - seen}"
