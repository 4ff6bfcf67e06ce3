"""Excitations: the harmonic force, and the linear swept sine of the paper's Simulink test (section 5).

The swept sine is q sin(theta(t)) with theta(t) = 2 pi (f0 t + alpha t^2 / 2), whose instantaneous frequency is
theta'(t) / 2 pi = f0 + alpha t. The paper writes sin(w(t) t) with w(t) = 2 pi alpha t; taken literally that is
sin(2 pi alpha t^2), whose instantaneous frequency is 2 alpha t: twice the intended one. What is implemented here is
the sweep the paper means: frequency rising (or falling, alpha < 0) by alpha Hz every second.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from vibroimpact.model.validation import require_non_negative, require_positive

__all__ = ["HarmonicForce", "SweptSine"]


@dataclass(frozen=True)
class HarmonicForce:
    """q cos(2 pi f t + phase) [N] on the primary mass."""

    amplitude: float = field(metadata={"units": "N"})
    frequency: float = field(metadata={"units": "Hz"})
    phase: float = field(default=0.0, metadata={"units": "rad"})

    def __post_init__(self) -> None:
        require_non_negative("amplitude", self.amplitude)
        require_positive("frequency", self.frequency)

    @property
    def omega(self) -> float:
        """Angular frequency w = 2 pi f [rad s-1]."""
        return 2.0 * math.pi * self.frequency

    @property
    def period(self) -> float:
        """T = 1 / f [s]."""
        return 1.0 / self.frequency

    def force(self, t: ArrayLike) -> NDArray[np.float64]:
        """Force at time(s) t [s] -> [N]."""
        return self.amplitude * np.cos(self.omega * np.asarray(t, dtype=float) + self.phase)


@dataclass(frozen=True)
class SweptSine:
    """Linear swept sine q sin(theta(t)), instantaneous frequency f0 + alpha t from t = 0 to ``duration``.

    Parameters
    ----------
    amplitude : float
        q [N], >= 0.
    start_frequency : float
        f0 [Hz], > 0.
    stop_frequency : float
        Frequency at the end [Hz], > 0 (below ``start_frequency`` for a sweep down).
    rate : float
        |alpha| [Hz s-1], > 0; the sign follows the direction of the sweep.
    """

    amplitude: float = field(metadata={"units": "N"})
    start_frequency: float = field(metadata={"units": "Hz"})
    stop_frequency: float = field(metadata={"units": "Hz"})
    rate: float = field(metadata={"units": "Hz s-1"})

    def __post_init__(self) -> None:
        require_non_negative("amplitude", self.amplitude)
        require_positive("start_frequency", self.start_frequency)
        require_positive("stop_frequency", self.stop_frequency)
        require_positive("rate", self.rate)
        if self.start_frequency == self.stop_frequency:
            raise ValueError(f"stop_frequency = {self.stop_frequency!r} must differ from start_frequency")

    @property
    def alpha(self) -> float:
        """Signed sweep rate [Hz s-1]: positive up, negative down."""
        return math.copysign(self.rate, self.stop_frequency - self.start_frequency)

    @property
    def duration(self) -> float:
        """Time to sweep from start to stop [s]."""
        return abs(self.stop_frequency - self.start_frequency) / self.rate

    def frequency(self, t: ArrayLike) -> NDArray[np.float64]:
        """Instantaneous frequency f0 + alpha t [Hz]."""
        return self.start_frequency + self.alpha * np.asarray(t, dtype=float)

    def phase(self, t: ArrayLike) -> NDArray[np.float64]:
        """theta(t) = 2 pi (f0 t + alpha t^2 / 2) [rad]."""
        tt = np.asarray(t, dtype=float)
        return 2.0 * math.pi * (self.start_frequency * tt + 0.5 * self.alpha * tt * tt)

    def time_at_phase(self, theta: ArrayLike) -> NDArray[np.float64]:
        """Inverse of :meth:`phase`: the time [s] at which theta(t) = ``theta`` [rad] (NaN past a sweep down's turn).

        t = 2 p / (f0 + sqrt(f0^2 + 2 alpha p)) with p = theta / 2 pi: the root that is free of cancellation.
        """
        cycles = np.asarray(theta, dtype=float) / (2.0 * math.pi)
        discriminant = self.start_frequency**2 + 2.0 * self.alpha * cycles
        with np.errstate(invalid="ignore"):
            return np.where(discriminant >= 0.0, 2.0 * cycles / (self.start_frequency + np.sqrt(np.maximum(discriminant, 0.0))), np.nan)

    def force(self, t: ArrayLike) -> NDArray[np.float64]:
        """q sin(theta(t)) [N]."""
        return self.amplitude * np.sin(self.phase(t))
