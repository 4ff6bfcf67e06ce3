"""The design search: every candidate evaluated through the runner, kept in order, scored on its worst case.

:class:`Evaluations` sends candidates to :meth:`vibroimpact.runs.runner.Runner.map` as
:class:`~vibroimpact.kinds.design.evaluate.DesignCase` (so they spread over local cores or a dask cluster, and a
rerun takes every finished one from the store), keeps each with the stage that asked for it, and scores it:

* a sample's value is the larger of the worst stable closed-form motion and, where the band is not covered by one,
  the guess at the motion there (:class:`~vibroimpact.analysis.band_worst.BandWorst`);
* the design's objective is the ``quantile`` of its samples' values (1: the worst), likewise its operating |X|;
* its score is the objective, raised by 10 times the relative excess of the operating |X| over its limit (a design
  that destroys the notch is never the best feasible one), and infinite where a sample has no value.

:func:`differential_evolution` is scipy's, vectorised: each generation's population is one batch of cases.
:func:`nelder_mead_polish` then refines the best point with a bounded simplex search. :func:`grid_search` evaluates
a full grid.
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import optimize

from vibroimpact.kinds.design.evaluate import DesignCase, DesignSpace, sample_chunks
from vibroimpact.kinds.design.quantity import quantity
from vibroimpact.runs.runner import CaseResult, Runner

__all__ = ["pareto_front", "STAGES", "WHOLE_CANDIDATES", "Evaluations", "differential_evolution", "nelder_mead_polish", "grid_search", "PENALTY", "POLISH_STEP", "POLISH_END"]

#: Why a candidate was evaluated (CF flag values of ``evaluation_stage``).
STAGES = ("global", "polish", "grid", "reference")
#: Score raised by this times the relative excess of the operating |X| over its limit [-].
PENALTY = 10.0
#: A batch of at least this many candidates sends each whole to a worker (one case, all its samples); a smaller batch
#: (a polish step, the scene's own design) splits each candidate's samples over a few cases, so that the workers share
#: even one candidate. Depends on the batch alone: a rerun asks for the same cases whatever the workers.
WHOLE_CANDIDATES = 8
#: The polish reports how far it got every this many evaluations.
POLISH_REPORT = 10
#: The polish's first simplex and its last, shares of each variable's range [-].
POLISH_STEP = 0.05
POLISH_END = 1e-6


@dataclass
class Evaluations:
    """Every candidate evaluated so far, in order, with its stage and scores (module docstring).

    Attributes
    ----------
    space : DesignSpace
    bounds : ndarray, shape (n, 2)
        Each variable's [low, high].
    runner : Runner
    quantile : float
        Of the samples' values (1: the worst).
    limit : float
        Largest operating |X| [m] (NaN: no constraint).
    corners : int
        Samples 1 ... ``corners`` are the tolerance box's corners: in the worst case (quantile 1), not in a quantile's
        statistics.
    """

    space: DesignSpace
    bounds: NDArray[np.float64]
    runner: Runner
    quantile: float = 1.0
    limit: float = math.nan
    corners: int = 0
    designs: list[NDArray[np.float64]] = field(default_factory=list)
    stages: list[int] = field(default_factory=list)
    results: list[CaseResult] = field(default_factory=list)
    scores: list[float] = field(default_factory=list)

    def evaluate(self, designs: NDArray[np.float64], stage: str, quiet: bool = False, verb: str = "simulating") -> NDArray[np.float64]:
        """The scores of ``designs`` (shape (m, n), in the variables' units), each kept; ``quiet``: without the
        runner's progress bar (a polish step of a second or two; the polish says how it goes); ``verb`` leads the bar
        (which generation it is)."""
        designs = np.atleast_2d(np.asarray(designs, dtype=float))
        whole = designs.shape[0] >= WHOLE_CANDIDATES
        chunks = [tuple(range(self.space.samples))] if whole else sample_chunks(self.space.samples)
        shown = self.runner.progress
        self.runner.progress = shown and not quiet
        try:
            parts = self.runner.map([DesignCase(self.space, tuple(float(v) for v in x), chunk) for x in designs for chunk in chunks], verb)
        finally:
            self.runner.progress = shown
        results = [{k: np.concatenate([np.atleast_1d(p[k]) for p in parts[i * len(chunks) : (i + 1) * len(chunks)]]) for k in parts[0]} for i in range(len(designs))]
        scores = np.array([self.score(result) for result in results])
        for x, result, value in zip(designs, results, scores):
            self.designs.append(x.copy())
            self.stages.append(STAGES.index(stage))
            self.results.append(result)
            self.scores.append(float(value))
        return scores

    def values(self, result: CaseResult) -> NDArray[np.float64]:
        """Each sample's value [m]: the worst closed-form motion, or the guess where the band is uncovered."""
        return np.fmax(np.asarray(result["worst"], dtype=float), np.where(np.asarray(result["uncovered"]) > 0.0, result["estimate"], np.nan))

    def over_samples(self, values: NDArray[np.float64]) -> float:
        """The ``quantile`` of per-sample ``values`` (1: the largest over every sample, the box's corners included;
        below 1: over the nominal design and the random samples alone); NaN where one has no value."""
        values = np.asarray(values, dtype=float)
        if not np.all(np.isfinite(values)):
            return math.nan
        if self.quantile >= 1.0:
            return float(np.max(values))
        statistics = np.delete(values, np.arange(1, 1 + self.corners)) if values.size > 1 + self.corners else values
        return float(np.quantile(statistics, self.quantile, method="higher"))

    def objective(self, result: CaseResult) -> float:
        """The samples' ``quantile`` [m] (:meth:`over_samples`; NaN where a sample has no value)."""
        return self.over_samples(self.values(result))

    def operating(self, result: CaseResult) -> float:
        """The operating value over the samples, the same rule [m] (NaN: no constraint)."""
        return self.over_samples(result["operating"]) if math.isfinite(self.limit) else math.nan

    def penalised(self, objective: float, operating: float) -> float:
        """The score of an ``objective`` with its ``operating`` value: the objective raised by :data:`PENALTY` times
        the relative excess over the limit; inf where either has no value."""
        if not math.isfinite(objective):
            return math.inf
        if not math.isfinite(self.limit):
            return objective
        return objective * (1.0 + PENALTY * max(0.0, operating / self.limit - 1.0)) if math.isfinite(operating) else math.inf

    def score(self, result: CaseResult) -> float:
        """The objective with the operating constraint's penalty; inf where a sample has no value."""
        return self.penalised(self.objective(result), self.operating(result))

    def feasible(self, result: CaseResult) -> bool:
        """The operating constraint holds (always, without one)."""
        return not math.isfinite(self.limit) or self.operating(result) <= self.limit

    def best_text(self) -> str:
        """How the best candidate so far stands, for the console: ``best worst case 3.036 mm, the constraint kept``;
        a penalised score is never written as a length."""
        result = self.results[self.best()]
        shown = quantity(self.space.objective.name)
        kept = "" if not math.isfinite(self.limit) else (", the constraint kept" if self.feasible(result) else f", the constraint broken ({quantity(self.space.constraint.name).text(self.operating(result))} against {quantity(self.space.constraint.name).text(self.limit)})")
        return f"best worst case {shown.text(self.objective(result))}{kept}"

    def best(self) -> int:
        """Index of the best evaluation (least score)."""
        return int(np.argmin(self.scores))

    def scaled(self, unit: NDArray[np.float64]) -> NDArray[np.float64]:
        """Points of the unit cube (shape (..., n)) in the variables' units."""
        low, high = self.bounds[:, 0], self.bounds[:, 1]
        return low + np.clip(unit, 0.0, 1.0) * (high - low)


def differential_evolution(evaluations: Evaluations, population: int, generations: int, seed: int) -> None:
    """scipy's differential evolution on the unit cube, each generation one batch (``population`` members per
    variable, Latin-hypercube start, seeded: a rerun asks for the same candidates and the store answers)."""
    n = evaluations.bounds.shape[0]
    done = [0]

    def batch(unit: NDArray[np.float64]) -> NDArray[np.float64]:
        which = "the first population" if done[0] == 0 else f"generation {done[0]} of at most {generations}"
        done[0] += 1
        return evaluations.evaluate(evaluations.scaled(np.asarray(unit).T), "global", verb=f"design: {which}")

    optimize.differential_evolution(batch, [(0.0, 1.0)] * n, popsize=population, maxiter=generations, seed=seed, polish=False, vectorized=True,
                                    updating="deferred", init="latinhypercube", tol=1e-6, atol=0.0)  # fmt: skip


def nelder_mead_polish(evaluations: Evaluations, budget: int, say: Callable[[str], None] | None = None) -> None:
    """Nelder-Mead from the best design so far, in the unit cube (bounded), its first simplex :data:`POLISH_STEP` of
    each range wide, until the simplex is :data:`POLISH_END` of each range or ``budget`` evaluations are spent: a
    local search that needs no gradient (the objective is a maximum of peaks, not smooth; on an equal-peak ridge a
    search along the axes stalls where the simplex turns along the ridge). One candidate at a time: its samples are
    what the workers share (:class:`~vibroimpact.kinds.design.evaluate.DesignCase` chunks); ``say`` hears how far
    it got every :data:`POLISH_REPORT` evaluations."""
    span = evaluations.bounds[:, 1] - evaluations.bounds[:, 0]
    centre = (evaluations.designs[evaluations.best()] - evaluations.bounds[:, 0]) / span
    n = centre.size
    simplex = np.vstack([centre, centre + POLISH_STEP * np.eye(n) * np.where(centre + POLISH_STEP <= 1.0, 1.0, -1.0)[:, None]])
    scale = max(abs(evaluations.scores[evaluations.best()]), 1e-300)

    done, started = [0], time.perf_counter()

    def one(unit: NDArray[np.float64]) -> float:
        value = float(evaluations.evaluate(evaluations.scaled(np.asarray(unit)[None, :]), "polish", quiet=say is not None)[0]) / scale
        done[0] += 1
        if say is not None and (done[0] % POLISH_REPORT == 0 or done[0] == budget):
            say(f"design: polish {done[0]}/{budget} evaluations, {time.perf_counter() - started:.0f} s; {evaluations.best_text()}")
        return value

    optimize.minimize(one, centre, method="Nelder-Mead", bounds=[(0.0, 1.0)] * n,
                      options={"initial_simplex": np.clip(simplex, 0.0, 1.0), "xatol": POLISH_END, "fatol": 1e-10, "maxfev": budget})  # fmt: skip


def grid_search(evaluations: Evaluations, points: int) -> None:
    """Every point of a grid of ``points`` per variable, bounds included (one batch)."""
    axes = [np.linspace(0.0, 1.0, points)] * evaluations.bounds.shape[0]
    unit = np.array(list(itertools.product(*axes)))
    evaluations.evaluate(evaluations.scaled(unit), "grid", verb=f"design: a grid of {len(unit)} points")


def pareto_front(objective: ArrayLike, impulse: ArrayLike, feasible: ArrayLike) -> NDArray[np.bool_]:
    """Whether each candidate is on the front: feasible, both values finite, and no other such candidate at most as
    large in both and smaller in one (equal pairs are all on it).

    Parameters
    ----------
    objective, impulse : array_like, shape (E,)
        The worst |X| [m] and the worst impulse of one impact [N s] of each candidate.
    feasible : array_like of bool, shape (E,)
        The operating constraint holds.
    """
    x, y = np.asarray(objective, dtype=float), np.asarray(impulse, dtype=float)
    ok = np.asarray(feasible, dtype=bool) & np.isfinite(x) & np.isfinite(y)
    front = np.zeros(x.size, dtype=bool)
    index = np.flatnonzero(ok)
    for i in index:
        others = index[index != i]
        dominated = (x[others] <= x[i]) & (y[others] <= y[i]) & ((x[others] < x[i]) | (y[others] < y[i]))
        front[i] = not np.any(dominated)
    return front
