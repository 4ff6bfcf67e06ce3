"""Fundamental harmonics and RMS over whole periods, from a trajectory's per-period moments.

Over N whole periods of length T the complex fundamental amplitude of a signal x(t) is
``(2 / (N T)) * integral x(t) exp(-j w t) dt`` (|.| is the amplitude of its cos(w t + phi) component), and its RMS is
``sqrt(integral x^2 dt / (N T))``. Engines accumulate the integrals exactly per period (Gauss-Legendre on each smooth
segment for ``exact``, quadrature states for the integrators), impulses included as their exact Fourier terms.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .engines.base import Trajectory

__all__ = ["HarmonicMeasures", "measure"]


@dataclass(frozen=True)
class HarmonicMeasures:
    """Steady-state quantities measured over whole periods.

    Attributes
    ----------
    x1, x2 : complex
        Fundamental-harmonic complex amplitudes of X1 and X2 [m] (phase relative to cos(w t)).
    suspension_force : complex
        Fundamental of K1 X1 + B1 X1' [N], taken as (K1 + j w B1) times the X1 fundamental.
    contact_force : complex
        Fundamental of the force of the stop on the base: impulses plus the holding force while stuck [N].
    x1_rms, x2_rms : float
        RMS of X1 and X2 [m].
    impacts_per_period : float
        Impacts per period [-].
    mean_impulse : float
        Mean impulse per impact [N s]; 0 if there was none. With chattering it depends on how many impacts were
        resolved before sticking (``EngineSettings.sticking_velocity``): prefer ``impulse_per_period``.
    impulse_per_period : float
        Total impulse of the impacts per period [N s]: the impact impulse for one impact per period; with
        chattering, the converged sum of the sequence (the unresolved rest is negligible).
    periods : int
        Whole periods measured.
    """

    x1: complex
    x2: complex
    suspension_force: complex
    contact_force: complex
    x1_rms: float
    x2_rms: float
    impacts_per_period: float
    mean_impulse: float
    impulse_per_period: float
    periods: int

    @property
    def force(self) -> complex:
        """Fundamental of the total force on the base (suspension plus stop) [N]."""
        return self.suspension_force + self.contact_force


def measure(trajectory: Trajectory) -> HarmonicMeasures:
    """Fundamental harmonics, RMS and impact statistics over all periods of ``trajectory`` (needs its moments)."""
    periods = trajectory.periods
    if periods == 0 or trajectory.moments.shape[0] != periods:
        raise ValueError("measure() needs a trajectory of at least one period integrated with moments=True")
    problem = trajectory.problem
    window = periods * problem.period
    total = trajectory.moments.sum(axis=0)
    x1 = complex(2.0 * total[0] / window)
    impacts = trajectory.impulses.size
    return HarmonicMeasures(
        x1=x1,
        x2=complex(2.0 * total[1] / window),
        suspension_force=(problem.system.k1 + 1j * problem.omega * problem.system.b1) * x1,
        contact_force=complex(2.0 * total[2] / window),
        x1_rms=math.sqrt(max(total[3].real, 0.0) / window),
        x2_rms=math.sqrt(max(total[4].real, 0.0) / window),
        impacts_per_period=impacts / periods,
        mean_impulse=float(np.mean(trajectory.impulses)) if impacts else 0.0,
        impulse_per_period=float(np.sum(trajectory.impulses)) / periods,
        periods=periods,
    )
