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
:func:`closed_form_refusal` returns that reason as a string (None where a closed form applies). The rules that are
not about the load or the contact law live in :func:`closed_form_kind` alone, which both ask, and so does
:func:`layout_refusal`, the same question of a :class:`~vibroimpact.model.layout.Layout` (its stops' geometry, and
the grid's values where a rule needs one) without building a problem.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from vibroimpact.model.contact import place_normal
from vibroimpact.model.excitation import HarmonicForce, load_weights
from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.model.layout import Layout
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.structure import LinearStructure

__all__ = ["ClosedFormLayout", "closed_form_kind", "closed_form_layout", "closed_form_refusal", "layout_refusal", "harmonic_load", "harmonic_load_of", "static_offset", "KINDS"]

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


def _same(a: float, b: float) -> bool:
    """Equal within :data:`_EQUAL`, or not known (NaN: not judged)."""
    return math.isnan(a) or math.isnan(b) or _close(a, b)


def closed_form_kind(
    structure: LinearStructure, places: Sequence[tuple[int, int | None, str]], clearances: Sequence[float], restitutions: Sequence[float],
    static: ArrayLike, scale: Callable[[], float],
) -> tuple[str, tuple[int, ...]]:  # fmt: skip
    """The closed form rigid stops at ``places`` have on ``structure`` under a harmonic load, and the stops it uses;
    ``ValueError`` saying why none does. The rules that are not about the load or the contact law (module docstring):
    the one place they live.

    Parameters
    ----------
    structure : LinearStructure
        M, K, C.
    places : sequence of (int, int or None, str)
        (coordinate, other, side) of every stop.
    clearances, restitutions : sequence of float
        Delta [m] and R [-] of every stop; a value that is not known (NaN) is not judged (it refuses nothing).
    static : array_like, shape (N,)
        The constant load F0 [N].
    scale : callable
        () -> the length [m] a two-sided stop's static offset n . K^-1 F0 must be negligible against (within 1e-12),
        asked only of a symmetric pair.

    Returns
    -------
    kind : str
        ``one_impact`` or ``two_impacts``.
    stops : tuple of int
        The stop (one impact), or the upper and the lower stop of the pair (two impacts).
    """
    rigid_modes = structure.rigid_body_modes()
    if rigid_modes:
        raise ValueError(
            f"system.stiffness: the structure has {rigid_modes} rigid-body mode(s) (a free mass): the periodic Green function "
            "sum_n h(t + nT) does not exist, so there is no closed-form impact orbit; use a time-domain engine"
        )
    size = structure.size
    if len(places) == 1:
        return "one_impact", (0,)
    if len(places) == 2:
        n1, n2 = place_normal(places[0], size), place_normal(places[1], size)
        pair = np.allclose(n1, -n2, rtol=0.0, atol=0.0)
        if pair and _same(clearances[0], clearances[1]) and _same(restitutions[0], restitutions[1]):
            if clearances[0] <= 0.0:
                raise ValueError(f"stops: the two-sided stop's clearance {clearances[0]!r} leaves no room between its sides: allowed (0, inf)")
            offset = static_offset(structure, n1, static)
            if abs(offset) > _EQUAL * scale():
                raise ValueError(
                    f"excitation.static: the static load moves the two-sided stop's coordinate by {offset:.6g} m; the symmetric "
                    "two-impacts orbit needs none (use a time-domain engine)"
                )
            return "two_impacts", (0, 1) if places[0][2] == "upper" else (1, 0)
        why = "they are not on the same coordinate with opposite sides" if not pair else "their clearances or restitutions differ"
        raise ValueError(f"stops: the two stops do not form a symmetric two-sided stop ({why}); no closed form applies (use a time-domain engine)")
    raise ValueError(
        f"stops: the problem has {len(places)} stops; the closed forms cover one stop, or a symmetric two-sided pair (use a time-domain engine)"
    )


def closed_form_layout(problem: ImpactProblem) -> ClosedFormLayout:
    """The closed form that applies to ``problem`` (module docstring), or ``ValueError`` saying why none does: a
    harmonic force and rigid stops, then the rules of :func:`closed_form_kind` (a two-sided stop's static offset
    negligible against Delta + |n . H F|)."""
    if not isinstance(problem.excitation, HarmonicForce):
        raise ValueError(f"excitation: the closed-form impact orbits need a harmonic force, got a {type(problem.excitation).__name__}")
    stops = problem.stops
    for k, stop in enumerate(stops):
        if not stop.rigid:
            raise ValueError(f"stops[{k}]: the closed-form impact orbits need rigid stops (an impulse), got a {type(stop.law).__name__}")
    structure = problem.structure
    kind, chosen = closed_form_kind(
        structure, [stop.place for stop in stops], [stop.clearance for stop in stops], [stop.law.restitution for stop in stops],
        problem.load()[1], lambda: stops[0].clearance + problem.gap_amplitude(0),
    )  # fmt: skip
    first = stops[0]
    n = stops[chosen[0]].normal(structure.size)
    return ClosedFormLayout(kind, structure, n, chosen, first.effective_mass(structure.mass_matrix), first.clearance, first.law.restitution)


@suggest_keywords
def closed_form_refusal(problem: ImpactProblem) -> str | None:
    """Why no closed form applies to ``problem`` (the message of :func:`closed_form_layout`), or None."""
    try:
        closed_form_layout(problem)
    except ValueError as error:
        return str(error)
    return None


def layout_refusal(layout: Layout, restitution: float = math.nan, clearance: float = math.nan) -> str | None:
    """Why no closed form applies to ``layout`` with rigid stops under its harmonic load, or None: the question of
    :func:`closed_form_refusal` asked of the layout, with the same rules (:func:`closed_form_kind`) and messages.

    A layout's load is harmonic and the closed forms build rigid stops, so what remains is geometry: no rigid-body
    mode, one stop or two opposite stops on the same (relative) coordinate, and no static offset of that coordinate.
    Two rules of a two-sided stop depend on values: its sides must have equal clearances (> 0) and equal
    restitutions, each the stop's own or the grid's ``restitution`` [-], ``clearance`` [m]; a value neither gives
    (NaN) is not judged. The static offset n . K^-1 F0 must be negligible (1e-12) against the pair's clearance (a
    problem compares it with Delta + |n . H F|, which needs the load's amplitude and frequency).
    """
    values = [spec.values(restitution, clearance) for spec in layout.stops]
    clearances = [delta for _, delta, _, _ in values]
    try:
        closed_form_kind(
            layout.problem_structure, [spec.place for spec in layout.stops], clearances, [r for r, _, _, _ in values],
            layout.load.static_vector(layout.size), lambda: clearances[0],
        )  # fmt: skip
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
