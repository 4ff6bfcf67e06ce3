"""Every motion that settles at one frequency, and the largest: basin sampling at a point such as an absorber's
operating frequency (:func:`point_motions`).

An absorber's notch is a promise about every motion the structure can settle on at its tuning frequency, not about
the contact-free one alone: on the paper's absorber with Delta = 2.3596 mm and R = 0.1893, at 33 Hz the contact-free
notch (|X1| = 8.97 um) coexists with a stable period-4 motion with one impact every four periods, |X1| = 0.776 mm,
reached from rest and from nearly every other start (tests/simulation/test_point_motions.py).

Runs start from the contact-free linear state, from rest, and from seeded random states whose size is spread
log-uniformly from 5 % to twice the motion's length (the clearance plus the absorber's linear stroke,
:meth:`~vibroimpact.model.problem.ImpactProblem.length_scale`), so that both small motions about the notch and large
impacting ones are entered. Each run drops ``transient`` periods and measures ``strobes``
(:func:`~vibroimpact.simulation.attractors.measure_motions`: one compiled call for an engine that batches). The runs are grouped into distinct motions (kind,
period k, impacts per k periods, and size); a periodic motion with impacts is then shot (``shoot_orbits``): its
orbit solved by Newton's method from the run's end state and measured over its k periods exactly, not over the last
sampled periods. A motion's value is its largest one-period ``measure`` over its k periods (the largest per-period
fundamental); a non-periodic motion's is the largest over the measured periods, a sample that can only grow with
more periods, so its convergence (the largest over the first half of the periods against all of them) is kept.

What it can miss: a motion whose basin no start enters (the share of starts that reach each motion says how large
the basins found are), and one that settles more slowly than ``transient`` periods.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from vibroimpact.analysis.measures import Measure, as_measure
from vibroimpact.engines.registry import engine_for
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.orbits.maps import ImpactMap
from vibroimpact.orbits.shooting import ShootingError, shoot
from vibroimpact.simulation.attractors import MOTION_CLASSES, at_frequency, measure_motions
from vibroimpact.simulation.band_attractors import pulled_inside
from vibroimpact.simulation.harmonics import linear_state, resting_state
from vibroimpact.simulation.history import engine_of

__all__ = ["PointMotion", "PointMotions", "point_motions", "point_starts", "SAME_SIZE", "SMALLEST_START"]

#: Two runs of the same kind, period and impacts are one motion where their values differ by less than this [-].
SAME_SIZE = 1e-4
#: The smallest random start, a share of the motion's length [-] (the largest: twice it).
SMALLEST_START = 0.05


@dataclass(frozen=True)
class PointMotion:
    """One distinct motion the runs settled on.

    Attributes
    ----------
    value : float
        Its measure [m or N]: the largest one-period value over its k periods (periodic), the closed form's
        (contact-free), the largest over the measured periods (non-periodic).
    regime : str
        Its :data:`~vibroimpact.simulation.attractors.MOTION_CLASSES` name.
    period : int
        k [excitation periods] (0: the strobes do not repeat).
    impacts : float
        Impacts per k periods (a whole number); where not periodic, per period, the mean over the measured periods.
    starts : int
        Runs that settled on it.
    from_rest, from_linear : bool
        Whether the run from rest, from the contact-free linear state, is among them.
    exact : bool
        Its value is the shot orbit's (periodic with impacts, Newton converged), not the run's last periods.
    converged : float
        Non-periodic: the relative rise of its largest value from the first half of the measured periods to all of
        them [-] (0: periodic).
    state : tuple of float
        A strobe of it (t = 0 mod T) [m, m s-1].
    """

    value: float
    regime: str
    period: int
    impacts: float
    starts: int
    from_rest: bool
    from_linear: bool
    exact: bool = False
    converged: float = 0.0
    state: tuple[float, ...] = ()

    def text(self) -> str:
        """``a period-4 motion, 1 impact per 4 periods``, ``the contact-free motion``, ``a chaotic motion, 2.3
        impacts per period``."""
        if self.regime == "linear":
            return "the contact-free motion"
        if self.period:
            per = "per period" if self.period == 1 else f"per {self.period} periods"
            count = int(round(self.impacts))
            return f"a period-{self.period} motion, {count} impact{'s' if count != 1 else ''} {per}"
        kind = self.regime.replace("_", "-")
        return f"{'an' if kind[0] in 'aeiou' else 'a'} {kind} (non-periodic) motion, {self.impacts:.2g} impacts per period on average"


@dataclass(frozen=True)
class PointMotions:
    """What the runs at one frequency settled on (:func:`point_motions`).

    Attributes
    ----------
    frequency : float
        [Hz].
    runs : int
        Starts run (rest and the linear state included); runs the engine could not finish count in none.
    motions : tuple of PointMotion
        The distinct motions, largest first.
    transient, strobes : int
        Periods dropped, then measured, per run.
    """

    frequency: float
    runs: int
    motions: tuple[PointMotion, ...]
    transient: int
    strobes: int

    @property
    def largest(self) -> PointMotion | None:
        """The motion with the largest value (None: no run settled)."""
        return self.motions[0] if self.motions else None

    @property
    def value(self) -> float:
        """The largest value over every motion [m or N] (NaN: none)."""
        return self.motions[0].value if self.motions else math.nan

    def share_text(self, motion: PointMotion) -> str:
        """``reached from rest and from 200 of 201 other starts``, ``reached from 1 of 64 starts, not from rest``."""
        if motion.from_rest:
            return f"reached from rest and from {motion.starts - 1} of {self.runs - 1} other starts"
        return f"reached from {motion.starts} of {self.runs} starts, not from rest"


def point_starts(problem: ImpactProblem, starts: int, seed: int) -> list[tuple[str, NDArray[np.float64]]]:
    """``starts`` (>= 2) initial states at t = 0 [m, m s-1] strictly inside every stop: the contact-free linear
    state, rest on the stops, then random ones (seeded) about rest of size log-uniform in
    [:data:`SMALLEST_START`, 2] times the motion's length, each coordinate and each velocity (times w) uniform in
    +- that size."""
    if starts < 2:
        raise ValueError(f"starts = {starts!r}: at least 2 (the linear state and rest)")
    rest = resting_state(problem)
    size, length = problem.size, problem.length_scale()
    rng = np.random.default_rng(seed)
    found = [("linear", pulled_inside(problem, rest, linear_state(problem).state(problem.omega))), ("rest", rest.copy())]
    for i in range(starts - 2):
        spread = length * math.exp(rng.uniform(math.log(SMALLEST_START), math.log(2.0)))
        state = rest + np.concatenate([spread * rng.uniform(-1.0, 1.0, size), problem.omega * spread * rng.uniform(-1.0, 1.0, size)])
        found.append((f"random {i + 1}", pulled_inside(problem, rest, state)))
    return found


def point_motions(
    problem: ImpactProblem, frequency: float, measure: int | Measure = 0, starts: int = 12, transient: int = 300, strobes: int = 64, seed: int = 0,
    shoot_orbits: bool = False, engine: Any = None,
) -> PointMotions:  # fmt: skip
    """Every motion ``starts`` runs settle on at ``frequency`` [Hz], grouped, largest first (module docstring).

    Parameters
    ----------
    problem : ImpactProblem
        Structure, stops and harmonic load; its frequency is replaced.
    frequency : float
        [Hz].
    measure : int or Measure
        What each motion is judged by (a coordinate index: its |X|).
    starts : int
        Runs (>= 2): the linear state, rest, then seeded random states (:func:`point_starts`).
    transient, strobes : int
        Periods dropped, then measured (strobes >= 16).
    seed : int
        Of the random starts.
    shoot_orbits : bool
        Shoot every periodic motion with impacts and measure its orbit exactly.
    engine : str or engine, optional
        By default the registry's engine with exact Jacobians for the contact law.
    """
    if not frequency > 0.0 or transient < 0 or strobes < 16:
        raise ValueError(f"frequency = {frequency!r} [Hz], transient = {transient!r}, strobes = {strobes!r}: expected a positive frequency, no negative transient, at least 16 strobes")
    measure = as_measure(measure, problem)
    engine = engine_of(engine_for(problem.contact_law, "exact_jacobians") if engine is None else engine)
    moved = at_frequency(problem, float(frequency))
    begun = point_starts(moved, starts, seed)
    rows = measure_motions(engine, [moved], [0] * len(begun), [start for _label, start in begun], transient, strobes, measure)  # regime -1: no progress
    linear = linear_state(moved)
    free = measure.of_state(moved, linear.amplitudes) if linear.fits(moved) else math.nan  # an undamped free mass's too (:func:`_run`)
    found: list[dict[str, Any]] = []
    for k, (label, _start) in enumerate(begun):
        run = _run(rows, k, strobes, free)
        if run is None:
            continue
        same = next((m for m in found if m["key"] == run["key"] and abs(m["value"] - run["value"]) <= SAME_SIZE * max(m["value"], run["value"])), None)
        if same is None:
            same = run | {"starts": 0, "from_rest": False, "from_linear": False}
            found.append(same)
        elif run["value"] > same["value"]:
            same.update(value=run["value"], converged=run["converged"])
        same["starts"] += 1
        same["from_rest"] |= label == "rest"
        same["from_linear"] |= label == "linear"
    motions = [_shot(moved, engine, m, measure) if shoot_orbits else _motion(m) for m in found]
    motions.sort(key=lambda m: -m.value)
    return PointMotions(float(frequency), len(begun), tuple(motions), transient, strobes)


def _run(rows: dict[str, NDArray[Any]], k: int, strobes: int, free: float) -> dict[str, Any] | None:
    """Run ``k``'s motion: its grouping key (kind, period, impacts), value, convergence and end state; None where the
    engine failed or a contact-free run is no attractor (its linear state crosses a stop). A contact-free run counts
    with the closed form ``free``, an undamped free mass's too: no attractor (a push makes it drift, see
    :func:`~vibroimpact.analysis.linear.contact_free_is_stable`), but a motion that lasts while nothing disturbs it."""
    regime = int(rows["regime"][k])
    if regime < 0:
        return None
    period = int(rows["period"][k])
    per_period = np.asarray(rows["amplitude"][k], dtype=float)
    converged = 0.0
    if regime == 0:
        if not math.isfinite(free):
            return None
        value, impacts = free, 0
    elif period:
        value = float(np.max(per_period[-period:]))
        impacts = int(round(float(rows["impacts"][k]) * period))
    else:
        value = float(np.max(per_period))
        half = float(np.max(per_period[: strobes // 2]))
        converged = (value - half) / value if value > 0.0 else 0.0
        impacts = float(rows["impacts"][k])
    return {"key": (regime, period, impacts), "value": value, "regime": MOTION_CLASSES[regime], "period": period, "impacts": impacts, "converged": converged,
            "state": tuple(float(x) for x in rows["state"][k])}  # fmt: skip


def _motion(found: dict[str, Any], value: float | None = None, exact: bool = False, state: tuple[float, ...] | None = None) -> PointMotion:
    """The :class:`PointMotion` of a group of runs."""
    return PointMotion(found["value"] if value is None else value, found["regime"], found["period"], found["impacts"], found["starts"], found["from_rest"], found["from_linear"],
                       exact, found["converged"], found["state"] if state is None else state)  # fmt: skip


def _shot(problem: ImpactProblem, engine: Any, found: dict[str, Any], measure: Measure) -> PointMotion:
    """A periodic motion with impacts shot (its k-period orbit by Newton from the run's end state, stable) and
    measured over its k periods from the orbit's state; the runs' value where shooting fails or the orbit found is
    unstable (then it is not the attractor the runs settled on)."""
    if not found["period"] or found["regime"] == "linear":
        return _motion(found)
    system = ImpactMap(problem, periods=found["period"])
    try:
        orbit = shoot(system, np.array(found["state"]), system.parameters)
    except (ShootingError, ValueError, RuntimeError):
        return _motion(found)
    if not orbit.stable:
        return _motion(found)
    try:
        run = engine.integrate(problem, orbit.state, 0.0, found["period"], moments=True)
    except RuntimeError:  # the engine made no progress from the shot state: keep the runs' value
        return _motion(found)
    n, m = problem.size, len(problem.stops)
    per_period = measure.of_harmonics(problem, problem.omega, run.moments[:, :n], run.moments[:, n : n + m]) * 2.0 / problem.period
    value = float(np.max(per_period))
    if abs(value - found["value"]) > 1e-3 * max(value, found["value"]):  # another orbit than the runs' (they had settled)
        return _motion(found)
    # the orbit's value, exact; never below what the runs showed (their last periods are at most the shooting
    # tolerance away)
    return _motion(found, max(value, found["value"]), True, tuple(float(x) for x in orbit.state))
