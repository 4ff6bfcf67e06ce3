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

from dataclasses import dataclass

import numpy as np
import xarray as xr
import yaml

from vibroimpact.analysis.regime import Regime
from vibroimpact.model.system import TwoDofSystem
from vibroimpact.scene.schema import ENGINE_SOLUTIONS, STUDY_KINDS

__all__ = ["SWEPT_SOLUTION", "StudyRecord", "StudySetting", "study_kind", "study_record", "study_setting", "stored_description"]

#: The solution a swept-sine test runs: the compliant bumper (scenes allow no other); its estimates are the
#: ``swept_<quantity>`` variables, not a value of the ``solution`` coordinate.
SWEPT_SOLUTION = "compliant"
_SYSTEM_KEYS = ("m1", "m2", "k1", "k2", "b1", "b2")


def study_kind(dataset: xr.Dataset) -> str:
    """The kind of study that wrote ``dataset``: its ``study_kind`` attribute, or, for datasets written before it
    existed, its dimensions (``engine`` or ``case``: benchmark; ``sweep``: swept; else stepped)."""
    kind = dataset.attrs.get("study_kind")
    if kind is not None:
        if kind not in STUDY_KINDS:
            raise ValueError(f"study_kind must be one of {', '.join(STUDY_KINDS)}, got {kind!r}")
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
        One of :data:`STUDY_KINDS`.
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
        if self.kind not in STUDY_KINDS:
            raise ValueError(f"kind must be one of {', '.join(STUDY_KINDS)}, got {self.kind!r}")


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
        return self.system.antiresonance_frequency() / (2.0 * np.pi)


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
        system=TwoDofSystem(**{key: float(attrs[f"system_{key}"]) for key in _SYSTEM_KEYS}),
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
