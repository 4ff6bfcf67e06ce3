"""Floquet stability of the one-impact periodic orbit: monodromy = saltation matrix x exact flow over the period.

Between impacts the state y = (X1, X2, X1', X2') obeys y' = A y + b(t), so a perturbation is carried over the
period by exp(A T). The impact at X2 = Delta (surface normal n = e2) with the reset y+ = D y-, D = diag(1, 1, 1, -R),
adds the saltation matrix (Leine & Nijmeijer; di Bernardo et al.)::

    S = D + (f(y+) - D f(y-)) n^T / (n^T f(y-))

which accounts for the shift of the impact time. The monodromy from just after one impact to just after the next is
``S exp(A T)``; the orbit is asymptotically stable when all its eigenvalues (Floquet multipliers) lie inside the
unit circle.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from vibroimpact.analysis.pgf import OneImpactSolution

__all__ = ["floquet_multipliers", "is_stable"]


def _flow_over_period(solution: OneImpactSolution) -> NDArray[np.float64]:
    """exp(A T) for every point, shape (..., 4, 4), from one eigendecomposition of the state matrix."""
    eigenvalues, vectors = np.linalg.eig(solution.system.state_matrix)
    inverse = np.linalg.inv(vectors)
    growth = np.exp(eigenvalues * solution.period[..., None])  # (..., 4)
    return np.real(np.einsum("ij,...j,jk->...ik", vectors, growth, inverse))


def floquet_multipliers(solution: OneImpactSolution) -> NDArray[np.complex128]:
    """Floquet multipliers of each one-impact orbit, shape (..., 4); NaN where no solution exists.

    Parameters
    ----------
    solution : OneImpactSolution
        Solutions from :func:`vibroimpact.analysis.pgf.solve_one_impact`.
    """
    system = solution.system
    shape = solution.omega.shape
    zeros = np.zeros(shape + (1,))
    ends = np.concatenate([zeros, solution.period[..., None]], axis=-1)  # t = 0+ and t = T- (= 0-)
    x1 = solution.x1(ends)
    v1 = solution.x1(ends, 1)
    v2 = solution.x2(ends, 1)
    position = np.stack([x1[..., 0], solution.clearance], axis=-1)
    forcing_phase = solution.phase - np.angle(solution.receptances.h12)
    force = np.stack([solution.amplitude * np.cos(forcing_phase), np.zeros(shape)], axis=-1)
    minv = np.linalg.inv(system.mass_matrix)

    def vector_field(velocity: NDArray) -> NDArray:
        acceleration = (force - position @ system.stiffness_matrix.T - velocity @ system.damping_matrix.T) @ minv.T
        return np.concatenate([velocity, acceleration], axis=-1)

    before = vector_field(np.stack([v1[..., 1], v2[..., 1]], axis=-1))
    after = vector_field(np.stack([v1[..., 0], v2[..., 0]], axis=-1))
    reset = np.broadcast_to(np.eye(4), shape + (4, 4)).copy()
    reset[..., 3, 3] = -solution.restitution
    normal = np.array([0.0, 1.0, 0.0, 0.0])
    jump = after - np.einsum("...ij,...j->...i", reset, before)
    with np.errstate(divide="ignore", invalid="ignore"):
        saltation = reset + jump[..., :, None] * normal[None, :] / before[..., 1, None, None]
    monodromy = saltation @ _flow_over_period(solution)
    multipliers = np.full(shape + (4,), np.nan, dtype=complex)
    ok = solution.exists & np.all(np.isfinite(monodromy), axis=(-2, -1))
    multipliers[ok] = np.linalg.eigvals(monodromy[ok])
    return multipliers


def is_stable(solution: OneImpactSolution) -> NDArray[np.bool_]:
    """True where the one-impact orbit exists and all Floquet multipliers satisfy |mu| < 1."""
    moduli = np.abs(floquet_multipliers(solution))
    return solution.exists & np.all(np.isfinite(moduli), axis=-1) & np.all(np.nan_to_num(moduli, nan=np.inf) < 1.0, axis=-1)
