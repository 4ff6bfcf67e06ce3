"""What a report knows of the study that made a dataset, read from the dataset alone.

A report never re-validates the scene stored in a dataset: a dataset written by an older version, whose scene the
parser of today would refuse, is still reported. Everything comes from the dataset's coordinates, variables and
attributes (``system_m1`` ... ``system_b2``, ``excitation_amplitude_N``, ``simulation_frequency_Hz``, ``scene_name``,
``study_kind``); the description is read from the stored scene text as plain YAML, unchecked, and the scene text
itself is shown verbatim.

* :func:`study_kind`: stepped steady states, swept-sine tests or a benchmark, the one place that tells them apart;
* :class:`StudyRecord`: what every page's heading shows (name, description, version, scene text);
* :class:`StudySetting`: the system, excitation, grids and bumper of a stepped or swept study.
"""

from __future__ import annotations

from collections.abc import Mapping

from dataclasses import dataclass

import numpy as np
import xarray as xr
import yaml

from vibroimpact.analysis.stability import Regime
from vibroimpact.model.layout import Layout, bumper_units
from vibroimpact.model.structure import LinearStructure
from vibroimpact.model.system import TwoDofSystem
from vibroimpact.scene.kinds import KIND_NAMES
from vibroimpact.scene.schema import ENGINE_SOLUTIONS
from vibroimpact.simulation.harmonics import base_force

__all__ = ["SWEPT_SOLUTION", "StudyRecord", "StudySetting", "study_kind", "study_record", "study_setting", "stored_description", "GeneralSetting", "general_setting", "named_layout", "named_view", "is_general", "dataset_layout", "bumper_text"]

#: The solution a swept-sine test runs: the compliant bumper (scenes allow no other); its estimates are the
#: ``swept_<quantity>`` variables, not a value of the ``solution`` coordinate.
SWEPT_SOLUTION = "compliant"


def study_kind(dataset: xr.Dataset) -> str:
    """The kind of study that wrote ``dataset``: its ``study_kind`` attribute, or, for datasets written before it
    existed, its dimensions (``engine`` or ``case``: benchmark; ``sweep``: swept; else stepped)."""
    kind = dataset.attrs.get("study_kind")
    if kind is not None:
        if kind not in KIND_NAMES:
            raise ValueError(f"study_kind must be one of {', '.join(KIND_NAMES)}, got {kind!r}")
        return str(kind)
    if "engine" in dataset.dims or "case" in dataset.dims:
        return "benchmark"
    return "swept" if "sweep" in dataset.dims else "stepped"


def stored_description(scene_text: str) -> str:
    """The ``description`` of a stored scene text read as plain YAML (no validation); empty if there is none."""
    try:
        document = yaml.safe_load(scene_text)
    except yaml.YAMLError:
        return ""
    description = document.get("description") if isinstance(document, dict) else None
    return description if isinstance(description, str) else ""


@dataclass(frozen=True)
class StudyRecord:
    """What the heading of every page shows.

    Attributes
    ----------
    kind : str
        One of :data:`vibroimpact.scene.kinds.KIND_NAMES`.
    name : str
        The scene's name (attribute ``scene_name``).
    description : str
        The scene's description (empty if it has none).
    scene_text : str
        The scene as stored, shown verbatim at the end of the page.
    version : str
        Version of vibroimpact that wrote the dataset (``?`` if unknown).
    """

    kind: str
    name: str
    description: str
    scene_text: str
    version: str

    def __post_init__(self) -> None:
        if self.kind not in KIND_NAMES:
            raise ValueError(f"kind must be one of {', '.join(KIND_NAMES)}, got {self.kind!r}")


def study_record(dataset: xr.Dataset) -> StudyRecord:
    """The :class:`StudyRecord` of ``dataset``."""
    text = str(dataset.attrs.get("scene", ""))
    return StudyRecord(
        kind=study_kind(dataset),
        name=str(dataset.attrs.get("scene_name", "")),
        description=stored_description(text),
        scene_text=text,
        version=str(dataset.attrs.get("vibroimpact_version", "?")),
    )


@dataclass(frozen=True, eq=False)
class StudySetting:
    """The system, excitation, grids and bumper of a stepped or swept study, as its dataset stores them.

    Attributes
    ----------
    system : TwoDofSystem
        From the attributes ``system_m1`` ... ``system_b2`` [SI].
    amplitude : float
        Excitation amplitude q [N] (``excitation_amplitude_N``).
    solutions : tuple of str
        Every solution the study computed: the ``solution`` coordinate, then :data:`SWEPT_SOLUTION` for a swept-sine
        test.
    frequency : ndarray
        The dataset's frequency grid [Hz].
    clearance : ndarray
        Clearances Delta [m], one or more.
    simulation_frequency : ndarray
        Frequencies of the stepped simulations [Hz] (``simulation_frequency_Hz``, else where a simulated solution was
        computed); empty without any.
    bumper_frequency : ndarray
        Omega_b / 2 pi of the compliant bumper [Hz]; empty without a bumper.
    bumper_loss_factor : ndarray
        xi_b [-], one or one per restitution ratio; empty without a bumper.
    """

    system: TwoDofSystem
    amplitude: float
    solutions: tuple[str, ...]
    frequency: np.ndarray
    clearance: np.ndarray
    simulation_frequency: np.ndarray
    bumper_frequency: np.ndarray
    bumper_loss_factor: np.ndarray

    def __post_init__(self) -> None:
        if not self.amplitude > 0.0:
            raise ValueError(f"amplitude must be positive [N], got {self.amplitude!r}")
        if self.frequency.size == 0 or self.clearance.size == 0:
            raise ValueError("a study's dataset has at least one frequency and one clearance")

    @property
    def split_frequency(self) -> float:
        """The anti-resonance frequency [Hz], which separates the two resonance bands."""
        return self.system.antiresonance_angular_frequency() / (2.0 * np.pi)


def study_setting(dataset: xr.Dataset) -> StudySetting:
    """The :class:`StudySetting` of a stepped or swept study's ``dataset``.

    Raises
    ------
    KeyError
        If the dataset lacks an attribute ``system_<key>`` or ``excitation_amplitude_N``.
    """
    attrs = dataset.attrs
    steady = tuple(str(s) for s in dataset["solution"].values) if "solution" in dataset.coords else ()
    swept = (SWEPT_SOLUTION,) if any(str(name).startswith("swept_") for name in dataset.data_vars) else ()
    return StudySetting(
        system=_named(attrs),
        amplitude=float(attrs["excitation_amplitude_N"]),
        solutions=steady + swept,
        frequency=np.asarray(dataset["frequency"].values, dtype=float),
        clearance=_values(dataset, "clearance") if "clearance" in dataset.coords else np.atleast_1d(np.asarray(attrs.get("stop_clearance_m", np.nan), dtype=float)),
        simulation_frequency=_simulation_frequency(dataset),
        bumper_frequency=_values(dataset, "bumper_frequency"),
        bumper_loss_factor=_values(dataset, "bumper_loss_factor"),
    )


def _values(dataset: xr.Dataset, name: str) -> np.ndarray:
    """The values of coordinate ``name`` as a 1-d float array (empty if there is no such coordinate)."""
    return np.atleast_1d(np.asarray(dataset[name].values, dtype=float)) if name in dataset.coords else np.array([])


def _simulation_frequency(dataset: xr.Dataset) -> np.ndarray:
    """The stepped simulations' frequencies [Hz]: the attribute ``simulation_frequency_Hz``, else the frequencies
    where a simulated solution was computed (regime not ``not_computed``, or a finite value)."""
    if "simulation_frequency_Hz" in dataset.attrs:
        return np.atleast_1d(np.asarray(dataset.attrs["simulation_frequency_Hz"], dtype=float))
    if "solution" not in dataset.coords:
        return np.array([])
    engines = [s for s in dataset["solution"].values if s in ENGINE_SOLUTIONS]
    if not engines:
        return np.array([])
    part = dataset.sel(solution=engines)
    if "regime" in part:
        computed = part["regime"] != Regime.NOT_COMPUTED
    else:
        computed = xr.concat([np.isfinite(part[name]) for name in part.data_vars if "solution" in part[name].dims], dim="variable").any("variable")
    others = [d for d in computed.dims if d != "frequency"]
    mask = computed.any(others) if others else computed
    return np.asarray(dataset["frequency"].values[np.asarray(mask.values)], dtype=float)


# --------------------------------------------------------------------------------------------------------------------
# What a report knows of a stepped study's structure, load and stops, read from its dataset's attributes
# (written by :meth:`vibroimpact.model.layout.Layout.attributes`); nothing is re-validated from the scene text.
# --------------------------------------------------------------------------------------------------------------------



def named_view(dataset: xr.Dataset) -> TwoDofSystem | None:
    """The named system of ``dataset``'s structure (attributes ``system_m1`` ... ``system_b2``, read by
    :meth:`~vibroimpact.model.layout.Layout.from_attributes`); None where it has none."""
    return _named(dataset.attrs) if "system_m1" in dataset.attrs else None


def _named(attrs: Mapping[str, object]) -> TwoDofSystem:
    """The named system the attributes record (``KeyError`` naming one missing)."""
    named = Layout.from_attributes(attrs).named_view()
    if named is None:
        raise KeyError("system_m1")
    return named


def dataset_layout(dataset: xr.Dataset) -> Layout:
    """The layout ``dataset``'s study ran (:meth:`~vibroimpact.model.layout.Layout.from_attributes`; a dataset written
    before the layout was recorded had the paper's layout on its named system)."""
    return Layout.from_attributes(dataset.attrs)


def named_layout(dataset: xr.Dataset) -> TwoDofSystem | None:
    """The named system where ``dataset``'s study had the paper's layout on it (two-mass chain, one upper stop on x2,
    force on x1); None otherwise (:meth:`~vibroimpact.model.layout.Layout.paper_view`)."""
    if "system_size" not in dataset.attrs and "system_m1" not in dataset.attrs:
        return None
    return dataset_layout(dataset).paper_view()


def bumper_text(attrs: Mapping[str, object], frequency: float) -> str:
    """The bumper of Omega_b / 2 pi = ``frequency`` [Hz] in the units its scene gave: ``bumper 250 Hz``, or where
    every stop's bumper was given as the same stiffness and damping (``stop_bumper_*`` attributes,
    :meth:`~vibroimpact.model.layout.Layout.attributes`), ``bumper K_b = 100000 N/m, B_b = 20 N s/m (Omega_b / 2 pi
    = 159.2 Hz)``."""
    stiffness, damping = (np.atleast_1d(np.asarray(attrs.get(key, np.nan), dtype=float)) for key in ("stop_bumper_stiffness_N_per_m", "stop_bumper_damping_N_s_per_m"))
    shared = np.isfinite(stiffness).all() and np.unique(stiffness).size == 1
    same_damping = np.isnan(damping).all() or (np.isfinite(damping).all() and np.unique(damping).size == 1)
    if not (shared and same_damping):
        return f"bumper {frequency:g} Hz"
    return f"bumper {bumper_units(float(stiffness[0]), float(damping[0]) if np.isfinite(damping[0]) else None)} (Omega_b / 2 pi = {frequency:.4g} Hz)"


def is_general(dataset: xr.Dataset) -> bool:
    """Does ``dataset`` record a layout (its structure, load and stops) that is not the paper's, so that its page
    draws every coordinate and stop by name? The paper's layout, however its scene wrote it, is not general."""
    return "system_size" in dataset.attrs and named_layout(dataset) is None


def _layout(dataset: xr.Dataset) -> dict:
    """The dataset's attributes with its layout's: those it recorded, else (written before they were recorded) the
    paper's named layout on its ``system_m1`` ... ``system_b2``, the clearance and restitution from its coordinates."""
    attrs = dict(dataset.attrs)
    if "system_size" in attrs or "system_m1" not in attrs:
        return attrs

    def grid(name: str) -> np.ndarray:
        return np.atleast_1d(np.asarray(dataset[name].values, dtype=float)) if name in dataset.coords else np.array([np.nan, np.nan])

    return attrs | Layout.from_attributes(attrs).attributes(grid("restitution"), grid("clearance"))


@dataclass(frozen=True, eq=False)
class GeneralSetting:
    """A general study's structure, load and stops.

    Attributes
    ----------
    structure : LinearStructure
        M, K, C and the coordinates' names.
    amplitude : float
        q [N], or the base displacement [m] (``base_motion``).
    base_motion : bool
        The load is a base motion (coordinates relative to the base).
    weights : ndarray
        Harmonic force per coordinate per unit amplitude [-].
    static : ndarray
        Constant force per coordinate [N].
    stops : tuple of str
        Each stop in words (e.g. ``x2 - x1 <= 3 mm, R = 0.2``).
    normals : ndarray, shape (K, N)
        n of every stop (the stopped coordinate n . x).
    solutions : tuple of str
        The ``solution`` coordinate.
    clearances : ndarray, shape (K,)
        Delta of every stop [m] (attribute ``stop_clearance_m``, else read from its description); NaN where the grid
        sweeps it.
    named : TwoDofSystem or None
        The structure's named view (the paper's m1 ... b2) where the dataset has one: the paper's extras (modal
        parameters and fit of H22, resonance bands split at the anti-resonance, reduction factors) apply.
    """

    structure: LinearStructure
    amplitude: float
    base_motion: bool
    weights: np.ndarray
    static: np.ndarray
    stops: tuple[str, ...]
    normals: np.ndarray
    solutions: tuple[str, ...]
    clearances: np.ndarray
    named: TwoDofSystem | None = None

    @property
    def names(self) -> tuple[str, ...]:
        """The coordinates' names."""
        return tuple(self.structure.coordinates)

    def static_deflection(self) -> np.ndarray | None:
        """x_static = K^-1 F0 [m] under the constant force (zeros without one); None where K is singular."""
        if not np.any(self.static):
            return np.zeros(self.structure.size)
        if self.structure.rigid_body_modes():  # the one rule: the same as cond(K) >= 1e12
            return None
        return np.linalg.solve(self.structure.stiffness_matrix, self.static)

    def load(self, w: np.ndarray) -> np.ndarray:
        """Harmonic load per coordinate at each w [rad s-1] [N], shape w.shape + (N,)."""
        if self.base_motion:
            return (self.structure.mass_matrix @ np.ones(self.structure.size)) * (self.amplitude * w**2)[..., None]
        return self.weights * self.amplitude * np.ones(np.shape(w))[..., None]

    def linear(self, w: np.ndarray) -> np.ndarray:
        """Complex amplitudes of the linear steady state without stops at each w [rad s-1] [m], shape w.shape + (N,)."""
        return np.einsum("...ij,...j->...i", self.structure.receptance_matrix(w), self.load(w))

    def linear_value(self, quantity: str, w: np.ndarray) -> np.ndarray:
        """|quantity| of the linear steady state at each w [rad s-1]: ``<name>_amplitude`` [m] of a coordinate, or
        ``force_amplitude`` / ``suspension_force_amplitude`` [N], 1^T (K + j w C) X (no stop loads the base)."""
        x = self.linear(w)
        if quantity in ("force_amplitude", "suspension_force_amplitude"):
            return np.abs(base_force(self.structure, w, x))
        return np.abs(x[..., self.names.index(quantity.removesuffix("_amplitude"))])

    def linear_fits(self, w: np.ndarray, clearance: float = float("nan")) -> np.ndarray:
        """Where the linear steady state stays clear of every stop, |n_k . X| + n_k . x_static <= Delta_k, at each
        w [rad s-1]; ``clearance`` [m] stands for the stops whose Delta the grid sweeps."""
        static = self.static_deflection()
        shift = self.normals @ static if static is not None else np.zeros(len(self.stops))
        deltas = np.where(np.isfinite(self.clearances), self.clearances, clearance)
        return np.all(np.abs(self.linear(w) @ self.normals.T) + shift <= deltas, axis=-1)

    def load_text(self) -> str:
        """The load in words."""
        if self.base_motion:
            return f"base motion of amplitude {self.amplitude * 1e3:g} mm (coordinates relative to the base)"
        on = [f"{w:g} x {name}" if w != 1.0 else name for w, name in zip(self.weights, self.names) if w != 0.0]
        text = f"harmonic force of amplitude {self.amplitude:g} N on {' + '.join(on)}"
        if np.any(self.static):
            text += "; constant force " + ", ".join(f"{f:g} N on {name}" for f, name in zip(self.static, self.names) if f != 0.0)
        return text


def general_setting(dataset: xr.Dataset) -> GeneralSetting:
    """The :class:`GeneralSetting` of a stepped study's ``dataset`` (``KeyError`` naming a missing attribute)."""
    attrs = _layout(dataset)
    layout = Layout.from_attributes(attrs)
    size = layout.size
    return GeneralSetting(
        structure=layout.structure,
        amplitude=float(attrs["excitation_amplitude_N"]),
        base_motion=layout.load.base_motion,
        weights=np.array(layout.load.weight_vector(size), dtype=float),
        static=np.array(layout.load.static_vector(size), dtype=float),
        stops=tuple(part.strip() for part in str(attrs["stop_layout"]).split(";")),
        normals=layout.normals(),
        solutions=tuple(str(s) for s in dataset["solution"].values) if "solution" in dataset.coords else (),
        clearances=np.array(layout.clearances()),
        named=named_view(dataset),
    )
