"""The compiled kernels of a piece of flow, shared by the ``exact`` and ``compliant_exact`` loops: the modal
coordinates of a piece from its start, the state at a time on it, the amplitudes of an observable h = w . y + offset
along it, and the same amplitudes kept once per conjugate pair.

Flows are stacked as :func:`~vibroimpact.engines.exact.stack_flows` stacks them (see
:mod:`~vibroimpact.engines.exact_core`): ``lams[f, :counts[f]]`` the nonzero eigenvalues of flow f, ``vecs[f]`` (n, m)
their eigenvectors, ``invs[f]`` (m, n) the rows giving the modal coordinates, ``hrms[f]`` the amplitude Y of the
harmonic particular solution Re(Y e^{jwt}), ``csts[f]`` the constant one; where ``polys[f]`` (rigid-body modes), the
polynomial part z0 + q1 tau + q2 tau^2 from the projector ``zpros[f]``, the nilpotent ``znils[f]`` and the drifts
``zdrvs[f]``, ``zdrv2s[f]``.

numba's disk cache keys a compiled function on its own source file only; the compiled functions of a module that
calls these kernels (or reads these constants) are stamped with this file's source as well, as these would be with
the sources of any other module they read (:mod:`~vibroimpact.engines.numba_cache`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from vibroimpact.engines.numba_cache import stamp_with_callees

__all__ = ["NONE", "ZERO", "YES", "modal_coordinates", "polynomial_part", "piece_state", "observable", "halve_pairs"]

#: -1 (no stop, no event), 0 and True as typed values, not literals: numba compiles a callee once per literal argument
#: (and a variable first set to a literal is typed as one in the first pass of type inference), so each literal call
#: site compiled its callees a second time (17 of the 56 compilations of a cold start).
NONE, ZERO, YES = np.int64(-1), np.int64(0), np.bool_(True)


# ------------------------------------------------------------------------------------------------ a piece of flow f
@njit(cache=True, error_model="numpy")
def modal_coordinates(lams, invs, hrms, csts, f, m, omega, t0, y0, out):
    """Modal coordinates of the homogeneous part of flow f through y0 at t0, into ``out[:m]``."""
    phasor = complex(math.cos(omega * t0), math.sin(omega * t0))
    for r in range(m):
        out[r] = 0j
    for i in range(y0.size):
        rel = y0[i] - ((hrms[f, i] * phasor).real + csts[f, i])
        for r in range(m):
            out[r] += invs[f, r, i] * rel


@njit(cache=True, error_model="numpy")
def polynomial_part(zpros, znils, zdrvs, zdrv2s, hrms, csts, f, omega, t0, y0, z0, q1, q2):
    """The polynomial part through y0 at t0: z0 = P_z (y0 - p(t0)), q1 = A_z z0 + c, q2 = A_z c / 2."""
    n = y0.size
    phasor = complex(math.cos(omega * t0), math.sin(omega * t0))
    for r in range(n):
        acc = 0.0
        for i in range(n):
            acc += zpros[f, r, i] * (y0[i] - ((hrms[f, i] * phasor).real + csts[f, i]))
        z0[r] = acc
    for r in range(n):
        acc = zdrvs[f, r]
        for i in range(n):
            acc += znils[f, r, i] * z0[i]
        q1[r] = acc
        q2[r] = zdrv2s[f, r]


@njit(cache=True, error_model="numpy")
def piece_state(lams, vecs, hrms, csts, f, m, omega, t0, modal, t, out, poly, z0, q1, q2):
    """The state of the piece at t, into ``out``."""
    phasor = complex(math.cos(omega * t), math.sin(omega * t))
    for r in range(out.size):
        out[r] = (hrms[f, r] * phasor).real + csts[f, r]
    for i in range(m):
        rate = lams[f, i]
        if rate.imag < 0.0:
            continue  # its conjugate's term, doubled, stands for both (the state is real)
        growth = np.exp(rate * (t - t0)) * modal[i] * (2.0 if rate.imag > 0.0 else 1.0)
        for r in range(out.size):
            out[r] += (vecs[f, r, i] * growth).real
    if poly:
        tau = t - t0
        for r in range(out.size):
            out[r] += z0[r] + (q1[r] + q2[r] * tau) * tau


@njit(cache=True, error_model="numpy")
def observable(weights, row, offset, extra, vecs, hrms, csts, f, m, modal, amp, poly, z0, q1, q2):
    """h = weights[row] . y + offset (+ Re(extra e^{jwt})) of the piece with ``modal`` coordinates: amplitudes into
    ``amp[0, :m]``; returns (har, con, p1, p2)."""
    n = weights.shape[1]
    for i in range(m):
        acc = 0j
        for r in range(n):
            acc += weights[row, r] * vecs[f, r, i]
        amp[0, i] = acc * modal[i]
    har = 0j
    con = offset
    for r in range(n):
        har += weights[row, r] * hrms[f, r]
        con += weights[row, r] * csts[f, r]
    har += extra
    p1 = 0.0
    p2 = 0.0
    if poly:
        for r in range(n):
            con += weights[row, r] * z0[r]
            p1 += weights[row, r] * q1[r]
            p2 += weights[row, r] * q2[r]
    return har, con, p1, p2


@njit(cache=True, error_model="numpy")
def halve_pairs(lams, f, m, amp, out, row):
    """Amplitudes on the half rates (Im >= 0) into ``out[row]``: Re(a e^{lt}) + Re(conj) = Re(2 a e^{lt}), so each pair
    is kept once, doubled (every evaluation of the observable then costs half)."""
    count = 0
    for i in range(m):
        if lams[f, i].imag > 0.0:
            out[row, count] = 2.0 * amp[0, i]
            count += 1
        elif lams[f, i].imag == 0.0:
            out[row, count] = amp[0, i]
            count += 1


stamp_with_callees(globals())
