"""A period-1 orbit of a problem with Kelvin-Voigt bumpers by damped Newton on the engine's compiled loop directly:
the design search's bumper screen shoots some 150 orbits per design (:mod:`vibroimpact.orbits.bumper_screen`), and
through the general map (:class:`~vibroimpact.orbits.maps.ImpactMap`, :func:`~vibroimpact.orbits.shooting.shoot`)
three quarters of each evaluation's time was Python around the compiled period.

The iteration is :func:`~vibroimpact.orbits.shooting.shoot`'s, step for step: the residual (P(y) - y) / scale, the
Newton step on the exact Jacobian, halved until the 2-norm of the residual decreases by the Armijo factor; converged
when its largest entry is at most ``tolerance``. A period on which the loop makes no progress, a non-finite state or
Jacobian, and a singular Newton matrix end the shot without an orbit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from vibroimpact.engines.compliant import exact_loop

__all__ = ["PeriodOrbit", "shoot_period"]

#: The Armijo factor of the line search (:func:`~vibroimpact.orbits.shooting.shoot`'s).
_ARMIJO = 1e-4


@dataclass(frozen=True, eq=False)
class PeriodOrbit:
    """A period-1 orbit found by :func:`shoot_period`.

    Attributes
    ----------
    state : ndarray, shape (2N,)
        (x, x') at t = 0 [m, m s-1].
    monodromy : ndarray, shape (2N, 2N)
        The exact Jacobian of the period's stroboscopic map there (its eigenvalues are the Floquet multipliers).
    contacts : int
        Contact onsets over the period.
    iterations : int
        Newton steps taken.
    """

    state: NDArray[np.float64]
    monodromy: NDArray[np.float64]
    contacts: int
    iterations: int

    @property
    def floquet_modulus(self) -> float:
        """The largest |Floquet multiplier| [-]."""
        return float(np.max(np.abs(np.linalg.eigvals(self.monodromy))))


def shoot_period(arguments: tuple, guess: NDArray[np.float64], scale: NDArray[np.float64], tolerance: float, max_iterations: int, min_damping: float) -> PeriodOrbit | None:
    """The period-1 orbit near ``guess`` (module docstring), or None where Newton does not converge.

    Parameters
    ----------
    arguments : tuple
        The leading arguments of :func:`~vibroimpact.engines.compliant.exact_loop.run_bumper_periods` for the problem.
    guess : ndarray, shape (2N,)
        The start (x, x') at t = 0 [m, m s-1].
    scale : ndarray, shape (2N,)
        The residual's units (the map's ``state_scale``) [m, m s-1].
    tolerance : float
        Largest scaled residual of a converged orbit [-].
    max_iterations : int
        Newton steps before giving up.
    min_damping : float
        Smallest step fraction of the line search [-].
    """
    run = exact_loop.run_bumper_periods

    def period(y: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64], int] | None:
        if not np.all(np.isfinite(y)):
            return None
        out = run(*arguments, y.copy(), 0.0, 1, False, True, False)
        if out[0] == exact_loop.STATUS_NO_PROGRESS:
            return None
        return out[2][1], out[3][0], int(out[9].shape[0])

    y = np.array(guess, dtype=float)
    identity = np.eye(y.size)
    current = period(y)
    if current is None:
        return None
    r = (current[0] - y) / scale
    for iteration in range(max_iterations + 1):
        if not (np.all(np.isfinite(r)) and np.all(np.isfinite(current[1]))):
            return None
        if np.max(np.abs(r)) <= tolerance:
            return PeriodOrbit(y, current[1], current[2], iteration)
        if iteration == max_iterations:
            return None
        try:
            step = np.linalg.solve(current[1] - identity, -(current[0] - y))
        except np.linalg.LinAlgError:  # a multiplier exactly 1
            return None
        norm = float(np.linalg.norm(r))
        damping = 1.0
        while True:
            trial = y + damping * step
            trial_out = period(trial)
            if trial_out is not None:
                trial_r = (trial_out[0] - trial) / scale
                if np.all(np.isfinite(trial_r)) and np.linalg.norm(trial_r) <= (1.0 - _ARMIJO * damping) * norm:
                    break
            damping *= 0.5
            if damping < min_damping:
                return None
        y, current, r = trial, trial_out, trial_r
    return None
