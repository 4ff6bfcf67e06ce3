"""Exact flow of a harmonically forced linear system, and guaranteed first-root search of its observables.

``y' = A y + Re(b exp(j w t)) + b0`` has the solution (:mod:`~vibroimpact.engines.exact_flows`)

    y(t) = Re(Y exp(j w t)) + y_c + Re(V diag(exp(lambda tau)) m) + z0 + q1 tau + q2 tau^2,   tau = t - t0,

with Y = (j w I - A)^-1 b, the exponentials on the nonzero eigenvalues and a polynomial of degree <= 2 on the
rigid-body modes (the generalized null space of A), so any linear observable ``h = c.y + d`` is a sum of complex
exponentials and a polynomial, whose derivatives of every order are explicit, and those of order >= 2 bounded over
[t, inf) (all Re(lambda) <= 0). :func:`first_crossing` uses a Taylor bound to step safely: from h(t) < 0 it jumps to
the first s at which ``h + h' s + sup|h''| s^2 / 2`` could reach 0, so no root is ever skipped, and it converges
quadratically onto the first root.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from vibroimpact.engines.exact_flows import Flow, decompose

__all__ = ["HarmonicLinearFlow", "Piece", "Observable", "first_crossing", "escape_step", "gauss_legendre"]


class HarmonicLinearFlow:
    """The exact flow of ``y' = A y + Re(b e^{jwt}) + b0``.

    Parameters
    ----------
    matrix : ndarray, shape (n, n)
        A [s-1]: eigenvalues with Re <= 0, the nonzero ones non-defective; Jordan blocks at 0 of size <= 2 (rigid-body
        modes, found from singular values).
    harmonic : ndarray of complex, shape (n,)
        b, complex amplitude of the harmonic forcing [state units s-1].
    constant : ndarray, shape (n,)
        b0, constant forcing [state units s-1].
    omega : float
        Forcing angular frequency [rad s-1].
    flow : Flow, optional
        A decomposition made already (:func:`.exact_flows.decompose`, or an engine's held flow); then the other
        arguments are not used and may be None.
    """

    def __init__(
        self, matrix: NDArray[np.float64] | None, harmonic: NDArray[np.complex128] | None, constant: NDArray[np.float64] | None, omega: float,
        flow: Flow | None = None,
    ) -> None:  # fmt: skip
        self.omega = float(omega)
        if flow is None:
            flow = decompose(np.asarray(matrix, dtype=float), np.asarray(harmonic, dtype=complex), np.asarray(constant, dtype=float), self.omega)
        self.flow = flow
        self.eigenvalues, self.vectors, self.inverse_vectors = flow.eigenvalues, flow.vectors, flow.inverse
        self.harmonic_response, self.constant_response = flow.harmonic, flow.constant

    @classmethod
    def from_flow(cls, flow: Flow) -> "HarmonicLinearFlow":
        """The flow of a ready decomposition."""
        return cls(None, None, None, flow.omega, flow)

    def particular(self, t: float | NDArray[np.float64]) -> NDArray[np.float64]:
        """Periodic particular solution at time(s) t, shape (..., n)."""
        return self.flow.particular(t)

    def start(self, t0: float, y0: NDArray[np.float64]) -> "Piece":
        """The solution through state ``y0`` at time ``t0``."""
        relative = np.asarray(y0, dtype=float) - self.particular(t0)
        modal = self.inverse_vectors @ relative.astype(complex)
        z0 = self.flow.projector @ relative
        q1 = self.flow.nilpotent @ z0 + self.flow.drift
        return Piece(self, float(t0), modal, z0, q1, self.flow.drift2)


@dataclass(frozen=True, eq=False)
class Piece:
    """One solution of a :class:`HarmonicLinearFlow`, from (t0, y0): modal coordinates and the polynomial part."""

    flow: HarmonicLinearFlow
    t0: float
    modal: NDArray[np.complex128]
    z0: NDArray[np.float64]
    q1: NDArray[np.float64]
    q2: NDArray[np.float64]

    def state(self, t: float | NDArray[np.float64]) -> NDArray[np.float64]:
        """State at time(s) t >= t0, shape (..., n)."""
        tau = np.asarray(t, dtype=float)[..., None] - self.t0
        growth = np.exp(self.flow.eigenvalues * tau)
        exponential = np.real((growth * self.modal) @ self.flow.vectors.T)
        return self.flow.particular(t) + exponential + self.z0 + (self.q1 + self.q2 * tau) * tau

    def observable(self, weights: NDArray[np.float64], offset: float = 0.0, extra: complex = 0j) -> "Observable":
        """h(t) = weights . y(t) + offset + Re(extra e^{jwt}) as a sum of exponentials and a polynomial.

        A real observable's terms come in complex-conjugate pairs; each pair is kept once, doubled (Re(a e^lt) +
        Re(conj) = 2 Re(a e^lt)), which halves the work of every evaluation.
        """
        w = np.asarray(weights, dtype=float)
        amplitudes = (w @ self.flow.vectors) * self.modal
        rates = self.flow.eigenvalues
        keep = rates.imag >= 0.0
        doubled = np.where(rates.imag > 0.0, 2.0, 1.0)
        return Observable(
            t0=self.t0,
            rates=tuple(complex(x) for x in rates[keep]),
            amplitudes=tuple(complex(x) for x in (amplitudes * doubled)[keep]),
            omega=self.flow.omega,
            harmonic=complex(w @ self.flow.harmonic_response) + complex(extra),
            constant=float(w @ self.flow.constant_response) + offset + float(w @ self.z0),
            p1=float(w @ self.q1),
            p2=float(w @ self.q2),
        )


@dataclass(frozen=True)
class Observable:
    """``h(t) = Re(sum_i a_i exp(l_i tau) + beta exp(j w t)) + gamma + p1 tau + p2 tau^2`` (tau = t - t0) with its
    derivatives and bounds."""

    t0: float
    rates: tuple[complex, ...]
    amplitudes: tuple[complex, ...]
    omega: float
    harmonic: complex
    constant: float
    p1: float = 0.0
    p2: float = 0.0

    def derivatives(self, t: float, orders: int) -> list[float]:
        """h(t), h'(t), ..., h^(orders-1)(t)."""
        terms = [a * cmath.exp(l * (t - self.t0)) for a, l in zip(self.amplitudes, self.rates)]
        forced = self.harmonic * cmath.exp(1j * self.omega * t)
        jw = 1j * self.omega
        tau = t - self.t0
        polynomial = ((self.p1 + self.p2 * tau) * tau, self.p1 + 2.0 * self.p2 * tau, 2.0 * self.p2)
        values = []
        for k in range(orders):
            total = sum(term * l**k for term, l in zip(terms, self.rates)) + forced * jw**k
            values.append(total.real + (self.constant if k == 0 else 0.0) + (polynomial[k] if k < 3 else 0.0))
        return values

    def step_data(self, t: float) -> tuple[float, float, float, float, float]:
        """h, h', h'' at t and bounds of |h''|, |h'''| over [t, inf), in one pass (the root search's inner loop)."""
        h0 = h1 = h2 = 0j
        w = self.omega
        magnitude = abs(self.harmonic)
        bound2, bound3 = magnitude * w * w, magnitude * w * w * w
        for a, l in zip(self.amplitudes, self.rates):
            term = a * cmath.exp(l * (t - self.t0))
            h0 += term
            h1 += term * l
            h2 += term * l * l
            size = abs(term) * (l.real * l.real + l.imag * l.imag)
            bound2 += size
            bound3 += size * abs(l)
        forced = self.harmonic * cmath.exp(1j * w * t)
        tau = t - self.t0
        return (
            (h0 + forced).real + self.constant + (self.p1 + self.p2 * tau) * tau,
            (h1 + forced * 1j * w).real + self.p1 + 2.0 * self.p2 * tau,
            (h2 - forced * w * w).real + 2.0 * self.p2,
            bound2 + 2.0 * abs(self.p2),
            bound3,
        )

    def round_off(self, t: float, tolerance: float) -> float:
        """How accurately h can be evaluated at t: ``tolerance``, or 1e-15 of its largest terms if that is more."""
        tau = t - self.t0
        polynomial = (abs(self.p1) + abs(self.p2) * tau) * tau
        return max(tolerance, 1e-15 * (sum(abs(a) for a in self.amplitudes) + abs(self.harmonic) + abs(self.constant) + polynomial))

    def bound(self, t: float, order: int) -> float:
        """An upper bound of |h^(order)| over [t, inf) for order >= 2; for orders 0 and 1, whose polynomial part
        grows, its size at t (a scale)."""
        total = abs(self.harmonic) * self.omega**order
        for a, l in zip(self.amplitudes, self.rates):
            total += abs(a) * abs(l) ** order * math.exp(l.real * (t - self.t0))
        tau = t - self.t0
        if order == 0:
            total += (abs(self.p1) + abs(self.p2) * tau) * tau
        elif order == 1:
            total += abs(self.p1) + 2.0 * abs(self.p2) * tau
        elif order == 2:
            total += 2.0 * abs(self.p2)
        return total


def first_crossing(h: Observable, t_from: float, t_to: float, tolerance: float, leaving: bool = False) -> float | None:
    """First time in (t_from, t_to] at which h reaches 0 from below, or ``None`` if h < 0 throughout.

    Parameters
    ----------
    h : Observable
        The function; h(t_from) <= 0 is required (a tiny positive round-off is treated as 0).
    t_from, t_to : float
        Search interval [s].
    tolerance : float
        Absolute accuracy of h at the returned root (units of h); the time is then polished by a Newton step.
    leaving : bool
        h(t_from) = 0 and the motion is leaving the surface (just after an impact or a release): the first step
        uses the first non-vanishing derivative of h, so that the start itself is not returned as a root.

    Notes
    -----
    Every step s keeps ``h(t) + h'(t) s + M s^2 / 2 < 0`` with M = sup |h''| on [t, inf), so h < 0 on the step and no
    root can be skipped, however tangent (grazing). Near a transversal root the steps converge quadratically.
    """
    # h cannot be evaluated more accurately than the round-off of its largest terms
    tau = t_from - h.t0
    polynomial = (abs(h.p1) + abs(h.p2) * tau) * tau
    tolerance = h.round_off(t_from, tolerance)
    t = t_from
    if leaving and h.derivatives(t, 1)[0] >= -tolerance:  # at the surface: the start must not count as a root
        step = escape_step(h, t, tolerance)
        if step is None:
            if h.bound(t, 0) - polynomial <= tolerance and abs(h.p1) + abs(h.p2) <= tolerance:
                return None  # h is zero from here on (at rest on the surface, no forcing): nothing crosses
            return t_from  # not leaving after all: the caller decides (contact or sticking)
        t += step
        if t >= t_to:
            return None
    departing = leaving
    while True:
        h0, h1, h2, curvature, jerk = h.step_data(t)
        if departing and h0 >= -8.0 * tolerance:
            # a slow departure from the surface stays within the round-off band of h for many escape steps (at rest
            # on the stop, a holding force of -2e-6 N against a 49 N force took ~1e3 of them): while h still goes
            # down it is not a root (returned as one, the caller applied a contact at zero speed and searched again,
            # ~1e-11 s further on, until the period's event budget ran out); clear of the band, the search goes on
            step = escape_step(h, t, tolerance)
            if step is not None:
                if t + step >= t_to:
                    return None
                if t + step == t:
                    return t
                t += step
                continue
        if h0 >= -tolerance:
            if h1 > 0.0:
                t = max(t + polish_step(h0, h1, h2), t_from)  # |h0| <= tolerance: onto the root of the local model
            return t
        departing = departing and h0 >= -8.0 * tolerance
        step = _quadratic_step(h0, h1, curvature)
        # a local bound is often much tighter: on [0, S], h'' <= h''(t) + S sup|h'''|; try S = twice the global step
        trial = 2.0 * step
        step = max(step, min(_quadratic_step(h0, h1, max(h2 + jerk * trial / 3.0, 0.0)), trial))
        if t + step >= t_to:
            # h < 0 on [t, t_to); a root exactly at t_to (an impact on a period boundary) is still a root
            return t_to if h.derivatives(t_to, 1)[0] >= -tolerance else None
        if t + step == t:  # converged to the resolution of the time axis
            return t
        t += step


def polish_step(h0: float, h1: float, h2: float) -> float:
    """The step onto the root of h0 + h1 s + h2 s^2 / 2 from a point within tolerance of it (h1 > 0).

    Newton's -h0 / h1 alone overshoots where the slope is tiny and the curvature is not (a slow departure from the
    stop, pushed back at once: h0 = -6e-19 m, h1 = 9e-12 m/s gave a step of 6.5e-8 s, past a root 1e-9 s away, and
    the flight went through the stop); the quadratic model's first root is nearer whenever h2 > 0.
    """
    newton = -h0 / h1
    if h0 < 0.0 and h2 > 0.0:
        return min(newton, _quadratic_step(h0, h1, h2))
    return newton


def _quadratic_step(h0: float, h1: float, curvature: float) -> float:
    """First s > 0 with h0 + h1 s + curvature s^2 / 2 = 0, for h0 < 0 (inf if there is none)."""
    if curvature <= 0.0 and h1 <= 0.0:
        return math.inf
    return 2.0 * -h0 / (h1 + math.sqrt(h1 * h1 - 2.0 * curvature * h0))


def escape_step(h: Observable, t: float, band: float | None = None) -> float | None:
    """A step over which h stays < 0 when h(t) = 0 and h leaves the surface; ``None`` if it does not leave.

    With derivatives h^(1) = ... = h^(k-1) = 0 and h^(k) < 0, ``h(t + s) <= h^(k) s^k / k! + M s^(k+1) / (k+1)!`` with
    M = sup |h^(k+1)|, negative for s < -(k + 1) h^(k) / M. Orders up to 4: an absorber at rest on the stop with zero
    holding force and an undamped spring (B2 = 0) leaves at the fourth order (h^(2) = H / M2 = 0, h^(3) = B2 X1^(2)
    / M2 = 0, h^(4) = K2 X1^(2) / M2); with three orders that start was neither leaving nor a contact, and the loop
    applied a touch at the same instant until its event budget ran out.

    Given ``band`` (the round-off of h), a rise that only touches the band is not a departure from it either: when
    h^(k) > 0 but h^(k+1) < 0 and h peaks within ``band`` of zero (:func:`tangency_step`), the step over the peak is
    returned. A holding force that touches zero once a period without turning negative (a ball at rest on a table
    vibrating at exactly Gamma = A w^2 / g = 1) is found within round-off of zero at a time within sqrt(round-off) of
    the touch, still falling at ~3e-8 of its scale: the stop let go there, the free flight went into it at once
    (its acceleration, -(1 + sin) g, never turns positive), and the stop, asked whether it pushed, answered from that
    fall that it did not: a touch without sticking, at the same instant, until the event budget ran out.
    """
    values = h.derivatives(t, 5)
    for k in range(1, 5):
        scale = h.bound(t, k)
        if values[k] < -1e-9 * scale:
            return -(k + 1) * values[k] / h.bound(t, k + 1)
        if values[k] > 1e-9 * scale:
            return None if band is None or k == 4 else tangency_step(values, k, h.bound(t, k + 2), band)
    return None


def tangency_step(values: list[float], k: int, bound: float, band: float) -> float | None:
    """The step over a rise of h that stays within ``band`` of zero, or ``None``.

    ``values`` are h, h', ..., h^(k+1) at t, the orders below k negligible, h^(k) > 0, and ``bound`` >= sup
    |h^(k+2)|. The model h^(k) s^k / k! + h^(k+1) s^(k+1) / (k+1)! (h^(k+1) < 0) peaks at s* = -k h^(k) / h^(k+1) at
    s*^k h^(k) / (k+1)! and is back to 0 at s0 = (k + 1) s* / k; on [0, s0] h is at most h(t) plus that peak, the
    neglected orders' sum |h^(j)| s0^j / j! and the remainder bound s0^(k+2) / (k+2)!: if that stays <= band, h
    never rises out of its round-off (a tangency, not a crossing) and s0 is returned.
    """
    if values[k + 1] >= 0.0:
        return None
    s0 = -(k + 1) * values[k] / values[k + 1]
    peak = values[0] + (k * s0 / (k + 1)) ** k * values[k] / math.factorial(k + 1)
    slack = bound * s0 ** (k + 2) / math.factorial(k + 2) + sum(abs(values[j]) * s0**j / math.factorial(j) for j in range(1, k))
    return s0 if peak + slack <= band else None


@lru_cache(maxsize=64)
def gauss_legendre(nodes: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Gauss-Legendre nodes and weights on [0, 1]."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    return (x + 1.0) / 2.0, w / 2.0
