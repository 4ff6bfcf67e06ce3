"""YAML scenes -> validated, frozen :class:`Scene` objects. Imports no engine, no solver library and no xarray."""

from vibroimpact.scene.core import Scene, SceneError, find_scene, load_scene, parse_scene, shipped_studies

__all__ = ["Scene", "SceneError", "find_scene", "load_scene", "parse_scene", "shipped_studies"]
