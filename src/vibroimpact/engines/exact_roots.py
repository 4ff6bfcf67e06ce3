"""The compiled guaranteed root search on an observable of a piece, shared by the ``exact`` and ``compliant_exact``
loops: h(t) = Re(sum amp_i e^{lam_i tau} + har e^{jwt}) + con + p1 tau + p2 tau^2 (tau = t - t0), its derivatives,
bounds of its derivatives over [t, inf), the first time it reaches 0 from below (Taylor bounds: none missed, however
tangent; see :func:`vibroimpact.engines.linear_flow.first_crossing`, the same algorithm in Python), and its largest
interior maximum (a closest approach).

An observable is indexed in stacked arrays, never sliced: rates ``rates[rr, :rc]``, amplitudes ``amp[ar]``.

numba's disk cache keys a compiled function on its own source file only; the compiled functions of a module that
calls these kernels are stamped with this file's source as well, and these with the source of
:mod:`~vibroimpact.engines.exact_pieces`, whose ``ZERO`` they hold as a constant
(:mod:`~vibroimpact.engines.numba_cache`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from vibroimpact.engines.exact_pieces import ZERO
from vibroimpact.engines.numba_cache import stamp_with_callees

__all__ = ["observable_value", "observable_derivatives", "escape_step", "round_off_band", "first_crossing", "closest_approach"]


# ---------------------------------------------------------------- an observable: rates[rr, :rc], amplitudes amp[ar]
@njit(cache=True, error_model="numpy")
def observable_value(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, t):
    """h(t)."""
    total = har * complex(math.cos(omega * t), math.sin(omega * t))
    for i in range(rc):
        total += amp[ar, i] * np.exp(rates[rr, i] * (t - t0))
    tau = t - t0
    return total.real + con + (p1 + p2 * tau) * tau


@njit(cache=True, error_model="numpy")
def observable_derivatives(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, t, out):
    """h, h', ..., h^(len(out) - 1) at t."""
    forced = har * complex(math.cos(omega * t), math.sin(omega * t))
    jw = 1j * omega
    power = 1.0 + 0j
    for k in range(out.size):
        out[k] = (forced * power).real + (con if k == 0 else 0.0)
        power *= jw
    for i in range(rc):
        rate = rates[rr, i]
        term = amp[ar, i] * np.exp(rate * (t - t0))
        for k in range(out.size):
            out[k] += term.real
            term *= rate
    tau = t - t0
    out[0] += (p1 + p2 * tau) * tau
    if out.size > 1:
        out[1] += p1 + 2.0 * p2 * tau
    if out.size > 2:
        out[2] += 2.0 * p2


@njit(cache=True, error_model="numpy")
def _bound(rates, rr, rc, amp, ar, har, p1, p2, omega, t0, t, order):
    """An upper bound of |h^(order)| over [t, inf) (all Re(lam) <= 0) for order >= 2; for orders 0 and 1, whose
    polynomial part grows, its size at t (a scale)."""
    total = abs(har) * omega**order
    for i in range(rc):
        total += abs(amp[ar, i]) * abs(rates[rr, i]) ** order * math.exp(rates[rr, i].real * (t - t0))
    tau = t - t0
    if order == 0:
        total += (abs(p1) + abs(p2) * tau) * tau
    elif order == 1:
        total += abs(p1) + 2.0 * abs(p2) * tau
    elif order == 2:
        total += 2.0 * abs(p2)
    return total


@njit(cache=True, error_model="numpy")
def _step_data(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, t):
    """h, h', h'' at t and bounds of |h''|, |h'''| over [t, inf), in one pass (the root search's inner loop)."""
    h0 = 0j
    h1 = 0j
    h2 = 0j
    magnitude = abs(har)
    bound2 = magnitude * omega * omega
    bound3 = bound2 * omega
    for i in range(rc):
        l = rates[rr, i]
        term = amp[ar, i] * np.exp(l * (t - t0))
        h0 += term
        h1 += term * l
        h2 += term * l * l
        size = abs(term) * (l.real * l.real + l.imag * l.imag)
        bound2 += size
        bound3 += size * abs(l)
    forced = har * complex(math.cos(omega * t), math.sin(omega * t))
    tau = t - t0
    return (
        (h0 + forced).real + con + (p1 + p2 * tau) * tau,
        (h1 + forced * 1j * omega).real + p1 + 2.0 * p2 * tau,
        (h2 - forced * omega * omega).real + 2.0 * p2,
        bound2 + 2.0 * abs(p2),
        bound3,
    )


@njit(cache=True, error_model="numpy")
def escape_step(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, t, band):
    """A step over which h stays < 0 from h(t) = 0 when h leaves the surface; -1.0 if it does not leave (orders up to
    4); with ``band`` >= 0 (h's round-off), a rise that peaks within it is stepped over (see linear_flow.escape_step
    and linear_flow.tangency_step)."""
    values = np.empty(5)
    observable_derivatives(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, t, values)
    for k in range(1, 5):
        scale = _bound(rates, rr, rc, amp, ar, har, p1, p2, omega, t0, t, k)
        if values[k] < -1e-9 * scale:
            return -(k + 1) * values[k] / _bound(rates, rr, rc, amp, ar, har, p1, p2, omega, t0, t, k + 1)
        if values[k] > 1e-9 * scale:
            if band < 0.0 or k == 4 or values[k + 1] >= 0.0:
                return -1.0
            s0 = -(k + 1) * values[k] / values[k + 1]
            factorial = 1.0  # (k + 1)!
            for i in range(2, k + 2):
                factorial *= i
            peak = values[0] + (k * s0 / (k + 1)) ** k * values[k] / factorial
            slack = _bound(rates, rr, rc, amp, ar, har, p1, p2, omega, t0, t, k + 2) * s0 ** (k + 2) / (factorial * (k + 2))
            term = 1.0  # s0^j / j!
            for j in range(1, k):
                term *= s0 / j
                slack += abs(values[j]) * term
            return s0 if peak + slack <= band else -1.0
    return -1.0


@njit(cache=True, error_model="numpy")
def round_off_band(rc, amp, ar, har, con, p1, p2, tau, tolerance):
    """How accurately h can be evaluated at t0 + tau: ``tolerance``, or 1e-15 of its largest terms if that is more."""
    size = abs(har) + abs(con) + (abs(p1) + abs(p2) * tau) * tau
    for i in range(rc):
        size += abs(amp[ar, i])
    return max(tolerance, 1e-15 * size)


@njit(cache=True, error_model="numpy")
def _quadratic_step(h0, h1, curvature):
    if curvature <= 0.0 and h1 <= 0.0:
        return math.inf
    return 2.0 * -h0 / (h1 + math.sqrt(h1 * h1 - 2.0 * curvature * h0))


@njit(cache=True, error_model="numpy")
def _polish(h0, h1, h2):
    """The step onto the root of the local quadratic model (see linear_flow.polish_step)."""
    newton = -h0 / h1
    if h0 < 0.0 and h2 > 0.0:
        return min(newton, _quadratic_step(h0, h1, h2))
    return newton


@njit(cache=True, error_model="numpy")
def first_crossing(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, t_from, t_to, tolerance, leaving):
    """First time in (t_from, t_to] at which h reaches 0 from below; NaN if none (see linear_flow.first_crossing)."""
    tolerance = round_off_band(rc, amp, ar, har, con, p1, p2, t_from - t0, tolerance)
    pair = np.empty(2)
    t = t_from
    if leaving:
        if observable_value(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, t) >= -tolerance:
            step = escape_step(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, t, tolerance)
            if step < 0.0:
                if _bound(rates, rr, rc, amp, ar, har, 0.0, 0.0, omega, t0, t, ZERO) <= tolerance and abs(p1) + abs(p2) <= tolerance:
                    return math.nan
                return t_from
            t += step
            if t >= t_to:
                return math.nan
    departing = leaving
    while True:
        h0, h1, h2, curvature, jerk = _step_data(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, t)
        if departing and h0 >= -8.0 * tolerance:
            step = escape_step(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, t, tolerance)
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
            observable_derivatives(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, t_to, pair)
            return t_to if pair[0] >= -tolerance or (pair[0] >= -8.0 * tolerance and pair[1] > 0.0) else math.nan
        if t + step == t:
            return t
        t += step


@njit(cache=True, error_model="numpy")
def closest_approach(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, ta, tb, fastest, best, stop):
    """Largest interior local maximum of h on (ta, tb) (h' from + to -), if above best[0]: stored in best."""
    chunks = max(2, int(math.ceil(fastest * (tb - ta) / 0.5)))
    d = np.empty(3)
    t_prev = ta
    observable_derivatives(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, ta, d)
    slope_prev = d[1]
    for c in range(1, chunks + 1):
        t = ta + (tb - ta) * c / chunks
        observable_derivatives(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, t, d)
        if slope_prev > 0.0 and d[1] < 0.0:
            lo, hi = t_prev, t
            for _ in range(200):  # bisection on h' (sign + at lo, - at hi)
                mid = 0.5 * (lo + hi)
                if mid <= lo or mid >= hi:
                    break
                observable_derivatives(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, mid, d)
                if d[1] > 0.0:
                    lo = mid
                else:
                    hi = mid
            observable_derivatives(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, lo, d)
            if lo > ta and lo < tb and d[0] > best[0]:
                best[0], best[1], best[2] = d[0], lo, stop
            observable_derivatives(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, t, d)
        slope_prev, t_prev = d[1], t


stamp_with_callees(globals())
