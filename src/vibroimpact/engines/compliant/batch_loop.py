"""Many runs of one bumper layout in one compiled call: the ``compliant_exact`` engine's batch loop
(:mod:`~vibroimpact.engines.batch_kernels` says what a batch runs and keeps; every number is the single run's, bit for
bit)."""

from __future__ import annotations

from numba import njit

from vibroimpact.engines.batch_kernels import batch_outputs, end_phase, run_start
from vibroimpact.engines.compliant.exact_loop import run_bumper_periods_until
from vibroimpact.engines.numba_cache import stamp_with_callees

__all__ = ["run_bumper_batch"]


@njit(cache=True, error_model="numpy", nogil=True)
def run_bumper_batch(
    lams, counts, vecs, invs, hrms, csts, zpros, znils, zdrvs, zdrv2s, polys, hlams, hcounts, rates_all, rinv_all, fastests,
    omega, period, obsw, obso, velw, salts, zero_har, gap_tolerance, force_tolerances, max_events, gl_nodes, gl_weights,
    case_of, starts, chain_from, transient, strobes, scales, max_period, cancel,
):  # fmt: skip
    """Run i: case ``case_of[i]`` (its entry of every stacked leading argument of
    :func:`~vibroimpact.engines.compliant.exact_loop.run_bumper_periods_until`) from ``starts[i]`` at t = 0,
    ``transient`` periods, then ``strobes`` periods with moments and Jacobians from the end state at t = 0 (as
    :func:`~vibroimpact.engines.batch_kernels.run_rigid_batch`)."""
    runs, n = starts.shape
    width = n + velw.shape[1]
    status, stopped, kept, jacobians, moments, impacts, velocities, after, mismatch = batch_outputs(runs, strobes, n, width, max_period)
    for i in range(runs):
        c = case_of[i]
        y = run_start(i, starts, chain_from, status, kept)
        for phase in range(2):  # the transient (nothing recorded), then the measured run
            periods = transient if phase == 0 else strobes
            if periods == 0:
                continue
            approach = phase > 1  # False, as a bool typed at run time: the single run's overload of the core (a literal False compiled it again, ~9 s)
            out = run_bumper_periods_until(
                lams[c], counts[c], vecs[c], invs[c], hrms[c], csts[c], zpros[c], znils[c], zdrvs[c], zdrv2s[c], polys[c], hlams[c], hcounts[c], rates_all[c], rinv_all[c], fastests[c],
                omega[c], period[c], obsw[c], obso[c], velw[c], salts[c], zero_har[c], gap_tolerance[c], force_tolerances[c], max_events[c], gl_nodes[c], gl_weights[c],
                y, 0.0, periods, phase == 1, phase == 1, approach, cancel,
            )  # fmt: skip
            if not end_phase(i, phase, out, period[c], scales[c], status, stopped, kept, jacobians, moments, impacts, velocities, after, mismatch):
                break
            y = out[2][-1].copy()
        if cancel[0] != 0:
            break
    return status, stopped, kept, jacobians, moments, impacts, velocities, after, mismatch


stamp_with_callees(globals())
