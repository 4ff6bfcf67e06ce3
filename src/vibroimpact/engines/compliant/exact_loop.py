"""The compiled core of the ``compliant_exact`` engine: the Kelvin-Voigt bumper's event loop in closed form, on the
``exact`` engine's machinery (the flows' pieces and observables, :mod:`~vibroimpact.engines.exact_pieces`; the
guaranteed first-root search, :mod:`~vibroimpact.engines.exact_roots`; transition matrices,
:mod:`~vibroimpact.engines.exact_matrices`; closed-form moments, :mod:`~vibroimpact.engines.exact_moments`), with the
bumper's contact law in place of the impact map.

Flows are stacked as :func:`~vibroimpact.engines.exact.stack_flows` stacks them, one per *contact mode*: flow f is the
structure with the bumpers of the stops in the bit mask f pushing (f = 0: free flight). Each stop k is in one of
three phases, each watched by observables h = w . y + offset of the current piece (rows 4 k ... 4 k + 3 of ``obsw``,
``obso``: the penetration d_k = n_k . x - Delta_k, -d_k, the bumper force F_k = K_k d_k + B_k n_k . x', -F_k), every
root found by :func:`~vibroimpact.engines.exact_roots.first_crossing` (Taylor bounds: none missed, however tangent):

* ``BELOW`` (free, d < 0): d rising to 0 is an onset;
* ``BEYOND`` (free, d >= 0 after a release with the bumper still compressed, F < 0): F rising to 0 is an onset (the
  bumper catches up again while d > 0), -d rising to 0 is the phase's end (d < 0 from there: ``BELOW``);
* ``CONTACT`` (bit k of the mode set): -F rising to 0 is the release (F >= 0 keeps d >= 0 throughout: where d
  returns to 0, F = B d' <= 0 has already vanished).

Whether an onset at a root starts a contact is decided as the exact engine decides a push: F > 0 beyond round-off,
or F = 0 and rising along the contact flow (its first non-zero derivative, :func:`_goes_negative` of -F); otherwise
the gap only touched the bumper. A release likewise needs F to fall along the free flight (a force that touches
zero and rises again keeps its contact). Onsets at d = 0 make the vector field jump by -M^-1 n_k B_k d'; everything
else is continuous. The Jacobian of the stroboscopic map is the product of the pieces' transition matrices and, at
each such onset, the saltation matrix S = I + (f+ - f-) (grad d)^T / (grad d . f-) = I - B_k (0, M^-1 n_k)(n_k, 0)^T
(``salts``; it does not depend on the entry speed); releases, onsets at d > 0 and phase ends have S = I.

Each contact's impulse (integral of F) and the Fourier moments of the coordinates and forces are integrated in
closed form piece by piece (the exact engine's factors; Gauss-Legendre on flows with rigid-body modes); its largest
force and largest deceleration -n_k . x'' are the largest of the values at the pieces' ends and of every interior
maximum, found by the same guaranteed search on the derivative (:func:`_largest`), not by sampling.

Numba's disk cache keys a compiled function on its own source file only: this module's functions compile those four
modules' kernels into themselves, so their cache index is stamped with their files as well
(:func:`~vibroimpact.engines.numba_cache.stamp_with_callees`) and an edit of any of them recompiles them.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from vibroimpact.engines.exact_matrices import end_period, grow_rows, left_multiply, transition_matrix
from vibroimpact.engines.exact_moments import add_moments_gl, coordinate_amplitudes, moment_integrals, piece_factors, weighted_amplitudes
from vibroimpact.engines.exact_pieces import halve_pairs, modal_coordinates, observable, piece_state, polynomial_part
from vibroimpact.engines.exact_roots import closest_approach, escape_step, first_crossing, observable_derivatives, observable_value, round_off_band
from vibroimpact.engines.numba_cache import stamp_with_callees

__all__ = ["run_bumper_periods_until", "sample_pieces", "STATUS_NO_PROGRESS"]

STATUS_OK, STATUS_NO_PROGRESS, STATUS_INTERRUPTED = 0, 1, 2
#: Phases of a stop (module docstring).
BELOW, BEYOND, CONTACT = 0, 1, 2
#: Most extrema of one observable :func:`_largest` visits in one call (at most a period): a contact's force has one or
#: two, a lightly damped bumper pressed for a whole period rings at Omega_b (200 maxima at 5 kHz and 25 Hz); a guard.
_MAX_EXTREMA = 100_000
#: Spacing of floats near 1.
_EPSILON = 2.220446049250313e-16
#: -1, 0, 1, True and False as typed values, not literals: numba compiles a callee once per literal argument (and a
#: variable first set to a literal is typed as one in the first pass of type inference), which made the first
#: compilation ~4x longer.
_NONE, _ZERO, _ONE, _YES, _NO = np.int64(-1), np.int64(0), np.int64(1), np.bool_(True), np.bool_(False)


# -------------------------------------------------------------------------------------------- observables of a piece
@njit(cache=True, error_model="numpy")
def _watch(obsw, obso, row, lams, vecs, hrms, csts, f, m, modal, amp, poly, z0, q1, q2, hamps, slot, hars, cons, p1s, p2s):
    """Observable ``row`` of the piece (flow f, ``modal`` coordinates) into slot ``slot`` of the watched ones."""
    har, con, p1, p2 = observable(obsw, row, obso[row], 0j, vecs, hrms, csts, f, m, modal, amp, poly, z0, q1, q2)
    halve_pairs(lams, f, m, amp, hamps, slot)
    hars[slot], cons[slot], p1s[slot], p2s[slot] = har, con, p1, p2


@njit(cache=True, error_model="numpy")
def _goes_negative(obsw, obso, row, lams, counts, vecs, invs, hrms, csts, zpros, znils, zdrvs, zdrv2s, polys, hlams, hcounts, f, omega, t, y, tolerance, modal, amp, hamp, z0, q1, q2):
    """Is observable ``row`` negative at (t, y) beyond round-off, or zero and falling along flow f (its first non-zero
    derivative; a rise that stays within round-off counts as a fall, as in the exact engine's push test)?"""
    m, hm, poly = counts[f], hcounts[f], polys[f]
    modal_coordinates(lams, invs, hrms, csts, f, m, omega, t, y, modal)
    if poly:
        polynomial_part(zpros, znils, zdrvs, zdrv2s, hrms, csts, f, omega, t, y, z0, q1, q2)
    har, con, p1, p2 = observable(obsw, row, obso[row], 0j, vecs, hrms, csts, f, m, modal, amp, poly, z0, q1, q2)
    halve_pairs(lams, f, m, amp, hamp, _ZERO)
    values = np.empty(2)
    row = _ZERO  # (not a literal: numba would compile the callees once more for it)
    observable_derivatives(hlams, f, hm, hamp, row, har, con, p1, p2, omega, t, t, values)
    band = round_off_band(hm, hamp, row, har, con, p1, p2, 0.0, tolerance)  # as a root search on it would allow
    # a root is as close to zero as the time axis allows: h moves by |h'| ulp(t) from one float of t to the next
    if abs(values[0]) > 64.0 * max(band, abs(values[1]) * _EPSILON * abs(t)):
        return values[0] < 0.0
    return escape_step(hlams, f, hm, hamp, row, har, con, p1, p2, omega, t, t, band) >= 0.0


@njit(cache=True, error_model="numpy")
def _largest(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, ta, tb, work, best):
    """The largest of ``best`` and of h over [ta, tb]: its ends and every interior maximum, where h' falls through 0
    (the guaranteed search on h' and -h' in turn: from a maximum to the next minimum, and on)."""
    d = np.empty(2)
    observable_derivatives(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, ta, d)
    best = max(best, d[0], observable_value(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, tb))
    if tb <= ta:
        return best
    for i in range(rc):
        work[0, i] = amp[ar, i] * rates[rr, i]
        work[1, i] = -work[0, i]
    rate = har * complex(0.0, omega)
    falling = d[1] > 0.0  # next: a maximum (-h' rising to 0); else a minimum first (h' rising to 0)
    leaving = _NO
    t = ta
    for _ in range(_MAX_EXTREMA):
        sign = -1.0 if falling else 1.0
        root = first_crossing(rates, rr, rc, work, 1 if falling else 0, sign * rate, sign * p1, sign * 2.0 * p2, 0.0, omega, t0, t, tb, 0.0, leaving)
        if math.isnan(root) or (leaving and root <= t):
            break
        if falling:
            best = max(best, observable_value(rates, rr, rc, amp, ar, har, con, p1, p2, omega, t0, root))
        if root >= tb:
            break
        t, falling, leaving = root, not falling, _YES
    return best


# ------------------------------------------------------------------------------------- what a piece adds to a period
@njit(cache=True, error_model="numpy")
def _piece_integrals(moments, row, want_moments, mask, impulses, lams, vecs, hrms, csts, f, m, modal, omega, t_piece, ta, tb, rates_all, rinv_all, buffers, obsw, obso, size, stops):
    """Over [ta, tb] of a piece without rigid-body modes, in closed form: each coordinate's Fourier and square
    integrals into ``moments[row]`` (if wanted), and for each stop in contact its force's impulse (into
    ``impulses``) and Fourier integral."""
    mm = m + 2
    amps, pair, single, fourier, ea, el = buffers
    length = tb - ta
    piece_factors(rates_all, rinv_all, f, mm, omega, ta - t_piece, length, pair, single, fourier, ea, el)
    phasor = complex(math.cos(omega * t_piece), -math.sin(omega * t_piece))
    if want_moments:
        for i in range(size):
            coordinate_amplitudes(vecs, hrms, f, m, modal, omega, t_piece, i, amps)
            moment_integrals(amps, mm, csts[f, i], length, pair, single, fourier, phasor, moments, row, i, size + stops + i)
    for j in range(stops):
        if not (mask >> j) & 1:
            continue
        minus = 4 * j + 3  # amplitudes of minus (-F): the force's
        weighted_amplitudes(vecs, hrms, f, m, modal, omega, t_piece, obsw, minus, 0j, amps)
        constant = -obso[minus]
        for r in range(obsw.shape[1]):
            constant -= obsw[minus, r] * csts[f, r]
        if want_moments:
            moment_integrals(amps, mm, constant, length, pair, single, fourier, phasor, moments, row, size + j, _NONE)
        total = constant * length
        for i in range(mm):
            total += (amps[i] * single[i]).real
        impulses[j] += total


@njit(cache=True, error_model="numpy")
def _peaks(mask, obsw, obso, velw, lams, vecs, hrms, csts, f, m, hlams, hm, modal, amp, poly, z0, q1, q2, scratch, work, omega, t_piece, ta, tb, peak_force, peak_deceleration):
    """Raise each stop in contact's largest force F and largest deceleration -n . x'' to their largest on [ta, tb]."""
    jw = complex(0.0, omega)
    for j in range(velw.shape[0]):
        if not (mask >> j) & 1:
            continue
        har, con, p1, p2 = observable(obsw, 4 * j + 2, obso[4 * j + 2], 0j, vecs, hrms, csts, f, m, modal, amp, poly, z0, q1, q2)
        halve_pairs(lams, f, m, amp, scratch, _ZERO)
        peak_force[j] = _largest(hlams, f, hm, scratch, _ZERO, har, con, p1, p2, omega, t_piece, ta, tb, work, peak_force[j])
        har, con, p1, p2 = observable(velw, j, 0.0, 0j, vecs, hrms, csts, f, m, modal, amp, poly, z0, q1, q2)
        halve_pairs(lams, f, m, amp, scratch, _ONE)
        for i in range(hm):  # -d/dt of n . x'
            scratch[1, i] *= -hlams[f, i]
        peak_deceleration[j] = _largest(hlams, f, hm, scratch, _ONE, -har * jw, -p1, -2.0 * p2, 0.0, omega, t_piece, ta, tb, work, peak_deceleration[j])


# ------------------------------------------------------------------------------------------------------- the loop
@njit(cache=True, error_model="numpy", nogil=True)
def run_bumper_periods_until(
    lams, counts, vecs, invs, hrms, csts, zpros, znils, zdrvs, zdrv2s, polys, hlams, hcounts, rates_all, rinv_all, fastests,
    omega, period, obsw, obso, velw, salts, zero_har, gap_tolerance, force_tolerances, max_events, gl_nodes, gl_weights,
    y_start, t_start, periods, want_moments, want_jacobians, want_approach, cancel,
):  # fmt: skip
    """Integrate ``periods`` periods from (t_start, y_start); see :class:`~vibroimpact.engines.compliant.exact.CompliantExactEngine`.

    Returns (by name, :class:`~vibroimpact.engines.kernel_arguments.BumperLoopOutput`) (status, t, strobes
    (periods + 1, n), jacobians (periods, n, n), impacts (c, 6): onset time, entry
    speed n . x', impulse, largest force, largest deceleration, stop, of each completed contact; segments (s, 2):
    start, contact mode, with segment_states (s, n); moments (periods, 2 N + K); counters [steps, events, onsets,
    touches, releases]; onsets (o, 5): time, entry speed n . x', stop, 1 for an onset at the surface (d = 0, from
    ``BELOW``) or 0 for one at d > 0 (``BEYOND``), and the free flight's d'' there (an onset at the surface; else 0),
    of each onset after the start; approach [value, time, stop]: the
    largest interior local maximum of a penetration d_k while stop k is ``BELOW`` (the closest approach of a free
    flight to the bumper's surface, the exact engine's :func:`~vibroimpact.engines.exact_roots.closest_approach`;
    -inf without one, or unless ``want_approach``)); status :data:`STATUS_NO_PROGRESS` stops the run at t after
    ``max_events`` in one period.

    Another thread can stop it: it returns :data:`STATUS_INTERRUPTED` (t where it stopped) at its next step once
    ``cancel[0]`` (int64 array of one entry) is nonzero. It releases the GIL (``nogil``), so the main thread can wait
    for it in Python and take a Ctrl-C meanwhile (:mod:`~vibroimpact.engines.interruptible`); reading the flag changes
    no number.
    """
    n = y_start.size
    size = n // 2
    stops = velw.shape[0]
    strobes = np.empty((periods + 1, n))
    jacobians = np.empty((periods if want_jacobians else 0, n, n))
    moments = np.zeros((periods if want_moments else 0, 2 * size + stops), dtype=np.complex128)
    contacts = np.empty((max(4, 2 * periods), 6))
    segments = np.empty((max(4, 2 * periods), 2))
    segment_states = np.empty((max(4, 2 * periods), n))
    counters = np.zeros(5, dtype=np.int64)
    onsets = np.empty((max(4, 2 * periods), 5))
    curvature = np.empty(3)
    approach = np.array([-math.inf, math.nan, -1.0])
    n_onsets = 0
    n_contacts = 0
    n_segments = 0
    widest = lams.shape[1]
    modal = np.empty(widest, dtype=np.complex128)
    other = np.empty(widest, dtype=np.complex128)
    amp = np.empty((1, widest), dtype=np.complex128)
    scratch = np.empty((2, widest), dtype=np.complex128)
    work = np.empty((2, widest), dtype=np.complex128)
    hamps = np.empty((2 * stops, widest), dtype=np.complex128)
    hars = np.empty(2 * stops, dtype=np.complex128)
    cons, p1s, p2s = np.empty(2 * stops), np.empty(2 * stops), np.empty(2 * stops)
    rows = np.zeros(2 * stops, dtype=np.int64)
    z0, q1, q2 = np.zeros(n), np.zeros(n), np.zeros(n)
    zb, qb1, qb2 = np.zeros(n), np.zeros(n), np.zeros(n)
    mm = widest + 2
    buffers = (np.empty(mm, dtype=np.complex128), np.empty((mm, mm), dtype=np.complex128), np.empty(mm, dtype=np.complex128), np.empty(mm + 1, dtype=np.complex128), np.empty(mm, dtype=np.complex128), np.empty(mm, dtype=np.complex128))
    jac = np.eye(n)
    phi = np.empty((n, n))
    product = np.empty((n, n))
    ybuf = np.empty(n)
    force_rows = 4 * np.arange(stops) + 2  # the force F_k: row 4 k + 2 of obsw, obso (zero_har: no harmonic part)
    ynew = np.empty(n)
    phase = np.zeros(stops, dtype=np.int64)
    onset_time, onset_speed = np.zeros(stops), np.zeros(stops)
    impulses, peak_force, peak_deceleration = np.zeros(stops), np.zeros(stops), np.zeros(stops)
    y = y_start.copy()
    t = t_start
    mask = _ZERO
    # the start's phases, stop by stop: in contact where the bumper pushes (or, at zero force, starts to)
    for j in range(stops):
        gap = obso[4 * j]
        speed = 0.0
        for r in range(n):
            gap += obsw[4 * j, r] * y[r]
            speed += velw[j, r] * y[r]
        if gap < 0.0:
            continue
        if _goes_negative(obsw, obso, 4 * j + 3, lams, counts, vecs, invs, hrms, csts, zpros, znils, zdrvs, zdrv2s, polys, hlams, hcounts, mask | (1 << j), omega, t, y, force_tolerances[j], other, amp, scratch, zb, qb1, qb2):
            mask |= 1 << j
            phase[j] = CONTACT
            onset_time[j], onset_speed[j], impulses[j], peak_force[j], peak_deceleration[j] = t, speed, 0.0, 0.0, 0.0
            counters[2] += 1
        elif gap > gap_tolerance:
            phase[j] = BEYOND
    origin = t
    for r in range(n):
        strobes[0, r] = y[r]
    k = 1
    fresh = True
    events_period = 0
    t_piece = t
    f = _ZERO
    m = _ZERO
    hm = _ZERO
    poly = False
    last_mask = -1
    while k <= periods:
        if cancel[0] != 0:  # asked to stop (a Ctrl-C in the waiting thread): what is done so far, flagged
            return STATUS_INTERRUPTED, t, strobes, jacobians, contacts[:n_contacts], segments[:n_segments], segment_states[:n_segments], moments, counters, onsets[:n_onsets], approach
        boundary = origin + k * period
        if fresh:
            t_piece = t
            f = mask
            m, hm, poly = counts[f], hcounts[f], polys[f]
            modal_coordinates(lams, invs, hrms, csts, f, m, omega, t, y, modal)
            if poly:
                polynomial_part(zpros, znils, zdrvs, zdrv2s, hrms, csts, f, omega, t, y, z0, q1, q2)
            for j in range(stops):
                # watched: d (below), F and -d (beyond), -F (in contact)
                rows[2 * j] = 4 * j + (3 if phase[j] == CONTACT else 2 if phase[j] == BEYOND else 0)
                rows[2 * j + 1] = 4 * j + 1 if phase[j] == BEYOND else -1
                for s in range(2 * j, 2 * j + 2):
                    if rows[s] >= 0:
                        _watch(obsw, obso, rows[s], lams, vecs, hrms, csts, f, m, modal, amp, poly, z0, q1, q2, hamps, s, hars, cons, p1s, p2s)
            if mask != last_mask:
                if n_segments == segments.shape[0]:
                    segments = grow_rows(segments, n_segments + 1)
                    segment_states = grow_rows(segment_states, n_segments + 1)
                segments[n_segments, 0], segments[n_segments, 1] = t, mask
                for r in range(n):
                    segment_states[n_segments, r] = y[r]
                n_segments += 1
                last_mask = mask
            fresh = False  # the piece lasts until the next event, across period boundaries
        counters[0] += 1
        t_event = math.nan
        event = -1
        limit = boundary
        for s in range(2 * stops):
            if rows[s] < 0:
                continue
            # every search starts as if leaving the surface: an observable at zero and rising is a root right here
            tolerance = gap_tolerance if rows[s] % 4 < 2 else force_tolerances[s // 2]
            found = first_crossing(hlams, f, hm, hamps, s, hars[s], cons[s], p1s[s], p2s[s], omega, t_piece, t, limit, tolerance, _YES)
            if not math.isnan(found) and (event < 0 or found < t_event):
                t_event, event, limit = found, s, found
        t_end = boundary if event < 0 else t_event
        if t_end > t:
            if want_jacobians:
                transition_matrix(lams, vecs, invs, f, m, t_end - t, poly, zpros, znils, phi)
                left_multiply(phi, jac, product)
            if mask != 0 or want_moments:
                if poly:
                    add_moments_gl(moments, k - 1, want_moments, mask, force_rows, _NO, impulses, lams, vecs, hrms, csts, f, m, modal, omega, t_piece, t, t_end, fastests[f], gl_nodes, gl_weights, obsw, obso, zero_har, size, stops, z0, q1, q2, ybuf)
                else:
                    _piece_integrals(moments, k - 1, want_moments, mask, impulses, lams, vecs, hrms, csts, f, m, modal, omega, t_piece, t, t_end, rates_all, rinv_all, buffers, obsw, obso, size, stops)
            if want_approach:
                for j in range(stops):
                    if phase[j] == BELOW:  # slot 2 j watches d_k
                        closest_approach(hlams, f, hm, hamps, 2 * j, hars[2 * j], cons[2 * j], p1s[2 * j], p2s[2 * j], omega, t_piece, t, t_end, fastests[f], approach, j)
            if mask != 0:
                _peaks(mask, obsw, obso, velw, lams, vecs, hrms, csts, f, m, hlams, hm, modal, amp, poly, z0, q1, q2, scratch, work, omega, t_piece, t, t_end, peak_force, peak_deceleration)
        piece_state(lams, vecs, hrms, csts, f, m, omega, t_piece, modal, t_end, ynew, poly, z0, q1, q2)
        for r in range(n):
            y[r] = ynew[r]
        t = t_end
        if event < 0:
            end_period(k, y, strobes, want_jacobians, jac, jacobians)
            k += 1
            events_period = 0
            continue
        events_period += 1
        if events_period > max_events:
            return STATUS_NO_PROGRESS, t, strobes, jacobians, contacts[:n_contacts], segments[:n_segments], segment_states[:n_segments], moments, counters, onsets[:n_onsets], approach
        counters[1] += 1
        fresh = True
        j = event // 2
        bit = 1 << j
        if phase[j] == CONTACT:
            # the force reached zero: a release if it goes on falling along the free flight (else it only touched zero)
            if _goes_negative(obsw, obso, 4 * j + 2, lams, counts, vecs, invs, hrms, csts, zpros, znils, zdrvs, zdrv2s, polys, hlams, hcounts, mask & ~bit, omega, t, y, force_tolerances[j], other, amp, scratch, zb, qb1, qb2):
                if n_contacts == contacts.shape[0]:
                    contacts = grow_rows(contacts, n_contacts + 1)
                contacts[n_contacts, 0], contacts[n_contacts, 1], contacts[n_contacts, 2] = onset_time[j], onset_speed[j], impulses[j]
                contacts[n_contacts, 3], contacts[n_contacts, 4], contacts[n_contacts, 5] = peak_force[j], peak_deceleration[j], j
                n_contacts += 1
                counters[4] += 1
                mask &= ~bit
                gap = obso[4 * j]
                for r in range(n):
                    gap += obsw[4 * j, r] * y[r]
                phase[j] = BEYOND if gap > gap_tolerance else BELOW
        elif phase[j] == BEYOND and event % 2 == 1:
            phase[j] = BELOW  # the compressed bumper's end passed: an onset is the gap closing again
        elif _goes_negative(obsw, obso, 4 * j + 3, lams, counts, vecs, invs, hrms, csts, zpros, znils, zdrvs, zdrv2s, polys, hlams, hcounts, mask | bit, omega, t, y, force_tolerances[j], other, amp, scratch, zb, qb1, qb2):
            # onset: the gap closing (the vector field jumps by the dashpot's force), or the force rising beyond it
            if want_jacobians and phase[j] == BELOW:
                left_multiply(salts[j], jac, product)
            speed = 0.0
            for r in range(n):
                speed += velw[j, r] * y[r]
            onset_time[j], onset_speed[j], impulses[j], peak_force[j], peak_deceleration[j] = t, speed, 0.0, 0.0, 0.0
            if n_onsets == onsets.shape[0]:
                onsets = grow_rows(onsets, n_onsets + 1)
            onsets[n_onsets, 0], onsets[n_onsets, 1], onsets[n_onsets, 2] = t, speed, j
            onsets[n_onsets, 3], onsets[n_onsets, 4] = 0.0, 0.0
            if phase[j] == BELOW:  # slot 2 j still watches d_k along the free flight that ends here
                observable_derivatives(hlams, f, hm, hamps, 2 * j, hars[2 * j], cons[2 * j], p1s[2 * j], p2s[2 * j], omega, t_piece, t, curvature)
                onsets[n_onsets, 3], onsets[n_onsets, 4] = 1.0, curvature[2]
            n_onsets += 1
            counters[2] += 1
            mask |= bit
            phase[j] = CONTACT
        else:
            counters[3] += 1  # the gap (or the force) touched zero without a contact
    return STATUS_OK, t, strobes, jacobians, contacts[:n_contacts], segments[:n_segments], segment_states[:n_segments], moments, counters, onsets[:n_onsets], approach


# ------------------------------------------------------------------------------------------------------ sampling
@njit(cache=True, error_model="numpy")
def sample_pieces(lams, counts, vecs, invs, hrms, csts, zpros, znils, zdrvs, zdrv2s, polys, omega, starts, flows, states, times, pieces):
    """The states at ``times``, exact: ``times[i]`` on piece ``pieces[i]`` (start ``starts[p]``, state ``states[p]``
    there, contact mode ``flows[p]``); a time on a piece's start gives its state as recorded (a start at rest is
    given back, not its round-off through the flow). Returns (len(times), n)."""
    n = states.shape[1]
    out = np.empty((times.size, n))
    modal = np.empty(lams.shape[1], dtype=np.complex128)
    z0, q1, q2 = np.zeros(n), np.zeros(n), np.zeros(n)
    y = np.empty(n)
    current = -1
    for i in range(times.size):
        p = pieces[i]
        f = flows[p]
        if p != current:
            modal_coordinates(lams, invs, hrms, csts, f, counts[f], omega, starts[p], states[p], modal)
            if polys[f]:
                polynomial_part(zpros, znils, zdrvs, zdrv2s, hrms, csts, f, omega, starts[p], states[p], z0, q1, q2)
            current = p
        if times[i] == starts[p]:
            for r in range(n):
                out[i, r] = states[p, r]
            continue
        piece_state(lams, vecs, hrms, csts, f, counts[f], omega, starts[p], modal, times[i], y, polys[f], z0, q1, q2)
        for r in range(n):
            out[i, r] = y[r]
    return out


stamp_with_callees(globals())
