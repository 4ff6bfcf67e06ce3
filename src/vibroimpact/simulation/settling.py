"""What a slowly settling motion reaches: run it on from a state, in stages, until its strobes repeat, its Lyapunov
exponent and strobes say quasi-periodic or chaotic, or the run's length is spent.

A brute-force point whose strobes nearly repeat (a strictly negative exponent over a few dozen periods, the
period that repeats best: :func:`vibroimpact.simulation.attractors.measure_motion`) may be a periodic orbit still
being approached, a long-period orbit locked on a torus, the torus itself, or a chaotic band. :func:`settle_motion`
tells them apart with the engine's exact Jacobians:

* stages of :data:`STAGE_PERIODS` periods from the state, each starting where the previous ended (a strobe, t = 0 mod
  T, the problem's force phase);
* ``periodic`` as soon as a stage's strobes repeat with a period p <= :data:`LONGEST_PERIOD` to
  :data:`~vibroimpact.simulation.attractors.REPEAT_TOLERANCE` of the motion's length over the whole stage (the least
  such p);
* from the second stage on (the first settles onto the attractor), the Jacobians and strobes of every stage but the
  first classified (:func:`vibroimpact.orbits.motion.classify_motion`): ``quasi_periodic`` and ``chaotic`` are final;
  anything else (an exponent below -``zero_band``: a contraction onto an orbit not reached yet; an exponent within
  its error of neither 0 nor a positive one) runs another stage, the evidence pooled, up to :data:`MAX_STAGES`; then
  ``undecided`` with the classifier's reason.

Why these lengths. A stage of 2000 periods holds a period of up to 500 four times over (:data:`LONGEST_PERIOD`), so
that orbits locked on a torus (measured on the paper's system and its relative stops: least periods 23-121 near the
Neimark-Sacker points at 34-40 Hz) are seen whole; it resolves spectral lines to 1/2000 cycles per period and bounds
the exponent's block error near 0.002 per period, well inside ``zero_band`` (0.01); pooled over 7 stages, 3 times
less, so that an exponent of 0.012 +- 0.004 after 4000 periods (measured near 35 Hz) is decided. 8 stages (16000 periods) let a
contraction five times slower than the brute force's mark of a contracting motion (-0.005 per period), i.e.
-0.001, shrink a mismatch of the motion's whole size to e^-16 ~ 1e-7 of it, below the repeat tolerance. Such a run
costs 0.1-0.5 s per 2000 periods with the compiled exact engine.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.structure import require_in_range
from vibroimpact.orbits.motion import MotionEvidence, MotionThresholds, classify_motion, classify_strobes
from vibroimpact.simulation.attractors import REPEAT_TOLERANCE, repeat_scale

__all__ = ["SETTLED_KINDS", "STAGE_PERIODS", "MAX_STAGES", "LONGEST_PERIOD", "SettledMotion", "repeat_mismatch", "settle_motion"]

#: What :func:`settle_motion` says a motion reached.
SETTLED_KINDS = ("periodic", "quasi_periodic", "chaotic", "undecided")
#: Periods of one stage [-].
STAGE_PERIODS = 2000
#: Most stages run [-] (16000 periods).
MAX_STAGES = 8
#: Longest period the strobes of a stage are compared over [periods] (a quarter of a stage).
LONGEST_PERIOD = STAGE_PERIODS // 4


@dataclass(frozen=True)
class SettledMotion:
    """What a motion run on from a state reached.

    Attributes
    ----------
    kind : str
        One of :data:`SETTLED_KINDS`.
    period : int
        ``periodic``: the least period its strobes repeat with [excitation periods]; 0 otherwise.
    best_period : int
        The period its last stage's strobes repeat best with [excitation periods], <= the longest compared.
    mismatch : float
        How well they repeat with it: the largest difference over the last stage, relative to the motion's length
        (velocities: times w) [-].
    periods : int
        Periods run [-].
    state : ndarray, shape (2N,)
        The end state, at a strobe (t = 0 mod T) [m, m s-1].
    strobes : ndarray, shape (n, 2N)
        The strobes classified (every stage's but the first's) [m, m s-1]; a periodic motion's last stage's.
    evidence : MotionEvidence or None
        The classification of those strobes and their Jacobians (the last before a periodic motion's strobes
        repeated; None where they repeated before any was).
    reason : str
        One sentence: why this kind.
    """

    kind: str
    period: int
    best_period: int
    mismatch: float
    periods: int
    state: NDArray[np.float64]
    strobes: NDArray[np.float64]
    evidence: MotionEvidence | None
    reason: str

    def __post_init__(self) -> None:
        if self.kind not in SETTLED_KINDS:
            raise ValueError(f"kind = {self.kind!r} is not allowed: use one of {SETTLED_KINDS}")
        if self.period < 0 or (self.kind == "periodic") != (self.period > 0):
            raise ValueError(f"period = {self.period}: a periodic motion has one (>= 1), any other none (0)")
        for name in ("state", "strobes"):
            getattr(self, name).setflags(write=False)

    @property
    def exponent(self) -> float:
        """The last classified stage's largest Lyapunov exponent [1/period] (NaN where none was estimated)."""
        return self.evidence.lyapunov_exponent if self.evidence is not None else float("nan")

    @property
    def exponent_error(self) -> float:
        """Its standard error [1/period] (NaN where none was estimated)."""
        return self.evidence.lyapunov_error if self.evidence is not None else float("nan")


def repeat_mismatch(strobes: NDArray[np.float64], scale: NDArray[np.float64], longest: int) -> NDArray[np.float64]:
    """max_k |y_{k+p} - y_k| / scale over the strobes for p = 1 ... ``longest`` (inf where fewer than 2p + 1 strobes).

    Parameters
    ----------
    strobes : ndarray, shape (n, 2N)
        Consecutive strobes [m, m s-1].
    scale : ndarray, shape (2N,)
        The motion's scales [m, m s-1] (:func:`~vibroimpact.simulation.attractors.repeat_scale`).
    longest : int
        Longest period compared [periods].
    """
    n = strobes.shape[0]
    return np.array([float(np.max(np.abs(strobes[p:] - strobes[:-p]) / scale)) if n > 2 * p else np.inf for p in range(1, longest + 1)])


def settle_motion(
    engine: Any, problem: ImpactProblem, state: NDArray[np.float64], stage: int = STAGE_PERIODS, stages: int = MAX_STAGES, thresholds: MotionThresholds = MotionThresholds(),
) -> SettledMotion:  # fmt: skip
    """Run the motion from ``state`` on in stages and say what it reaches (module docstring).

    Parameters
    ----------
    engine : object
        A built engine with exact Jacobians for the problem's contact law (``integrate(..., jacobians=True)``).
    problem : ImpactProblem
        The problem, at its frequency; ``state`` is at its t = 0.
    state : ndarray, shape (2N,)
        The start (x, x') [m, m s-1], e.g. a brute-force point's end state.
    stage : int
        Periods per stage (>= 64: the classifier's least).
    stages : int
        Most stages (>= 2).
    thresholds : MotionThresholds
        Of the classification; its ``zero_band`` also marks a stage as still contracting.

    Returns
    -------
    SettledMotion

    Raises
    ------
    RuntimeError
        Where the engine made no progress (endless chattering): no motion to say anything of.
    """
    require_in_range("stage", stage, 64, 1e7)
    require_in_range("stages", stages, 2, 1e4)
    scale = repeat_scale(problem)
    longest = max(1, stage // 4)
    y = np.array(state, dtype=float)
    evidence: MotionEvidence | None = None
    kept: list[tuple[NDArray[np.float64], NDArray[np.float64]]] = []  # (Jacobians, strobes) of every stage after the first
    for done in range(1, stages + 1):
        run = engine.integrate(problem, y, 0.0, stage, jacobians=True)
        strobes = np.array(run.strobe_states)
        y = strobes[-1].copy()
        mismatch = repeat_mismatch(strobes, scale, longest)
        best = int(np.argmin(mismatch)) + 1
        repeats = np.flatnonzero(mismatch < REPEAT_TOLERANCE)
        if repeats.size:
            period = int(repeats[0]) + 1
            return SettledMotion("periodic", period, best, float(mismatch[period - 1]), done * stage, y, strobes, evidence,
                                 f"its strobes repeat with period {period} to {mismatch[period - 1]:.1e} of the motion's size over periods {(done - 1) * stage}-{done * stage}")  # fmt: skip
        if done == 1:
            continue  # the first stage settles onto the attractor
        kept.append((np.array(run.strobe_jacobians), strobes[1:]))
        jacobians, pooled = np.concatenate([j for j, _ in kept]), np.concatenate([s for _, s in kept])
        finite = jacobians.shape[0] == pooled.shape[0] and bool(np.all(np.isfinite(jacobians)))
        evidence = classify_motion(jacobians, pooled, thresholds) if finite else classify_strobes(pooled, thresholds=thresholds)
        if evidence.kind != "irregular":
            return SettledMotion(evidence.kind, 0, best, float(mismatch[best - 1]), done * stage, y, pooled, evidence, f"over periods {stage}-{done * stage}: {evidence.reason}")
    assert evidence is not None
    return SettledMotion("undecided", 0, best, float(mismatch[best - 1]), done * stage, y, pooled, evidence,
                         f"over periods {stage}-{done * stage}: {evidence.reason}; its strobes repeat best with period {best}, to {mismatch[best - 1]:.2g} of the motion's size")  # fmt: skip
