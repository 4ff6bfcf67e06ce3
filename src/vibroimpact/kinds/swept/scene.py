"""The scene of a swept-sine study: the grid grammar (:mod:`vibroimpact.scene.grid`) of a scene with a
``swept_sine`` section (its :class:`~vibroimpact.scene.grid.SweptSineSettings`), the paper's Simulink test of section
5 run on the compliant bumper."""

from __future__ import annotations

from typing import Any

from vibroimpact.scene.grid import ADMISSIBILITY, GRID_SETTINGS, GRID_STOP, GRID_TOP, SWEEP, SWEPT_SINE, parse_grid_scene
from vibroimpact.scene.simulation import SIMULATION
from vibroimpact.scene.schema import Scene

__all__ = ["parse_swept_scene", "SECTIONS"]

#: The sections of a swept scene that are declared (``run-study --keys`` lists them).
SECTIONS = (GRID_TOP, SWEEP, GRID_STOP, SWEPT_SINE, SIMULATION, GRID_SETTINGS, ADMISSIBILITY)


def parse_swept_scene(document: Any, text: str = "", source: str = "scene") -> Scene:
    """Validate a swept-sine scene's document (the grid grammar with ``swept_sine``) and build the :class:`Scene`;
    raise :class:`~vibroimpact.scene.checker.SceneError` listing all problems."""
    return parse_grid_scene(document, text, source)
