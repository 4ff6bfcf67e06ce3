"""What the exact engines need of one problem: its flows (:mod:`.exact_flows`) and, per stop, its geometry, impact
maps and holding force.

The free flight is ``y' = A y + Re(b e^{jwt}) + b0`` from :meth:`~vibroimpact.model.problem.ImpactProblem.first_order`.
Held on stop k, the structure moves on the surface n_k . x = Delta_k: x = x_p + T q with T an orthonormal basis of the
plane n_k^T T = 0 and x_p = Delta_k n_k / |n_k|^2, so the held flow is the structure reduced by T (M_r = T^T M T, ...,
loads T^T (f - K x_p)), of 2N - 2 states, lifted to the full state. The holding force is
lambda_k = m_k (M^-1 n_k) . (f(t) - C x' - K x) (:meth:`~vibroimpact.model.problem.ImpactProblem.contact_holding`).

Every layout, the paper's included, is built by this one route.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from vibroimpact.engines.exact_flows import Flow, decompose, mechanical_null_basis
from vibroimpact.model.problem import ImpactProblem

__all__ = ["ExactModel", "build_model"]


@dataclass(frozen=True, eq=False)
class ExactModel:
    """Everything the exact engines need of one problem: its flows and, per stop, its geometry and impact maps.

    Attributes
    ----------
    size : int
        N coordinates (the state has n = 2 N entries).
    free : Flow
        Free flight.
    stuck : tuple of Flow
        Flight held on stop k (lifted to the full state), one per stop.
    matrix, load, static : ndarray
        A, b (complex) and b0 of the free flight (the vector field of the saltation matrices).
    normals : ndarray, shape (K, N)
        n_k (gap Delta_k - n_k . x).
    clearances, restitutions, masses : ndarray, shape (K,)
        Delta_k [m], R_k [-], effective mass m_k [kg].
    kicks : ndarray, shape (K, N)
        M^-1 n_k [kg-1].
    simple : ndarray of int, shape (K,)
        Index i if stop k is absolute and its impulse moves x_i alone (n_k = +-e_i, M^-1 n_k parallel to e_i): its
        position and velocity are then set exactly; -1 otherwise.
    hold_weights, hold_offsets, hold_harmonics : ndarray, shapes (K, n), (K,), (K,)
        Minus the holding force of stop k: -lambda_k = w . y + offset + Re(harmonic e^{jwt}) [N].
    force_tolerances : ndarray, shape (K,)
        Round-off of each holding force [N].
    bounce, stick, touch : ndarray, shape (K, n, n)
        The impact's velocity map D (y+ = D y- on the impact's velocity), sticking's, and a touch that sticks (which
        also holds the gap's position).
    """

    size: int
    free: Flow
    stuck: tuple[Flow, ...]
    matrix: NDArray[np.float64]
    load: NDArray[np.complex128]
    static: NDArray[np.float64]
    normals: NDArray[np.float64]
    clearances: NDArray[np.float64]
    restitutions: NDArray[np.float64]
    masses: NDArray[np.float64]
    kicks: NDArray[np.float64]
    simple: NDArray[np.int64]
    hold_weights: NDArray[np.float64]
    hold_offsets: NDArray[np.float64]
    hold_harmonics: NDArray[np.complex128]
    force_tolerances: NDArray[np.float64]
    bounce: NDArray[np.float64]
    stick: NDArray[np.float64]
    touch: NDArray[np.float64]


def _tangent(normal: NDArray[np.float64]) -> NDArray[np.float64]:
    """T (N x N-1), orthonormal, T^T n = 0: unit vectors off the stop's coordinates, and the complement of n on them."""
    size = normal.size
    support = np.flatnonzero(normal)
    columns = [np.eye(size)[:, i] for i in range(size) if i not in support]
    if support.size > 1:
        _u, _s, vt = np.linalg.svd(normal[support][None, :])
        for row in vt[1:]:
            column = np.zeros(size)
            column[support] = row
            columns.append(column)
    return np.array(columns).T.reshape(size, size - 1)


def _stuck_flow(problem: ImpactProblem, k: int) -> tuple[Flow, NDArray[np.float64]]:
    """The flow held on stop k, lifted to the full state, and the lift L (n x 2N-2)."""
    structure = problem.structure
    mass, stiffness, damping = structure.mass_matrix, structure.stiffness_matrix, structure.damping_matrix
    size = problem.size
    normal = problem.stops[k].normal(size)
    tangent = _tangent(normal)
    point = problem.stops[k].clearance * normal / float(normal @ normal)
    harmonic, static = problem.load()
    reduced = size - 1
    if reduced:
        mr, kr, cr = tangent.T @ mass @ tangent, tangent.T @ stiffness @ tangent, tangent.T @ damping @ tangent
        minv = np.linalg.inv(mr)
        a = np.block([[np.zeros((reduced, reduced)), np.eye(reduced)], [-minv @ kr, -minv @ cr]])
        b = np.concatenate([np.zeros(reduced, dtype=complex), minv @ (tangent.T @ harmonic)])
        b0 = np.concatenate([np.zeros(reduced), minv @ (tangent.T @ (static - stiffness @ point))])
        scales = float(np.max(np.abs(stiffness))), float(np.max(np.abs(damping)))
        flow = decompose(a, b, b0, problem.omega, mechanical_null_basis(mr, kr, cr, *scales))
    else:
        flow = decompose(np.zeros((0, 0)), np.zeros(0, dtype=complex), np.zeros(0), problem.omega)
    zero = np.zeros((size, reduced))
    lift = np.block([[tangent, zero], [zero, tangent]])
    offset = np.concatenate([point, np.zeros(size)])
    return flow.lifted(lift, offset, lift.T), lift  # T orthonormal: L^T is L's left inverse


def build_model(problem: ImpactProblem, length_scale: float) -> ExactModel:
    """The :class:`ExactModel` of a problem with rigid stops and a harmonic load; ``length_scale`` [m] sets the
    round-off of the holding forces (see :class:`~vibroimpact.engines.rigid_contact.RigidContact`)."""
    size, count = problem.size, len(problem.stops)
    n = 2 * size
    structure = problem.structure
    mass, stiffness, damping = structure.mass_matrix, structure.stiffness_matrix, structure.damping_matrix
    a, b, b0 = problem.first_order()
    normals = problem.normals()
    kicks = np.linalg.solve(mass, normals.T).T.reshape(count, size)
    masses = 1.0 / np.einsum("ki,ki->k", normals, kicks)
    harmonic, static = problem.load()
    simple = np.full(count, -1, dtype=np.int64)
    for k in range(count):
        support = np.flatnonzero(normals[k])
        if support.size == 1 and np.count_nonzero(kicks[k]) == 1 and kicks[k, support[0]] != 0.0:
            simple[k] = support[0]
    free = decompose(a, b, b0, problem.omega, mechanical_null_basis(mass, stiffness, damping))
    flows = [_stuck_flow(problem, k) for k in range(count)]
    stuck = tuple(flow for flow, _lift in flows)
    # lambda_k = m_k (M^-1 n_k) . (f(t) - C x' - K x): minus it, as weights over y, an offset and a harmonic
    hold_weights = np.array([masses[k] * np.concatenate([kicks[k] @ stiffness, kicks[k] @ damping]) for k in range(count)]).reshape(count, n)
    hold_offsets = np.array([-masses[k] * kicks[k] @ static for k in range(count)])
    hold_harmonics = np.array([-masses[k] * kicks[k] @ harmonic for k in range(count)], dtype=complex)
    tolerances = []
    for k, (_flow, lift) in enumerate(flows):
        on_surface = hold_weights[k] @ lift
        half = on_surface.size // 2
        spread = (np.sum(np.abs(on_surface[:half])) + problem.omega * np.sum(np.abs(on_surface[half:]))) * length_scale
        tolerances.append(1e-15 * (spread + abs(hold_harmonics[k]) + abs(hold_offsets[k])))
    force_tolerances = np.array(tolerances)
    restitutions = np.array([stop.law.restitution for stop in problem.stops])
    bounce, stick, touch = (np.tile(np.eye(n), (count, 1, 1)) for _ in range(3))
    for k in range(count):
        i = simple[k]
        if i >= 0:
            bounce[k, size + i, size + i] = -restitutions[k]
            stick[k, size + i, size + i] = 0.0
            touch[k, size + i, size + i] = 0.0
            touch[k, i, i] = 0.0
            continue
        outer = masses[k] * np.outer(kicks[k], normals[k])
        bounce[k, size:, size:] -= (1.0 + restitutions[k]) * outer
        stick[k, size:, size:] -= outer
        touch[k, size:, size:] -= outer
        touch[k, :size, :size] -= np.outer(normals[k], normals[k]) / float(normals[k] @ normals[k])
    return ExactModel(
        size=size, free=free, stuck=stuck, matrix=np.ascontiguousarray(a, dtype=float), load=np.asarray(b, dtype=complex),
        static=np.asarray(b0, dtype=float), normals=normals, clearances=problem.clearances(), restitutions=restitutions,
        masses=masses, kicks=kicks, simple=simple, hold_weights=hold_weights, hold_offsets=hold_offsets,
        hold_harmonics=hold_harmonics, force_tolerances=force_tolerances, bounce=bounce, stick=stick, touch=touch,
    )  # fmt: skip

