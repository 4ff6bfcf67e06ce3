"""Modal decomposition of a receptance: exact poles and residues, and the paper's curve fit (eq. 10).

Two representations of the same kind of object:

* :class:`PoleResidueModel`: ``H(s) = sum_k r_k / (s - p_k)`` over all (complex-conjugate) poles. Exact for the
  rational receptances of eq. 4; it is what the periodic Green functions are built from.
* :class:`ModalParameters`: the paper's eigenform decomposition ``H(j w) = sum_i A_i / (Omega_i^2 - w^2 +
  2 j xi_i Omega_i w)`` with real form factors ``A_i``. It is a pole-residue model whose residues are
  ``A_i / (2 j Theta_i)``; it is exact only when the numerator of each modal term is constant, which for a damped
  system is true only approximately (the exact ``A_i`` have small imaginary parts).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray

from vibroimpact.model.structure import LinearStructure
from vibroimpact.model.system import TwoDofSystem

__all__ = [
    "ModalParameters",
    "ModalResponse",
    "PoleResidueModel",
    "exact_modal_parameters",
    "exact_pole_residue",
    "fit_modal_parameters",
    "impulse_modes",
    "underdamped_mode_count",
]


@dataclass(frozen=True, eq=False)
class PoleResidueModel:
    """Rational function ``H(s) = sum_k residues[k] / (s - poles[k])``.

    Attributes
    ----------
    poles : ndarray of complex, shape (n,)
        Poles p_k [rad s-1]; complex-conjugate pairs for a real system.
    residues : ndarray of complex, shape (n,)
        Residues r_k [m N-1 s-1].
    """

    poles: NDArray[np.complex128]
    residues: NDArray[np.complex128]

    def __call__(self, s: ArrayLike) -> NDArray[np.complex128]:
        """Evaluate H(s) at Laplace variables ``s`` [rad s-1] (use ``1j * omega`` for a receptance)."""
        s_arr = np.asarray(s, dtype=complex)[..., None]
        return np.sum(self.residues / (s_arr - self.poles), axis=-1)

    def impulse_response(self, t: ArrayLike, derivative: int = 0) -> NDArray[np.float64]:
        """Impulse response h(t) for t >= 0 (or its ``derivative``-th time derivative) [m N-1 s-1-derivative]."""
        t_arr = np.asarray(t, dtype=float)[..., None]
        terms = self.residues * self.poles**derivative * np.exp(self.poles * t_arr)
        return np.sum(terms, axis=-1).real


@dataclass(frozen=True, eq=False)
class ModalParameters:
    """Modal parameters of eq. 10 for ``N`` modes.

    Attributes
    ----------
    omega : ndarray, shape (N,)
        Natural angular frequencies Omega_i [rad s-1].
    loss_factor : ndarray, shape (N,)
        Modal loss factors (damping ratios) xi_i [-], 0 <= xi_i < 1.
    form_factor : ndarray, shape (N,)
        Form factors A_i [kg-1]. Real in the paper's fit; complex in the exact decomposition.
    """

    omega: NDArray[np.float64]
    loss_factor: NDArray[np.float64]
    form_factor: NDArray[np.complexfloating] | NDArray[np.float64]

    @property
    def damped_omega(self) -> NDArray[np.float64]:
        """Damped natural angular frequencies Theta_i = Omega_i sqrt(1 - xi_i^2) [rad s-1]."""
        return self.omega * np.sqrt(1.0 - self.loss_factor**2)

    def receptance(self, omega: ArrayLike) -> NDArray[np.complex128]:
        """Eq. 10 evaluated at angular frequencies ``omega`` [rad s-1] -> [m N-1]."""
        w = np.asarray(omega, dtype=float)[..., None]
        terms = self.form_factor / (self.omega**2 - w**2 + 2j * self.loss_factor * self.omega * w)
        return np.sum(terms, axis=-1)

    def to_pole_residue(self) -> PoleResidueModel:
        """The same function as a :class:`PoleResidueModel` (poles -xi Omega +- j Theta, residues A/(+-2 j Theta))."""
        form = np.asarray(self.form_factor)
        if np.iscomplexobj(form) and np.any(form.imag != 0.0):
            # A complex form factor is not a real-valued modal term of eq. 10: use exact_pole_residue instead.
            raise ValueError("form_factor must be real to convert eq. 10 to a pole-residue model")
        form = form.real.astype(float)
        theta = self.damped_omega
        upper = -self.loss_factor * self.omega + 1j * theta
        residue_upper = form / (2j * theta)
        return PoleResidueModel(
            poles=np.concatenate([upper, np.conj(upper)]),
            residues=np.concatenate([residue_upper, np.conj(residue_upper)]),
        )


def _polish_roots(coefficients: NDArray[np.float64], roots: NDArray[np.complex128]) -> NDArray[np.complex128]:
    """Newton steps on the polynomial to bring eigenvalue-based roots to machine precision."""
    derivative = np.polyder(coefficients)
    for _ in range(3):
        roots = roots - np.polyval(coefficients, roots) / np.polyval(derivative, roots)
    return roots


def exact_pole_residue(system: TwoDofSystem, output: int = 2, load: int = 2) -> PoleResidueModel:
    """Exact poles and residues of the receptance H_{output,load}(s) of ``system``.

    Poles are the eigenvalues of the state matrix, polished by Newton steps on D(s); residues are
    ``N(p) / D'(p)``. Requires simple poles (any damped two-degree-of-freedom system with distinct modes).

    Parameters
    ----------
    system : TwoDofSystem
        The linear system.
    output, load : {1, 2}
        Displacement index and loaded mass index.
    """
    denominator = system.characteristic_polynomial()
    numerator = system.numerator_polynomial(output, load)
    poles = _polish_roots(denominator, np.linalg.eigvals(system.state_matrix).astype(complex))
    poles = poles[np.lexsort((poles.imag, np.abs(poles)))]
    residues = np.polyval(numerator, poles) / np.polyval(np.polyder(denominator), poles)
    return PoleResidueModel(poles=poles, residues=residues)


def exact_modal_parameters(system: TwoDofSystem, output: int = 2, load: int = 2) -> ModalParameters:
    """Modal parameters of eq. 10 that follow exactly from the poles and residues.

    ``Omega_i = |p_i|``, ``xi_i = -Re(p_i) / |p_i|``, ``A_i = 2 j Theta_i r_i`` (complex: its small imaginary part
    is what a real-valued eq. 10 cannot represent).
    """
    model = exact_pole_residue(system, output, load)
    upper = model.poles.imag > 0
    poles, residues = model.poles[upper], model.residues[upper]
    order = np.argsort(poles.imag)
    poles, residues = poles[order], residues[order]
    omega = np.abs(poles)
    return ModalParameters(omega=omega, loss_factor=-poles.real / omega, form_factor=2j * poles.imag * residues)


def underdamped_mode_count(system: TwoDofSystem) -> int:
    """Number of oscillatory (complex-pole) modes of the system: 2 for a lightly damped absorber."""
    return int(np.sum(exact_pole_residue(system).poles.imag > 0))


@lru_cache(maxsize=32)
def fit_modal_parameters(system: TwoDofSystem, omega_grid: tuple[float, ...] | None = None) -> ModalParameters:
    """The paper's curve fit of |H22| by eq. 10 with Omega_i fixed at the undamped values of eq. 11.

    Fits the real form factors A_i and loss factors xi_i by least squares on ``log |H22|`` (relative error, so the
    sharp peaks and the anti-resonance both count), starting from the real parts of the exact modal values.
    Cached per system (the fit is deterministic).

    Parameters
    ----------
    system : TwoDofSystem
        The linear system.
    omega_grid : tuple of float, optional
        Angular frequencies [rad s-1] to fit on. Default: 0.5 Omega_1 ... 1.5 Omega_2, densified around each peak.

    Returns
    -------
    ModalParameters
        Real form factors [kg-1] and loss factors [-]; ``omega`` are the undamped natural frequencies.

    Raises
    ------
    ValueError
        If the system does not have two underdamped modes (eq. 10 then does not describe it).
    RuntimeError
        If the least-squares fit does not converge.
    """
    modes = underdamped_mode_count(system)
    if modes != 2:
        raise ValueError(f"the paper's modal fit (eq. 10) needs two underdamped modes; this system has {modes}")
    omega_n = np.array(system.natural_angular_frequencies())
    if omega_grid is None:
        wide = np.linspace(0.5 * omega_n[0], 1.5 * omega_n[1], 2001)
        peaks = [wn * (1.0 + np.linspace(-0.02, 0.02, 401)) for wn in omega_n]
        w = np.unique(np.concatenate([wide, *peaks]))
    else:
        w = np.asarray(omega_grid, dtype=float)
    target = np.log(np.abs(system.receptances(w).h22))

    def residual(x: NDArray[np.float64]) -> NDArray[np.float64]:
        model = ModalParameters(omega=omega_n, loss_factor=x[2:], form_factor=x[:2])
        return np.log(np.abs(model.receptance(w))) - target

    exact = exact_modal_parameters(system)
    start = np.concatenate([np.abs(np.real(exact.form_factor)), np.clip(exact.loss_factor, 1e-9, 0.98)])
    lower = np.array([0.0, 0.0, 1e-12, 1e-12])
    upper = np.array([np.inf, np.inf, 0.99, 0.99])
    from scipy.optimize import least_squares  # here, not at import: reading a scene must not load scipy's solvers

    fit = least_squares(residual, start, bounds=(lower, upper), x_scale=np.abs(start) + 1e-300, xtol=1e-14, ftol=1e-14, gtol=1e-14)
    if not fit.success:
        raise RuntimeError(f"the modal curve fit did not converge: {fit.message}")
    return ModalParameters(omega=omega_n, loss_factor=fit.x[2:], form_factor=fit.x[:2])


@dataclass(frozen=True, eq=False)
class ModalResponse:
    """Displacements of every coordinate after a unit impulse: ``x(t) = Re sum_k residues[:, k] exp(poles[k] t)``.

    The Laplace transform of the columns is ``H(s) d`` for the impulse direction ``d`` (``H(s) = (M s^2 + C s + K)^-1``),
    so each row is a :class:`PoleResidueModel` of one coordinate and ``weights @ residues`` that of a combination
    (e.g. a stop's coordinate n . x).

    Attributes
    ----------
    poles : ndarray of complex, shape (2N,)
        Eigenvalues of the state matrix [rad s-1].
    residues : ndarray of complex, shape (N, 2N)
        Residue of each coordinate at each pole [m N-1 s-1].
    """

    poles: NDArray[np.complex128]
    residues: NDArray[np.complex128]

    def output(self, weights: ArrayLike) -> PoleResidueModel:
        """The model of the combination ``weights . x`` (e.g. a stop's normal)."""
        return PoleResidueModel(poles=self.poles, residues=np.asarray(weights, dtype=float) @ self.residues)

    def coordinate(self, index: int) -> PoleResidueModel:
        """The model of coordinate ``index``."""
        return PoleResidueModel(poles=self.poles, residues=self.residues[index].copy())


@lru_cache(maxsize=64)
def _impulse_modes(structure: LinearStructure, direction: tuple[float, ...]) -> ModalResponse:
    a = structure.state_matrix
    poles, vectors = np.linalg.eig(a)
    condition = float(np.linalg.cond(vectors))
    if not np.isfinite(condition) or condition > 1e10:
        raise ValueError(
            f"the structure's state matrix is (nearly) defective (eigenvector condition {condition:.3g}): a repeated pole, "
            "e.g. a critically damped mode or a rigid-body mode, has no pole-residue form"
        )
    size = structure.size
    kick = np.concatenate([np.zeros(size), np.linalg.solve(structure.mass_matrix, np.asarray(direction, dtype=float))])
    weights = np.linalg.solve(vectors, kick.astype(complex))
    order = np.lexsort((poles.imag, np.abs(poles)))
    return ModalResponse(poles=poles[order], residues=(vectors[:size, :] * weights[None, :])[:, order])


def impulse_modes(structure: LinearStructure, direction: ArrayLike) -> ModalResponse:
    """Poles and residues of every coordinate's response to a unit impulse along ``direction`` (cached per structure).

    The impulse gives the velocity jump M^-1 d; the free motion from (0, M^-1 d) is expanded on the eigenvectors of
    the state matrix A = [[0, I], [-M^-1 K, -M^-1 C]]: residues = V[:N] diag(V^-1 (0, M^-1 d)).

    Parameters
    ----------
    structure : LinearStructure
        The structure (any N).
    direction : array_like, shape (N,)
        Distribution of the unit impulse over the coordinates [-] (a stop's normal n for the impulse n; the contact
        impulse of a stop is -J n).

    Raises
    ------
    ValueError
        If the state matrix has no eigenvector basis (repeated poles).
    """
    return _impulse_modes(structure, tuple(float(x) for x in np.asarray(direction, dtype=float)))
