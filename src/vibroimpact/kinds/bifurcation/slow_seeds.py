"""Brute-force seeds that settle slowly: what the motion from a seed reaches when shooting from it does not converge.

A seed (:class:`~vibroimpact.kinds.bifurcation.cases.Seed`) is a brute-force point whose strobes repeat, or nearly
repeat while contracting; shooting from one whose strobes repeated only to 4e-4 ... 0.6 of the motion's size (a
motion still settling near a torus) does not converge. :func:`settle_seed` runs the motion on from the seed's state
(:func:`vibroimpact.simulation.settling.settle_motion`: up to 16000 periods, in stages of 2000) and says what it
reached (:data:`SEED_OUTCOMES`):

* ``periodic``: its strobes repeat, with a period up to 500 (longer than the sweeps' 32: an orbit locked on a torus)
  or after more periods; the orbit is shot through a strobe clear of its impacts and continued like any seed's
  (:func:`continue_seed_orbit`), or found on a known branch;
* ``quasi_periodic``: a motion on a torus, with its rotation number and the Neimark-Sacker point it comes from. The
  torus born at a Neimark-Sacker point of a period-k orbit is k closed curves the strobes visit in turn, each
  invariant under the k-period map (:func:`on_islands`); the rotation number is that of every k-th
  strobe around their centroid, and the point it comes from the Neimark-Sacker point it comes from the nearest by frequency of a
  continued branch's that the torus fits and that can give birth to an attracting torus (:func:`torus_origin`),
  whose critical multipliers' angle / 2 pi it is compared with;
* ``chaotic``: a Lyapunov exponent positive beyond its error;
* ``undecided``: what the evidence was;
* ``failed``: the engine failed running it on (an error, said as a failure).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from vibroimpact.kinds.bifurcation.branches import OrbitSet
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.orbits.branch import SPECIAL_POINT_KINDS
from vibroimpact.orbits.continuation import ContinuationSettings, continue_branch
from vibroimpact.orbits.maps import ImpactMap, resection
from vibroimpact.orbits.motion import rotation_number
from vibroimpact.orbits.orbit_measures import orbit_measures
from vibroimpact.orbits.shooting import ShootingError, shoot
from vibroimpact.simulation.attractors import MAX_PERIOD
from vibroimpact.simulation.settling import SettledMotion, settle_motion

__all__ = ["SEED_OUTCOMES", "SeedOutcome", "settle_seed", "continue_seed_orbit", "neimark_sacker_angle", "on_islands", "attracting_side", "torus_origin", "torus_rotation", "ISLAND_SPREAD", "NEXT_TO", "SLOW_SEED_FIELDS", "slow_seed_arrays"]

#: What a seed that shooting did not converge from reached (CF flags of ``slow_seed_outcome``, values 0 ...).
SEED_OUTCOMES = ("failed", "periodic", "quasi_periodic", "chaotic", "undecided")


@dataclass(frozen=True)
class SeedOutcome:
    """What the motion from a slowly settling seed reached.

    Attributes
    ----------
    frequency : float
        The seed's frequency [Hz].
    sweep_period : int
        The period its sweep's strobes repeated best with [excitation periods].
    outcome : str
        One of :data:`SEED_OUTCOMES`.
    periods_run : int
        Periods the motion was run on for [-] (0: the engine failed at once).
    orbit_period : int
        ``periodic``: the orbit's least period [excitation periods]; else 0.
    lyapunov_exponent, lyapunov_error : float
        The largest exponent of the last stage run and its standard error [1/period] (NaN: none estimated).
    rotation_number : float
        ``quasi_periodic``: the rotation number of the strobes of every ``rotation_period``-th period around their
        centroid [cycles per ``rotation_period`` periods], in [0, 1/2]; else NaN.
    rotation_period : int
        The map whose rotation is measured, in excitation periods: the number of closed curves the torus's strobes
        visit in turn, the period of the orbit of the Neimark-Sacker point it comes from (:func:`torus_origin`); 0
        where none was measured.
    ns_frequency : float
        ``quasi_periodic``: the Neimark-Sacker point it comes from (:func:`torus_origin`) [Hz]; NaN where no branch
        has one.
    ns_angle : float
        Its critical multipliers' angle / 2 pi [-], in [0, 1/2]; NaN where there is none.
    branch : int
        The branch its periodic orbit was continued as or lies on (the case's label; -1: none).
    text : str
        What it reached, in words (one line, naming the seed).
    """

    frequency: float
    sweep_period: int
    outcome: str
    periods_run: int = 0
    orbit_period: int = 0
    lyapunov_exponent: float = math.nan
    lyapunov_error: float = math.nan
    rotation_number: float = math.nan
    rotation_period: int = 0
    ns_frequency: float = math.nan
    ns_angle: float = math.nan
    branch: int = -1
    text: str = ""

    def __post_init__(self) -> None:
        if self.outcome not in SEED_OUTCOMES:
            raise ValueError(f"outcome = {self.outcome!r} is not allowed: use one of {SEED_OUTCOMES}")
        if self.periods_run < 0 or self.orbit_period < 0 or self.rotation_period < 0 or self.branch < -1:
            raise ValueError(f"periods_run, orbit_period, rotation_period >= 0 and branch >= -1: got {self.periods_run}, {self.orbit_period}, {self.rotation_period}, {self.branch}")
        if (self.outcome == "periodic") != (self.orbit_period > 0):
            raise ValueError(f"orbit_period = {self.orbit_period}: a periodic outcome has one (>= 1), any other none (0)")
        if not (math.isnan(self.rotation_number) or 0.0 <= self.rotation_number <= 0.5):
            raise ValueError(f"rotation_number = {self.rotation_number!r} is out of range: allowed [0, 0.5] or NaN")


def neimark_sacker_angle(multipliers: np.ndarray) -> float:
    """The angle / 2 pi [-] in [0, 1/2] of the complex multiplier pair nearest the unit circle (NaN: no complex pair)."""
    mu = np.asarray(multipliers, dtype=complex)
    pair = mu[np.abs(mu.imag) > 1e-9 * np.maximum(np.abs(mu), 1e-300)]
    if pair.size == 0:
        return math.nan
    critical = pair[int(np.argmin(np.abs(np.abs(pair) - 1.0)))]
    return abs(math.atan2(critical.imag, critical.real)) / (2.0 * math.pi)


#: A torus's strobes lie on k closed curves visited in turn when every k-th strobe stays within this share of the
#: spread of all of them around their centroid [-] (:func:`on_islands`).
ISLAND_SPREAD = 0.5
#: Fewest strobes per curve for a rotation number [-] (:func:`~vibroimpact.orbits.motion.MotionThresholds`'
#: ``min_periods``).
ROTATION_STROBES = 64


def on_islands(strobes: np.ndarray, k: int) -> bool:
    """Do a torus's strobes lie on k closed curves visited in turn (k >= 2, with at least :data:`ROTATION_STROBES`
    strobes each)? Each sequence of every k-th strobe stays within :data:`ISLAND_SPREAD` of the spread of all of them,
    around its own centroid (in units of each component's standard deviation). A torus born at a Neimark-Sacker
    point of a period-k orbit is k such curves, each invariant under the k-period map; over a finite run a torus whose
    rotation number is near j/k looks alike, which is why only the periods of Neimark-Sacker points are tried
    (:func:`torus_origin`)."""
    z = np.asarray(strobes, dtype=float)
    if k < 2 or z.shape[0] // k < ROTATION_STROBES:
        return False
    spread = z.std(axis=0)
    z = (z - z.mean(axis=0)) / np.where(spread > 0.0, spread, 1.0)
    whole = float(np.mean(np.linalg.norm(z, axis=1)))
    return max(float(np.mean(np.linalg.norm(z[j::k] - z[j::k].mean(axis=0), axis=1))) for j in range(k)) < ISLAND_SPREAD * whole


def attracting_side(multipliers: np.ndarray) -> bool:
    """Are the multipliers but the critical complex pair (:func:`neimark_sacker_angle`) inside the unit circle, so
    that the torus born at this Neimark-Sacker point can attract?"""
    mu = np.asarray(multipliers, dtype=complex)
    complex_ = np.flatnonzero(np.abs(mu.imag) > 1e-9 * np.maximum(np.abs(mu), 1e-300))
    if complex_.size < 2:
        return False
    critical = complex_[np.argsort(np.abs(np.abs(mu[complex_]) - 1.0), kind="stable")[:2]]
    return bool(np.all(np.abs(np.delete(mu, critical)) < 1.0))


def torus_origin(found: OrbitSet, frequency: float, strobes: np.ndarray) -> tuple[dict | None, int, bool]:
    """The Neimark-Sacker point a torus at ``frequency`` [Hz] with these strobes comes from: the nearest by frequency
    of those the torus fits (period 1, or a period-k orbit's point where its strobes lie on k closed curves,
    :func:`on_islands`) whose other multipliers are inside the unit circle (:func:`attracting_side`); the nearest the
    torus fits where none is. Returns its record (None: no branch has a point it fits), the k of the map whose
    rotation is measured, and whether that point's other multipliers are inside."""
    kind = SPECIAL_POINT_KINDS.index("neimark_sacker")
    points = sorted((point for point in found.specials if point["kind"] == kind), key=lambda point: abs(point["frequency"] - frequency))
    fitting = [point for point in points if int(point["period"]) == 1 or on_islands(strobes, int(point["period"]))]
    for point in fitting:
        if attracting_side(point["multipliers"]):
            return point, int(point["period"]), True
    return (fitting[0], int(fitting[0]["period"]), False) if fitting else (None, 1, False)


def torus_rotation(strobes: np.ndarray, period: int) -> float:
    """The rotation number [cycles per ``period`` periods] of every ``period``-th strobe around their centroid
    (:func:`~vibroimpact.orbits.motion.rotation_number`), in [0, 1/2]."""
    return rotation_number(strobes[:: max(1, int(period))]).rotation_number


def settle_seed(
    found: OrbitSet, problem: ImpactProblem, frequency: float, sweep_period: int, state: np.ndarray, residual: str, continue_orbit: Callable[[SettledMotion], tuple[int, str]],
    engine: object,
) -> SeedOutcome:  # fmt: skip
    """What the motion from a seed reaches (module docstring); a periodic one is handed to ``continue_orbit``.

    Parameters
    ----------
    found : OrbitSet
        The branches known (their Neimark-Sacker points are looked up here).
    problem : ImpactProblem
        The problem at the seed's frequency.
    frequency : float
        The seed's frequency [Hz].
    sweep_period : int
        Its sweep's period [excitation periods].
    state : ndarray, shape (2N,)
        Its state at t = 0 [m, m s-1].
    residual : str
        How shooting from it failed, for the text ("residual 0.0637 at the start").
    continue_orbit : callable
        Given the periodic motion, shoots and continues its orbit: (branch label or -1, what became of it).
    engine : object
        The engine with exact Jacobians the motion is run with.
    """
    head = f"brute-force seed at {frequency:.3f} Hz (period {sweep_period}): shooting did not converge ({residual})"
    try:
        motion = settle_motion(engine, problem, np.asarray(state, dtype=float))
    except (RuntimeError, ValueError) as error:  # the engine made no progress: a genuine failure
        return SeedOutcome(frequency, sweep_period, "failed", text=f"{head}; running it on failed: {type(error).__name__}: {str(error)[:160]}")
    common = {"periods_run": motion.periods, "lyapunov_exponent": motion.exponent, "lyapunov_error": motion.exponent_error}
    ran = f"{head}; run on for {motion.periods} periods"
    if motion.kind == "periodic":
        label, what = continue_orbit(motion)
        longer = f", longer than the {MAX_PERIOD} the sweeps look for" if motion.period > MAX_PERIOD else ", repeating once run longer"
        return SeedOutcome(frequency, sweep_period, "periodic", orbit_period=motion.period, branch=label, **common,
                           text=f"{ran}: a periodic orbit of period {motion.period}{longer}: {motion.reason}; {what}")  # fmt: skip
    if motion.kind == "chaotic":
        return SeedOutcome(frequency, sweep_period, "chaotic", **common, text=f"{ran}: chaotic, {motion.reason}")
    if motion.kind == "undecided":
        return SeedOutcome(frequency, sweep_period, "undecided", **common, text=f"{ran}: undecided, {motion.reason}")
    near, k, attracting = torus_origin(found, frequency, motion.strobes)
    rho = torus_rotation(motion.strobes, k)
    of = f" of the {k}-period map (the torus is {k} closed curves visited in turn)" if k > 1 else ""
    if near is None:
        where, ns_frequency, angle = "no continued branch has a Neimark-Sacker point", math.nan, math.nan
    else:
        ns_frequency, angle = float(near["frequency"]), neimark_sacker_angle(near["multipliers"])
        orbit = f" of the period-{k} orbit" if k > 1 else ""
        away = abs(ns_frequency - frequency)
        where = (f"next to the Neimark-Sacker point{orbit} at {ns_frequency:.4f} Hz (its angle/2pi {angle:.4f})" if away <= NEXT_TO * frequency
                 else f"the Neimark-Sacker point{orbit} it may come from is {away:.3f} Hz away, at {ns_frequency:.4f} Hz (its angle/2pi {angle:.4f})")  # fmt: skip
        if not attracting:
            where += f", where another multiplier is outside the unit circle (max |mu| = {float(np.max(np.abs(near['multipliers']))):.4g}): no attracting torus is born there"
    return SeedOutcome(frequency, sweep_period, "quasi_periodic", rotation_number=rho, rotation_period=k, ns_frequency=ns_frequency, ns_angle=angle, **common,
                       text=f"{ran}: a motion on a torus, rotation number {rho:.4f}{of}, {where} ({motion.reason})")  # fmt: skip


#: A Neimark-Sacker point within this share of the seed's frequency is "next to" it [-] (the tori measured on the
#: paper's system at 20.85-21.15 Hz lie within 0.36 Hz, 1.7 %, of the point at 21.2052 Hz they come from).
NEXT_TO = 0.02


def continue_seed_orbit(
    found: OrbitSet, problem: ImpactProblem, motion: SettledMotion, bounds: dict[str, tuple[float, float]], settings: ContinuationSettings, engine: object, may_add: bool,
) -> tuple[int, str]:  # fmt: skip
    """Shoot the periodic orbit a settled motion reached, through a strobe clear of its impacts, and continue it in
    frequency unless a known branch passes through it.

    Parameters
    ----------
    found : OrbitSet
        The branches known; a new one is added.
    problem : ImpactProblem
        At the seed's frequency (force phase 0: the motion's strobes).
    motion : SettledMotion
        ``periodic``, ending on the orbit.
    bounds : dict
        Of the maps (:func:`~vibroimpact.kinds.bifurcation.branches.map_bounds`).
    settings : ContinuationSettings
        Of the continuation.
    engine : object
        The exact engine.
    may_add : bool
        False once the most seeded branches were added: the orbit is shot, not continued.

    Returns
    -------
    (int, str)
        The label of the branch it was continued as or lies on (-1: none), and what became of it in words.
    """
    period = motion.period
    try:
        moved, state = resection(problem, motion.state, period, engine)
        mapping = ImpactMap(moved, period, engine, bounds)
        orbit = shoot(mapping, state, mapping.parameters)
    except (ShootingError, RuntimeError, ValueError) as error:
        return -1, f"shooting that orbit did not converge ({type(error).__name__}: {str(error)[:120]})"
    if not orbit.stable:
        return -1, f"the orbit shot there is unstable (max |mu| = {orbit.floquet_modulus:.4g}): not the motion's attractor, not continued"
    measures = orbit_measures(mapping, orbit)
    impacts = int(measures.impulses.size)
    impulse = float(measures.impulses.sum()) / period
    label = _branch_through(found, float(problem.harmonic.frequency), period, impacts, impulse)
    if label >= 0:
        return label, f"shot (max |mu| = {orbit.floquet_modulus:.4g}, {impacts} impacts), on branch {label} already"
    if not may_add:
        return -1, f"shot (max |mu| = {orbit.floquet_modulus:.4g}, {impacts} impacts), not continued: the most seeded branches were added"
    try:
        branch = continue_branch(mapping, orbit, "frequency", settings)
    except (ShootingError, RuntimeError, ValueError) as error:
        return -1, f"shot (max |mu| = {orbit.floquet_modulus:.4g}), its continuation failed: {type(error).__name__}: {str(error)[:120]}"
    label = found.add_branch(mapping, branch, "brute_force")
    found.maps.append((mapping, branch))
    found.notes[-1] += f"; seeded at {problem.harmonic.frequency:.3f} Hz from a slowly settling seed, period {period}, {impacts} impacts, max |mu| = {orbit.floquet_modulus:.4g} there"
    return label, f"shot (max |mu| = {orbit.floquet_modulus:.4g}, {impacts} impacts) and continued as branch {label} ({len(branch.orbits)} points, {branch.values.min():.4f}-{branch.values.max():.4f} Hz)"


def _branch_through(found: OrbitSet, frequency: float, period: int, impacts: int, impulse: float) -> int:
    """The label of a known branch through an orbit of this period, impact count and impulse per period at
    ``frequency`` [Hz] (:meth:`OrbitSet.known`'s test, segment by segment), -1 where none passes."""
    if not found.known(frequency, period, impacts, impulse):
        return -1
    points = found.points
    best, label = math.inf, -1
    for a, b in zip(points[:-1], points[1:]):
        if a["branch"] != b["branch"] or (a["period"], a["impacts"]) != (period, impacts) or (b["period"], b["impacts"]) != (period, impacts):
            continue
        low, high = sorted((a["frequency"], b["frequency"]))
        if not low <= frequency <= high:
            continue
        t = 0.0 if high == low else (frequency - a["frequency"]) / (b["frequency"] - a["frequency"])
        distance = abs(a["impulse"] + t * (b["impulse"] - a["impulse"]) - impulse)
        if distance < best:
            best, label = distance, int(a["branch"])
    return label


#: Fields of :func:`slow_seed_arrays` (a branch case's arrays, :data:`~vibroimpact.kinds.bifurcation.cases.BRANCH_FIELDS`).
SLOW_SEED_FIELDS = (
    "ss_frequency", "ss_sweep_period", "ss_outcome", "ss_periods_run", "ss_orbit_period", "ss_lyapunov", "ss_lyapunov_error", "ss_rotation", "ss_rotation_period",
    "ss_ns_frequency", "ss_ns_angle", "ss_branch", "ss_text",
)  # fmt: skip


def slow_seed_arrays(outcomes: list[SeedOutcome]) -> dict[str, np.ndarray]:
    """The outcomes as flat arrays, one row per seed (:data:`SLOW_SEED_FIELDS`; ``ss_outcome`` the index in
    :data:`SEED_OUTCOMES`)."""
    columns = (("frequency", float), ("sweep_period", int), ("outcome", int), ("periods_run", int), ("orbit_period", int), ("lyapunov_exponent", float), ("lyapunov_error", float),
               ("rotation_number", float), ("rotation_period", int), ("ns_frequency", float), ("ns_angle", float), ("branch", int), ("text", str))  # fmt: skip
    return {
        field: np.array([SEED_OUTCOMES.index(o.outcome) if name == "outcome" else getattr(o, name) for o in outcomes], dtype=kind)
        for field, (name, kind) in zip(SLOW_SEED_FIELDS, columns)
    }
