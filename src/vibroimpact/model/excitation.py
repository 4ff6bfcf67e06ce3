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

from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.model.structure import require_finite, require_non_negative, require_positive

__all__ = ["HarmonicForce", "SweptSine", "load_weights", "static_load", "angular_frequency", "check_closed_form_inputs"]


def _vector(name: str, value: object) -> tuple[float, ...] | None:
    if value is None:
        return None
    try:
        array = np.array(value, dtype=float)
    except (TypeError, ValueError) as error:
        raise ValueError(f"{name}: expected a list of numbers (one per coordinate), got {value!r}") from error
    if array.ndim != 1 or array.size == 0 or not np.all(np.isfinite(array)):
        raise ValueError(f"{name}: expected a list of finite numbers (one per coordinate), got {value!r}")
    return tuple(float(v) for v in array)


def load_weights(weights: tuple[float, ...] | None, size: int, key: str = "excitation.on") -> NDArray[np.float64]:
    """The harmonic load's distribution over ``size`` coordinates: ``weights``, or e_1 (the primary mass) if None."""
    if weights is None:
        out = np.zeros(size)
        out[0] = 1.0
        return out
    if len(weights) != size:
        raise ValueError(f"{key}: expected {size} weights (one per coordinate), got {len(weights)}")
    return np.array(weights, dtype=float)


def static_load(static: tuple[float, ...] | None, size: int, key: str = "excitation.static") -> NDArray[np.float64]:
    """The constant force per coordinate [N] (zeros if None)."""
    if static is None:
        return np.zeros(size)
    if len(static) != size:
        raise ValueError(f"{key}: expected {size} forces (one per coordinate), got {len(static)}")
    return np.array(static, dtype=float)


@suggest_keywords
@dataclass(frozen=True)
class HarmonicForce:
    """A harmonic load q cos(2 pi f t + phase), distributed over the coordinates, plus an optional constant force.

    Parameters
    ----------
    amplitude : float
        q [N] (or, for ``base_motion``, the base displacement amplitude Y [m]), >= 0.
    frequency : float
        f [Hz], > 0.
    phase : float
        Phase at t = 0 [rad].
    weights : tuple of float, optional
        Distribution of the load over the coordinates (force per coordinate per unit q [-]); None: all of it on the
        first coordinate (the paper's primary mass).
    static : tuple of float, optional
        Constant force on each coordinate [N] (e.g. gravity, -m g); None: none.
    base_motion : bool
        The base moves as Y cos(2 pi f t + phase) and the coordinates are measured relative to it: the load is the
        inertial force M 1 Y w^2 cos(w t + phase) [N] (every coordinate is carried by the base).
    """

    amplitude: float = field(metadata={"units": "N"})
    frequency: float = field(metadata={"units": "Hz"})
    phase: float = field(default=0.0, metadata={"units": "rad"})
    weights: tuple[float, ...] | None = None
    static: tuple[float, ...] | None = field(default=None, metadata={"units": "N"})
    base_motion: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "amplitude", require_non_negative("amplitude", self.amplitude))
        object.__setattr__(self, "frequency", require_positive("frequency", self.frequency))  # a float, whatever number type came
        object.__setattr__(self, "phase", require_finite("phase", self.phase))
        object.__setattr__(self, "weights", _vector("excitation.on", self.weights))
        object.__setattr__(self, "static", _vector("excitation.static", self.static))
        if self.base_motion and self.weights is not None:
            raise ValueError("excitation: a base motion loads every coordinate through its mass; give no 'on' weights with it")

    def load_vector(self, mass_matrix: NDArray[np.float64]) -> NDArray[np.complex128]:
        """Complex amplitude of the harmonic load per coordinate [N]: the load is Re(F e^{jwt})."""
        size = mass_matrix.shape[0]
        phasor = complex(math.cos(self.phase), math.sin(self.phase))
        if self.base_motion:
            return mass_matrix @ np.ones(size) * self.amplitude * self.omega**2 * phasor
        return load_weights(self.weights, size) * self.amplitude * phasor

    def static_vector(self, size: int) -> NDArray[np.float64]:
        """Constant force per coordinate [N]."""
        return static_load(self.static, size)

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


@suggest_keywords
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
    weights : tuple of float, optional
        Distribution of the force over the coordinates (see :class:`HarmonicForce`); None: the first coordinate.
    static : tuple of float, optional
        Constant force per coordinate [N].
    """

    amplitude: float = field(metadata={"units": "N"})
    start_frequency: float = field(metadata={"units": "Hz"})
    stop_frequency: float = field(metadata={"units": "Hz"})
    rate: float = field(metadata={"units": "Hz s-1"})
    weights: tuple[float, ...] | None = None
    static: tuple[float, ...] | None = field(default=None, metadata={"units": "N"})

    def __post_init__(self) -> None:
        object.__setattr__(self, "weights", _vector("excitation.on", self.weights))
        object.__setattr__(self, "static", _vector("excitation.static", self.static))
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


def angular_frequency(frequency: ArrayLike | None, omega: ArrayLike | None, default: ArrayLike | None = None) -> ArrayLike:
    """The angular frequency [rad s-1] of a public call that takes ``frequency`` [Hz] or, under the name that says
    so, ``omega`` [rad s-1]: the one conversion between the package's public unit (Hz) and its internal one.

    Parameters
    ----------
    frequency : array_like or None
        f [Hz]: finite and > 0 (``ValueError`` naming the value otherwise).
    omega : array_like or None
        w [rad s-1], as given (the caller's own angular frequencies).
    default : array_like, optional
        w [rad s-1] where neither is given (a problem's own); ``TypeError`` when there is none.
    """
    if frequency is not None and omega is not None:
        raise TypeError("give frequency [Hz] or omega [rad s-1], not both")
    if frequency is not None:
        f = np.asarray(frequency, dtype=float)
        if f.size and not np.all(np.isfinite(f) & (f > 0.0)):
            bad = f[~(np.isfinite(f) & (f > 0.0))].ravel()[0]
            raise ValueError(f"frequency: {float(bad):g} Hz is out of range: allowed (0, inf) [Hz] (an angular frequency goes in omega= [rad s-1])")
        return 2.0 * np.pi * f
    if omega is not None:
        return omega
    if default is None:
        raise TypeError("a frequency is needed: give frequency [Hz] (or omega [rad s-1])")
    return default


def check_closed_form_inputs(clearance: ArrayLike | None, restitution: ArrayLike | None, amplitude: ArrayLike | None) -> None:
    """``ValueError`` naming the argument and its allowed range where a closed form's given inputs are out of range:
    clearance Delta finite [m], restitution R in [0, 1] [-], amplitude q finite [N] (None: not given, not checked)."""
    for name, value, ok, allowed in (
        ("clearance", clearance, np.isfinite, "finite [m]"),
        ("restitution", restitution, lambda r: (r >= 0.0) & (r <= 1.0), "[0, 1] [-]"),
        ("amplitude", amplitude, np.isfinite, "finite [N] (base motion: [m])"),
    ):
        if value is None:
            continue
        array = np.asarray(value, dtype=float)
        good = ok(array)
        if array.size and not np.all(good):
            raise ValueError(f"{name}: {float(array[~good].ravel()[0]):g} is out of range: allowed {allowed}")
