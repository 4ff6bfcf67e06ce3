"""Lyapunov exponents of the stroboscopic map: from its exact per-period Jacobians, or from two nearby trajectories.

The stroboscopic map P advances the state (x, x') (2N wide; (X1, X2, X1', X2') on the paper's layout) by one
excitation period T. Its largest Lyapunov exponent

    lambda_1 = lim (1/n) ln |J_{n-1} ... J_1 J_0 v|,   J_k = dP(y_k),

is in units of 1/period (divide by T for 1/s). It is > 0 on a chaotic attractor, 0 on an invariant circle
(quasi-periodic motion after a Neimark-Sacker bifurcation) and < 0 on a stable periodic orbit. The product is
renormalised every period (Benettin et al., Meccanica 15, 1980) so that it never overflows; the full spectrum comes
from the same product applied to an orthonormal frame re-orthonormalised by QR.

The error estimate is the standard error of block averages: the per-period logarithmic growths are cut into
``blocks`` consecutive blocks, and the spread of the block means divided by sqrt(blocks) says how far the mean over
the whole run can be from its limit (correlations shorter than a block are accounted for; a slow drift of the
attractor is not).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from vibroimpact.engines.base import Engine, Trajectory
from vibroimpact.model.problem import ImpactProblem

__all__ = ["LyapunovEstimate", "lyapunov_from_jacobians", "lyapunov_spectrum", "lyapunov_two_trajectories", "lyapunov_along_run", "block_estimate", "state_scales"]

#: A generic start direction: no component zero, no simple relation between components (so that it has a component
#: along every Oseledets direction, with probability one).
_GENERIC = np.array([0.5406, -0.3212, 0.7188, 0.3005, -0.1873, 0.6021, 0.2507, -0.4411])


def _generic(m: int) -> NDArray[np.float64]:
    """A fixed, generic start vector of length m (the first 8 entries are :data:`_GENERIC`)."""
    if m <= _GENERIC.size:
        return _GENERIC[:m].copy()
    extra = np.sin(1.618 * np.arange(_GENERIC.size, m) + 0.37) * 0.5
    return np.concatenate([_GENERIC, extra])


def _start_direction(problem: ImpactProblem) -> NDArray[np.float64]:
    """The unit start direction of a perturbation of the 2N-wide state: the paper's 4 entries on its layout."""
    v = _generic(2 * problem.size)
    return v / np.linalg.norm(v)


@dataclass(frozen=True)
class LyapunovEstimate:
    """A Lyapunov exponent of the stroboscopic map with its error.

    Attributes
    ----------
    exponent : float
        Largest Lyapunov exponent [1/period] (mean logarithmic growth per excitation period); ``-inf`` when the tangent
        vector was annihilated (a singular Jacobian, e.g. sticking that forgets the absorber's state).
    error : float
        Standard error of the block means [1/period] (``inf`` with fewer than 2 blocks).
    periods : int
        Periods averaged (after the discarded transient).
    growth : ndarray, shape (periods,)
        Logarithmic growth of the tangent vector (or of the separation) over each period [-].
    spectrum : ndarray, shape (m,)
        All exponents, largest first [1/period], when the full spectrum was computed; else ``(exponent,)``.
    spectrum_error : ndarray, shape (m,)
        Standard error of each entry of ``spectrum`` [1/period].
    """

    exponent: float
    error: float
    periods: int
    growth: NDArray[np.float64]
    spectrum: NDArray[np.float64]
    spectrum_error: NDArray[np.float64]

    def __post_init__(self) -> None:
        for name in ("growth", "spectrum", "spectrum_error"):
            getattr(self, name).setflags(write=False)


def block_estimate(growth: ArrayLike, blocks: int = 10) -> tuple[float, float]:
    """Mean of per-period logarithmic growths and the standard error of its block means.

    Parameters
    ----------
    growth : array_like, shape (n,)
        ln of the growth factor over each period [-].
    blocks : int
        Number of consecutive blocks (at most n); the trailing ``n % blocks`` values only enter the mean.

    Returns
    -------
    mean : float
        Mean growth per period [1/period] (``-inf`` if any growth is ``-inf``).
    error : float
        std(block means, ddof=1) / sqrt(blocks) [1/period]; ``inf`` with fewer than 2 blocks or a ``-inf`` growth.
    """
    g = np.asarray(growth, dtype=float).ravel()
    if g.size == 0:
        raise ValueError("growth is empty: at least one period is needed")
    if np.any(np.isneginf(g)):
        return -math.inf, math.inf
    mean = float(np.mean(g))
    b = min(int(blocks), g.size)
    if b < 2:
        return mean, math.inf
    size = g.size // b
    means = g[: size * b].reshape(b, size).mean(axis=1)
    return mean, float(np.std(means, ddof=1) / math.sqrt(b))


def _check_jacobians(jacobians: ArrayLike, transient: int | None) -> tuple[NDArray[np.float64], int]:
    """The Jacobians as a float array (n, m, m), checked, and the periods to skip (default n // 10)."""
    jac = np.asarray(jacobians, dtype=float)
    if jac.ndim != 3 or jac.shape[1] != jac.shape[2] or jac.shape[0] == 0 or jac.shape[1] == 0:
        raise ValueError(f"jacobians: expected shape (n, m, m) with n, m >= 1, got {jac.shape}")
    skip = jac.shape[0] // 10 if transient is None else int(transient)
    if not 0 <= skip < jac.shape[0]:
        raise ValueError(f"transient = {transient} is out of range: allowed [0, {jac.shape[0] - 1}] for {jac.shape[0]} Jacobians")
    if not np.all(np.isfinite(jac)):
        raise ValueError("jacobians: non-finite entries")
    return jac, skip


def lyapunov_from_jacobians(jacobians: ArrayLike, transient: int | None = None, blocks: int = 10, start: ArrayLike | None = None) -> LyapunovEstimate:
    """Largest Lyapunov exponent from a sequence of per-period Jacobians, by the renormalised product.

    Parameters
    ----------
    jacobians : array_like, shape (n, m, m)
        Entry k is d y_{k+1} / d y_k along the orbit (``Trajectory.strobe_jacobians``; m = 4 for the impact system).
    transient : int, optional
        Periods discarded while the tangent vector aligns with the most expanding direction; default n // 10.
    blocks : int
        Blocks of the error estimate (:func:`block_estimate`).
    start : array_like, shape (m,), optional
        Initial tangent vector; default a fixed generic vector.

    Returns
    -------
    LyapunovEstimate
        ``exponent`` [1/period], ``error``, per-period ``growth``.
    """
    jac, skip = _check_jacobians(jacobians, transient)
    n, m = jac.shape[0], jac.shape[1]
    v = np.array(start, dtype=float) if start is not None else _generic(m)
    norm = float(np.linalg.norm(v))
    if v.shape != (m,) or not norm > 0.0:
        raise ValueError(f"start: expected a non-zero vector of length {m}")
    v /= norm
    growth = np.empty(n)
    for k in range(n):
        v = jac[k] @ v
        norm = math.sqrt(float(v.dot(v)))  # np.linalg.norm's own arithmetic for a real vector, without its checks
        if norm == 0.0:  # exact: an annihilated tangent vector stays zero
            growth[k:] = -math.inf
            break
        growth[k] = math.log(norm)
        v /= norm
    kept = growth[skip:]
    exponent, error = block_estimate(kept, blocks)
    return LyapunovEstimate(exponent, error, kept.size, kept, np.array([exponent]), np.array([error]))


def lyapunov_spectrum(jacobians: ArrayLike, transient: int | None = None, blocks: int = 10) -> LyapunovEstimate:
    """All Lyapunov exponents from a sequence of per-period Jacobians, by repeated QR of a tangent frame.

    Q_{k+1} R_k = J_k Q_k; exponent i is the mean of ln |R_k[i, i]|. Their sum is the mean of ln |det J_k| (for the
    impact system's stroboscopic map, 2 ln R + tr(A) T per impact-period without sticking).

    Parameters
    ----------
    jacobians : array_like, shape (n, m, m)
        Entry k is d y_{k+1} / d y_k along the orbit.
    transient : int, optional
        Periods discarded while the frame aligns; default n // 10.
    blocks : int
        Blocks of the error estimate.

    Returns
    -------
    LyapunovEstimate
        ``spectrum`` (m,) largest first [1/period] with ``spectrum_error``; ``exponent``, ``error`` and ``growth``
        are those of the largest. A direction that a singular Jacobian annihilates has exponent ``-inf``.
    """
    jac, skip = _check_jacobians(jacobians, transient)
    n, m = jac.shape[0], jac.shape[1]
    rng = np.random.default_rng(20240611)  # a fixed generic frame: same answer every run
    q, _ = np.linalg.qr(rng.standard_normal((m, m)))
    logs = np.empty((n, m))
    with np.errstate(divide="ignore"):
        for k in range(n):
            q, r = np.linalg.qr(jac[k] @ q)
            d = np.abs(np.diag(r))
            logs[k] = np.log(d)
    kept = logs[skip:]
    estimates = [block_estimate(kept[:, i], blocks) for i in range(m)]
    spectrum = np.array([e[0] for e in estimates])
    errors = np.array([e[1] for e in estimates])
    order = np.argsort(-spectrum, kind="stable")
    spectrum, errors = spectrum[order], errors[order]
    return LyapunovEstimate(float(spectrum[0]), float(errors[0]), kept.shape[0], kept[:, order[0]].copy(), spectrum, errors)


def state_scales(problem: ImpactProblem) -> NDArray[np.float64]:
    """Scales of the state (x, x') that make a perturbation dimensionless [m ..., m/s ...], shape (2N,).

    L = Delta + v / w = 2 Delta + q |H12| for the displacements on the paper's layout (v = w (Delta + q |H12|) is the
    problem's velocity scale; the rigid-contact engines use the same length for their relative thresholds), in
    general the largest |Delta_k| plus v / w; w L for the velocities.
    """
    clearance = float(np.max(np.abs(problem.clearances()), initial=0.0))
    length = clearance + problem.length_scale()
    return np.repeat([length, problem.omega * length], problem.size)


def lyapunov_two_trajectories(
    engine: Engine,
    problem: ImpactProblem,
    state: ArrayLike,
    t_start: float,
    periods: int,
    relative_size: float = 1e-6,
    renormalise_every: int = 1,
    transient: int | None = None,
    blocks: int = 10,
) -> LyapunovEstimate:
    """Largest Lyapunov exponent of any engine, from a reference trajectory and a perturbed copy (Benettin).

    Every ``renormalise_every`` periods both copies are integrated by the same engine call from the same time, their
    separation d is measured in the dimensionless norm of :func:`state_scales`, ln(|d| / delta) is recorded, and the
    perturbed copy is restarted from the reference's end plus d rescaled back to size delta = ``relative_size``.

    Choice of delta. The separation must stay (a) far above the noise with which the engine reproduces a trajectory
    and (b) small enough to grow linearly over a renormalisation interval. (a) Two copies integrated alike take
    nearly the same steps and events, so their *difference* is reproduced far better than an integrator's rtol;
    still, a step-size decision or an event location that differs between them adds a jump of order rtol times the
    motion's scale, which reads as growth. delta must be >= ~100 rtol. Measured on the paper's system (R = 0.2, on
    the invariant circle at 21.1 Hz, exponent 0): ``momentary`` at rtol 1e-8 gives 0.0003 +- 0.0026 with delta =
    1e-5, 0.0011 +- 0.0025 with 1e-6 and -0.013 +- 0.010 with 1e-7 (noise); the ``exact`` engine gives the same
    exponent to 3 digits for delta = 1e-5 ... 1e-9 (also at 37.5 and 38.9 Hz) and garbage at 1e-11. (b) The impact
    system's nonlinearity is the stop: near-grazing flights stretch a separation by up to e^4.5 in one period on
    the chaotic attractors at 37-39 Hz, and two copies that straddle a grazing contact (one touches, the other not)
    separate at once by far more than delta e^{lambda m}; that happens with probability ~ delta per period, rarely
    at 1e-6. Default delta = 1e-6: right for the exact engine and for integrators at rtol <= 1e-8; at looser rtol
    tighten the tolerance rather than raise delta.

    Parameters
    ----------
    engine : Engine
        Any time-domain engine (``integrate(problem, state, t_start, periods, moments=False) -> Trajectory``).
    problem : ImpactProblem
        The problem.
    state : array_like, shape (4,)
        Start (X1, X2, X1', X2') [m, m, m/s, m/s] at ``t_start``, on the attractor (after the transient).
    t_start : float
        Start time [s] (a strobe time keeps the phase of the force).
    periods : int
        Periods to integrate (>= renormalise_every).
    relative_size : float
        delta: the separation, relative to :func:`state_scales` [-], in [1e-12, 1e-3].
    renormalise_every : int
        Periods between renormalisations (>= 1); use > 1 for engines whose per-call overhead dominates, while
        delta e^{lambda m} stays << 1.
    transient : int, optional
        Renormalisation intervals discarded while the separation aligns with the most expanding direction;
        default a tenth of them.
    blocks : int
        Blocks of the error estimate.

    Returns
    -------
    LyapunovEstimate
        ``exponent`` [1/period], ``error``, ``growth`` per renormalisation interval divided by its length.
    """
    if not 1e-12 <= relative_size <= 1e-3:
        raise ValueError(f"relative_size = {relative_size!r} is out of range: allowed [1e-12, 0.001]")
    every = int(renormalise_every)
    if every < 1 or int(periods) < every:
        raise ValueError(f"renormalise_every = {renormalise_every} and periods = {periods}: need 1 <= renormalise_every <= periods")
    intervals = int(periods) // every
    transient = intervals // 10 if transient is None else int(transient)
    if not 0 <= transient < intervals:
        raise ValueError(f"transient = {transient} is out of range: allowed [0, {intervals - 1}]")
    scale = state_scales(problem)
    y = np.array(state, dtype=float)
    d = _start_direction(problem) * relative_size
    t = float(t_start)
    growth = np.empty(intervals)
    for i in range(intervals):
        d = _inside(problem, y, d, scale)
        reference = engine.integrate(problem, y, t, every)
        perturbed = engine.integrate(problem, y + d * scale, t, every)
        y = np.array(reference.final_state, dtype=float)
        separation = (np.asarray(perturbed.final_state) - y) / scale
        size = float(np.linalg.norm(separation))
        if size == 0.0:  # exact: the copies merged (sticking forgets the absorber's state)
            growth[i:] = -math.inf
            break
        growth[i] = math.log(size / relative_size) / every
        d = separation * (relative_size / size)
        t = float(reference.strobe_times[-1])
    kept = growth[transient:]
    exponent, error = block_estimate(kept, blocks)
    return LyapunovEstimate(exponent, error, kept.size * every, kept, np.array([exponent]), np.array([error]))


def lyapunov_along_run(engine: Engine, problem: ImpactProblem, run: Trajectory, every: int, relative_size: float = 1e-6) -> LyapunovEstimate:
    """Largest Lyapunov exponent [1/period] of any engine along a run it made: a copy perturbed by ``relative_size``
    (of :func:`state_scales`) restarts from the run's strobe every ``every`` periods and its separation from the run's
    next strobe is measured and renormalised (Benettin), as :func:`lyapunov_two_trajectories` does, but with the run
    itself as the reference trajectory, so the estimate costs one more run of the same length instead of two.

    Parameters
    ----------
    engine : Engine
        The engine that made ``run``.
    problem : ImpactProblem
        The problem.
    run : Trajectory
        The reference, on the attractor, over at least ``every`` periods.
    every : int
        Periods between renormalisations (>= 1).
    relative_size : float
        delta, the separation (see :func:`lyapunov_two_trajectories` for the choice).

    Returns
    -------
    LyapunovEstimate
        The first tenth of the intervals is discarded while the separation aligns; the error is the spread of 10
        block averages.
    """
    intervals = run.periods // every
    scale = state_scales(problem)
    direction = _start_direction(problem)
    growth = np.empty(intervals)
    for i in range(intervals):
        start = run.strobe_states[i * every]
        d = _inside(problem, start, direction * relative_size, scale)
        copy = engine.integrate(problem, start + d * scale, float(run.strobe_times[i * every]), every)
        separation = (copy.final_state - run.strobe_states[(i + 1) * every]) / scale
        length = float(np.linalg.norm(separation))
        growth[i] = np.log(max(length, 1e-300) / relative_size) / every
        direction = separation / length if length > 0.0 else direction
    kept = growth[intervals // 10 :]
    exponent, error = block_estimate(kept, 10)
    return LyapunovEstimate(exponent, error, kept.size * every, kept, np.array([exponent]), np.array([error]))


def _inside(problem: ImpactProblem, y: NDArray[np.float64], d: NDArray[np.float64], scale: NDArray[np.float64]) -> NDArray[np.float64]:
    """The perturbation, turned away from every stop it would push the structure through.

    For each stop k whose gap
    Delta_k - n_k . (x + dx) would be negative, the displacement part is mirrored in the stop's plane (dx -> dx - 2
    (n_k . dx) n_k / |n_k|^2, the displacement scales being equal), which for n = e2 is the same sign flip.
    """
    size = problem.size
    for n, clearance in zip(problem.normals(), problem.clearances()):
        step = d[:size] * scale[:size]
        if clearance - n @ (y[:size] + step) < 0.0 and n @ step > 0.0:
            d = d.copy()
            d[:size] = d[:size] - 2.0 * (n @ d[:size]) * n / (n @ n)
    return d
