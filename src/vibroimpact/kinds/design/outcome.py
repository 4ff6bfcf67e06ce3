"""What a design study found, the content of its dataset (:class:`Outcome`): filled by the study
(:mod:`vibroimpact.kinds.design.study`), read by the dataset (:mod:`vibroimpact.kinds.design.dataset`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from vibroimpact.analysis.linear_optimum import LinearAbsorberOptimum
from vibroimpact.kinds.design.evaluate import DesignSpace
from vibroimpact.kinds.design.scene import DesignSettings
from vibroimpact.kinds.design.search import Evaluations

__all__ = ["Outcome"]


class Outcome:
    """What a design study found (the dataset's content): the evaluations, the certified candidates, the comparisons."""

    def __init__(self, settings: DesignSettings, space: DesignSpace, evaluations: Evaluations) -> None:
        self.settings = settings
        self.space = space
        self.evaluations = evaluations
        self.scene_design = np.array([space.map.parameters[space.map.parameter_names.index(n)] for n in settings.names])
        self.certified: list[dict[str, Any]] = []
        self.linear: LinearAbsorberOptimum | None = None
        self.linear_values = np.full(space.samples, np.nan)
        self.linear_operating = math.nan
        self.alone = math.nan
        self.recommended = -1
        self.corrected: dict[int, float] = {}
        self.corrected_operating: dict[int, float] = {}
        self.contradicted: list[int] = []
        self.box: dict[str, Any] = {}
        self.wall_times: dict[str, float] = {}
