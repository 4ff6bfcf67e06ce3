"""Many runs of one layout in one compiled call: the ``exact`` engine's batch loop, and what every batch loop keeps.

A brute force, a basin sampling or a certification runs hundreds of starts (and frequencies, and mistuned samples) of
one layout, each the same two runs: ``transient`` periods dropped, then ``strobes`` periods measured with their
moments and exact Jacobians. From Python each run costs an engine call (checks, the problem's set-up looked up, a
trajectory built), several times the compiled loop's own cost per period on short runs. Here one compiled call runs
them all: run i is case ``case_of[i]`` (a problem: its leading arguments stacked over the cases, entry c of each
stacked array) from ``starts[i]``, by calls of the engine's own loop with the arguments the single-run path gives it
(from t = 0, then from the transient's end state at t = 0 again), so every number is bit for bit the single run's.

What is kept of the measured run (:func:`keep_run`): its strobes, Jacobians and per-period moments, how many impacts
it had and the last :data:`KEPT_VELOCITIES` impact speeds, for each strobe how many impacts fell at or after it, and
the repeat test of the strobes for every period p up to the bound: max |s[j + p] - s[j]| / scale (NaN where a strobe
is NaN, inf where fewer than 2 p + 1 strobes), the test :func:`~vibroimpact.simulation.attractors.measure_motion`
applies. A run that fails (no progress, two stops held at once) keeps its status and the time it stopped at.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from vibroimpact.engines.exact_core import run_periods_until
from vibroimpact.engines.numba_cache import stamp_with_callees

__all__ = ["KEPT_VELOCITIES", "batch_outputs", "keep_run", "run_start", "end_phase", "run_rigid_batch"]

#: Impact speeds kept per run, the last ones (NaN-padded) [-].
KEPT_VELOCITIES = 64


@njit(cache=True, error_model="numpy")
def batch_outputs(runs, strobes, n, width, max_period):
    """The arrays a batch fills: status, stop time, strobes, Jacobians, moments, impact counts, the last impact speeds,
    impacts at or after each strobe, and the repeat test (module docstring)."""
    status = np.zeros(runs, dtype=np.int64)
    stopped = np.full(runs, math.nan)
    kept = np.full((runs, strobes + 1, n), math.nan)
    jacobians = np.full((runs, strobes, n, n), math.nan)
    moments = np.zeros((runs, strobes, width), dtype=np.complex128)
    impacts = np.zeros(runs, dtype=np.int64)
    velocities = np.full((runs, KEPT_VELOCITIES), math.nan)
    after = np.zeros((runs, strobes + 1), dtype=np.int64)
    mismatch = np.full((runs, max_period), math.inf)
    return status, stopped, kept, jacobians, moments, impacts, velocities, after, mismatch


@njit(cache=True, error_model="numpy")
def keep_run(i, strobes_run, jacobians_run, impacts_run, moments_run, period, scale, kept, jacobians, moments, impacts, velocities, after, mismatch):
    """Keep row ``i`` of a batch from a measured run (its strobes, Jacobians, impacts (m, >= 2): time, speed, ...,
    and moments); ``period`` [s] and ``scale`` (n,) of its case."""
    count, n = strobes_run.shape
    for j in range(count):  # element by element: an array-to-slice copy compiles numba's shape-error text (~4 s)
        for r in range(n):
            kept[i, j, r] = strobes_run[j, r]
    for j in range(jacobians_run.shape[0]):
        for r in range(n):
            for c in range(n):
                jacobians[i, j, r, c] = jacobians_run[j, r, c]
    for j in range(moments_run.shape[0]):
        for r in range(moments_run.shape[1]):
            moments[i, j, r] = moments_run[j, r]
    m = impacts_run.shape[0]
    impacts[i] = m
    first = max(0, m - KEPT_VELOCITIES)
    for r in range(first, m):
        velocities[i, r - first] = impacts_run[r, 1]
    for j in range(count):
        boundary = 0.0 + j * period  # the strobe's time as the trajectory gives it (t_start + k T)
        total = 0
        for r in range(m):
            if impacts_run[r, 0] >= boundary:
                total += 1
        after[i, j] = total
    for p in range(1, mismatch.shape[1] + 1):
        if count <= 2 * p:
            continue
        largest = -math.inf
        undefined = False
        for j in range(count - p):
            for r in range(n):
                value = abs(strobes_run[j + p, r] - strobes_run[j, r]) / scale[r]
                if value != value:  # NaN
                    undefined = True
                elif value > largest:
                    largest = value
        mismatch[i, p - 1] = math.nan if undefined else largest


@njit(cache=True, error_model="numpy")
def run_start(i, starts, chain_from, status, kept):
    """Where run i starts: where run ``chain_from[i]`` ended, if it is a run (a stepped sweep) and it did not fail;
    else ``starts[i]`` (a copy)."""
    j = chain_from[i]
    return kept[j, kept.shape[1] - 1].copy() if j >= 0 and status[j] == 0 else starts[i].copy()


@njit(cache=True, error_model="numpy")
def end_phase(i, phase, out, period, scale, status, stopped, kept, jacobians, moments, impacts, velocities, after, mismatch):
    """After phase ``phase`` of run i (0: the transient, 1: the measured run; ``out`` the loop's output): its failure
    recorded (status, time; False: the run ends here), or the measured run kept (:func:`keep_run`)."""
    if out[0] != 0:
        status[i], stopped[i] = out[0], out[1]
        return False
    if phase == 1:
        keep_run(i, out[2], out[3], out[4], out[7], period, scale, kept, jacobians, moments, impacts, velocities, after, mismatch)
    return True


@njit(cache=True, error_model="numpy", nogil=True)
def run_rigid_batch(
    lams, counts, vecs, invs, hrms, csts, zpros, znils, zdrvs, zdrv2s, polys, hlams, hcounts, rates_all, rinv_all, fastests,
    a_matrix, load, static, omega, period,
    gapw, velw, kickw, clearances, restitutions, masses, simple, signs,
    hold_w, hold_off, hold_har, force_tolerances, bounce, stick, touch,
    sticking_velocity, max_impacts, tolerance, resolution_velocity, gl_nodes, gl_weights,
    case_of, starts, chain_from, transient, strobes, scales, max_period, cancel,
):  # fmt: skip
    """Run i: case ``case_of[i]`` (its entry of every stacked leading argument of
    :func:`~vibroimpact.engines.exact_core.run_periods_until`) from ``starts[i]`` at t = 0 (where ``chain_from[i]``
    = j >= 0, from run j's end state, unless run j failed: a stepped sweep; j < i), ``transient`` periods, then
    ``strobes`` periods with moments and Jacobians from the end state at t = 0; ``scales`` (cases, n) the repeat
    test's scales, ``max_period`` its longest period. Returns :func:`batch_outputs`' arrays; stops at the next step
    once ``cancel[0]`` is nonzero."""
    runs, n = starts.shape
    width = n + clearances.shape[1]
    status, stopped, kept, jacobians, moments, impacts, velocities, after, mismatch = batch_outputs(runs, strobes, n, width, max_period)
    for i in range(runs):
        c = case_of[i]
        y = run_start(i, starts, chain_from, status, kept)
        for phase in range(2):  # the transient (nothing recorded), then the measured run
            periods = transient if phase == 0 else strobes
            if periods == 0:
                continue
            approach = phase > 1  # False, as a bool typed at run time: the single run's overload of the core (a literal False compiled it again, ~9 s)
            out = run_periods_until(
                lams[c], counts[c], vecs[c], invs[c], hrms[c], csts[c], zpros[c], znils[c], zdrvs[c], zdrv2s[c], polys[c], hlams[c], hcounts[c], rates_all[c], rinv_all[c], fastests[c],
                a_matrix[c], load[c], static[c], omega[c], period[c], gapw[c], velw[c], kickw[c], clearances[c], restitutions[c], masses[c], simple[c], signs[c],
                hold_w[c], hold_off[c], hold_har[c], force_tolerances[c], bounce[c], stick[c], touch[c],
                sticking_velocity[c], max_impacts[c], tolerance[c], resolution_velocity[c], gl_nodes[c], gl_weights[c],
                y, 0.0, periods, phase == 1, phase == 1, approach, cancel,
            )  # fmt: skip
            if not end_phase(i, phase, out, period[c], scales[c], status, stopped, kept, jacobians, moments, impacts, velocities, after, mismatch):
                break
            y = out[2][-1].copy()
        if cancel[0] != 0:
            break
    return status, stopped, kept, jacobians, moments, impacts, velocities, after, mismatch


stamp_with_callees(globals())
