"""Which closed-form impact orbit a problem's layout has, and its harmonic load at any frequency.

The closed forms (:mod:`~vibroimpact.analysis.pgf` for one stop, :mod:`~vibroimpact.analysis.impact_orbit` for a symmetric pair) superpose the linear response and
the response to a train of impulses through Green functions of the stopped coordinate. That needs

* a harmonic force (the forcing must be periodic),
* rigid stops only (a bumper has no impulse),
* no rigid-body mode: the periodic Green function sum_n h(t + n T) diverges for a pole at 0 (a free mass drifts under
  a train of impulses of one sign), and a static load needs K^-1;
* one stop (absolute or relative, upper or lower), or two stops on the same coordinate (or relative coordinate), one
  upper and one lower, with equal clearance > 0 and equal restitution, and no static load on that coordinate (the
  symmetric two-impacts-per-period orbit u(t + T/2) = -u(t)).

:func:`closed_form_layout` returns the layout or raises ``ValueError`` saying which condition fails;
:func:`closed_form_refusal` returns that reason as a string (None where a closed form applies).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from vibroimpact.model.excitation import HarmonicForce, load_weights
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.structure import LinearStructure

__all__ = ["ClosedFormLayout", "closed_form_layout", "closed_form_refusal", "harmonic_load", "harmonic_load_of", "static_offset", "KINDS"]

#: The closed forms: one impact per period on one stop, two per period on a symmetric two-sided stop.
KINDS = ("one_impact", "two_impacts")

#: Relative tolerance for "equal" clearances and restitutions of a two-sided pair, and for a zero static offset.
_EQUAL = 1e-12


@dataclass(frozen=True, eq=False)
class ClosedFormLayout:
    """The part of a problem a closed form uses.

    Attributes
    ----------
    kind : str
        ``one_impact`` or ``two_impacts`` (:data:`KINDS`).
    structure : LinearStructure
        M, K, C.
    normal : ndarray, shape (N,)
        n of the (upper, for a pair) stop: the stopped coordinate is u = n . x and its gap Delta - u.
    stops : tuple of int
        Index of the stop (``one_impact``), or of the upper and the lower stop of the pair (``two_impacts``).
    effective_mass : float
        m_eff = 1 / (n^T M^-1 n) [kg].
    clearance : float
        Delta [m] of the problem's stop(s).
    restitution : float
        R [-] of the problem's stop(s).
    """

    kind: str
    structure: LinearStructure
    normal: NDArray[np.float64]
    stops: tuple[int, ...]
    effective_mass: float
    clearance: float
    restitution: float

    @property
    def two_sided(self) -> bool:
        """Is it the symmetric two-impacts orbit?"""
        return self.kind == "two_impacts"


def _close(a: float, b: float) -> bool:
    return abs(a - b) <= _EQUAL * max(abs(a), abs(b), 1e-300)


def closed_form_layout(problem: ImpactProblem) -> ClosedFormLayout:
    """The closed form that applies to ``problem`` (module docstring), or ``ValueError`` saying why none does."""
    if not isinstance(problem.excitation, HarmonicForce):
        raise ValueError(f"excitation: the closed-form impact orbits need a harmonic force, got a {type(problem.excitation).__name__}")
    stops = problem.stops
    for k, stop in enumerate(stops):
        if not stop.rigid:
            raise ValueError(f"stops[{k}]: the closed-form impact orbits need rigid stops (an impulse), got a {type(stop.law).__name__}")
    structure = problem.structure
    rigid_modes = structure.rigid_body_modes()
    if rigid_modes:
        raise ValueError(
            f"system.stiffness: the structure has {rigid_modes} rigid-body mode(s) (a free mass): the periodic Green function "
            "sum_n h(t + nT) does not exist, so there is no closed-form impact orbit; use a time-domain engine"
        )
    size = structure.size
    mass = structure.mass_matrix
    if len(stops) == 1:
        n = stops[0].normal(size)
        return ClosedFormLayout("one_impact", structure, n, (0,), stops[0].effective_mass(mass), stops[0].clearance, stops[0].law.restitution)
    if len(stops) == 2:
        first, second = stops
        n1, n2 = first.normal(size), second.normal(size)
        pair = np.allclose(n1, -n2, rtol=0.0, atol=0.0)
        if pair and _close(first.clearance, second.clearance) and _close(first.law.restitution, second.law.restitution):
            if first.clearance <= 0.0:
                raise ValueError(f"stops: the two-sided stop's clearance {first.clearance!r} leaves no room between its sides: allowed (0, inf)")
            _, static = problem.load()
            offset = static_offset(structure, n1, static)
            scale = first.clearance + problem.gap_amplitude(0)
            if abs(offset) > _EQUAL * scale:
                raise ValueError(
                    f"excitation.static: the static load moves the two-sided stop's coordinate by {offset:.6g} m; the symmetric "
                    "two-impacts orbit needs none (use a time-domain engine)"
                )
            upper, lower = (0, 1) if first.side == "upper" else (1, 0)
            n = stops[upper].normal(size)
            return ClosedFormLayout("two_impacts", structure, n, (upper, lower), first.effective_mass(mass), first.clearance, first.law.restitution)
        why = "they are not on the same coordinate with opposite sides" if not pair else "their clearances or restitutions differ"
        raise ValueError(f"stops: the two stops do not form a symmetric two-sided stop ({why}); no closed form applies (use a time-domain engine)")
    raise ValueError(
        f"stops: the problem has {len(stops)} stops; the closed forms cover one stop, or a symmetric two-sided pair (use a time-domain engine)"
    )


def closed_form_refusal(problem: ImpactProblem) -> str | None:
    """Why no closed form applies to ``problem`` (the message of :func:`closed_form_layout`), or None."""
    try:
        closed_form_layout(problem)
    except ValueError as error:
        return str(error)
    return None


def harmonic_load(problem: ImpactProblem, omega: ArrayLike, amplitude: ArrayLike | None = None) -> NDArray[np.complex128]:
    """F(w): the complex harmonic load per coordinate [N] of ``problem`` at angular frequencies ``omega``
    (:func:`harmonic_load_of` its structure and harmonic force)."""
    return harmonic_load_of(problem.structure, problem.harmonic, omega, amplitude)


def harmonic_load_of(structure: LinearStructure, excitation: HarmonicForce, omega: ArrayLike, amplitude: ArrayLike | None = None) -> NDArray[np.complex128]:
    """F(w): the complex harmonic load per coordinate [N] at angular frequencies ``omega``, shape omega.shape + (N,).

    The load is Re(F e^{jwt}) in the excitation's time (its phase included). A force is q w_i e^{j phase} whatever
    w; a base motion's inertial load M 1 Y w^2 e^{j phase} grows with w. ``amplitude`` (q or Y, broadcast against
    ``omega``) replaces the excitation's.
    """
    w = np.asarray(omega, dtype=float)
    q = np.asarray(excitation.amplitude if amplitude is None else amplitude, dtype=float)
    w, q = np.broadcast_arrays(w, q)
    phasor = complex(math.cos(excitation.phase), math.sin(excitation.phase))
    size = structure.size
    if excitation.base_motion:
        distribution = structure.mass_matrix @ np.ones(size)
        return distribution * (q * w**2 * phasor)[..., None]
    return load_weights(excitation.weights, size) * (q * phasor)[..., None]


def static_offset(structure: LinearStructure, normal: ArrayLike, static: ArrayLike) -> float:
    """n . K^-1 F0 [m]: how far a constant load moves the stopped coordinate (0 for no load)."""
    load = np.asarray(static, dtype=float)
    if not np.any(load):
        return 0.0
    return float(np.asarray(normal, dtype=float) @ np.linalg.solve(structure.stiffness_matrix, load))
