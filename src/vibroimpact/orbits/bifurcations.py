"""Test functions of the special points of a branch, their location, and branch switching at a period doubling.

Test functions (each changes sign at its point):

* fold: the continued parameter's component of the branch tangent (the branch turns back);
* period doubling: ``det(J + I)`` (a real multiplier crosses -1);
* Neimark-Sacker: ``det(J(2) - I)`` with ``J(2)`` the second compound (bialternate) matrix of the monodromy, whose
  eigenvalues are the products mu_i mu_j (i < j): it vanishes when a complex pair crosses the unit circle, and also
  at a neutral saddle (a real pair with mu_i mu_j = 1), which the location rejects;
* grazing (hybrid maps): the margin to grazing, ``min(-closest_approach / L, min_impact_velocity / V)`` with the
  sign of the side: positive with the impact count of the branch's start, negative with another count (or where
  no orbit is found). It reaches 0 where a free flight touches the stop (a new impact is born) or an impact's
  velocity goes to zero.

Location: the branch between two points a and b is parametrised by the arclength sigma along a's tangent; at each
trial sigma the corrector puts the point back on the branch and the test function is evaluated there; sigma is
found by regula falsi with the Illinois modification (bisection when a trial fails), to a tolerance that gives the
parameter to better than 1e-8 relative.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from itertools import combinations

import numpy as np
from numpy.typing import NDArray

from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.orbits.arclength import ArclengthSystem, Point
from vibroimpact.orbits.branch import HybridInfo, Iterated, MapEvaluation, ParametrisedMap, PeriodicOrbit, SpecialPoint

__all__ = [
    "second_compound",
    "critical_pair",
    "fold_test",
    "period_doubling_test",
    "neimark_sacker_test",
    "grazing_margin",
    "locate",
    "locate_grazing",
    "classify",
    "switch_period_doubling",
]


def second_compound(matrix: NDArray[np.float64]) -> NDArray[np.float64]:
    """Second compound matrix (2x2 minors, rows and columns indexed by pairs i < j); eigenvalues mu_i mu_j."""
    pairs = list(combinations(range(matrix.shape[0]), 2))
    out = np.empty((len(pairs), len(pairs)))
    for a, (i, j) in enumerate(pairs):
        for b, (k, l) in enumerate(pairs):
            out[a, b] = matrix[i, k] * matrix[j, l] - matrix[i, l] * matrix[j, k]
    return out


def fold_test(point: Point, index: int) -> float:
    """The tangent's component along the continued parameter (unknown ``index`` of z)."""
    return float(point.tangent[index])


def period_doubling_test(out: MapEvaluation) -> float:
    """det(J + I) of the monodromy (NaN where the map has no value)."""
    if not np.all(np.isfinite(out.jacobian)):
        return math.nan
    return float(np.linalg.det(out.jacobian + np.eye(out.jacobian.shape[0])))


def neimark_sacker_test(out: MapEvaluation) -> float:
    """det(J(2) - I) of the monodromy's second compound (0 when mu_i mu_j = 1 for a pair); 0 for a 1-D map."""
    if out.jacobian.shape[0] < 2:
        return 1.0
    if not np.all(np.isfinite(out.jacobian)):
        return math.nan
    compound = second_compound(out.jacobian)
    return float(np.linalg.det(compound - np.eye(compound.shape[0])))


def grazing_margin(info: HybridInfo) -> float:
    """Dimensionless distance to grazing, >= 0: min(-closest_approach / L, min_impact_velocity / V) (bumpers:
    ``onset_depth`` / L in place of the speed, :attr:`HybridInfo.speed_margin`)."""
    return float(min(-info.closest_approach / info.length_scale, info.speed_margin))


def locate(
    arc: ArclengthSystem,
    start: Point,
    end_sigma: float,
    test: Callable[[Point | None], float | None],
    tolerance: float,
    corrector_tolerance: float,
    max_iterations: int = 80,
) -> tuple[Point, Point | None, float]:
    """The point between ``start`` (sigma = 0) and sigma = ``end_sigma`` where ``test`` changes sign.

    Parameters
    ----------
    arc : ArclengthSystem
        The continuation problem.
    start : Point
        Point a, with its tangent.
    end_sigma : float
        Arclength (along a's tangent) of point b, where the test has the other sign.
    test : callable
        Test value of a corrected point (``None`` is passed when the corrector fails; the test may return ``None``
        for "the far side, no value": then the bracket is bisected).
    tolerance : float
        Bracket width in sigma at which to stop.
    corrector_tolerance : float
        Scaled residual of the corrector.

    Returns
    -------
    (Point, Point or None, float)
        The last point with a's sign, the last point with b's sign (None if none was found there) and the final
        bracket width.
    """
    f_lo = test(start)
    lo, hi, f_hi = 0.0, float(end_sigma), None
    lo_point, hi_point = start, None
    sign = np.sign(f_lo) if f_lo else 1.0
    side = 0
    for _ in range(max_iterations):
        if hi - lo <= tolerance:
            break
        if f_hi is None or f_lo is None:
            sigma = 0.5 * (lo + hi)
        else:
            sigma = (lo * f_hi - hi * f_lo) / (f_hi - f_lo)
            if not lo < sigma < hi:
                sigma = 0.5 * (lo + hi)
        trial = arc.correct(start.z + sigma * start.tangent, start.tangent, corrector_tolerance, 12)
        value = test(trial)
        if value is not None and np.sign(value) == sign:
            lo, f_lo, lo_point = sigma, value, trial
            if side == 1 and f_hi is not None:
                f_hi *= 0.5  # Illinois: the retained end's value is halved when the same end moves twice
            side = 1
        else:
            hi, f_hi, hi_point = sigma, value, trial if value is not None else hi_point
            if side == -1 and f_lo is not None:
                f_lo *= 0.5
            side = -1
        if value is not None and value == 0.0:  # exact: the test vanishes at a trial point
            return trial, trial, 0.0
    return lo_point, hi_point, hi - lo


def locate_grazing(
    arc: ArclengthSystem, start: Point, end_sigma: float, tolerance: float, corrector_tolerance: float, hint: Point | None = None
) -> tuple[Point, Point | None, Point | None, float]:
    """The grazing point between ``start`` (sigma = 0) and sigma = ``end_sigma``.

    Beyond a grazing point the map changes (an impact appears or disappears). On the side with the impact its
    Jacobian grows like one over the slowest impact's speed, so Newton's method converges only ever closer to the
    point; on the side without it the map is smooth up to the point. The margin (:func:`grazing_margin`) crosses zero
    linearly on either side (the closest approach, or the speed of the vanishing impact, is proportional to the
    distance to the point), so the inverse interpolation of sigma in the margin through the side points nearest the
    boundary predicts where it vanishes. The point is first approached from ``start``'s side; if an orbit with fewer
    impacts is found beyond it (or given as ``hint``), the approach is repeated from there, where Newton's method
    works to the end.

    Returns
    -------
    (Point, Point or None, Point or None, float)
        The point of ``start``'s side nearest the grazing point; the orbit at the grazing point from the side with
        fewer impacts (None when none was found: then the branch ends there); a point beyond, with another impact
        count (None if none); and the parameter value of the grazing point (NaN when the margin does not vanish within
        the step: a failed step, not a grazing point).
    """
    n = arc.n
    reference = start.out.hybrid.signature
    side, estimate, beyond, rough = _approach(arc, start, end_sigma, tolerance, corrector_tolerance)
    if beyond is None and hint is not None and hint.out.hybrid is not None and hint.out.hybrid.signature != reference:
        beyond = hint
    if beyond is None and math.isfinite(rough) and 0.0 < rough < 8.0 * end_sigma:
        beyond = _jump(arc, start, side, rough, reference, corrector_tolerance)
    if beyond is not None and beyond.out.hybrid.impacts < start.out.hybrid.impacts:
        # approach again from the smooth side, towards the parameter where start's side extrapolates the point
        # (the other branch may leave the point in either direction: a nonsmooth fold when the linear orbit turns back)
        target = float(start.z[n] + rough * start.tangent[n]) if math.isfinite(rough) else float(side.z[n])
        tangent = beyond.tangent if beyond.tangent[n] * (target - beyond.z[n]) >= 0.0 else -beyond.tangent
        back = Point(beyond.z, beyond.y, beyond.p, beyond.out, beyond.residual, beyond.jacobian, tangent, 0, beyond.history)
        # as far as the start's side's nearest point at least: the point lies between it and the orbit beyond
        span = max(abs(target - float(beyond.z[n])), abs(float(side.z[n]) - float(beyond.z[n])))
        reach = 2.0 * span / max(abs(float(tangent[n])), 1e-3) + 10.0 * tolerance
        other, other_estimate, _, _ = _approach(arc, back, reach, tolerance, corrector_tolerance)
        if math.isfinite(other_estimate):
            value = float(other.z[n] + (other_estimate - float(back.tangent @ (other.z - back.z))) * other.tangent[n] / float(back.tangent @ other.tangent))
            return side, other, beyond, value * float(arc.sp[0])
    if not math.isfinite(estimate):
        return side, None, None, math.nan
    value = float(side.z[n] + (estimate - float(start.tangent @ (side.z - start.z))) * side.tangent[n] / float(start.tangent @ side.tangent))
    return side, side, beyond, value * float(arc.sp[0])


def _jump(arc: ArclengthSystem, start: Point, side: Point, rough: float, reference: tuple[int, int], tolerance: float) -> Point | None:
    """An orbit with another impact count just across the grazing point (Newton fails next to it on the impacting
    side): along the branch's tangent beyond the extrapolated point, then at fixed parameter on either side of it
    (where the branch meets the other orbits at an angle, e.g. the linear orbit turning back)."""
    for factor in (1.25, 1.6, 2.5, 4.0):
        trial = arc.correct(start.z + factor * rough * start.tangent, start.tangent, tolerance, 12)
        if trial is not None and trial.out.hybrid is not None and trial.out.hybrid.signature != reference:
            return trial
    n = arc.n
    fixed = np.zeros(n + 1)
    fixed[n] = 1.0
    distance = float(start.tangent @ (side.z - start.z))
    for factor in (1.25, 2.0, -0.25, -1.0, 4.0):
        shift = (rough - distance) * factor
        predicted = side.z.copy()
        predicted[n] += shift * side.tangent[n]
        trial = arc.correct(predicted, fixed, tolerance, 12)
        if trial is not None and trial.out.hybrid is not None and trial.out.hybrid.signature != reference:
            tangent = trial.tangent if trial.tangent @ (side.z - trial.z) < 0.0 else -trial.tangent
            return Point(trial.z, trial.y, trial.p, trial.out, trial.residual, trial.jacobian, tangent, trial.iterations, trial.history)
    return None


def _approach(
    arc: ArclengthSystem, start: Point, end_sigma: float, tolerance: float, corrector_tolerance: float, max_iterations: int = 60
) -> tuple[Point, float, Point | None, float]:
    """Approach the grazing point from ``start``'s side.

    Returns (nearest side point, sigma of the point or NaN, a point beyond or None, the last extrapolated sigma).
    """
    reference = start.out.hybrid.signature
    samples = [(0.0, grazing_margin(start.out.hybrid), start)]
    lo, hi, beyond = 0.0, float(end_sigma), None
    estimate = math.nan
    failures = 0
    for _ in range(max_iterations):
        if len(samples) >= 2:
            estimate = _extrapolate_zero(samples[-3:])
        if hi - lo <= tolerance or (len(samples) >= 2 and abs(estimate - samples[-1][0]) <= tolerance):
            break
        if len(samples) >= 3 and not estimate < 1.5 * end_sigma:
            return samples[-1][2], math.nan, beyond, estimate  # the margin does not vanish within the step
        sigma = estimate if lo < estimate < hi else 0.5 * (lo + hi)
        near = samples[-1][2]  # predict from the side point nearest the boundary, along its own tangent
        predicted = near.z + (sigma - samples[-1][0]) / float(start.tangent @ near.tangent) * near.tangent
        trial = arc.correct(predicted, start.tangent, corrector_tolerance, 8, reference if len(samples) < 3 else None, near.z)
        if trial is not None and trial.out.hybrid is not None and trial.out.hybrid.signature == reference:
            lo = sigma
            samples.append((sigma, grazing_margin(trial.out.hybrid), trial))
            failures = 0
        else:
            hi = sigma
            failures += 1
            if trial is not None and trial.out.hybrid is not None:
                beyond = trial
                if beyond.out.hybrid.impacts < reference[0] and len(samples) >= 2 and samples[-1][1] < 1e-3:
                    break  # the side without the impact is smooth: the caller approaches from there
            if failures >= 4 and len(samples) >= 2 and samples[-1][1] < 1e-3:
                break  # Newton's region shrinks next to the point on the impacting side: extrapolate from here
    side = samples[-1][2]
    # the margin must approach zero inside the step; Newton may fail right next to the point (hi < estimate)
    if len(samples) >= 2:
        estimate = _extrapolate_zero(samples[-3:])
    if not (len(samples) >= 2 and samples[-1][1] < 1e-3 and math.isfinite(estimate) and lo - tolerance <= estimate <= end_sigma + tolerance):
        return side, math.nan, beyond, estimate
    if beyond is None:  # look once just beyond the grazing point for an orbit with another impact count
        for offset in (1e-6, 1e-4, 1e-2):
            sigma = estimate + offset * max(1.0, abs(float(start.z[-1])))
            trial = arc.correct(start.z + sigma * start.tangent, start.tangent, corrector_tolerance, 12)
            if trial is not None and trial.out.hybrid is not None and trial.out.hybrid.signature != reference:
                beyond = trial
                break
    return side, float(estimate), beyond, estimate


def _extrapolate_zero(samples: list[tuple[float, float, Point]]) -> float:
    """sigma where the margin vanishes: the inverse interpolation (sigma as a polynomial in the margin) at 0."""
    sigmas = [item[0] for item in samples]
    margins = [item[1] for item in samples]
    if len(set(margins)) < len(margins):
        return math.nan
    total = 0.0
    for i, (si, mi) in enumerate(zip(sigmas, margins)):
        weight = 1.0
        for j, mj in enumerate(margins):
            if j != i:
                weight *= (0.0 - mj) / (mi - mj)
        total += weight * si
    return total


def _closest(multipliers: NDArray[np.complex128], target: complex) -> complex:
    return complex(multipliers[np.argmin(np.abs(multipliers - target))])


def critical_pair(multipliers: NDArray[np.complex128]) -> complex | None:
    """The complex multiplier nearest the unit circle (None: every multiplier is real): the one a Neimark-Sacker
    point puts on it."""
    pair = multipliers[np.abs(multipliers.imag) > 1e-9 * np.maximum(np.abs(multipliers), 1e-300)]
    return None if pair.size == 0 else complex(pair[np.argmin(np.abs(np.abs(pair) - 1.0))])


def classify(kind: str, orbit: PeriodicOrbit, parameter: str, test_value: float) -> SpecialPoint | None:
    """The special point of ``kind`` at ``orbit``, or None when its multipliers deny it (a neutral saddle)."""
    mu = orbit.multipliers
    if kind == "neimark_sacker":
        critical = critical_pair(mu)
        if critical is None or abs(abs(critical) - 1.0) > 1e-5:
            return None
        note = f"complex pair crosses the unit circle at angle {abs(np.angle(critical)):.6g} rad"
        return SpecialPoint(kind, orbit, parameter, orbit.parameter(parameter), test_value, note)
    if kind == "period_doubling":
        eigenvalues, vectors = np.linalg.eig(orbit.monodromy)
        k = int(np.argmin(np.abs(eigenvalues + 1.0)))
        vector = np.real(vectors[:, k])
        note = f"multiplier {_closest(mu, -1.0).real:.10g} crosses -1"
        return SpecialPoint(kind, orbit, parameter, orbit.parameter(parameter), test_value, note, eigenvector=vector / np.linalg.norm(vector))
    if kind == "fold":
        note = f"the branch turns back; multiplier {_closest(mu, 1.0).real:.10g}"
        return SpecialPoint(kind, orbit, parameter, orbit.parameter(parameter), test_value, note)
    raise ValueError(f"kind = {kind!r}: classify handles fold, period_doubling and neimark_sacker")


@suggest_keywords
def switch_period_doubling(system: ParametrisedMap, point: SpecialPoint, amplitude: float = 1e-3, tolerance: float = 1e-11) -> PeriodicOrbit:
    """The period-2k orbit born at a period doubling, from the guess y* +- eps v (v: the -1 eigenvector).

    At the period doubling the fixed points of P^{2k} have a pitchfork: the period-k branch and the period-2k one,
    whose tangent there is (v, 0). The guess y* + eps v is corrected by Newton's method on P^{2k}(y) - y = 0 with the
    parameter free and the step kept orthogonal to v (a pseudo-arclength step of length eps along v), so the new
    orbit is found on whichever side of the bifurcation it exists. Both signs of eps are tried.

    Parameters
    ----------
    system : ParametrisedMap
        The map P whose period-k orbit doubles (k is taken from the special point's orbit).
    point : SpecialPoint
        A ``period_doubling`` point.
    amplitude : float
        eps, relative to the map's state scale [-].
    tolerance : float
        Scaled residual of the corrector.

    Returns
    -------
    PeriodicOrbit
        A period-2k orbit (``period`` = 2k) whose two halves differ.
    """
    if point.kind != "period_doubling" or point.eigenvector is None:
        raise ValueError(f"switch_period_doubling needs a period_doubling point, got {point.kind!r}")
    orbit = point.orbit
    k = orbit.period
    doubled = Iterated(system, 2 * k)
    index = orbit.parameter_names.index(point.parameter)
    arc = ArclengthSystem(doubled, orbit.parameters, (index,))
    direction = np.concatenate([point.eigenvector / arc.sy, [0.0]])
    direction /= np.linalg.norm(direction)
    start = arc.to_z(orbit.state, orbit.parameters)
    for sign in (1.0, -1.0):
        found = arc.correct(start + sign * amplitude * direction, direction, tolerance, 30)
        if found is None:
            continue
        half = Iterated(system, k).evaluate(found.y, found.p).image
        if np.max(np.abs(half - found.y) / arc.sy) > 0.1 * amplitude:
            return found.orbit(doubled)
    raise RuntimeError(f"no period-{2 * k} orbit found next to the period doubling at {point.parameter} = {orbit.parameter(point.parameter)!r}")
