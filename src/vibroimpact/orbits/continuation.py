"""Pseudo-arclength continuation of periodic orbits in one parameter, with the detection of special points.

From a periodic orbit the branch is followed by predictor (a step h along the unit tangent in scaled variables) and
corrector (Newton's method on ``P^k(y) - y = 0`` plus the arclength condition), so it goes around folds and through
unstable parts alike. The step grows after an easy correction and shrinks after a hard or failed one, or when the
tangent turns by more than ``max_turn``. Between consecutive points the test functions of
:mod:`~vibroimpact.orbits.bifurcations` are compared and every sign change is located and stored with its multipliers.

Where a step fails next to an impact at the strobe (the map is not smooth where an impact crosses t = 0 mod T), the
strobe is moved into the middle of the widest gap the contacts leave (``resectioned``, a change of the force's phase:
:mod:`~vibroimpact.orbits.sections`) and the step is tried again; each orbit of the branch carries its own phase, so
every state is read at its own strobe.

The continuation stops at a bound of the parameter (the last point lies on the bound), after ``max_steps`` steps,
when the branch closes on itself (an isola), when the step falls below ``min_step``, at a grazing point when
``stop_at_grazing``, or on a contact-free stretch that has left every stop behind (``clear``). At a grazing point the
contact count changes (or no orbit is found beyond); the point is located (in closed form where one side is
contact-free: :mod:`~vibroimpact.orbits.onsets`), and the orbit beyond it, if one is found, carries the branch on
with the new count (``SpecialPoint.continues``, ``impacts_after``), in the direction the geometry gives: on through
the point, or back (a nonsmooth fold). Next to a soft contact's onset the branch curves sharply; it is followed there
by its distance to grazing instead of its arclength (:meth:`~vibroimpact.orbits.onset_steps.OnsetSteps.leave`).
What happens across an onset is in the grazing point's note: a jump of the multipliers across the unit circle named
as the discontinuity-induced bifurcation it is, a nonsmooth fold; special points next to an onset say that it
induced them.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.orbits.arclength import ArclengthSystem, Point
from vibroimpact.orbits.bifurcations import classify, grazing_margin, locate
from vibroimpact.orbits.bifurcations import neimark_sacker_test, period_doubling_test
from vibroimpact.orbits.call_progress import CallProgress
from vibroimpact.orbits.branch import Branch, ParametrisedMap, PeriodicOrbit, SpecialPoint, lower_period_maps
from vibroimpact.orbits.continuation_settings import ContinuationSettings
from vibroimpact.orbits.onset_steps import NOT_GRAZING, OnsetSteps, signature_of
from vibroimpact.orbits.onsets import touches_ahead
from vibroimpact.orbits.special_curves import SpecialCurve, continue_special_point, defining_function

__all__ = ["ContinuationSettings", "continue_branch", "SpecialCurve", "continue_special_point", "defining_function"]

#: A failed step moves the strobe when the nearest contact is closer to it than this fraction of the distance the moved
#: strobe would have (half the widest gap between contacts).
RESECTION_RATIO = 0.5
#: A step across which the number of Floquet multipliers outside the unit circle changes while no test function changes
#: sign (two crossings inside it cancel in the tests: a torus pair leaving the circle next to another pair's product
#: crossing 1) is split in two at a point of the branch between its ends, at most this many times over.
MAX_DETECTION_SPLITS = 10


class _Walker(OnsetSteps):
    """One direction of one branch (its steps at contact onsets: :class:`~vibroimpact.orbits.onset_steps.OnsetSteps`)."""

    def __init__(self, system: ParametrisedMap, orbit: PeriodicOrbit, index: int, settings: ContinuationSettings) -> None:
        self.system, self.index, self.settings = system, index, settings
        self.name = system.parameter_names[index]
        self.progress = CallProgress(f"continuing in {self.name}")  # on a terminal, a call of seconds says how far it got
        self.arc = self.first_arc = ArclengthSystem(system, orbit.parameters, (index,))
        self.n = system.dimension
        self.specials: list[tuple[float, SpecialPoint]] = []
        self.lower = lower_period_maps(system)
        self.clear_onset()

    def tolerance(self, point: Point) -> float:
        """Arclength bracket that gives the parameter to locate_tolerance relative."""
        return self.settings.locate_tolerance * max(abs(point.z[self.n]), 1e-3)

    def tests(self, point: Point) -> dict[str, float]:
        kinds = self.settings.detect
        values = {}
        if "fold" in kinds:
            values["fold"] = float(point.tangent[self.n])
        if "period_doubling" in kinds:
            values["period_doubling"] = period_doubling_test(point.out)
        if "neimark_sacker" in kinds:
            values["neimark_sacker"] = neimark_sacker_test(point.out)
        return values

    def special(self, kind: str, a: Point, sigma: float, arclength: float) -> None:
        """Locate a sign change of ``kind``'s test between a and sigma along a's tangent, and keep it if real."""

        def test(point: Point | None) -> float | None:
            return None if point is None else self.tests(point)[kind]

        tol = self.settings.tolerance
        lo, hi, _width = locate(self.arc, a, sigma, test, self.tolerance(a), tol)
        best = lo if hi is None or abs(test(lo) or 0.0) <= abs(test(hi) or 0.0) else hi
        found = classify(kind, best.orbit(self.system), self.name, float(test(best) or 0.0))
        if found is not None and kind == "fold" and self._collapsed(best):
            self.parent = best  # not a fold: the period-2k branch meets the period-k orbit it was born from
            return
        if found is not None:
            self.specials.append((arclength + float(a.tangent @ (best.z - a.z)), found))

    def _between(self, a: Point, b: Point) -> Point | None:
        """A point of the branch between a and b in the continued parameter, with their impacts: an ordinary step from
        a along its own tangent (the branch's, oriented towards b), a half, a quarter or an eighth of the way; None
        where none is found."""
        n = self.n
        chord = b.z - a.z
        tangent = self.arc.tangent(a.jacobian, chord / float(np.linalg.norm(chord)))
        way = float(tangent @ chord)
        for fraction in (0.5, 0.25, 0.125):
            middle = self.arc.correct(a.z + fraction * way * tangent, tangent, self.settings.tolerance, 12)
            if middle is not None and signature_of(middle) == signature_of(a) and min(a.z[n], b.z[n]) < middle.z[n] < max(a.z[n], b.z[n]):
                return middle
        return None

    def _collapsed(self, point: Point) -> bool:
        """Is this fixed point of P^K also one of P^d for a proper divisor d of K: the branch meets the lower-period
        orbit it was born from (a period doubling, or a k-tupling where a multiplier is a k-th root of unity)?"""
        for _d, lower in self.lower:
            image = lower.evaluate(point.y, point.p).image
            if np.max(np.abs(image - point.y) / self.arc.sy) < 1e-3:  # amplitude ~ sqrt(parameter distance)
                return True
        return False

    def detect(self, a: Point, values_a: dict[str, float], b: Point, values_b: dict[str, float], sigma: float, arclength: float, splits: int = 0) -> None:
        """Locate every test function that changes sign between a and b (sigma along a's tangent). Where none does but
        the number of multipliers outside the unit circle changed (the same impacts at both ends: two crossings inside
        the step cancel in the tests), the step is split at a point of the branch between its ends (:meth:`_between`) and
        each part searched (:data:`MAX_DETECTION_SPLITS`)."""
        if splits == 0:
            self.parent = None
        changed = [kind for kind, before in values_a.items() if np.sign(before) * np.sign(values_b[kind]) < 0]
        if not changed and splits < MAX_DETECTION_SPLITS and signature_of(a) == signature_of(b):  # (multipliers only then)
            outside = (_unstable(a), _unstable(b))
            middle = self._between(a, b) if outside[0] != outside[1] and min(outside) >= 0 else None
            if middle is not None:
                values_middle = self.tests(middle)
                first = float(a.tangent @ (middle.z - a.z))
                self.detect(a, values_a, middle, values_middle, first, arclength, splits + 1)
                self.detect(middle, values_middle, b, values_b, float(middle.tangent @ (b.z - middle.z)), arclength + first, splits + 1)
                return
        for kind in changed:
            self.special(kind, a, sigma, arclength)

    def _grazing_distance(self, a: Point) -> float:
        """Arclength to the grazing point extrapolated from the margin's slope (inf when it is not approaching)."""
        if a.out.hybrid is None or self.slope is None or self.slope >= 0.0:
            return math.inf
        margin = grazing_margin(a.out.hybrid)
        return -margin / self.slope if margin < self.settings.grazing_margin else math.inf

    def _grazing_ahead(self, a: Point, h: float) -> bool:
        """After a failed step: is a grazing point likely within h (the margin, extrapolated, reaches zero)?"""
        margin = grazing_margin(a.out.hybrid)
        if margin >= self.settings.grazing_margin:
            return False
        return self.slope is None or margin + 4.0 * h * min(self.slope, 0.0) <= 0.0

    def clear(self, b: Point, a: Point) -> bool:
        """Is the contact-free orbit at ``b`` clear of every stop by more than ``settings.clear`` of its clearance,
        farther than at ``a``, and does it touch none ahead (:func:`~vibroimpact.orbits.onsets.touches_ahead`)?
        False without a closed-form contact-free orbit (:meth:`~vibroimpact.orbits.maps.ImpactMap.linear_orbit`)."""
        closed = getattr(self.system, "linear_orbit", None)
        here = None if closed is None else closed(b.p)
        there = None if closed is None else closed(a.p)
        if here is None or there is None or not (here[1] > self.settings.clear and here[1] > there[1]):
            return False
        way = float(np.sign(b.p[self.index] - a.p[self.index]))
        return not touches_ahead(self.system, b.p, self.index, way, self.settings.lower, self.settings.upper)

    def resection(self, a: Point) -> Point | None:
        """``a`` seen through a strobe in the middle of the widest gap between its contacts, on a new arclength system
        holding that phase; None when the map cannot move its strobe, or the strobe is not near a contact."""
        move = getattr(self.system, "resectioned", None)
        if move is None or a is self.moved:
            return None
        found = move(a.y, a.p)
        if found is None or found.gap.nearest >= RESECTION_RATIO * found.gap.half_width:
            return None
        arc = ArclengthSystem(self.system, found.parameters, (self.index,))
        along = np.zeros(self.n + 1)
        along[self.n] = 1.0 if a.tangent[self.n] >= 0.0 else -1.0  # the same direction in the parameter
        moved = arc.point(arc.to_z(found.state, found.parameters), along)
        if not np.all(np.isfinite(moved.residual)) or np.max(np.abs(moved.residual)) > 1e3 * self.settings.tolerance:
            return None  # not an orbit seen from the new strobe (the engine's run did not close)
        self.arc, self.moved = arc, moved
        return moved

    def bound(self, a: Point, sigma: float, value: float) -> Point:
        """The point between a and sigma where the parameter equals ``value``."""

        def test(point: Point | None) -> float | None:
            return None if point is None else float(point.p[self.index] - value)

        lo, hi, _width = locate(self.arc, a, sigma, test, self.tolerance(a), self.settings.tolerance)
        found = hi if hi is not None else lo
        if abs(float(found.p[self.index]) - value) <= self.settings.locate_tolerance * max(abs(value), 1e-300):
            return found
        # the orbit at the bound itself: Newton on the state with the parameter held at the bound (a map whose own
        # bounds box ends there fails for every trial beyond it, so the bracket may stop short)
        fixed = np.array(found.z, dtype=float)
        fixed[self.n] = value / self.arc.sp[0]
        direction = np.zeros_like(fixed)
        direction[self.n] = 1.0
        polished = self.arc.correct(fixed, direction, self.settings.tolerance, self.settings.max_corrector_iterations)
        if polished is None or signature_of(polished) != signature_of(found):
            return found
        return dataclasses.replace(polished, tangent=self.arc.tangent(polished.jacobian, a.tangent))

    def run(self, start: Point) -> tuple[list[Point], str]:
        s = self.settings
        self.slope: float | None = None
        self.retry_margin = 2e-3  # margin below which a grazing point is sought ahead whatever the step
        a, points, h, arclength = start, [start], s.step, 0.0
        self.arc = self.first_arc  # each direction starts at the start's strobe
        self.moved: Point | None = None  # the last point whose strobe was moved
        values_a = self.tests(a)
        turn = math.cos(s.max_turn)
        for _ in range(s.max_steps):
            self.progress.update(f"{len(points)} points, {self.name} = {float(a.p[self.index]):.6g}")
            b = self.arc.correct(a.z + h * a.tangent, a.tangent, s.tolerance, s.max_corrector_iterations)
            if b is not None and b.tangent @ a.tangent < turn and h > s.min_step:
                b = None  # the tangent turned too much: a smaller step
            hybrid = a.out.hybrid is not None and "grazing" in s.detect
            changed = b is not None and signature_of(b) != signature_of(a)
            if changed and h > 1e-3:
                h *= 0.5  # walk up to the grazing point with ordinary steps, so that no other test is skipped
                continue
            ahead = self._grazing_distance(a)
            close = ahead < 0.5 * h or (math.isfinite(ahead) and grazing_margin(a.out.hybrid) < self.retry_margin)
            if close:
                self.retry_margin = 0.5 * grazing_margin(a.out.hybrid)  # if it is no grazing point, retry when halved
            if hybrid and (changed or (b is None and self._grazing_ahead(a, h)) or close):
                # a grazing point within the step: the impact count changed, or Newton failed next to it, or the
                # margin extrapolates to zero (Newton's region shrinks near it, the steps would creep)
                beyond = self.grazing(a, h if changed or b is None else 1.5 * ahead, arclength, b if changed else None)
                if beyond is not NOT_GRAZING:
                    last = self.last_before
                    first_special = len(self.specials)
                    if not self.arrival:  # (else the arriving points replace the approach's nearest one)
                        self.detect(a, values_a, last, self.tests(last), float(a.tangent @ (last.z - a.z)), arclength)
                        points.append(last)
                        arclength += float(a.tangent @ (last.z - a.z))
                        a, values_a = last, self.tests(last)
                    near_before = self.reference if self.reference is not None else last  # (1e-3 from it: its stability)
                    near_start = len(self.specials)
                    for arriving in self.arrival:  # the last stretch to an onset, from its own side
                        chord = arriving.z - a.z  # (located along the chord: the branch curves sharply there)
                        sigma = float(np.linalg.norm(chord))
                        along = dataclasses.replace(a, tangent=chord / sigma) if sigma > 0.0 else a
                        self.detect(along, values_a, arriving, self.tests(arriving), sigma, arclength)
                        arclength += sigma
                        a, values_a = arriving, self.tests(arriving)
                        points.append(a)
                    if self.touching is not None:  # the onset's own orbit, on the branch where it goes on past it
                        touching = dataclasses.replace(self.touching, tangent=self.arc.tangent(self.touching.jacobian, a.tangent))
                        sigma = float(a.tangent @ (touching.z - a.z))
                        self.detect(a, values_a, touching, self.tests(touching), sigma, arclength)
                        arclength += sigma
                        a, values_a = touching, self.tests(touching)
                        if beyond is not None and not s.stop_at_grazing:
                            points.append(a)
                    graze_at, arriving_way = arclength, float(a.tangent[self.n])
                    if beyond is None or s.stop_at_grazing:
                        after = [] if beyond is None else [beyond]
                        self._record_onset(graze_at, near_before, after[-1] if after else None, arriving_way, near_start, first_special)
                        return points, "grazing"
                    arclength += float(a.tangent @ (beyond.z - a.z))
                    a, values_a = beyond, self.tests(beyond)
                    points.append(a)
                    for left in self.leave(a):  # the first points of a branch that curves sharply from the point
                        self.detect(a, values_a, left, self.tests(left), float(a.tangent @ (left.z - a.z)), arclength)
                        arclength += float(np.linalg.norm(left.z - a.z))
                        a, values_a = left, self.tests(left)
                        points.append(a)
                        h = max(min(h, float(np.linalg.norm(points[-1].z - points[-2].z))), s.min_step)
                    if len(points) >= 2 and points[-2].out.hybrid is not None:  # the approach's margin slope says
                        step = float(np.linalg.norm(points[-1].z - points[-2].z))  # nothing of the branch leaving it
                        if step > 0.0:
                            self.slope = (grazing_margin(a.out.hybrid) - grazing_margin(points[-2].out.hybrid)) / step
                    self._record_onset(graze_at, near_before, a, arriving_way, near_start, first_special)
                    continue
                b = None
            elif changed:
                b = None
            if b is None:
                predicted = float((a.z[self.n] + h * a.tangent[self.n]) * self.arc.sp[0])
                if not s.lower <= predicted <= s.upper:
                    # no orbit beyond the bound (e.g. the map's own bounds box): locate the bound by bisection
                    # instead of creeping up to it with ever smaller steps
                    points.append(self.bound(a, h, s.lower if predicted < s.lower else s.upper))
                    return points, "bound"
                moved = self.resection(a)
                if moved is not None:  # an impact at the strobe: the same step from a strobe clear of it
                    a = points[-1] = moved
                    continue
                h *= 0.5
                if h < s.min_step:
                    return points, "step_too_small"
                continue
            sigma = float(a.tangent @ (b.z - a.z))
            value = float(b.p[self.index])
            if not s.lower <= value <= s.upper:
                points.append(self.bound(a, sigma, s.lower if value < s.lower else s.upper))
                return points, "bound"
            values_b = self.tests(b)
            self.detect(a, values_a, b, values_b, sigma, arclength)
            if self.parent is not None:
                points.append(self.parent)
                return points, "parent"
            if self.lower and self._collapsed(b):  # on the lower-period orbit without a fold (a k-tupling): stop
                points.append(b)
                return points, "parent"
            arclength += sigma
            if len(points) > 3 and self.moved is None:  # (a moved strobe reads the states elsewhere than the start's)
                offset_a, offset_b = a.z - start.z, b.z - start.z
                if start.tangent @ offset_a < 0.0 <= start.tangent @ offset_b and np.linalg.norm(offset_b) < 2.0 * h:
                    points.append(b)
                    return points, "closed"
            points.append(b)
            if not s.stop_at_grazing and b.out.hybrid is not None and b.out.hybrid.impacts == 0 and self.clear(b, a):
                return points, "clear"  # contact-free and moving away from every stop
            self.slope = (grazing_margin(b.out.hybrid) - grazing_margin(a.out.hybrid)) / sigma if b.out.hybrid is not None else 0.0
            a, values_a = b, values_b
            h = min(h * 1.5, s.max_step) if b.iterations <= 3 else (max(h / 1.5, s.min_step) if b.iterations >= 6 else h)
        return points, "max_steps"



@suggest_keywords
def continue_branch(system: ParametrisedMap, orbit: PeriodicOrbit, parameter: str, settings: ContinuationSettings = ContinuationSettings(), direction: int = 0) -> Branch:
    """Follow the branch of periodic orbits through ``orbit`` as ``parameter`` varies.

    Parameters
    ----------
    system : ParametrisedMap
        The map P^k whose fixed points are continued (``Iterated(map, k)`` for a period-k orbit).
    orbit : PeriodicOrbit
        A converged orbit (:func:`vibroimpact.orbits.shooting.shoot`).
    parameter : str
        Name of the continued parameter (one of ``system.parameter_names``).
    settings : ContinuationSettings
        Steps, bounds, tolerances and what to detect.
    direction : {1, -1, 0}
        Increasing parameter first, decreasing, or both ways (the branch then runs from its lower-direction end to
        its upper-direction end).

    Returns
    -------
    Branch
        The points in arclength order with the located special points. ``end`` says why the continuation stopped;
        both ways, it is ``"<first end>, <last end>"``.
    """
    names = list(system.parameter_names)
    if parameter not in names:  # a layout scalar is continued once the map carries it (ImpactMap(layout=[...]))
        raise ValueError(f"parameter = {parameter!r} is not one of the map's parameters: allowed {', '.join(names)} (a layout scalar such as 'k2' or 'mass[x2]' once the map is built with layout=[...])")
    index = names.index(parameter)
    if direction not in (1, -1, 0):
        raise ValueError(f"direction = {direction!r}: allowed 1, -1, 0")
    walker = _Walker(system, orbit, index, settings)
    start = walker.arc.point(walker.arc.to_z(orbit.state, orbit.parameters), None)
    n = system.dimension

    def oriented(sign: float) -> Point:
        t = start.tangent if start.tangent[n] * sign >= 0.0 else -start.tangent
        return Point(start.z, start.y, start.p, start.out, start.residual, start.jacobian, t, 0, orbit.residual_history)

    runs = []
    try:
        for sign in ((1.0, -1.0) if direction == 0 else (float(direction),)):
            walker.specials = []
            points, end = walker.run(oriented(sign))
            runs.append((points, end, sorted(walker.specials, key=lambda item: item[0])))
            if end == "closed":
                break
    finally:
        walker.progress.close(f"{sum(len(run[0]) for run in runs)} points")
    if direction != 0:
        points, end, specials = runs[0]
        return Branch(parameter, tuple(p.orbit(system) for p in points), tuple(s for _, s in specials), end)
    if runs[-1][1] == "closed":  # an isola: the run went all the way round
        points, _end, specials = runs[-1]
        return Branch(parameter, tuple(p.orbit(system) for p in points), tuple(s for _, s in specials), "closed")
    (up, up_end, up_specials), (down, down_end, down_specials) = runs
    points = list(reversed(down)) + up[1:]
    specials = [s for _, s in reversed(down_specials)] + [s for _, s in up_specials]
    return Branch(parameter, tuple(p.orbit(system) for p in points), tuple(specials), f"{down_end}, {up_end}")


def _unstable(point: Point) -> int:
    """How many of the point's Floquet multipliers lie outside the unit circle (-1: the map has no Jacobian there)."""
    jacobian = point.out.jacobian
    if not np.all(np.isfinite(jacobian)):
        return -1
    return int(np.sum(np.abs(np.linalg.eigvals(jacobian)) > 1.0))

