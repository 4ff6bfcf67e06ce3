"""Engine ``exact``: piecewise-exact propagation, the reference every integrator is measured against.

Between events the motion is linear with harmonic forcing, so it is propagated in closed form (eigenvectors of the
state matrix plus the harmonic particular solution). Contacts are found by guaranteed root bracketing (Taylor bounds
of the gap, :func:`.linear_flow.first_crossing`): no contact is missed however tangent, and contact times are exact
to round-off. At a contact X2' -> -R X2'. When impacts accumulate (chattering, small R) and the stop pushes the
absorber, it sticks: X2 = Delta, X2' = 0, only the primary mass moves, until the holding force
B2 X1' + K2 (X1 - Delta) turns negative (found by the same root search).

The event loop runs compiled (:mod:`.exact_core`, numba); this module is its thin Python face. It also returns the
exact Jacobian of the stroboscopic map (state-transition matrices times the saltation matrices of impacts, sticking
and release), for shooting, continuation and Lyapunov exponents (:mod:`vibroimpact.orbits`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from vibroimpact.engines import exact_core
from vibroimpact.engines.base import Trajectory, check_run
from vibroimpact.engines.exact_python import PythonExactEngine
from vibroimpact.engines.rigid_contact import RigidContact
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import TwoDofSystem

__all__ = ["ExactEngine", "StrobeMap"]


@dataclass(frozen=True, eq=False)
class StrobeMap:
    """The stroboscopic map over ``periods`` periods from one state, with its exact Jacobian.

    Attributes
    ----------
    state : ndarray, shape (4,)
        Image (X1, X2, X1', X2') after the periods [m, m, m s-1, m s-1].
    jacobian : ndarray, shape (4, 4)
        d state / d start [-, s-1 or s]: NaN where the map is not differentiable (a grazing touch at zero speed).
    impact_times : ndarray
        Times of the impacts [s].
    impact_velocities : ndarray
        Speed of the absorber just before each impact, > 0 [m s-1].
    sticks, releases : int
        Impacts that ended in sticking, and releases from the stop.
    closest_approach : float
        Largest X2 - Delta at an interior local maximum of a free flight [m] (<= 0; -inf if none): a new impact
        is born (grazing) where it reaches 0.
    closest_approach_time : float
        When it happens [s] (NaN if none).
    """

    state: NDArray[np.float64]
    jacobian: NDArray[np.float64]
    impact_times: NDArray[np.float64]
    impact_velocities: NDArray[np.float64]
    sticks: int
    releases: int
    closest_approach: float
    closest_approach_time: float
    stats: dict[str, int] = field(default_factory=dict)


@lru_cache(maxsize=32)
def _eigen(matrix: tuple[tuple[float, ...], ...]) -> tuple[NDArray[np.complex128], NDArray[np.complex128], NDArray[np.complex128]]:
    """Eigenvalues, eigenvectors and their inverse of a state matrix: once per system (cached)."""
    a = np.array(matrix, dtype=complex)
    lam, vec = np.linalg.eig(a)
    return lam, np.ascontiguousarray(vec), np.ascontiguousarray(np.linalg.inv(vec))


@lru_cache(maxsize=32)
def _matrices(system: TwoDofSystem) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The free state matrix A (4 x 4) and the stuck one of (X1, X1') (2 x 2)."""
    s = system
    stuck = np.array([[0.0, 1.0], [-(s.k1 + s.k2) / s.m1, -(s.b1 + s.b2) / s.m1]])
    return np.ascontiguousarray(s.state_matrix, dtype=float), stuck


class _Flows:
    """The arrays the compiled loop needs for one problem (eigen-decompositions shared per system).

    The harmonic particular solution is a linear solve, (jw I - A) Y = b: through the eigenvectors it is ~10x less
    accurate (7e-11 against 1e-11 of the motion at the anti-resonance).
    """

    def __init__(self, problem: ImpactProblem) -> None:
        s, p = problem.system, problem
        a, stuck = _matrices(s)
        self.a = a
        self.lam, self.vec, self.inv = _eigen(tuple(map(tuple, a)))
        self.slam, self.svec, self.sinv = _eigen(tuple(map(tuple, stuck)))
        forcing = p.amplitude * complex(math.cos(p.phase), math.sin(p.phase)) / s.m1
        jw = 1j * p.omega
        self.hrm = np.linalg.solve(jw * np.eye(4) - a, np.array([0, 0, forcing, 0], dtype=complex))
        self.cst = np.zeros(4)
        self.shrm = np.linalg.solve(jw * np.eye(2) - stuck, np.array([0, forcing], dtype=complex))
        # stuck: X1'' = -(K1 + K2)/M1 X1 - ... + K2 Delta / M1: the constant solution X1 = K2 Delta / (K1 + K2)
        self.scst = np.array([s.k2 * p.clearance / (s.k1 + s.k2), 0.0])


@dataclass(frozen=True, eq=False)
class _Setup:
    """What the compiled loop needs of one problem: its flows and thresholds, as the loop's leading arguments."""

    law: RigidContact
    arguments: tuple


@lru_cache(maxsize=512)
def _setup(problem: ImpactProblem, settings: EngineSettings) -> _Setup:
    """Once per problem (continuation and Lyapunov runs call the map of one problem thousands of times)."""
    law = RigidContact("exact", problem, settings, 0)
    f, p, s = _Flows(problem), problem, problem.system
    length = law.length_scale
    arguments = (
        f.lam, f.vec, f.inv, f.hrm, f.cst, f.slam, f.svec, f.sinv, f.shrm, f.scst,
        f.a, p.amplitude / s.m1, p.phase, p.omega, p.period,
        p.clearance, p.restitution, s.m2, s.k2, s.b2,
        law.sticking_velocity, law.max_impacts, 1e-15 * length, 1e-15 * (s.k2 + s.b2 * p.omega) * length,
        1e-14 * law.velocity_scale,
    )  # fmt: skip
    return _Setup(law, arguments)


class ExactEngine:
    """Exact piecewise-linear reference engine, compiled (see module docstring)."""

    name = "exact"

    def __init__(self, settings: EngineSettings = EngineSettings()) -> None:
        self.settings = settings

    def _run(self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float, periods: int, moments: bool, jacobians: bool, approach: bool) -> tuple:
        check_run(self.name, problem, RigidStop, periods)
        setup = _setup(problem, self.settings)
        state = np.ascontiguousarray(state, dtype=float)
        setup.law.check_start(state)
        out = exact_core.run_periods(*setup.arguments, state, float(t_start), int(periods), moments, jacobians, approach)
        if out[0] != exact_core.STATUS_OK:
            raise RuntimeError(f"no progress at t = {out[1]!r} s: more than {10 * setup.law.max_impacts} events in one period")
        return out

    def integrate(
        self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float, periods: int, moments: bool = False, jacobians: bool = False
    ) -> Trajectory:
        """Integrate ``periods`` whole periods from ``state`` (X1, X2, X1', X2') at ``t_start`` [s].

        With ``jacobians``, ``strobe_jacobians[k]`` is the exact Jacobian of period k's stroboscopic map.
        """
        _status, _t, strobes, jac, impacts, segments, segment_states, period_moments, counters, _approach = self._run(
            problem, state, t_start, periods, moments, jacobians, False
        )
        times = float(t_start) + np.arange(periods + 1) * problem.period  # the loop's boundaries, bit for bit
        starts = segments[:, 0]
        ends = np.append(starts[1:], times[-1]) if starts.size else starts
        keep = ends > starts
        return Trajectory(
            problem=problem,
            strobe_times=times,
            strobe_states=strobes,
            impact_times=impacts[:, 0].copy(),
            impact_velocities=impacts[:, 1].copy(),
            impulses=impacts[:, 2].copy(),
            segments=np.column_stack([starts, ends, segments[:, 1]])[keep],
            segment_states=segment_states[keep],
            moments=period_moments if moments else np.zeros((0, 5), dtype=complex),
            stats=_stats(counters, impacts.shape[0]),
            strobe_jacobians=jac if jacobians else np.zeros((0, 4, 4)),
        )

    def strobe_map(self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float = 0.0, periods: int = 1) -> StrobeMap:
        """The stroboscopic map over ``periods`` periods from ``state`` at ``t_start`` [s], with its exact Jacobian
        and what a continuation watches (impact speeds, closest approach of the gap)."""
        _status, _t, strobes, jac, impacts, _segments, _states, _moments, counters, approach = self._run(problem, state, t_start, periods, False, True, True)
        product = np.eye(4)
        for factor in jac:
            product = factor @ product
        return StrobeMap(
            state=strobes[-1].copy(),
            jacobian=product,
            impact_times=impacts[:, 0].copy(),
            impact_velocities=impacts[:, 1].copy(),
            sticks=int(counters[2]),
            releases=int(counters[3]),
            closest_approach=float(approach[0]),
            closest_approach_time=float(approach[1]),
            stats=_stats(counters, impacts.shape[0]),
        )

    def dense(self, trajectory: Trajectory, times: NDArray[np.float64]) -> NDArray[np.float64]:
        """States at arbitrary ``times`` inside a trajectory, shape (n, 4), exact (from its segments)."""
        return PythonExactEngine(self.settings).dense(trajectory, times)


def _stats(counters: NDArray[np.int64], impacts: int) -> dict[str, int]:
    steps, events, sticks, releases, touches = (int(c) for c in counters)
    return {"impacts": impacts, "sticks": sticks, "releases": releases, "steps": steps, "events": events, "touches": touches}
