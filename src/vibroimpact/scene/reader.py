"""Reading a scene: YAML text -> parsed document -> validated :class:`~vibroimpact.scene.schema.Scene`.

A scene is read with a safe YAML loader (no Python objects; a repeated key is an error) and checked completely
before any work starts: every unknown key, wrong type or out-of-range value is reported (all of them at once, each
naming its key and the allowed range) in one :class:`SceneError`. Example (all values SI, frequencies in Hz)::

    name: restitution
    system: {m1: 1.0, m2: 0.1, k1: 25000, k2: 4300, b1: 0.8, b2: 0.08}
    excitation: {amplitude: 10.0}
    stop: {clearance: 0.003}
    sweep:
      restitution: [0.0, 0.2, 0.4, 0.6, 0.8]
      frequency: {start: 15.0, stop: 45.0, step: 0.005}
    solutions: [linear, pgf, pgf_paper]
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import yaml

from vibroimpact.scene.benchmark import parse_benchmark_scene
from vibroimpact.scene.bifurcation import parse_bifurcation_scene
from vibroimpact.scene.concepts import parse_concepts_scene
from vibroimpact.scene.validation import parse_validation_scene
from vibroimpact.scene.checker import SceneError
from vibroimpact.scene.schema import Scene
from vibroimpact.scene.sections import TOP_KEYS, parse_grid_scene

__all__ = ["read_yaml", "parse_scene", "load_scene"]


class _UniqueKeyLoader(yaml.SafeLoader):
    """``yaml.SafeLoader`` that refuses a key repeated in one mapping (PyYAML silently keeps the last one) and reads
    YAML 1.2 numbers such as ``3e-3`` as floats (YAML 1.1, PyYAML's default, reads them as strings) and YAML 1.2
    booleans (``true``/``false`` only: ``on``, ``off``, ``yes``, ``no`` stay strings, so ``on: x1`` is a key)."""

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        seen: set[Any] = set()
        for key_node, _value_node in node.value:
            key = self.construct_object(key_node, deep=deep)
            if key in seen:
                raise yaml.constructor.ConstructorError(None, None, f"key {key!r} is repeated", key_node.start_mark)
            seen.add(key)
        return super().construct_mapping(node, deep=deep)


# YAML 1.2 booleans: only true/false (YAML 1.1 also reads on/off/yes/no as booleans, so `on: x1` lost its key)
_UniqueKeyLoader.yaml_implicit_resolvers = {
    first: [(tag, regexp) for tag, regexp in resolvers if tag != "tag:yaml.org,2002:bool"]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
_UniqueKeyLoader.add_implicit_resolver("tag:yaml.org,2002:bool", re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"), list("tTfF"))
_UniqueKeyLoader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"),
    list("-+0123456789"),
)


def read_yaml(text: str) -> Any:
    """Parse YAML safely (no Python objects), rejecting repeated keys."""
    return yaml.load(text, Loader=_UniqueKeyLoader)  # noqa: S506 - a SafeLoader subclass


def parse_scene(document: Any, text: str = "", source: str = "scene") -> Scene:
    """Validate a parsed YAML document and build the :class:`Scene`; raise :class:`SceneError` listing all problems.

    A document with a ``benchmark``, ``concepts``, ``validation`` or ``bifurcation`` section is a scene of that
    kind; any other is a scene over parameter grids.
    """
    if not isinstance(document, dict):
        what = "an empty document" if document is None else f"a {type(document).__name__}"
        raise SceneError([f"scene: expected a mapping with keys {sorted(TOP_KEYS)}, got {what}"], source)
    if "benchmark" in document:
        return parse_benchmark_scene(document, text, source)
    if "concepts" in document:
        return parse_concepts_scene(document, text, source)
    if "validation" in document:
        return parse_validation_scene(document, text, source)
    if "bifurcation" in document:
        return parse_bifurcation_scene(document, text, source)
    return parse_grid_scene(document, text, source)


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file; raise :class:`SceneError` (or ``OSError`` if it cannot be read)."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as error:
        raise SceneError([f"not UTF-8 text: {error}"], str(path)) from None
    try:
        document = read_yaml(text)
    except yaml.YAMLError as error:
        for mark in (getattr(error, "context_mark", None), getattr(error, "problem_mark", None)):
            if mark is not None:
                mark.name = str(path)  # PyYAML names a parsed string "<unicode string>"
        raise SceneError([f"not valid YAML: {error}"], str(path)) from None
    return parse_scene(document, text=text, source=str(path))
