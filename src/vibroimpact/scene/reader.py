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

import importlib.resources
import re
from pathlib import Path
from typing import Any

import yaml

from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.scene.checker import SceneError
from vibroimpact.scene.kinds import KINDS, kind_of_document
from vibroimpact.scene.schema import Scene

__all__ = ["read_yaml", "parse_scene", "load_scene", "scene_text", "find_scene", "shipped_studies_dir", "shipped_studies"]

class _UniqueKeyLoader(yaml.SafeLoader):
    """``yaml.SafeLoader`` that refuses a key repeated in one mapping (PyYAML silently keeps the last one) and reads
    YAML 1.2 numbers such as ``3e-3`` as floats (YAML 1.1, PyYAML's default, reads them as strings) and YAML 1.2
    booleans (``true``/``false`` only: ``on``, ``off``, ``yes``, ``no`` stay strings, so ``on: x1`` is a key)."""

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        seen: set[Any] = set()
        for key_node, _value_node in node.value:
            if key_node.tag == "tag:yaml.org,2002:merge":  # `<<: *defaults`: merged below, its keys overridable
                continue
            key = self.construct_object(key_node, deep=deep)
            if key in seen:
                raise yaml.constructor.ConstructorError(None, None, f"key {key!r} is repeated", key_node.start_mark)
            seen.add(key)
        return super().construct_mapping(node, deep=deep)  # SafeConstructor's: flattens merge keys first


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


#: Most nodes a scene may hold once its aliases are expanded (the largest shipped scene holds a few hundred): aliases
#: that multiply (`a: [*b, *b, ...]` nested, "billion laughs") are refused before anything reads the values.
MAX_EXPANDED_NODES = 100_000
#: Most characters a scene's values may hold once its aliases are expanded (the largest shipped scene is ~6 kB): a
#: long string repeated by aliases (a "bytes bomb": 90 000 aliases of 200 kB) is refused before anything reads it.
MAX_EXPANDED_CHARACTERS = 1_000_000


def read_yaml(text: str) -> Any:
    """Parse YAML safely (no Python objects), rejecting repeated keys, aliases that expand beyond
    :data:`MAX_EXPANDED_NODES` nodes, and numbers too long to read; the merge key ``<<`` works as in ``yaml.safe_load``.

    Raises
    ------
    yaml.YAMLError
        Naming the problem and, where it has one, its line.
    """
    loader = _UniqueKeyLoader(text)
    try:
        node = loader.get_single_node()
        if node is None:
            return None
        size = _expanded_size(node, {}, 0)
        if size > MAX_EXPANDED_NODES:
            raise yaml.YAMLError(f"its aliases expand to more than {MAX_EXPANDED_NODES} values (a scene needs a few hundred); refused before reading them")
        if _expanded_characters(node, {}) > MAX_EXPANDED_CHARACTERS:
            raise yaml.YAMLError(f"its values hold more than {MAX_EXPANDED_CHARACTERS} characters once its aliases are expanded (a scene holds a few thousand); refused before reading them")
        try:
            return loader.construct_document(node)
        except ValueError as error:  # Python's limit on the digits of an integer (4300), as PyYAML lets it through
            raise yaml.YAMLError(f"a number cannot be read: {str(error).split(';')[0]}") from None
    finally:
        loader.dispose()


def _expanded_size(node: yaml.Node, sizes: dict[int, int], depth: int) -> int:
    """Nodes under ``node`` with every alias expanded (shared nodes counted each time they are referred to)."""
    known = sizes.get(id(node))
    if known is not None:
        return known
    if depth > 100:  # deeper than any scene: as good as too large (and a recursive alias never ends)
        return MAX_EXPANDED_NODES + 1
    sizes[id(node)] = MAX_EXPANDED_NODES + 1  # a node met again while being counted: an alias of itself
    total = 1
    if isinstance(node, yaml.SequenceNode):
        for child in node.value:
            total += _expanded_size(child, sizes, depth + 1)
            if total > MAX_EXPANDED_NODES:
                break
    elif isinstance(node, yaml.MappingNode):
        for key, value in node.value:
            total += _expanded_size(key, sizes, depth + 1) + _expanded_size(value, sizes, depth + 1)
            if total > MAX_EXPANDED_NODES:
                break
    sizes[id(node)] = total
    return total


def _expanded_characters(node: yaml.Node, sizes: dict[int, int]) -> int:
    """Characters of the scalars under ``node`` with every alias expanded (after :func:`_expanded_size` bounded the
    nodes and their depth), counted up to just past :data:`MAX_EXPANDED_CHARACTERS`."""
    known = sizes.get(id(node))
    if known is not None:
        return known
    total = 0
    if isinstance(node, yaml.ScalarNode):
        total = len(node.value)
    else:
        children = node.value if isinstance(node, yaml.SequenceNode) else [part for pair in node.value for part in pair]
        for child in children:
            total += _expanded_characters(child, sizes)
            if total > MAX_EXPANDED_CHARACTERS:
                break
    sizes[id(node)] = total
    return total


@suggest_keywords
def parse_scene(document: Any, text: str = "", source: str = "scene") -> Scene:
    """Validate a parsed YAML document and build the :class:`Scene`; raise :class:`SceneError` listing all problems.
    Without ``text`` (a scene made in Python), the scene keeps the document written as YAML (:func:`scene_text`).

    The document is a scene of the first kind (:data:`vibroimpact.scene.kinds.KINDS`) whose section it has
    (``concepts``, ``validation``, ``benchmark``, ``bifurcation``, ``swept_sine``); any other is a stepped scene over
    parameter grids. Only that kind's scene parser is imported.
    """
    if not isinstance(document, dict):
        what = "an empty document" if document is None else f"a {type(document).__name__}"
        sections = ", ".join(kind.section for kind in KINDS if kind.section)
        raise SceneError([f"scene: expected a mapping of a scene's sections (name, system, excitation, ...; a kind's own: {sections}), got {what}"], source)
    kind = kind_of_document(document)
    scene: Scene = kind.parse_scene(document, text or scene_text(document), source)
    if scene.kind != kind.name:  # a parser that names another kind than its row: a broken table, not a user error
        raise RuntimeError(f"the scene parser of kind {kind.name!r} ({kind.scene}) made a scene of kind {scene.kind!r}")
    return scene


def scene_text(document: dict) -> str:
    """The YAML text of a scene given as a mapping (from Python, not a file): what the dataset and the page keep of
    it (its description, its stated spreads, the scene shown at the page's foot), as a file's text is kept. numpy
    numbers and arrays are written as the plain numbers and lists they hold."""

    def plain(value: Any) -> Any:
        if isinstance(value, dict):
            return {str(key): plain(item) for key, item in value.items()}
        if isinstance(value, (list, tuple)):
            return [plain(item) for item in value]
        return value.tolist() if hasattr(value, "tolist") else value

    try:
        return yaml.safe_dump(plain(document), sort_keys=False, allow_unicode=True)
    except yaml.YAMLError:  # a value YAML cannot write (an object): the scene's own checks say what is wrong with it
        return ""


@suggest_keywords
def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene, found as ``run-study`` finds it (:func:`find_scene`: a path, ``studies/<name>`` here,
    or a shipped scene such as ``restitution`` or ``validation/zeno``); raise :class:`SceneError` (or ``OSError`` if
    it cannot be found or read: ``FileNotFoundError`` names every place looked at)."""
    path = find_scene(path)
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
                mark.buffer = None  # line and column, never the line itself: the path may name a file that is not a scene
        raise SceneError([f"not valid YAML: {error}"], str(path)) from None
    return parse_scene(document, text=text, source=str(path))


# --------------------------------------------------------------------------------------------------------------------
# Where scenes are: a scene named on the command line, and the scenes shipped with the package.
# --------------------------------------------------------------------------------------------------------------------

@suggest_keywords
def find_scene(name: str | Path) -> Path:
    """Locate a scene: the path as given, else ``studies/<name>`` in the working directory, else the shipped one.

    A bare name may omit ``.yaml``. A local file wins over a shipped scene of the same name.

    Raises
    ------
    FileNotFoundError
        Naming every place looked at, each once.
    """
    given = Path(name)
    if given.is_dir():
        raise IsADirectoryError(f"scene {given} is a directory, not a YAML file")
    if given.exists() and not given.is_file():  # a device (/dev/zero would be read for ever), a pipe, a socket
        raise OSError(f"scene {given} is not a regular file (a device, pipe or socket); give a YAML file")
    candidates = [given]
    if not given.is_absolute():
        candidates.append(Path.cwd() / "studies" / given)
        candidates.append(shipped_studies_dir() / given)  # a shipped scene in a subfolder: validation/zeno.yaml
        candidates.append(shipped_studies_dir() / given.name)
    if given.suffix not in (".yaml", ".yml"):
        candidates += [c.with_name(c.name + ".yaml") for c in list(candidates)]
    unique: dict[Path, Path] = {}
    for candidate in candidates:
        unique.setdefault(candidate.resolve(), candidate)  # in a checkout ./studies is the shipped folder
    for candidate in unique.values():
        if candidate.is_file():
            return candidate
    raise FileNotFoundError("scene not found; looked at: " + ", ".join(str(p) for p in unique.values()))


def shipped_studies_dir() -> Path:
    """The shipped scenes: package data ``vibroimpact/studies`` (in a checkout, its top-level ``studies/``)."""
    return Path(str(importlib.resources.files("vibroimpact.studies")))


def shipped_studies() -> list[tuple[str, str]]:
    """Name and one-line description of every shipped scene, sorted by name (a scene that fails to load says so);
    a scene in a subfolder is named with it (``validation/zeno``), as ``run-study`` finds it."""
    listing = []
    root = shipped_studies_dir()
    for path in sorted(root.rglob("*.yaml"), key=lambda p: p.relative_to(root).with_suffix("").as_posix()):
        try:
            document = read_yaml(path.read_text(encoding="utf-8"))
            description = str(document.get("description", "")) if isinstance(document, dict) else ""
        except (OSError, UnicodeDecodeError, yaml.YAMLError) as error:
            description = f"(unreadable: {error})"
        listing.append((path.relative_to(root).with_suffix("").as_posix(), " ".join(description.split())))
    return listing
