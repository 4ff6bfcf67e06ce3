"""The compiled core of the ``exact`` engine: its whole event loop in one numba function, with the exact Jacobian.

Everything the loop calls lives in this one module on purpose: numba's on-disk cache is keyed by the source file of
each cached function only, so a change in a function called from another file would not recompile its callers
(numba PR #8396, unmerged); a kernel module beside this one served stale machine code after an edit.

The algorithm is :mod:`.exact_python`'s (closed-form flow, guaranteed first-root search by Taylor bounds, impact map,
sticking and release, strobes, Fourier moments), compiled with ``@njit(cache=True)``: the interpreter overhead of the
pure-Python loop was ~97 % of its cost (README, "Speed: before and after the compiled core"). Flows are passed as
arrays:

* ``lam`` (n,) eigenvalues, ``vec`` (n, n) eigenvectors, ``inv`` (n, n) their inverse, ``hrm`` (n,) the complex
  amplitude Y of the harmonic particular solution Re(Y e^{jwt}), ``cst`` (n,) the constant particular solution;
  the free flow has n = 4 (X1, X2, X1', X2'), the stuck flow n = 2 (X1, X1') with X2 = Delta, X2' = 0.
* an observable h = w . y + offset of a piece from (t0, y0) is ``amp`` complex (one per eigenvalue; the root search
  keeps one of each conjugate pair, doubled), ``har`` (complex), ``con`` (float):
  h(t) = Re(sum amp_i e^{lam_i (t - t0)} + har e^{jwt}) + con.

The Jacobian of the stroboscopic map is the product, over the pieces of a period, of the state-transition matrices
Re(V diag(e^{lam dt}) V^-1) and of the saltation matrix of each event (Leine & Nijmeijer; di Bernardo et al.):
an impact y+ = D y- with D = diag(1, 1, 1, -R) (or diag(1, 1, 1, 0) when it sticks) gives
S = D + (f(y+) - D f(y-)) e2^T / X2'(t-); a release is continuous in y and in the vector field (the absorber leaves
at rest with zero holding force), so its saltation matrix is the identity. While stuck, X2 and X2' are held, so the
transition matrix has zero rows for them.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["run_periods", "STATUS_OK", "STATUS_NO_PROGRESS"]

STATUS_OK, STATUS_NO_PROGRESS = 0, 1


@njit(cache=True, error_model="numpy")
def _modal(lam, vec, inv, hrm, cst, omega, t0, y0, out):
    """Modal coordinates of the homogeneous part through y0 at t0, into ``out``."""
    n = lam.size
    phasor = complex(math.cos(omega * t0), math.sin(omega * t0))
    for r in range(n):
        out[r] = 0j
    for i in range(n):
        rel = y0[i] - ((hrm[i] * phasor).real + cst[i])
        for r in range(n):
            out[r] += inv[r, i] * rel


@njit(cache=True, error_model="numpy")
def _state(lam, vec, hrm, cst, omega, t0, modal, t, out):
    n = lam.size
    phasor = complex(math.cos(omega * t), math.sin(omega * t))
    for r in range(n):
        out[r] = (hrm[r] * phasor).real + cst[r]
    for i in range(n):
        if lam[i].imag < 0.0:
            continue  # its conjugate's term, doubled, stands for both (the state is real)
        growth = np.exp(lam[i] * (t - t0)) * modal[i] * (2.0 if lam[i].imag > 0.0 else 1.0)
        for r in range(n):
            out[r] += (vec[r, i] * growth).real


@njit(cache=True, error_model="numpy")
def _observable(weights, offset, vec, hrm, cst, modal, amp):
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


@njit(cache=True, error_model="numpy")
def _half_rates(lam):
    """The eigenvalues a real observable needs: one of each complex-conjugate pair (Im > 0) and the real ones."""
    count = 0
    for i in range(lam.size):
        if lam[i].imag >= 0.0:
            count += 1
    out = np.empty(count, dtype=np.complex128)
    count = 0
    for i in range(lam.size):
        if lam[i].imag >= 0.0:
            out[count] = lam[i]
            count += 1
    return out


@njit(cache=True, error_model="numpy")
def _halve(lam, amp, out):
    """Amplitudes on :func:`_half_rates`: Re(a e^{lt}) + Re(conj) = Re(2 a e^{lt}), so each pair is kept once,
    doubled (every evaluation of the observable then costs half)."""
    count = 0
    for i in range(lam.size):
        if lam[i].imag > 0.0:
            out[count] = 2.0 * amp[i]
            count += 1
        elif lam[i].imag == 0.0:
            out[count] = amp[i]
            count += 1


@njit(cache=True, error_model="numpy")
def _value(lam, amp, har, con, omega, t0, t):
    """h(t)."""
    total = har * complex(math.cos(omega * t), math.sin(omega * t))
    for i in range(lam.size):
        total += amp[i] * np.exp(lam[i] * (t - t0))
    return total.real + con


@njit(cache=True, error_model="numpy")
def _derivatives(lam, amp, har, con, omega, t0, t, out):
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


@njit(cache=True, error_model="numpy")
def _bound(lam, amp, har, omega, t0, t, order):
    """An upper bound of |h^(order)| over [t, inf) (all Re(lam) <= 0)."""
    total = abs(har) * omega**order
    for i in range(lam.size):
        total += abs(amp[i]) * abs(lam[i]) ** order * math.exp(lam[i].real * (t - t0))
    return total


@njit(cache=True, error_model="numpy")
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


@njit(cache=True, error_model="numpy")
def _escape_step(lam, amp, har, con, omega, t0, t):
    """A step over which h stays < 0 from h(t) = 0 when h leaves the surface; -1.0 if it does not leave (orders up to
    4, see linear_flow.escape_step)."""
    values = np.empty(5)
    _derivatives(lam, amp, har, con, omega, t0, t, values)
    for k in range(1, 5):
        scale = _bound(lam, amp, har, omega, t0, t, k)
        if values[k] < -1e-9 * scale:
            return -(k + 1) * values[k] / _bound(lam, amp, har, omega, t0, t, k + 1)
        if values[k] > 1e-9 * scale:
            return -1.0
    return -1.0


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
def _first_crossing(lam, amp, har, con, omega, t0, t_from, t_to, tolerance, leaving):
    """First time in (t_from, t_to] at which h reaches 0 from below; NaN if none (see linear_flow.first_crossing)."""
    size = abs(har) + abs(con)
    for i in range(amp.size):
        size += abs(amp[i])
    tolerance = max(tolerance, 1e-15 * size)
    pair = np.empty(2)
    t = t_from
    if leaving:
        if _value(lam, amp, har, con, omega, t0, t) >= -tolerance:
            step = _escape_step(lam, amp, har, con, omega, t0, t)
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
            step = _escape_step(lam, amp, har, con, omega, t0, t)
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
            _derivatives(lam, amp, har, con, omega, t0, t_to, pair)
            return t_to if pair[0] >= -tolerance or (pair[0] >= -8.0 * tolerance and pair[1] > 0.0) else math.nan
        if t + step == t:
            return t
        t += step


@njit(cache=True, error_model="numpy")
def _transition(lam, vec, inv, dt):
    n = lam.size
    scaled = np.empty((n, n), dtype=np.complex128)
    for i in range(n):
        g = np.exp(lam[i] * dt)
        for j in range(n):
            scaled[i, j] = g * inv[i, j]
    return np.ascontiguousarray((vec @ scaled).real)


@njit(cache=True, error_model="numpy")
def _left_multiply(factor, jac, work):
    """jac <- factor @ jac (4 x 4), through ``work``."""
    for r in range(4):
        for c in range(4):
            acc = 0.0
            for m in range(4):
                acc += factor[r, m] * jac[m, c]
            work[r, c] = acc
    jac[:, :] = work


@njit(cache=True, error_model="numpy")
def _free_field(a_matrix, force_over_m1, omega, phase, t, y):
    f = a_matrix @ y
    f[2] += force_over_m1 * math.cos(omega * t + phase)
    return f


@njit(cache=True, error_model="numpy")
def _grow(array, rows):
    bigger = np.empty((max(2 * array.shape[0], rows),) + array.shape[1:], dtype=array.dtype)
    bigger[: array.shape[0]] = array
    return bigger


@njit(cache=True, error_model="numpy")
def _closest_approach(lam, amp, har, con, omega, t0, ta, tb, fastest, best):
    """Largest interior local maximum of h on (ta, tb) (h' from + to -), if above best[0]: stored in best."""
    chunks = max(2, int(math.ceil(fastest * (tb - ta) / 0.5)))
    d = np.empty(3)
    t_prev = ta
    _derivatives(lam, amp, har, con, omega, t0, ta, d)
    slope_prev = d[1]
    for c in range(1, chunks + 1):
        t = ta + (tb - ta) * c / chunks
        _derivatives(lam, amp, har, con, omega, t0, t, d)
        if slope_prev > 0.0 and d[1] < 0.0:
            lo, hi = t_prev, t
            for _ in range(200):  # bisection on h' (sign + at lo, - at hi)
                mid = 0.5 * (lo + hi)
                if mid <= lo or mid >= hi:
                    break
                _derivatives(lam, amp, har, con, omega, t0, mid, d)
                if d[1] > 0.0:
                    lo = mid
                else:
                    hi = mid
            _derivatives(lam, amp, har, con, omega, t0, lo, d)
            if lo > ta and lo < tb and d[0] > best[0]:
                best[0], best[1] = d[0], lo
            _derivatives(lam, amp, har, con, omega, t0, t, d)
        slope_prev, t_prev = d[1], t


@njit(cache=True, error_model="numpy")
def run_periods(
    lam, vec, inv, hrm, cst,  # free flow
    slam, svec, sinv, shrm, scst,  # stuck flow of (X1, X1')
    a_matrix, force_over_m1, phase, omega, period,
    clearance, restitution, m2, k2, b2,
    sticking_velocity, max_impacts, tolerance, force_tolerance, resolution_velocity,
    y_start, t_start, periods, want_moments, want_jacobians, want_approach,
):  # fmt: skip
    """Integrate ``periods`` periods from (t_start, y_start); see :class:`vibroimpact.engines.exact.ExactEngine`.

    Returns (status, t_fail, strobes, jacobians, impacts (m, 3): time, speed, impulse, segments (s, 2): start, mode,
    segment_states (s, 4), moments (periods, 5), counters [steps, events, sticks, releases, touches],
    approach [value, time]).
    """
    n_strobes = periods + 1
    strobes = np.empty((n_strobes, 4))
    jacobians = np.empty((periods if want_jacobians else 0, 4, 4))
    moments = np.zeros((periods if want_moments else 0, 5), dtype=np.complex128)
    impacts = np.empty((max(4, 2 * periods), 3))
    segments = np.empty((max(4, 2 * periods), 2))
    segment_states = np.empty((max(4, 2 * periods), 4))
    counters = np.zeros(5, dtype=np.int64)
    approach = np.array([-math.inf, math.nan])
    n_impacts = 0
    n_segments = 0
    gap_w = np.array([0.0, 1.0, 0.0, 0.0])
    hold_w = np.array([-k2, -b2])
    fastest = omega
    for i in range(lam.size):
        fastest = max(fastest, abs(lam[i]) + omega)
    y = y_start.copy()
    y[1] = min(y[1], clearance)
    t = t_start
    jac = np.eye(4)
    # is the start stuck (at rest on the stop and pushed)?
    stuck = False
    if y[1] == clearance and y[3] == 0.0:
        stuck = _pushed(slam, svec, sinv, shrm, scst, omega, hold_w, k2 * clearance, force_tolerance, t, y)
    # at the stop to round-off (a strobe just after an impact may land a few 1e-19 m below it): the first search
    # starts by leaving the surface, or finds the contact at once if the absorber moves into the stop
    leaving = y[1] >= clearance - tolerance
    origin = t
    strobes[0] = y
    k = 1
    fresh = True
    impacts_period = 0
    events_period = 0
    events_at = t if leaving else math.nan
    modal = np.empty(4, dtype=np.complex128)
    amp = np.empty(4, dtype=np.complex128)
    smodal = np.empty(2, dtype=np.complex128)
    samp = np.empty(2, dtype=np.complex128)
    hlam, hslam = _half_rates(lam), _half_rates(slam)  # the observables' rates: one of each conjugate pair
    hamp, hsamp = np.empty(hlam.size, dtype=np.complex128), np.empty(hslam.size, dtype=np.complex128)
    free_rates, stuck_rates = _moment_rates(lam, omega), _moment_rates(slam, omega)  # the closed-form moments' exponents
    m = lam.size + 2
    buffers = (np.empty(m, dtype=np.complex128), np.empty((m, m), dtype=np.complex128), np.empty(m, dtype=np.complex128), np.empty(m + 1, dtype=np.complex128), np.empty(m, dtype=np.complex128), np.empty(m, dtype=np.complex128))
    weights = (np.array([1.0, 0.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0, 0.0]), np.array([1.0, 0.0]), np.array([k2, b2]))  # X1, X2; stuck X1, holding force
    work = np.empty((4, 4))
    har = 0j
    con = 0.0
    t_piece = t
    ynew = np.empty(4)
    y2 = np.empty(2)
    while k <= periods:
        boundary = origin + k * period
        if fresh:
            t_piece = t
            if stuck:
                y2[0], y2[1] = y[0], y[2]
                _modal(slam, svec, sinv, shrm, scst, omega, t, y2, smodal)
                har, con = _observable(hold_w, k2 * clearance, svec, shrm, scst, smodal, samp)
                _halve(slam, samp, hsamp)
            else:
                _modal(lam, vec, inv, hrm, cst, omega, t, y, modal)
                har, con = _observable(gap_w, -clearance, vec, hrm, cst, modal, amp)
                _halve(lam, amp, hamp)
            if n_segments == segments.shape[0]:
                segments = _grow(segments, n_segments + 1)
                segment_states = _grow(segment_states, n_segments + 1)
            segments[n_segments, 0], segments[n_segments, 1] = t, 1.0 if stuck else 0.0
            segment_states[n_segments] = y
            n_segments += 1
            fresh = False  # the piece lasts until the next event, across period boundaries
        counters[0] += 1
        if stuck:
            t_event = _first_crossing(hslam, hsamp, har, con, omega, t_piece, t, boundary, force_tolerance, leaving)
        else:
            t_event = _first_crossing(hlam, hamp, har, con, omega, t_piece, t, boundary, tolerance, leaving)
        leaving = False
        t_end = boundary if math.isnan(t_event) else t_event
        # moments, closest approach and the transition matrix of [t, t_end]
        if t_end > t:
            if want_moments:
                _add_moments(
                    moments, k - 1, stuck, lam, vec, hrm, cst, slam, svec, shrm, scst, omega, t_piece, smodal if stuck else modal,
                    t, t_end, clearance, k2, b2, free_rates, stuck_rates, buffers, weights,
                )  # fmt: skip
            if want_approach and not stuck:
                _closest_approach(hlam, hamp, har, con, omega, t_piece, t, t_end, fastest, approach)
            if want_jacobians:
                if stuck:
                    phi2 = _transition(slam, svec, sinv, t_end - t)
                    phi = np.zeros((4, 4))
                    phi[0, 0], phi[0, 2], phi[2, 0], phi[2, 2] = phi2[0, 0], phi2[0, 1], phi2[1, 0], phi2[1, 1]
                else:
                    phi = _transition(lam, vec, inv, t_end - t)
                _left_multiply(phi, jac, work)
        if stuck:
            _state(slam, svec, shrm, scst, omega, t_piece, smodal, t_end, y2)
            ynew[0], ynew[1], ynew[2], ynew[3] = y2[0], clearance, y2[1], 0.0
        else:
            _state(lam, vec, hrm, cst, omega, t_piece, modal, t_end, ynew)
            ynew[1] = min(ynew[1], clearance)
        y[:] = ynew
        t = t_end
        if math.isnan(t_event):
            leaving = t_end - events_at <= 1e-9 * period
            strobes[k] = y
            if want_jacobians:
                jacobians[k - 1] = jac
                jac[:, :] = 0.0
                for r in range(4):
                    jac[r, r] = 1.0
            k += 1
            impacts_period = 0
            events_period = 0
            continue
        events_period += 1
        events_at = t
        if events_period > 10 * max_impacts:
            return STATUS_NO_PROGRESS, t, strobes, jacobians, impacts[:n_impacts], segments[:n_segments], segment_states[:n_segments], moments, counters, approach
        if stuck:
            counters[3] += 1
            stuck = False  # release: continuous state and vector field, saltation = identity
        else:
            impacts_period += 1
            counters[1] += 1
            y[1] = clearance
            velocity = y[3] if y[3] > resolution_velocity else 0.0
            chatters = velocity <= sticking_velocity or impacts_period > max_impacts or restitution == 0.0
            sticks = False
            if chatters:
                sticks = _pushed(slam, svec, sinv, shrm, scst, omega, hold_w, k2 * clearance, force_tolerance, t, y)
            after = 0.0 if sticks else -restitution * velocity
            if want_jacobians:
                _left_multiply(_saltation(a_matrix, force_over_m1, phase, omega, t, y, after, restitution, sticks, velocity), jac, work)
            impulse = m2 * (velocity - after)
            if velocity > 0.0:
                if n_impacts == impacts.shape[0]:
                    impacts = _grow(impacts, n_impacts + 1)
                impacts[n_impacts, 0], impacts[n_impacts, 1], impacts[n_impacts, 2] = t, velocity, impulse
                n_impacts += 1
                if want_moments:
                    moments[k - 1, 2] += impulse * complex(math.cos(omega * t), -math.sin(omega * t))
            else:
                counters[4] += 1
            counters[2] += 1 if sticks else 0
            y[3] = after
            stuck = sticks
        fresh = True
        leaving = True
        continue
    return STATUS_OK, t, strobes, jacobians, impacts[:n_impacts], segments[:n_segments], segment_states[:n_segments], moments, counters, approach


@njit(cache=True, error_model="numpy")
def _pushed(slam, svec, sinv, shrm, scst, omega, hold_w, hold_offset, force_tolerance, t, y):
    """Would the stop have to push to hold the absorber at rest at (t, y) (holding force > 0, or = 0 and rising)?"""
    y2 = np.array([y[0], y[2]])
    modal = np.empty(2, dtype=np.complex128)
    amp = np.empty(2, dtype=np.complex128)
    _modal(slam, svec, sinv, shrm, scst, omega, t, y2, modal)
    har, con = _observable(hold_w, hold_offset, svec, shrm, scst, modal, amp)
    value = _value(slam, amp, har, con, omega, t, t)
    if abs(value) > 64.0 * force_tolerance:
        return value < 0.0
    return _escape_step(slam, amp, har, con, omega, t, t) >= 0.0


@njit(cache=True, error_model="numpy")
def _saltation(a_matrix, force_over_m1, phase, omega, t, y_contact, after, restitution, sticks, velocity):
    """Saltation matrix of an impact at time t, at ``y_contact`` (X2 = Delta), from X2' = velocity to ``after``."""
    salt = np.eye(4)
    salt[3, 3] = 0.0 if sticks else -restitution
    if velocity <= 0.0:
        if not sticks:
            salt[:, :] = math.nan  # a grazing touch: the map is not differentiable here
        else:
            salt[1, 1] = 0.0  # touch and stick: X2 and X2' are held from here on
        return salt
    before = y_contact.copy()
    before[3] = velocity
    y_after = y_contact.copy()
    y_after[3] = after
    f_before = _free_field(a_matrix, force_over_m1, omega, phase, t, before)
    f_after = _free_field(a_matrix, force_over_m1, omega, phase, t, y_after)
    if sticks:
        f_after[3] = 0.0  # the stuck field: X2' stays 0
    for r in range(4):  # S = D + (f+ - D f-) e2^T / X2'(t-), D = diag(salt) before this loop changes column 1
        salt[r, 1] += (f_after[r] - salt[r, r] * f_before[r]) / f_before[1]
    return salt


@njit(cache=True, error_model="numpy")
def _series(z):
    """(e^z - 1) / z for small z, without cancellation: e^(x+iy) - 1 = expm1(x) cos y - 2 sin^2(y/2) + i e^x sin y."""
    if z == 0.0:  # exact: the constant term of a real harmonic pair, e^{jwt} e^{-jwt}
        return 1.0 + 0j
    x, y = z.real, z.imag
    half = math.sin(0.5 * y)
    return complex(math.expm1(x) * math.cos(y) - 2.0 * half * half, math.exp(x) * math.sin(y)) / z


@njit(cache=True, error_model="numpy")
def _moment_rates(lam, omega):
    """The exponents of a piece's components (the eigenvalues, then +-jw for the two halves of the harmonic term) and
    the reciprocals the closed-form integrals divide by: of each rate, of each pairwise sum, of each rate - jw (0 where
    the sum vanishes: that integral is then taken by its series)."""
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
def _amplitudes(lam, vec, hrm, modal, omega, t0, weights, amps):
    """weights . y of the piece as sum_k amps_k e^{rates_k (t - t0)} plus a constant: the modal terms (their sum is
    real) and the harmonic Re(Y e^{jwt}) as two conjugate halves."""
    n = lam.size
    harmonic = 0j
    for i in range(n):
        acc = 0j
        for r in range(n):
            acc += weights[r] * vec[r, i]
        amps[i] = acc * modal[i]
        harmonic += weights[i] * hrm[i]
    harmonic *= complex(math.cos(omega * t0), math.sin(omega * t0))
    amps[n], amps[n + 1] = 0.5 * harmonic, 0.5 * np.conj(harmonic)


@njit(cache=True, error_model="numpy")
def _piece_factors(rates, inverse, omega, a, length, pair, single, fourier, ea, el):
    """E(s) = int_a^{a+L} e^{s u} du = e^{s a} (e^{s L} - 1) / s for every sum of two rates (``pair``), every rate
    (``single``) and every rate - jw (``fourier``; the last entry: the constant's, s = -jw); near s L = 0 by the series.
    Every exponential is a product of the m exponentials e^{r_k a}, e^{r_k L} of this piece."""
    m = rates.size
    for k in range(m):
        ea[k] = np.exp(rates[k] * a)
        el[k] = np.exp(rates[k] * length)
    wa = complex(math.cos(omega * a), -math.sin(omega * a))
    wl = complex(math.cos(omega * length), -math.sin(omega * length))
    for k in range(m):
        for l in range(k, m):
            s = rates[k] + rates[l]
            growth = ea[k] * ea[l]
            if abs(s) * length >= 0.5:
                pair[k, l] = growth * (el[k] * el[l] - 1.0) * inverse[k, l]
            else:
                pair[k, l] = growth * length * _series(s * length)
        s = rates[k]
        single[k] = ea[k] * ((el[k] - 1.0) / s if abs(s) * length >= 0.5 else length * _series(s * length))
        s = rates[k] - complex(0.0, omega)
        fourier[k] = ea[k] * wa * ((el[k] * wl - 1.0) * inverse[m, k] if abs(s) * length >= 0.5 else length * _series(s * length))
    s = complex(0.0, -omega)
    fourier[m] = wa * ((wl - 1.0) / s if abs(s) * length >= 0.5 else length * _series(s * length))


@njit(cache=True, error_model="numpy")
def _integrals(amps, constant, length, pair, single, fourier, phasor, out, slot_fourier, slot_square):
    """Add int x e^{-jwt} dt (``phasor`` = e^{-jw t0}) to out[slot_fourier] and int x^2 dt to out[slot_square]
    (if >= 0) for x = sum_k amps_k e^{rates_k u} + constant, from the piece's factors."""
    m = amps.size
    total = constant * fourier[m]
    for k in range(m):
        total += amps[k] * fourier[k]
    out[slot_fourier] += total * phasor
    if slot_square < 0:
        return
    square = constant * constant * length + 0j
    for k in range(m):
        square += amps[k] * (2.0 * constant * single[k] + amps[k] * pair[k, k])
        for l in range(k + 1, m):
            square += 2.0 * amps[k] * amps[l] * pair[k, l]
    out[slot_square] += square.real


@njit(cache=True, error_model="numpy")
def _add_moments(moments, row, stuck, lam, vec, hrm, cst, slam, svec, shrm, scst, omega, t_piece, modal, ta, tb, clearance, k2, b2, free_rates, stuck_rates, buffers, weights):
    """Add the piece's Fourier and square integrals over [ta, tb] to ``moments[row]``, in closed form (the motion is
    a sum of exponentials): X1 and X2 times e^{-jwt}, the holding force times e^{-jwt} while stuck, X1^2 and X2^2."""
    rates, inverse = stuck_rates if stuck else free_rates
    m = rates.size
    amps, pair, single, fourier = buffers[0][:m], buffers[1][:m, :m], buffers[2][:m], buffers[3][: m + 1]
    a, length = ta - t_piece, tb - ta
    _piece_factors(rates, inverse, omega, a, length, pair, single, fourier, buffers[4][:m], buffers[5][:m])
    phasor = complex(math.cos(omega * t_piece), -math.sin(omega * t_piece))
    out = moments[row]
    if stuck:
        _amplitudes(slam, svec, shrm, modal, omega, t_piece, weights[2], amps)
        _integrals(amps, scst[0], length, pair, single, fourier, phasor, out, 0, 3)
        _integrals(amps[:0], clearance, length, pair, single, fourier[m:], phasor, out, 1, 4)  # X2 = Delta
        _amplitudes(slam, svec, shrm, modal, omega, t_piece, weights[3], amps)
        _integrals(amps, k2 * (scst[0] - clearance) + b2 * scst[1], length, pair, single, fourier, phasor, out, 2, -1)
        return
    _amplitudes(lam, vec, hrm, modal, omega, t_piece, weights[0], amps)
    _integrals(amps, cst[0], length, pair, single, fourier, phasor, out, 0, 3)
    _amplitudes(lam, vec, hrm, modal, omega, t_piece, weights[1], amps)
    _integrals(amps, cst[1], length, pair, single, fourier, phasor, out, 1, 4)
