"""Where scenes are: a scene named on the command line, and the scenes shipped with the package."""

from __future__ import annotations

import importlib.resources
from pathlib import Path

import yaml

from vibroimpact.scene.reader import read_yaml

__all__ = ["find_scene", "shipped_studies_dir", "shipped_studies"]


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
