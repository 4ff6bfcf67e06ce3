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
from numpy.typing import ArrayLike

from vibroimpact.analysis.regime import Regime
from vibroimpact.model.validation import require_in_range, require_positive
from vibroimpact.orbits.lyapunov import LyapunovEstimate, lyapunov_from_jacobians
from vibroimpact.orbits.spectrum import rotation_number, strobe_spectrum

__all__ = ["MOTION_KINDS", "MotionThresholds", "MotionEvidence", "classify_motion", "classify_strobes"]

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
