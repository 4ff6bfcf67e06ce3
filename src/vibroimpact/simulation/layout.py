"""What steady states need to know of any layout: the linear steady state, the force on the base and a start that
respects every stop.

For the paper's layout these are the paper's quantities: the suspension force (K1 + j w B1) X1, the stop's force on
the base, the linear state q H X. For any structure the force on the base through its springs and dashpots is
1^T (K x + C x') (internal springs cancel in the sum), and an absolute stop k pushes the base with (1^T n_k) lambda_k
(+lambda for an upper stop, -lambda for a lower one; a relative stop acts inside the structure, 1^T n_k = 0).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.structure import LinearStructure

__all__ = ["base_force", "suspension_force", "base_coupling", "base_weights", "LinearState", "linear_state", "static_offset", "resting_state", "gaps"]


def base_coupling(system: LinearStructure) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(1^T K, 1^T C): the force on the base through the springs [N m-1] and dashpots [N s m-1] per coordinate
    ((K1, 0) and (B1, 0) for the paper's system)."""
    return system.stiffness_matrix.sum(axis=0), system.damping_matrix.sum(axis=0)


def base_force(system: LinearStructure, omega: ArrayLike, x: ArrayLike, through: ArrayLike | None = None, contact: ArrayLike | None = None) -> NDArray[np.complex128]:
    """Fundamental of the force on the base [N]: 1^T (K + j w C) x through the springs and dashpots, plus
    sum_k (1^T n_k) F_k of the stops' contact forces when given; the one formula of every closed form and study.

    Parameters
    ----------
    system : LinearStructure
        The structure (K, C).
    omega : array_like
        Angular frequency [rad s-1], broadcast against ``x``'s leading axes.
    x : array_like of complex, shape (..., N)
        Fundamentals of the coordinates [m].
    through : array_like, shape (K,), optional
        1^T n_k of each stop (:func:`base_weights`): +1 an upper stop against the base, -1 a lower one, 0 relative.
    contact : array_like of complex, shape (..., K), optional
        Fundamentals of the stops' contact forces [N].
    """
    stiffness, damping = base_coupling(system)
    force = np.einsum("...i,...i->...", stiffness + 1j * np.asarray(omega, dtype=float)[..., None] * damping, np.asarray(x))
    if contact is not None and through is not None:
        force = force + np.einsum("...k,k->...", np.asarray(contact), np.asarray(through, dtype=float))
    return force


def suspension_force(system: LinearStructure, omega: float, x: NDArray[np.complex128]) -> complex:
    """Fundamental of the force on the base through springs and dashpots [N] for coordinate fundamentals ``x`` [m]."""
    return complex(base_force(system, omega, x))


def base_weights(problem: ImpactProblem) -> NDArray[np.float64]:
    """1^T n_k of every stop: +1 an upper stop against the base, -1 a lower one, 0 a relative stop, shape (K,)."""
    return problem.normals().sum(axis=1)


def static_offset(problem: ImpactProblem) -> NDArray[np.float64]:
    """x0 = K^-1 F0, the static displacement under the constant load [m] (least squares on a free structure:
    no offset along a rigid-body mode); zeros without a static load."""
    _, static = problem.load()
    if not np.any(static):
        return np.zeros(problem.size)
    return np.linalg.lstsq(problem.structure.stiffness_matrix, static, rcond=None)[0]


class LinearState:
    """The linear steady state without stops: x(t) = x0 + Re(X e^{j w t}) (force phase included).

    Attributes
    ----------
    amplitudes : ndarray of complex, shape (N,)
        X [m].
    offset : ndarray, shape (N,)
        x0 [m].
    """

    def __init__(self, amplitudes: NDArray[np.complex128], offset: NDArray[np.float64]) -> None:
        self.amplitudes, self.offset = amplitudes, offset

    def state(self, omega: float) -> NDArray[np.float64]:
        """(x, x') at t = 0 [m, m s-1]."""
        return np.concatenate([self.offset + self.amplitudes.real, (1j * omega * self.amplitudes).real])

    def rms(self) -> NDArray[np.float64]:
        """RMS of each coordinate over a period [m]."""
        return np.sqrt(self.offset**2 + 0.5 * np.abs(self.amplitudes) ** 2)

    def fits(self, problem: ImpactProblem) -> bool:
        """Does the motion stay clear of every stop: n_k . x0 + |n_k . X| <= Delta_k?"""
        normals = problem.normals()
        reach = normals @ self.offset + np.abs(normals @ self.amplitudes)
        return bool(np.all(reach <= problem.clearances()))


def linear_state(problem: ImpactProblem) -> LinearState:
    """The linear steady state of ``problem`` without its stops (harmonic force with its phase)."""
    harmonic, _ = problem.load()
    h = problem.structure.receptance_matrix(problem.omega)
    return LinearState(h @ harmonic, static_offset(problem))


def gaps(problem: ImpactProblem, state: NDArray[np.float64]) -> NDArray[np.float64]:
    """Delta_k - n_k . x of every stop [m] (negative: inside the stop)."""
    return problem.clearances() - problem.normals() @ np.asarray(state[: problem.size], dtype=float)


def resting_state(problem: ImpactProblem) -> NDArray[np.float64]:
    """A state at rest that respects every stop: the static position, pushed onto the stops it would cross.

    The push is the one a contact gives, along M^-1 n_k: x = x0 - M^-1 N_a^T lambda with N_a x = Delta_a on the
    stops crossed (solved in the least-squares sense, repeated while another stop is crossed). Zeros for the paper's
    layout with a non-negative clearance.
    """
    size = problem.size
    x = static_offset(problem)
    normals, clearances = problem.normals(), problem.clearances()
    minv_n = np.linalg.solve(problem.structure.mass_matrix, normals.T)  # (N, K)
    active = np.zeros(len(clearances), dtype=bool)
    for _ in range(len(clearances) + 1):
        crossed = clearances - normals @ x < -1e-15 * (1.0 + np.abs(clearances))
        if not np.any(crossed & ~active):
            break
        active |= crossed
        a = normals[active]
        lam = np.linalg.lstsq(a @ minv_n[:, active], a @ x - clearances[active], rcond=None)[0]
        x = x - minv_n[:, active] @ lam
    return np.concatenate([x, np.zeros(size)])


def velocity_length(problem: ImpactProblem) -> float:
    """A length typical of the motion [m]: the problem's velocity scale over w (Delta + q |H12| for the paper)."""
    return problem.velocity_scale() / problem.omega if problem.omega > 0.0 else math.inf
