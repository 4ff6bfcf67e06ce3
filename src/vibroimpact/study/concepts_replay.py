"""The force on the base in the time domain with Kelvin-Voigt bumpers: a dense replay of a bumper steady state.

The ``compliant`` engine gives strobe states, fundamentals and contact peaks, not the signal between strobes. From a
steady state it found, this module integrates the same model again, densely, with SciPy (DOP853, its error control
stepping onto every contact's onset and end), for any structure and any bumper stops::

    M x'' + C x' + K x = Re(F e^{jwt}) + F0 - sum_k n_k lambda_k,
    lambda_k = max(0, K_k (-g_k) + B_k (-g_k')) while g_k = Delta_k - n_k . x < 0, else 0,

with K_k = m_eff Omega_b^2 and B_k = 2 m_eff xi_b Omega_b (:mod:`vibroimpact.model.stops`), and samples the force on
the base f(t) = 1^T (K x + C x') + sum_k (1^T n_k) lambda_k. The replay's state after the periods, against the
engine's, measures how far the two integrations agree (an independent check of the engine on the layout).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.integrate import solve_ivp

from vibroimpact.model.contact import KelvinVoigtBumper
from vibroimpact.model.problem import ImpactProblem

__all__ = ["Replay", "replay_base_force", "SAMPLES_PER_PERIOD"]

#: Samples of the force per excitation period (a 250 Hz bumper's contact of ~2 ms at 25 Hz: ~100 samples).
SAMPLES_PER_PERIOD = 4000


@dataclass(frozen=True)
class Replay:
    """A dense replay.

    Attributes
    ----------
    peak_base_force : float
        Largest |f(t)| over the replayed periods [N].
    end_state : ndarray, shape (2 N,)
        State after the periods.
    times, base_force : ndarray
        The samples [s] and f(t) [N].
    """

    peak_base_force: float
    end_state: NDArray[np.float64]
    times: NDArray[np.float64]
    base_force: NDArray[np.float64]


def replay_base_force(problem: ImpactProblem, t0: float, y0: NDArray[np.float64], periods: int = 1, rtol: float = 1e-10) -> Replay:
    """Integrate ``periods`` periods of ``problem`` (bumper stops only) from (``t0`` [s], ``y0``) and sample the force
    on the base."""
    stops = problem.stops
    if not all(isinstance(stop.law, KelvinVoigtBumper) for stop in stops):
        raise TypeError("replay_base_force: every stop must be a KelvinVoigtBumper")
    structure = problem.structure
    n = problem.size
    m, k, c = structure.mass_matrix, structure.stiffness_matrix, structure.damping_matrix
    minv = np.linalg.inv(m)
    harmonic, static = problem.load()
    normals, clearances = problem.normals(), problem.clearances()
    m_eff = np.array([stop.effective_mass(m) for stop in stops])
    omega_b = np.array([stop.law.omega for stop in stops])  # type: ignore[union-attr]
    xi = np.array([stop.law.loss_factor for stop in stops])  # type: ignore[union-attr]
    spring, dashpot = m_eff * omega_b**2, 2.0 * m_eff * xi * omega_b
    w = problem.omega
    ones = np.ones(n)
    through = normals.sum(axis=1)

    def contact(y: NDArray[np.float64]) -> NDArray[np.float64]:
        gap = clearances - normals @ y[:n]
        rate = -(normals @ y[n:])
        return np.where(gap < 0.0, np.maximum(spring * (-gap) + dashpot * (-rate), 0.0), 0.0)

    def field(t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        force = (harmonic * complex(math.cos(w * t), math.sin(w * t))).real + static - normals.T @ contact(y) - k @ y[:n] - c @ y[n:]
        return np.concatenate([y[n:], minv @ force])

    end = t0 + periods * problem.period
    times = t0 + np.arange(periods * SAMPLES_PER_PERIOD + 1) * (problem.period / SAMPLES_PER_PERIOD)
    y = np.asarray(y0, dtype=float)
    scale = float(np.max(np.abs(y[:n]))) + 1e-12
    # the dashpot's force jumps at a contact's onset: DOP853's error control shrinks the step onto it (no restart needed)
    solution = solve_ivp(field, (t0, end), y, method="DOP853", t_eval=times, rtol=rtol, max_step=0.05 / float(np.max(omega_b / (2.0 * math.pi))),
                         atol=rtol * scale * np.concatenate([np.ones(n), np.full(n, w)]))  # fmt: skip
    if solution.status != 0:
        raise RuntimeError(f"replay failed: {solution.message}")
    samples = solution.y.T
    lam = np.array([contact(sample) for sample in samples])
    force = samples[:, :n] @ k.T @ ones + samples[:, n:] @ c.T @ ones + lam @ through
    return Replay(float(np.max(np.abs(force))), samples[-1].copy(), times, force)
