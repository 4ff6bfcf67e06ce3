"""What a non-periodic steady motion is: quasi-periodic, chaotic, or undecided, from its Lyapunov exponent, its
rotation number and the spectrum of its strobes.

Decision (thresholds in :class:`MotionThresholds`, exponent lambda and its standard error sigma in 1/period):

* ``chaotic``: lambda > ``chaotic_exponent`` and lambda > ``margin`` sigma: the exponent is positive beyond its error.
* ``quasi_periodic``: |lambda| <= ``zero_band`` and sigma <= ``zero_band`` (the exponent is known to be near 0), and
  the strobes show two-frequency order: a line spectrum (line fraction >= ``line_fraction``) or a regular rotation
  (the angle around the centroid advances as a circle map's: :func:`.spectrum.rotation_number`).
* ``irregular`` otherwise: the evidence does not decide (an exponent near 0 with broadband strobes; an exponent
  positive but within its error; a clearly negative exponent, i.e. a contraction onto a periodic orbit that
  marching has not reached yet; too few periods).

Without an exponent (an engine without Jacobians and no two-trajectory estimate), the strobes alone decide only clear
cases: ``quasi_periodic`` when the spectrum is a line spectrum *and* the rotation is regular, ``chaotic`` when the
spectrum is broadband (line fraction < ``broadband_fraction``) *and* the rotation is not regular, ``irregular``
otherwise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from vibroimpact.analysis.stability import Regime
from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.model.structure import require_in_range, require_positive
from vibroimpact.orbits.lyapunov import LyapunovEstimate, lyapunov_from_jacobians

__all__ = ["RotationEstimate", "StrobeSpectrum", "rotation_number", "strobe_spectrum", "MOTION_KINDS", "MotionThresholds", "MotionEvidence", "classify_motion", "classify_strobes"]


# --------------------------------------------------------------------------------------------------------------------
# What a sequence of stroboscopic states says about the motion: its rotation number and its spectral lines.
# --------------------------------------------------------------------------------------------------------------------

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

#: The kinds of non-periodic motion :func:`classify_motion` tells apart.
MOTION_KINDS = ("quasi_periodic", "chaotic", "irregular")


@dataclass(frozen=True)
class MotionThresholds:
    """Thresholds of the classification (module docstring).

    Parameters
    ----------
    chaotic_exponent : float
        Smallest exponent called chaotic [1/period]: 0.01 means a separation grows e-fold in 100 periods.
    margin : float
        The exponent must also exceed this many standard errors [-].
    zero_band : float
        |exponent| and its error at most this for "zero" [1/period]. On an invariant circle the tangent growth is
        bounded, so the estimate over n periods is O(1/n): 0.01 needs a few hundred periods.
    line_fraction : float
        Spectral power fraction in the largest lines above which the strobe spectrum is a line spectrum [-].
    broadband_fraction : float
        Fraction below which it is broadband [-] (strobes-only decision).
    order_fraction : float
        Fraction of points keeping their cyclic order above which the rotation is regular [-].
    min_periods : int
        Fewer strobes (or Jacobians) than this: ``irregular`` whatever they show.
    """

    chaotic_exponent: float = 0.01
    margin: float = 3.0
    zero_band: float = 0.01
    line_fraction: float = 0.9
    broadband_fraction: float = 0.5
    order_fraction: float = 0.98
    min_periods: int = 64

    def __post_init__(self) -> None:
        require_positive("chaotic_exponent", self.chaotic_exponent)
        require_in_range("margin", self.margin, 0.0, 100.0)
        require_positive("zero_band", self.zero_band)
        require_in_range("line_fraction", self.line_fraction, 0.0, 1.0)
        require_in_range("broadband_fraction", self.broadband_fraction, 0.0, self.line_fraction)
        require_in_range("order_fraction", self.order_fraction, 0.0, 1.0)
        require_in_range("min_periods", self.min_periods, 16, 1e9)


@dataclass(frozen=True)
class MotionEvidence:
    """The kind of a non-periodic motion and the evidence for it.

    Attributes
    ----------
    kind : str
        One of :data:`MOTION_KINDS`.
    lyapunov_exponent : float
        Largest Lyapunov exponent of the stroboscopic map [1/period]; NaN when not estimated.
    lyapunov_error : float
        Its standard error [1/period]; NaN when not estimated.
    rotation_number : float
        Rotation number of the strobes around their centroid [cycles/period] in [0, 1/2]; meaningful only when
        ``rotation_regular``.
    rotation_regular : bool
        The angle advances as a circle map's (cyclic order kept for >= ``order_fraction`` of the points).
    order_fraction : float
        That fraction [-].
    spectral_line_fraction : float
        Power fraction of the strobes' X1 spectrum in its largest lines [-].
    peak_frequencies : tuple of float
        Those lines [cycles/period], strongest first.
    periods : int
        Strobes analysed.
    method : str
        ``"jacobians"`` (exponent from the exact Jacobians), ``"estimate"`` (an exponent given, e.g. from two
        trajectories) or ``"strobes"`` (no exponent).
    reason : str
        One sentence: why this kind.
    """

    kind: str
    lyapunov_exponent: float
    lyapunov_error: float
    rotation_number: float
    rotation_regular: bool
    order_fraction: float
    spectral_line_fraction: float
    peak_frequencies: tuple[float, ...]
    periods: int
    method: str
    reason: str

    def __post_init__(self) -> None:
        if self.kind not in MOTION_KINDS:
            raise ValueError(f"kind = {self.kind!r} is not allowed: use one of {MOTION_KINDS}")

    @property
    def regime(self) -> Regime:
        """The ``regime`` flag of this kind: ``QUASI_PERIODIC``, ``CHAOTIC`` or ``IRREGULAR``."""
        return {"quasi_periodic": Regime.QUASI_PERIODIC, "chaotic": Regime.CHAOTIC}.get(self.kind, Regime.IRREGULAR)


@suggest_keywords
def classify_motion(jacobians: ArrayLike, strobes: ArrayLike, thresholds: MotionThresholds = MotionThresholds(), transient: int | None = None) -> MotionEvidence:
    """Classify a non-periodic motion from its exact per-period Jacobians and its strobes.

    Parameters
    ----------
    jacobians : array_like, shape (n, 4, 4)
        d y_{k+1} / d y_k of the stroboscopic map along the motion (``Trajectory.strobe_jacobians``).
    strobes : array_like, shape (n + 1, 4) or (n, 4)
        The stroboscopic states of the same run (``Trajectory.strobe_states``), on the attractor.
    thresholds : MotionThresholds
        Decision thresholds.
    transient : int, optional
        Jacobians discarded while the tangent vector aligns (default n // 10).

    Returns
    -------
    MotionEvidence
    """
    estimate = lyapunov_from_jacobians(jacobians, transient=transient)
    return _decide(strobes, estimate, "jacobians", thresholds)


def classify_strobes(strobes: ArrayLike, lyapunov: LyapunovEstimate | None = None, thresholds: MotionThresholds = MotionThresholds()) -> MotionEvidence:
    """Classify a non-periodic motion from its strobes, with an exponent when one was estimated.

    For engines without Jacobians: pass the estimate of
    :func:`vibroimpact.orbits.lyapunov.lyapunov_two_trajectories` when it was run, else the strobes alone decide
    the clear cases (module docstring).

    Parameters
    ----------
    strobes : array_like, shape (n, 4)
        Stroboscopic states on the attractor.
    lyapunov : LyapunovEstimate, optional
        The largest exponent and its error.
    thresholds : MotionThresholds
        Decision thresholds.

    Returns
    -------
    MotionEvidence
    """
    return _decide(strobes, lyapunov, "estimate" if lyapunov is not None else "strobes", thresholds)


def _decide(strobes: ArrayLike, estimate: LyapunovEstimate | None, method: str, th: MotionThresholds) -> MotionEvidence:
    s = np.asarray(strobes, dtype=float)
    rotation = rotation_number(s, th.order_fraction)
    spectrum = strobe_spectrum(s)
    exponent = estimate.exponent if estimate is not None else math.nan
    error = estimate.error if estimate is not None else math.nan
    lines = spectrum.line_fraction >= th.line_fraction
    ordered = lines or rotation.regular
    counted = min(s.shape[0], estimate.periods) if estimate is not None else s.shape[0]
    if counted < th.min_periods:
        kind, reason = "irregular", f"{counted} periods are fewer than the {th.min_periods} needed"
    elif estimate is not None:
        if exponent > th.chaotic_exponent and exponent > th.margin * error:
            kind, reason = "chaotic", f"exponent {exponent:.4g} > {th.chaotic_exponent:g} and > {th.margin:g} x its error {error:.2g}"
        elif abs(exponent) <= th.zero_band and error <= th.zero_band and ordered:
            what = "a line spectrum" if lines else "a regular rotation"
            kind, reason = "quasi_periodic", f"exponent {exponent:.2g} +- {error:.2g} within {th.zero_band:g} of 0 and {what}"
        elif exponent < -th.zero_band:
            kind, reason = "irregular", f"exponent {exponent:.4g} < 0: contracting, a periodic orbit not yet reached"
        else:
            kind, reason = "irregular", f"exponent {exponent:.2g} +- {error:.2g}, line fraction {spectrum.line_fraction:.2f}, order {rotation.order_fraction:.2f}: undecided"
    elif lines and rotation.regular:
        kind, reason = "quasi_periodic", f"line spectrum ({spectrum.line_fraction:.3f}) and a regular rotation ({rotation.order_fraction:.3f})"
    elif spectrum.line_fraction < th.broadband_fraction and not rotation.regular:
        kind, reason = "chaotic", f"broadband spectrum ({spectrum.line_fraction:.3f}) and no regular rotation ({rotation.order_fraction:.3f})"
    else:
        kind, reason = "irregular", f"line fraction {spectrum.line_fraction:.2f}, order {rotation.order_fraction:.2f}: undecided without an exponent"
    return MotionEvidence(
        kind=kind,
        lyapunov_exponent=exponent,
        lyapunov_error=error,
        rotation_number=rotation.rotation_number,
        rotation_regular=rotation.regular,
        order_fraction=rotation.order_fraction,
        spectral_line_fraction=spectrum.line_fraction,
        peak_frequencies=tuple(float(f) for f in spectrum.peak_frequencies),
        periods=int(s.shape[0]),
        method=method,
        reason=reason,
    )
