"""A time-domain solution on part of a stepped study's simulation grid: the scene key ``simulation.subset``.

A cheap engine can cover the whole grid while a costly one checks it on a few points, in the same run::

    simulation:
      frequency: {start: 16.0, stop: 45.0, step: 0.25}
      subset:
        compliant: {frequency: [20.0, 24.0, 28.0], restitution: [0.2, 0.6]}

Each named solution is one of the scene's time-domain solutions; each axis is ``frequency`` (values of the
simulation's frequency grid [Hz]) or a swept parameter (``restitution``, ``clearance`` [m], ``bumper_frequency``
[Hz]: values of its sweep); an axis not named is kept whole. The solution's values elsewhere are not computed (NaN,
regime ``not_computed``), like the analytic grid's frequencies that are not simulated.
"""

from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np

from vibroimpact.scene.checker import Checker
from vibroimpact.scene.schema import SWEEPABLE, Scene
from vibroimpact.simulation.settings import SWEEP_STARTS

__all__ = ["SUBSET_AXES", "Subset", "parse_subset", "on_subset", "subset_axes", "subset_share", "subset_text"]

#: Axes a subset may restrict, with their units.
SUBSET_AXES = {"frequency": "Hz", "restitution": "-", "clearance": "m", "bumper_frequency": "Hz"}
#: solution -> axis -> the values kept (each one of the axis' grid values).
Subset = Mapping[str, Mapping[str, np.ndarray]]
#: Relative distance at which a scene's value names a grid value (YAML decimals against a generated grid).
_MATCH = 1e-9


def parse_subset(c: Checker, value: Any, engines: list[str], axes: Mapping[str, np.ndarray | None], start: str) -> dict[str, dict[str, np.ndarray]]:
    """``simulation.subset: {SOLUTION: {AXIS: values}}`` checked against the scene's time-domain solutions
    (``engines``), the grids of the swept ``axes`` (``frequency``: the simulation's) and the simulation's ``start``;
    every problem is recorded in ``c``. Returns the values snapped onto their grids (only the valid entries)."""
    subset: dict[str, dict[str, np.ndarray]] = {}
    if not isinstance(value, dict):
        c.fail("simulation.subset", f"expected a mapping {{solution: {{axis: values}}}}, got {value!r}")
        return subset
    swept = [axis for axis in SUBSET_AXES if axes.get(axis) is not None]
    for name, spec in value.items():
        key = f"simulation.subset.{name}"
        if name not in engines:
            c.fail(key, f"{name!r} is not a time-domain solution of this scene: use one of {', '.join(engines) or 'none (no engine is asked for)'}")
            continue
        kept = c.mapping(key, spec, set(SUBSET_AXES))
        if not kept and isinstance(spec, dict):
            c.fail(key, f"empty: name at least one axis of {', '.join(swept)}")
        chosen: dict[str, np.ndarray] = {}
        for axis, values in kept.items():
            place = f"{key}.{axis}"
            grid = axes.get(axis)
            if grid is None:
                c.fail(place, f"{axis} is not swept in this scene: a subset keeps values of the simulated frequencies or of a swept parameter ({', '.join(swept)})")
                continue
            if axis == "frequency" and start in SWEEP_STARTS:
                c.fail(place, f"a stepped sweep (start: {start}) follows every simulated frequency in one chain: a subset of them is another sweep; keep every frequency, or subset another axis")
                continue
            row = SWEEPABLE[axis]
            given = c.grid(place, values, row.low, row.high, row.low_inclusive)
            if given is None:
                continue
            snapped = _snap(c, place, given, grid, axis)
            if snapped is not None:
                chosen[axis] = snapped
        if chosen:
            subset[str(name)] = chosen
    return subset


def _snap(c: Checker, place: str, given: np.ndarray, grid: np.ndarray, axis: str) -> np.ndarray | None:
    """``given`` as values of ``grid`` (each within :data:`_MATCH` relative of one), or None with the problem recorded."""
    where = np.abs(given[:, None] - grid[None, :]) <= _MATCH * np.maximum(np.abs(grid[None, :]), 1e-300)
    missing = given[~where.any(axis=1)]
    if missing.size:
        c.fail(place, f"{', '.join(f'{m:g}' for m in missing)} not on the {_grid_name(axis)}: allowed {_grid_text(grid, axis)}")
        return None
    return grid[where.any(axis=0)]


def _grid_name(axis: str) -> str:
    return "simulated frequencies (simulation.frequency, else sweep.frequency)" if axis == "frequency" else f"grid of sweep.{axis}"


def _grid_text(grid: np.ndarray, axis: str) -> str:
    """The allowed values: all of them if few, else the range, the count and the step if even."""
    units = SUBSET_AXES[axis]
    if grid.size <= 12:
        return f"one of {', '.join(f'{g:g}' for g in grid)} [{units}]"
    steps = np.diff(grid)
    step = f", step {steps[0]:g}" if np.allclose(steps, steps[0], rtol=1e-6) else ""
    return f"{grid.size} values from {grid[0]:g} to {grid[-1]:g}{step} [{units}]"


def on_subset(subset: Subset, solution: str, axis: str, values: np.ndarray) -> np.ndarray:
    """Which of ``values`` (of ``axis``) ``solution`` runs on: all unless its subset restricts that axis."""
    kept = subset.get(solution, {}).get(axis)
    values = np.atleast_1d(np.asarray(values, dtype=float))
    return np.ones(values.shape, dtype=bool) if kept is None else np.isin(values, kept)


def subset_axes(scene: Scene, frequencies: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """The simulation grid's axes of ``scene`` (``frequencies`` [Hz]: the simulated ones, by default all of them)."""
    settings = scene.settings
    assert settings.simulation is not None
    bumpers = settings.bumper_frequency if settings.bumper_frequency is not None else np.zeros(0)
    frequency = settings.simulation.frequency if frequencies is None else frequencies
    return {"frequency": frequency, "restitution": settings.restitution, "clearance": settings.clearance, "bumper_frequency": bumpers}


def subset_share(subset: Subset, solution: str, axes: Mapping[str, np.ndarray]) -> float:
    """The share of the simulation grid (``axes``: axis -> its values) that ``solution`` runs on [1]."""
    return math.prod(float(np.mean(on_subset(subset, solution, axis, values))) for axis, values in axes.items() if np.size(values))


def subset_text(kept: Mapping[str, np.ndarray]) -> str:
    """One solution's subset in words, for the dataset's attributes and the page: 'frequency 22, 26 Hz; restitution 0.2'."""
    return "; ".join(f"{axis} {', '.join(f'{v:g}' for v in values)}{'' if SUBSET_AXES[axis] == '-' else ' ' + SUBSET_AXES[axis]}" for axis, values in kept.items())
