"""YAML scenes -> validated, frozen :class:`Scene` objects. Imports no engine, no solver library and no xarray.

The grammar every kind shares: ``schema`` (what a scene says: the dataclasses, vocabulary and limits), ``checker``
(problem-collecting checks and :class:`SceneError`), ``header`` (what every scene has: name, description, report,
cluster), ``layout_parse`` (the system, excitation and stops sections, read into one
:class:`~vibroimpact.model.layout.Layout`), ``simulation`` and ``subset`` (the ``simulation`` section), ``grid`` (the
grid grammar of the stepped and swept kinds), ``variables`` (units, long names and flags of the variables more than
one kind writes), ``kinds`` (the table of kinds: which section makes a scene of which kind, and where each kind's
scene parser, run and page are) and ``reader`` (safe YAML, :func:`parse_scene`, :func:`load_scene`, named and shipped
scenes). A kind's own section is checked by its folder's ``scene`` module (``vibroimpact.kinds.<kind>.scene``),
imported only when a scene of that kind is read.
"""

from vibroimpact.scene.checker import SceneError
from vibroimpact.scene.reader import find_scene, shipped_studies, shipped_studies_dir, load_scene, parse_scene, read_yaml
from vibroimpact.scene.schema import Scene

__all__ = ["Scene", "SceneError", "find_scene", "load_scene", "parse_scene", "read_yaml", "shipped_studies", "shipped_studies_dir"]
