"""Contact onsets located in closed form where one side of them is contact-free.

Where a branch of periodic orbits meets the stops' contact onset (the rigid stop's grazing, a bumper's tangency) and
one side of it has no contact, the orbit on that side is the linear steady state, known in closed form
(:meth:`vibroimpact.orbits.maps.ImpactMap.linear_orbit`): the onset is where it touches a stop, the root of its least
clearance min_k (Delta_k - |n_k . X(p)| - n_k . x0(p)) in the continued parameter p. A bracket is widened around the
continuation's own estimate until that clearance changes sign, and Brent's method finds the root to round-off. The
orbit there is the linear orbit touching the stop: the grazing orbit itself, not a neighbour.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import brentq

from vibroimpact.orbits.branch import ParametrisedMap

__all__ = ["contact_free_onset", "impacting_ladder", "linear_clearance", "stability_change", "touches_ahead", "SCAN_POINTS", "LADDER"]

#: The distances to grazing (approach speed over w L) of the closed-form impacting orbits that carry a rigid stop's
#: branch to and from its onset: 1.5625e-5 doubling to 1e-3, where arclength steps take over (the impacting orbit's
#: multipliers grow like one over the impact speed next to grazing, and Newton's region shrinks with it). The first
#: is 16 times the rigid engines' default sticking velocity (1e-6 of the velocity scale): slower impacts end in
#: sticking there, and the engine's orbit is no longer the closed form's.
LADDER = tuple(1.5625e-5 * 2.0**k for k in range(7))


def impacting_ladder(system: ParametrisedMap, p: NDArray[np.float64], index: int, root: float, margins: tuple[float, ...] = LADDER) -> list[tuple[NDArray[np.float64], NDArray[np.float64], float]]:
    """The closed-form one-impact orbits (:meth:`~vibroimpact.orbits.maps.ImpactMap.impact_orbit`) next to a rigid
    stop's onset at parameter ``index`` = ``root``, at about the distances to grazing ``margins`` [-], on the side of
    the onset where they exist: (state, parameters, margin) of each, in the order of ``margins``; empty where the map
    has no closed-form impact orbit or none is born at the onset.

    Next to the onset the orbit's impact speed grows linearly with the parameter's distance to it (the impulse is a
    simple root of eq. 16 at J = 0), so a probe at 1e-9 of the root's magnitude (or of 1) sets the offset of each margin,
    refined by one secant step. The ladder ends at the first margin no orbit comes within a factor 2 of: where the
    impulse does not grow from 0 at the root (it jumps to a finite orbit, e.g. one that exists on both sides), the
    orbits found are not the ones born there."""
    closed = getattr(system, "impact_orbit", None)
    if closed is None or not margins:
        return []
    probe = 1e-9 * max(abs(root), 1.0)
    found = None
    for sign in (1.0, -1.0):
        q = np.array(p, dtype=float)
        q[index] = root + sign * probe
        found = closed(q)
        if found is not None and found[1] > 0.0:
            break
        found = None
    if found is None:
        return []
    slope = found[1] / probe  # margin per unit of the parameter's distance to the onset
    ladder = []
    for target in margins:
        offset = target / slope
        for _ in range(2):  # the first guess, then one secant step on the margin
            q = np.array(p, dtype=float)
            q[index] = root + sign * offset
            orbit = closed(q)
            if orbit is None or not orbit[1] > 0.0:
                break
            if abs(orbit[1] - target) <= 0.05 * target:
                break
            offset *= target / orbit[1]
        if orbit is None or not 0.5 * target <= orbit[1] <= 2.0 * target:
            break  # no orbit near this margin: the one found is not born at the onset (the impulse jumps there)
        ladder.append((orbit[0], q, orbit[1]))
    return ladder


def linear_clearance(system: ParametrisedMap, p: NDArray[np.float64], index: int, value: float) -> float:
    """The contact-free orbit's least clearance [-] with parameter ``index`` set to ``value`` (NaN: none)."""
    closed = getattr(system, "linear_orbit", None)
    q = np.array(p, dtype=float)
    q[index] = value
    found = None if closed is None else closed(q)
    return math.nan if found is None else found[1]


def contact_free_onset(system: ParametrisedMap, p: NDArray[np.float64], index: int, estimate: float, reach: float) -> tuple[float, NDArray[np.float64]] | None:
    """The parameter value [its unit] where the contact-free orbit touches a stop, within ``reach`` of ``estimate``,
    and the parameter vector there; None where the map has no closed-form contact-free orbit, or its clearance does
    not change sign within ``reach`` (the point is no onset from a contact-free side).

    Parameters
    ----------
    system : ParametrisedMap
        The map (an ``ImpactMap``, or an iterate of one).
    p : ndarray
        A parameter vector; entry ``index`` is the continued parameter.
    estimate : float
        The continuation's estimate of the onset.
    reach : float
        How far from ``estimate`` the onset may lie [the parameter's unit], > 0.
    """
    if getattr(system, "linear_orbit", None) is None or not math.isfinite(estimate) or not reach > 0.0:
        return None
    at = linear_clearance(system, p, index, estimate)
    if not math.isfinite(at):
        return None
    if at == 0.0:  # exact: the estimate touches already
        root = estimate
    else:
        width = max(reach * 1e-6, abs(estimate) * 1e-14)
        root, ends = math.nan, math.nan
        while width <= reach:
            for end in (estimate - width, estimate + width):
                there = linear_clearance(system, p, index, end)
                if math.isfinite(there) and there * at <= 0.0:
                    low, high = sorted((estimate, end))
                    root = brentq(lambda v: linear_clearance(system, p, index, v), low, high, xtol=1e-300, rtol=4.0 * np.finfo(float).eps, maxiter=200)
                    ends = max(abs(at), abs(there))
                    break
            if math.isfinite(root):
                break
            width *= 2.0
        if not math.isfinite(root):
            return None
        if not abs(linear_clearance(system, p, index, root)) <= ends:  # a pole (or a gap) the sign changed across, no zero
            return None
    q = np.array(p, dtype=float)
    q[index] = root
    return float(root), q


def stability_change(before: NDArray[np.complex128], after: NDArray[np.complex128]) -> str:
    """How the Floquet multipliers change across a contact onset, in words: '' where as many lie outside the unit
    circle on both sides; else which cross it ('a complex pair', 'a real multiplier through +1' / '-1') and the
    largest moduli on each side, named as the discontinuity-induced bifurcation it is.

    Parameters
    ----------
    before, after : ndarray of complex
        The multipliers of the orbits on the two sides, in the order the branch passes them.
    """
    outside_before = np.abs(before) > 1.0
    outside_after = np.abs(after) > 1.0
    if int(outside_before.sum()) == int(outside_after.sum()):
        return ""
    gained = int(outside_after.sum()) > int(outside_before.sum())
    changed = after[outside_after] if gained else before[outside_before]
    complex_pair = bool(np.any(np.abs(changed.imag) > 1e-9 * np.abs(changed)))
    if complex_pair:
        what, name = "a complex pair of multipliers", "Neimark-Sacker"
    elif np.any(changed.real < 0.0):
        what, name = "a real multiplier through -1", "period doubling"
    else:
        what, name = "a real multiplier through +1", "fold"
    way = "leaves" if gained else "enters"
    return (f"{what} {way} the unit circle across it, largest |mu| {np.max(np.abs(before)):.4g} -> {np.max(np.abs(after)):.4g}: "
            f"a discontinuity-induced {name}")


#: Points of the closed-form scan for a contact ahead of a contact-free stretch (:func:`touches_ahead`).
SCAN_POINTS = 4001


def touches_ahead(system: ParametrisedMap, p: NDArray[np.float64], index: int, way: float, lower: float, upper: float) -> bool:
    """Does the contact-free orbit touch a stop anywhere ahead of parameter ``index``'s value in ``p``, going ``way``
    (+1 up, -1 down), up to the bound (``lower``/``upper``), or within a decade of the value where that bound is
    infinite? Scanned in closed form over :data:`SCAN_POINTS` values (geometric where the value keeps its sign,
    linear otherwise); True without a closed form (then nothing may end the stretch early)."""
    if getattr(system, "linear_orbit", None) is None:
        return True
    value = float(p[index])
    end = upper if way > 0.0 else lower
    if not math.isfinite(end):
        magnitude = max(abs(value), 1e-300)
        end = value + way * 9.0 * magnitude if way > 0.0 or value <= 0.0 else value / 10.0
    if (end - value) * way <= 0.0:
        return False
    if value > 0.0 and end > 0.0:
        values = np.geomspace(value, end, SCAN_POINTS)
    else:
        values = np.linspace(value, end, SCAN_POINTS)
    for v in values[1:]:
        clearance = linear_clearance(system, p, index, float(v))
        if math.isfinite(clearance) and clearance <= 0.0:
            return True
    return False
