"""The Kelvin-Voigt bumper model of eq. 25 as the compliant engines integrate it: residuals, Jacobians and events.

The equations of motion are written as the residual ``y' - f(t, y)`` of the state (X1, u, X1', X2') with the gap
u = X2 - Delta, then the running integral of the bumper force (impulses), then quadratures: for ``integrate``, the
harmonic moments of :mod:`vibroimpact.engines.event_loop` when asked (their contact-force channel integrates the bumper force itself);
for ``sweep``, the Fourier integral of the bumper force against the sweep's own phase, integral of
F exp(-j theta) theta' dt (the force is a pulse far shorter than the output sampling: it cannot be summed from
samples). In contact the bumper force F = K u + B X2' acts on the absorber, outside it does not. Each mode has its
own IDA solver, residual, Jacobian ``cj I - df/dy`` and events, so every residual is smooth; the switches are events:

* free flight: the gap rising through zero, or within the bumper's reach (after a release with u > 0) the force it
  would exert rising through zero (onset, terminal), and the absorber's apex, X2' falling through zero
  (recorded only): an apex at u >= 0 is a grazing contact whose two gap crossings fell inside one step; the run goes
  back to that apex and the contact starts there;
* contact: -F rising through zero (release, terminal: eq. 25, the bumper never pulls), dF/dt falling through zero
  (largest force) and the absorber's jerk rising through zero (largest deceleration), both recorded only.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from vibroimpact.engines.event_loop import QUADRATURES, write_quadratures
from vibroimpact.model.excitation import SweptSine
from vibroimpact.model.problem import ImpactProblem

__all__ = ["MODE_CONTACT", "BumperModel", "absolute_tolerances"]

MODE_CONTACT = 2  # segment mode: absorber on the bumper


def absolute_tolerances(atol: float, omega_ref: float, m2: float, quadratures: str = "none") -> NDArray[np.float64]:
    """Per-component absolute tolerances of the compliant engine's state.

    ``atol`` [m] applies to X1 and u; the velocities get ``atol * omega_ref`` [m s-1], the force integral
    ``atol * omega_ref * m2`` [N s] (a momentum). Quadratures: the sweep's Fourier integrals of the force [N]
    ``atol * omega_ref**2 * m2``; the harmonic moments of the displacements [m s] ``atol / omega_ref``, of the force
    ``atol * m2`` [N s], of the squares [m2 s] ``1e-3 * atol / omega_ref`` (millimetre amplitudes).

    Parameters
    ----------
    atol : float
        Absolute tolerance of the displacements [m].
    omega_ref : float
        Angular frequency of the motion [rad s-1] (the excitation's, or the sweep's highest).
    m2 : float
        Absorber mass [kg].
    quadratures : {'none', 'sweep', 'moments'}
        The states after the force integral: none, the sweep's two Fourier integrals, or the eight moments.
    """
    v = atol * omega_ref
    tolerances = [atol, atol, v, v, v * m2]
    if quadratures == "sweep":
        tolerances += [v * omega_ref * m2] * 2
    elif quadratures == "moments":
        d = atol / omega_ref
        tolerances += [d, d, d, d, atol * m2, atol * m2, 1e-3 * d, 1e-3 * d]
    elif quadratures != "none":
        raise ValueError(f"quadratures = {quadratures!r} is not allowed: use 'none', 'sweep' or 'moments'")
    return np.array(tolerances)


class BumperModel:
    """Residuals, Jacobians and events of each mode, and the right-hand side, of the system with a bumper."""

    def __init__(self, problem: ImpactProblem, with_moments: bool) -> None:
        s, bumper = problem.system, problem.bumper
        sweep = problem.excitation if isinstance(problem.excitation, SweptSine) else None
        if with_moments and sweep is not None:
            raise ValueError("harmonic moments are for a harmonic force, not a sweep")
        self.problem, self.sweep = problem, sweep
        # (X1, u, X1', X2', integral of F), then 8 moments (integrate) or 2 Fourier integrals of F (sweep)
        self.quadratures = "sweep" if sweep is not None else "moments" if with_moments else "none"
        self.size = 5 + {"none": 0, "sweep": 2, "moments": QUADRATURES}[self.quadratures]
        self.k, self.b = bumper.stiffness(s.m2), bumper.damping(s.m2)
        #: [residual calls, step attempts (distinct residual times), last residual time]
        self.counter: list[float] = [0, 0, math.nan]
        if sweep is None:
            self._w0, self._half_alpha = problem.omega, 0.0
        else:  # theta(t) = t (w0 + pi alpha t), theta'(t) = w0 + 2 pi alpha t
            self._w0, self._half_alpha = 2.0 * math.pi * sweep.start_frequency, math.pi * sweep.alpha
        base = np.zeros((self.size, self.size))
        base[:4, :4] = s.state_matrix
        contact = base.copy()
        contact[3, 1] -= self.k / s.m2
        contact[3, 3] -= self.b / s.m2
        contact[4, 1] += self.k
        contact[4, 3] += self.b
        self._minus_jacobian = {False: -base, True: -contact}
        self._identity = np.eye(self.size)

    @property
    def rhs_calls(self) -> int:
        return int(self.counter[0])

    @property
    def steps(self) -> int:
        return int(self.counter[1])

    def external(self, t: float) -> float:
        """Force on the primary mass [N]."""
        p = self.problem
        if self.sweep is None:
            return p.amplitude * math.cos(p.omega * t + p.phase)
        return self.sweep.amplitude * math.sin(t * (self._w0 + self._half_alpha * t))

    def force(self, y: NDArray[np.float64]) -> float:
        """Bumper force on the absorber in contact mode, K u + B X2' [N] (may be negative: then it releases)."""
        return self.k * y[1] + self.b * y[3]

    def enters(self, t: float, y: NDArray[np.float64]) -> bool:
        """Does a run started in state y at time t begin in contact? At or beyond the bumper (u >= 0) with a force
        K u + B X2' > 0: yes; < 0: no. A force of exactly 0 (at rest on the bumper, as from rest with Delta = 0, or an
        elastic bumper touched at u = 0) is decided by the gap's first non-zero time derivative in free flight: the
        onset event cannot see a gap that is 0 at the start and then only rises, so a free start would go through
        the bumper. The derivatives follow y^(k+1) = A y^(k) + F^(k)(t) (a sweep's force is taken as harmonic at its
        instantaneous frequency and phase, exact to first order, which decides every start but a tie)."""
        if y[1] < 0.0:
            return False
        force = self.force(y)
        if force != 0.0:
            return force > 0.0
        s = self.problem.system
        if self.sweep is None:
            amplitude, omega, angle = self.problem.amplitude, self.problem.omega, self.problem.omega * t + self.problem.phase
        else:  # q sin(theta) = q cos(theta - pi / 2)
            amplitude, omega = self.sweep.amplitude, self._w0 + 2.0 * self._half_alpha * t
            angle = t * (self._w0 + self._half_alpha * t) - 0.5 * math.pi
        a = s.state_matrix
        size = float(np.abs(a).max())
        rate = np.array([y[0], y[1] + self.problem.clearance, y[2], y[3]], dtype=float)
        scale = float(np.abs(rate).max())
        for k in range(6):
            forcing = amplitude / s.m1 * (complex(0.0, omega) ** k * complex(math.cos(angle), math.sin(angle))).real
            rate = a @ rate + np.array([0.0, 0.0, forcing, 0.0])  # y^(k + 1)
            scale = size * scale + amplitude / s.m1 * omega**k
            if abs(rate[1]) > 1e-12 * scale:
                return bool(rate[1] > 0.0)
        return False

    def derivative(self, t: float, y: NDArray[np.float64], contact: bool) -> NDArray[np.float64]:
        """f(t, y) of the given mode (restarts, peaks, moments)."""
        s, delta = self.problem.system, self.problem.clearance
        x1, gap, v1, v2 = float(y[0]), float(y[1]), float(y[2]), float(y[3])
        spring = s.k2 * (x1 - gap - delta) + s.b2 * (v1 - v2)
        bumper = self.k * gap + self.b * v2 if contact else 0.0
        yp = np.zeros(self.size)
        yp[:5] = v1, v2, (self.external(t) - s.k1 * x1 - s.b1 * v1 - spring) / s.m1, (spring - bumper) / s.m2, bumper
        if self.quadratures == "moments":
            write_quadratures(yp, 5, t, self.problem.omega, x1, gap + delta, bumper)
        elif self.sweep is not None and contact:
            theta, rate = t * (self._w0 + self._half_alpha * t), self._w0 + 2.0 * self._half_alpha * t
            yp[5], yp[6] = bumper * math.cos(theta) * rate, bumper * math.sin(theta) * rate
        return yp

    def residual(self, contact: bool) -> Callable[..., None]:
        """The residual y' - f(t, y) of one mode, written for speed (it is called millions of times)."""
        s, delta, counter = self.problem.system, self.problem.clearance, self.counter
        if self.quadratures == "moments":

            def general(t: float, y: NDArray[np.float64], yp: NDArray[np.float64], res: NDArray[np.float64]) -> None:
                counter[0] += 1
                if t != counter[2]:
                    counter[1] += 1
                    counter[2] = t
                np.subtract(yp, self.derivative(t, y, contact), out=res)

            return general
        m1, m2, k1, k2, b1, b2, k, b = s.m1, s.m2, s.k1, s.k2, s.b1, s.b2, self.k, self.b
        sin, cos, swept = math.sin, math.cos, self.sweep is not None
        q = self.problem.amplitude
        w0, half_alpha, phase = self._w0, self._half_alpha, 0.0 if swept else self.problem.phase

        def residual(t: float, y: NDArray[np.float64], yp: NDArray[np.float64], res: NDArray[np.float64]) -> None:
            counter[0] += 1
            if t != counter[2]:
                counter[1] += 1
                counter[2] = t
            x1, u, v1, v2 = y[:4].tolist()
            d = yp.tolist()
            spring = k2 * (x1 - u - delta) + b2 * (v1 - v2)
            if swept:
                theta = t * (w0 + half_alpha * t)
                sine = sin(theta)
                external = q * sine
            else:
                external = q * cos(w0 * t + phase)
            bumper = k * u + b * v2 if contact else 0.0
            res[0] = d[0] - v1
            res[1] = d[1] - v2
            res[2] = d[2] - (external - k1 * x1 - b1 * v1 - spring) / m1
            res[3] = d[3] - (spring - bumper) / m2
            res[4] = d[4] - bumper
            if swept:
                if contact:
                    rate = bumper * (w0 + 2.0 * half_alpha * t)
                    res[5] = d[5] - rate * cos(theta)
                    res[6] = d[6] - rate * sine
                else:
                    res[5] = d[5]
                    res[6] = d[6]

        return residual

    def jacobian(self, contact: bool) -> Callable[..., None]:
        """d(res)/dy + cj d(res)/dy' = cj I - df/dy; exact but for the moment rows (their dependence on the state is
        left out, which only slows Newton's convergence on those rows, never the solution)."""
        minus, identity = self._minus_jacobian[contact], self._identity
        fourier = self.sweep is not None and contact
        k, b, w0, half_alpha = self.k, self.b, self._w0, self._half_alpha

        def jacobian(t: float, y: NDArray[np.float64], yp: NDArray[np.float64], res: NDArray[np.float64], cj: float, jj: NDArray[np.float64]) -> None:
            np.multiply(identity, cj, out=jj)
            jj += minus
            if fourier:  # rows of F cos(theta) theta' and F sin(theta) theta'
                theta, rate = t * (w0 + half_alpha * t), w0 + 2.0 * half_alpha * t
                c, s = math.cos(theta) * rate, math.sin(theta) * rate
                jj[5, 1], jj[5, 3], jj[6, 1], jj[6, 3] = -k * c, -b * c, -k * s, -b * s

        return jacobian

    def events(self, contact: bool) -> Callable[..., None]:
        """The event function of one mode, with its ``terminal`` and ``direction`` attributes.

        Free: [K u, or the force K u + B X2' within the bumper's reach (rising, terminal: onset), X2' (falling:
        apex)]. Contact: [-F (rising, terminal: release), dF/dt (falling: largest force), jerk of X2 (rising: largest
        deceleration)]. The rates use the y' that IDA passes
        (its interpolant's derivative): a root of a rate is located to the solution's accuracy, and the peak values
        are then evaluated from the state at the root, where an error in the time only enters to second order.
        """
        s = self.problem.system
        k, b, k2, b2, m2 = self.k, self.b, s.k2, s.b2, s.m2
        if contact:

            def contact_events(t: float, y: NDArray[np.float64], yp: NDArray[np.float64], out: NDArray[np.float64]) -> None:
                u, v1, v2, a1, a2 = y[1], y[2], y[3], yp[2], yp[3]
                rate = k * v2 + b * a2
                out[0] = -(k * u + b * v2)
                out[1] = rate
                out[2] = (k2 * (v1 - v2) + b2 * (a1 - a2) - rate) / m2

            contact_events.terminal = [True, False, False]  # type: ignore[attr-defined]
            contact_events.direction = [1, -1, 1]  # type: ignore[attr-defined]
            return contact_events

        def free_events(t: float, y: NDArray[np.float64], yp: NDArray[np.float64], out: NDArray[np.float64]) -> None:
            u = y[1]
            # onset: K u < 0 short of the bumper; within its reach (u >= 0, after a release that left the absorber
            # inside it, the dashpot having cancelled the spring) the force K u + B X2' it would exert: pushed back
            # in before it got out, the contact resumes when that force turns positive, not when u crosses 0 (it
            # does not). The two agree at u = 0 but for the dashpot's B X2' > 0 there: a rise through 0 either way.
            out[0] = k * u + b * y[3] if u >= 0.0 else k * u
            out[1] = y[3]

        free_events.terminal = [True, False]  # type: ignore[attr-defined]
        free_events.direction = [1, -1]  # type: ignore[attr-defined]
        return free_events
