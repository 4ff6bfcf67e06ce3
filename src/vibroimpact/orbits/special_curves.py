"""Two-parameter continuation of folds, period doublings, Neimark-Sacker and grazing points.

A special point found on a branch (:func:`~vibroimpact.orbits.continuation.continue_branch`) is followed in its own
parameter and a second one: the fixed-point equations plus the point's defining function (:func:`defining_function`)
in n + 2 unknowns, by the same pseudo-arclength corrector (:class:`~vibroimpact.orbits.arclength.ArclengthSystem`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.orbits.arclength import ArclengthSystem, Point, TestFunction
from vibroimpact.orbits.bifurcations import critical_pair, grazing_margin, locate, period_doubling_test
from vibroimpact.orbits.branch import MapEvaluation, ParametrisedMap, PeriodicOrbit, SpecialPoint
from vibroimpact.orbits.continuation_settings import ContinuationSettings

__all__ = ["SpecialCurve", "continue_special_point", "defining_function"]


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
        return _critical_pair_test(out)

    def grazing(out: MapEvaluation, y: NDArray[np.float64], p: NDArray[np.float64]) -> float:
        if out.hybrid is None:
            raise ValueError("grazing needs a hybrid map (its evaluations carry no HybridInfo)")
        margin = grazing_margin(out.hybrid)
        return margin if out.hybrid.signature == reference else -margin

    table = {"fold": fold, "period_doubling": doubling, "neimark_sacker": torus, "grazing": grazing}
    if kind not in table:
        raise ValueError(f"kind = {kind!r}: allowed {sorted(table)}")
    return table[kind]


def _critical_pair_test(out: MapEvaluation) -> float:
    """|mu|^2 - 1 of the complex multiplier nearest the unit circle (NaN: no complex pair): the Neimark-Sacker
    condition on the pair alone. The branch's test, det(J(2) - I) (:func:`~vibroimpact.orbits.bifurcations.
    neimark_sacker_test`), is the product of mu_i mu_j - 1 over every pair: beside an unstable multiplier of 35 (the
    paper's second band at 37.574 Hz) its other factors scale it by ~1e3 and round-off in them kept Newton from
    reaching the curve's tolerance ("does not solve its extended system"); this one is O(1) wherever the pair is."""
    if not np.all(np.isfinite(out.jacobian)):
        return math.nan
    critical = critical_pair(np.linalg.eigvals(out.jacobian))
    return math.nan if critical is None else float(abs(critical) ** 2 - 1.0)


@suggest_keywords
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
