"""Steady-state response of the linear system (no stop, Delta -> infinity) and its resonance peaks."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import minimize_scalar

from vibroimpact.model.system import TwoDofSystem

__all__ = ["LinearResponse", "linear_response", "ResonancePeak", "resonance_peaks"]


@dataclass(frozen=True, eq=False)
class LinearResponse:
    """Complex amplitudes of the linear steady state under the force q cos(w t).

    Attributes
    ----------
    x1, x2 : ndarray of complex
        Displacement amplitudes of the primary mass and the absorber [m].
    force : ndarray of complex
        Force transmitted to the base through the suspension, (K1 + j w B1) X1 [N].
    """

    x1: NDArray[np.complex128]
    x2: NDArray[np.complex128]
    force: NDArray[np.complex128]


def linear_response(system: TwoDofSystem, omega: ArrayLike, amplitude: float) -> LinearResponse:
    """Linear steady-state amplitudes at angular frequencies ``omega`` [rad s-1] for force amplitude q [N]."""
    w = np.asarray(omega, dtype=float)
    h = system.receptances(w)
    x1 = amplitude * h.h11
    return LinearResponse(x1=x1, x2=amplitude * h.h12, force=(system.k1 + 1j * w * system.b1) * x1)


@dataclass(frozen=True)
class ResonancePeak:
    """Maximum of a linear amplitude near one natural frequency.

    Attributes
    ----------
    mode : int
        1 or 2.
    frequency : float
        Frequency of the maximum [Hz].
    value : float
        Peak amplitude (units of the quantity: [m] or [N]).
    """

    mode: int
    frequency: float
    value: float


def resonance_peaks(system: TwoDofSystem, amplitude: float, quantity: str = "x1", span: float = 0.05) -> list[ResonancePeak]:
    """Maxima of a linear amplitude near each natural frequency, by analytic maximisation (not from a grid).

    Parameters
    ----------
    system : TwoDofSystem
        The linear system.
    amplitude : float
        Force amplitude q [N].
    quantity : {'x1', 'x2', 'force'}
        Which amplitude.
    span : float
        Relative half-width of the search window around each undamped natural frequency [-].
    """
    if quantity not in ("x1", "x2", "force"):
        raise ValueError(f"quantity must be 'x1', 'x2' or 'force', got {quantity!r}")

    def magnitude(w: ArrayLike) -> NDArray[np.float64]:
        return np.abs(getattr(linear_response(system, w, amplitude), quantity))

    peaks = []
    for mode, omega_n in enumerate(system.natural_frequencies(), start=1):
        grid = omega_n * np.linspace(1.0 - span, 1.0 + span, 4001)
        k = int(np.argmax(magnitude(grid)))
        lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
        best = minimize_scalar(lambda w: -float(magnitude(w)), bounds=(lo, hi), method="bounded", options={"xatol": 1e-10 * omega_n})
        peaks.append(ResonancePeak(mode=mode, frequency=float(best.x) / (2.0 * np.pi), value=float(-best.fun)))
    return peaks
