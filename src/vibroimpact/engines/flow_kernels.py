"""Compiled closed-form pieces of a harmonically forced linear flow: states, observables, their derivatives and
bounds, and the guaranteed first-root search (the numba twins of :mod:`.linear_flow`, used by :mod:`.exact_core`).

A flow is passed as arrays: ``lam`` (n,) eigenvalues, ``vec`` (n, n) eigenvectors, ``inv`` (n, n) their inverse,
``hrm`` (n,) the complex amplitude Y of the harmonic particular solution Re(Y e^{jwt}), ``cst`` (n,) the constant
particular solution. An observable h = w . y + offset of a piece from (t0, y0) is ``amp`` (n,) complex (one per
eigenvalue), ``har`` (complex), ``con`` (float): h(t) = Re(sum amp_i e^{lam_i (t - t0)} + har e^{jwt}) + con.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["modal", "state", "observable", "value", "derivatives", "escape_step", "first_crossing"]


@njit(cache=True)
def modal(lam, vec, inv, hrm, cst, omega, t0, y0, out):
    """Modal coordinates of the homogeneous part through y0 at t0, into ``out``."""
    n = lam.size
    phasor = complex(math.cos(omega * t0), math.sin(omega * t0))
    for r in range(n):
        out[r] = 0j
    for i in range(n):
        rel = y0[i] - ((hrm[i] * phasor).real + cst[i])
        for r in range(n):
            out[r] += inv[r, i] * rel


@njit(cache=True)
def state(lam, vec, hrm, cst, omega, t0, modal, t, out):
    n = lam.size
    phasor = complex(math.cos(omega * t), math.sin(omega * t))
    for r in range(n):
        out[r] = (hrm[r] * phasor).real + cst[r]
    for i in range(n):
        growth = np.exp(lam[i] * (t - t0)) * modal[i]
        for r in range(n):
            out[r] += (vec[r, i] * growth).real


@njit(cache=True)
def observable(weights, offset, vec, hrm, cst, modal, amp):
    """h = weights . y + offset of the piece with ``modal`` coordinates: amplitudes into ``amp``; (har, con)."""
    n = modal.size
    har = 0j
    con = offset
    for i in range(n):
        acc = 0j
        for r in range(n):
            acc += weights[r] * vec[r, i]
        amp[i] = acc * modal[i]
        har += weights[i] * hrm[i]
        con += weights[i] * cst[i]
    return har, con


@njit(cache=True)
def value(lam, amp, har, con, omega, t0, t):
    """h(t)."""
    total = har * complex(math.cos(omega * t), math.sin(omega * t))
    for i in range(lam.size):
        total += amp[i] * np.exp(lam[i] * (t - t0))
    return total.real + con


@njit(cache=True)
def derivatives(lam, amp, har, con, omega, t0, t, out):
    """h, h', ..., h^(len(out) - 1) at t."""
    forced = har * complex(math.cos(omega * t), math.sin(omega * t))
    jw = 1j * omega
    power = 1.0 + 0j
    for k in range(out.size):
        out[k] = (forced * power).real + (con if k == 0 else 0.0)
        power *= jw
    for i in range(lam.size):
        term = amp[i] * np.exp(lam[i] * (t - t0))
        for k in range(out.size):
            out[k] += term.real
            term *= lam[i]


@njit(cache=True)
def _bound(lam, amp, har, omega, t0, t, order):
    """An upper bound of |h^(order)| over [t, inf) (all Re(lam) <= 0)."""
    total = abs(har) * omega**order
    for i in range(lam.size):
        total += abs(amp[i]) * abs(lam[i]) ** order * math.exp(lam[i].real * (t - t0))
    return total


@njit(cache=True)
def _step_data(lam, amp, har, con, omega, t0, t):
    h0 = 0j
    h1 = 0j
    h2 = 0j
    magnitude = abs(har)
    bound2 = magnitude * omega * omega
    bound3 = bound2 * omega
    for i in range(lam.size):
        term = amp[i] * np.exp(lam[i] * (t - t0))
        l = lam[i]
        h0 += term
        h1 += term * l
        h2 += term * l * l
        size = abs(term) * (l.real * l.real + l.imag * l.imag)
        bound2 += size
        bound3 += size * abs(l)
    forced = har * complex(math.cos(omega * t), math.sin(omega * t))
    return (h0 + forced).real + con, (h1 + forced * 1j * omega).real, (h2 - forced * omega * omega).real, bound2, bound3


@njit(cache=True)
def escape_step(lam, amp, har, con, omega, t0, t):
    """A step over which h stays < 0 from h(t) = 0 when h leaves the surface; -1.0 if it does not leave."""
    values = np.empty(4)
    derivatives(lam, amp, har, con, omega, t0, t, values)
    for k in range(1, 4):
        scale = _bound(lam, amp, har, omega, t0, t, k)
        if values[k] < -1e-9 * scale:
            return -(k + 1) * values[k] / _bound(lam, amp, har, omega, t0, t, k + 1)
        if values[k] > 1e-9 * scale:
            return -1.0
    return -1.0


@njit(cache=True)
def _quadratic_step(h0, h1, curvature):
    if curvature <= 0.0 and h1 <= 0.0:
        return math.inf
    return 2.0 * -h0 / (h1 + math.sqrt(h1 * h1 - 2.0 * curvature * h0))


@njit(cache=True)
def _polish(h0, h1, h2):
    """The step onto the root of the local quadratic model (see linear_flow.polish_step)."""
    newton = -h0 / h1
    if h0 < 0.0 and h2 > 0.0:
        return min(newton, _quadratic_step(h0, h1, h2))
    return newton


@njit(cache=True)
def first_crossing(lam, amp, har, con, omega, t0, t_from, t_to, tolerance, leaving):
    """First time in (t_from, t_to] at which h reaches 0 from below; NaN if none (see linear_flow.first_crossing)."""
    size = abs(har) + abs(con)
    for i in range(amp.size):
        size += abs(amp[i])
    tolerance = max(tolerance, 1e-15 * size)
    pair = np.empty(2)
    t = t_from
    if leaving:
        if value(lam, amp, har, con, omega, t0, t) >= -tolerance:
            step = escape_step(lam, amp, har, con, omega, t0, t)
            if step < 0.0:
                if _bound(lam, amp, har, omega, t0, t, 0) <= tolerance:
                    return math.nan
                return t_from
            t += step
            if t >= t_to:
                return math.nan
    departing = leaving
    while True:
        h0, h1, h2, curvature, jerk = _step_data(lam, amp, har, con, omega, t0, t)
        if departing and h0 >= -8.0 * tolerance:
            step = escape_step(lam, amp, har, con, omega, t0, t)
            if step >= 0.0:
                if t + step >= t_to:
                    return math.nan
                if t + step == t:
                    return t
                t += step
                continue
        if h0 >= -tolerance:
            if h1 > 0.0:
                t = max(t + _polish(h0, h1, h2), t_from)
            return t
        departing = departing and h0 >= -8.0 * tolerance
        step = _quadratic_step(h0, h1, curvature)
        trial = 2.0 * step
        step = max(step, min(_quadratic_step(h0, h1, max(h2 + jerk * trial / 3.0, 0.0)), trial))
        if t + step >= t_to:
            # h < 0 on [t, t_to); a root at t_to (an impact on a period boundary) is still a root, and so is one
            # within a few round-off units of it, arriving: it is applied before the strobe, not after it
            derivatives(lam, amp, har, con, omega, t0, t_to, pair)
            return t_to if pair[0] >= -tolerance or (pair[0] >= -8.0 * tolerance and pair[1] > 0.0) else math.nan
        if t + step == t:
            return t
        t += step
