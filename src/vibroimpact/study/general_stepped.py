"""The values of a stepped study, whichever way its scene writes the system (the paper's named form is the layout
of a two-mass chain, one upper stop on x2 and a force on x1, and takes this path too): any structure, load and stops.

Output: dimension ``solution``, the swept parameters and ``frequency``; one ``<name>_amplitude`` and ``<name>_rms``
per coordinate (``x1_amplitude``, ``x2_amplitude``, ... for the paper's layout); per-stop quantities (``impulse``, ``one_impact_impulse``,
``peak_contact_force``, ``peak_acceleration``) with a dimension ``stop`` (index in the scene's ``stops``) and its
coordinate ``stop_description`` (e.g. ``x2 - x1 <= 3 mm, R = 0.2``) where the scene has several stops, without it
where it has one. The structure, load and stop layout are attributes (:func:`vibroimpact.study.grid.layout_attributes`).
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from vibroimpact.scene.layout import stop_descriptions
from vibroimpact.scene.schema import GRID_DIMS, STOP_QUANTITIES, Scene
from vibroimpact.scene.variables import quantity_attributes
from vibroimpact.study.general_engines import general_simulated_values
from vibroimpact.study.grid import StudyGrid, grid_coordinates, solve_each
from vibroimpact.study.runner import Runner

__all__ = ["general_block", "general_coordinates", "describe_stops", "general_quantity_attributes"]

_PER_COORDINATE = {"_amplitude": "x1_amplitude", "_rms": "x1_rms"}


def general_quantity_attributes(quantity: str, scene: Scene) -> dict[str, object]:
    """Units and long name of a stepped study's quantity (per-coordinate names included)."""
    relative = " relative to the base" if scene.load_spec.base_motion else ""
    for name in scene.coordinates:
        if quantity == f"{name}_amplitude":
            return {"units": "m", "long_name": f"fundamental-harmonic amplitude of coordinate {name}{relative}"}
        if quantity == f"{name}_rms":
            return {"units": "m", "long_name": f"RMS of coordinate {name}{relative} (static offset included)"}
        if quantity == f"one_impact_{name}_amplitude":
            return {"units": "m", "long_name": f"|{name}| fundamental of the closed-form impact orbit wherever it exists, unchecked"}
    attrs = quantity_attributes(quantity)
    if quantity in STOP_QUANTITIES:
        attrs = attrs | {"long_name": f"{attrs.get('long_name', quantity)}; per stop (the stopped coordinate's deceleration)"}
    if quantity in ("force_amplitude", "suspension_force_amplitude"):
        attrs = attrs | {"long_name": "fundamental-harmonic amplitude of the force on the base: 1^T (K x + C x') through springs and dashpots" + (" plus the absolute stops' contact forces" if quantity == "force_amplitude" else "")}
    return attrs


def general_block(scene: Scene, runner: Runner) -> xr.Dataset:
    """Every solution of ``scene`` (or of a block of one) over its unsqueezed grid, without coordinates or metadata;
    per-stop quantities have the dimension ``stop`` where the scene has several stops."""
    grid = StudyGrid.of(scene)
    per_solution = solve_each(scene, grid, lambda name: general_simulated_values(scene, name, grid.full, runner), None)
    count = len(scene.stop_specs)
    data_vars = {}
    for quantity in scene.quantities:
        attrs = general_quantity_attributes(quantity, scene)
        if quantity in STOP_QUANTITIES:
            stacked = np.stack([np.broadcast_to(values[quantity], (count, *grid.full)) for values in per_solution])
            if count > 1:
                data_vars[quantity] = xr.Variable(("solution", "stop", *GRID_DIMS), stacked, attrs)
            else:
                data_vars[quantity] = xr.Variable(("solution", *GRID_DIMS), stacked[:, 0], attrs)
        else:
            stacked = np.stack([np.broadcast_to(values[quantity], grid.full) for values in per_solution])
            data_vars[quantity] = xr.Variable(("solution", *GRID_DIMS), stacked, attrs)
    return xr.Dataset(data_vars)


def general_coordinates(scene: Scene, grid: StudyGrid) -> dict[str, object]:
    """Coordinates of a stepped study's dataset before squeezing: those of :func:`grid_coordinates`, and ``stop``
    with ``stop_description`` where the scene has several stops and writes a per-stop quantity."""
    coords = grid_coordinates(scene, grid, list(scene.solutions))
    count = len(scene.stop_specs)
    if count > 1 and any(q in STOP_QUANTITIES for q in scene.quantities):
        coords["stop"] = np.arange(count)
        coords["stop_description"] = ("stop", np.array(stop_descriptions(scene.stop_specs, scene.coordinates, scene.restitution, scene.clearance), dtype=object))
    return coords


def describe_stops(dataset: xr.Dataset) -> xr.Dataset:
    """The attributes of the ``stop`` coordinates, where the dataset has them."""
    if "stop" in dataset.coords:
        dataset["stop"].attrs.update({"units": "1", "long_name": "index of the stop in the scene's stops"})
        dataset["stop_description"].attrs.update({"long_name": "the stop's constraint in words (Delta, R: the swept values)"})
    return dataset
