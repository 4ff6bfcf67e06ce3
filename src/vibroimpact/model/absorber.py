"""Den Hartog's classical damped absorber: the optimal tuning and damping that the ``concepts`` scene can ask for.

A primary mass m1 on a spring k1 (undamped), forced by q cos(w t), carries an absorber m2 on a spring k2 and a
dashpot c2. With the mass ratio mu = m2 / m1, the primary's natural frequency Omega_p = sqrt(k1 / m1), the tuning
f = omega_a / Omega_p (omega_a = sqrt(k2 / m2)), g = w / Omega_p and Den Hartog's damping ratio
zeta = c2 / c_c, c_c = 2 m2 Omega_p (his "critical damping", taken with the *primary's* natural frequency), the
primary's amplitude is, with x_st = q / k1::

    |X1| / x_st = sqrt( ((2 zeta g)^2 + (g^2 - f^2)^2)
                  / ((2 zeta g)^2 (g^2 - 1 + mu g^2)^2 + (mu f^2 g^2 - (g^2 - 1)(g^2 - f^2))^2) )

Every curve, whatever zeta, passes through two fixed points P and Q, the roots of
``g^4 - 2 g^2 (1 + f^2 + mu f^2) / (2 + mu) + 2 f^2 / (2 + mu) = 0``. Den Hartog's optimum:

* tuning: P and Q equally high, ``f = 1 / (1 + mu)``; then g_{P,Q}^2 = (1 -+ sqrt(mu / (2 + mu))) / (1 + mu) and
  both heights are |X1| / x_st = sqrt(1 + 2 / mu);
* damping: the curve is horizontal at P for zeta^2 = mu (3 - sqrt(mu / (mu + 2))) / (8 (1 + mu)^3) and at Q for
  zeta^2 = mu (3 + sqrt(mu / (mu + 2))) / (8 (1 + mu)^3); Den Hartog takes their mean,
  ``zeta^2 = 3 mu / (8 (1 + mu)^3)``, so the curve is flat at P and Q to that approximation.

With c_c = 2 m2 Omega_p the optimal dashpot is c2 = 2 zeta m2 Omega_p whatever the absorber's tuning. (Written with
the absorber's own frequency, c2 = 2 zeta_a m2 omega_a, the same optimum reads zeta_a^2 = 3 mu / (8 (1 + mu)).)

References: J. P. Den Hartog, *Mechanical Vibrations*, 4th ed., McGraw-Hill, New York 1956, sec. 3.3 (the damped
vibration absorber); J. E. Brock, "A note on the damped vibration absorber", J. Appl. Mech. 13 (1946) A-284 (the
optimal damping); J. Ormondroyd and J. P. Den Hartog, "The theory of the dynamic vibration absorber", Trans. ASME
APM-50-7 (1928) 9-22 (the fixed points, and stops between absorber and primary mass).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "DenHartogAbsorber",
    "den_hartog_absorber",
    "optimal_tuning",
    "optimal_damping_ratio",
    "fixed_point_ratios",
    "fixed_point_height",
    "flat_point_damping_ratios",
    "primary_amplitude_ratio",
]


def _mass_ratio(mu: float) -> float:
    if not (math.isfinite(mu) and mu > 0.0):
        raise ValueError(f"mass ratio mu = m2 / m1 = {mu!r} is out of range: allowed (0, inf)")
    return float(mu)


def optimal_tuning(mu: float) -> float:
    """Den Hartog's optimal tuning f = omega_a / Omega_p = 1 / (1 + mu) [-] (P and Q equally high)."""
    return 1.0 / (1.0 + _mass_ratio(mu))


def optimal_damping_ratio(mu: float) -> float:
    """Den Hartog's (and Brock's) optimal zeta = c2 / (2 m2 Omega_p) = sqrt(3 mu / (8 (1 + mu)^3)) [-]."""
    mu = _mass_ratio(mu)
    return math.sqrt(3.0 * mu / (8.0 * (1.0 + mu) ** 3))


def flat_point_damping_ratios(mu: float) -> tuple[float, float]:
    """The zeta that makes the optimally tuned curve horizontal at P, and the one at Q [-] (their squares' mean is
    :func:`optimal_damping_ratio` squared)."""
    mu = _mass_ratio(mu)
    root = math.sqrt(mu / (mu + 2.0))
    scale = mu / (8.0 * (1.0 + mu) ** 3)
    return math.sqrt(scale * (3.0 - root)), math.sqrt(scale * (3.0 + root))


def fixed_point_ratios(mu: float, tuning: float | None = None) -> tuple[float, float]:
    """g_P < g_Q: the forcing frequencies of the fixed points P and Q over Omega_p [-], for ``tuning`` f (default
    the optimal one)."""
    mu = _mass_ratio(mu)
    f = optimal_tuning(mu) if tuning is None else float(tuning)
    if not (math.isfinite(f) and f > 0.0):
        raise ValueError(f"tuning f = {tuning!r} is out of range: allowed (0, inf)")
    b = (1.0 + f * f + mu * f * f) / (2.0 + mu)
    c = 2.0 * f * f / (2.0 + mu)
    root = math.sqrt(b * b - c)  # b^2 > c for every f > 0, mu > 0
    return math.sqrt(b - root), math.sqrt(b + root)


def fixed_point_height(mu: float) -> float:
    """|X1| / x_st at P and Q of the optimally tuned absorber, sqrt(1 + 2 / mu) [-]."""
    return math.sqrt(1.0 + 2.0 / _mass_ratio(mu))


def primary_amplitude_ratio(g: ArrayLike, mu: float, tuning: float, zeta: float) -> NDArray[np.float64]:
    """|X1| / x_st of Den Hartog's formula at g = w / Omega_p [-] (undamped primary)."""
    g = np.asarray(g, dtype=float)
    mu = _mass_ratio(mu)
    f2, g2 = tuning * tuning, g * g
    damping = (2.0 * zeta * g) ** 2
    numerator = damping + (g2 - f2) ** 2
    denominator = damping * (g2 - 1.0 + mu * g2) ** 2 + (mu * f2 * g2 - (g2 - 1.0) * (g2 - f2)) ** 2
    return np.sqrt(numerator / denominator)


@dataclass(frozen=True)
class DenHartogAbsorber:
    """The optimal absorber of a primary (m1, k1) for an absorber mass m2.

    Attributes
    ----------
    mass_ratio : float
        mu = m2 / m1 [-].
    tuning : float
        f = omega_a / Omega_p = 1 / (1 + mu) [-].
    damping_ratio : float
        zeta = c2 / (2 m2 Omega_p) [-].
    stiffness : float
        k2 = m2 (f Omega_p)^2 [N m-1].
    damping : float
        c2 = 2 zeta m2 Omega_p [N s m-1].
    primary_frequency : float
        Omega_p / 2 pi [Hz].
    """

    mass_ratio: float
    tuning: float
    damping_ratio: float
    stiffness: float
    damping: float
    primary_frequency: float

    @property
    def absorber_frequency(self) -> float:
        """omega_a / 2 pi = f Omega_p / 2 pi [Hz]."""
        return self.tuning * self.primary_frequency


def den_hartog_absorber(m1: float, k1: float, m2: float) -> DenHartogAbsorber:
    """Den Hartog's optimal stiffness and dashpot of an absorber of mass ``m2`` [kg] on a primary ``m1`` [kg],
    ``k1`` [N m-1]."""
    for name, value in (("system.m1", m1), ("system.k1", k1), ("system.m2", m2)):
        if not (math.isfinite(value) and value > 0.0):
            raise ValueError(f"{name} = {value!r} is out of range: allowed (0, inf)")
    mu = m2 / m1
    omega_p = math.sqrt(k1 / m1)
    tuning = optimal_tuning(mu)
    zeta = optimal_damping_ratio(mu)
    return DenHartogAbsorber(mu, tuning, zeta, m2 * (tuning * omega_p) ** 2, 2.0 * zeta * m2 * omega_p, omega_p / (2.0 * math.pi))
