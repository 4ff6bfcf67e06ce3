"""Attractors by brute force: stepped sweeps of an engine over frequencies, each point's motion measured and named.

:func:`stepped_sweep` runs the engine with exact Jacobians for the problem's contact law (the compiled exact engine
for rigid stops, the bumper's closed-form engine for Kelvin-Voigt bumpers) over frequencies in one direction, the end
state carried to the next frequency; at each frequency (:func:`measure_motion`) a transient is dropped, then the
strobes of the first coordinate (X1 on the paper's layout), its per-period fundamental and the impact velocities are
kept and the motion is classified (:data:`MOTION_CLASSES`): linear, one impact per period, another periodic motion,
or, where the strobes do not repeat, quasi-periodic, chaotic or irregular from the exact Jacobians
(:func:`vibroimpact.orbits.motion.classify_motion`; from the strobes alone where a Jacobian is undefined,
:func:`~vibroimpact.orbits.motion.classify_strobes`). A strictly negative Lyapunov exponent means a periodic orbit
approached slowly: the motion is classified by the period that repeats best.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from vibroimpact.analysis.measures import Measure, as_measure
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.orbits.motion import classify_motion, classify_strobes
from vibroimpact.simulation.harmonics import linear_state, resting_state

__all__ = ["MOTION_CLASSES", "MAX_KEPT_IMPACTS", "MAX_PERIOD", "REPEAT_TOLERANCE", "SWEEP_FIELDS", "at_frequency", "sweep_arrays", "linear_start", "measure_motion", "measure_motions", "repeat_scale", "stepped_sweep", "sweep_chain"]

#: What the motion at a brute-force point is (CF flags of ``brute_regime`` and ``chart_regime``, values 0...).
MOTION_CLASSES = ("linear", "one_impact", "other_periodic", "quasi_periodic", "chaotic", "irregular")
#: Impact velocities kept per brute-force point (NaN-padded).
MAX_KEPT_IMPACTS = 64
#: Longest period looked for in the strobes [periods] (the strobes kept must cover it twice).
MAX_PERIOD = 32
#: Strobes repeat when they differ by less than this, relative to the motion's length (Delta + q |H12| on the paper's
#: layout, :meth:`ImpactProblem.velocity_scale` / w in general; velocities: times w) [-].
REPEAT_TOLERANCE = 1e-6
#: The arrays of :func:`stepped_sweep`, over the frequencies in increasing order.
SWEEP_FIELDS = ("strobe", "amplitude", "velocity", "impacts", "regime", "period", "lyapunov", "state", "error")


def at_frequency(problem: ImpactProblem, frequency: float) -> ImpactProblem:
    """``problem`` at another excitation frequency [Hz]: the structure, stops and the load's distribution, phase and
    static part kept (the bifurcation kind's ``problem_at`` without its clearance and phase)."""
    excitation = dataclasses.replace(problem.harmonic, frequency=float(frequency))
    return ImpactProblem(problem.system, problem.stops, excitation)


def stepped_sweep(
    problem: ImpactProblem, direction: str, frequencies: Sequence[float], transient: int, strobes: int, engine: Any,
    report: Callable[[float], None] | None = None, measure: int | Measure = 0,
) -> dict[str, NDArray[Any]]:  # fmt: skip
    """A stepped brute-force sweep of ``problem`` in one direction, the end state carried from point to point.

    Parameters
    ----------
    problem : ImpactProblem
        Structure, stops (rigid or Kelvin-Voigt bumpers) and harmonic load; its frequency is replaced by each point's.
    direction : str
        ``up`` (increasing frequency) or anything else (decreasing).
    frequencies : sequence of float
        The points [Hz], in any order.
    transient, strobes : int
        Periods dropped, then periods kept, at each point [-].
    engine : object
        A built engine with exact Jacobians for the problem's contact law (``integrate(..., moments=True,
        jacobians=True)``).
    report : callable, optional
        Gets the number of points done after each.
    measure : int or Measure
        What ``amplitude`` holds per period: a row of :mod:`vibroimpact.analysis.measures`, or a coordinate index for
        its |X| (0: x1).

    Returns
    -------
    dict
        :data:`SWEEP_FIELDS` over the frequencies in increasing order (whatever the direction): ``strobe`` (n, s) x1
        at the strobes [m], ``amplitude`` (n, s) per-period ``measure`` [its unit], ``velocity`` (n, :data:`MAX_KEPT_IMPACTS`) the
        last impact velocities [m s-1], ``impacts`` per period, ``regime`` (:data:`MOTION_CLASSES` index, -1 where
        the engine failed), ``period`` (0: no repeat), ``lyapunov`` [1/period], ``state`` (n, 2N) the end state and
        ``error`` the raw message where the engine failed (the next point then starts at rest), else empty.
    """
    f = np.array(frequencies)
    order = np.argsort(f) if direction == "up" else np.argsort(f)[::-1]
    n, s = f.size, strobes
    out = sweep_arrays(n, s, 2 * problem.size)
    state = None
    errors = [""] * n
    for done, k in enumerate(order):
        moved = at_frequency(problem, float(f[k]))
        state = linear_start(moved) if state is None else state
        try:
            state = measure_motion(engine, moved, state, transient, s, out, k, measure)
        except RuntimeError as error:  # the engine made no progress (endless chattering): start the next point at rest
            state = resting_state(moved)
            errors[k] = f"{type(error).__name__}: {str(error)[:160]}"
        if report is not None:
            report(done + 1)
    return out | {"error": np.array(errors, dtype=str)}


def sweep_chain(problems: Sequence[ImpactProblem], first: int = 0) -> tuple[list[NDArray[np.float64]], list[int]]:
    """:func:`stepped_sweep`'s rule as starts and links for :func:`measure_motions`: through ``problems`` in their
    order, the first point from :func:`linear_start`, each next one from the previous point's end state (a link to
    that run, which is run ``first + i`` in the call), or from rest where that point failed."""
    starts = [linear_start(problems[0])] + [resting_state(problem) for problem in problems[:-1]]
    return starts, [-1] + [first + i for i in range(len(problems) - 1)]


def sweep_arrays(n: int, strobes: int, width: int) -> dict[str, NDArray[Any]]:
    """The arrays :func:`measure_motion` fills for ``n`` points of ``strobes`` periods and states of ``width`` (2N)
    entries, unmeasured: NaN, no impacts, ``regime`` -1, ``period`` 0 (:data:`SWEEP_FIELDS` but ``error``)."""
    return {
        "strobe": np.full((n, strobes), np.nan), "amplitude": np.full((n, strobes), np.nan), "velocity": np.full((n, MAX_KEPT_IMPACTS), np.nan),
        "impacts": np.zeros(n), "regime": np.full(n, -1, dtype=np.int8), "period": np.zeros(n, dtype=np.int16), "lyapunov": np.full(n, np.nan),
        "state": np.full((n, width), np.nan),
    }  # fmt: skip


def linear_start(problem: ImpactProblem) -> NDArray[np.float64]:
    """The linear steady state at t = 0 if it fits inside every stop, else rest on the stops [m, m s-1]."""
    linear = linear_state(problem)
    return linear.state(problem.omega) if linear.fits(problem) else resting_state(problem)


def measure_motion(engine: Any, problem: ImpactProblem, state: NDArray[np.float64], transient: int, strobes: int, out: dict, k: int, measure: int | Measure = 0) -> NDArray[np.float64]:
    """Drop ``transient`` periods from ``state``, keep ``strobes`` periods at row ``k`` of ``out`` (the arrays of
    :func:`stepped_sweep`, ``error`` aside; ``amplitude`` the per-period ``measure``); return the end state
    [m, m s-1]."""
    if transient:
        state = engine.integrate(problem, state, 0.0, transient).final_state
    run = engine.integrate(problem, state, 0.0, strobes, moments=True, jacobians=True)
    s = run.strobe_states
    scale = repeat_scale(problem)
    mismatch = [float(np.max(np.abs(s[p:] - s[:-p]) / scale)) if s.shape[0] > 2 * p else math.inf for p in range(1, MAX_PERIOD + 1)]
    velocities = run.impact_velocities
    _keep_motion(
        problem, out, k, s, run.moments, velocities[-MAX_KEPT_IMPACTS:], velocities.size, np.array(mismatch), lambda: run.strobe_jacobians,
        lambda first: int(np.count_nonzero(run.impact_times >= run.strobe_times[first])), as_measure(measure, problem),
    )  # fmt: skip
    return run.final_state


def repeat_scale(problem: ImpactProblem) -> NDArray[np.float64]:
    """The scales of the strobes' repeat test [m, m s-1]: the motion's length for positions, times w for velocities."""
    length = problem.length_scale()
    return np.repeat([length, problem.omega * length], problem.size)


def measure_motions(
    engine: Any, problems: Sequence[ImpactProblem], case_of: Sequence[int], starts: Sequence[NDArray[np.float64]], transient: int, strobes: int,
    measure: int | Measure = 0, chain_from: Sequence[int] | None = None,
) -> dict[str, NDArray[Any]]:  # fmt: skip
    """:func:`measure_motion` of many runs: run i from ``starts[i]`` on ``problems[case_of[i]]``; row i of the arrays
    returned (:func:`sweep_arrays`), ``regime`` -1 where the engine made no progress. Where ``chain_from[i]`` = j >= 0
    (j < i), run i starts from run j's end state instead, unless run j failed (a stepped sweep, as
    :func:`stepped_sweep` carries its state; ``starts[i]`` is then where it starts).

    An engine that can (capability ``batched``) runs them all in one compiled call
    (:mod:`~vibroimpact.engines.batch`), bit for bit the single runs; any other runs them one by one.
    """
    runs = len(starts)
    width = 2 * problems[0].size if problems else 0
    out = sweep_arrays(runs, strobes, width)
    if runs == 0:
        return out
    chain = [-1] * runs if chain_from is None else [int(j) for j in chain_from]
    if not getattr(engine.capabilities, "batched", False):
        ends: list[NDArray[np.float64] | None] = [None] * runs
        for i, (c, start) in enumerate(zip(case_of, starts)):
            begin = ends[chain[i]] if chain[i] >= 0 and ends[chain[i]] is not None else start
            try:
                ends[i] = measure_motion(engine, problems[c], begin, transient, strobes, out, i, measure)
            except RuntimeError:  # no progress (endless chattering): no attractor from this start
                out["regime"][i] = -1
        return out
    scales = np.array([repeat_scale(problem) for problem in problems])
    batch = engine.run_many(problems, np.asarray(case_of, dtype=np.int64), np.array(starts, dtype=float), transient, strobes, scales, MAX_PERIOD, np.array(chain, dtype=np.int64))
    measures = [as_measure(measure, problem) for problem in problems]
    for i, c in enumerate(case_of):
        if batch.status[i] != 0:  # no progress (endless chattering): no attractor from this start
            continue
        count = int(batch.impacts[i])
        _keep_motion(
            problems[c], out, i, batch.strobes[i], batch.moments[i], batch.velocities[i, : min(count, MAX_KEPT_IMPACTS)], count, batch.mismatch[i],
            lambda i=i: batch.jacobians[i], lambda first, i=i: int(batch.after[i, first]), measures[c],
        )  # fmt: skip
    return out


def _keep_motion(
    problem: ImpactProblem, out: dict, k: int, s: NDArray[np.float64], moments: NDArray[np.complex128], velocities: NDArray[np.float64], count: int,
    mismatch: NDArray[np.float64], jacobians: Callable[[], NDArray[np.float64]], impacts_from: Callable[[int], int], measure: Measure,
) -> None:  # fmt: skip
    """Row ``k`` of ``out`` from a measured run: its strobes ``s`` and per-period ``moments``, its last impact speeds
    and their ``count``, the repeat test per period (``mismatch``), its Jacobians (asked only where the strobes do not
    repeat) and the impacts at or after strobe j (``impacts_from(j)``)."""
    strobes = s.shape[0] - 1
    out["state"][k] = s[-1]
    out["strobe"][k] = s[1:, 0]
    n, m = problem.size, len(problem.stops)
    out["amplitude"][k] = measure.of_harmonics(problem, problem.omega, moments[:, :n], moments[:, n : n + m]) * 2.0 / problem.period
    out["velocity"][k, : velocities.size] = velocities
    out["impacts"][k] = count / strobes
    period = next((p for p, value in enumerate(mismatch, start=1) if value < REPEAT_TOLERANCE), 0)
    if count == 0:
        out["regime"][k], out["period"][k] = 0, 1
        return
    if not period:
        matrices = jacobians()
        if np.all(np.isfinite(matrices)):
            evidence = classify_motion(matrices, s[1:])
        else:  # a degenerate event (e.g. a chatter sequence ending as a release begins) left a Jacobian undefined
            evidence = classify_strobes(s[1:])  # the strobes alone decide the clear cases; no exponent
        out["lyapunov"][k] = evidence.lyapunov_exponent
        if evidence.lyapunov_exponent < -0.005:  # contracting: a periodic orbit approached slowly
            period = int(np.argmin(mismatch)) + 1
        else:
            out["regime"][k] = MOTION_CLASSES.index(evidence.kind)
            return
    out["period"][k] = period
    tail = (strobes // period) * period
    out["regime"][k] = 1 if period == 1 and impacts_from(strobes - tail) == tail else 2
