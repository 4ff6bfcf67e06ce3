"""The free flight, the stuck flights and the bumper contacts of any N-dof structure with K stops, as the integrator
engines (``momentary``, ``solve_ivp_*``, ``compliant``) integrate them.

State. The integrators carry y = (w, v): v = x' are the physical velocities, and w = T x - d are the displacements
with each stop's penetration u_k = n_k . x - Delta_k = -g_k in place of one coordinate (its *pivot*): row p_k of T is
n_k and d_{p_k} = Delta_k; every other row of T is e_i (d_i = 0). A gap near zero then keeps its absolute precision
(with x itself, a gap of 1e-20 m vanishes in x - Delta, and an event function would look identically zero). A stop
whose normal is a combination of rows already taken (the second side of a two-sided stop) has no pivot: its
penetration is computed, G_k . w + g0_k, from a coordinate near -2 Delta (1 ulp ~ 1e-18 m, and integrated to rtol x
2 Delta), too coarse for a chatter on it; the engines switch to the layout with that stop taken first when it is hit
(``flow_layout(problem, first=k)``, :meth:`FlowLayout.carrying`, :meth:`FlowLayout.convert`). T has entries 0 and +-1 with at most one +1 and one -1 per row, so it is
totally unimodular: its inverse is an integer matrix, exact in floating point. For the paper's layout T = I and
w = (X1, X2 - Delta): the state of the engines before the N-dof generalisation.

Flow. Between events y' = A y + c + Re(b e^{jwt}) with one (A, c, b) per mode:

* free flight: w' = T v, M v' = f(t) - C v - K x with x = T^-1 (w + d);
* stuck on rigid stop k (n_k . x = Delta_k held): the stop's force -n_k lambda_k with the holding force
  lambda_k = r_k . (f - C v - K x), r_k = M^-1 n_k / (n_k . M^-1 n_k) (``problem.contact_holding``), so
  M v' = Q_k (f - C v - K x) with Q_k = I - n_k r_k^T, and the pivot's w' = 0 (the gap stays exactly 0);
* bumper k in contact: the force -n_k lambda_k with lambda_k = K_k u_k + B_k n_k . v, K_k = m_k Omega_b^2 and
  B_k = 2 m_k xi_b Omega_b (m_k = 1 / (n_k . M^-1 n_k), the stop's effective mass), for every stop of the mode.

Every acceleration is M^-1 applied to a force (``solve``), so that on a diagonal mass matrix the numbers are the
divisions the paper's equations make (a stuck absorber's row is exactly zero).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem

__all__ = ["FlowLayout", "flow_layout"]


def _pivots(normals: NDArray[np.float64], stops: tuple, size: int, first: int = -1) -> tuple[NDArray[np.float64], list[int]]:
    """T and the pivot coordinate of each stop (-1: none, its normal depends on the pivots already taken), the stops
    taken in order, stop ``first`` (if >= 0) before the others."""
    t = np.eye(size)
    pivots = [-1] * len(stops)
    for k in ([first] if first >= 0 else []) + [k for k in range(len(stops)) if k != first]:
        stop = stops[k]
        for candidate in (stop.coordinate, stop.other):
            if candidate is None or candidate in pivots:
                continue
            trial = t.copy()
            trial[candidate] = normals[k]
            if abs(np.linalg.det(trial)) > 0.5:  # +-1 or 0: totally unimodular
                t, pivots[k] = trial, candidate
                break
    return t, pivots


def _probe(normal: NDArray[np.float64]) -> tuple[int, float, int, float]:
    """(i, n_i, j, n_j) of a normal with one or two non-zero entries (j = -1, n_j = 0 for one)."""
    entries = np.flatnonzero(normal)
    i = int(entries[0])
    j = int(entries[1]) if entries.size > 1 else -1
    return i, float(normal[i]), j, float(normal[j]) if j >= 0 else 0.0


class FlowLayout:
    """Matrices of every mode of one problem in the integrators' coordinates y = (w, v) (see the module docstring).

    Attributes
    ----------
    size, stop_count : int
        N coordinates, K stops.
    t, t_inverse : ndarray, shape (N, N)
        w = T x - d; x = T^-1 w + offset.
    offset : ndarray, shape (N,)
        T^-1 d [m].
    pivots : tuple of int
        Index into w of each stop's penetration (-1: computed from ``gap_rows``).
    gap_rows, gap_constants : ndarray, shapes (K, N) and (K,)
        u_k = gap_rows[k] . w + gap_constants[k] [m] (exactly e_p and 0 for a stop with a pivot).
    normals, clearances : ndarray
        n_k (K, N) and Delta_k (K,).
    free : tuple (A, c, b)
        The free flight: A (2N, 2N), c (2N,) [SI], b complex (2N,).
    stuck : tuple of (A, c, b)
        The flight stuck on each stop (for rigid stops).
    holding : tuple (H, h0, hb)
        lambda_k = H[k] . y + h0[k] + Re(hb[k] e^{jwt}) [N]: the force stop k must exert to hold its gap closed.
    kicks, masses : ndarray
        M^-1 n_k (K, N) [kg-1] and the effective masses m_k (K,) [kg].
    omega : float
        Angular frequency of the harmonic excitation (0 for a sweep) [rad s-1].
    """

    def __init__(self, problem: ImpactProblem, first: int = -1) -> None:
        structure = problem.structure
        n, stops = problem.size, problem.stops
        mass, stiffness, damping = structure.mass_matrix, structure.stiffness_matrix, structure.damping_matrix
        self.problem, self.first = problem, first
        self.size, self.stop_count = n, len(stops)
        self.normals, self.clearances = problem.normals(), problem.clearances()
        t, pivots = _pivots(self.normals, stops, n, first)
        inverse = np.linalg.inv(t)
        rounded = np.rint(inverse)
        self.t, self.t_inverse = t, (rounded if np.array_equal(t @ rounded, np.eye(n)) else inverse)
        self._identity = bool(np.array_equal(t, np.eye(n)))
        d = np.zeros(n)
        for k, p in enumerate(pivots):
            if p >= 0:
                d[p] = self.clearances[k]
        self.pivots = tuple(pivots)
        self.offset = self.t_inverse @ d
        # (offset, -0.0...): y[:2N] + this is x = w + offset and v unchanged to the bit (v + -0.0 = v, also for -0.0)
        self._shift = np.concatenate([self.offset, np.full(n, -0.0)])
        self.gap_rows = self.normals @ self.t_inverse
        self.gap_constants = self.normals @ self.offset - self.clearances
        for k, p in enumerate(pivots):
            if p >= 0:
                self.gap_rows[k] = 0.0
                self.gap_rows[k, p] = 1.0
                self.gap_constants[k] = 0.0
        self.kicks = np.linalg.solve(mass, self.normals.T).T.reshape(-1, n)
        self.masses = 1.0 / np.einsum("ki,ki->k", self.normals, self.kicks)
        self.reactions = self.kicks * self.masses[:, None]  # r_k = M^-1 n_k m_k
        #: the one velocity an impulse of each stop moves (an absolute stop on a decoupled mass), else -1
        self.kicked = tuple(
            int(np.flatnonzero(kick)[0]) if np.count_nonzero(kick) == 1 and np.count_nonzero(normal) == 1 and np.flatnonzero(kick)[0] == np.flatnonzero(normal)[0] else -1
            for kick, normal in zip(self.kicks, self.normals)
        )
        #: each stop's n_k . v as (i, n_ki, j, n_kj) with j = -1 for an absolute stop: for scalar arithmetic
        self.probes = tuple(_probe(normal) for normal in self.normals)
        self.omega = float(problem.omega) if isinstance(problem.excitation, HarmonicForce) else 0.0
        harmonic, static = problem.load()
        self.harmonic_load, self.static_load = harmonic, static
        # forces per unit of y: -K x - C v with x = T^-1 w + offset
        self.force_rows = np.hstack([-stiffness @ self.t_inverse, -damping])  # (N, 2N)
        self.force_constant = static - stiffness @ self.offset
        self.free = self._mode(mass, np.eye(n), self.force_rows, self.force_constant, harmonic, ())
        self.holding = (
            self.reactions @ self.force_rows,
            self.reactions @ self.force_constant,
            self.reactions @ harmonic,
        )
        self.stuck = tuple(
            self._mode(mass, np.eye(n) - np.outer(self.normals[k], self.reactions[k]), self.force_rows, self.force_constant, harmonic, (k,))
            for k in range(self.stop_count)
        )

    def _mode(self, mass: NDArray[np.float64], projection: NDArray[np.float64], rows: NDArray[np.float64], constant: NDArray[np.float64],
              harmonic: NDArray[np.complex128], held: tuple[int, ...]) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.complex128]]:
        """(A, c, b) of a flight with the force ``projection`` (f - C v - K x) and the pivots of ``held`` fixed."""
        n = self.size
        a = np.zeros((2 * n, 2 * n))
        a[:n, n:] = self.t
        for k in held:
            if self.pivots[k] >= 0:
                a[self.pivots[k], n:] = 0.0
        a[n:] = np.linalg.solve(mass, projection @ rows)
        c = np.zeros(2 * n)
        c[n:] = np.linalg.solve(mass, projection @ constant)
        b = np.zeros(2 * n, dtype=complex)
        b[n:] = np.linalg.solve(mass.astype(complex), projection @ harmonic)
        return a, c, b

    def bumper_mode(self, mass: NDArray[np.float64], active: tuple[int, ...], stiffness: NDArray[np.float64], damping: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(A, c) of a flight with the bumpers of the stops ``active`` pushing (K_k, B_k in ``stiffness``, ``damping``
        per stop): the force -n_k (K_k u_k + B_k n_k . v) added for each."""
        n = self.size
        rows, constant = self.force_rows.copy(), self.force_constant.copy()
        for k in active:
            push = np.concatenate([stiffness[k] * self.gap_rows[k], damping[k] * self.normals[k]])
            rows -= np.outer(self.normals[k], push)
            constant -= self.normals[k] * stiffness[k] * self.gap_constants[k]
        a = np.zeros((2 * n, 2 * n))
        a[:n, n:] = self.t
        a[n:] = np.linalg.solve(mass, rows)
        c = np.zeros(2 * n)
        c[n:] = np.linalg.solve(mass, constant)
        return a, c

    # ------------------------------------------------------------- conversions
    def internal(self, state: NDArray[np.float64]) -> NDArray[np.float64]:
        """(x, x') -> (w, v)."""
        n = self.size
        out = np.array(state[: 2 * n], dtype=float)
        out[:n] = self.t @ out[:n]
        for k, p in enumerate(self.pivots):
            if p >= 0:
                out[p] -= self.clearances[k]
        return out

    def physical(self, y: NDArray[np.float64]) -> NDArray[np.float64]:
        """(w, v, ...) -> (x, x')."""
        n = self.size
        if self._identity:
            return y[: 2 * n] + self._shift  # a new array (the hot path: every event and strobe)
        out = np.array(y[: 2 * n], dtype=float)
        out[:n] = self.t_inverse @ out[:n] + self.offset
        return out

    def penetration(self, y: NDArray[np.float64], stop: int) -> float:
        """u_k = n_k . x - Delta_k = -g_k [m] (positive: beyond the stop)."""
        p = self.pivots[stop]
        if p >= 0:
            return float(y[p])
        return float(self.gap_rows[stop] @ y[: self.size] + self.gap_constants[stop])

    def approach(self, y: NDArray[np.float64], stop: int) -> float:
        """n_k . v [m s-1] (positive: closing the gap)."""
        i, a, j, b = self.probes[stop]
        n = self.size
        return float(a * y[n + i] + b * y[n + j]) if j >= 0 else float(a * y[n + i])

    def set_approach(self, y: NDArray[np.float64], stop: int, value: float) -> None:
        """Make n_k . v = ``value`` in place: the correction along M^-1 n_k (an impulse of stop k's), then exact on
        the stop's first coordinate (for value 0 on a relative stop, v_i = v_j exactly: no round-off approach)."""
        n = self.size
        i, a, j, b = self.probes[stop]
        if j >= 0:
            residual = a * y[n + i] + b * y[n + j] - value
            y[n : 2 * n] -= residual * self.kicks[stop] * (self.masses[stop])
            y[n + i] = (value - b * y[n + j]) / a
        else:
            y[n + i] = value / a

    def carrying(self, stop: int) -> "FlowLayout":
        """The layout of the same problem in which ``stop`` has a pivot: this one if it has one, else the layout with
        the stop taken first (the other side of a two-sided stop then carries its own penetration, and the first
        side's is computed)."""
        return self if self.pivots[stop] >= 0 else flow_layout(self.problem, stop)

    def convert(self, y: NDArray[np.float64], source: "FlowLayout") -> NDArray[np.float64]:
        """The state y of layout ``source`` in this layout (a new array): a displacement whose row of T and offset are
        the same keeps its value, a pivot's is its stop's penetration in ``source``, any other is T x; velocities and
        the quadratures after them are unchanged."""
        n = self.size
        out = np.array(y, dtype=float)
        x = source.physical(y)[:n]
        owner = {p: k for k, p in enumerate(self.pivots) if p >= 0}
        old_owner = {p: k for k, p in enumerate(source.pivots) if p >= 0}
        for i in range(n):
            if owner.get(i, -1) == old_owner.get(i, -1):
                continue  # the same row of T and the same clearance
            out[i] = source.penetration(y, owner[i]) if i in owner else float(self.t[i] @ x)
        return out

    def close(self, y: NDArray[np.float64], stop: int) -> None:
        """Set stop ``stop``'s penetration to zero in place (the pivot, or the largest entry of its gap row)."""
        p = self.pivots[stop]
        if p < 0:
            row = self.gap_rows[stop]
            p = int(np.argmax(np.abs(row)))
            y[p] -= self.penetration(y, stop) / row[p]
            return
        y[p] = 0.0


@lru_cache(maxsize=64)
def flow_layout(problem: ImpactProblem, first: int = -1) -> FlowLayout:
    """The :class:`FlowLayout` of ``problem`` (cached: problems are frozen), its pivots chosen with stop ``first``
    (if >= 0) before the others."""
    return FlowLayout(problem, first)
