"""What a sequence of stroboscopic states says about the motion: its rotation number and its spectral lines.

A quasi-periodic motion with two frequencies (the excitation's f and a second f2, born at a Neimark-Sacker
bifurcation) strobes onto an invariant closed curve, on which the map acts as a circle map with rotation number
rho = f2 / f (mod 1): the strobe sequence is x_k = g(theta_0 + 2 pi k rho), whose spectrum is a set of lines at the
multiples of rho (mod 1). A periodic motion of period p strobes onto p points (lines at multiples of 1/p). A chaotic
motion has a broadband spectrum and no rotation number.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["RotationEstimate", "StrobeSpectrum", "rotation_number", "strobe_spectrum"]


@dataclass(frozen=True)
class RotationEstimate:
    """Rotation number of a strobe sequence around its centroid.

    Attributes
    ----------
    rotation_number : float
        Mean angle increment per period divided by 2 pi [cycles/period], folded into [0, 1/2]: the projection's
        orientation is arbitrary, so rho and 1 - rho describe the same motion. Meaningful only when ``regular``.
    order_fraction : float
        Fraction of the points whose image keeps the cyclic order of the points around the centroid [-]: 1 for an
        orientation-preserving circle map (the angle advances monotonically along the invariant curve: neighbours
        on the curve stay neighbours), a few / n for a cloud of points (chaos).
    angle_increments : ndarray, shape (n - 1,)
        Lifted angle increments [rad], each within pi of their circular mean.
    regular : bool
        ``order_fraction >= order_threshold``: the strobes lie on a curve around the centroid traversed as by a
        rotation.
    """

    rotation_number: float
    order_fraction: float
    angle_increments: NDArray[np.float64]
    regular: bool

    def __post_init__(self) -> None:
        self.angle_increments.setflags(write=False)


@dataclass(frozen=True)
class StrobeSpectrum:
    """Windowed power spectrum of one component of a strobe sequence.

    Attributes
    ----------
    frequencies : ndarray, shape (n // 2 + 1,)
        Frequency of each bin [cycles/period] (multiply by the excitation frequency for Hz), 0 ... 1/2.
    power : ndarray
        |FFT|^2 of the Hann-windowed, mean-removed sequence [units^2] (one-sided, not normalised).
    peak_frequencies : ndarray
        Frequencies of the largest peaks, strongest first [cycles/period].
    line_fraction : float
        Fraction of the power within ``half_width`` bins of those peaks [-]: near 1 for a line spectrum (periodic
        or quasi-periodic), small for a broadband (chaotic) one; 1 for a constant sequence (a period-one orbit).
    """

    frequencies: NDArray[np.float64]
    power: NDArray[np.float64]
    peak_frequencies: NDArray[np.float64]
    line_fraction: float

    def __post_init__(self) -> None:
        for name in ("frequencies", "power", "peak_frequencies"):
            getattr(self, name).setflags(write=False)


def _strobes(strobes: ArrayLike, least: int) -> NDArray[np.float64]:
    s = np.asarray(strobes, dtype=float)
    if s.ndim == 1:
        s = s[:, None]
    if s.ndim != 2 or s.shape[0] < least:
        raise ValueError(f"strobes: expected shape (n, m) with n >= {least}, got {np.shape(strobes)}")
    if not np.all(np.isfinite(s)):
        raise ValueError("strobes: non-finite entries")
    return s


def _projection(strobes: NDArray[np.float64]) -> NDArray[np.float64]:
    """Coordinates of the centred strobes in the plane of their two largest principal components, each component
    first divided by its own spread (displacements and velocities have different units)."""
    centred = strobes - strobes.mean(axis=0)
    spread = centred.std(axis=0)
    keep = spread > 1e-12 * np.max(np.abs(strobes), axis=0)
    if not np.any(keep):  # a fixed point (period-one orbit): every angle 0
        return np.zeros((strobes.shape[0], 2))
    scaled = centred[:, keep] / spread[keep]
    if scaled.shape[1] == 1:
        return np.column_stack([scaled[:, 0], np.zeros(len(scaled))])
    _u, _s, vt = np.linalg.svd(scaled, full_matrices=False)
    return scaled @ vt[:2].T


def rotation_number(strobes: ArrayLike, order_threshold: float = 0.98) -> RotationEstimate:
    """Rotation number of a strobe sequence on an invariant closed curve.

    The strobes are projected on the plane of their two largest principal components (the plane of the invariant
    circle near a Neimark-Sacker bifurcation) and their angle around the centroid is followed. Each increment is
    lifted to within pi of the increments' circular mean (so a non-uniform circle map whose increments straddle 0 or
    2 pi is still lifted consistently), and rho is their mean / 2 pi, folded into [0, 1/2].

    Monotonicity test: on an invariant circle traversed by an orientation-preserving circle map the cyclic order of
    the points is preserved: if the points sorted by angle are p_1, p_2, ..., the images of p_i and p_{i+1} are again
    neighbours in the sorted images, all shifted by the same number of places. ``order_fraction`` is the fraction
    of points whose shift equals the most common one. Points closer in angle than 1 % of the mean spacing count as
    one (the repeated points of a periodic orbit).

    Parameters
    ----------
    strobes : array_like, shape (n, m)
        Stroboscopic states (n >= 8), one per period, on the attractor.
    order_threshold : float
        ``regular`` when ``order_fraction`` is at least this [-].

    Returns
    -------
    RotationEstimate
    """
    s = _strobes(strobes, 8)
    xy = _projection(s)
    theta = np.arctan2(xy[:, 1], xy[:, 0])
    raw = np.diff(theta)
    centre = math.atan2(float(np.mean(np.sin(raw))), float(np.mean(np.cos(raw))))
    lifted = centre + np.mod(raw - centre + np.pi, 2.0 * np.pi) - np.pi
    rho = float(np.mod(np.mean(lifted) / (2.0 * np.pi), 1.0))
    rho = min(rho, 1.0 - rho)
    # cyclic order: rank of each point among the pre-images and of its image among the images
    tolerance = 0.01 * 2.0 * np.pi / theta.size  # closer than 1 % of the mean spacing: the same point (periodic orbit)
    rank_pre, count = _ranks(theta[:-1], tolerance)
    rank_post, _ = _ranks(theta[1:], tolerance)
    shift = np.mod(rank_post - rank_pre, count)
    fraction = float(np.bincount(shift, minlength=count).max() / shift.size)
    return RotationEstimate(rho, fraction, lifted, fraction >= order_threshold)


def _ranks(angles: NDArray[np.float64], tolerance: float) -> tuple[NDArray[np.int_], int]:
    """Rank of each angle in increasing order, angles closer than ``tolerance`` sharing a rank, and the ranks' count."""
    order = np.argsort(angles, kind="stable")
    new = np.concatenate([[0], (np.diff(angles[order]) > tolerance).astype(int)])
    ranks = np.empty(angles.size, dtype=int)
    ranks[order] = np.cumsum(new)
    return ranks, int(ranks.max()) + 1


def strobe_spectrum(strobes: ArrayLike, component: int = 0, peaks: int = 5, half_width: int = 3) -> StrobeSpectrum:
    """Spectral lines of one component of a strobe sequence (X1 by default).

    The mean is removed, a Hann window applied and the one-sided power spectrum taken. The ``peaks`` largest local
    maxima are the lines; the power within ``half_width`` bins of each (the Hann main lobe is +-2 bins; its side
    lobes fall as the cube of the distance, so +-3 bins hold all but ~1e-4 of a pure tone's power, whatever its
    frequency) over the total is the line fraction. A quasi-periodic sequence has its power in a few harmonics of
    the rotation number (the smoother the invariant curve, the fewer), a chaotic one spreads it over all bins.

    Parameters
    ----------
    strobes : array_like, shape (n, m) or (n,)
        Stroboscopic states, one per period (n >= 16; a few hundred resolve lines to ~1/n cycles/period).
    component : int
        Column analysed (0: X1).
    peaks : int
        Lines counted (>= 1).
    half_width : int
        Bins each side of a line counted as the line (>= 1).

    Returns
    -------
    StrobeSpectrum
    """
    s = _strobes(strobes, 16)
    if not 0 <= component < s.shape[1]:
        raise ValueError(f"component = {component} is out of range: allowed [0, {s.shape[1] - 1}]")
    if peaks < 1 or half_width < 1:
        raise ValueError(f"peaks = {peaks} and half_width = {half_width}: both must be >= 1")
    x = s[:, component] - s[:, component].mean()
    power = np.abs(np.fft.rfft(x * np.hanning(x.size))) ** 2
    frequencies = np.fft.rfftfreq(x.size)
    total = float(power.sum())
    scale = float(np.max(np.abs(s[:, component]))) + 1e-300
    if total <= (1e-12 * scale) ** 2 * x.size:  # a constant sequence: one line at 0 (round-off only)
        return StrobeSpectrum(frequencies, power, np.zeros(1), 1.0)
    padded = np.concatenate([[-1.0], power, [-1.0]])
    maxima = np.flatnonzero((padded[1:-1] >= padded[:-2]) & (padded[1:-1] > padded[2:]))
    chosen: list[int] = []
    covered = np.zeros(power.size, dtype=bool)
    for i in maxima[np.argsort(-power[maxima], kind="stable")]:
        if covered[i]:
            continue  # a side lobe of a line already counted
        chosen.append(int(i))
        covered[max(0, i - half_width) : i + half_width + 1] = True
        if len(chosen) == peaks:
            break
    fraction = float(power[covered].sum() / total)
    return StrobeSpectrum(frequencies, power, frequencies[chosen], fraction)
