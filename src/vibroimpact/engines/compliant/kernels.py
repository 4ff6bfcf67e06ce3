"""The bumper model of :mod:`.model` as compiled kernels over one flat parameter array per contact mode
(:func:`pack_mode`): the right-hand side f(t, y) and the event functions, called by the residual and event callbacks
the SUNDIALS solvers are given (each call from Python costs about as much as one line of Python arithmetic did,
whatever the number of coordinates and stops).

State y (size 2 N + K + Q): (w, v) of :mod:`..flow_layout`, the running integral of each stop's bumper force, then Q
quadratures: none; for a sweep, the integrals of F_k cos(theta) theta' and F_k sin(theta) theta' per stop; for
harmonic moments, x_i cos(wt), x_i sin(wt) per coordinate, F_k cos(wt), F_k sin(wt) per stop, x_i^2 per coordinate.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

__all__ = ["pack_mode", "bumper_rhs", "bumper_residual", "bumper_events", "force_kernel", "NONE", "SWEEP", "MOMENTS"]

#: Quadrature kinds.
NONE, SWEEP, MOMENTS = 0, 1, 2
_N, _K, _SIZE, _MASK, _QUAD, _SWEPT, _OMEGA, _W0, _HALF_ALPHA, _A, _C, _BR, _BI, _LAM, _LAM0, _NORMAL, _T, _TINV, _XOFF, _LENGTH = range(20)
_HEADER = 20


def pack_mode(n: int, k: int, size: int, mask: int, quadratures: int, swept: bool, omega: float, w0: float, half_alpha: float,
              a: NDArray[np.float64], c: NDArray[np.float64], b: NDArray[np.complex128], force_rows: NDArray[np.float64],
              force_constants: NDArray[np.float64], normals: NDArray[np.float64], t: NDArray[np.float64], t_inverse: NDArray[np.float64],
              offset: NDArray[np.float64]) -> NDArray[np.float64]:
    """The parameter array of one contact mode (``mask``: bit k set while stop k's bumper pushes).

    ``a``, ``c``, ``b``: the mode's flow y' = A y + c + forcing, forcing Re(b e^{jwt}) (harmonic, w = ``omega``) or
    Re(b) sin(theta(t)) (a sweep, theta = t (w0 + half_alpha t)); ``force_rows`` and ``force_constants``: the bumper
    force K_k u_k + B_k n_k . v of each stop as a row over (w, v) plus a constant [N].
    """
    blocks = [a.ravel(), c, b.real.copy(), b.imag.copy(), force_rows.ravel(), force_constants, normals.ravel(), t.ravel(), t_inverse.ravel(), offset]
    header = np.zeros(_HEADER)
    header[:_A] = n, k, size, mask, quadratures, float(swept), omega, w0, half_alpha
    start = _HEADER
    for index, block in zip(range(_A, _LENGTH), blocks):
        header[index] = start
        start += block.size
    header[_LENGTH] = start
    return np.concatenate([header, *blocks]).astype(np.float64)


@njit(cache=True)
def force_kernel(y: NDArray[np.float64], p: NDArray[np.float64], stop: int) -> float:  # pragma: no cover - compiled
    """K_k u_k + B_k n_k . v [N]: the force stop ``stop``'s bumper exerts in contact (negative: it would pull)."""
    n2 = 2 * int(p[_N])
    row = int(p[_LAM]) + stop * n2
    value = p[int(p[_LAM0]) + stop]
    for j in range(n2):
        value += p[row + j] * y[j]
    return value


@njit(cache=True)
def bumper_rhs(t: float, y: NDArray[np.float64], f: NDArray[np.float64], p: NDArray[np.float64]) -> None:  # pragma: no cover - compiled
    """f(t, y) of the mode into ``f``."""
    n = int(p[_N])
    k_count = int(p[_K])
    n2 = 2 * n
    mask = int(p[_MASK])
    swept = p[_SWEPT] != 0.0
    a0, c0, br0, bi0 = int(p[_A]), int(p[_C]), int(p[_BR]), int(p[_BI])
    if swept:
        theta = t * (p[_W0] + p[_HALF_ALPHA] * t)
        c, s = math.cos(theta), math.sin(theta)
        for i in range(n2):
            acc = p[c0 + i] + p[br0 + i] * s
            for j in range(n2):
                acc += p[a0 + i * n2 + j] * y[j]
            f[i] = acc
    else:
        wt = p[_OMEGA] * t
        c, s = math.cos(wt), math.sin(wt)
        for i in range(n2):
            acc = p[c0 + i] + p[br0 + i] * c - p[bi0 + i] * s
            for j in range(n2):
                acc += p[a0 + i * n2 + j] * y[j]
            f[i] = acc
    quadratures = int(p[_QUAD])
    q = n2 + k_count
    for k in range(k_count):
        force = force_kernel(y, p, k) if (mask >> k) & 1 else 0.0
        f[n2 + k] = force
        if quadratures == 1:
            rate = force * (p[_W0] + 2.0 * p[_HALF_ALPHA] * t)
            f[q + 2 * k] = rate * c
            f[q + 2 * k + 1] = rate * s
        elif quadratures == 2:
            f[q + 2 * n + 2 * k] = force * c
            f[q + 2 * n + 2 * k + 1] = force * s
    if quadratures == 2:
        tinv, xoff = int(p[_TINV]), int(p[_XOFF])
        for i in range(n):
            x = p[xoff + i]
            for j in range(n):
                x += p[tinv + i * n + j] * y[j]
            f[q + 2 * i] = x * c
            f[q + 2 * i + 1] = x * s
            f[q + 2 * n + 2 * k_count + i] = x * x


@njit(cache=True)
def bumper_residual(t: float, y: NDArray[np.float64], yp: NDArray[np.float64], res: NDArray[np.float64], p: NDArray[np.float64]) -> None:  # pragma: no cover
    """The residual y' - f(t, y) into ``res``."""
    bumper_rhs(t, y, res, p)
    for i in range(res.size):
        res[i] = yp[i] - res[i]


@njit(cache=True)
def bumper_events(t: float, y: NDArray[np.float64], yp: NDArray[np.float64], out: NDArray[np.float64], p: NDArray[np.float64]) -> None:  # pragma: no cover
    """The mode's event functions: first one terminal event per stop (onset in flight, release in contact), then the
    recorded ones of each stop in turn (in flight its apex, n_k . v falling; in contact its force rate, falling,
    and the jerk of n_k . x, rising). Rates use the y' given (IDA's interpolant) for the accelerations."""
    n = int(p[_N])
    k_count = int(p[_K])
    n2 = 2 * n
    mask = int(p[_MASK])
    a0, normal, tt = int(p[_A]), int(p[_NORMAL]), int(p[_T])
    slot = k_count
    for k in range(k_count):
        row = int(p[_LAM]) + k * n2
        stiffness_part = p[int(p[_LAM0]) + k]
        for j in range(n):
            stiffness_part += p[row + j] * y[j]
        force = force_kernel(y, p, k)
        if (mask >> k) & 1:
            out[k] = -force
            # force rate: the stiffness row times w' = T v, the damping row times v' (IDA's)
            rate = 0.0
            for j in range(n):
                w_rate = 0.0
                for m in range(n):
                    w_rate += p[tt + j * n + m] * y[n + m]
                rate += p[row + j] * w_rate + p[row + n + j] * yp[n + j]
            # jerk of n . x: n . d(v')/dt with d(v')/dt = A_v (w', v') + the forcing's rate
            jerk = 0.0
            for i in range(n):
                weight = p[normal + k * n + i]
                if weight == 0.0:
                    continue
                acc = _forcing_rate(t, p, n + i)
                for j in range(n):
                    w_rate = 0.0
                    for m in range(n):
                        w_rate += p[tt + j * n + m] * y[n + m]
                    acc += p[a0 + (n + i) * n2 + j] * w_rate + p[a0 + (n + i) * n2 + n + j] * yp[n + j]
                jerk += weight * acc
            out[slot] = rate
            out[slot + 1] = jerk
            slot += 2
        else:
            # onset: K u short of the bumper; within its reach (u >= 0) the force it would exert (K u + B n . v)
            out[k] = force if stiffness_part >= 0.0 else stiffness_part
            speed = 0.0
            for j in range(n):
                speed += p[normal + k * n + j] * y[n + j]
            out[slot] = speed
            slot += 1


@njit(cache=True)
def _forcing_rate(t: float, p: NDArray[np.float64], i: int) -> float:  # pragma: no cover - compiled
    """d/dt of row i's forcing: -w (Re b sin + Im b cos)(wt), or Re b cos(theta) theta' for a sweep."""
    br, bi = p[int(p[_BR]) + i], p[int(p[_BI]) + i]
    if br == 0.0 and bi == 0.0:
        return 0.0
    if p[_SWEPT] != 0.0:
        theta = t * (p[_W0] + p[_HALF_ALPHA] * t)
        return br * math.cos(theta) * (p[_W0] + 2.0 * p[_HALF_ALPHA] * t)
    wt = p[_OMEGA] * t
    return -p[_OMEGA] * (br * math.sin(wt) + bi * math.cos(wt))
