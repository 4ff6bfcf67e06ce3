"""Published closed forms the validation scenes compare the project's numbers with, and what follows from them.

* Budd & Dux, Phil. Trans. R. Soc. A 347 (1994) 365: the undamped impact oscillator x'' + x = cos(w t), x <= sigma,
  x' -> -r x' at x = sigma. A period-one orbit (one impact per period T = 2 pi / w) with impact velocity V > 0 has

      (sigma + c V / 2)^2 + ((1 - r) V / (2 w))^2 = gamma^2,   gamma = 1 / (1 - w^2),   c = (1 + r) sin T / (1 - cos T),

  and its impact phase phi = w t0 has gamma cos(phi) = sigma + c V / 2, gamma sin(phi) = -(1 - r) V / (2 w)
  (derived in :func:`budd_dux_phase`). Its multipliers are those of the impact map (t_n, V_n) -> (t_n+1, V_n+1),
  linearised here: det J = r^2 and tr J = (1 + r) sin T a / V - 2 r cos T, with a = x''(t0-) = cos(phi) - sigma
  the acceleration at impact; the period doubling (1 + tr J + det J = 0) is where
  (1 + r) sin T a / V = -(1 + r^2 - 2 r cos T), which with the ellipse gives sigma and V in closed form
  (:func:`budd_dux_period_doubling`).
* The bouncing ball on a table moving as A sin(w t) (Holmes, J. Sound Vib. 84 (1982) 173), Gamma = A w^2 / g: the
  period-one orbit (one bounce per table period) exists from Gamma cos(theta) = pi (1 - e) / (1 + e) (theta the
  table's phase at impact), i.e. from Gamma = pi (1 - e) / (1 + e), for the exact table motion and for Holmes'
  high-bounce map alike. Its stability differs: linearising the *exact* impact map (the table's displacement kept)
  gives det J = e^2, tr J = 1 + e^2 - (1 + e)^2 Gamma sin(theta), so the period doubling is at
  Gamma sin(theta) = 2 (1 + e^2) / (1 + e)^2 and Gamma_pd = sqrt((pi (1 - e)/(1 + e))^2 + (2 (1 + e^2)/(1 + e)^2)^2),
  the formula of issue 12. Holmes' map (impacts at the table's mean position, its velocity kept) has det J = e,
  tr J = 1 + e - 2 (1 + e) Gamma sin(theta), and doubles at Gamma sin(theta) = 1: Gamma_pd = sqrt((pi (1 - e)/(1 +
  e))^2 + 1) (:func:`ball_period_doubling_high_bounce`); the two agree at e = 1 only.
* The Zeno time of a ball dropped from rest at height h on a fixed table: sqrt(2 h / g) (1 + e) / (1 - e). An engine
  sticks the ball at the first impact no faster than its sticking velocity v_s; it then misses the rest of the
  geometric series, 2 e v_n / (g (1 - e)) with v_n in (e v_s, v_s]: :func:`zeno_sticking_deficit`.
* The grazing boundary of x'' + c x' + k x = A cos(w t) (mass m) with a stop at d: the linear amplitude
  A / |k - m w^2 + j c w| reaches d at A = d sqrt((k - m w^2)^2 + (c w)^2).

Everything is in the units of the scene (SI, or Budd & Dux's dimensionless time and length).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike, NDArray

__all__ = ["budd_dux_constants", "budd_dux_residual", "budd_dux_velocities", "budd_dux_phase", "budd_dux_state", "budd_dux_multipliers", "budd_dux_period_doubling", "ball_existence", "ball_period_doubling", "ball_period_doubling_high_bounce", "ball_phase", "ball_multipliers", "ball_state", "zeno_time", "zeno_sticking_deficit", "zeno_sticking_bounds", "grazing_amplitude", "multipliers_of", "Check", "CaseOutcome", "PASSED_MEANINGS", "check", "outcome_dataset"]

# ------------------------------------------------------------------------------------------------ Budd & Dux
def budd_dux_constants(w: float, r: float) -> tuple[float, float, float]:
    """(gamma, c, T) of Budd & Dux's ellipse for forcing frequency ``w`` [-] (natural frequency 1) and restitution r."""
    period = 2.0 * math.pi / w
    return 1.0 / (1.0 - w * w), (1.0 + r) * math.sin(period) / (1.0 - math.cos(period)), period


def budd_dux_residual(sigma: ArrayLike, velocity: ArrayLike, w: float, r: float) -> NDArray[np.float64]:
    """((sigma + c V / 2)^2 + ((1 - r) V / (2 w))^2) / gamma^2 - 1 [-]: zero on Budd & Dux's ellipse."""
    gamma, c, _ = budd_dux_constants(w, r)
    s, v = np.asarray(sigma, dtype=float), np.asarray(velocity, dtype=float)
    return ((s + 0.5 * c * v) ** 2 + ((1.0 - r) * v / (2.0 * w)) ** 2) / gamma**2 - 1.0


def budd_dux_velocities(sigma: ArrayLike, w: float, r: float) -> NDArray[np.float64]:
    """Both roots V of the ellipse at each ``sigma``, shape sigma.shape + (2,), smaller first (NaN: none)."""
    gamma, c, _ = budd_dux_constants(w, r)
    s = np.asarray(sigma, dtype=float)
    a = 0.25 * c * c + ((1.0 - r) / (2.0 * w)) ** 2
    b = s * c
    cc = s * s - gamma * gamma
    disc = b * b - 4.0 * a * cc
    with np.errstate(invalid="ignore"):
        root = np.sqrt(disc)
        # the root free of cancellation, then the other from the product of the roots
        q = -0.5 * (b + np.copysign(root, b))
        first = np.where(q != 0.0, q / a, 0.0)
        second = np.where(q != 0.0, cc / np.where(q != 0.0, q, 1.0), 0.0)
    roots = np.stack([np.minimum(first, second), np.maximum(first, second)], axis=-1)
    return np.where((disc >= 0.0)[..., None], roots, np.nan)


def budd_dux_phase(sigma: float, velocity: float, w: float, r: float) -> float:
    """The forcing phase phi = w t0 of the impact of the orbit (sigma, V), in (-pi, pi] [rad].

    Between impacts x = gamma cos(w t) + a cos(t - t0) + b sin(t - t0); x(t0) = sigma, x'(t0+) = -r V and the same
    state one period later give gamma w sin(phi) = -(1 - r) V / 2 and gamma cos(phi) = sigma + c V / 2.
    """
    gamma, c, _ = budd_dux_constants(w, r)
    return math.atan2(-(1.0 - r) * velocity / (2.0 * w * gamma), (sigma + 0.5 * c * velocity) / gamma)


def budd_dux_state(sigma: float, velocity: float, w: float, r: float, t: float) -> NDArray[np.float64]:
    """(x, x') at time ``t`` of the period-one orbit (sigma, V) (just after the impact at t = t0 mod T)."""
    gamma, c, period = budd_dux_constants(w, r)
    phi = budd_dux_phase(sigma, velocity, w, r)
    t0 = phi / w
    tau = (t - t0) % period
    a = sigma - gamma * math.cos(phi)
    b = -r * velocity + gamma * w * math.sin(phi)
    x = gamma * math.cos(w * t) + a * math.cos(tau) + b * math.sin(tau)
    v = -gamma * w * math.sin(w * t) - a * math.sin(tau) + b * math.cos(tau)
    return np.array([x, v])


def multipliers_of(trace: float, determinant: float) -> NDArray[np.complex128]:
    """Eigenvalues of a 2 x 2 matrix from its trace and determinant, the larger modulus first."""
    disc = complex(trace * trace - 4.0 * determinant)
    root = disc**0.5
    pair = np.array([0.5 * (trace + root), 0.5 * (trace - root)])
    return pair[np.argsort(-np.abs(pair), kind="stable")]


def budd_dux_multipliers(sigma: float, velocity: float, w: float, r: float) -> NDArray[np.complex128]:
    """Floquet multipliers of the period-one orbit (sigma, V): tr = (1 + r) sin T a / V - 2 r cos T, det = r^2,
    with a = cos(phi) - sigma the acceleration just before the impact (module docstring)."""
    _, _, period = budd_dux_constants(w, r)
    phi = budd_dux_phase(sigma, velocity, w, r)
    acceleration = math.cos(phi) - sigma
    trace = (1.0 + r) * math.sin(period) * acceleration / velocity - 2.0 * r * math.cos(period)
    return multipliers_of(trace, r * r)


def budd_dux_period_doubling(w: float, r: float) -> tuple[float, float]:
    """(sigma, V) where the period-one orbit has a multiplier -1.

    With a = cos(phi) - sigma = c V (1 - w^2) / 2 - w^2 sigma (from the ellipse's phase), the condition
    (1 + r) sin T a / V = -(1 + r^2 - 2 r cos T) makes sigma = kappa V, kappa = (c (1 - w^2) / 2 + D / ((1 + r) sin T))
    / w^2 with D = 1 + r^2 - 2 r cos T; the ellipse then gives V = |gamma| / sqrt((kappa + c/2)^2 + ((1 - r)/(2 w))^2).
    """
    gamma, c, period = budd_dux_constants(w, r)
    d = 1.0 + r * r - 2.0 * r * math.cos(period)
    kappa = (0.5 * c * (1.0 - w * w) + d / ((1.0 + r) * math.sin(period))) / (w * w)
    velocity = abs(gamma) / math.hypot(kappa + 0.5 * c, (1.0 - r) / (2.0 * w))
    return kappa * velocity, velocity


# ------------------------------------------------------------------------------------------------ bouncing ball
def ball_existence(e: float) -> float:
    """Gamma = A w^2 / g from which the period-one orbit exists: pi (1 - e) / (1 + e) [-]."""
    return math.pi * (1.0 - e) / (1.0 + e)


def ball_period_doubling(e: float) -> float:
    """Gamma of the period doubling of the period-one orbit, exact table motion (module docstring) [-]."""
    return math.hypot(ball_existence(e), 2.0 * (1.0 + e * e) / (1.0 + e) ** 2)


def ball_period_doubling_high_bounce(e: float) -> float:
    """The same in Holmes' high-bounce map (impacts at the table's mean position): Gamma sin(theta) = 1 [-]."""
    return math.hypot(ball_existence(e), 1.0)


def ball_phase(gamma: float, e: float, stable_side: bool = True) -> float:
    """Table phase theta of the period-one orbit's impact (table at A sin(theta)) [rad]: Gamma cos(theta) =
    pi (1 - e) / (1 + e), sin(theta) > 0 on the node's side (the orbit that is stable up to the doubling)."""
    cosine = ball_existence(e) / gamma
    if not -1.0 <= cosine <= 1.0:
        return math.nan
    theta = math.acos(cosine)
    return theta if stable_side else -theta


def ball_multipliers(gamma: float, e: float, stable_side: bool = True) -> NDArray[np.complex128]:
    """Multipliers of the exact map's period-one orbit: tr = 1 + e^2 - (1 + e)^2 Gamma sin(theta), det = e^2."""
    theta = ball_phase(gamma, e, stable_side)
    return multipliers_of(1.0 + e * e - (1.0 + e) ** 2 * gamma * math.sin(theta), e * e)


def ball_state(gamma: float, e: float, g: float, omega: float, t: float, stable_side: bool = True) -> NDArray[np.float64]:
    """(z, z') of the period-one orbit at time ``t`` [s], z the ball's height above the table [m].

    The table moves as A sin(w t), A = Gamma g / w^2; the ball leaves the table at t0 = theta / w (mod T) with the
    absolute velocity g T / 2 and lands one period later.
    """
    period = 2.0 * math.pi / omega
    theta = ball_phase(gamma, e, stable_side)
    amplitude = gamma * g / omega**2
    t0 = theta / omega
    tau = (t - t0) % period
    table, table_rate = amplitude * math.sin(omega * t), amplitude * omega * math.cos(omega * t)
    height = amplitude * math.sin(theta) + 0.5 * g * period * tau - 0.5 * g * tau * tau
    rate = 0.5 * g * period - g * tau
    return np.array([height - table, rate - table_rate])


# ------------------------------------------------------------------------------------------------ Zeno
def zeno_time(height: float, g: float, e: float) -> float:
    """Time for a ball dropped from rest at ``height`` [m] on a fixed table to come to rest: sqrt(2 h / g) (1 + e) /
    (1 - e) [s]."""
    return math.sqrt(2.0 * height / g) * (1.0 + e) / (1.0 - e)


def zeno_sticking_deficit(height: float, g: float, e: float, sticking_velocity: float) -> float:
    """Zeno time minus the time of the impact at which an engine with sticking velocity v_s sticks the ball [s].

    Impact n (n >= 1) arrives at v_n = e^(n-1) sqrt(2 g h); the engine sticks at the first v_n <= v_s, and the
    flights it leaves out last 2 e v_n / (g (1 - e)) in all.
    """
    velocity = math.sqrt(2.0 * g * height)
    while velocity > sticking_velocity:
        velocity *= e
    return 2.0 * e * velocity / (g * (1.0 - e))


def zeno_sticking_bounds(e: float, g: float, sticking_velocity: float) -> tuple[float, float]:
    """(low, high] of the deficit whatever the height: v_n lies in (e v_s, v_s], so 2 e v_n / (g (1 - e)) lies in
    (2 e^2 v_s / (g (1 - e)), 2 e v_s / (g (1 - e))] [s]."""
    scale = 2.0 * e * sticking_velocity / (g * (1.0 - e))
    return e * scale, scale


# ------------------------------------------------------------------------------------------------ grazing
def grazing_amplitude(clearance: float, mass: float, stiffness: float, damping: float, omega: float) -> float:
    """Force amplitude A [N] at which the linear steady state of m x'' + c x' + k x = A cos(w t) reaches x = d:
    d sqrt((k - m w^2)^2 + (c w)^2)."""
    return clearance * math.hypot(stiffness - mass * omega * omega, damping * omega)


# --------------------------------------------------------------------------------------------------------------------
# The record of a validation: one row per compared quantity, and the dataset a validation scene writes.
# --------------------------------------------------------------------------------------------------------------------

#: Meanings of the ``passed`` flag, in order of its values 0, 1, 2.
PASSED_MEANINGS = ("failed", "passed", "informative")


@dataclass(frozen=True)
class Check:
    """One compared quantity.

    Attributes
    ----------
    quantity : str
        What is compared (a short phrase; the page's first column).
    published : float
        The closed form's value (in ``unit``).
    computed : float
        The project's value.
    relative_error : float
        |computed - published| / |published| unless the row defines its own measure (e.g. a residual) [-].
    tolerance : float
        Largest relative error that passes [-]; NaN: an informative row, not a check.
    unit : str
        Unit of ``published`` and ``computed`` (CF string; ``1`` for dimensionless).
    note : str
        Where the tolerance comes from, or what the row means.
    """

    quantity: str
    published: float
    computed: float
    relative_error: float
    tolerance: float
    unit: str = "1"
    note: str = ""

    @property
    def informative(self) -> bool:
        """Is the row shown beside the checks without being one?"""
        return math.isnan(self.tolerance)

    @property
    def passed(self) -> bool:
        """The relative error is finite and within the tolerance (False for an informative row)."""
        return not self.informative and math.isfinite(self.relative_error) and self.relative_error <= self.tolerance

    @property
    def flag(self) -> int:
        """0 failed, 1 passed, 2 informative (:data:`PASSED_MEANINGS`)."""
        return 2 if self.informative else int(self.passed)


def check(quantity: str, published: float, computed: float, tolerance: float, unit: str = "1", note: str = "", error: float | None = None) -> Check:
    """A :class:`Check` whose relative error is |computed - published| / |published| unless ``error`` is given."""
    if error is None:
        error = abs(computed - published) / abs(published) if published != 0.0 else abs(computed)
    return Check(quantity, float(published), float(computed), float(error), float(tolerance), unit, note)


@dataclass(frozen=True, eq=False)
class CaseOutcome:
    """What a validation case found: its rows and the variables of its figure.

    Attributes
    ----------
    case : str
        The case's name.
    checks : tuple of Check
        The rows of the table.
    data : xarray.Dataset
        The case's own variables (the figure's data), with units and long names.
    notes : tuple of str
        Sentences for the page (conventions, approximations, what was run).
    """

    case: str
    checks: tuple[Check, ...]
    data: xr.Dataset = field(default_factory=xr.Dataset)
    notes: tuple[str, ...] = ()

    @property
    def passed(self) -> bool:
        """Every check (not the informative rows) passed."""
        return all(c.passed for c in self.checks if not c.informative)


def outcome_dataset(outcome: CaseOutcome, attrs: dict[str, object]) -> xr.Dataset:
    """The dataset of a validation (module docstring), with ``attrs`` added."""
    rows = outcome.checks
    index = np.arange(len(rows), dtype=np.int32)
    table = xr.Dataset(
        {
            "quantity": ("check", np.array([c.quantity for c in rows], dtype=str), {"long_name": "compared quantity"}),
            "unit": ("check", np.array([c.unit for c in rows], dtype=str), {"long_name": "unit of published and computed (CF)"}),
            "note": ("check", np.array([c.note for c in rows], dtype=str), {"long_name": "where the tolerance comes from, or what the row means"}),
            "published": ("check", np.array([c.published for c in rows], dtype=float), {"long_name": "value of the published closed form (unit: variable 'unit')", "units": "1"}),
            "computed": ("check", np.array([c.computed for c in rows], dtype=float), {"long_name": "value computed by the project's engines and continuation (unit: variable 'unit')", "units": "1"}),
            "relative_error": ("check", np.array([c.relative_error for c in rows], dtype=float), {"long_name": "relative error of computed against published", "units": "1"}),
            "tolerance": ("check", np.array([c.tolerance for c in rows], dtype=float), {"long_name": "largest relative error that passes (NaN: informative row)", "units": "1"}),
            "passed": ("check", np.array([c.flag for c in rows], dtype=np.int8), {
                "long_name": "whether the check passed", "units": "1",
                "flag_values": np.arange(len(PASSED_MEANINGS), dtype=np.int8), "flag_meanings": " ".join(PASSED_MEANINGS)}),
        },  # fmt: skip
        coords={"check": ("check", index, {"long_name": "index of the compared quantity", "units": "1"})},
    )
    merged = xr.merge([table, outcome.data], combine_attrs="override")  # each variable keeps its own attributes
    merged.attrs = dict(outcome.data.attrs)
    merged.attrs.update(attrs)
    merged.attrs["validation_case"] = outcome.case
    merged.attrs["validation_passed"] = np.int8(outcome.passed)
    merged.attrs["validation_notes"] = "\n".join(outcome.notes)
    return merged
