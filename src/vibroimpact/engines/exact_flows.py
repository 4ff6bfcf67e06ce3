"""The closed-form flows of the exact engines, for any linear structure with any rigid stops.

Between events the state y = (x, x') of N coordinates obeys ``y' = A y + Re(b e^{jwt}) + b0`` (free flight), or the
same structure held on stop k (``n_k . x = Delta_k``, ``n_k . x' = 0``: stuck). Each flow is split into

* the invariant subspace W of the nonzero eigenvalues of A, where it is a sum of exponentials, and
* the generalized null space Z of A (rigid-body modes: a free mass), where A is nilpotent (Jordan blocks of size
  <= 2: ``A_z^2 = 0``, so ``e^{A_z tau} = I + A_z tau``) and a constant load drives a polynomial of degree <= 2,

so that from (t0, y0), with tau = t - t0 and the periodic-plus-constant particular solution
``p(t) = Re(Y e^{jwt}) + y_c`` (``Y = (jw I - A)^-1 b``, ``y_c`` = minus the Drazin inverse of A times b0),

    y(t) = p(t) + Re(V diag(e^{lambda tau}) m) + z0 + q1 tau + q2 tau^2,
    m = V^+ (y0 - p(t0)),  z0 = P_z (y0 - p(t0)),  q1 = A_z z0 + c,  q2 = A_z c / 2,  c = P_z b0

(P_z the spectral projector on Z along W, ``A_z = A P_z``). A stuck flow is built in the 2N - 2 coordinates of the
surface (x = x_p + T q) and lifted to the full state (y = L s + l0, s = L^+ (y - l0)), so that every flow of a problem
has the same shape and the compiled loop treats them alike; a lifted flow projects its start onto the surface. For
N = 1 the stuck flow has no coordinates: the state just sits on the stop.

A whole problem's flows and stop maps are assembled in :mod:`~vibroimpact.engines.exact_flows`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.structure import resonance_refusal, stiffness_modes

__all__ = ["Flow", "decompose", "unforced_flow", "harmonic_response", "mechanical_null_basis", "ExactModel", "build_model"]

#: Relative size below which an eigenvalue of the damping on K's rigid-body modes counts as zero (a rigid mode no
#: dashpot resists); K's own rigid modes are the model's one rule (:func:`~vibroimpact.model.structure.stiffness_modes`).
_ZERO = 1e-12
#: Largest condition number of the modal basis [V | Z] (a defective nonzero eigenvalue has none).
_CONDITION = 1e12


@dataclass(frozen=True, eq=False)
class Flow:
    """The closed-form flow of one mode of motion (see module docstring), in the full state's coordinates.

    Attributes
    ----------
    eigenvalues : ndarray of complex, shape (m,)
        Nonzero eigenvalues lambda [s-1] (Re <= 0); complex ones in conjugate pairs.
    vectors : ndarray of complex, shape (n, m)
        V, their eigenvectors.
    inverse : ndarray of complex, shape (m, n)
        V^+, the rows of [V | Z]^-1 that give the modal coordinates m.
    harmonic : ndarray of complex, shape (n,)
        Y, complex amplitude of the harmonic particular solution [state units].
    constant : ndarray, shape (n,)
        y_c, the constant particular solution (in W; on a lifted flow it includes the surface's offset l0).
    projector : ndarray, shape (n, n)
        P_z, the spectral projector on the generalized null space (zero without rigid-body modes).
    nilpotent : ndarray, shape (n, n)
        A_z = A P_z [s-1] (A_z^2 = 0).
    drift : ndarray, shape (n,)
        c = P_z b0 [state units s-1]: the constant load's part that drives the polynomial.
    omega : float
        Forcing angular frequency w [rad s-1].
    """

    eigenvalues: NDArray[np.complex128]
    vectors: NDArray[np.complex128]
    inverse: NDArray[np.complex128]
    harmonic: NDArray[np.complex128]
    constant: NDArray[np.float64]
    projector: NDArray[np.float64]
    nilpotent: NDArray[np.float64]
    drift: NDArray[np.float64]
    omega: float

    @property
    def polynomial(self) -> bool:
        """Does the flow have rigid-body (polynomial) terms?"""
        return bool(np.any(self.projector != 0.0))

    @property
    def drift2(self) -> NDArray[np.float64]:
        """q2 = A_z c / 2 [state units s-2]."""
        return 0.5 * (self.nilpotent @ self.drift)

    def particular(self, t: float | NDArray[np.float64]) -> NDArray[np.float64]:
        """p(t) = Re(Y e^{jwt}) + y_c, shape (..., n)."""
        phasor = np.exp(1j * self.omega * np.asarray(t, dtype=float))[..., None]
        return np.real(self.harmonic * phasor) + self.constant

    def lifted(self, lift: NDArray[np.float64], offset: NDArray[np.float64], left_inverse: NDArray[np.float64]) -> "Flow":
        """This flow of s, mapped to y = lift s + offset (s = left_inverse (y - offset))."""
        return Flow(
            eigenvalues=self.eigenvalues,
            vectors=np.ascontiguousarray(lift @ self.vectors).astype(complex),
            inverse=np.ascontiguousarray(self.inverse @ left_inverse).astype(complex),
            harmonic=(lift @ self.harmonic).astype(complex),
            constant=lift @ self.constant + offset,
            projector=lift @ self.projector @ left_inverse,
            nilpotent=lift @ self.nilpotent @ left_inverse,
            drift=lift @ self.drift,
            omega=self.omega,
        )


def numeric_null_basis(matrix: NDArray[np.float64]) -> NDArray[np.float64]:
    """A basis of the generalized null space of a general square matrix (null(A^2)), from singular values."""
    a = np.asarray(matrix, dtype=float)
    n = a.shape[0]
    if n == 0:
        return np.zeros((0, 0))
    scale = float(np.linalg.norm(a, 2)) or 1.0
    _u, s, vt = np.linalg.svd(a @ a)
    zero = int(np.sum(s <= (1e-8 * scale) ** 2))
    if int(np.sum(np.linalg.svd(a @ a @ a, compute_uv=False) <= (1e-8 * scale) ** 3)) > zero:
        raise ValueError("system: the state matrix has a Jordan block at zero longer than 2 (a rigid-body chain); the exact engine handles blocks of size <= 2 only")
    return vt[n - zero :].T.copy() if zero else np.zeros((n, 0))


def mechanical_null_basis(
    mass: NDArray[np.float64], stiffness: NDArray[np.float64], damping: NDArray[np.float64], stiffness_scale: float = 0.0, damping_scale: float = 0.0,
) -> NDArray[np.float64]:  # fmt: skip
    """A basis of the generalized null space of ``A = [[0, I], [-M^-1 K, -M^-1 C]]``, from its structure.

    null(A) = {(r, 0): K r = 0} (every rigid-body mode r); a rigid mode u that no dashpot resists (r^T C u = 0 for all
    rigid r) adds a Jordan chain of length 2, (x_u, u) with K x_u = -C u (then A (x_u, u) = (u, 0)). Longer chains
    cannot occur (M is definite), so A_z^2 = 0.

    K's rigid modes are the model's one rule (:func:`~vibroimpact.model.structure.stiffness_modes`).
    ``stiffness_scale`` and ``damping_scale`` [N m-1, N s m-1] are the scales below which an eigenvalue is round-off
    zero, at least the matrices' own: a reduced (held) structure passes the full structure's, since its K may be
    round-off alone (a free-free pair held together by a relative stop: T^T K T ~ 1e-29 of nothing).
    """
    size = mass.shape[0]
    if size == 0:
        return np.zeros((0, 0))
    modes = stiffness_modes(stiffness, floor=stiffness_scale)
    rigid = modes.rigid
    if rigid.shape[1] == 0:
        return np.zeros((2 * size, 0))
    inner = rigid.T @ damping @ rigid
    nu, w = np.linalg.eigh(0.5 * (inner + inner.T))
    damping_scale = max(float(np.max(np.abs(damping))) if damping.size else 0.0, float(damping_scale))
    free = rigid @ w[:, np.abs(nu) <= _ZERO * max(damping_scale, 1e-300)] if damping_scale > 0.0 else rigid
    flexible = modes.flexible
    pseudo = flexible @ np.diag(1.0 / modes.flexible_values) @ flexible.T if modes.scale > 0.0 else np.zeros((size, size))
    columns = [np.concatenate([rigid, np.zeros_like(rigid)])]
    if free.shape[1]:
        columns.append(np.concatenate([-pseudo @ damping @ free, free]))
    return np.hstack(columns)


def decompose(
    matrix: NDArray[np.float64], harmonic: NDArray[np.complex128], constant: NDArray[np.float64], omega: float,
    null_basis: NDArray[np.float64] | None = None,
) -> Flow:  # fmt: skip
    """The flow of ``y' = A y + Re(b e^{jwt}) + b0`` split into exponentials and a polynomial (module docstring).

    Parameters
    ----------
    matrix : ndarray, shape (n, n)
        A [s-1]: nonzero eigenvalues distinct or at least non-defective, Re <= 0; Jordan blocks at 0 of size <= 2.
    harmonic : ndarray of complex, shape (n,)
        b [state units s-1].
    constant : ndarray, shape (n,)
        b0 [state units s-1].
    omega : float
        w [rad s-1], > 0.
    null_basis : ndarray, shape (n, z), optional
        A basis of the generalized null space of A (:func:`mechanical_null_basis`); computed from singular values if
        omitted.

    Raises
    ------
    ValueError
        A Jordan block at zero longer than 2, a defective nonzero eigenvalue, or w so near an undamped (or nearly
        undamped) natural frequency that the harmonic response is ill-conditioned
        (:func:`~vibroimpact.model.structure.resonance_refusal`) while the harmonic load is nonzero.
    """
    a = np.asarray(matrix, dtype=float)
    n = a.shape[0]
    if n == 0:
        empty = np.zeros(0)
        return Flow(empty.astype(complex), np.zeros((0, 0), complex), np.zeros((0, 0), complex), empty.astype(complex), empty, np.zeros((0, 0)), np.zeros((0, 0)), empty, float(omega))
    return with_harmonic(_remembered_unforced_flow(a, np.asarray(constant, dtype=float), null_basis), a, harmonic, omega)


#: Most unforced flows :func:`decompose` remembers (per process): a continuation in frequency rebuilds the same
#: structure's model at every step, and its eigen-decomposition is most of that cost.
REMEMBERED_FLOWS = 64
_FLOWS: dict[bytes, Flow] = {}


def _remembered_unforced_flow(a: NDArray[np.float64], constant: NDArray[np.float64], null_basis: NDArray[np.float64] | None) -> Flow:
    """:func:`unforced_flow`, remembered by the bytes of its inputs (the same bits in, the same flow out); the oldest
    of :data:`REMEMBERED_FLOWS` forgotten first. Nothing reads a flow's arrays but to compute new ones."""
    basis = None if null_basis is None else np.asarray(null_basis, dtype=float)
    key = b"|".join((repr((a.shape, constant.shape, None if basis is None else basis.shape)).encode(), a.tobytes(), constant.tobytes(), b"-" if basis is None else basis.tobytes()))
    flow = _FLOWS.get(key)
    if flow is None:
        flow = unforced_flow(a, constant, basis)
        if len(_FLOWS) >= REMEMBERED_FLOWS:
            del _FLOWS[next(iter(_FLOWS))]
        _FLOWS[key] = flow
    return flow


def unforced_flow(matrix: NDArray[np.float64], constant: NDArray[np.float64], null_basis: NDArray[np.float64] | None = None) -> Flow:
    """:func:`decompose` without the harmonic load: every part of the flow but ``harmonic`` (zero) and ``omega`` (NaN),
    which :func:`with_harmonic` adds. What does not depend on the forcing frequency, for a caller that keeps it while
    the frequency changes (a continuation in frequency); raises as :func:`decompose` does, but for the frequency."""
    a = np.asarray(matrix, dtype=float)
    n = a.shape[0]
    b0 = np.asarray(constant, dtype=float)
    zeros = numeric_null_basis(a) if null_basis is None else np.asarray(null_basis, dtype=float).reshape(n, -1)
    z = zeros.shape[1]
    if z:
        # the chain closes: A Z lies in Z and (A Z)^2 = 0 (no Jordan block of size 3 or more)
        scale = float(np.linalg.norm(a, 2)) or 1.0
        image = a @ zeros
        if np.linalg.norm(a @ image) > 1e-8 * scale * scale * max(1.0, float(np.linalg.norm(zeros))):
            raise ValueError("system: the state matrix has a Jordan block at zero longer than 2 (a rigid-body chain); the exact engine handles blocks of size <= 2 only")
    lam_all, vec_all = np.linalg.eig(a)
    order = np.argsort(np.abs(lam_all), kind="stable")
    keep = np.sort(order[z:])
    lam, vec = lam_all[keep], vec_all[:, keep]
    if lam.size and np.min(np.abs(lam)) <= 1e-9 * max(float(np.max(np.abs(lam))), 1.0):
        raise ValueError("system: a zero eigenvalue of the state matrix is not a rigid-body mode of the structure; cannot split its flow")
    basis = np.hstack([vec, zeros.astype(complex)])
    if np.linalg.cond(basis) > _CONDITION:
        raise ValueError("system: the state matrix is defective (repeated eigenvalues without independent eigenvectors); the exact engine needs a modal basis")
    full_inverse = np.linalg.inv(basis)
    m = lam.size
    inverse, zrows = full_inverse[:m], full_inverse[m:]
    projector = np.real(zeros @ zrows) if z else np.zeros((n, n))
    nilpotent = a @ projector
    return Flow(
        eigenvalues=np.ascontiguousarray(lam),
        vectors=np.ascontiguousarray(vec),
        inverse=np.ascontiguousarray(inverse),
        harmonic=np.zeros(n, dtype=complex),
        constant=-np.real(vec @ ((inverse @ b0) / lam)) if np.any(b0) and m else np.zeros(n),
        projector=projector,
        nilpotent=nilpotent,
        drift=projector @ b0,
        omega=math.nan,
    )


def with_harmonic(flow: Flow, matrix: NDArray[np.float64], harmonic: NDArray[np.complex128], omega: float) -> Flow:
    """An :func:`unforced_flow` of ``matrix`` (A [s-1]) with the harmonic load b (``harmonic``) at w = ``omega``
    [rad s-1]: :func:`decompose`'s flow, bit for bit."""
    return dataclasses.replace(flow, harmonic=harmonic_response(flow, matrix, harmonic, omega), omega=float(omega))


def harmonic_response(flow: Flow, matrix: NDArray[np.float64], harmonic: NDArray[np.complex128], omega: float) -> NDArray[np.complex128]:
    """The harmonic particular solution of :func:`with_harmonic`'s flow, alone (a scan in frequency needs no other
    part of the flow anew)."""
    return _harmonic_response(np.asarray(matrix, dtype=float), np.asarray(harmonic, dtype=complex), flow.eigenvalues, omega)


def _harmonic_response(a: NDArray[np.float64], b: NDArray[np.complex128], lam: NDArray[np.complex128], omega: float) -> NDArray[np.complex128]:
    """Y = (jw I - A)^-1 b: a linear solve (through the eigenvectors it is ~10x less accurate at an anti-resonance)."""
    n = a.shape[0]
    if not np.any(b):
        return np.zeros(n, dtype=complex)
    if omega <= 0.0:
        raise ValueError(f"excitation.frequency: w = {omega!r} rad/s: a harmonic load needs w > 0")
    refusal = resonance_refusal(lam, omega)  # the closed forms and the steady states refuse the same band
    if refusal is not None:
        raise ValueError(refusal)
    return np.linalg.solve(1j * omega * np.eye(n) - a, b)


# --------------------------------------------------------------------------------------------------------------------
# What the exact engines need of one problem: its flows (:mod:`~vibroimpact.engines.exact_flows`) and, per stop, its geometry, impact
# maps and holding force.
# --------------------------------------------------------------------------------------------------------------------

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
    round-off of the holding forces (see :class:`~vibroimpact.engines.rigid_kernels.RigidContact`)."""
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
