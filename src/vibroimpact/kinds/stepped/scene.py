"""The scene of a stepped study: the grid grammar (:mod:`vibroimpact.scene.grid`) of a scene without a
``swept_sine`` section: steady states stepped over a grid of frequencies, restitutions, clearances and bumpers."""

from __future__ import annotations

from typing import Any

from vibroimpact.scene.grid import ADMISSIBILITY, GRID_SETTINGS, GRID_STOP, GRID_TOP, SWEEP, parse_grid_scene
from vibroimpact.scene.simulation import SIMULATION
from vibroimpact.scene.schema import Scene

__all__ = ["parse_stepped_scene", "SECTIONS"]

#: The sections of a stepped scene that are declared (``run-study --keys`` lists them).
SECTIONS = (GRID_TOP, SWEEP, GRID_STOP, SIMULATION, GRID_SETTINGS, ADMISSIBILITY)


def parse_stepped_scene(document: Any, text: str = "", source: str = "scene") -> Scene:
    """Validate a stepped scene's document (the grid grammar) and build the :class:`Scene`; raise
    :class:`~vibroimpact.scene.checker.SceneError` listing all problems."""
    return parse_grid_scene(document, text, source)
