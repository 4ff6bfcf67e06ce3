"""The layout of a study: a structure, its load and where its stops act, without the values a study sweeps.

One :class:`Layout` value goes from scene to dataset to page. It builds each problem of a study
(:meth:`Layout.problem`, from the grid point's values), writes the dataset's layout attributes
(:meth:`Layout.attributes`) and reads them back (:meth:`Layout.from_attributes`), and is the one place that
recognises the paper's layout (:meth:`Layout.paper_view`: two masses x1, x2 in a chain, one upper stop against the
base on the absorber x2, the harmonic force on the primary mass x1 only), whose named view (m1 ... b2, natural and
anti-resonance frequencies, the curve-fitted route of the paper) applies there only.

A stop of a layout is a :class:`StopSpec`: where it acts, and the values it gives itself (clearance, restitution,
bumper); the values it does not give come from the study's grid (:func:`build_stops`).
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.model.units import LENGTH_UNITS, length_text
from vibroimpact.model.collision import loss_factor_from_restitution, restitution_from_loss_factor
from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop, Stop, check_room, place_effective_mass, place_normal
from vibroimpact.model.excitation import HarmonicForce, SweptSine
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.structure import LinearStructure
from vibroimpact.model.system import NAMED_KEYS, TwoDofSystem

__all__ = ["Layout", "LoadSpec", "StopSpec", "PAPER_STOP", "build_stops", "describe_stop", "stop_descriptions", "bumper_units", "NAMED_KEYS"]


@dataclass(frozen=True)
class LoadSpec:
    """How a layout loads its structure.

    Attributes
    ----------
    weights : tuple of float or None
        Harmonic force per coordinate per unit amplitude [-] (``excitation.on``); None: all on the first coordinate.
    static : tuple of float or None
        Constant force per coordinate [N] (``excitation.static``); None: none.
    base_motion : bool
        The amplitude is a base displacement [m] and coordinates are relative to the base (``excitation.base_motion``).
    """

    weights: tuple[float, ...] | None = None
    static: tuple[float, ...] | None = None
    base_motion: bool = False

    def force(self, amplitude: float, frequency: float, phase: float = 0.0) -> HarmonicForce:
        """The harmonic load of amplitude q [N] (or Y [m] for a base motion) at ``frequency`` [Hz]."""
        return HarmonicForce(amplitude, frequency, phase, weights=self.weights, static=self.static, base_motion=self.base_motion)

    def weight_vector(self, size: int) -> tuple[float, ...]:
        """The harmonic force per coordinate per unit amplitude [-] over ``size`` coordinates (e_1 without weights)."""
        return self.weights if self.weights is not None else (1.0,) + (0.0,) * (size - 1)

    def static_vector(self, size: int) -> tuple[float, ...]:
        """The constant force per coordinate [N] over ``size`` coordinates (zeros without one)."""
        return self.static if self.static is not None else (0.0,) * size

    @property
    def primary_force(self) -> bool:
        """Is it the paper's load: a harmonic force on the first coordinate only, nothing constant, no base motion?"""
        weights_ok = self.weights is None or (self.weights[0] == 1.0 and not any(self.weights[1:]))
        static_ok = self.static is None or not any(self.static)
        return weights_ok and static_ok and not self.base_motion


@dataclass(frozen=True)
class StopSpec:
    """One stop of a layout: where it acts and the values it gives itself.

    Attributes
    ----------
    coordinate : int
        Index of the stopped coordinate.
    other : int or None
        For a relative stop (``between: [a, b]``), the index of b: the gap is on x_a - x_b.
    side : str
        ``upper`` (x <= Delta) or ``lower`` (x >= -Delta).
    clearance : float or None
        Delta [m]; None: the study's grid value (swept, or shared by every stop).
    restitution : float or None
        R [-]; None: the grid value.
    bumper_frequency : float or None
        Omega_b / 2 pi of this stop's bumper [Hz]; None: the grid value (the scene's ``bumper`` section or sweep).
    bumper_loss_factor : float or None
        xi_b [-]; None: the grid value, or the exact inverse of the stop's restitution.
    bumper_stiffness : float or None
        K_b [N m-1] where the scene gave the bumper in physical units (its words and attributes say it): the values
        used are still ``bumper_frequency`` and ``bumper_loss_factor`` (or the grid's), converted with the stop's
        effective mass (:meth:`effective_mass`); None: given as a frequency.
    bumper_damping : float or None
        B_b [N s m-1] where the scene gave it with ``bumper_stiffness``; None otherwise.
    """

    coordinate: int
    other: int | None = None
    side: str = "upper"
    clearance: float | None = None
    restitution: float | None = None
    bumper_frequency: float | None = None
    bumper_loss_factor: float | None = None
    bumper_stiffness: float | None = None
    bumper_damping: float | None = None

    def effective_mass(self, structure: LinearStructure) -> float:
        """m_eff = 1 / (n . M^-1 n) [kg]: the mass this stop's bumper pushes on ``structure``
        (:func:`~vibroimpact.model.contact.place_effective_mass`)."""
        return place_effective_mass(self.place, structure.mass_matrix)

    def stop(self, law: RigidStop | KelvinVoigtBumper) -> Stop:
        """The model's :class:`Stop` with contact law ``law``."""
        return Stop(law, coordinate=self.coordinate, other=self.other, side=self.side)

    def values(self, restitution: float, clearance: float, bumper_frequency: float = math.nan, loss_factor: float = math.nan) -> tuple[float, float, float, float]:
        """(R, Delta, Omega_b / 2 pi, xi_b) of this stop at a grid point: its own where it gives one, else the grid's.

        A loss factor that neither the stop nor the grid gives is the exact inverse of the stop's restitution
        (NaN for R = 0); a restitution the stop does not give while its bumper gives a loss factor is R(xi_b).
        """
        xi = self.bumper_loss_factor if self.bumper_loss_factor is not None else loss_factor
        if self.restitution is not None:
            r = self.restitution
        elif self.bumper_loss_factor is not None and math.isnan(restitution):
            r = restitution_from_loss_factor(self.bumper_loss_factor)
        else:
            r = restitution
        if math.isnan(xi) and r > 0.0:
            xi = loss_factor_from_restitution(r)
        delta = self.clearance if self.clearance is not None else clearance
        fb = self.bumper_frequency if self.bumper_frequency is not None else bumper_frequency
        return r, delta, fb, xi

    @property
    def place(self) -> tuple[int, int | None, str]:
        """(coordinate, other, side): where the stop acts, without its values."""
        return (self.coordinate, self.other, self.side)


#: The paper's stop: an upper stop of the absorber x2 against the base, taking the grid's values.
PAPER_STOP = StopSpec(coordinate=1)


def build_stops(specs: tuple[StopSpec, ...], bumper: bool, restitution: float, clearance: float, bumper_frequency: float = math.nan, loss_factor: float = math.nan) -> tuple[Stop, ...]:
    """The model's stops at one grid point: rigid stops (``bumper`` False) or Kelvin-Voigt bumpers.

    Parameters
    ----------
    specs : tuple of StopSpec
        The layout's stops.
    bumper : bool
        Build bumpers (the compliant solution) instead of rigid stops.
    restitution, clearance, bumper_frequency, loss_factor : float
        The grid point's R [-], Delta [m], Omega_b / 2 pi [Hz] and xi_b [-] (NaN: none), for stops that give none.
    """
    stops = []
    for spec in specs:
        r, delta, fb, xi = spec.values(restitution, clearance, bumper_frequency, loss_factor)
        law: RigidStop | KelvinVoigtBumper = KelvinVoigtBumper(delta, fb, xi) if bumper else RigidStop(delta, r)
        stops.append(spec.stop(law))
    return tuple(stops)


def describe_stop(spec: StopSpec, names: tuple[str, ...], clearance: float | None = None, restitution: float | None = None, bumper_frequency: float | None = None) -> str:
    """The stop in words, e.g. ``x2 - x1 <= 3 mm, R = 0.2`` (``Delta`` and ``R`` where the grid sweeps them); a bumper
    given in physical units as ``bumper K_b = 100000 N/m, B_b = 20 N s/m (Omega_b / 2 pi = 159.2 Hz)``, its
    frequency the stop's own or ``bumper_frequency`` [Hz] (the grid's one value)."""
    delta = spec.clearance if spec.clearance is not None else clearance
    r = spec.restitution if spec.restitution is not None else restitution
    target = names[spec.coordinate] if spec.other is None else f"{names[spec.coordinate]} - {names[spec.other]}"
    relation = "<=" if spec.side == "upper" else ">="
    if delta is None or not np.isfinite(delta):
        bound = "Delta" if spec.side == "upper" else "-Delta"
    else:
        bound = length_text(delta if spec.side == "upper" else -delta)  # in the clearance's own unit: "3 mm", "1 m"
    words = f"{target} {relation} {bound}"
    if r is not None and np.isfinite(r):
        words += f", R = {r:g}"
    if spec.bumper_stiffness is not None:
        words += f", bumper {bumper_units(spec.bumper_stiffness, spec.bumper_damping)}"
        fb = spec.bumper_frequency if spec.bumper_frequency is not None else bumper_frequency
        if fb is not None and np.isfinite(fb):
            words += f" (Omega_b / 2 pi = {fb:.4g} Hz)"
    elif spec.bumper_frequency is not None:
        words += f", bumper {spec.bumper_frequency:g} Hz"
    return words


def bumper_units(stiffness: float, damping: float | None = None) -> str:
    """A bumper in the physical units a scene gave: ``K_b = 100000 N/m, B_b = 20 N s/m`` (K_b [N m-1], B_b [N s m-1]
    where given)."""
    return f"K_b = {stiffness:g} N/m" + (f", B_b = {damping:g} N s/m" if damping is not None else "")


def stop_descriptions(
    specs: tuple[StopSpec, ...], names: tuple[str, ...], restitution: np.ndarray, clearance: np.ndarray, bumper_frequency: np.ndarray | None = None
) -> tuple[str, ...]:
    """Each stop in words; a value shared through a one-point grid is written out, a swept one as ``Delta``/``R``
    (``bumper_frequency`` [Hz]: the grid's, said only beside a bumper given in physical units)."""
    delta = float(clearance[0]) if clearance.size == 1 else None
    r = float(restitution[0]) if restitution.size == 1 else None
    fb = float(bumper_frequency[0]) if bumper_frequency is not None and bumper_frequency.size == 1 else None
    return tuple(describe_stop(spec, names, delta, r, fb) for spec in specs)


def _attribute(values: object) -> object:
    """``values`` as a flat array attribute, or its one value (netCDF stores a one-entry attribute as a scalar: a
    dataset reads back as written)."""
    flat = np.asarray(values).ravel()
    return flat[0].item() if flat.size == 1 else flat


#: The bound of a stop's description (:func:`describe_stop`): ``<= 3 mm``, ``>= -2 mm``, ``<= 1 m``.
_BOUND = re.compile(r"(<=|>=)\s*(-?[0-9.]+(?:e[-+]?[0-9]+)?) (mm|m|µm)\b")


def _described_clearance(words: str, side: str) -> float:
    """Delta [m] of a stop from its description (upper: n . x <= Delta; lower: the coordinate >= -Delta); NaN where
    it is written ``Delta`` (swept)."""
    match = _BOUND.search(words.split(",")[0])
    if match is None:
        return float("nan")
    value = float(match.group(2)) * {unit: metres for unit, metres, _ in LENGTH_UNITS}[match.group(3)]
    return value if side == "upper" else -value


@suggest_keywords
@dataclass(frozen=True)
class Layout:
    """A structure, its load and its stops, without the values a study sweeps.

    Parameters
    ----------
    structure : LinearStructure or TwoDofSystem
        M, K, C and the coordinates' names. A :class:`TwoDofSystem` is kept as its structure, and its parameters
        m1 ... b2 as they were written (the named view, :meth:`paper_view`, gives them back unrounded).
    load : LoadSpec
        The load's distribution, constant force and base motion; the default is the paper's force on x1.
    stops : tuple of StopSpec
        Where each stop acts, with the values it gives itself; the default is the paper's stop above x2.

    Raises
    ------
    TypeError, ValueError
        A part of the wrong kind, no stop, or a stop on a coordinate the structure does not have (naming the stop).
    """

    structure: LinearStructure
    load: LoadSpec = LoadSpec()
    stops: tuple[StopSpec, ...] = (PAPER_STOP,)
    _named: TwoDofSystem | None = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if isinstance(self.structure, TwoDofSystem):
            object.__setattr__(self, "_named", self.structure)
            object.__setattr__(self, "structure", self.structure.structure)
        if not isinstance(self.structure, LinearStructure):
            raise TypeError(f"structure = {self.structure!r} is not a LinearStructure (or the paper's TwoDofSystem)")
        if not isinstance(self.load, LoadSpec):
            raise TypeError(f"load = {self.load!r} is not a LoadSpec")
        stops = tuple(self.stops)
        if not stops or not all(isinstance(spec, StopSpec) for spec in stops):
            raise TypeError(f"stops = {self.stops!r}: expected a non-empty tuple of StopSpec")
        size = self.structure.size
        for k, spec in enumerate(stops):
            if not 0 <= spec.coordinate < size or (spec.other is not None and not 0 <= spec.other < size):
                raise ValueError(f"stops[{k}]: acts on a coordinate the structure does not have (it has {size}: {', '.join(self.structure.coordinates)})")
        object.__setattr__(self, "stops", stops)

    # ------------------------------------------------------------------ reading
    @property
    def coordinates(self) -> tuple[str, ...]:
        """Names of the structure's coordinates."""
        return tuple(self.structure.coordinates)

    @property
    def size(self) -> int:
        """N, the number of degrees of freedom."""
        return self.structure.size

    def paper_view(self) -> TwoDofSystem | None:
        """The paper's named system where this is the paper's layout, however it was written; None otherwise.

        The paper's layout: the structure is the two-mass chain x1 (primary), x2 (absorber) (:meth:`TwoDofSystem.of`),
        with one upper stop of x2 against the base and the harmonic force on x1 only (no constant force, no base
        motion). This is the one place that says so; the named view is where the paper's own route (its curve-fitted
        periodic Green function), its tables and its resonance bands apply.
        """
        if self.size != 2 or len(self.stops) != 1 or self.stops[0].place != PAPER_STOP.place or not self.load.primary_force:
            return None
        return self._named if self._named is not None else TwoDofSystem.of(self.structure)

    def named_view(self) -> TwoDofSystem | None:
        """The structure's named view (m1 ... b2) whatever its load and stops: the parameters as written, or those of
        a structure that is the two-mass chain; None otherwise."""
        return self._named if self._named is not None else TwoDofSystem.of(self.structure)

    @property
    def problem_structure(self) -> LinearStructure:
        """The structure every problem of this layout holds (:meth:`problem_with`): the named view's own matrices
        where the layout has one, else :attr:`structure`."""
        return self._named.structure if self._named is not None else self.structure

    def normals(self) -> np.ndarray:
        """n of every stop, shape (K, N) [-]: the stopped coordinate is n_k . x, its gap Delta_k - n_k . x (the rows
        of a problem's :meth:`~vibroimpact.model.problem.ImpactProblem.normals`)."""
        size = self.size
        return np.array([place_normal(spec.place, size) for spec in self.stops]).reshape(-1, size)

    def clearances(self, clearance: float = math.nan) -> tuple[float, ...]:
        """Delta of every stop [m]: its own, else ``clearance`` (the grid's; NaN: not known)."""
        return tuple(spec.clearance if spec.clearance is not None else clearance for spec in self.stops)

    def check_room(self, clearance: float = math.nan) -> None:
        """``ValueError`` if two opposite stops on the same (relative) coordinate leave it no room (their clearances
        sum to <= 0), with each stop's own Delta or ``clearance`` [m] (the grid's) for those that give none; a stop
        whose Delta is not known (NaN) is not judged. The message is the one a problem with these stops raises
        (:func:`~vibroimpact.model.contact.check_room`)."""
        check_room([spec.place for spec in self.stops], self.clearances(clearance), self.coordinates)

    def with_stops(self, stops: tuple[StopSpec, ...]) -> Layout:
        """The same structure and load with ``stops`` (the named view kept)."""
        layout = Layout(self.structure, self.load, stops)
        object.__setattr__(layout, "_named", self._named)
        return layout

    @classmethod
    def of_problem(cls, problem: ImpactProblem) -> Layout:
        """The layout of ``problem``: its structure, load and where its stops act (their values left out)."""
        excitation = problem.excitation
        load = LoadSpec(excitation.weights, excitation.static, isinstance(excitation, HarmonicForce) and excitation.base_motion)
        system = problem.system
        return cls(system, load, tuple(StopSpec(stop.coordinate, stop.other, stop.side) for stop in problem.stops))

    # ------------------------------------------------------------------ problems
    def problem(
        self, amplitude: float, frequency: float, restitution: float, clearance: float, bumper: bool = False,
        bumper_frequency: float = math.nan, loss_factor: float = math.nan, phase: float = 0.0,
    ) -> ImpactProblem:  # fmt: skip
        """The impact problem at one grid point.

        Parameters
        ----------
        amplitude : float
            q [N] (for a base motion, Y [m]).
        frequency : float
            Excitation frequency [Hz].
        restitution, clearance : float
            R [-] and Delta [m] of the stops that give none themselves.
        bumper : bool
            Kelvin-Voigt bumpers instead of rigid stops.
        bumper_frequency, loss_factor : float
            Omega_b / 2 pi [Hz] and xi_b [-] of bumpers that give none (NaN: none; xi_b then follows R).
        phase : float
            Phase of the harmonic load at t = 0 [rad].
        """
        stops = build_stops(self.stops, bumper, restitution, clearance, bumper_frequency, loss_factor)
        return self.problem_with(stops, self.load.force(amplitude, frequency, phase))

    def problem_with(self, stops: tuple[Stop, ...], excitation: HarmonicForce | SweptSine) -> ImpactProblem:
        """The impact problem of this structure with model ``stops`` (built from this layout's, or a variant of them)
        and ``excitation``."""
        return ImpactProblem(self._named if self._named is not None else self.structure, stops, excitation)

    # ------------------------------------------------------------- attributes
    def attributes(self, restitution: np.ndarray, clearance: np.ndarray, bumper_frequency: np.ndarray | None = None) -> dict[str, object]:
        """What a dataset records of the layout (plain netCDF attributes: matrices flattened row by row, names and
        descriptions joined, one value per stop), read back by :meth:`from_attributes`.

        ``restitution`` [-] and ``clearance`` [m] are the values the study gives the stops that take them (one value:
        stated; several: swept). The named view's parameters (``system_m1`` ... ``system_b2``) are written where the
        structure has one. Where a stop's bumper was given in physical units, ``stop_bumper_stiffness_N_per_m`` and
        ``stop_bumper_damping_N_s_per_m`` record them (one per stop, NaN where not given) and the stops' words say
        them beside the grid's ``bumper_frequency`` [Hz]."""
        structure = self.structure
        size = structure.size
        specs = self.stops
        attrs: dict[str, object] = {}
        named = self.named_view()
        if named is not None:
            attrs.update({f"system_{key}": value for key, value in named.as_dict().items()})
        return attrs | {
            "system_size": size,
            "system_coordinates": " ".join(structure.coordinates),
            "system_mass_kg": _attribute(structure.mass_matrix),
            "system_stiffness_N_per_m": _attribute(structure.stiffness_matrix),
            "system_damping_N_s_per_m": _attribute(structure.damping_matrix),
            "excitation_kind": "base_motion" if self.load.base_motion else "force",
            "excitation_weights": _attribute(self.load.weight_vector(size)),
            "excitation_static_N": _attribute(self.load.static_vector(size)),
            "stop_count": len(specs),
            "stop_layout": "; ".join(stop_descriptions(specs, tuple(structure.coordinates), restitution, clearance, bumper_frequency)),
            "stop_coordinate": _attribute([spec.coordinate for spec in specs]),
            "stop_other": _attribute([-1 if spec.other is None else spec.other for spec in specs]),
            "stop_side": " ".join(spec.side for spec in specs),
            # each stop's own clearance, or the grid's single value; NaN where the grid sweeps it
            "stop_clearance_m": _attribute([
                float(spec.clearance) if spec.clearance is not None else (float(clearance[0]) if clearance.size == 1 else np.nan) for spec in specs
            ]),  # fmt: skip
        } | self._bumper_attributes()

    def _bumper_attributes(self) -> dict[str, object]:
        """K_b [N m-1] and B_b [N s m-1] of the stops whose bumpers were given in physical units (NaN where not); none
        where no stop's was."""
        if all(spec.bumper_stiffness is None for spec in self.stops):
            return {}
        return {
            "stop_bumper_stiffness_N_per_m": _attribute([np.nan if spec.bumper_stiffness is None else spec.bumper_stiffness for spec in self.stops]),
            "stop_bumper_damping_N_s_per_m": _attribute([np.nan if spec.bumper_damping is None else spec.bumper_damping for spec in self.stops]),
        }

    @classmethod
    def from_attributes(cls, attrs: Mapping[str, object]) -> Layout:
        """The layout a dataset's attributes record (:meth:`attributes`): the structure, the load and every stop with
        its recorded clearance (NaN: swept). A dataset written before the layout was recorded (only ``system_m1`` ...
        ``system_b2``) had the paper's layout on that named system.

        Raises
        ------
        KeyError
            Naming a missing attribute.
        """
        named = TwoDofSystem(**{key: float(attrs[f"system_{key}"]) for key in NAMED_KEYS}) if "system_m1" in attrs else None  # type: ignore[arg-type]
        if "system_size" not in attrs:
            if named is None:
                raise KeyError("system_size")
            return cls(named)
        size = int(attrs["system_size"])  # type: ignore[call-overload]

        def matrix(key: str) -> np.ndarray:
            return np.asarray(attrs[key], dtype=float).reshape(size, size)

        names = tuple(str(attrs["system_coordinates"]).split())
        structure = LinearStructure(matrix("system_mass_kg"), matrix("system_stiffness_N_per_m"), matrix("system_damping_N_s_per_m"), names)
        coordinate = np.atleast_1d(np.asarray(attrs["stop_coordinate"], dtype=int))
        other = np.atleast_1d(np.asarray(attrs["stop_other"], dtype=int))
        sides = str(attrs["stop_side"]).split()
        if "stop_clearance_m" in attrs:
            clearances = np.atleast_1d(np.asarray(attrs["stop_clearance_m"], dtype=float))
        else:
            described = [part.strip() for part in str(attrs["stop_layout"]).split(";")]
            clearances = np.array([_described_clearance(words, side) for words, side in zip(described, sides)])
        given = [np.atleast_1d(np.asarray(attrs.get(key, np.nan), dtype=float)) for key in ("stop_bumper_stiffness_N_per_m", "stop_bumper_damping_N_s_per_m")]
        k_b, b_b = (np.broadcast_to(values, clearances.shape) for values in given)  # the bumpers given in physical units
        stops = tuple(
            StopSpec(int(i), None if j < 0 else int(j), side, None if not np.isfinite(d) else float(d),
                     bumper_stiffness=float(k) if np.isfinite(k) else None, bumper_damping=float(b) if np.isfinite(b) else None)
            for i, j, side, d, k, b in zip(coordinate, other, sides, clearances, k_b, b_b)
        )  # fmt: skip
        base_motion = attrs.get("excitation_kind") == "base_motion"
        weights = tuple(float(w) for w in np.atleast_1d(np.asarray(attrs["excitation_weights"], dtype=float)))
        static = tuple(float(f) for f in np.atleast_1d(np.asarray(attrs["excitation_static_N"], dtype=float)))
        load = LoadSpec(weights if len(weights) == size and not base_motion else None, static if len(static) == size else None, base_motion)
        layout = cls(structure, load, stops)
        if named is not None and np.allclose(named.structure.stiffness_matrix, structure.stiffness_matrix, rtol=1e-12, atol=0.0) and named.structure.coordinates == names:
            object.__setattr__(layout, "_named", named)  # the parameters as recorded, not recovered from the matrices
        return layout
