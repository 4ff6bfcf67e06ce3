"""Periodic Green functions (PGF, eq. 7) in closed form on the interval of periodicity.

For a causal impulse response ``h(t) = sum_k r_k exp(p_k t)`` the T-periodic Green function of eq. 7,
``chi(t) = (1/T) sum_m H(j m w) exp(j m w t)``, is the periodic sum ``sum_{n >= 0} h(t + n T)``, which for
``0 <= t <= T`` sums to::

    chi(t) = sum_k r_k exp(p_k t) / (1 - exp(p_k T))

This is the paper's eq. 12 for any set of poles; eq. 12 itself is kept as :func:`paper_periodic_green` for the
``pgf_paper`` variant and as an independent check.

The *antiperiodic* Green function is the response to impulses of alternating sign every half period,
``psi(t) = sum_{n >= 0} (-1)^n h(t + n T / 2)``, so that psi(t + T/2) = -psi(t); for ``0 <= t <= T/2``::

    psi(t) = sum_k r_k exp(p_k t) / (1 + exp(p_k T / 2))

(the two-sided symmetric stop, :mod:`~vibroimpact.analysis.impact_orbit`). Its only harmonics are the odd ones, and unlike chi it stays
finite for a pole at 0 (a rigid-body mode) since 1 + exp(0) = 2. :func:`green_vector` gives either function for
every coordinate at once from a :class:`~vibroimpact.model.modal.ModalResponse`.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from vibroimpact.model.modal import ModalParameters, ModalResponse, PoleResidueModel
from vibroimpact.model.structure import CONDITION_LIMIT

__all__ = ["periodic_green", "paper_periodic_green", "green_vector", "green_condition", "GREEN_CONDITION_LIMIT"]

#: Largest condition number of the periodic sums (:func:`green_condition`) at which a closed form is evaluated [-]:
#: the model's :data:`~vibroimpact.model.structure.CONDITION_LIMIT`, which the steady states and the exact engines
#: apply to the harmonic response. The harmonics lose ~eps kappa^2 (relative): <= ~5e-8 below it. The shipped
#: (damped) scenes stay below 146 (73 for one stop): a margin of 68 in kappa, 4700 in the error.
GREEN_CONDITION_LIMIT = CONDITION_LIMIT


def green_condition(poles: ArrayLike, omega: ArrayLike, antiperiodic: bool = False) -> NDArray[np.float64]:
    """Condition number kappa = max_k 1 / |1 - exp(p_k T)| of the periodic sums (antiperiodic: 1 / |1 + exp(p_k T/2)|).

    Each term of chi is kappa_k times the impulse response's; near an undamped or nearly undamped natural frequency,
    |1 - exp(j Omega T)| = 2 |sin(pi Omega / w)| ~ 2 pi |w - Omega| / w, so kappa ~ 1 / (2 pi relative detuning)
    (or, damped, at most ~1 / (2 pi zeta), zeta the mode's damping ratio). There the linear part q H F and the
    impacts' part J chi of a closed-form orbit are each ~kappa times the motion and cancel, and round-off in
    exp(p T) (absolute ~eps, relative ~eps kappa) leaves the motion's harmonics with a relative error ~eps kappa^2:
    measured on the paper's system with b1 = b2 = 0 against the same closed form extrapolated from 1e-3 detuning,
    |X2| is off by 1.4e-7 at kappa = 1.6e4, 7e-7 at 5.3e4, 7e-2 at 1.6e7 (1e-8 detuning) and 14 x at 1.6e8; the
    impulse J and the RMS stay within 1e-7. Closed forms flag points beyond :data:`GREEN_CONDITION_LIMIT`.

    Parameters
    ----------
    poles : array_like of complex, shape (n,)
        Poles p_k of the structure [rad s-1] (a pole at 0 has no periodic sum: kappa = inf).
    omega : array_like
        Excitation angular frequency w [rad s-1].
    antiperiodic : bool
        The antiperiodic sums psi (the two-sided stop).

    Returns
    -------
    ndarray
        kappa [-], shape of ``omega``; inf exactly at a singular sum.
    """
    p = np.asarray(poles, dtype=complex)
    w = np.asarray(omega, dtype=float)
    if p.size == 0:
        return np.ones(w.shape)
    period = 2.0 * np.pi / w[..., None]
    with np.errstate(divide="ignore", over="ignore"):
        return np.max(1.0 / np.abs(_denominator(p, period, antiperiodic)), axis=-1)


def _denominator(poles: NDArray[np.complex128], period: NDArray[np.float64], antiperiodic: bool) -> NDArray[np.complex128]:
    """The periodic sum's 1 - exp(p T) (antiperiodic: 1 + exp(p T / 2)) [-], ``period`` T [s]."""
    return 1.0 + np.exp(poles * 0.5 * period) if antiperiodic else 1.0 - np.exp(poles * period)


def _weights(poles: NDArray[np.complex128], t: NDArray[np.float64], period: NDArray[np.float64], derivative: int, antiperiodic: bool) -> NDArray[np.complex128]:
    """p^d exp(p t) / (1 -+ exp(p T')) with T' = T (periodic) or T/2 (antiperiodic)."""
    return poles**derivative * np.exp(poles * t) / _denominator(poles, period, antiperiodic)


def periodic_green(model: PoleResidueModel, omega: ArrayLike, t: ArrayLike, derivative: int = 0, antiperiodic: bool = False, paired: bool = False) -> NDArray[np.float64]:
    """Periodic Green function chi(t) (or its time derivative) for excitation angular frequency ``omega``.

    Parameters
    ----------
    model : PoleResidueModel
        Poles and residues of the receptance.
    omega : array_like
        Angular frequency of the periodic impulse train [rad s-1]; the period is T = 2 pi / omega.
    t : array_like
        Time within the period, 0 <= t <= T [s]; broadcast against ``omega``. For ``derivative >= 1`` the value
        at t = 0 is the right limit chi^(d)(0+) and at t = T the left limit chi^(d)(T-) = chi^(d)(0-).
    derivative : int
        Order of the time derivative, >= 0.
    antiperiodic : bool
        The antiperiodic function psi (impulses of alternating sign every T/2), for 0 <= t <= T/2.
    paired : bool
        Sum each pair of complex-conjugate terms once (its real part doubled), with the coefficients computed once per
        frequency: ~1.7x faster on a long time axis, equal to ~1e-16 relative but not bit for bit (the admissibility
        search, whose samples only locate a maximum, uses it; every value a study reports takes the default).

    Returns
    -------
    ndarray
        chi^(derivative)(t) [m N-1 s-1-derivative], broadcast shape of ``omega`` and ``t``.
    """
    w = np.asarray(omega, dtype=float)[..., None]
    tt = np.asarray(t, dtype=float)[..., None]
    period = 2.0 * np.pi / w
    if paired:
        p, residues, weight = _real_sum_terms(model)
        # the coefficients once per frequency, then one exponential per time and pole (the time axis is the long one)
        coefficient = residues * p**derivative / _denominator(p, period, antiperiodic)
        return np.sum(weight * (coefficient * np.exp(p * tt)).real, axis=-1)
    p = model.poles
    if not antiperiodic:  # the paper's path, unchanged
        terms = model.residues * p**derivative * np.exp(p * tt) / _denominator(p, period, False)
        return np.sum(terms, axis=-1).real
    return np.sum(model.residues * _weights(p, tt, period, derivative, True), axis=-1).real


def _real_sum_terms(model: PoleResidueModel) -> tuple[NDArray[np.complex128], NDArray[np.complex128], NDArray[np.float64]]:
    """Poles, residues and weights whose weighted real parts sum to the model's real sums: a pair of complex-conjugate
    poles (and residues) once, its real part doubled, a real pole once; every term once (weight 1) if the poles do not
    pair. The periodic sums of a real structure then cost half the exponentials."""
    p, r = model.poles, model.residues
    upper, real = p.imag > 0.0, p.imag == 0.0  # exact: a real pole is one whose imaginary part is zero
    lower = np.flatnonzero(p.imag < 0.0)
    if lower.size != np.count_nonzero(upper):
        return p, r, np.ones(p.shape)
    partner = [lower[np.argmin(np.abs(p[lower] - np.conj(pole)))] for pole in p[upper]]
    scale = np.max(np.abs(p)) if p.size else 1.0
    if len(set(partner)) != len(partner) or np.any(np.abs(p[partner] - np.conj(p[upper])) > 1e-14 * scale) or np.any(np.abs(r[partner] - np.conj(r[upper])) > 1e-14 * np.max(np.abs(r))):
        return p, r, np.ones(p.shape)
    keep = upper | real
    return p[keep], r[keep], np.where(real[keep], 1.0, 2.0)


def green_vector(modes: ModalResponse, omega: ArrayLike, t: ArrayLike, derivative: int = 0, antiperiodic: bool = False) -> NDArray[np.float64]:
    """The periodic (or antiperiodic) Green function of every coordinate, shape broadcast(omega, t) + (N,).

    Parameters
    ----------
    modes : ModalResponse
        Poles and residues of the coordinates' response to a unit impulse along some direction.
    omega : array_like
        Excitation angular frequency [rad s-1].
    t : array_like
        Time within the period (0 <= t <= T; antiperiodic: 0 <= t <= T/2) [s], broadcast against ``omega``; the ends
        are one-sided limits as in :func:`periodic_green`.
    derivative : int
        Order of the time derivative, >= 0.
    antiperiodic : bool
        psi instead of chi (module docstring).

    Returns
    -------
    ndarray
        [m N-1 s-1-derivative], last axis the coordinates.
    """
    w = np.asarray(omega, dtype=float)[..., None]
    tt = np.asarray(t, dtype=float)[..., None]
    weights = _weights(modes.poles, tt, 2.0 * np.pi / w, derivative, antiperiodic)
    return np.einsum("...k,ik->...i", weights, modes.residues).real


def paper_periodic_green(modes: ModalParameters, omega: ArrayLike, t: ArrayLike) -> NDArray[np.float64]:
    """Eq. 12 as printed (with ``A`` read as ``A_i``): chi(t) from real modal parameters, 0 <= t <= T.

    Parameters
    ----------
    modes : ModalParameters
        Omega_i [rad s-1], xi_i [-], real A_i [kg-1].
    omega : array_like
        Excitation angular frequency [rad s-1].
    t : array_like
        Time within the period [s], broadcast against ``omega``.

    Returns
    -------
    ndarray
        chi(t) [m N-1 s-1].
    """
    w = np.asarray(omega, dtype=float)[..., None]
    tt = np.asarray(t, dtype=float)[..., None]
    period = 2.0 * np.pi / w
    sigma = modes.loss_factor * modes.omega
    theta = modes.damped_omega
    decay = np.exp(-sigma * period)
    numerator = np.real(modes.form_factor) * np.exp(-sigma * tt) * (np.sin(theta * tt) + decay * np.sin(theta * (period - tt)))
    denominator = theta * (1.0 + decay**2 - 2.0 * decay * np.cos(theta * period))
    return np.sum(numerator / denominator, axis=-1)
