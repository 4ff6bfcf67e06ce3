"""Pseudo-arclength continuation of periodic orbits in one parameter, with the detection of special points.

From a periodic orbit the branch is followed by predictor (a step h along the unit tangent in scaled variables) and
corrector (Newton's method on ``P^k(y) - y = 0`` plus the arclength condition), so it goes around folds and through
unstable parts alike. The step grows after an easy correction and shrinks after a hard or failed one, or when the
tangent turns by more than ``max_turn``. Between consecutive points the test functions of
:mod:`~vibroimpact.orbits.bifurcations` are compared and every sign change is located and stored with its multipliers.

The continuation stops at a bound of the parameter (the last point lies on the bound), after ``max_steps`` steps,
when the branch closes on itself (an isola), when the step falls below ``min_step``, or at a grazing point when
``stop_at_grazing``. At a grazing point the impact count changes (or no orbit is found beyond); the point is
located, and the orbit beyond it, if Newton's method finds one, tells whether the branch continues with the new
impact count (``SpecialPoint.continues``, ``impacts_after``).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from vibroimpact.model.structure import require_in_range, require_positive
from vibroimpact.orbits.arclength import ArclengthSystem, Point, TestFunction
from vibroimpact.orbits.bifurcations import classify, grazing_margin, locate, locate_grazing, neimark_sacker_test, period_doubling_test
from vibroimpact.orbits.branch import SPECIAL_POINT_KINDS, Branch, ParametrisedMap, PeriodicOrbit, SpecialPoint, lower_period_maps, MapEvaluation

__all__ = ["ContinuationSettings", "continue_branch", "SpecialCurve", "continue_special_point", "defining_function"]

@dataclass(frozen=True)
class ContinuationSettings:
    """How a branch is followed.

    Parameters
    ----------
    step : float
        First arclength step, in scaled variables (state / state_scale, parameter / parameter_scale) [-].
    min_step, max_step : float
        Limits of the adapted step [-].
    max_steps : int
        Most points on the branch (per direction).
    lower, upper : float
        Bounds of the continued parameter (its own unit, e.g. Hz).
    tolerance : float
        Scaled residual at which the corrector stops [-].
    max_corrector_iterations : int
        Newton iterations per corrector.
    max_turn : float
        Largest angle between consecutive tangents [rad]; a larger turn halves the step.
    locate_tolerance : float
        Relative precision of a located special point's parameter [-].
    detect : tuple of str
        Special points to detect (subset of ``SPECIAL_POINT_KINDS``).
    stop_at_grazing : bool
        End the branch at a grazing point (True), or carry on with the new impact count when an orbit exists there.
    grazing_margin : float
        A failed step from a point whose grazing margin is below this is searched for a grazing point [-].
    """

    step: float = 0.05
    min_step: float = 1e-7
    max_step: float = 0.3
    max_steps: int = 2000
    lower: float = -math.inf
    upper: float = math.inf
    tolerance: float = 1e-11
    max_corrector_iterations: int = 8
    max_turn: float = 0.35
    locate_tolerance: float = 1e-10
    detect: tuple[str, ...] = SPECIAL_POINT_KINDS
    stop_at_grazing: bool = True
    grazing_margin: float = 0.05

    def __post_init__(self) -> None:
        for name in ("step", "min_step", "max_step", "tolerance", "locate_tolerance", "grazing_margin"):
            require_positive(name, getattr(self, name))
        require_in_range("max_steps", self.max_steps, 1, 10**7)
        require_in_range("max_turn", self.max_turn, 1e-3, math.pi / 2)
        if not self.lower < self.upper:
            raise ValueError(f"lower = {self.lower!r} must be below upper = {self.upper!r}")
        unknown = set(self.detect) - set(SPECIAL_POINT_KINDS)
        if unknown:
            raise ValueError(f"detect: unknown kinds {sorted(unknown)}; allowed {SPECIAL_POINT_KINDS}")


def _signature(point: Point) -> tuple[int, int] | None:
    return point.out.hybrid.signature if point.out.hybrid is not None else None


class _Walker:
    """One direction of one branch."""

    def __init__(self, system: ParametrisedMap, orbit: PeriodicOrbit, index: int, settings: ContinuationSettings) -> None:
        self.system, self.index, self.settings = system, index, settings
        self.name = system.parameter_names[index]
        self.arc = ArclengthSystem(system, orbit.parameters, (index,))
        self.n = system.dimension
        self.specials: list[tuple[float, SpecialPoint]] = []
        self.lower = lower_period_maps(system)

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

    def _collapsed(self, point: Point) -> bool:
        """Is this fixed point of P^K also one of P^d for a proper divisor d of K: the branch meets the lower-period
        orbit it was born from (a period doubling, or a k-tupling where a multiplier is a k-th root of unity)?"""
        for _d, lower in self.lower:
            image = lower.evaluate(point.y, point.p).image
            if np.max(np.abs(image - point.y) / self.arc.sy) < 1e-3:  # amplitude ~ sqrt(parameter distance)
                return True
        return False

    def grazing(self, a: Point, sigma: float, arclength: float, hint: Point | None = None) -> object:
        """Locate a grazing point between a and sigma; return the point beyond it (None: the branch ends there)."""
        side, grazing, beyond, value = locate_grazing(self.arc, a, sigma, self.tolerance(a), self.settings.tolerance, hint)
        if not math.isfinite(value):
            return _NOT_GRAZING  # a plain corrector failure, not a grazing
        before = side.out.hybrid
        tangency = -before.closest_approach / before.length_scale <= before.speed_margin
        what = "a free flight touches the stop" if tangency else "an impact's velocity goes to zero"
        if beyond is not None:
            after = beyond.out.hybrid
            if after.impacts == before.impacts:
                what = f"{what} (the sticking phases change, {before.sticks} -> {after.sticks})"
            note = f"{what}; the branch continues with {after.impacts} impacts per period"
        else:
            note = f"{what}; no periodic orbit beyond: the branch ends"
        at = grazing if grazing is not None else side
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
        self.specials.append((arclength + float(a.tangent @ (side.z - a.z)), found))
        self.last_before = side
        return beyond

    def detect(self, a: Point, values_a: dict[str, float], b: Point, values_b: dict[str, float], sigma: float, arclength: float) -> None:
        """Locate every test function that changes sign between a and b (sigma along a's tangent)."""
        self.parent = None
        for kind, before in values_a.items():
            if np.sign(before) * np.sign(values_b[kind]) < 0:
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
        if polished is None or _signature(polished) != _signature(found):
            return found
        return dataclasses.replace(polished, tangent=self.arc.tangent(polished.jacobian, a.tangent))

    def run(self, start: Point) -> tuple[list[Point], str]:
        s = self.settings
        self.slope: float | None = None
        self.retry_margin = 2e-3  # margin below which a grazing point is sought ahead whatever the step
        a, points, h, arclength = start, [start], s.step, 0.0
        values_a = self.tests(a)
        turn = math.cos(s.max_turn)
        for _ in range(s.max_steps):
            b = self.arc.correct(a.z + h * a.tangent, a.tangent, s.tolerance, s.max_corrector_iterations)
            if b is not None and b.tangent @ a.tangent < turn and h > s.min_step:
                b = None  # the tangent turned too much: a smaller step
            hybrid = a.out.hybrid is not None and "grazing" in s.detect
            changed = b is not None and _signature(b) != _signature(a)
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
                if beyond is not _NOT_GRAZING:
                    last = self.last_before
                    self.detect(a, values_a, last, self.tests(last), float(a.tangent @ (last.z - a.z)), arclength)
                    points.append(last)
                    if beyond is None or s.stop_at_grazing:
                        return points, "grazing"
                    arclength += float(a.tangent @ (beyond.z - a.z))
                    a, values_a = beyond, self.tests(beyond)
                    points.append(a)
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
            if len(points) > 3:
                offset_a, offset_b = a.z - start.z, b.z - start.z
                if start.tangent @ offset_a < 0.0 <= start.tangent @ offset_b and np.linalg.norm(offset_b) < 2.0 * h:
                    points.append(b)
                    return points, "closed"
            points.append(b)
            self.slope = (grazing_margin(b.out.hybrid) - grazing_margin(a.out.hybrid)) / sigma if b.out.hybrid is not None else 0.0
            a, values_a = b, values_b
            h = min(h * 1.5, s.max_step) if b.iterations <= 3 else (max(h / 1.5, s.min_step) if b.iterations >= 6 else h)
        return points, "max_steps"


_NOT_GRAZING = object()


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
    index = list(system.parameter_names).index(parameter)
    if direction not in (1, -1, 0):
        raise ValueError(f"direction = {direction!r}: allowed 1, -1, 0")
    walker = _Walker(system, orbit, index, settings)
    start = walker.arc.point(walker.arc.to_z(orbit.state, orbit.parameters), None)
    n = system.dimension

    def oriented(sign: float) -> Point:
        t = start.tangent if start.tangent[n] * sign >= 0.0 else -start.tangent
        return Point(start.z, start.y, start.p, start.out, start.residual, start.jacobian, t, 0, orbit.residual_history)

    runs = []
    for sign in ((1.0, -1.0) if direction == 0 else (float(direction),)):
        walker.specials = []
        points, end = walker.run(oriented(sign))
        runs.append((points, end, sorted(walker.specials, key=lambda item: item[0])))
        if end == "closed":
            break
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


# --------------------------------------------------------------------------------------------------------------------
# Two-parameter continuation of folds, period doublings, Neimark-Sacker and grazing points.
# --------------------------------------------------------------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class SpecialCurve:
    """A curve of special points of one kind in two parameters.

    Attributes
    ----------
    kind : str
        'fold', 'period_doubling', 'neimark_sacker' or 'grazing'.
    parameters : (str, str)
        The two free parameters (p1, p2).
    orbits : tuple of PeriodicOrbit
        The orbit at each point of the curve, in arclength order.
    end : str
        Why each end stopped: ``"<first end>, <last end>"`` ('bound', 'max_steps', 'step_too_small', 'closed').
    """

    kind: str
    parameters: tuple[str, str]
    orbits: tuple[PeriodicOrbit, ...]
    end: str

    def values(self, name: str) -> NDArray[np.float64]:
        """One parameter along the curve."""
        return np.array([o.parameter(name) for o in self.orbits])


def defining_function(kind: str, reference: tuple[int, int] | None = None) -> TestFunction:
    """The scalar g(out, y, p) whose zero set is the ``kind`` of special point (see the module docstring).

    ``reference`` is the (impacts, sticks) signature of the grazing point's own side (grazing only).
    """
    identity_cache: dict[int, NDArray[np.float64]] = {}

    def fold(out: MapEvaluation, y: NDArray[np.float64], p: NDArray[np.float64]) -> float:
        n = out.jacobian.shape[0]
        if not np.all(np.isfinite(out.jacobian)):
            return math.nan
        identity = identity_cache.setdefault(n, np.eye(n))
        return float(np.linalg.det(out.jacobian - identity))

    def doubling(out: MapEvaluation, y: NDArray[np.float64], p: NDArray[np.float64]) -> float:
        return period_doubling_test(out)

    def torus(out: MapEvaluation, y: NDArray[np.float64], p: NDArray[np.float64]) -> float:
        return neimark_sacker_test(out)

    def grazing(out: MapEvaluation, y: NDArray[np.float64], p: NDArray[np.float64]) -> float:
        if out.hybrid is None:
            raise ValueError("grazing needs a hybrid map (its evaluations carry no HybridInfo)")
        margin = grazing_margin(out.hybrid)
        return margin if out.hybrid.signature == reference else -margin

    table = {"fold": fold, "period_doubling": doubling, "neimark_sacker": torus, "grazing": grazing}
    if kind not in table:
        raise ValueError(f"kind = {kind!r}: allowed {sorted(table)}")
    return table[kind]


def continue_special_point(
    system: ParametrisedMap,
    point: SpecialPoint,
    second: str,
    settings: ContinuationSettings = ContinuationSettings(),
    bounds: dict[str, tuple[float, float]] | None = None,
    direction: int = 0,
) -> SpecialCurve:
    """Follow a located special point in its own parameter and ``second``.

    Parameters
    ----------
    system : ParametrisedMap
        The map of the branch on which the point was found (``Iterated(map, k)`` for a period-k orbit).
    point : SpecialPoint
        A fold, period doubling, Neimark-Sacker or grazing point from :func:`.continuation.continue_branch`.
    second : str
        The second free parameter.
    settings : ContinuationSettings
        Steps, tolerances, ``max_steps`` (per direction); its ``lower``/``upper`` are ignored: see ``bounds``.
    bounds : dict, optional
        Parameter name -> (lower, upper) for either free parameter; the curve stops on a bound.
    direction : {1, -1, 0}
        Increasing ``second`` first, decreasing, or both ways.

    Returns
    -------
    SpecialCurve
        The curve of special points with the orbit at each.
    """
    names = list(system.parameter_names)
    free = (names.index(point.parameter), names.index(second))
    orbit = point.orbit
    reference = orbit.hybrid.signature if orbit.hybrid is not None else None
    arc = ArclengthSystem(system, orbit.parameters, free, (defining_function(point.kind, reference),))
    start = arc.correct(arc.to_z(orbit.state, orbit.parameters), np.eye(arc.n + 2)[arc.n + 1], settings.tolerance, 20)
    if start is None:
        raise RuntimeError(f"the {point.kind} point at {point.parameter} = {point.value!r} does not solve its extended system")
    limits = {free[0]: (-math.inf, math.inf), free[1]: (-math.inf, math.inf)}
    for name, (low, high) in (bounds or {}).items():
        limits[names.index(name)] = (low, high)
    runs = []
    for sign in ((1.0, -1.0) if direction == 0 else (float(direction),)):
        t = start.tangent if start.tangent[arc.n + 1] * sign >= 0.0 else -start.tangent
        first = Point(start.z, start.y, start.p, start.out, start.residual, start.jacobian, t, 0, start.history)
        runs.append(_walk(arc, first, settings, limits))
        if runs[-1][1] == "closed":
            break
    if len(runs) == 1:
        points, end = runs[0]
    else:
        (up, up_end), (down, down_end) = runs
        points, end = list(reversed(down)) + up[1:], f"{down_end}, {up_end}"
    return SpecialCurve(point.kind, (point.parameter, second), tuple(p.orbit(system) for p in points), end)


def _walk(arc: ArclengthSystem, start: Point, s: ContinuationSettings, limits: dict[int, tuple[float, float]]) -> tuple[list[Point], str]:
    a, points, h = start, [start], s.step
    turn = math.cos(s.max_turn)
    for _ in range(s.max_steps):
        b = arc.correct(a.z + h * a.tangent, a.tangent, s.tolerance, s.max_corrector_iterations)
        if b is None or (b.tangent @ a.tangent < turn and h > s.min_step):
            h *= 0.5
            if h < s.min_step:
                return points, "step_too_small"
            continue
        sigma = float(a.tangent @ (b.z - a.z))
        for index, (low, high) in limits.items():
            value = float(b.p[index])
            if not low <= value <= high:
                bound = low if value < low else high

                def test(point: Point | None, index: int = index, bound: float = bound) -> float | None:
                    return None if point is None else float(point.p[index] - bound)

                lo, hi, _width = locate(arc, a, sigma, test, s.locate_tolerance * max(1.0, float(np.max(np.abs(a.z)))), s.tolerance)
                points.append(hi if hi is not None else lo)
                return points, "bound"
        if len(points) > 3:
            offset_a, offset_b = a.z - start.z, b.z - start.z
            if start.tangent @ offset_a < 0.0 <= start.tangent @ offset_b and np.linalg.norm(offset_b) < 2.0 * h:
                points.append(b)
                return points, "closed"
        points.append(b)
        a = b
        h = min(h * 1.5, s.max_step) if b.iterations <= 3 else (max(h / 1.5, s.min_step) if b.iterations >= 6 else h)
    return points, "max_steps"
