"""Every kind of study, in one table: the scene section that makes a scene of that kind, and where the kind's code is.

A kind is one folder, ``vibroimpact/kinds/<kind>/``: its scene section (``scene.py``), its run and estimate
(``study.py``, with the cases it sends to the runner and the dataset it writes) and its report page (``page.py``).
The table names them by import string (``"module:attribute"``), so reading a scene imports the kind's scene parser
only, never a solver; a study imports its kind's run when it runs and a report its page when it is drawn. A new kind
is its folder plus one row here.

The order of the rows is the one precedence of kinds: a scene is of the first kind whose section it has
(:func:`kind_of_document` for a YAML document, :attr:`vibroimpact.scene.schema.Scene.kind` for a checked scene); the
last row, with no section, takes every other scene.
"""

from __future__ import annotations

import importlib
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

__all__ = ["Kind", "KINDS", "KIND_NAMES", "kind_of_document", "kind_named"]


@dataclass(frozen=True)
class Kind:
    """One kind of study and where its code is.

    Attributes
    ----------
    name : str
        The kind's name, as :attr:`~vibroimpact.scene.schema.Scene.kind` says it and datasets record it
        (attribute ``study_kind``).
    section : str or None
        The scene key (and :class:`~vibroimpact.scene.schema.Scene` field) whose presence makes a scene this kind;
        None for the kind that takes every scene no earlier row claims.
    scene : str
        ``"module:function"`` that checks a YAML document of this kind into a scene,
        ``function(document, text, source) -> Scene``; it imports no solver.
    study : str
        ``"module:class"`` of the kind's study: ``run(scene, progress, runner)`` and ``estimate(scene, jobs, costs)``.
    page : str
        ``"module:function"`` that chooses the report page of a dataset of this kind, ``function(dataset) -> page``.
    shares_work : bool
        Whether the kind's run shares its work among a runner's dask workers (then a local cluster starts before the
        kind's code is imported, its workers starting meanwhile); False: it runs in the study's process (timings a
        starting cluster would disturb).
    title : str
        What the kind's datasets say they are (attribute ``title``, after ``vibroimpact``): a ``str.format`` template
        of the scene's ``name`` and ``settings`` (:meth:`title_of`).
    """

    name: str
    section: str | None
    scene: str
    study: str
    page: str
    shares_work: bool = True
    title: str = "study '{name}'"

    def __post_init__(self) -> None:
        for field in ("scene", "study", "page"):
            module, _, attribute = getattr(self, field).partition(":")
            if not module.startswith("vibroimpact.kinds.") or not attribute.isidentifier():
                raise ValueError(f"kind {self.name!r}: {field} must be 'vibroimpact.kinds.<module>:<name>', got {getattr(self, field)!r}")

    def title_of(self, scene: Any) -> str:
        """The ``title`` of ``scene``'s dataset: ``vibroimpact`` and the kind's :attr:`title` of the scene's name and
        settings (``vibroimpact design 'paper'``, ``vibroimpact validation 'zeno': zeno``)."""
        return f"vibroimpact {self.title.format(name=scene.name, settings=scene.settings)}"

    def parse_scene(self, document: dict, text: str, source: str) -> Any:
        """Check ``document`` as a scene of this kind (the kind's scene parser, imported now)."""
        return _resolve(self.scene)(document, text, source)

    def sections(self) -> tuple[Any, ...]:
        """The kind's declared scene sections (:class:`~vibroimpact.scene.declared.Section`: the ``SECTIONS`` of its
        scene module; imports the scene parser only)."""
        module, _, _ = self.scene.partition(":")
        return tuple(getattr(importlib.import_module(module), "SECTIONS", ()))

    def make_study(self) -> Any:
        """The kind's study object (imports its run)."""
        return _resolve(self.study)()

    def page_for(self, dataset: Any) -> Any:
        """The report page of ``dataset`` (imports the kind's page)."""
        return _resolve(self.page)(dataset)


def _resolve(target: str) -> Any:
    module, _, attribute = target.partition(":")
    return getattr(importlib.import_module(module), attribute)


#: Every kind of study, first match first (see the module's docstring).
KINDS: tuple[Kind, ...] = (
    Kind("design", "design", "vibroimpact.kinds.design.scene:parse_design_scene", "vibroimpact.kinds.design.study:DesignStudy", "vibroimpact.kinds.design.page:page_for", title="design '{name}'"),
    Kind("concepts", "concepts", "vibroimpact.kinds.concepts.scene:parse_concepts_scene", "vibroimpact.kinds.concepts.study:ConceptsStudy", "vibroimpact.kinds.concepts.page:page_for", title="absorber concepts '{name}'"),
    Kind("validation", "validation", "vibroimpact.kinds.validation.scene:parse_validation_scene", "vibroimpact.kinds.validation.study:ValidationStudy", "vibroimpact.kinds.validation.page:page_for", shares_work=False, title="validation '{name}': {settings.name}"),
    Kind("benchmark", "benchmark", "vibroimpact.kinds.benchmark.scene:parse_benchmark_scene", "vibroimpact.kinds.benchmark.study:BenchmarkStudy", "vibroimpact.kinds.benchmark.page:page_for", shares_work=False, title="benchmark '{name}'"),
    Kind("bifurcation", "bifurcation", "vibroimpact.kinds.bifurcation.scene:parse_bifurcation_scene", "vibroimpact.kinds.bifurcation.study:BifurcationStudy", "vibroimpact.kinds.bifurcation.page:page_for", title="bifurcation study '{name}'"),
    Kind("swept", "swept_sine", "vibroimpact.kinds.swept.scene:parse_swept_scene", "vibroimpact.kinds.swept.study:SweptStudy", "vibroimpact.kinds.swept.page:page_for"),
    Kind("stepped", None, "vibroimpact.kinds.stepped.scene:parse_stepped_scene", "vibroimpact.kinds.stepped.study:SteppedStudy", "vibroimpact.kinds.stepped.page:page_for"),
)  # fmt: skip

#: The kinds' names, in the table's order.
KIND_NAMES: tuple[str, ...] = tuple(kind.name for kind in KINDS)
_BY_NAME: Mapping[str, Kind] = {kind.name: kind for kind in KINDS}


def kind_of_document(document: Mapping[str, Any]) -> Kind:
    """The kind of a parsed YAML scene: the first row whose section the document has."""
    return next(kind for kind in KINDS if kind.section is None or kind.section in document)


def kind_named(name: str) -> Kind:
    """The kind called ``name``; ``KeyError`` naming the known kinds otherwise."""
    try:
        return _BY_NAME[name]
    except KeyError:
        raise KeyError(f"no kind of study called {name!r}; the kinds are {', '.join(KIND_NAMES)}") from None
