"""The best linear absorber of a given mass: the H-infinity optimum, the design a stop must beat (issue 32).

The paper's two-mass layout: a primary mass m1 on a suspension (k1, b1), forced by q cos(w t), and an absorber m2
on (k2, b2). The absorber to compare a nonlinear design with is the linear one of the same mass that minimises the
largest |X1| over a frequency band, the H-infinity optimum. For an undamped primary it has a closed form
(Nishihara & Asami, J. Vib. Acoust. 2002) in the mass ratio mu = m2 / m1::

    gamma = w_a / w_p = 1 / (1 + mu) sqrt(8 (16 + 23 mu + 9 mu^2 + 2 (2 + mu) sqrt(4 + 3 mu)) / (3 (64 + 80 mu + 27 mu^2)))
    zeta = b2 / (2 m2 w_a) = 1 / 4 sqrt((8 + 9 mu - 4 sqrt(4 + 3 mu)) / (1 + mu))

with w_p = sqrt(k1 / m1) and w_a = sqrt(k2 / m2) (mu = 0.05: gamma = 0.95237, zeta = 0.13394, a peak of 6.4079 q / k1;
Den Hartog's fixed-point design, gamma = 1 / (1 + mu), zeta = sqrt(3 mu / (8 (1 + mu))), is its approximation).
:func:`optimal_linear_absorber` finds it numerically for any primary (damped, and worst case over mistuned primaries),
starting from the closed form: the minimax of the band peaks of |X1| (each peak located to 1e-12 rad/s by a bounded
search around the maxima of a fine scan) over (k2, b2), by Nelder-Mead in their logarithms.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize, minimize_scalar

from vibroimpact.model.structure import require_non_negative, require_positive
from vibroimpact.model.system import TwoDofSystem

__all__ = ["nishihara_asami", "band_peak", "BandPeak", "LinearAbsorberOptimum", "optimal_linear_absorber", "SCAN_POINTS"]

#: Frequencies of the scan whose local maxima the band peak is refined from (each then to 1e-12 rad/s).
SCAN_POINTS = 4001


def nishihara_asami(mass_ratio: float) -> tuple[float, float]:
    """The H-infinity optimum absorber of an undamped primary: (tuning w_a / w_p, damping ratio b2 / (2 m2 w_a))
    [-] for mass ratio mu = m2 / m1 > 0 (module docstring)."""
    mu = require_positive("mass_ratio", mass_ratio)
    root = math.sqrt(4.0 + 3.0 * mu)
    tuning = math.sqrt(8.0 * (16.0 + 23.0 * mu + 9.0 * mu * mu + 2.0 * (2.0 + mu) * root) / (3.0 * (64.0 + 80.0 * mu + 27.0 * mu * mu))) / (1.0 + mu)
    damping = 0.25 * math.sqrt((8.0 + 9.0 * mu - 4.0 * root) / (1.0 + mu))
    return tuning, damping


@dataclass(frozen=True)
class BandPeak:
    """The largest |X1| of a linear system over a band and where it is.

    Attributes
    ----------
    amplitude : float
        max |X1| [m].
    frequency : float
        Where [Hz].
    peaks : tuple of (float, float)
        Every local maximum inside the band (frequency [Hz], |X1| [m]), increasing in frequency (the band's ends
        included where |X1| is largest there).
    """

    amplitude: float
    frequency: float
    peaks: tuple[tuple[float, float], ...]


def band_peak(system: TwoDofSystem, amplitude: float, band: tuple[float, float]) -> BandPeak:
    """max |X1| = q |H11(w)| over ``band`` [Hz] for the force amplitude q = ``amplitude`` [N] on the primary mass:
    the maxima of a :data:`SCAN_POINTS` scan, each refined by a bounded search between its neighbours."""
    low, high = (float(f) for f in band)
    if not 0.0 < low < high:
        raise ValueError(f"band = {band!r}: expected 0 < start < stop [Hz]")
    q = abs(float(amplitude))

    def response(f: float | np.ndarray) -> np.ndarray:
        return q * np.abs(system.receptances(2.0 * math.pi * np.asarray(f, dtype=float)).h11)

    f = np.linspace(low, high, SCAN_POINTS)
    h = response(f)
    peaks = []
    for i in range(h.size):
        left = h[i - 1] if i > 0 else -math.inf
        right = h[i + 1] if i + 1 < h.size else -math.inf
        if h[i] >= left and h[i] >= right:
            if 0 < i < h.size - 1:
                found = minimize_scalar(lambda x: -float(response(x)), bounds=(f[i - 1], f[i + 1]), method="bounded", options={"xatol": 1e-12 * f[i]})
                peaks.append((float(found.x), -float(found.fun)))
            else:
                peaks.append((float(f[i]), float(h[i])))
    frequency, value = max(peaks, key=lambda p: p[1])
    return BandPeak(value, frequency, tuple(peaks))


@dataclass(frozen=True)
class LinearAbsorberOptimum:
    """The best linear absorber of mass m2 for a primary (:func:`optimal_linear_absorber`).

    Attributes
    ----------
    system : TwoDofSystem
        The primary with the optimum absorber (k2 [N m-1], b2 [N s m-1]).
    tuning : float
        w_a / w_p = sqrt(k2 / m2) / sqrt(k1 / m1) of the nominal primary [-].
    damping_ratio : float
        b2 / (2 m2 w_a) [-].
    worst : float
        The largest band peak of |X1| over the primaries it was optimised for [m].
    peaks : tuple of BandPeak
        The band peak of each of those primaries (the nominal one first).
    """

    system: TwoDofSystem
    tuning: float
    damping_ratio: float
    worst: float
    peaks: tuple[BandPeak, ...] = field(default=())

    @property
    def equal_peaks(self) -> float:
        """The relative difference of the nominal primary's two largest peaks [-] (0 on the equal-peak ridge)."""
        values = sorted((p for _f, p in self.peaks[0].peaks), reverse=True)
        return (values[0] - values[1]) / values[0] if len(values) > 1 else math.nan


def optimal_linear_absorber(
    primary: TwoDofSystem, amplitude: float, band: tuple[float, float], mistuned: Sequence[TwoDofSystem] = (), tolerance: float = 1e-10,
) -> LinearAbsorberOptimum:  # fmt: skip
    """The linear absorber of ``primary``'s mass m2 that minimises the worst band peak of |X1|.

    Parameters
    ----------
    primary : TwoDofSystem
        m1, k1, b1 and the absorber's mass m2 (its k2 and b2 are ignored).
    amplitude : float
        q [N] on the primary mass.
    band : (float, float)
        The band [Hz].
    mistuned : sequence of TwoDofSystem, optional
        Other primaries (their m1, k1, b1; e.g. +-5 % of k1) the absorber must serve too: the objective is the worst
        band peak over ``primary`` and these.
    tolerance : float
        Nelder-Mead's tolerance on log k2 and log b2 and on the relative peak [-].

    Returns
    -------
    LinearAbsorberOptimum
    """
    require_non_negative("tolerance", tolerance)
    m1, k1, m2 = primary.m1, primary.k1, primary.m2
    tuning, zeta = nishihara_asami(m2 / m1)
    w_p = math.sqrt(k1 / m1)
    start = np.log([m2 * (tuning * w_p) ** 2, 2.0 * m2 * zeta * tuning * w_p])
    primaries = (primary, *mistuned)

    def designed(x: np.ndarray) -> list[TwoDofSystem]:
        k2, b2 = (float(v) for v in np.exp(x))
        return [dataclasses.replace(p, m2=m2, k2=k2, b2=b2) for p in primaries]

    def worst(x: np.ndarray) -> float:
        return max(band_peak(s, amplitude, band).amplitude for s in designed(x))

    scale = worst(start)
    found = minimize(lambda x: worst(x) / scale, start, method="Nelder-Mead", options={"xatol": tolerance, "fatol": tolerance, "maxiter": 4000})
    systems = designed(found.x)
    peaks = tuple(band_peak(s, amplitude, band) for s in systems)
    k2, b2 = systems[0].k2, systems[0].b2
    w_a = math.sqrt(k2 / m2)
    return LinearAbsorberOptimum(systems[0], w_a / w_p, b2 / (2.0 * m2 * w_a), max(p.amplitude for p in peaks), peaks)
