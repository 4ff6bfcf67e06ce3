"""The kinds of study, each a type with its run and its estimate, chosen once by :attr:`Scene.kind`.

A kind runs a validated scene into one dataset and predicts what that costs on the calibration machine (the caller
scales it to this machine, :func:`vibroimpact.study.estimate.estimate_scene`). A new kind is one class with these two
methods and one line in :data:`KINDS` (and its name in :attr:`vibroimpact.scene.schema.Scene.kind`).
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType
from typing import Protocol

import xarray as xr

from vibroimpact.scene.schema import Scene
from vibroimpact.study.benchmark import BenchmarkStudy
from vibroimpact.study.bifurcation import BifurcationStudy
from vibroimpact.study.concepts import ConceptsStudy
from vibroimpact.study.validation import ValidationStudy
from vibroimpact.study.cost_model import Costs, Estimate
from vibroimpact.study.grid import Progress
from vibroimpact.study.runner import Runner
from vibroimpact.study.stepped import SteppedStudy
from vibroimpact.study.swept import SweptStudy

__all__ = ["StudyKind", "KINDS", "study_kind"]


class StudyKind(Protocol):
    """What a kind of study does with a scene."""

    @property
    def name(self) -> str:
        """The kind's name, as :attr:`Scene.kind` says it and datasets record it (``study_kind``)."""
        ...

    def run(self, scene: Scene, progress: Progress | None, runner: Runner) -> xr.Dataset:
        """The scene's dataset; ``progress`` receives a line per finished step (None: silence); its work runs in
        ``runner`` (this process, a local dask cluster or a running one), which keeps finished work in its store."""
        ...

    def estimate(self, scene: Scene, jobs: int, costs: Costs) -> Estimate:
        """The predicted wall time and memory of running the scene with ``jobs`` processes, on the calibration machine."""
        ...


#: Every kind of study by name.
KINDS: Mapping[str, StudyKind] = MappingProxyType({kind.name: kind for kind in (SteppedStudy(), SweptStudy(), BenchmarkStudy(), BifurcationStudy(), ValidationStudy(), ConceptsStudy())})


def study_kind(scene: Scene) -> StudyKind:
    """The kind of study ``scene`` is."""
    return KINDS[scene.kind]
