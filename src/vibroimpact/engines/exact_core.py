"""The compiled core of the ``exact`` engine: its whole event loop in one numba function, with the exact Jacobian.

Its kernels live beside it, shared with the ``compliant_exact`` loop: a piece of flow
(:mod:`~vibroimpact.engines.exact_pieces`), the guaranteed root search (:mod:`~vibroimpact.engines.exact_roots`), the
closed-form moments (:mod:`~vibroimpact.engines.exact_moments`) and the transition matrices and array helpers
(:mod:`~vibroimpact.engines.exact_matrices`). numba's on-disk cache is keyed by the source file
of each cached function only, so an edit of a kernel would not recompile its callers (numba PR #8396, unmerged; a
kernel module beside this one once served stale machine code): every compiled function here is stamped with their
sources (:mod:`~vibroimpact.engines.numba_cache`).

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

from vibroimpact.engines.exact_matrices import end_period, grow_rows, left_multiply, transition_matrix
from vibroimpact.engines.exact_moments import add_moments, add_moments_gl
from vibroimpact.engines.exact_pieces import NONE, YES, ZERO, halve_pairs, modal_coordinates, observable, piece_state, polynomial_part
from vibroimpact.engines.exact_roots import closest_approach, escape_step, first_crossing, observable_value, round_off_band
from vibroimpact.engines.kernel_arguments import LoopOutput
from vibroimpact.engines.numba_cache import stamp_with_callees

__all__ = ["run_periods", "run_periods_until", "sample_states", "STATUS_OK", "STATUS_NO_PROGRESS", "STATUS_TWO_STICKS"]

STATUS_OK, STATUS_NO_PROGRESS, STATUS_TWO_STICKS, STATUS_INTERRUPTED = 0, 1, 2, 3


# ------------------------------------------------------------------------------------ Jacobians, stops, bookkeeping
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
    modal_coordinates(lams, invs, hrms, csts, f, m, omega, t, y, modal)
    if polys[f]:
        polynomial_part(zpros, znils, zdrvs, zdrv2s, hrms, csts, f, omega, t, y, z0, q1, q2)
    har, con, p1, p2 = observable(hold_w, stop, hold_off[stop], hold_har[stop], vecs, hrms, csts, f, m, modal, amp, polys[f], z0, q1, q2)
    value = observable_value(lams, f, m, amp, ZERO, har, con, p1, p2, omega, t, t)
    if abs(value) > 64.0 * force_tolerance:
        return value < 0.0
    band = round_off_band(m, amp, ZERO, har, con, p1, p2, 0.0, force_tolerance)  # as the held search will allow
    return escape_step(lams, f, m, amp, ZERO, har, con, p1, p2, omega, t, t, band) >= 0.0


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
def run_periods(*arguments: object) -> LoopOutput:
    """Integrate ``periods`` periods from (t_start, y_start); see :class:`vibroimpact.engines.exact.ExactEngine`.

    The arguments are :func:`run_periods_until`'s without ``cancel`` (no one stops this run); returns its
    :class:`~vibroimpact.engines.kernel_arguments.LoopOutput`: ``status``, ``t`` (where it stopped), ``strobes``
    (periods + 1, n), ``jacobians`` (periods, n, n), ``impacts`` (m, 4): time, speed, impulse, stop, ``segments``
    (s, 3): start, mode, stop, ``segment_states`` (s, n), ``moments`` (periods, 2 N + K), ``counters`` [steps, events,
    sticks, releases, touches], ``approach`` [value, time, stop]; status :data:`STATUS_TWO_STICKS` stops the run where
    the structure would stick on two stops at once (at ``t``; ``approach[2]`` the other stop, ``counters[4]`` the
    first).
    """
    return LoopOutput._make(run_periods_until(*arguments, np.zeros(1, dtype=np.int64)))


@njit(cache=True, error_model="numpy", nogil=True)
def run_periods_until(
    lams, counts, vecs, invs, hrms, csts, zpros, znils, zdrvs, zdrv2s, polys, hlams, hcounts, rates_all, rinv_all, fastests,
    a_matrix, load, static, omega, period,
    gapw, velw, kickw, clearances, restitutions, masses, simple, signs,
    hold_w, hold_off, hold_har, force_tolerances, bounce, stick, touch,
    sticking_velocity, max_impacts, tolerance, resolution_velocity, gl_nodes, gl_weights,
    y_start, t_start, periods, want_moments, want_jacobians, want_approach, cancel,
):  # fmt: skip
    """:func:`run_periods` (its result a plain tuple) that another thread can stop: it returns
    :data:`STATUS_INTERRUPTED` (t where it stopped) at its next step once ``cancel[0]`` (int64 array of one entry) is
    nonzero. It releases the GIL (``nogil``), so the main thread can wait for it in Python and take a Ctrl-C meanwhile
    (:mod:`~vibroimpact.engines.interruptible`); reading the flag changes no number.
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
    stuck = NONE
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
    force_rows = np.arange(stops)  # the holding force of stop j: row j of hold_w, hold_off, hold_har
    held_impulses = np.zeros(stops)  # (the Gauss-Legendre moments integrate it too; a rigid stop's impulses are its impacts')
    ynew = np.empty(n)
    t_piece = t
    f = 0  # the piece's flow: 0 free, 1 + k held on stop k
    m = 0
    hm = 0
    poly = False
    while k <= periods:
        if cancel[0] != 0:  # asked to stop (a Ctrl-C in the waiting thread): what is done so far, flagged
            return STATUS_INTERRUPTED, t, strobes[:k], jacobians[: k - 1], impacts[:n_impacts], segments[:n_segments], segment_states[:n_segments], moments, counters, approach
        boundary = origin + k * period
        if fresh:
            t_piece = t
            f = stuck + 1
            m, hm, poly = counts[f], hcounts[f], polys[f]
            modal_coordinates(lams, invs, hrms, csts, f, m, omega, t, y, modal)
            if poly:
                polynomial_part(zpros, znils, zdrvs, zdrv2s, hrms, csts, f, omega, t, y, z0, q1, q2)
            for j in range(stops):
                if j == stuck:
                    har, con, p1, p2 = observable(hold_w, j, hold_off[j], hold_har[j], vecs, hrms, csts, f, m, modal, amp, poly, z0, q1, q2)
                    leave[j] = True  # a fresh stick's holding force starts by leaving zero (or the start is held)
                else:
                    har, con, p1, p2 = observable(gapw, j, -clearances[j], 0j, vecs, hrms, csts, f, m, modal, amp, poly, z0, q1, q2)
                    leave[j] = _gap(gapw, clearances, j, y) >= -tolerance  # at the surface: the search starts by leaving it
                hars[j], cons[j], p1s[j], p2s[j] = har, con, p1, p2
                halve_pairs(lams, f, m, amp, hamps, j)
                if leave[j]:
                    events_at[j] = t
            if n_segments == segments.shape[0]:
                segments = grow_rows(segments, n_segments + 1)
                segment_states = grow_rows(segment_states, n_segments + 1)
            segments[n_segments, 0], segments[n_segments, 1], segments[n_segments, 2] = t, 1.0 if stuck >= 0 else 0.0, stuck
            for r in range(n):
                segment_states[n_segments, r] = y[r]
            n_segments += 1
            fresh = False  # the piece lasts until the next event, across period boundaries
        counters[0] += 1
        t_event = math.nan
        event = NONE
        limit = boundary
        for j in range(stops):
            found = first_crossing(hlams, f, hm, hamps, j, hars[j], cons[j], p1s[j], p2s[j], omega, t_piece, t, limit, force_tolerances[j] if j == stuck else tolerance, leave[j])
            leave[j] = False
            if not math.isnan(found) and (event < 0 or found < t_event):
                t_event, event, limit = found, j, found
        t_end = boundary if event < 0 else t_event
        # moments, closest approach and the transition matrix of [t, t_end]
        if t_end > t:
            if want_moments:
                if poly:
                    held = (1 << stuck) if stuck >= 0 else 0
                    add_moments_gl(moments, k - 1, YES, held, force_rows, YES, held_impulses, lams, vecs, hrms, csts, f, m, modal, omega, t_piece, t, t_end, fastests[f], gl_nodes, gl_weights, hold_w, hold_off, hold_har, size, stops, z0, q1, q2, ybuf)
                else:
                    add_moments(moments, k - 1, stuck, lams, vecs, hrms, csts, f, m, modal, omega, t_piece, t, t_end, rates_all, rinv_all, buffers, hold_w, hold_off, hold_har, size, stops)
            if want_approach:
                for j in range(stops):
                    if j != stuck:
                        closest_approach(hlams, f, hm, hamps, j, hars[j], cons[j], p1s[j], p2s[j], omega, t_piece, t, t_end, fastests[f], approach, j)
            if want_jacobians:
                transition_matrix(lams, vecs, invs, f, m, t_end - t, poly, zpros, znils, phi)
                left_multiply(phi, jac, work)
        piece_state(lams, vecs, hrms, csts, f, m, omega, t_piece, modal, t_end, ynew, poly, z0, q1, q2)
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
            end_period(k, y, strobes, want_jacobians, jac, jacobians)
            k += 1
            events_period = 0
            continue
        events_period += 1
        if events_period > 10 * max_impacts:
            return STATUS_NO_PROGRESS, t, strobes, jacobians, impacts[:n_impacts], segments[:n_segments], segment_states[:n_segments], moments, counters, approach
        fresh = True
        if event == stuck:
            counters[3] += 1
            stuck = NONE  # release: continuous state and vector field, saltation = identity
            continue
        # an impact on stop ``event`` (from free flight, or while held on another stop, which it frees unless that
        # stop holds on after the impulse)
        held_before = stuck
        stuck = NONE
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
            left_multiply(salt, jac, work)
        impulse = masses[j] * (velocity - after)
        if velocity > 0.0:
            if n_impacts == impacts.shape[0]:
                impacts = grow_rows(impacts, n_impacts + 1)
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
    evaluates it (modal coordinates at the piece's start, :func:`piece_state`, round-off beyond a stop not held snapped
    onto it), so a time on a strobe gives the strobe state. Returns (len(times), n)."""
    count = times.size
    n = states.shape[1]
    out = np.empty((count, n))
    modal = np.empty(lams.shape[1], dtype=np.complex128)
    z0, q1, q2 = np.zeros(n), np.zeros(n), np.zeros(n)
    y = np.empty(n)
    current = NONE
    for i in range(count):
        p = pieces[i]
        f = flows[p]
        m = counts[f]
        poly = polys[f]
        if p != current:
            modal_coordinates(lams, invs, hrms, csts, f, m, omega, starts[p], states[p], modal)
            if poly:
                polynomial_part(zpros, znils, zdrvs, zdrv2s, hrms, csts, f, omega, starts[p], states[p], z0, q1, q2)
            current = p
        piece_state(lams, vecs, hrms, csts, f, m, omega, starts[p], modal, times[i], y, poly, z0, q1, q2)
        for j in range(clearances.size):
            if j != f - 1 and _gap(gapw, clearances, j, y) > 0.0:
                _snap(gapw, clearances, simple, signs, j, y)  # round-off beyond a stop is the stop
        for r in range(n):
            out[i, r] = y[r]
    return out


stamp_with_callees(globals())
