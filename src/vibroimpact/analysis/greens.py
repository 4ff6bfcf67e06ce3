"""Periodic Green functions (PGF, eq. 7) in closed form on the interval of periodicity.

For a causal impulse response ``h(t) = sum_k r_k exp(p_k t)`` the T-periodic Green function of eq. 7,
``chi(t) = (1/T) sum_m H(j m w) exp(j m w t)``, is the periodic sum ``sum_{n >= 0} h(t + n T)``, which for
``0 <= t <= T`` sums to::

    chi(t) = sum_k r_k exp(p_k t) / (1 - exp(p_k T))

This is the paper's eq. 12 for any set of poles; eq. 12 itself is kept as :func:`paper_periodic_green` for the
``pgf_paper`` variant and as an independent check.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from vibroimpact.model.modal import ModalParameters, PoleResidueModel

__all__ = ["periodic_green", "paper_periodic_green"]


def periodic_green(model: PoleResidueModel, omega: ArrayLike, t: ArrayLike, derivative: int = 0) -> NDArray[np.float64]:
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

    Returns
    -------
    ndarray
        chi^(derivative)(t) [m N-1 s-1-derivative], broadcast shape of ``omega`` and ``t``.
    """
    w = np.asarray(omega, dtype=float)[..., None]
    tt = np.asarray(t, dtype=float)[..., None]
    period = 2.0 * np.pi / w
    p = model.poles
    terms = model.residues * p**derivative * np.exp(p * tt) / (1.0 - np.exp(p * period))
    return np.sum(terms, axis=-1).real


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
