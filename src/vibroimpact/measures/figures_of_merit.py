"""What a page judges an absorber by, declared once for every kind: its operating point's tolerances, the worst
stable response over every coexisting motion, the anti-resonance band and the notch depth.

An absorber exists for its notch: at its operating point (the anti-resonance of the linear absorber, or a frequency
the scene declares) the primary mass barely moves. A stop that makes the response there worse than the same absorber
without it has destroyed the notch, whatever it does at the resonances. The stepped, design and concepts kinds read
what is here; none copies it.

* The **worst stable response** E(f): at each frequency of the fine grid, the largest |X1| (and base force) over every
  stable steady state found there: the linear motion where it clears the stops, the closed-form impact orbit where it
  is stable, the stable stretches of the continued branches (interpolated between consecutive stable points), and the
  simulated steady state at the nearest grid point (an attractor, periodic or not). Coexisting stable motions are all
  reachable, so the worst one counts.
* The **anti-resonance band**: the stretch around the absorber's anti-resonance where the reference system (the
  scene's, without a stop) keeps |X1| below the static deflection q / k1.
* The **notch depth**: the smallest E(f) in the band over q / k1, in dB (negative: below the static deflection).
* **Impacts in the band**: the share of the band's grid points where the motion impacts: everywhere the linear motion
  does not clear the stops (then every steady motion impacts), and wherever a stable impacting motion was found.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["WORSE_RATIO", "NEAREST", "NEAR_OPERATING", "Envelope", "anti_resonance_band", "envelope", "stretches", "BandMetrics", "band_metrics"]

#: A stop makes the operating point worse where its value exceeds the linear absorber's by more than this factor [-]
#: (1 % above: beyond the round-off of a computed ratio, well below any change an engineer would accept).
WORSE_RATIO = 1.01
#: A computed grid frequency stands for the operating frequency only within this share of it [-] (the notch is narrow:
#: its width is of the order of the absorber's damping ratio times its frequency).
NEAREST = 0.01
#: A stable motion with the stop this close to the operating frequency [-, of it] is warned of where it exceeds what is
#: allowed there: a machine's speed drifts by a few per cent with its load and supply (stepped and design pages).
NEAR_OPERATING = 0.05


def anti_resonance_band(frequency: NDArray[np.float64], x1: NDArray[np.float64], static: float) -> tuple[float, float, float]:
    """(low, high, anti-resonance) [Hz]: the contiguous stretch of ``frequency`` around the smallest |X1| where
    ``x1`` < ``static``, and the frequency of that smallest |X1|; NaNs if |X1| never drops below ``static``."""
    below = x1 < static
    if not np.any(below):
        return math.nan, math.nan, math.nan
    k = int(np.argmin(np.where(below, x1, np.inf)))
    first, last = k, k
    while first > 0 and below[first - 1]:
        first -= 1
    while last < below.size - 1 and below[last + 1]:
        last += 1
    return float(frequency[first]), float(frequency[last]), float(frequency[k])


@dataclass(frozen=True)
class Envelope:
    """The worst stable response of one concept on the fine grid (NaN where no stable motion was found).

    Attributes
    ----------
    x1 : ndarray
        max |X1| [m].
    base_force : ndarray
        max |base force fundamental| [N].
    impacts : ndarray of int8
        1: the motion impacts there (the linear motion does not clear the stops, or a stable impacting motion was
        found); 0: a stable motion clear of the stops and none that impacts; -1: nothing known.
    """

    x1: NDArray[np.float64]
    base_force: NDArray[np.float64]
    impacts: NDArray[np.int8]


def _merge(target: NDArray[np.float64], index: NDArray[np.intp], values: NDArray[np.float64]) -> None:
    """target[index] = max(target[index], values), NaN-aware (NaN targets take the value)."""
    current = target[index]
    target[index] = np.where(np.isnan(current) | (values > current), values, current)


def envelope(
    frequency: NDArray[np.float64],
    linear: tuple[NDArray, NDArray, NDArray],
    closed: tuple[NDArray, NDArray, NDArray, int],
    simulated: tuple[NDArray, NDArray, NDArray, NDArray],
    branches: tuple[NDArray, NDArray, NDArray, NDArray, NDArray, NDArray],
) -> Envelope:
    """E(f) from every source (module docstring).

    Parameters
    ----------
    frequency : ndarray, shape (F,)
        Fine grid [Hz], increasing.
    linear : (x1, base force, fits)
        The linear steady state on the grid; ``fits``: it clears the stops.
    closed : (x1, base force, stable flag, impacts per period)
        The closed-form impact orbit on the grid (flag 1: stable).
    simulated : (frequency, x1, base force, impacts per period)
        Simulated steady states (NaN where failed).
    branches : (frequency, x1, base force, Floquet modulus, impacts per period, branch label)
        Continued orbits, in branch order.
    """
    f = np.asarray(frequency, dtype=float)
    x1 = np.full(f.shape, np.nan)
    force = np.full(f.shape, np.nan)
    impacts = np.full(f.shape, -1, dtype=np.int8)
    every = np.arange(f.size)

    def add(index: NDArray[np.intp], values_x1: NDArray, values_force: NDArray, impacting: NDArray[np.bool_] | bool) -> None:
        _merge(x1, index, values_x1)
        _merge(force, index, values_force)
        flag = np.where(np.broadcast_to(impacting, index.shape), 1, 0).astype(np.int8)
        impacts[index] = np.maximum(impacts[index], flag)

    fits = np.asarray(linear[2], dtype=bool)
    add(every[fits], linear[0][fits], linear[1][fits], False)
    impacts[~fits] = 1  # the only impactless steady motion is the linear one: where it hits a stop, every motion impacts
    stable = np.asarray(closed[2]) == 1
    add(every[stable], closed[0][stable], closed[1][stable], closed[3] > 0)
    sim_f, sim_x1, sim_force, sim_impacts = (np.asarray(a, dtype=float) for a in simulated)
    ok = np.isfinite(sim_x1)
    if np.any(ok) and f.size:
        nearest = np.clip(np.searchsorted(f, sim_f[ok]), 0, f.size - 1)
        lower = np.clip(nearest - 1, 0, f.size - 1)
        nearest = np.where(np.abs(f[lower] - sim_f[ok]) < np.abs(f[nearest] - sim_f[ok]), lower, nearest)
        add(nearest, sim_x1[ok], sim_force[ok], sim_impacts[ok] > 0.0)
    b_f, b_x1, b_force, b_modulus, b_impacts, b_label = (np.asarray(a, dtype=float) for a in branches)
    for a in range(b_f.size - 1):
        b = a + 1
        if b_label[a] != b_label[b] or not (b_modulus[a] < 1.0 and b_modulus[b] < 1.0):
            continue
        lo, hi = sorted((b_f[a], b_f[b]))
        inside = every[(f >= lo) & (f <= hi)]
        if inside.size == 0:
            continue
        t = (f[inside] - b_f[a]) / (b_f[b] - b_f[a]) if b_f[b] != b_f[a] else np.zeros(inside.size)
        add(inside, b_x1[a] + t * (b_x1[b] - b_x1[a]), b_force[a] + t * (b_force[b] - b_force[a]), bool(b_impacts[a] > 0.0 or b_impacts[b] > 0.0))
    return Envelope(x1, force, impacts)


def stretches(frequency: NDArray[np.float64], mask: NDArray[np.bool_], gap: float) -> list[tuple[float, float]]:
    """The (first, last) frequency [Hz] of each run of True in ``mask`` over the sorted ``frequency``, runs closer than
    ``gap`` [Hz] joined."""
    f = np.asarray(frequency, dtype=float)
    order = np.argsort(f, kind="stable")
    f, m = f[order], np.asarray(mask, dtype=bool)[order]
    out: list[tuple[float, float]] = []
    for value, flag in zip(f, m):
        if not flag:
            continue
        if out and value - out[-1][1] <= gap:
            out[-1] = (out[-1][0], float(value))
        else:
            out.append((float(value), float(value)))
    return out


@dataclass(frozen=True)
class BandMetrics:
    """One concept's figures of merit.

    Attributes
    ----------
    peak_x1, peak_x1_frequency : float
        Largest worst-stable |X1| [m] and where [Hz].
    peak_force, peak_force_frequency : float
        Largest worst-stable base-force fundamental [N] and where [Hz].
    notch_depth : float
        20 log10(min E in the band / (q / k1)) [dB]; NaN if no stable motion was found in the band.
    notch_frequency : float
        Where that minimum is [Hz].
    band_impact_fraction : float
        Share of the band's grid points with a stable impacting motion [-].
    band_impacts : list of (float, float)
        Where in the band a stable motion impacts [Hz].
    band_coverage : float
        Share of the band's grid points where a stable motion was found at all [-].
    """

    peak_x1: float
    peak_x1_frequency: float
    peak_force: float
    peak_force_frequency: float
    notch_depth: float
    notch_frequency: float
    band_impact_fraction: float
    band_impacts: list[tuple[float, float]]
    band_coverage: float


def band_metrics(frequency: NDArray[np.float64], worst: Envelope, band: tuple[float, float], static: float) -> BandMetrics:
    """:class:`BandMetrics` of ``worst`` over ``frequency`` [Hz] with the anti-resonance ``band`` [Hz] and the static
    deflection ``static`` [m]."""
    f = np.asarray(frequency, dtype=float)
    nan = math.nan

    def peak(values: NDArray[np.float64]) -> tuple[float, float]:
        if not np.any(np.isfinite(values)):
            return nan, nan
        k = int(np.nanargmax(values))
        return float(values[k]), float(f[k])

    peak_x1, peak_x1_f = peak(worst.x1)
    peak_force, peak_force_f = peak(worst.base_force)
    inside = (f >= band[0]) & (f <= band[1]) if math.isfinite(band[0]) else np.zeros(f.shape, dtype=bool)
    found = inside & np.isfinite(worst.x1)
    depth = where = nan
    if np.any(found):
        k = int(np.flatnonzero(found)[np.argmin(worst.x1[found])])
        depth, where = 20.0 * math.log10(worst.x1[k] / static), float(f[k])
    count = int(np.sum(inside))
    impacting = inside & (worst.impacts == 1)
    step = float(np.median(np.diff(f))) if f.size > 1 else 0.0
    fraction = float(np.sum(impacting)) / count if count else nan
    coverage = float(np.sum(found)) / count if count else nan
    return BandMetrics(peak_x1, peak_x1_f, peak_force, peak_force_f, depth, where, fraction, stretches(f, impacting, 1.5 * step), coverage)
