"""The rigid-stop flight of any layout as compiled kernels: right-hand side, Jacobian, event functions and holding
force over one flat parameter array (:func:`pack_parameters`), for the ``momentary`` engine's CVODE callbacks (numba
``cfunc`` wrappers in :mod:`~vibroimpact.engines.momentary`) and, called from Python, for its fallback and the ``solve_ivp_*`` engines.

The integrated state (see :mod:`~vibroimpact.engines.flow_layout`) is y = (w, v) of 2 N entries, followed, when harmonic moments are
wanted, by 3 N + 2 K quadratures: x_i cos(wt) and x_i sin(wt) for each coordinate, the contact force of each stop
times cos and sin (the holding force of the stuck stop, 0 for the others: impulses are added by the engine), and
x_i^2 for each coordinate (for the paper's layout: X1 c, X1 s, X2 c, X2 s, H c, H s, X1^2, X2^2).

Event functions (2 K + 1): the penetration u_k of each stop (rising: contact; -1 on the stop held), the holding force
of the stuck stop (falling: release; 1 in free flight), and the approach velocity n_k . v of each stop (falling: an
apex, the grazing guard; 1 on the stop held or without the guard). A stop parallel to the one held (the other side of
a two-sided stop) cannot be reached while it is held: its events are constants too.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
from numba import carray, cfunc, njit, types
from numpy.typing import NDArray

from vibroimpact.engines.base import TrajectoryBuilder, check_run
from vibroimpact.engines.flow_layout import FlowLayout
from vibroimpact.engines.numba_cache import stamp_with_callees
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.engines.sundae import as_doubles, content_data
from vibroimpact.model.contact import Impact, RigidStop
from vibroimpact.model.problem import ImpactProblem

__all__ = ["pack_parameters", "pack_blocks", "quadrature_count", "rhs_kernel", "jacobian_kernel", "events_kernel", "holding_kernel", "STUCK", "APEX", "COMPILED_RHS", "COMPILED_JACOBIAN", "COMPILED_EVENTS", "RigidContact"]

# header of the parameter array: mode, flags, sizes and the offsets of the blocks after it
STUCK, APEX, SIZE, _N, STOPS, _OMEGA, _TRIG, _A, _C, _BR, _BI, _G, _G0, _NORMAL, _H, _H0, _HBR, _HBI, _TINV, _XOFF, LENGTH = range(21)
HEADER = 21


def quadrature_count(size: int, stops: int) -> int:
    """Moment quadratures of N coordinates and K stops: 3 N + 2 K (8 for the paper's layout)."""
    return 3 * size + 2 * stops


def pack_parameters(layout: FlowLayout, states: int, apex: bool = True) -> NDArray[np.float64]:
    """The flat parameter array of ``layout`` for a state of ``states`` entries (2 N, or 2 N plus the quadratures).

    Header: mode, flags, sizes, w, the trigonometric functions the forcing needs, and the blocks' offsets.
    Blocks: the matrices A of the free flight and of each stuck mode ((K + 1) x 2N x 2N, row-major), their c, Re b
    and Im b ((K + 1) x 2N each), the gap rows and constants, the normals, the holding rows H, h0, Re hb, Im hb, T^-1
    and its offset. Entry :data:`STUCK` holds the stuck stop (-1: free flight), :data:`APEX` the grazing guard flag.
    """
    n, k = layout.size, layout.stop_count
    modes = (layout.free, *layout.stuck)
    holding_rows, holding_constants, holding_harmonic = layout.holding
    blocks = [
        np.concatenate([m[0].ravel() for m in modes]),
        np.concatenate([m[1] for m in modes]),
        np.concatenate([m[2].real for m in modes]),
        np.concatenate([m[2].imag for m in modes]),
        layout.gap_rows.ravel(),
        layout.gap_constants,
        layout.normals.ravel(),
        holding_rows.ravel(),
        holding_constants,
        holding_harmonic.real,
        holding_harmonic.imag,
        layout.t_inverse.ravel(),
        layout.offset,
    ]
    header = np.zeros(HEADER)
    header[STUCK], header[APEX], header[SIZE], header[_N], header[STOPS], header[_OMEGA] = -1.0, float(apex), states, n, k, layout.omega
    # which of cos(wt), sin(wt) the flight's forcing needs (the moments need both): none, cos, or both
    header[_TRIG] = 2.0 if np.any(blocks[3] != 0.0) else 1.0 if np.any(blocks[2] != 0.0) else 0.0
    return pack_blocks(header, _A, LENGTH, blocks)


def pack_blocks(header: NDArray[np.float64], first: int, length: int, blocks: list[NDArray]) -> NDArray[np.float64]:
    """``header`` followed by ``blocks``, flat, as the compiled kernels read a parameter array: entries ``first`` to
    ``length - 1`` of the header get the blocks' offsets in it, entry ``length`` its total size."""
    start = header.size
    for index, block in zip(range(first, length), blocks):
        header[index] = start
        start += block.size
    header[length] = start
    return np.concatenate([header, *blocks]).astype(np.float64)


@njit(cache=True)
def holding_kernel(t: float, y: NDArray[np.float64], p: NDArray[np.float64], stop: int) -> float:  # pragma: no cover - compiled
    """lambda_k [N]: the force stop ``stop`` must exert to hold its gap closed, in state y at time t."""
    n2 = 2 * int(p[_N])
    row = int(p[_H]) + stop * n2
    wt = p[_OMEGA] * t
    value = p[int(p[_H0]) + stop] + p[int(p[_HBR]) + stop] * math.cos(wt) - p[int(p[_HBI]) + stop] * math.sin(wt)
    for j in range(n2):
        value += p[row + j] * y[j]
    return value


@njit(cache=True)
def rhs_kernel(t: float, y: NDArray[np.float64], yp: NDArray[np.float64], p: NDArray[np.float64]) -> None:  # pragma: no cover - compiled
    """y' of the current mode into ``yp`` (and the moment quadratures when the state has them)."""
    n = int(p[_N])
    n2 = 2 * n
    stuck = int(p[STUCK])
    mode = stuck + 1
    a0, c0 = int(p[_A]) + mode * n2 * n2, int(p[_C]) + mode * n2
    br0, bi0 = int(p[_BR]) + mode * n2, int(p[_BI]) + mode * n2
    wt = p[_OMEGA] * t
    trig = 2 if int(p[SIZE]) > n2 else int(p[_TRIG])
    c = math.cos(wt) if trig > 0 else 0.0
    s = math.sin(wt) if trig > 1 else 0.0
    for i in range(n2):
        acc = p[c0 + i] + p[br0 + i] * c - p[bi0 + i] * s
        row = a0 + i * n2
        for j in range(n2):
            acc += p[row + j] * y[j]
        yp[i] = acc
    if int(p[SIZE]) > n2:
        k_count = int(p[STOPS])
        tinv, xoff = int(p[_TINV]), int(p[_XOFF])
        squares = n2 + 2 * n + 2 * k_count
        for i in range(n):
            x = p[xoff + i]
            for j in range(n):
                x += p[tinv + i * n + j] * y[j]
            yp[n2 + 2 * i] = x * c
            yp[n2 + 2 * i + 1] = x * s
            yp[squares + i] = x * x
        for k in range(k_count):
            force = holding_kernel(t, y, p, k) if k == stuck else 0.0
            yp[n2 + 2 * n + 2 * k] = force * c
            yp[n2 + 2 * n + 2 * k + 1] = force * s


@njit(cache=True)
def jacobian_kernel(t: float, y: NDArray[np.float64], jt: NDArray[np.float64], p: NDArray[np.float64]) -> None:  # pragma: no cover - compiled
    """d y' / d y into ``jt`` transposed: jt[j, i] = d y'_i / d y_j (CVODE's column-major dense matrix)."""
    n = int(p[_N])
    n2 = 2 * n
    stuck = int(p[STUCK])
    size = int(p[SIZE])
    a0 = int(p[_A]) + (stuck + 1) * n2 * n2
    jt[:, :] = 0.0
    for i in range(n2):
        for j in range(n2):
            jt[j, i] = p[a0 + i * n2 + j]
    if size > n2:
        k_count = int(p[STOPS])
        tinv, xoff = int(p[_TINV]), int(p[_XOFF])
        wt = p[_OMEGA] * t
        c, s = math.cos(wt), math.sin(wt)
        squares = n2 + 2 * n + 2 * k_count
        for i in range(n):
            x = p[xoff + i]
            for j in range(n):
                x += p[tinv + i * n + j] * y[j]
            for j in range(n):
                entry = p[tinv + i * n + j]
                jt[j, n2 + 2 * i] = entry * c
                jt[j, n2 + 2 * i + 1] = entry * s
                jt[j, squares + i] = 2.0 * x * entry
        if stuck >= 0:
            row = int(p[_H]) + stuck * n2
            for j in range(n2):
                jt[j, n2 + 2 * n + 2 * stuck] = p[row + j] * c
                jt[j, n2 + 2 * n + 2 * stuck + 1] = p[row + j] * s


@njit(cache=True)
def _parallel(p: NDArray[np.float64], normal: int, n: int, k: int, held: int) -> bool:  # pragma: no cover - compiled
    """Is n_k = +-n_held? (Equality in Cauchy-Schwarz; exact for the normals' entries 0, +-1.)"""
    dot = kk = hh = 0.0
    for j in range(n):
        a, b = p[normal + k * n + j], p[normal + held * n + j]
        dot += a * b
        kk += a * a
        hh += b * b
    return dot * dot == kk * hh


@njit(cache=True)
def events_kernel(t: float, y: NDArray[np.float64], out: NDArray[np.float64], p: NDArray[np.float64]) -> None:  # pragma: no cover - compiled
    """The 2 K + 1 event functions into ``out``: penetrations, the holding force, approach velocities."""
    n = int(p[_N])
    k_count = int(p[STOPS])
    stuck = int(p[STUCK])
    apex = p[APEX] != 0.0
    g, g0, normal = int(p[_G]), int(p[_G0]), int(p[_NORMAL])
    for k in range(k_count):
        if k == stuck or (stuck >= 0 and _parallel(p, normal, n, k, stuck)):
            # the stop held, or another side of it (n_k = +-n_held): its gap and n_k . v are frozen while held, and
            # n_k . v is round-off of 0 whose sign changes are not apexes (a root at and near one point is an error)
            out[k] = -1.0
            out[k_count + 1 + k] = 1.0
            continue
        value = p[g0 + k]
        for j in range(n):
            value += p[g + k * n + j] * y[j]
        out[k] = value
        if apex:
            speed = 0.0
            for j in range(n):
                speed += p[normal + k * n + j] * y[n + j]
            out[k_count + 1 + k] = speed
        else:
            out[k_count + 1 + k] = 1.0
    out[k_count] = holding_kernel(t, y, p, stuck) if stuck >= 0 else 1.0


# The CVODE callbacks (``CVRhsFn``, ``CVLsJacFn``, ``CVRootFn``) over the kernels, in this module: numba's disk cache
# keys a compiled function on its own file only, so callbacks in another file would keep a stale copy of an edited
# kernel.
@njit(cache=True, inline="always")
def _parameters(data: Any) -> Any:  # pragma: no cover - compiled
    """The user data as the parameter array of :func:`~vibroimpact.engines.rigid_kernels.pack_parameters`."""
    return carray(as_doubles(data), (int(carray(as_doubles(data), (HEADER,))[LENGTH]),))


@cfunc(types.intc(types.float64, types.voidptr, types.voidptr, types.voidptr), cache=True)
def _rhs(t: float, y_vector: Any, yp_vector: Any, data: Any) -> int:  # pragma: no cover - compiled
    p = _parameters(data)
    size = int(p[SIZE])
    rhs_kernel(t, carray(content_data(y_vector), (size,)), carray(content_data(yp_vector), (size,)), p)
    return 0


@cfunc(types.intc(types.float64, types.voidptr, types.voidptr, types.voidptr, types.voidptr, types.voidptr, types.voidptr, types.voidptr), cache=True)
def _jacobian(t: float, y_vector: Any, f_vector: Any, matrix: Any, data: Any, tmp1: Any, tmp2: Any, tmp3: Any) -> int:  # pragma: no cover
    p = _parameters(data)
    size = int(p[SIZE])
    # column-major: jac[j, i] = d y'_i / d y_j
    jacobian_kernel(t, carray(content_data(y_vector), (size,)), carray(content_data(matrix), (size, size)), p)
    return 0


@cfunc(types.intc(types.float64, types.voidptr, types.CPointer(types.float64), types.voidptr), cache=True)
def _events(t: float, y_vector: Any, out: Any, data: Any) -> int:  # pragma: no cover - compiled
    p = _parameters(data)
    size = int(p[SIZE])
    events_kernel(t, carray(content_data(y_vector), (size,)), carray(out, (2 * int(p[STOPS]) + 1,)), p)
    return 0


#: The compiled callbacks (numba ``cfunc``; ``.address`` for CVODE, ``.ctypes`` to call them from Python).
COMPILED_RHS, COMPILED_JACOBIAN, COMPILED_EVENTS = _rhs, _jacobian, _events


# --------------------------------------------------------------------------------------------------------------------
# The rigid stop's law as the momentary-impact engines apply it: one place for ``exact`` and the event loop.
# --------------------------------------------------------------------------------------------------------------------

class RigidContact:
    """The rigid stops of one problem with an engine's settings.

    Parameters
    ----------
    engine : str
        Name of the engine (for messages).
    problem : ImpactProblem
        Every stop must have a :class:`RigidStop` law, and the excitation must be harmonic (``TypeError`` otherwise).
    settings : EngineSettings
        Sticking velocity (a fraction of the problem's velocity scale) and impacts per period before sticking.
    periods : int
        Periods the run integrates (>= 0).

    Attributes
    ----------
    laws : tuple of RigidStop
        The law of each stop (``stop``: the first one's, for single-stop callers).
    normals : ndarray, shape (K, N)
        n_k: stop k's gap is clearances[k] - n_k . x.
    clearances : ndarray, shape (K,)
        Delta_k [m].
    masses : ndarray, shape (K,)
        Effective mass m_eff = 1 / (n^T M^-1 n) of each stop [kg] (``mass``: the first one's; M2 on the paper's layout).
    kicks : ndarray, shape (K, N)
        M^-1 n_k [kg-1]: an impulse P on stop k changes the velocities by -P M^-1 n_k.
    velocity_scale : float
        The problem's velocity scale (w (Delta + q |H12|) on the paper's layout) [m s-1].
    length_scale : float
        max |Delta| + velocity_scale / w [m]: the size of the motion, for round-off thresholds.
    sticking_velocity : float
        Impacts at most this fast [m s-1] are chattering.
    """

    def __init__(self, engine: str, problem: ImpactProblem, settings: EngineSettings, periods: int) -> None:
        check_run(engine, problem, RigidStop, periods)
        problem.harmonic  # a frequency is needed for the scales (TypeError naming the excitation otherwise)
        mass_matrix = problem.structure.mass_matrix
        self.size = problem.size
        self.names = problem.structure.coordinates
        self.stops = problem.stops
        self.laws: tuple[RigidStop, ...] = tuple(stop.law for stop in self.stops)  # type: ignore[misc]
        self.normals = problem.normals()
        self.clearances = problem.clearances()
        self.kicks = np.linalg.solve(mass_matrix, self.normals.T).T.reshape(-1, self.size)
        self.masses = 1.0 / np.einsum("ki,ki->k", self.normals, self.kicks)
        self.stop, self.mass = self.laws[0], float(self.masses[0])
        self.velocity_scale = problem.velocity_scale()
        self.length_scale = float(np.max(np.abs(self.clearances))) + self.velocity_scale / problem.omega
        self.sticking_velocity = settings.sticking_velocity * self.velocity_scale
        self.max_impacts = settings.max_impacts_per_period

    def gaps(self, state: NDArray[np.float64]) -> NDArray[np.float64]:
        """Delta_k - n_k . x of every stop [m] (negative: penetrating)."""
        return self.clearances - self.normals @ np.asarray(state[: self.size], dtype=float)

    def approach(self, state: NDArray[np.float64]) -> NDArray[np.float64]:
        """n_k . x' of every stop [m s-1]: positive while the gap closes."""
        return self.normals @ np.asarray(state[self.size : 2 * self.size], dtype=float)

    def check_start(self, state: NDArray[np.float64]) -> None:
        """A start beyond any stop (by more than round-off of the length scale) is an error naming the stop."""
        gaps = self.gaps(state)
        for k, gap in enumerate(gaps):
            if gap < -1e-12 * self.length_scale:
                where = self.stops[k].describe(self.names)
                raise ValueError(f"the initial state penetrates stop {k} ({where}) by {float(-gap):.6g} m: start on the allowed side of every stop")

    def collide(self, rec: TrajectoryBuilder, t: float, velocity: float, impacts: int, pushed: Callable[[], bool], stop: int = 0) -> Impact:
        """Apply stop ``stop``'s law to an impact at time t [s] at approach ``velocity`` = n . x' >= 0 [m s-1], the
        ``impacts``-th of its period, and record it (an impact at zero speed is a touch: only a stick is counted)."""
        law = self.laws[stop]
        outcome = law.impact(float(self.masses[stop]), velocity, law.chatters(velocity, impacts, self.sticking_velocity, self.max_impacts), pushed)
        if velocity > 0.0:
            rec.impact(t, velocity, outcome.impulse, stop=stop)  # m_eff (1 + R) v, or m_eff v when it sticks
        rec.stats["sticks"] += int(outcome.sticks)
        return outcome

    def kick(self, state: NDArray[np.float64], stop: int, impulse: float) -> NDArray[np.float64]:
        """The state after an impulse ``impulse`` [N s] of stop ``stop``: x' -> x' - impulse M^-1 n (x unchanged).

        With impulse m_eff (1 + R) v this restitutes the gap velocity, n . x'(t+) = -R n . x'(t-), and on a relative
        stop it conserves the momentum of the two bodies."""
        out = np.array(state, dtype=float)
        out[self.size : 2 * self.size] -= impulse * self.kicks[stop]
        return out


# the compiled kernels read sundae's intrinsics: an edit of it recompiles them (not the ``cfunc`` callbacks above: they
# compiled or loaded as they were defined, see numba_cache's docstring)
stamp_with_callees(globals())
