"""The small array kernels both compiled loops share (the ``exact`` engine's :mod:`~vibroimpact.engines.exact_core` and
the ``compliant_exact`` loop): a flow's state-transition matrix, the in-place left product that chains a period's
Jacobian, a period's end recorded (its strobe and Jacobian), and an output array grown by rows.

Flows are stacked as :mod:`~vibroimpact.engines.exact_core` describes (``lams``, ``vecs``, ``invs``; ``zpros``,
``znils`` where ``polys[f]``). The compiled functions of a module that calls these are stamped with this file's source
as well (:mod:`~vibroimpact.engines.numba_cache`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from vibroimpact.engines.numba_cache import stamp_with_callees

__all__ = ["transition_matrix", "left_multiply", "end_period", "grow_rows"]


@njit(cache=True, error_model="numpy")
def transition_matrix(lams, vecs, invs, f, m, dt, poly, zpros, znils, out):
    """exp(A dt) of flow f: Re(V diag(e^{lam dt}) V^+) (+ P_z + A_z dt), into ``out`` (n x n)."""
    n = out.shape[0]
    for r in range(n):
        for c in range(n):
            out[r, c] = 0.0
    for i in range(m):
        g = np.exp(lams[f, i] * dt)
        for r in range(n):
            left = vecs[f, r, i] * g
            for c in range(n):
                out[r, c] += (left * invs[f, i, c]).real
    if poly:
        for r in range(n):
            for c in range(n):
                out[r, c] += zpros[f, r, c] + znils[f, r, c] * dt


@njit(cache=True, error_model="numpy")
def left_multiply(factor, jac, work):
    """jac <- factor @ jac (n x n), through ``work``."""
    n = jac.shape[0]
    for r in range(n):
        for c in range(n):
            acc = 0.0
            for m in range(n):
                acc += factor[r, m] * jac[m, c]
            work[r, c] = acc
    for r in range(n):
        for c in range(n):
            jac[r, c] = work[r, c]


@njit(cache=True, error_model="numpy")
def end_period(k, y, strobes, want_jacobians, jac, jacobians):
    """The end of period k: the state ``y`` as ``strobes[k]`` and, if wanted, the period's Jacobian ``jac`` as
    ``jacobians[k - 1]``, ``jac`` then the identity again (the next period's product starts)."""
    n = y.size
    for r in range(n):
        strobes[k, r] = y[r]
    if want_jacobians:
        for r in range(n):
            for c in range(n):
                jacobians[k - 1, r, c] = jac[r, c]
                jac[r, c] = 1.0 if r == c else 0.0


@njit(cache=True, error_model="numpy")
def grow_rows(array, rows):
    bigger = np.empty((max(2 * array.shape[0], rows),) + array.shape[1:], dtype=array.dtype)
    # the old rows lead a new C-ordered array, so a flat copy fills them; element by element, since an array-to-slice
    # copy compiles numba's shape-error text (~1.5 s of a cold compile)
    old, flat = np.ascontiguousarray(array).reshape(-1), bigger.reshape(-1)
    for i in range(old.size):
        flat[i] = old[i]
    return bigger


stamp_with_callees(globals())
