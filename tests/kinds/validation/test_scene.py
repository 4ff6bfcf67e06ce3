"""Validation scenes: every shipped one reads, every problem of a bad one is reported with its key."""

from __future__ import annotations

from pathlib import Path

import pytest

from vibroimpact.scene.checker import SceneError
from vibroimpact.scene.reader import read_yaml
from vibroimpact.kinds.validation.scene import read_validation_scene
from vibroimpact.kinds.validation.settings import CASE_PARAMETERS, VALIDATION_CASES, BuddDuxCase

STUDIES = Path(__file__).resolve().parents[3] / "studies" / "validation"


def _read(text: str):
    return read_validation_scene(read_yaml(text), text)


def test_every_case_has_a_shipped_scene() -> None:
    """One scene per case under studies/validation/, each read without a problem and naming its case."""
    names = {}
    for path in sorted(STUDIES.glob("*.yaml")):
        scene = read_validation_scene(read_yaml(path.read_text(encoding="utf-8")), source=str(path))
        names[scene.settings.name] = path.stem
        assert scene.description
    assert set(names) == set(VALIDATION_CASES)


def test_defaults_and_ranges() -> None:
    """A scene giving only the case gets the dataclass defaults; every key of a case has a parameter entry."""
    scene = _read("name: bd\nvalidation: {case: budd_dux}")
    assert scene.settings.case == BuddDuxCase()
    for name, cls in VALIDATION_CASES.items():
        assert set(CASE_PARAMETERS[name]) == {f for f in cls.__dataclass_fields__}


def test_every_problem_is_reported_with_its_key() -> None:
    """Unknown keys, out-of-range values, reversed ranges and unknown engines, all at once."""
    with pytest.raises(SceneError) as error:
        _read("name: bd\nvalidation: {case: budd_dux, restitution: 1.5, foo: 1, clearance: {start: 0.1, stop: -0.1}}")
    problems = "\n".join(error.value.problems)
    assert "validation.foo: unknown key" in problems
    assert "validation.restitution: 1.5 is out of range" in problems
    assert "validation.clearance.stop" in problems
    with pytest.raises(SceneError, match=r"validation.engines\[1\]: unknown name 'bar'"):
        _read("name: z\nvalidation: {case: zeno, engines: [exact, bar]}")
    with pytest.raises(SceneError, match="validation.case: 'nope' is not allowed"):
        _read("name: z\nvalidation: {case: nope}")
    with pytest.raises(SceneError, match="validation.clearance.stop: 0.2 is out of range: allowed below"):
        _read("name: z\nvalidation: {case: budd_dux, clearance: {start: -0.5, stop: 0.2}}")
    with pytest.raises(SceneError, match="validation.start_clearance"):
        _read("name: z\nvalidation: {case: budd_dux, start_clearance: 0.13, clearance: {start: -0.5, stop: 0.1}}")
    with pytest.raises(SceneError, match="unknown key"):
        _read("name: z\nsystem: {}\nvalidation: {case: zeno}")
