"""Grazing points followed in two parameters by repeated one-parameter location.

A grazing point is where a periodic orbit's free flight touches the stop tangentially (its closest approach
``closest_approach`` reaches 0: a new impact is born) or where one of its impacts loses its speed
(``min_impact_velocity`` reaches 0). The map is not differentiable there, so the extended system of
:mod:`~vibroimpact.orbits.continuation` (Newton on ``[P^k(y) - y, g]``) has no Jacobian to work with across the point. Here the curve is
traced instead by stepping the second parameter and, at each value, locating the point in the first parameter
from the smooth side (:func:`locate_grazing_at`): the orbit is shot (damped Newton, exact Jacobian) at trial values
of the first parameter on the side where it keeps its impact count, and the zero of its grazing measure (the
closest approach over L, or the slowest impact over V) is extrapolated by inverse interpolation through the last
side samples. On the smooth side the measure is a smooth function that crosses zero with a non-zero slope, so the
located value is as precise as the extrapolation (~1e-12 relative when the nearest sample is within 1e-6 of the
point); a trial that lands beyond the point (another impact count, or no orbit) only narrows the bracket.

From one located point to the next the first parameter and the orbit's state are predicted by extrapolation along
the curve; a failed location halves the step of the second parameter, an easy one lets it grow.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from vibroimpact.model.structure import require_in_range, require_positive
from vibroimpact.orbits.branch import HybridInfo, ParametrisedMap, PeriodicOrbit, SpecialPoint
from vibroimpact.orbits.shooting import ShootingError, ShootingSettings, shoot

__all__ = ["GrazingCurveSettings", "GrazingCurve", "GrazingLocation", "grazing_measure", "locate_grazing_at", "trace_grazing"]

#: Grazing measures: the free flight's closest approach to the stop, or the slowest impact's speed.
MEASURES = ("tangency", "velocity")


def grazing_measure(info: HybridInfo, measure: str) -> float:
    """The scaled distance to grazing, >= 0: ``-closest_approach / L`` (tangency) or ``min_impact_velocity / V``
    (bumpers: ``onset_depth / L``, :attr:`~vibroimpact.orbits.branch.HybridInfo.speed_margin`)."""
    if measure == "tangency":
        return float(-info.closest_approach / info.length_scale)
    if measure == "velocity":
        return float(info.speed_margin)
    raise ValueError(f"measure = {measure!r}: allowed {MEASURES}")


@dataclass(frozen=True)
class GrazingCurveSettings:
    """How a grazing curve is traced.

    Parameters
    ----------
    step : float
        First step of the second parameter, in units of its ``parameter_scale`` [-].
    min_step, max_step : float
        Limits of the adapted step (same units) [-].
    max_points : int
        Most points per direction.
    tolerance : float
        Relative precision of the located first parameter [-].
    probe : float
        First offset of a trial from the predicted point into the smooth side, in units of the first parameter's
        ``parameter_scale`` [-].
    max_trials : int
        Shots per location.
    """

    step: float = 0.05
    min_step: float = 1e-4
    max_step: float = 0.5
    max_points: int = 400
    tolerance: float = 1e-11
    probe: float = 1e-3
    max_trials: int = 40

    def __post_init__(self) -> None:
        for name in ("step", "min_step", "max_step", "tolerance", "probe"):
            require_positive(name, getattr(self, name))
        require_in_range("max_points", self.max_points, 1, 10**6)
        require_in_range("max_trials", self.max_trials, 4, 10_000)


@dataclass(frozen=True, eq=False)
class GrazingLocation:
    """A grazing point located in the first parameter at fixed other parameters.

    Attributes
    ----------
    value : float
        The first parameter at the grazing point.
    orbit : PeriodicOrbit
        The smooth-side orbit nearest the point (its measure is ``margin``).
    margin : float
        Its grazing measure [-].
    side : int
        +1 when the smooth side lies above ``value``, -1 below.
    shots : int
        Orbits shot for this location.
    """

    value: float
    orbit: PeriodicOrbit
    margin: float
    side: int
    shots: int


@dataclass(frozen=True, eq=False)
class GrazingCurve:
    """A curve of grazing points in two parameters.

    Attributes
    ----------
    parameters : (str, str)
        (first, second): the located parameter and the stepped one.
    measure : str
        'tangency' (a free flight touches the stop) or 'velocity' (an impact's speed vanishes).
    points : tuple of GrazingLocation
        In order of the second parameter along the curve.
    end : str
        Why each end stopped: ``"<first end>, <last end>"`` ('bound', 'max_points', 'step_too_small').
    """

    parameters: tuple[str, str]
    measure: str
    points: tuple[GrazingLocation, ...]
    end: str
    kind: str = "grazing"

    @property
    def orbits(self) -> tuple[PeriodicOrbit, ...]:
        """The smooth-side orbit at each point."""
        return tuple(p.orbit for p in self.points)

    def values(self, name: str) -> NDArray[np.float64]:
        """One parameter along the curve (the first: the located values)."""
        if name == self.parameters[0]:
            return np.array([p.value for p in self.points])
        return np.array([p.orbit.parameter(name) for p in self.points])


def _zero(pts: list[tuple[float, float, PeriodicOrbit]]) -> float:
    """The parameter where the measure vanishes: inverse interpolation (parameter as a polynomial in the measure)."""
    margins = [m for _p, m, _o in pts]
    if len(pts) < 2 or len(set(margins)) < len(margins):
        return math.nan
    total = 0.0
    for i, (pi, mi, _o) in enumerate(pts):
        weight = 1.0
        for j, (_pj, mj, _oj) in enumerate(pts):
            if j != i:
                weight *= -mj / (mi - mj)
        total += weight * pi
    return total


def locate_grazing_at(
    system: ParametrisedMap,
    guess: NDArray[np.float64],
    parameters: NDArray[np.float64],
    first: str,
    reference: tuple[int, int],
    measure: str,
    side: int,
    period: int = 1,
    settings: GrazingCurveSettings = GrazingCurveSettings(),
    slope: NDArray[np.float64] | None = None,
) -> GrazingLocation:
    """Locate the grazing point in parameter ``first`` near ``parameters`` (the other parameters fixed).

    Parameters
    ----------
    system : ParametrisedMap
        The map P (the orbit is a fixed point of P^period).
    guess : ndarray, shape (n,)
        A state of the orbit near the point (predicted).
    parameters : ndarray, shape (m,)
        The parameter vector, with ``first`` at the predicted grazing value.
    first : str
        The located parameter.
    reference : (int, int)
        (impacts, sticks) of the orbit on the smooth side.
    measure : str
        'tangency' or 'velocity' (:func:`grazing_measure`).
    side : {1, -1}
        The smooth side: above (+1) or below (-1) the point in ``first``.
    period : int
        k: map iterations per orbit period.
    settings : GrazingCurveSettings
        Tolerance, first probe, most shots.
    slope : ndarray, shape (n,), optional
        d state / d ``first`` along the orbit family (improves the guesses).

    Raises
    ------
    RuntimeError
        No smooth-side orbit found near the prediction, or no convergence within ``max_trials`` shots.
    """
    index = list(system.parameter_names).index(first)
    scale = float(system.parameter_scale[index])
    predicted = float(parameters[index])
    tol = settings.tolerance * max(abs(predicted), scale)
    shooting = ShootingSettings(max_iterations=20)
    samples: list[tuple[float, float, PeriodicOrbit]] = []  # smooth-side (value, measure, orbit)
    bad = math.nan  # the nearest trial beyond the point (another impact count, or no orbit)
    offset = settings.probe * scale
    trial = predicted + side * offset
    d_state = np.zeros(len(guess)) if slope is None else np.asarray(slope, dtype=float)
    estimate = math.nan
    for shots in range(1, settings.max_trials + 1):
        p = np.array(parameters, dtype=float)
        p[index] = trial
        near_p, near_y = (samples[-1][0], samples[-1][2].state) if samples else (predicted, np.asarray(guess, dtype=float))
        try:
            orbit = shoot(system, near_y + d_state * (trial - near_p), p, period, shooting)
            margin = grazing_measure(orbit.hybrid, measure) if orbit.hybrid is not None and orbit.hybrid.signature == reference else math.nan
        except ShootingError:
            orbit, margin = None, math.nan
        if margin > 0.0:
            if samples:
                d_state = (orbit.state - samples[-1][2].state) / (trial - samples[-1][0])
            samples.append((trial, margin, orbit))
            samples.sort(key=lambda sample: -side * sample[0])  # the nearest to the point last
        elif not samples:  # no smooth-side orbit yet: probe farther into the smooth side
            offset *= 4.0
            if offset > 50.0 * scale:
                break
            trial = predicted + side * offset
            continue
        else:
            bad = trial
        nearest = samples[-1][0]
        if len(samples) == 1:  # a second sample for the slope: between the first and the failed trial, or farther in
            trial = 0.5 * (nearest + bad) if math.isfinite(bad) else nearest + side * offset
            continue
        previous, estimate = estimate, _zero(samples[-3:])
        # converged: the nearest sample is within tol, or a new sample moved the extrapolated point by less than tol
        converged = abs(estimate - nearest) <= tol or (margin > 0.0 and abs(estimate - previous) <= tol and samples[-1][1] < 1e-4)
        if math.isfinite(estimate) and converged:
            return GrazingLocation(float(estimate), samples[-1][2], samples[-1][1], side, shots)
        if math.isfinite(bad) and abs(bad - nearest) <= tol:
            if samples[-1][1] > 1e-6:  # the orbit ends (a fold, or Newton fails) before its measure vanishes
                raise RuntimeError(f"the orbit is lost at {first} = {nearest!r} with grazing measure {samples[-1][1]:.3g}: no grazing point there")
            value = estimate if math.isfinite(estimate) and side * (nearest - estimate) >= 0.0 else 0.5 * (bad + nearest)
            return GrazingLocation(float(value), samples[-1][2], samples[-1][1], side, shots)
        inside = math.isfinite(estimate) and side * (nearest - estimate) > 0.0 and (not math.isfinite(bad) or side * (estimate - bad) > 0.0)
        if inside:
            trial = estimate
        elif math.isfinite(bad):
            trial = 0.5 * (nearest + bad)
        else:
            trial = nearest - side * 2.0 * abs(nearest - samples[0][0])
    raise RuntimeError(f"no grazing point located in {first} near {predicted!r} ({len(samples)} smooth-side orbits in {settings.max_trials} shots)")


def _start(system: ParametrisedMap, point: SpecialPoint | PeriodicOrbit, first: str, settings: GrazingCurveSettings) -> tuple[GrazingLocation, str, tuple[int, int]]:
    """The first location: from a grazing special point (or an orbit on the smooth side), both sides tried."""
    orbit = point.orbit if isinstance(point, SpecialPoint) else point
    if orbit.hybrid is None:
        raise ValueError("a grazing curve needs a hybrid map (its orbits carry no HybridInfo)")
    info = orbit.hybrid
    measure = "tangency" if grazing_measure(info, "tangency") <= grazing_measure(info, "velocity") else "velocity"
    value = point.value if isinstance(point, SpecialPoint) else orbit.parameter(first)
    own = orbit.parameter(first)
    sides = (1, -1) if own >= value else (-1, 1)
    errors = []
    period = orbit.period
    base = _base(system)
    for side in sides:
        p = orbit.parameters.copy()
        p[list(system.parameter_names).index(first)] = value
        try:
            return locate_grazing_at(base, orbit.state, p, first, info.signature, measure, side, period, settings), measure, info.signature
        except RuntimeError as error:
            errors.append(str(error))
    raise RuntimeError("; ".join(errors))


def _base(system: ParametrisedMap) -> ParametrisedMap:
    from vibroimpact.orbits.branch import Iterated

    return system.base if isinstance(system, Iterated) else system


def trace_grazing(
    system: ParametrisedMap,
    point: SpecialPoint | PeriodicOrbit,
    second: str,
    bounds: dict[str, tuple[float, float]] | None = None,
    settings: GrazingCurveSettings = GrazingCurveSettings(),
    direction: int = 0,
    first: str | None = None,
) -> GrazingCurve:
    """Follow a grazing point in its own parameter and ``second`` (see the module docstring).

    Parameters
    ----------
    system : ParametrisedMap
        The map of the branch on which the point was found (``Iterated(map, k)`` or the map with ``point``'s orbit of
        period k).
    point : SpecialPoint or PeriodicOrbit
        A ``grazing`` point from :func:`.continuation.continue_branch` (its orbit is the smooth-side orbit), or an orbit
        on the smooth side of a grazing point (then it is first located in ``first``).
    second : str
        The stepped parameter.
    bounds : dict, optional
        Parameter name -> (lower, upper) for either parameter; the curve stops at a bound (on it, for ``second``).
    settings : GrazingCurveSettings
        Steps and tolerances.
    direction : {1, -1, 0}
        Increasing ``second`` first, decreasing, or both ways (the curve then runs in increasing ``second``... from
        the lower-direction end to the upper-direction end).
    first : str, optional
        The located parameter (default: ``point.parameter``; required for an orbit).

    Returns
    -------
    GrazingCurve
        The located points and why each end stopped.
    """
    if first is None:
        if not isinstance(point, SpecialPoint):
            raise ValueError("first: the located parameter is required when point is an orbit")
        first = point.parameter
    if isinstance(point, SpecialPoint) and point.kind != "grazing":
        raise ValueError(f"trace_grazing needs a grazing point, got {point.kind!r}")
    if direction not in (1, -1, 0):
        raise ValueError(f"direction = {direction!r}: allowed 1, -1, 0")
    names = list(system.parameter_names)
    i1, i2 = names.index(first), names.index(second)
    limits = {i1: (-math.inf, math.inf), i2: (-math.inf, math.inf)}
    for name, (low, high) in (bounds or {}).items():
        limits[names.index(name)] = (low, high)
    start, measure, reference = _start(system, point, first, settings)
    base = _base(system)
    runs = []
    for sign in ((1, -1) if direction == 0 else (direction,)):
        runs.append(_walk(base, start, i1, i2, sign, reference, measure, settings, limits))
    if len(runs) == 1:
        points, end = runs[0]
    else:
        (up, up_end), (down, down_end) = runs
        points, end = list(reversed(down)) + up[1:], f"{down_end}, {up_end}"
    return GrazingCurve((first, second), measure, tuple(points), end)


def _walk(
    system: ParametrisedMap, start: GrazingLocation, i1: int, i2: int, sign: int, reference: tuple[int, int], measure: str,
    s: GrazingCurveSettings, limits: dict[int, tuple[float, float]],
) -> tuple[list[GrazingLocation], str]:  # fmt: skip
    first = system.parameter_names[i1]
    scale2 = float(system.parameter_scale[i2])
    low2, high2 = limits[i2]
    low1, high1 = limits[i1]
    points = [start]
    h = s.step
    period = start.orbit.period
    while len(points) < s.max_points:
        last = points[-1]
        x2 = last.orbit.parameters[i2]
        if (sign > 0 and x2 >= high2) or (sign < 0 and x2 <= low2):
            return points, "bound"
        target = x2 + sign * h * scale2
        target = min(target, high2) if sign > 0 else max(target, low2)
        p = last.orbit.parameters.copy()
        p[i2] = target
        guess = last.orbit.state.copy()
        value = last.value
        if len(points) >= 2:
            prev = points[-2]
            dx = last.orbit.parameters[i2] - prev.orbit.parameters[i2]
            if dx != 0.0:
                t = (target - last.orbit.parameters[i2]) / dx
                value = last.value + t * (last.value - prev.value)
                guess = last.orbit.state + t * (last.orbit.state - prev.orbit.state)
        p[i1] = value
        try:
            found = locate_grazing_at(system, guess, p, first, reference, measure, last.side, period, s)
        except RuntimeError:
            found = None
        if found is not None and len(points) >= 2:
            # a jump to another grazing point (the prediction was far off): a smaller step
            jump = abs(found.value - value) / max(abs(last.value - points[-2].value), 1e-3 * float(system.parameter_scale[i1]))
            if jump > 2.0:
                found = None
        if found is None:
            h *= 0.5
            if h < s.min_step:
                return points, "step_too_small"
            continue
        points.append(found)
        if not low1 <= found.value <= high1:
            return points, "bound"
        h = min(h * 1.5, s.max_step) if found.shots <= 6 else (max(h / 1.5, s.min_step) if found.shots >= 12 else h)
    return points, "max_points"
