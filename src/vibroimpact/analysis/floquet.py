"""Floquet stability of the one-impact periodic orbit: monodromy = saltation matrix x exact flow over the period.

Between impacts the state y = (X1, X2, X1', X2') obeys y' = A y + b(t), so a perturbation is carried over the
period by exp(A T). The impact at X2 = Delta (surface normal n = e2) with the reset y+ = D y-, D = diag(1, 1, 1, -R),
adds the saltation matrix (Leine & Nijmeijer; di Bernardo et al.)::

    S = D + (f(y+) - D f(y-)) n^T / (n^T f(y-))

which accounts for the shift of the impact time. The monodromy from just after one impact to just after the next is
``S exp(A T)``; the orbit is asymptotically stable when all its eigenvalues (Floquet multipliers) lie inside the
unit circle.

Any structure (:class:`~vibroimpact.analysis.impact_orbit.ImpactOrbit`, 2N x 2N): the state is y = (x, x'), the
stop's gap Delta - n . x has the gradient -(n, 0), the reset is x'+ = x'- - (1 + R) m_eff M^-1 n n^T x'-, i.e.
D = blockdiag(I, I - (1 + R) m_eff M^-1 n n^T), and the same saltation formula with n^T f -> (n, 0) . f gives
S. One impact per period: monodromy S exp(A T). The symmetric two-sided orbit: S_u exp(A T/2) S_l exp(A T/2), the
lower impact at T/2 with the normal -n and the mirrored state (2 x_s - x, -x'); :func:`half_period_jacobian` is the
Jacobian -S exp(A T/2) of the half-period map y -> mirror(flow(y)), whose fixed point the symmetric orbit is: its
multiplier -1 is a symmetry-breaking pitchfork (the full multiplier +1), +1 a fold.

The orbit's class (:class:`~vibroimpact.analysis.impact_orbit.ImpactOrbit`) computes its multipliers here
(:attr:`~vibroimpact.analysis.impact_orbit.ImpactOrbit.multipliers`), so this module sits below it and imports it for
type checking only; :mod:`~vibroimpact.analysis.stability` re-exports these names with the regime flag.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from vibroimpact.model.keywords import suggest_keywords


if TYPE_CHECKING:  # annotations only: impact_orbit imports this module (ImpactOrbit.multipliers)
    from vibroimpact.analysis.impact_orbit import ImpactOrbit

__all__ = ["floquet_multipliers", "monodromy", "half_period_jacobian", "saltation"]


def _flow(state_matrix: NDArray[np.float64], duration: NDArray[np.float64]) -> NDArray[np.float64]:
    """exp(A t) for every duration, shape duration.shape + (2N, 2N), from one eigendecomposition."""
    eigenvalues, vectors = np.linalg.eig(state_matrix)
    inverse = np.linalg.inv(vectors)
    growth = np.exp(eigenvalues * np.asarray(duration)[..., None])
    return np.real(np.einsum("ij,...j,jk->...ik", vectors, growth, inverse))


def saltation(orbit: ImpactOrbit, lower: bool = False) -> NDArray[np.float64]:
    """The saltation matrix of the orbit's (upper, or lower) impact, shape S + (2N, 2N)."""
    layout = orbit.layout
    structure = layout.structure
    size = structure.size
    minv = np.linalg.inv(structure.mass_matrix)
    n = -layout.normal if lower else layout.normal
    before, after = orbit.state_before_impact(), orbit.state_after_impact()
    t_impact = orbit.impact_time
    static_load = structure.stiffness_matrix @ orbit.static
    if lower:  # the mirror image half a period later: x - x_s and x' change sign, so does the harmonic load
        mirror = np.concatenate([-np.ones(size), -np.ones(size)])
        shift = np.concatenate([2.0 * orbit.static, np.zeros(size)])
        before, after = before * mirror + shift, after * mirror + shift
        t_impact = t_impact + orbit.period / 2.0
    force = (orbit.load * np.exp(1j * orbit.omega * t_impact)[..., None]).real + static_load
    a = structure.state_matrix

    def field(y: NDArray) -> NDArray:
        return y @ a.T + np.concatenate([np.zeros_like(force), force @ minv.T], axis=-1)

    kick = (1.0 + orbit.restitution)[..., None, None] * layout.effective_mass * np.outer(minv @ n, n)
    reset = np.broadcast_to(np.eye(2 * size), orbit.omega.shape + (2 * size, 2 * size)).copy()
    reset[..., size:, size:] -= kick
    f_before, f_after = field(before), field(after)
    jump = f_after - np.einsum("...ij,...j->...i", reset, f_before)
    gradient = np.concatenate([n, np.zeros(size)])
    with np.errstate(divide="ignore", invalid="ignore"):
        return reset + jump[..., :, None] * gradient[None, :] / (f_before @ gradient)[..., None, None]


def monodromy(orbit: ImpactOrbit) -> NDArray[np.float64]:
    """The monodromy matrix from just after the (upper) impact over one period, shape S + (2N, 2N)."""
    a = orbit.layout.structure.state_matrix
    upper = saltation(orbit)
    if not orbit.two_sided:
        return upper @ _flow(a, orbit.period)
    half = _flow(a, orbit.period / 2.0)
    return upper @ half @ saltation(orbit, lower=True) @ half


def half_period_jacobian(orbit: ImpactOrbit) -> NDArray[np.float64]:
    """Two-sided orbits: -S exp(A T/2), the Jacobian of the half-period map (module docstring); monodromy = its square."""
    if not orbit.two_sided:
        raise ValueError("half_period_jacobian: the orbit is not the symmetric two-sided one")
    return -saltation(orbit) @ _flow(orbit.layout.structure.state_matrix, orbit.period / 2.0)


@suggest_keywords
def floquet_multipliers(solution: ImpactOrbit) -> NDArray[np.complex128]:
    """Floquet multipliers of each impact orbit, shape S + (2N,), sorted by decreasing modulus; NaN where no orbit
    exists.

    Parameters
    ----------
    solution : ImpactOrbit
        Any structure's orbit, one- or two-sided (:func:`vibroimpact.analysis.impact_orbit.solve_impact_orbit`,
        :func:`vibroimpact.analysis.pgf.solve_one_impact`).
    """
    matrix = monodromy(solution)
    size = matrix.shape[-1]
    out = np.full(solution.omega.shape + (size,), np.nan, dtype=complex)
    ok = solution.exists & np.all(np.isfinite(matrix), axis=(-2, -1))
    if np.any(ok):
        values = np.linalg.eigvals(matrix[ok])
        out[ok] = np.take_along_axis(values, np.argsort(-np.abs(values), axis=-1, kind="stable"), axis=-1)
    return out
