"""One collision on the Kelvin-Voigt bumper of the seed paper's section 5 (eq. 25): its restitution, the loss factor
that gives a restitution, its duration and its peak acceleration. The law itself is
:class:`~vibroimpact.model.contact.KelvinVoigtBumper`; :mod:`~vibroimpact.model.contact` re-exports these names.

A bumper of apparent natural frequency Omega_b and loss factor xi_b acts on the absorber with
K = M2 Omega_b^2, B = 2 M2 xi_b Omega_b, only while X2 >= Delta and the force K (X2 - Delta) + B X2' is positive.

One collision (the absorber alone, entering at speed v0; the absorber spring is negligible over the short contact):
``x'' + 2 xi Omega x' + Omega^2 x = 0`` from x = 0, x' = v0, until the force, which equals -M2 x'', falls to zero.
With the roots r1,2 of s^2 + 2 xi Omega s + Omega^2:

* release at the first t > 0 with x''(t) = 0; underdamped (beta = arccos xi, w_d = Omega sqrt(1 - xi^2)):
  t_r = 2 beta / w_d, and the exit speed is v0 exp(-xi Omega t_r), so

      R(xi) = exp(-2 xi arccos(xi) / sqrt(1 - xi^2))      (= exp(-xi (pi - 2 arcsin xi) / sqrt(1 - xi^2)))

  R(1) = exp(-2), and overdamped (s = sqrt(xi^2 - 1)) Omega t_r = 2 atanh(s / xi) / s with again R = exp(-xi Omega
  t_r), so R falls like 1 / (4 xi^2) for a very damped bumper. The printed eq. 26 is wrong (README errata).
* the largest contact acceleration, as a multiple of Omega v0 (the peak-acceleration factor Gamma): the force starts
  at 2 xi Omega v0 (the dashpot) and, for xi < 1/2 only, has an interior maximum at t_p = (3 beta - pi) / w_d
  (x''' = 0 before release). The paper's gamma(xi) of section 6.3 is the reciprocal of a factor of this kind.
"""

from __future__ import annotations

import cmath
import math

from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.model.structure import require_in_range, require_non_negative

__all__ = [
    "MAX_LOSS_FACTOR",
    "MIN_BUMPER_RESTITUTION",
    "loss_factor_from_restitution",
    "paper_restitution",
    "peak_acceleration_factor",
    "release_time",
    "restitution_from_loss_factor",
]

#: The most damped bumper accepted, as xi_b [-] (its restitution 2.5e-7): the scenes' limit too.
MAX_LOSS_FACTOR = 1e3


def _roots(xi: float) -> tuple[complex, complex]:
    """Roots of s^2 + 2 xi s + 1 (Omega = 1): r1 (slower decay) and r2."""
    root = cmath.sqrt(xi * xi - 1.0)
    return -xi + root, -xi - root


def release_time(xi: float) -> float:
    """Omega_b times the duration of one collision: the first t > 0 where the force (-M2 x'') vanishes [-].

    2 arccos(xi) / sqrt(1 - xi^2) (underdamped), 2 (critical), 2 atanh(s / xi) / s with s = sqrt(xi^2 - 1)
    (overdamped): one function, continuous through xi = 1 and free of cancellation on both sides.
    """
    xi = require_non_negative("loss_factor", xi)
    if xi < 1.0:
        return 2.0 * math.acos(xi) / math.sqrt(1.0 - xi * xi)
    if xi == 1.0:
        return 2.0
    s = math.sqrt(xi * xi - 1.0)
    if xi > 1e4:  # s / xi rounds to 1 (atanh: a domain error from 7e7 on); atanh(s / xi) = log(xi + s) since xi^2 - s^2 = 1
        return 2.0 * math.log(xi + s) / s
    return 2.0 * math.atanh(s / xi) / s


@suggest_keywords
def restitution_from_loss_factor(xi: float) -> float:
    """R(xi_b) of one Kelvin-Voigt collision that releases when the force would turn negative [-].

    At release the exit speed is exactly v0 exp(-xi Omega t_r) for every xi (the oscillating factor equals one
    there), so R = exp(-xi * release_time(xi)).

    Parameters
    ----------
    xi : float
        Bumper loss factor xi_b [-], >= 0.
    """
    return math.exp(-xi * release_time(xi))


#: The least restitution a bumper gives, R(:data:`MAX_LOSS_FACTOR`) = 2.5e-7 [-]: a rigid stop's R below it has no
#: bumper to stand for it.
MIN_BUMPER_RESTITUTION = restitution_from_loss_factor(MAX_LOSS_FACTOR)


@suggest_keywords
def loss_factor_from_restitution(restitution: float) -> float:
    """The loss factor xi_b [-] of the Kelvin-Voigt bumper whose one collision restitutes R (the inverse of
    :func:`restitution_from_loss_factor`, to 1e-15): the bumper that stands for a rigid stop of restitution R.

    R(xi) decreases from 1 (xi = 0) through exp(-2) (xi = 1) towards 0 for an ever more damped bumper.

    Parameters
    ----------
    restitution : float
        R [-], 0 < R <= 1 (R = 0 needs an infinitely damped bumper: ``ValueError``).

    Returns
    -------
    float
        xi_b [-], >= 0 (0 for R = 1).
    """
    r = require_in_range("restitution", restitution, 0.0, 1.0)
    if r == 1.0:
        return 0.0
    if r <= 0.0:
        raise ValueError("restitution = 0 needs an infinitely damped bumper: allowed (0, 1]")
    high = 1.0
    while restitution_from_loss_factor(high) > r:
        high *= 2.0
        if high > MAX_LOSS_FACTOR:
            if MIN_BUMPER_RESTITUTION > r:
                raise ValueError(f"restitution = {r!r} is below what a bumper of loss factor up to {MAX_LOSS_FACTOR:g} reaches: allowed [{MIN_BUMPER_RESTITUTION:.3g}, 1]")
            high = MAX_LOSS_FACTOR
    from scipy.optimize import brentq  # here, not at import: reading a scene must not load scipy's solvers

    return float(brentq(lambda xi: restitution_from_loss_factor(xi) - r, 0.0, high, xtol=1e-15, rtol=1e-15))


def peak_acceleration_factor(xi: float) -> float:
    """Gamma(xi_b): the largest contact acceleration of one collision divided by Omega_b v0 [-]."""
    xi = require_non_negative("loss_factor", xi)
    initial = 2.0 * xi  # the dashpot force at first touch
    if xi >= 0.5:
        return initial  # no interior maximum before release
    beta = math.acos(xi)
    damped = math.sqrt(1.0 - xi * xi)
    t = (3.0 * beta - math.pi) / damped  # x''' = 0 (Omega = 1)
    r1, r2 = _roots(xi)
    acceleration = ((r1 * r1 * cmath.exp(r1 * t) - r2 * r2 * cmath.exp(r2 * t)) / (r1 - r2)).real
    return max(initial, abs(acceleration))


def paper_restitution(xi: float) -> float:
    """Eq. 26 exactly as printed (for the errata: it is not the restitution of eq. 25's collision)."""
    root = math.sqrt(1.0 - xi * xi)
    angle = math.atan(-2.0 * xi * root / (1.0 - 2.0 * xi * xi))
    return -math.exp(-xi / root * angle) * math.sin(angle)
