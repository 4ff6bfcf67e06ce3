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

Both take the measure a design judges (:mod:`vibroimpact.analysis.measures`, default ``x1_amplitude``):
``x2_amplitude`` the absorber's |X2| = q |H12|, ``force_amplitude`` the force to the base |F| =
|(k1 + j w b1) X1| (:func:`~vibroimpact.analysis.linear.base_force`; no stop). The closed form stays the start (the
|X1| optimum; the force's is within 1e-5 of it on a lightly damped primary); the optimum found is the measure's own.
|X2| has none at a finite absorber (its worst peak falls as k2, b2 -> 0: :class:`NoLinearOptimum`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize, minimize_scalar

from vibroimpact.analysis.linear import ResonancePeak, paper_linear_response, peaks_near
from vibroimpact.analysis.measures import Measure, measure as measure_named
from vibroimpact.model.structure import STIFFNESS_RATIO, require_non_negative, require_positive
from vibroimpact.model.system import TwoDofSystem

__all__ = ["nishihara_asami", "band_peak", "BandPeak", "linear_measure", "resonance_peaks", "as_linear_measure", "LinearAbsorberOptimum", "NoLinearOptimum", "optimal_linear_absorber", "SCAN_POINTS", "X1_AMPLITUDE"]

#: The default measure: the primary mass's |X1| (the H-infinity optimum's).
X1_AMPLITUDE = measure_named("x1_amplitude")

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
    """The largest value of a measure of a linear system over a band and where it is.

    Attributes
    ----------
    amplitude : float
        The measure's maximum over the band, in the measure's unit (|X1|, |X2| [m]; |F| [N]).
    frequency : float
        Where [Hz].
    peaks : tuple of (float, float)
        Every local maximum inside the band (frequency [Hz], value in the measure's unit), increasing in frequency
        (the band's ends included where the measure is largest there).
    measure : Measure
        What was measured (default |X1|, ``x1_amplitude``).
    """

    amplitude: float
    frequency: float
    peaks: tuple[tuple[float, float], ...]
    measure: Measure = X1_AMPLITUDE


def as_linear_measure(measure: Measure | str) -> Measure:
    """``measure`` (a :class:`~vibroimpact.analysis.measures.Measure` or its name) as one of the paper's two-mass
    system: x1_amplitude, x2_amplitude or force_amplitude.

    Raises
    ------
    ValueError
        Another name, or a coordinate the system lacks.
    """
    found = measure_named(measure) if isinstance(measure, str) else measure
    if not isinstance(found, Measure):
        raise TypeError(f"measure = {measure!r}: expected a Measure or a measure's name")
    if found.coordinate is not None and found.coordinate > 1:
        raise ValueError(f"measure = {found.name!r}: coordinate {found.coordinate} is not one of the two-mass system's (x1, x2)")
    return found


def linear_measure(system: TwoDofSystem, amplitude: float, omega: float | np.ndarray, measure: Measure | str = X1_AMPLITUDE) -> np.ndarray:
    """The measure of the linear steady state (no stop) under the force q = |``amplitude``| [N] on the primary mass at
    angular frequencies ``omega`` [rad s-1]: q |H11| or q |H12| [m] for a coordinate's amplitude, |F| [N] of the
    base force 1^T (K + j w C) X = (k1 + j w b1) X1 for ``force_amplitude``."""
    chosen = as_linear_measure(measure)
    q = abs(float(amplitude))
    w = np.asarray(omega, dtype=float)
    h = system.receptances(w)
    if chosen.coordinate == 0:
        return q * np.abs(h.h11)
    if chosen.coordinate == 1:
        return q * np.abs(h.h12)
    x = np.stack([q * h.h11, q * h.h12], axis=-1)  # X1, X2 [m]
    return chosen.of_harmonics(system, w, x)


def resonance_peaks(system: TwoDofSystem, amplitude: float, quantity: str = "x1", span: float = 0.05) -> list[ResonancePeak]:
    """Maxima of a linear amplitude of the paper's system near each natural frequency, by analytic maximisation (not
    from a grid; :func:`~vibroimpact.analysis.linear.structure_peaks` is the same for any problem).

    Parameters
    ----------
    system : TwoDofSystem
        The linear system.
    amplitude : float
        Force amplitude q [N].
    quantity : {'x1', 'x2', 'force'}
        Which amplitude (:func:`~vibroimpact.model.system.paper_linear_response`).
    span : float
        Relative half-width of the search window around each undamped natural frequency [-].
    """
    if quantity not in ("x1", "x2", "force"):
        raise ValueError(f"quantity must be 'x1', 'x2' or 'force', got {quantity!r}")

    def magnitude(w: np.ndarray) -> np.ndarray:
        return np.abs(getattr(paper_linear_response(system, omega=w, amplitude=amplitude), quantity))

    return peaks_near(system.natural_angular_frequencies(), magnitude, span)


def band_peak(system: TwoDofSystem, amplitude: float, band: tuple[float, float], measure: Measure | str = X1_AMPLITUDE) -> BandPeak:
    """The largest value of ``measure`` (default |X1| = q |H11(w)|; :func:`linear_measure`) over ``band`` [Hz] for
    the force amplitude q = ``amplitude`` [N] on the primary mass: the maxima of a :data:`SCAN_POINTS` scan, each
    refined by a bounded search between its neighbours. :attr:`BandPeak.amplitude` is in the measure's unit ([m] for
    a displacement amplitude, [N] for ``force_amplitude``)."""
    low, high = (float(f) for f in band)
    if not 0.0 < low < high:
        raise ValueError(f"band = {band!r}: expected 0 < start < stop [Hz]")
    chosen = as_linear_measure(measure)

    def response(f: float | np.ndarray) -> np.ndarray:
        return linear_measure(system, amplitude, 2.0 * math.pi * np.asarray(f, dtype=float), chosen)

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
    return BandPeak(value, frequency, tuple(peaks), chosen)


class NoLinearOptimum(ValueError):
    """A measure whose worst band peak has no minimum at a finite linear absorber (:func:`optimal_linear_absorber`)."""


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
        The largest band peak of the measure over the primaries it was optimised for, in the measure's unit (|X1|,
        |X2| [m]; |F| [N]).
    peaks : tuple of BandPeak
        The band peak of each of those primaries (the nominal one first).
    measure : Measure
        The measure it minimises (default |X1|, ``x1_amplitude``).
    """

    system: TwoDofSystem
    tuning: float
    damping_ratio: float
    worst: float
    peaks: tuple[BandPeak, ...] = field(default=())
    measure: Measure = X1_AMPLITUDE

    @property
    def equal_peaks(self) -> float:
        """The relative difference of the nominal primary's two largest peaks [-] (0 on the equal-peak ridge)."""
        values = sorted((p for _f, p in self.peaks[0].peaks), reverse=True)
        return (values[0] - values[1]) / values[0] if len(values) > 1 else math.nan


def optimal_linear_absorber(
    primary: TwoDofSystem, amplitude: float, band: tuple[float, float], mistuned: Sequence[TwoDofSystem] = (), tolerance: float = 1e-10,
    measure: Measure | str = X1_AMPLITUDE,
) -> LinearAbsorberOptimum:  # fmt: skip
    """The linear absorber of ``primary``'s mass m2 that minimises the worst band peak of ``measure`` (default |X1|).

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
    measure : Measure or str
        What a band peak measures (:func:`band_peak`): ``x1_amplitude`` (default, the H-infinity optimum),
        ``x2_amplitude`` or ``force_amplitude``; the search starts from the |X1| closed form whatever it is.

    Returns
    -------
    LinearAbsorberOptimum

    Raises
    ------
    NoLinearOptimum
        The measure has no optimum at a finite absorber: the search leaves the springs' admissible ratio k2 / k1
        (:data:`~vibroimpact.model.structure.STIFFNESS_RATIO`). The absorber's own |X2| under a force on m1 does: its
        worst band peak falls without end as k2 and b2 go to 0 together (the absorber moves least when it is not
        attached; on the paper's primary 5.2e-3 m at the |X1| optimum, 6.6e-4 m at 1/100 of its k2 and b2).
    """
    require_non_negative("tolerance", tolerance)
    chosen = as_linear_measure(measure)
    m1, k1, m2 = primary.m1, primary.k1, primary.m2
    tuning, zeta = nishihara_asami(m2 / m1)
    w_p = math.sqrt(k1 / m1)
    start = np.log([m2 * (tuning * w_p) ** 2, 2.0 * m2 * zeta * tuning * w_p])
    primaries = (primary, *mistuned)

    def designed(x: np.ndarray) -> list[TwoDofSystem]:
        k2, b2 = (float(v) for v in np.exp(x))
        if not 1.0 / STIFFNESS_RATIO <= k2 / k1 <= STIFFNESS_RATIO:
            raise NoLinearOptimum(
                f"optimal_linear_absorber: the worst band peak of {chosen.symbol} ({chosen.name}) keeps falling as k2 / k1 leaves "
                f"[1/{STIFFNESS_RATIO:g}, {STIFFNESS_RATIO:g}] (k2 = {k2:.6g} N/m, b2 = {b2:.6g} N s/m): its least value is a "
                f"{'detached' if k2 < k1 else 'rigid'} absorber, no linear optimum to compare with",
            )
        return [dataclasses.replace(p, m2=m2, k2=k2, b2=b2) for p in primaries]

    def worst(x: np.ndarray) -> float:
        return max(band_peak(s, amplitude, band, chosen).amplitude for s in designed(x))

    scale = worst(start)
    found = minimize(lambda x: worst(x) / scale, start, method="Nelder-Mead", options={"xatol": tolerance, "fatol": tolerance, "maxiter": 4000})
    systems = designed(found.x)
    peaks = tuple(band_peak(s, amplitude, band, chosen) for s in systems)
    k2, b2 = systems[0].k2, systems[0].b2
    w_a = math.sqrt(k2 / m2)
    return LinearAbsorberOptimum(systems[0], w_a / w_p, b2 / (2.0 * m2 * w_a), max(p.amplitude for p in peaks), peaks, chosen)
