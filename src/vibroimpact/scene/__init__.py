"""YAML scenes -> validated, frozen :class:`Scene` objects. Imports no engine, no solver library and no xarray.

``schema`` (what a scene says: the dataclasses, vocabulary and limits), ``checker`` (problem-collecting checks and
:class:`SceneError`), ``sections`` (the sections of a scene over parameter grids), ``benchmark`` (benchmark scenes),
``reader`` (safe YAML, :func:`parse_scene`, :func:`load_scene`), ``locate`` (named and shipped scenes).
"""

from vibroimpact.scene.checker import SceneError
from vibroimpact.scene.locate import find_scene, shipped_studies, shipped_studies_dir
from vibroimpact.scene.reader import load_scene, parse_scene, read_yaml
from vibroimpact.scene.schema import Scene

__all__ = ["Scene", "SceneError", "find_scene", "load_scene", "parse_scene", "read_yaml", "shipped_studies", "shipped_studies_dir"]
