"""The compiled core of the ``exact`` engine: its whole event loop in one numba function, with the exact Jacobian.

Everything the loop calls lives in this one module on purpose, which is why it is longer than the house's ~400
lines: numba's on-disk cache is keyed by the source file of each cached function only, so a change in a function
called from another file would not recompile its callers (numba PR #8396, unmerged); a kernel module beside this one
served stale machine code after an edit.

The algorithm is :mod:`~vibroimpact.engines.exact_python`'s (closed-form flow, guaranteed first-root search by Taylor bounds, impact map,
sticking and release, strobes, Fourier moments), compiled with ``@njit(cache=True)``: the interpreter overhead of the
pure-Python loop was ~97 % of its cost (the README of c3744b1, "Speed: before and after the compiled core"). It runs any N-dof
structure (state y = (x, x') of n = 2 N entries) with any K rigid stops. Flows (:mod:`~vibroimpact.engines.exact_flows`) are passed
stacked, flow 0 the free flight and flow 1 + k the flight held on stop k, all in the full state's coordinates:

* ``lams[f, :counts[f]]`` the nonzero eigenvalues, ``vecs[f]`` (n, m) their eigenvectors, ``invs[f]`` (m, n) the
  rows giving the modal coordinates, ``hrms[f]`` the amplitude Y of the harmonic particular solution Re(Y e^{jwt}),
  ``csts[f]`` the constant one; where ``polys[f]`` (rigid-body modes), the polynomial part z0 + q1 tau + q2 tau^2
  from the projector ``zpros[f]``, the nilpotent ``znils[f]`` and the drifts ``zdrvs[f]`` (c), ``zdrv2s[f]`` (q2).
* an observable h = w . y + offset of a piece from (t0, y0) is its amplitudes (one per eigenvalue; the root search
  keeps one of each conjugate pair, doubled: ``hlams[f, :hcounts[f]]``), ``har`` (complex), ``con``, ``p1``, ``p2``:
  h(t) = Re(sum amp_i e^{lam_i tau} + har e^{jwt}) + con + p1 tau + p2 tau^2, tau = t - t0. The loop watches one
  observable per stop: the gap's n_k . x - Delta_k in free flight, minus the holding force while held on stop k.

Helpers index the stacked arrays (flow f, stop j) instead of receiving slices: an array view made in the loop, or an
array variable reassigned in it, costs numba's atomic reference counting, which took ~20 % of a run.

The Jacobian of the stroboscopic map is the product, over the pieces of a period, of the state-transition matrices
Re(V diag(e^{lam dt}) V^+) + P_z + A_z dt and of the saltation matrix of each event (Leine & Nijmeijer; di Bernardo et
al.): an impact on stop k maps y+ = D y- (D restitutes n_k . x' along M^-1 n_k, or cancels it when it sticks) and gives
S = D + (f(y+) - D f(y-)) (grad g)^T / (grad g . f(y-)) with grad g = (n_k, 0); a release is continuous in y and in the
vector field (the stop lets go at zero holding force), so its saltation matrix is the identity. While held, the
transition matrix of the lifted flow projects onto the stop's surface.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["run_periods", "sample_states", "moment_rates", "STATUS_OK", "STATUS_NO_PROGRESS", "STATUS_TWO_STICKS"]

STATUS_OK, STATUS_NO_PROGRESS, STATUS_TWO_STICKS = 0, 1, 2
#: -1 (no stop, no event), 0 and True as typed values, not literals: numba compiles a callee once per literal argument
#: (and a variable first set to a literal is typed as one in the first pass of type inference), so each literal call
#: site compiled its callees a second time (17 of the 56 compilations of a cold start).
_NONE, _ZERO, _YES = np.int64(-1), np.int64(0), np.bool_(True)


# ------------------------------------------------------------------------------------------------ a piece of flow f
@njit(cache=True, error_model="numpy")
def _modal(lams, invs, hrms, csts, f, m, omega, t0, y0, out):
    """Modal coordinates of the homogeneous part of flow f through y0 at t0, into ``out[:m]``."""
    phasor = complex(math.cos(omega * t0), math.sin(omega * t0))
    for r in range(m):
        out[r] = 0j
    for i in range(y0.size):
        rel = y0[i] - ((hrms[f, i] * phasor).real + csts[f, i])
        for r in range(m):
            out[r] += invs[f, r, i] * rel


@njit(cache=True, error_model="numpy")
def _rigid(zpros, znils, zdrvs, zdrv2s, hrms, csts, f, omega, t0, y0, z0, q1, q2):
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
def _state(lams, vecs, hrms, csts, f, m, omega, t0, modal, t, out, poly, z0, q1, q2):
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
def _observable(weights, row, offset, extra, vecs, hrms, csts, f, m, modal, amp, poly, z0, q1, q2):
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
def _halve(lams, f, m, amp, out, row):
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


# ---------------------------------------------------------------- an observable: rates[rr, :rc], amplitudes amp[ar]
@njit(cache=True, error_model="numpy")
def _value(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, t):
    """h(t)."""
    total = har * complex(math.cos(omega * t), math.sin(omega * t))
    for i in range(rc):
        total += amp[ar, i] * np.exp(rates[rr, i] * (t - t0))
    tau = t - t0
    return total.real + con + (p1 + p2 * tau) * tau


@njit(cache=True, error_model="numpy")
def _derivatives(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, t, out):
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
def _escape_step(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, t, band):
    """A step over which h stays < 0 from h(t) = 0 when h leaves the surface; -1.0 if it does not leave (orders up to
    4); with ``band`` >= 0 (h's round-off), a rise that peaks within it is stepped over (see linear_flow.escape_step
    and linear_flow.tangency_step)."""
    values = np.empty(5)
    _derivatives(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, t, values)
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
def _round_off(rc, amp, ar, har, con, p1, p2, tau, tolerance):
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
def _first_crossing(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, t_from, t_to, tolerance, leaving):
    """First time in (t_from, t_to] at which h reaches 0 from below; NaN if none (see linear_flow.first_crossing)."""
    tolerance = _round_off(rc, amp, ar, har, con, p1, p2, t_from - t0, tolerance)
    pair = np.empty(2)
    t = t_from
    if leaving:
        if _value(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, t) >= -tolerance:
            step = _escape_step(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, t, tolerance)
            if step < 0.0:
                if _bound(rates, rr, rc, amp, ar, har, 0.0, 0.0, omega, t0, t, _ZERO) <= tolerance and abs(p1) + abs(p2) <= tolerance:
                    return math.nan
                return t_from
            t += step
            if t >= t_to:
                return math.nan
    departing = leaving
    while True:
        h0, h1, h2, curvature, jerk = _step_data(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, t)
        if departing and h0 >= -8.0 * tolerance:
            step = _escape_step(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, t, tolerance)
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
            _derivatives(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, t_to, pair)
            return t_to if pair[0] >= -tolerance or (pair[0] >= -8.0 * tolerance and pair[1] > 0.0) else math.nan
        if t + step == t:
            return t
        t += step


@njit(cache=True, error_model="numpy")
def _closest_approach(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, ta, tb, fastest, best, stop):
    """Largest interior local maximum of h on (ta, tb) (h' from + to -), if above best[0]: stored in best."""
    chunks = max(2, int(math.ceil(fastest * (tb - ta) / 0.5)))
    d = np.empty(3)
    t_prev = ta
    _derivatives(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, ta, d)
    slope_prev = d[1]
    for c in range(1, chunks + 1):
        t = ta + (tb - ta) * c / chunks
        _derivatives(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, t, d)
        if slope_prev > 0.0 and d[1] < 0.0:
            lo, hi = t_prev, t
            for _ in range(200):  # bisection on h' (sign + at lo, - at hi)
                mid = 0.5 * (lo + hi)
                if mid <= lo or mid >= hi:
                    break
                _derivatives(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, mid, d)
                if d[1] > 0.0:
                    lo = mid
                else:
                    hi = mid
            _derivatives(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, lo, d)
            if lo > ta and lo < tb and d[0] > best[0]:
                best[0], best[1], best[2] = d[0], lo, stop
            _derivatives(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, t, d)
        slope_prev, t_prev = d[1], t


# ------------------------------------------------------------------------------------ Jacobians, stops, bookkeeping
@njit(cache=True, error_model="numpy")
def _transition(lams, vecs, invs, f, m, dt, poly, zpros, znils, out):
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
def _left_multiply(factor, jac, work):
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
def _field(a_matrix, load, static, omega, t, y, held, velw, kickw, masses, simple, out):
    """The vector field at (t, y): free (``held`` < 0), or held on stop ``held`` (its holding force subtracted)."""
    n = y.size
    phasor = complex(math.cos(omega * t), math.sin(omega * t))
    for r in range(n):
        acc = (load[r] * phasor).real + static[r]
        for c in range(n):
            acc += a_matrix[r, c] * y[c]
        out[r] = acc
    if held >= 0:
        i = simple[held]
        if i >= 0:
            out[n // 2 + i] = 0.0
            return
        normal = 0.0
        for r in range(n):
            normal += velw[held, r] * out[r]
        for r in range(n):
            out[r] -= masses[held] * kickw[held, r] * normal


@njit(cache=True, error_model="numpy")
def _saltation(jumps, stop, a_matrix, load, static, omega, t, before, after, velocity, held_before, held_after, gapw, velw, kickw, masses, simple, out):
    """Saltation matrix of an impact on ``stop`` at time t from ``before`` (at the contact, approach ``velocity``) to
    ``after``, with the impact's velocity map D = ``jumps[stop]``: S = D + (f+ - D f-) (grad g)^T / v."""
    n = before.size
    for r in range(n):
        for c in range(n):
            out[r, c] = jumps[stop, r, c]
    if velocity <= 0.0:
        if held_after != stop:
            out[:, :] = math.nan  # a grazing touch: the map is not differentiable here
        return  # touch and stick: the gap and its velocity are held from here on (the touch's D holds both)
    f_before = np.empty(n)
    f_after = np.empty(n)
    _field(a_matrix, load, static, omega, t, before, held_before, velw, kickw, masses, simple, f_before)
    _field(a_matrix, load, static, omega, t, after, held_after, velw, kickw, masses, simple, f_after)
    for r in range(n):
        acc = 0.0
        for c in range(n):
            acc += jumps[stop, r, c] * f_before[c]
        difference = (f_after[r] - acc) / velocity
        for c in range(n):
            if gapw[stop, c] != 0.0:
                out[r, c] += difference * gapw[stop, c]


@njit(cache=True, error_model="numpy")
def _grow(array, rows):
    bigger = np.empty((max(2 * array.shape[0], rows),) + array.shape[1:], dtype=array.dtype)
    bigger[: array.shape[0]] = array
    return bigger


@njit(cache=True, error_model="numpy")
def _gap(gapw, clearances, stop, y):
    """h = n . x - Delta of ``stop`` (>= 0: at or beyond it)."""
    acc = -clearances[stop]
    for r in range(y.size):
        acc += gapw[stop, r] * y[r]
    return acc


@njit(cache=True, error_model="numpy")
def _snap(gapw, clearances, simple, signs, stop, y):
    """Put the position on stop ``stop``'s surface (exactly, for a stop that moves one coordinate)."""
    i = simple[stop]
    if i >= 0:
        y[i] = signs[stop] * clearances[stop]
        return
    excess = _gap(gapw, clearances, stop, y)
    norm = 0.0
    for r in range(y.size):
        norm += gapw[stop, r] * gapw[stop, r]
    for r in range(y.size):
        y[r] -= excess * gapw[stop, r] / norm


@njit(cache=True, error_model="numpy")
def _pushed(stop, lams, counts, vecs, invs, hrms, csts, zpros, znils, zdrvs, zdrv2s, polys, hold_w, hold_off, hold_har, force_tolerance, omega, t, y):
    """Would stop ``stop`` have to push to hold the structure at rest on it at (t, y) (holding force > 0, or = 0 and
    rising)?"""
    f = stop + 1
    m = counts[f]
    n = y.size
    modal = np.empty(m, dtype=np.complex128)
    amp = np.empty((1, m), dtype=np.complex128)
    z0, q1, q2 = np.zeros(n), np.zeros(n), np.zeros(n)
    _modal(lams, invs, hrms, csts, f, m, omega, t, y, modal)
    if polys[f]:
        _rigid(zpros, znils, zdrvs, zdrv2s, hrms, csts, f, omega, t, y, z0, q1, q2)
    har, con, p1, p2 = _observable(hold_w, stop, hold_off[stop], hold_har[stop], vecs, hrms, csts, f, m, modal, amp, polys[f], z0, q1, q2)
    value = _value(lams, f, m, amp, _ZERO, har, con, p1, p2, omega, t, t)
    if abs(value) > 64.0 * force_tolerance:
        return value < 0.0
    band = _round_off(m, amp, _ZERO, har, con, p1, p2, 0.0, force_tolerance)  # as the held search will allow
    return _escape_step(lams, f, m, amp, _ZERO, har, con, p1, p2, omega, t, t, band) >= 0.0


@njit(cache=True, error_model="numpy")
def _holds(stop, lams, counts, vecs, invs, hrms, csts, zpros, znils, zdrvs, zdrv2s, polys, hold_w, hold_off, hold_har, force_tolerance, omega, t, y, gapw, velw, clearances, tolerance):
    """Does held stop ``stop`` hold on after an impulse on another stop: still closed, at rest on it (n . x' within
    1e-12 of the velocities it is made of: a relative stop's two velocities cancel only to round-off) and pushed?"""
    if _gap(gapw, clearances, stop, y) < -tolerance:
        return False
    speed = 0.0
    noise = 0.0
    for r in range(y.size):
        speed += velw[stop, r] * y[r]
        noise += abs(velw[stop, r] * y[r])
    if abs(speed) > 1e-12 * noise:
        return False
    return _pushed(stop, lams, counts, vecs, invs, hrms, csts, zpros, znils, zdrvs, zdrv2s, polys, hold_w, hold_off, hold_har, force_tolerance, omega, t, y)


# ------------------------------------------------------------------------------------------------------- the loop
@njit(cache=True, error_model="numpy")
def run_periods(
    lams, counts, vecs, invs, hrms, csts, zpros, znils, zdrvs, zdrv2s, polys, hlams, hcounts, rates_all, rinv_all, fastests,
    a_matrix, load, static, omega, period,
    gapw, velw, kickw, clearances, restitutions, masses, simple, signs,
    hold_w, hold_off, hold_har, force_tolerances, bounce, stick, touch,
    sticking_velocity, max_impacts, tolerance, resolution_velocity, gl_nodes, gl_weights,
    y_start, t_start, periods, want_moments, want_jacobians, want_approach,
):  # fmt: skip
    """Integrate ``periods`` periods from (t_start, y_start); see :class:`vibroimpact.engines.exact.ExactEngine`.

    Returns (status, t_fail, strobes (periods + 1, n), jacobians (periods, n, n), impacts (m, 4): time, speed,
    impulse, stop, segments (s, 3): start, mode, stop, segment_states (s, n), moments (periods, 2 N + K),
    counters [steps, events, sticks, releases, touches], approach [value, time, stop]); status
    :data:`STATUS_TWO_STICKS` stops the run where the structure would stick on two stops at once (t_fail, and
    approach[2] the other stop, counters[4] the first).
    """
    n = y_start.size
    size = n // 2
    stops = clearances.size
    width = 2 * size + stops
    strobes = np.empty((periods + 1, n))
    jacobians = np.empty((periods if want_jacobians else 0, n, n))
    moments = np.zeros((periods if want_moments else 0, width), dtype=np.complex128)
    impacts = np.empty((max(4, 2 * periods), 4))
    segments = np.empty((max(4, 2 * periods), 3))
    segment_states = np.empty((max(4, 2 * periods), n))
    counters = np.zeros(5, dtype=np.int64)
    approach = np.array([-math.inf, math.nan, -1.0])
    n_impacts = 0
    n_segments = 0
    widest = lams.shape[1]
    y = y_start.copy()
    for j in range(stops):  # round-off beyond a stop is the stop
        if _gap(gapw, clearances, j, y) > 0.0:
            _snap(gapw, clearances, simple, signs, j, y)
    t = t_start
    jac = np.eye(n)
    # is the start held (at rest on a stop that pushes)?
    stuck = _NONE
    for j in range(stops):
        speed = 0.0
        for r in range(n):
            speed += velw[j, r] * y[r]
        if _gap(gapw, clearances, j, y) >= -tolerance and abs(speed) <= resolution_velocity:
            if _pushed(j, lams, counts, vecs, invs, hrms, csts, zpros, znils, zdrvs, zdrv2s, polys, hold_w, hold_off, hold_har, force_tolerances[j], omega, t, y):
                if stuck >= 0:
                    counters[4], approach[2] = stuck, j
                    return STATUS_TWO_STICKS, t, strobes[:0], jacobians[:0], impacts[:0], segments[:0], segment_states[:0], moments[:0], counters, approach
                stuck = j
    origin = t
    for r in range(n):
        strobes[0, r] = y[r]
    k = 1
    fresh = True
    impacts_period = np.zeros(stops, dtype=np.int64)
    events_period = 0
    leave = np.zeros(stops, dtype=np.bool_)
    events_at = np.full(stops, math.nan)
    modal = np.empty(widest, dtype=np.complex128)
    amp = np.empty((1, widest), dtype=np.complex128)
    hamps = np.empty((stops, widest), dtype=np.complex128)
    hars = np.empty(stops, dtype=np.complex128)
    cons = np.empty(stops)
    p1s = np.empty(stops)
    p2s = np.empty(stops)
    z0, q1, q2 = np.zeros(n), np.zeros(n), np.zeros(n)
    mm = widest + 2
    buffers = (np.empty(mm, dtype=np.complex128), np.empty((mm, mm), dtype=np.complex128), np.empty(mm, dtype=np.complex128), np.empty(mm + 1, dtype=np.complex128), np.empty(mm, dtype=np.complex128), np.empty(mm, dtype=np.complex128))
    work = np.empty((n, n))
    phi = np.empty((n, n))
    salt = np.empty((n, n))
    before = np.empty(n)
    ybuf = np.empty(n)
    ynew = np.empty(n)
    t_piece = t
    f = 0  # the piece's flow: 0 free, 1 + k held on stop k
    m = 0
    hm = 0
    poly = False
    while k <= periods:
        boundary = origin + k * period
        if fresh:
            t_piece = t
            f = stuck + 1
            m, hm, poly = counts[f], hcounts[f], polys[f]
            _modal(lams, invs, hrms, csts, f, m, omega, t, y, modal)
            if poly:
                _rigid(zpros, znils, zdrvs, zdrv2s, hrms, csts, f, omega, t, y, z0, q1, q2)
            for j in range(stops):
                if j == stuck:
                    har, con, p1, p2 = _observable(hold_w, j, hold_off[j], hold_har[j], vecs, hrms, csts, f, m, modal, amp, poly, z0, q1, q2)
                    leave[j] = True  # a fresh stick's holding force starts by leaving zero (or the start is held)
                else:
                    har, con, p1, p2 = _observable(gapw, j, -clearances[j], 0j, vecs, hrms, csts, f, m, modal, amp, poly, z0, q1, q2)
                    leave[j] = _gap(gapw, clearances, j, y) >= -tolerance  # at the surface: the search starts by leaving it
                hars[j], cons[j], p1s[j], p2s[j] = har, con, p1, p2
                _halve(lams, f, m, amp, hamps, j)
                if leave[j]:
                    events_at[j] = t
            if n_segments == segments.shape[0]:
                segments = _grow(segments, n_segments + 1)
                segment_states = _grow(segment_states, n_segments + 1)
            segments[n_segments, 0], segments[n_segments, 1], segments[n_segments, 2] = t, 1.0 if stuck >= 0 else 0.0, stuck
            for r in range(n):
                segment_states[n_segments, r] = y[r]
            n_segments += 1
            fresh = False  # the piece lasts until the next event, across period boundaries
        counters[0] += 1
        t_event = math.nan
        event = _NONE
        limit = boundary
        for j in range(stops):
            found = _first_crossing(hlams, f, hm, hamps, j, hars[j], cons[j], p1s[j], p2s[j], omega, t_piece, t, limit, force_tolerances[j] if j == stuck else tolerance, leave[j])
            leave[j] = False
            if not math.isnan(found) and (event < 0 or found < t_event):
                t_event, event, limit = found, j, found
        t_end = boundary if event < 0 else t_event
        # moments, closest approach and the transition matrix of [t, t_end]
        if t_end > t:
            if want_moments:
                if poly:
                    _add_moments_gl(moments, k - 1, stuck, lams, vecs, hrms, csts, f, m, modal, omega, t_piece, t, t_end, fastests[f], gl_nodes, gl_weights, hold_w, hold_off, hold_har, size, stops, z0, q1, q2, ybuf)
                else:
                    _add_moments(moments, k - 1, stuck, lams, vecs, hrms, csts, f, m, modal, omega, t_piece, t, t_end, rates_all, rinv_all, buffers, hold_w, hold_off, hold_har, size, stops)
            if want_approach:
                for j in range(stops):
                    if j != stuck:
                        _closest_approach(hlams, f, hm, hamps, j, hars[j], cons[j], p1s[j], p2s[j], omega, t_piece, t, t_end, fastests[f], approach, j)
            if want_jacobians:
                _transition(lams, vecs, invs, f, m, t_end - t, poly, zpros, znils, phi)
                _left_multiply(phi, jac, work)
        _state(lams, vecs, hrms, csts, f, m, omega, t_piece, modal, t_end, ynew, poly, z0, q1, q2)
        for j in range(stops):
            if j != stuck and _gap(gapw, clearances, j, ynew) > 0.0:
                _snap(gapw, clearances, simple, signs, j, ynew)  # round-off beyond a stop is the stop
        for r in range(n):
            y[r] = ynew[r]
        t = t_end
        if event < 0:
            for j in range(stops):
                leave[j] = t_end - events_at[j] <= 1e-9 * period
                impacts_period[j] = 0
            for r in range(n):
                strobes[k, r] = y[r]
            if want_jacobians:
                for r in range(n):
                    for c in range(n):
                        jacobians[k - 1, r, c] = jac[r, c]
                        jac[r, c] = 1.0 if r == c else 0.0
            k += 1
            events_period = 0
            continue
        events_period += 1
        if events_period > 10 * max_impacts:
            return STATUS_NO_PROGRESS, t, strobes, jacobians, impacts[:n_impacts], segments[:n_segments], segment_states[:n_segments], moments, counters, approach
        fresh = True
        if event == stuck:
            counters[3] += 1
            stuck = _NONE  # release: continuous state and vector field, saltation = identity
            continue
        # an impact on stop ``event`` (from free flight, or while held on another stop, which it frees unless that
        # stop holds on after the impulse)
        held_before = stuck
        stuck = _NONE
        j = event
        impacts_period[j] += 1
        counters[1] += 1
        _snap(gapw, clearances, simple, signs, j, y)
        raw = 0.0
        noise = 0.0
        for r in range(n):
            raw += velw[j, r] * y[r]
            noise += abs(velw[j, r] * y[r])
        # below round-off (of the velocity scale, or of the velocities a relative stop's n . x' is made of): a touch
        velocity = raw if raw > resolution_velocity and raw > 1e-12 * noise else 0.0
        chatters = velocity <= sticking_velocity or impacts_period[j] > max_impacts or restitutions[j] == 0.0
        sticks = False
        if chatters:
            sticks = _pushed(j, lams, counts, vecs, invs, hrms, csts, zpros, znils, zdrvs, zdrv2s, polys, hold_w, hold_off, hold_har, force_tolerances[j], omega, t, y)
        if sticks:
            for other in range(stops):
                if other != j and _gap(gapw, clearances, other, y) >= -tolerance:
                    if _pushed(other, lams, counts, vecs, invs, hrms, csts, zpros, znils, zdrvs, zdrv2s, polys, hold_w, hold_off, hold_har, force_tolerances[other], omega, t, y):
                        counters[4], approach[2] = j, other
                        return STATUS_TWO_STICKS, t, strobes, jacobians, impacts[:n_impacts], segments[:n_segments], segment_states[:n_segments], moments, counters, approach
        after = 0.0 if sticks else -restitutions[j] * velocity
        if want_jacobians:
            for r in range(n):
                before[r] = y[r]
        i = simple[j]
        if i >= 0:
            y[size + i] = signs[j] * after
        else:
            change = (after - raw) * masses[j]
            for r in range(n):
                y[r] += change * kickw[j, r]
        held_after = j if sticks else -1
        if held_before >= 0 and not sticks:
            h = held_before
            if _holds(h, lams, counts, vecs, invs, hrms, csts, zpros, znils, zdrvs, zdrv2s, polys, hold_w, hold_off, hold_har, force_tolerances[h], omega, t, y, gapw, velw, clearances, tolerance):
                # still closed, at rest on it (n . x' at round-off) and pushed: it holds on, its n . x' made exactly 0
                held_after = h
                _snap(gapw, clearances, simple, signs, h, y)
                i = simple[h]
                if i >= 0:
                    y[size + i] = 0.0
                else:
                    change = 0.0
                    for r in range(n):
                        change -= velw[h, r] * y[r]
                    change *= masses[h]
                    for r in range(n):
                        y[r] += change * kickw[h, r]
        if held_before >= 0 and held_after != held_before:
            counters[3] += 1
        if want_jacobians:
            if not sticks:
                _saltation(bounce, j, a_matrix, load, static, omega, t, before, y, velocity, held_before, held_after, gapw, velw, kickw, masses, simple, salt)
            elif velocity > 0.0:
                _saltation(stick, j, a_matrix, load, static, omega, t, before, y, velocity, held_before, held_after, gapw, velw, kickw, masses, simple, salt)
            else:
                _saltation(touch, j, a_matrix, load, static, omega, t, before, y, velocity, held_before, held_after, gapw, velw, kickw, masses, simple, salt)
            _left_multiply(salt, jac, work)
        impulse = masses[j] * (velocity - after)
        if velocity > 0.0:
            if n_impacts == impacts.shape[0]:
                impacts = _grow(impacts, n_impacts + 1)
            impacts[n_impacts, 0], impacts[n_impacts, 1], impacts[n_impacts, 2], impacts[n_impacts, 3] = t, velocity, impulse, j
            n_impacts += 1
            if want_moments:
                moments[k - 1, size + j] += impulse * complex(math.cos(omega * t), -math.sin(omega * t))
        else:
            counters[4] += 1
        counters[2] += 1 if sticks else 0
        stuck = held_after
    return STATUS_OK, t, strobes, jacobians, impacts[:n_impacts], segments[:n_segments], segment_states[:n_segments], moments, counters, approach


# ------------------------------------------------------------------------------------------------------ sampling
@njit(cache=True, error_model="numpy")
def sample_states(lams, counts, vecs, invs, hrms, csts, zpros, znils, zdrvs, zdrv2s, polys, omega, gapw, clearances, simple, signs, starts, flows, states, times, pieces):
    """The states at ``times`` on the pieces of a run, exact: piece ``pieces[i]`` (start time ``starts[p]``, state
    ``states[p]`` there, flow ``flows[p]``: 0 free, 1 + k held on stop k) is evaluated at ``times[i]`` as the loop
    evaluates it (modal coordinates at the piece's start, :func:`_state`, round-off beyond a stop not held snapped
    onto it), so a time on a strobe gives the strobe state. Returns (len(times), n)."""
    count = times.size
    n = states.shape[1]
    out = np.empty((count, n))
    modal = np.empty(lams.shape[1], dtype=np.complex128)
    z0, q1, q2 = np.zeros(n), np.zeros(n), np.zeros(n)
    y = np.empty(n)
    current = _NONE
    for i in range(count):
        p = pieces[i]
        f = flows[p]
        m = counts[f]
        poly = polys[f]
        if p != current:
            _modal(lams, invs, hrms, csts, f, m, omega, starts[p], states[p], modal)
            if poly:
                _rigid(zpros, znils, zdrvs, zdrv2s, hrms, csts, f, omega, starts[p], states[p], z0, q1, q2)
            current = p
        _state(lams, vecs, hrms, csts, f, m, omega, starts[p], modal, times[i], y, poly, z0, q1, q2)
        for j in range(clearances.size):
            if j != f - 1 and _gap(gapw, clearances, j, y) > 0.0:
                _snap(gapw, clearances, simple, signs, j, y)  # round-off beyond a stop is the stop
        for r in range(n):
            out[i, r] = y[r]
    return out


# ---------------------------------------------------------------------------------------------------------- moments
@njit(cache=True, error_model="numpy")
def _series(z):
    """(e^z - 1) / z for small z, without cancellation: e^(x+iy) - 1 = expm1(x) cos y - 2 sin^2(y/2) + i e^x sin y."""
    if z == 0.0:  # exact: the constant term of a real harmonic pair, e^{jwt} e^{-jwt}
        return 1.0 + 0j
    x, y = z.real, z.imag
    half = math.sin(0.5 * y)
    return complex(math.expm1(x) * math.cos(y) - 2.0 * half * half, math.exp(x) * math.sin(y)) / z


@njit(cache=True, error_model="numpy")
def moment_rates(lam, omega):
    """The exponents of a piece's components (the eigenvalues, then +-jw for the two halves of the harmonic term) and
    the reciprocals the closed-form integrals divide by: of each pairwise sum, of each rate - jw (0 where the sum
    vanishes: that integral is then taken by its series). Called once per flow when the engine prepares a problem."""
    m = lam.size + 2
    rates = np.empty(m, dtype=np.complex128)
    rates[: lam.size] = lam
    rates[lam.size], rates[lam.size + 1] = complex(0.0, omega), complex(0.0, -omega)
    inverse = np.zeros((m + 1, m), dtype=np.complex128)  # rows 0..m-1: 1 / (r_k + r_l); row m: 1 / (r_k - jw)
    for k in range(m):
        for l in range(m):
            s = rates[k] + rates[l]
            inverse[k, l] = 1.0 / s if abs(s) > 0.0 else 0.0
        s = rates[k] - complex(0.0, omega)
        inverse[m, k] = 1.0 / s if abs(s) > 0.0 else 0.0
    return rates, inverse


@njit(cache=True, error_model="numpy")
def _amplitudes(vecs, hrms, f, m, modal, omega, t0, coordinate, amps):
    """Coordinate ``coordinate`` of the piece as sum_k amps_k e^{rates_k (t - t0)} plus a constant: the modal terms
    (their sum is real) and the harmonic Re(Y e^{jwt}) as two conjugate halves."""
    for i in range(m):
        amps[i] = vecs[f, coordinate, i] * modal[i]
    harmonic = hrms[f, coordinate] * complex(math.cos(omega * t0), math.sin(omega * t0))
    amps[m], amps[m + 1] = 0.5 * harmonic, 0.5 * np.conj(harmonic)


@njit(cache=True, error_model="numpy")
def _weighted_amplitudes(vecs, hrms, f, m, modal, omega, t0, weights, row, extra, amps):
    """As :func:`_amplitudes` for minus the observable weights[row] . y + Re(extra e^{jwt}) (the holding force)."""
    harmonic = extra
    for r in range(weights.shape[1]):
        harmonic += weights[row, r] * hrms[f, r]
    for i in range(m):
        acc = 0j
        for r in range(weights.shape[1]):
            acc += weights[row, r] * vecs[f, r, i]
        amps[i] = -acc * modal[i]
    harmonic *= -complex(math.cos(omega * t0), math.sin(omega * t0))
    amps[m], amps[m + 1] = 0.5 * harmonic, 0.5 * np.conj(harmonic)


@njit(cache=True, error_model="numpy")
def _piece_factors(rates_all, rinv_all, f, m, omega, a, length, pair, single, fourier, ea, el):
    """E(s) = int_a^{a+L} e^{s u} du = e^{s a} (e^{s L} - 1) / s for every sum of two rates (``pair``), every rate
    (``single``) and every rate - jw (``fourier``; the last entry: the constant's, s = -jw); near s L = 0 by the series.
    Every exponential is a product of the m exponentials e^{r_k a}, e^{r_k L} of this piece (rates of flow f)."""
    for k in range(m):
        ea[k] = np.exp(rates_all[f, k] * a)
        el[k] = np.exp(rates_all[f, k] * length)
    wa = complex(math.cos(omega * a), -math.sin(omega * a))
    wl = complex(math.cos(omega * length), -math.sin(omega * length))
    for k in range(m):
        for l in range(k, m):
            s = rates_all[f, k] + rates_all[f, l]
            growth = ea[k] * ea[l]
            if abs(s) * length >= 0.5:
                pair[k, l] = growth * (el[k] * el[l] - 1.0) * rinv_all[f, k, l]
            else:
                pair[k, l] = growth * length * _series(s * length)
        s = rates_all[f, k]
        single[k] = ea[k] * ((el[k] - 1.0) / s if abs(s) * length >= 0.5 else length * _series(s * length))
        s = rates_all[f, k] - complex(0.0, omega)
        fourier[k] = ea[k] * wa * ((el[k] * wl - 1.0) * rinv_all[f, m, k] if abs(s) * length >= 0.5 else length * _series(s * length))
    s = complex(0.0, -omega)
    fourier[m] = wa * ((wl - 1.0) / s if abs(s) * length >= 0.5 else length * _series(s * length))


@njit(cache=True, error_model="numpy")
def _integrals(amps, m, constant, length, pair, single, fourier, phasor, out, row, slot_fourier, slot_square):
    """Add int x e^{-jwt} dt (``phasor`` = e^{-jw t0}) to out[row, slot_fourier] and int x^2 dt to
    out[row, slot_square] (if >= 0) for x = sum_k amps_k e^{rates_k u} + constant (k < m), from the piece's factors."""
    total = constant * fourier[m]
    for k in range(m):
        total += amps[k] * fourier[k]
    out[row, slot_fourier] += total * phasor
    if slot_square < 0:
        return
    square = constant * constant * length + 0j
    for k in range(m):
        square += amps[k] * (2.0 * constant * single[k] + amps[k] * pair[k, k])
        for l in range(k + 1, m):
            square += 2.0 * amps[k] * amps[l] * pair[k, l]
    out[row, slot_square] += square.real


@njit(cache=True, error_model="numpy")
def _add_moments(out, row, stuck, lams, vecs, hrms, csts, f, m, modal, omega, t_piece, ta, tb, rates_all, rinv_all, buffers, hold_w, hold_off, hold_har, size, stops):
    """Add the piece's Fourier and square integrals over [ta, tb] to the period's row ``out[row]``, in closed form
    (the motion is a sum of exponentials): each coordinate times e^{-jwt}, the holding force times e^{-jwt} while
    held, each coordinate squared."""
    mm = m + 2
    amps, pair, single, fourier, ea, el = buffers
    a, length = ta - t_piece, tb - ta
    _piece_factors(rates_all, rinv_all, f, mm, omega, a, length, pair, single, fourier, ea, el)
    phasor = complex(math.cos(omega * t_piece), -math.sin(omega * t_piece))
    for i in range(size):
        _amplitudes(vecs, hrms, f, m, modal, omega, t_piece, i, amps)
        _integrals(amps, mm, csts[f, i], length, pair, single, fourier, phasor, out, row, i, size + stops + i)
    if stuck >= 0:
        _weighted_amplitudes(vecs, hrms, f, m, modal, omega, t_piece, hold_w, stuck, hold_har[stuck], amps)
        constant = hold_off[stuck]
        for r in range(hold_w.shape[1]):
            constant += hold_w[stuck, r] * csts[f, r]
        _integrals(amps, mm, -constant, length, pair, single, fourier, phasor, out, row, size + stuck, _NONE)


@njit(cache=True, error_model="numpy")
def _add_moments_gl(out, row, stuck, lams, vecs, hrms, csts, f, m, modal, omega, t_piece, ta, tb, fastest, nodes, weights, hold_w, hold_off, hold_har, size, stops, z0, q1, q2, y):
    """As :func:`_add_moments` for a flow with rigid-body (polynomial) terms, by Gauss-Legendre quadrature on chunks
    of at most 2 / (|lambda|max + w) [s]: exact for the polynomial parts (degree <= 4 in the squares), to round-off
    for the exponentials."""
    chunks = max(1, int(math.ceil(fastest * (tb - ta) / 2.0)))
    for c in range(chunks):
        a = ta + (tb - ta) * c / chunks
        b = ta + (tb - ta) * (c + 1) / chunks
        for q in range(nodes.size):
            t = a + (b - a) * nodes[q]
            w = (b - a) * weights[q]
            _state(lams, vecs, hrms, csts, f, m, omega, t_piece, modal, t, y, _YES, z0, q1, q2)
            phasor = complex(math.cos(omega * t), -math.sin(omega * t))
            for i in range(size):
                out[row, i] += w * y[i] * phasor
                out[row, size + stops + i] += w * y[i] * y[i]
            if stuck >= 0:
                force = hold_off[stuck] + (hold_har[stuck] * complex(math.cos(omega * t), math.sin(omega * t))).real
                for r in range(y.size):
                    force += hold_w[stuck, r] * y[r]
                out[row, size + stuck] -= w * force * phasor
