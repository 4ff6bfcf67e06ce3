"""Where the strobe of a periodic orbit sits: the gaps its contacts leave, and moving the strobe into the widest.

A stroboscopic map P (the state at t = 0 mod T to the state a period later) is smooth near an orbit only while no
impact (rigid stops) or contact interval (bumpers) crosses the strobe: where an impact crosses it, the fixed point
jumps between the states just before and just after the impact, and Newton's method and a continuation cannot
follow. Moving the strobe is a change of the force's phase: the orbit seen at t' = t - g T is the orbit of the problem
with phase + 2 pi g, whose multipliers are the same (the two maps are conjugate by the flow over g T).

:func:`strobe_gap` measures an orbit's contacts against its strobe; :func:`resection` moves a problem's strobe into
the middle of the widest gap; :meth:`vibroimpact.orbits.maps.ImpactMap.resectioned` does it for a point of a map, and
the continuation calls it when a step fails next to an impact at the strobe.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from vibroimpact.engines.base import MODE_FREE
from vibroimpact.engines.registry import BUMPER, engine_for, make_engine
from vibroimpact.model.problem import ImpactProblem

__all__ = ["StrobeGap", "strobe_gap", "resection", "moved_state"]


@dataclass(frozen=True)
class StrobeGap:
    """The strobe of an orbit against its contacts, in fractions of the excitation period T.

    Attributes
    ----------
    shift : float
        g in [0, 1): the middle of the widest gap between the contact instants (intervals with bumpers) modulo T,
        measured from the strobe [-].
    nearest : float
        Distance from the strobe (t = 0 mod T) to the nearest contact modulo T [-]; 0 when a contact interval spans it.
    half_width : float
        Half the widest gap: the distance from the moved strobe to the nearest contact [-].
    """

    shift: float
    nearest: float
    half_width: float


def strobe_gap(problem: ImpactProblem, state: NDArray[np.float64], periods: int, engine: Any) -> tuple[StrobeGap | None, Any]:
    """The gaps the contacts of the motion from ``state`` (at t = 0) over ``periods`` periods leave modulo T, with the
    engine's run; None where there is no contact, or no gap (a bumper in contact all the time)."""
    if problem.contact_law == BUMPER:
        return _bumper_gap(problem, state, periods, engine)
    run = engine.integrate(problem, state, 0.0, periods)
    fractions = np.sort((run.impact_times / problem.period) % 1.0)
    if fractions.size == 0:
        return None, run
    gaps = np.diff(np.concatenate([fractions, [fractions[0] + 1.0]]))
    k = int(np.argmax(gaps))
    g = float((fractions[k] + 0.5 * gaps[k]) % 1.0)
    nearest = float(min(fractions[0], 1.0 - fractions[-1]))
    return StrobeGap(g, nearest, float(0.5 * gaps[k])), run


def _bumper_gap(problem: ImpactProblem, state: NDArray[np.float64], periods: int, engine: Any) -> tuple[StrobeGap | None, Any]:
    """:func:`strobe_gap` with bumpers: the gaps between the contact intervals (onset to release) modulo T."""
    run = engine.integrate(problem, state, 0.0, periods)
    busy = [(float(a), float(b)) for a, b, mode in run.segments / np.array([problem.period, problem.period, 1.0]) if mode != MODE_FREE and b > a]
    if not busy:
        return None, run
    pieces = []  # the intervals modulo 1, split where they wrap
    for a, b in busy:
        if b - a >= 1.0:
            return None, run  # in contact all the time: no better strobe
        lo, hi = a % 1.0, a % 1.0 + (b - a)
        pieces += [(lo, min(hi, 1.0))] + ([(0.0, hi - 1.0)] if hi > 1.0 else [])
    pieces.sort()
    merged = [list(pieces[0])]
    for lo, hi in pieces[1:]:
        if lo <= merged[-1][1]:
            merged[-1][1] = max(merged[-1][1], hi)
        else:
            merged.append([lo, hi])
    ends = [(hi, (merged[(i + 1) % len(merged)][0] + (1.0 if i + 1 == len(merged) else 0.0)) - hi) for i, (_lo, hi) in enumerate(merged)]
    start, width = max(ends, key=lambda item: item[1])
    if width <= 0.0:
        return None, run
    g = float((start + 0.5 * width) % 1.0)
    nearest = 0.0 if merged[0][0] <= 0.0 or merged[-1][1] >= 1.0 else float(min(merged[0][0], 1.0 - merged[-1][1]))
    return StrobeGap(g, nearest, 0.5 * width), run


def moved_state(problem: ImpactProblem, state: NDArray[np.float64], periods: int, engine: Any, run: Any, shift: float) -> NDArray[np.float64]:
    """The state at t = ``shift`` T of the motion from ``state`` (``run``: the engine's integration of it)."""
    if problem.contact_law == BUMPER:
        return np.asarray(engine.sample(problem, state, 0.0, periods, np.array([shift * problem.period]))[1][0], dtype=float)
    return np.asarray(engine.dense(run, np.array([shift * problem.period]))[0], dtype=float)


def moved_phase(problem: ImpactProblem, shift: float) -> float:
    """The force phase [rad] in [0, 2 pi) whose t = 0 is ``problem``'s t = ``shift`` T."""
    return float((problem.phase + 2.0 * np.pi * shift) % (2.0 * np.pi))


def resection(problem: ImpactProblem, state: NDArray[np.float64], periods: int, engine: Any = None) -> tuple[ImpactProblem, NDArray[np.float64]]:
    """The same motion seen through a strobe away from its impacts.

    ``state`` is the state at t = 0 of ``problem`` on (or near) an orbit of ``periods`` excitation periods, e.g. the
    end of a brute-force run. The motion is integrated over ``periods`` periods; the impact instants modulo T leave
    gaps, and the new strobe goes in the middle of the widest: at tau = g T, i.e. the problem with force phase
    phase + 2 pi g, whose t = 0 is the old t = tau. An :class:`~vibroimpact.orbits.maps.ImpactMap` of that problem has
    the orbit as a fixed point of a map that is smooth near it (no impact crosses its strobe). With bumpers the gaps
    are those the contact intervals leave (from onset to release, modulo T).

    Returns
    -------
    (ImpactProblem, ndarray)
        The problem with the new force phase [rad] (everything else kept), and the state (x, x') at its t = 0.
    """
    engine = engine if engine is not None else make_engine(engine_for(problem.contact_law, "exact_jacobians"))
    state = np.asarray(state, dtype=float)
    gap, run = strobe_gap(problem, state, int(periods), engine)
    if gap is None:
        return problem, state.copy()
    moved = moved_state(problem, state, int(periods), engine, run, gap.shift)
    excitation = dataclasses.replace(problem.harmonic, phase=moved_phase(problem, gap.shift))
    return ImpactProblem(problem.system, problem.contact, excitation), moved
