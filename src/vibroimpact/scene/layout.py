"""What a general scene says beyond the paper's layout: the load and the stops, checked values only.

A scene written in the paper's named form (``system: {m1 ... b2}``, ``excitation: {amplitude}``, ``stop:``) has no
:class:`LoadSpec` and no :class:`StopSpec`: it means what it always meant (one upper stop on the absorber, the force
on the primary mass) and writes the paper's outputs. Anything else is a *general* scene: its structure is any
:class:`~vibroimpact.model.structure.LinearStructure` (or the named one), its load a :class:`LoadSpec` and its stops
:class:`StopSpec` entries, and its outputs are named after its coordinates and stops.

Values of a stop follow the study's grid where the stop gives none (a swept parameter, or one value shared by every
stop); :func:`build_stops` turns the specifications and one grid point into model :class:`~vibroimpact.model.contact.Stop`
objects. Nothing here reads YAML (:mod:`vibroimpact.scene.layout_parse` does).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop, loss_factor_from_restitution, restitution_from_loss_factor, Stop
from vibroimpact.model.excitation import HarmonicForce

__all__ = ["LoadSpec", "StopSpec", "build_stops", "stop_descriptions", "describe_stop"]


@dataclass(frozen=True)
class LoadSpec:
    """How a general scene loads its structure.

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


@dataclass(frozen=True)
class StopSpec:
    """One stop of a general scene, as checked: where it acts and the values it gives itself.

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
    """

    coordinate: int
    other: int | None = None
    side: str = "upper"
    clearance: float | None = None
    restitution: float | None = None
    bumper_frequency: float | None = None
    bumper_loss_factor: float | None = None

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


def build_stops(specs: tuple[StopSpec, ...], bumper: bool, restitution: float, clearance: float, bumper_frequency: float = math.nan, loss_factor: float = math.nan) -> tuple[Stop, ...]:
    """The model's stops at one grid point: rigid stops (``bumper`` False) or Kelvin-Voigt bumpers.

    Parameters
    ----------
    specs : tuple of StopSpec
        The scene's stops.
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


def describe_stop(spec: StopSpec, names: tuple[str, ...], clearance: float | None = None, restitution: float | None = None) -> str:
    """The stop in words, e.g. ``x2 - x1 <= 3 mm, R = 0.2`` (``Delta`` and ``R`` where the grid sweeps them)."""
    delta = spec.clearance if spec.clearance is not None else clearance
    r = spec.restitution if spec.restitution is not None else restitution
    target = names[spec.coordinate] if spec.other is None else f"{names[spec.coordinate]} - {names[spec.other]}"
    relation = "<=" if spec.side == "upper" else ">="
    if delta is None or not np.isfinite(delta):
        bound = "Delta" if spec.side == "upper" else "-Delta"
    else:
        bound = f"{(delta if spec.side == 'upper' else -delta) * 1e3 + 0.0:g} mm"  # + 0.0: no "-0 mm"
    words = f"{target} {relation} {bound}"
    if r is not None and np.isfinite(r):
        words += f", R = {r:g}"
    if spec.bumper_frequency is not None:
        words += f", bumper {spec.bumper_frequency:g} Hz"
    return words


def stop_descriptions(specs: tuple[StopSpec, ...], names: tuple[str, ...], restitution: np.ndarray, clearance: np.ndarray) -> tuple[str, ...]:
    """Each stop in words; a value shared through a one-point grid is written out, a swept one as ``Delta``/``R``."""
    delta = float(clearance[0]) if clearance.size == 1 else None
    r = float(restitution[0]) if restitution.size == 1 else None
    return tuple(describe_stop(spec, names, delta, r) for spec in specs)
