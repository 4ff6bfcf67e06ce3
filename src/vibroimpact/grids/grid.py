"""The frequency-grid study shared by the stepped and swept kinds: the full grid, the loop over solutions, and the
dataset around the values (its coordinates, the attributes of its variables and of its stops, its metadata).

The full grid is (restitution, clearance, bumper_frequency, sweep, frequency): unswept axes have length 1 and are
squeezed at the end; each solution computes only along the axes it depends on, then is broadcast. The closed forms'
values come from :mod:`vibroimpact.grids.closed_forms`; a study's estimate is :mod:`vibroimpact.grids.estimate`'s.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Callable

import numpy as np
import xarray as xr

from vibroimpact.model.modal import fit_modal_parameters
from vibroimpact.scene.schema import ENGINE_SOLUTIONS, STOP_QUANTITIES, Scene
from vibroimpact.scene.variables import COORDINATE_ATTRIBUTES, quantity_attributes
from vibroimpact.grids.closed_forms import general_linear_values, general_pgf_values
from vibroimpact.runs.cluster import Progress
from vibroimpact.reporting.solutions import closed_form_methods, solution_method

__all__ = ["StudyGrid", "solve_each", "grid_coordinates", "steady_variable", "finish_dataset", "no_one_impact_orbit", "general_quantity_attributes", "describe_stops", "grid_engines"]

#: The values of one solution, quantity -> array over (part of) the full grid.
Values = dict[str, np.ndarray]


@dataclass(frozen=True, eq=False)
class StudyGrid:
    """The full grid of a study and its axes, shaped for broadcasting.

    Attributes
    ----------
    frequency : ndarray
        Every frequency of the dataset [Hz].
    bumper : ndarray
        Omega_b / 2 pi [Hz]; ``[nan]`` without a bumper.
    directions : tuple of str
        Sweep directions; ``("",)`` for stepped studies.
    full : tuple of int
        Shape of the full grid.
    r, delta, omega : ndarray
        Restitution [-], clearance [m] and angular frequency [rad s-1] on their axes of the full grid.
    base : tuple of int
        Shape of the closed forms' grid (restitution, clearance, frequency).
    """

    frequency: np.ndarray
    bumper: np.ndarray
    directions: tuple[str, ...]
    full: tuple[int, ...]
    r: np.ndarray
    delta: np.ndarray
    omega: np.ndarray
    base: tuple[int, ...]

    @classmethod
    def of(cls, scene: Scene) -> "StudyGrid":
        """The grid of ``scene``."""
        frequency = scene.settings.all_frequencies
        bumper = scene.settings.bumper_frequency if scene.settings.bumper_frequency is not None else np.array([np.nan])
        directions = scene.settings.sweep_directions or ("",)
        full = (scene.settings.restitution.size, scene.settings.clearance.size, bumper.size, len(directions), frequency.size)
        r = scene.settings.restitution[:, None, None, None, None]
        delta = scene.settings.clearance[None, :, None, None, None]
        omega = 2.0 * np.pi * frequency[None, None, None, None, :]
        base = np.broadcast_shapes(r.shape, delta.shape, omega.shape)
        return cls(frequency, bumper, directions, full, r, delta, omega, base)


def solve_each(scene: Scene, grid: StudyGrid, simulate: Callable[[str], Values], progress: Progress | None) -> list[Values]:
    """The values of every solution of ``scene``, in its order; ``simulate(name)`` computes a time-domain one.

    The closed forms are those of any layout (:mod:`vibroimpact.grids.closed_forms`): per-coordinate quantities named
    after the coordinates, per-stop ones with a leading axis of one entry per stop; ``pgf_paper`` is the paper's own
    route where the scene has its layout (:mod:`vibroimpact.grids.closed_forms`).
    """
    report = progress or (lambda _message: None)
    total = len(scene.settings.solutions)
    per_solution = []
    for i, name in enumerate(scene.settings.solutions, start=1):
        if name == "linear":
            values = general_linear_values(scene, grid.omega, grid.base)
        elif name in ENGINE_SOLUTIONS:
            values = simulate(name)
        else:  # pgf, or pgf_paper: the same orbit with the paper's fitted Green function
            values = general_pgf_values(scene, grid.omega, grid.delta, grid.r, grid.base, name)
        per_solution.append(values)
        report(f"[{i}/{total}] {name}: done")
    return per_solution


def grid_coordinates(scene: Scene, grid: StudyGrid, solutions: list[str]) -> dict[str, object]:
    """Coordinates of the dataset before squeezing: ``solution`` (if any), the parameters and ``frequency``."""
    coords: dict[str, object] = {"solution": np.array(solutions, dtype=object), "restitution": scene.settings.restitution, "clearance": scene.settings.clearance, "frequency": grid.frequency}
    if scene.settings.bumper_frequency is not None:
        coords["bumper_frequency"] = scene.settings.bumper_frequency
    if not solutions:
        del coords["solution"]
    return coords


def steady_variable(quantity: str, scene: Scene, grid: StudyGrid, per_solution: list[Values], solutions: list[str]) -> np.ndarray | None:
    """``quantity`` of the named solutions stacked along a leading ``solution`` axis over the full grid; None if none.
    A per-stop quantity is taken at the scene's one stop (a layout with one stop has no ``stop`` dimension)."""
    one_stop = quantity in STOP_QUANTITIES and len(scene.layout.stops) == 1

    def full(name: str, values: Values) -> np.ndarray:
        value = values[quantity]
        if one_stop and name not in ENGINE_SOLUTIONS:
            value = np.broadcast_to(value, (1, *grid.full))[0]
        return np.broadcast_to(value, grid.full)

    steady = [full(name, values) for name, values in zip(scene.settings.solutions, per_solution) if name in solutions]
    return np.stack(steady) if steady else None


def grid_engines(scene: Scene) -> tuple[str, ...]:
    """The engines among a grid scene's solutions (the closed forms need none): the stepped and swept kinds'
    ``engines``."""
    return tuple(name for name in scene.settings.solutions if name in ENGINE_SOLUTIONS)


def finish_dataset(dataset: xr.Dataset, scene: Scene, coords: dict[str, object], simulation_attributes: dict[str, object], keep: tuple[str, ...] = ()) -> xr.Dataset:
    """Squeeze the unswept axes (not those in ``keep``), add the bumper's loss factor, the coordinates' attributes and
    the dataset's metadata (``simulation_attributes``: what the study kind says of its simulations)."""
    for key in ("restitution", "clearance", "bumper_frequency", "sweep"):
        if key in keep:
            continue
        swept = key in scene.settings.swept or (key == "restitution" and "bumper_loss_factor" in scene.settings.swept)
        if not swept and key in dataset.dims:
            dataset = dataset.squeeze(key, drop=key not in coords)
        if key in dataset.coords and dataset[key].ndim == 0 and dataset[key].dtype.kind == "f" and not np.isfinite(float(dataset[key])):
            dataset = dataset.drop_vars(key)  # the stops give different values: the stop descriptions say them
    if scene.settings.bumper_frequency is not None:
        losses = scene.settings.loss_factors()
        if "restitution" in dataset.dims or np.isfinite(losses[0]):  # none at R = 0 (no loss factor gives it); stops may each have their own
            dataset = dataset.assign_coords(bumper_loss_factor=("restitution", losses) if "restitution" in dataset.dims else float(losses[0]))
        if "bumper_loss_factor" in scene.settings.swept:
            dataset = dataset.swap_dims({"restitution": "bumper_loss_factor"})
    for key, attrs in COORDINATE_ATTRIBUTES.items():
        if key in dataset.coords:
            dataset[key].attrs.update(attrs)
    dataset.attrs.update(_metadata(scene, simulation_attributes))
    return dataset


def _metadata(scene: Scene, simulation_attributes: dict[str, object]) -> dict[str, object]:
    structure = scene.layout.structure
    named = scene.layout.named_view()  # the named view: the paper's two-mass chain, however it was written
    fit = fit_modal_parameters(named) if named is not None and "pgf_paper" in scene.settings.solutions else None
    natural = named.natural_angular_frequencies() if named is not None else structure.natural_angular_frequencies()
    attrs: dict[str, object] = {
        "excitation_amplitude_N": scene.amplitude,
        "natural_frequencies_Hz": np.array(natural) / (2.0 * np.pi),
    }
    if named is not None:
        attrs["antiresonance_frequency_Hz"] = named.antiresonance_angular_frequency() / (2.0 * np.pi)
    attrs.update(scene.layout.attributes(scene.settings.restitution, scene.settings.clearance, scene.settings.bumper_frequency) | closed_form_methods())
    if "pgf_paper" in scene.settings.solutions:
        attrs["method_pgf_paper"] = solution_method("pgf_paper")
    for key, value in asdict(scene.settings.admissibility).items():
        attrs[f"admissibility_{key}"] = value
    attrs.update(simulation_attributes)
    if fit is not None:
        attrs["pgf_paper_form_factors_per_kg"] = np.real(fit.form_factor)
        attrs["pgf_paper_loss_factors"] = fit.loss_factor
    return attrs


def no_one_impact_orbit(shape: tuple[int, ...]) -> dict[str, np.ndarray]:
    """Values of the variables that describe the closed form's orbit, for solutions that have none (time-domain
    engines, swept-sine tests)."""
    nan = np.full(shape, np.nan)
    return {
        "stable": np.full(shape, -1, dtype=np.int8),
        "floquet_modulus": nan,
        "one_impact_x1_amplitude": nan,
        "one_impact_x2_amplitude": nan,
        "one_impact_force_amplitude": nan,
        "one_impact_impulse": nan,
    }


# --------------------------------------------------------------------------------------------------------------------
# The attributes of the grid's variables and of its stops, whichever way the scene writes the system (the paper's
# named form is the layout of a two-mass chain, one upper stop on x2 and a force on x1, and takes this path too).
# --------------------------------------------------------------------------------------------------------------------


def general_quantity_attributes(quantity: str, scene: Scene) -> dict[str, object]:
    """Units and long name of a grid study's quantity, stepped or swept (per-coordinate names included)."""
    relative = " relative to the base" if scene.layout.load.base_motion else ""
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


def describe_stops(dataset: xr.Dataset) -> xr.Dataset:
    """The attributes of the ``stop`` coordinates, where the dataset has them."""
    if "stop" in dataset.coords:
        dataset["stop"].attrs.update({"units": "1", "long_name": "index of the stop in the scene's stops"})
        dataset["stop_description"].attrs.update({"long_name": "the stop's constraint in words (Delta, R: the swept values)"})
    return dataset
