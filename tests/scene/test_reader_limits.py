"""Bounded inputs (issue 22, items 5 and 7): a scene cannot make the reader expand aliases without bound, a number
too long to read, a device or a repeated key are refused in one message (exit 2 from run-study); the merge key works
as ``yaml.safe_load`` reads it; a long value quoted in a message is cut."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from vibroimpact.scene import SceneError, find_scene, load_scene
from vibroimpact.scene.reader import MAX_EXPANDED_NODES, read_yaml


def _laughs(levels: int) -> str:
    lines = ['a0: &a0 ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]']
    lines += [f"a{n}: &a{n} [{', '.join([f'*a{n - 1}'] * 9)}]" for n in range(1, levels)]
    return "\n".join(lines) + f"\nname: *a{levels - 1}\n"


def test_aliases_that_multiply_are_refused_before_they_are_expanded() -> None:
    with pytest.raises(yaml.YAMLError, match=f"its aliases expand to more than {MAX_EXPANDED_NODES} values"):
        read_yaml(_laughs(9))  # 9**9 = 387 million strings, counted on the node graph, never expanded (~ms)
    assert len(read_yaml(_laughs(4))["name"]) == 9  # 9**4 = 6561 values: a scene may use aliases
    recursive = "a: &a [*a]\n"
    with pytest.raises(yaml.YAMLError):
        read_yaml(recursive)


def test_the_merge_key_works_and_a_repeated_key_is_still_refused() -> None:
    text = "defaults: &d {m1: 1.0, m2: 0.1}\nsystem:\n  <<: *d\n  m2: 0.2\n"
    assert read_yaml(text)["system"] == {"m1": 1.0, "m2": 0.2}  # as yaml.safe_load: the mapping's own key wins
    assert yaml.safe_load(text)["system"] == {"m1": 1.0, "m2": 0.2}
    with pytest.raises(yaml.YAMLError, match="key 'm2' is repeated"):
        read_yaml("system: {m2: 0.1, m2: 0.2}\n")


def test_a_number_too_long_to_read_is_a_scene_error(tmp_path: Path) -> None:
    path = tmp_path / "long.yaml"
    path.write_text(f"name: long\nsystem: {{m1: {'9' * 5001}}}\n")
    with pytest.raises(SceneError, match=r"a number cannot be read: Exceeds the limit \(4300 digits\)") as raised:
        load_scene(path)
    assert "set_int_max_str_digits" not in str(raised.value)


def test_a_device_is_not_a_scene_and_long_values_are_cut_in_messages() -> None:
    with pytest.raises(OSError, match="is not a regular file"):
        find_scene("/dev/zero")
    error = SceneError(["name: " + "x" * 5000])
    assert len(error.problems[0]) < 450 and error.problems[0].endswith("... (5006 characters)")
