"""What a continuation does at a contact onset: locate it, name what happens across it, and step off it.

:class:`OnsetSteps` is the part of the continuation's walker (:mod:`~vibroimpact.orbits.continuation`) that acts at
grazing points: the point located by :func:`~vibroimpact.orbits.bifurcations.locate_grazing`, then in closed form where
one side is contact-free (:mod:`~vibroimpact.orbits.onsets`); the orbit beyond it pointed away from it, whichever way
the branch leaves (on through, or back: a nonsmooth fold); next to a soft contact's onset, where the branch curves too
sharply for arclength steps, the orbits at growing distances from grazing (:meth:`OnsetSteps.leave`); and the note
that names the stability change across the point as a discontinuity-induced bifurcation. The walker provides
``system``, ``index``, ``name``, ``n``, ``settings``, ``arc``, ``specials`` and ``tolerance()``.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from vibroimpact.orbits.arclength import Point
from vibroimpact.orbits.bifurcations import grazing_margin, locate_grazing
from vibroimpact.orbits.branch import SpecialPoint
from vibroimpact.orbits.onsets import contact_free_onset, impacting_ladder, stability_change

__all__ = ["OnsetSteps", "NOT_GRAZING", "signature_of"]

#: What :meth:`OnsetSteps.grazing` returns when the failed step it was given was no grazing point.
NOT_GRAZING = object()


def signature_of(point: Point) -> tuple[int, int] | None:
    """(impacts, sticks) of a point's flight; None for a map without hybrid information."""
    return point.out.hybrid.signature if point.out.hybrid is not None else None


#: How far (scaled state, max norm) a contacting orbit next to a grazing point may be from the contact-free orbit at
#: its parameter for the point to be taken for an onset from a contact-free side.
ONSET_NEIGHBOURHOOD = 1e-2

#: The least distance to grazing (:func:`grazing_margin`) of a contacting orbit whose multipliers say which side of an
#: onset is stable: a rigid stop's impacting orbit has a multiplier growing like one over the impact's speed next to
#: grazing, which says nothing of the branch beyond that speed.
MEASURABLE_MARGIN = 1e-4


#: The distance to grazing within which a special point found on the last stretch to an onset is said to be induced
#: by it.
INDUCED_MARGIN = 1e-3


def _measurable(point: Point) -> bool:
    """Contact-free, or in contact at least :data:`MEASURABLE_MARGIN` from grazing."""
    hybrid = point.out.hybrid
    return hybrid is not None and (hybrid.impacts == 0 or grazing_margin(hybrid) >= MEASURABLE_MARGIN)


class OnsetSteps:
    """The walker's steps at grazing points (module docstring)."""

    system: Any
    index: int
    name: str
    n: int
    settings: Any
    arc: Any
    specials: list[tuple[float, SpecialPoint]]
    tolerance: Any  # (point) -> the arclength bracket of a located point
    touching: Point | None
    arrival: list[Point]
    reference: Point | None
    departure: list[Point]

    def clear_onset(self) -> None:
        """Forget the last onset's points (the walker's constructor, and each grazing point): its own orbit
        (``touching``), the last stretch arriving at it and the point 1e-3 from it (``arrival``, ``reference``), and
        the closed-form orbits leaving it (``departure``, for :meth:`leave`)."""
        self.touching, self.arrival, self.reference, self.departure = None, [], None, []

    def grazing(self, a: Point, sigma: float, arclength: float, hint: Point | None = None) -> object:
        """Locate a grazing point between a and sigma; return the point beyond it (None: the branch ends there)."""
        side, grazing, beyond, value = locate_grazing(self.arc, a, sigma, self.tolerance(a), self.settings.tolerance, hint)
        if not math.isfinite(value):
            return NOT_GRAZING  # a plain corrector failure, not a grazing
        onset = self.onset(side, beyond, value)
        self.clear_onset()
        if onset is not None:
            value, touching, free = onset
            grazing = touching if touching is not None else grazing
            self.touching = touching
            if side.out.hybrid.impacts > 0 and beyond is None:
                beyond = free  # the contact-free orbit carries the branch on
            margin = grazing_margin(a.out.hybrid) if signature_of(a) == signature_of(side) else math.inf
            if side.out.hybrid.impacts > 0 and touching is not None:  # arriving on the contact side: the last stretch by its margin
                stretch = self.leave(grazing, signature_of(side), side.z)
                back = [p for p in stretch if grazing_margin(p.out.hybrid) < margin]
                self.arrival = [dataclasses.replace(p, tangent=-p.tangent) for p in reversed(back)]
                self.reference = stretch[-1] if stretch else None
            elif side.out.hybrid.onset_depth is None and (side.out.hybrid.impacts > 0 or beyond is None):
                stretch = self._rigid_ladder(side, value)  # a rigid stop: the impacting orbits next to it in closed form
                if side.out.hybrid.impacts > 0:
                    back = [p for p in stretch if grazing_margin(p.out.hybrid) < margin]
                    self.arrival = [dataclasses.replace(p, tangent=-p.tangent) for p in reversed(back)]
                    self.reference = stretch[-1] if stretch else None
                elif stretch:
                    beyond, self.departure = stretch[0], stretch[1:]
        before = side.out.hybrid
        tangency = -before.closest_approach / before.length_scale <= before.speed_margin
        vanishing = "an impact's velocity goes to zero" if before.onset_depth is None else "a contact's depth goes to zero"
        what = "a free flight touches the stop" if tangency else vanishing
        if beyond is not None:
            after = beyond.out.hybrid
            if after.impacts == before.impacts:
                what = f"{what} (the sticking phases change, {before.sticks} -> {after.sticks})"
            note = f"{what}; the branch continues with {after.impacts} impact{'' if after.impacts == 1 else 's'} per period"
        else:
            note = f"{what}; no periodic orbit beyond: the branch ends"
        at = grazing if grazing is not None else side
        if beyond is not None:
            beyond = self._away(beyond, at)
        found = SpecialPoint(
            "grazing",
            at.orbit(self.system),
            self.name,
            value,
            grazing_margin(at.out.hybrid),
            note,
            continues=beyond is not None,
            impacts_after=None if beyond is None else beyond.out.hybrid.impacts,
        )
        self.graze = found  # recorded by the caller, after the points that arrive at it
        self.last_before = side
        return beyond

    def onset(self, side: Point, beyond: Point | None, value: float) -> tuple[float, Point | None, Point | None] | None:
        """Where one side of the grazing point near ``value`` is contact-free (``side`` or ``beyond`` has no contact,
        or nothing was found beyond a contacting ``side``): the onset in closed form (:mod:`~vibroimpact.orbits.
        onsets`), the linear orbit touching the stop there, and a contact-free orbit just past it on the side it
        exists (None where the closed form does not apply)."""
        if not (side.out.hybrid.impacts == 0 or beyond is None or beyond.out.hybrid.impacts == 0):
            return None
        if side.out.hybrid.impacts > 0:  # the contact side of an onset is next to the contact-free orbit ...
            closed = getattr(self.system, "linear_orbit", lambda p: None)(side.p)
            near = closed is not None and np.max(np.abs(side.y - closed[0]) / self.arc.sy) <= ONSET_NEIGHBOURHOOD
            impacting = getattr(self.system, "impact_orbit", lambda p: None)(side.p) if not near else None
            born = impacting is not None and np.max(np.abs(side.y - impacting[0]) / self.arc.sy) <= 1e-6  # ... or the closed-form orbit born there
            if not (near or born):
                return None  # not an onset from a contact-free side (another contact count beyond)
        n, scale = self.n, float(self.arc.sp[0])
        known = [float(side.p[self.index])] + ([float(beyond.p[self.index])] if beyond is not None else [])
        reach = 4.0 * max(max(abs(v - value) for v in known), self.tolerance(side) * scale)
        found = contact_free_onset(self.system, side.p, self.index, value, reach)
        if found is None:
            return None
        root, q = found
        closed = self.system.linear_orbit(q)  # type: ignore[attr-defined]
        touching = self.arc.point(self.arc.to_z(closed[0], q), side.tangent)
        if side.out.hybrid.onset_depth is None or not (np.all(np.isfinite(touching.out.jacobian)) and np.all(np.isfinite(touching.tangent))):
            touching = None  # a rigid stop's impact of zero speed: its Jacobian is singular there (the located point stays)
        free = None  # (none when the contact-free orbit exists on neither side within the offset)
        offset = max(1e-6 * abs(root), 1e3 * self.tolerance(side) * scale)
        for end in (root + offset, root - offset):
            there = np.array(q)
            there[self.index] = end
            orbit = self.system.linear_orbit(there)  # type: ignore[attr-defined]
            if orbit is not None and orbit[1] > 0.0:
                point = self.arc.point(self.arc.to_z(orbit[0], there), None)
                t = point.tangent if point.tangent[n] * (end - root) >= 0.0 else -point.tangent
                free = dataclasses.replace(point, tangent=t)
                break
        return root, touching, free

    def _rigid_ladder(self, side: Point, root: float) -> list[Point]:
        """The closed-form one-impact orbits born at a rigid stop's onset at ``root`` (:func:`~vibroimpact.orbits.
        onsets.impacting_ladder`), as points at distances to grazing 1.6e-5 ... 1e-3 from it, each with its tangent
        pointing away from the onset; empty where the closed form does not apply."""
        ladder = impacting_ladder(self.system, side.p, self.index, root)
        points: list[Point] = []
        previous = None
        for state, q, _margin in ladder:
            point = self.arc.point(self.arc.to_z(state, q), None)
            if point.out.hybrid is None or point.out.hybrid.impacts == 0 or not np.all(np.isfinite(point.out.jacobian)):
                break
            if previous is not None:
                secant = point.z - previous.z
                if not np.linalg.norm(secant) > 1e-12 * max(np.linalg.norm(point.z), 1e-300):  # the same orbit again: no way on
                    continue
                point = dataclasses.replace(point, tangent=self.arc.tangent(point.jacobian, secant / np.linalg.norm(secant)))
            points.append(point)
            previous = point
        if len(points) >= 2:  # the first: the way to the second
            secant = points[1].z - points[0].z
            points[0] = dataclasses.replace(points[0], tangent=self.arc.tangent(points[0].jacobian, secant / np.linalg.norm(secant)))
        return points

    def _record_onset(self, at: float, before: Point, after: Point | None, arriving_way: float, near: int, first: int) -> None:
        """Keep the grazing point just located (at arclength ``at``) with what happens across it: the stability change
        between ``before`` and ``after`` (the orbits on either side, at most 1e-3 from it in margin where the branch
        curves sharply; both contact-free or :data:`MEASURABLE_MARGIN` from it) named as a discontinuity-induced
        bifurcation, and a nonsmooth fold where the branch leaves back the way it came (its parameter's direction
        reverses with no smooth fold in between). Special points found within that 1e-3 of the onset (from index
        ``near`` of the points found since ``first``) are marked as induced by it."""
        found = self.graze
        notes = [found.note]
        folds_near = any(point.kind == "fold" for _, point in self.specials[first:])
        if after is not None and all(_measurable(point) for point in (before, after)):
            change = stability_change(before.orbit(self.system).multipliers, after.orbit(self.system).multipliers)
            if change:
                notes.append(change)
            leaving_way = float(after.tangent[self.n])
            if arriving_way * leaving_way < 0.0 and not folds_near:
                notes.append("the branch turns back here: a nonsmooth fold")
        for k in range(near, len(self.specials)):
            key, point = self.specials[k]
            if point.orbit.hybrid is not None and grazing_margin(point.orbit.hybrid) >= INDUCED_MARGIN:
                continue  # found on the way to it, farther than where it induces
            self.specials[k] = (key, dataclasses.replace(point, note=f"{point.note} (next to the contact onset at {found.value:.10g}: induced by it)", induced_by=found.value))
        self.specials.append((at, dataclasses.replace(found, note="; ".join(notes))))

    def _away(self, beyond: Point, at: Point) -> Point:
        """``beyond`` with its tangent pointing away from the grazing point ``at``: the way its distance to grazing
        grows along a short corrected step (the new branch may leave the point either way: on through it, or back,
        a nonsmooth fold), else the way from ``at`` to it."""
        s = self.settings
        margin = grazing_margin(beyond.out.hybrid)
        reach = max(4.0 * float(np.linalg.norm(beyond.z - at.z)), 1e-6)
        for sign in (1.0, -1.0):
            t = sign * beyond.tangent
            trial = self.arc.correct(beyond.z + reach * t, t, s.tolerance, s.max_corrector_iterations)
            if trial is not None and signature_of(trial) == signature_of(beyond) and grazing_margin(trial.out.hybrid) > margin:
                return beyond if sign > 0.0 else dataclasses.replace(beyond, tangent=t)
        return beyond if beyond.tangent @ (beyond.z - at.z) >= 0.0 else dataclasses.replace(beyond, tangent=-beyond.tangent)

    def leave(self, start: Point, signature: tuple[int, int] | None = None, anchor: NDArray[np.float64] | None = None) -> list[Point]:
        """Points that carry the branch away from a grazing point where it has just arrived at ``start``, on the side
        with the new contact: the orbits whose distance to grazing (:func:`grazing_margin`) is 1e-6, 2e-6, 4e-6, ...
        up to 1e-3, each the solution of the fixed-point equations plus that margin, from the last, with its tangent
        the way they go. ``signature``: the contacts of the side to leave on (default ``start``'s own);
        ``anchor``: a point of that side to approach ``start`` from, when ``start`` is not on it. Empty when ``start``
        is already that far, or no such orbit is found (the pseudo-arclength steps then try).

        Next to the grazing point of a soft contact the branch curves sharply (the contact's effect grows like a power
        of the depth above one, a square root in the Jacobian; at a turning point the contacting branch leaves back
        along the tangent the contact-free one arrived on): a step along the tangent from the point misses the
        branch at any size, and so does an orbit at a fixed parameter next to it (the contact-free orbit is nearer).
        The margin grows linearly away from the point on the contacting branch whichever way it goes, so it is the
        parameter that leaves the point.
        """
        if start.out.hybrid is None or start.out.hybrid.onset_depth is None:
            departure, self.departure = self.departure, []
            return departure  # rigid stops: the closed-form orbits found at the onset (:meth:`_rigid_ladder`)
        signature = signature_of(start) if signature is None else signature
        margin = grazing_margin(start.out.hybrid) if signature_of(start) == signature else 0.0
        if margin >= 1e-3:
            return []
        found: list[Point] = []
        target, history = max(1e-6, 2.0 * margin), [(margin, start.z)]
        first = start.z if anchor is None else anchor
        while target <= 1.5e-3:
            if len(history) >= 2:  # extrapolate in the margin (the branch is smooth in it)
                (m0, z0), (m1, z1) = history[-2], history[-1]
                predicted = z1 + (z1 - z0) * (target - m1) / (m1 - m0)
            else:
                predicted = history[-1][1]
            point = self._at_margin(predicted, target, signature, history[-1][1] if len(history) > 1 else first)
            if point is None:
                break
            secant = point.z - history[-1][1]
            found.append(dataclasses.replace(point, tangent=self.arc.tangent(point.jacobian, secant / np.linalg.norm(secant))))
            history.append((grazing_margin(point.out.hybrid), point.z))
            target *= 2.0
        return found

    def _at_margin(self, predicted: NDArray[np.float64], target: float, signature: tuple[int, int] | None, anchor: NDArray[np.float64]) -> Point | None:
        """The orbit of ``signature`` whose grazing margin is ``target``: Newton's method on the fixed-point equations
        plus ``margin - target = 0`` (the margin's gradient by forward differences), from ``predicted``, each iterate
        kept on the side of ``signature`` by halving its step towards the last one (from ``anchor`` first)."""
        arc, n, s = self.arc, self.n, self.settings
        z, previous = np.array(predicted, dtype=float), np.array(anchor, dtype=float)

        def margin_at(zz: NDArray[np.float64]) -> tuple[float, NDArray[np.float64], NDArray[np.float64]] | None:
            residual, jac, out = arc.equations(zz)
            if out.hybrid is None or out.hybrid.signature != signature or not np.all(np.isfinite(residual)):
                return None
            return grazing_margin(out.hybrid), residual, jac

        for _ in range(s.max_corrector_iterations + 4):
            for _halving in range(30):
                value = margin_at(z)
                if value is not None:
                    break
                z = previous + 0.5 * (z - previous)
            else:
                return None
            margin, residual, jac = value
            gradient = np.empty(n + 1)
            for i in range(n + 1):
                step = 1e-8 * max(1.0, abs(float(z[i])))
                shifted = z.copy()
                shifted[i] += step
                moved = margin_at(shifted)
                if moved is None:
                    shifted[i] -= 2.0 * step
                    moved, step = margin_at(shifted), -step
                if moved is None:
                    return None
                gradient[i] = (moved[0] - margin) / step
            try:
                dz = np.linalg.solve(np.vstack([jac, gradient]), -np.concatenate([residual, [margin - target]]))
            except np.linalg.LinAlgError:
                return None
            if float(np.max(np.abs(residual))) <= s.tolerance and abs(margin - target) <= 1e-3 * target:
                return arc.point(z, None)
            previous, z = z, z + dz
        return None
