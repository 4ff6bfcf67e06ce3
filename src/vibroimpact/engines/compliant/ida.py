"""Engine ``compliant``: the Kelvin-Voigt bumper of eq. 25 through SUNDIALS IDA (scikit-sundae).

The equations of motion are written as the residual ``y' - f(t, y)`` of the state (X1, u, X1', X2') with the gap
u = X2 - Delta, then the running integral of the bumper force (impulses), then quadratures: for ``integrate``, the
harmonic moments of :mod:`.event_loop` when asked (their contact-force channel integrates the bumper force itself);
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

How it runs, and why it is fast: between two mode switches the mode's solver runs in one ``IDA.solve`` call over
the output times (sweep samples or period boundaries) in that stretch (at most :data:`_OUTPUTS_PER_CALL`), so
SUNDIALS interpolates the outputs and locates the recorded roots without returning to Python; only the terminal
events (two per contact) return. Each switch re-initialises the new mode's solver with consistent y' = f(t, y) and a
first step sqrt(2 rtol) / (the mode's fastest angular frequency), a backward-Euler step of about the tolerance (the
step then grows as usual; SUNDIALS' own guess would depend on the distance to the next output; 0.03 to 30 times
this first step changed the step count by +-10 % without a trend: a restart costs ~15 steps of ramp-up to order 5
either way, of ~170 per period at 25 Hz with one contact). The event records
scikit-sundae keeps on an event function are cleared after every call, or each call would get slower (NOTES).
Measured on the paper's 300 s swept-sine test (rtol 1e-6, 2858 contacts, one process): 10 s with
:data:`SWEEP_SETTINGS`, 12 s with atol 1e-12; the earlier loop of one ``IDA.step`` per output and per root took
16 s with every record cleared and ~155 s as it was, its steps slowing down as the ``_yp`` records piled up.
Profiled, ~75 % of the time is inside ``IDA.solve`` outside the Python callbacks (SUNDIALS, and scikit-sundae
wrapping the arrays of every callback), the rest in the residual and event functions; there are ~1.1 residual
calls per step attempt (the model is linear and the Jacobian exact).

Tolerances: ``settings.rtol`` is the relative tolerance; ``settings.atol`` is the absolute tolerance of the
displacements [m], and the other components get the same tolerance in their own units (:func:`absolute_tolerances`).
With ``atol`` a small fraction of the motion's amplitude the error test no longer asks for a relative accuracy of
each component as it crosses zero. The paper's swept-sine test uses :data:`SWEEP_SETTINGS` (rtol 1e-6, atol 1e-10 m).

Each contact is recorded as an impact (onset time, entry speed, impulse = integral of F) with its peak force and
peak deceleration (``Trajectory.contact_peaks``). The restitution of ``ImpactProblem`` is not used: the bumper's
loss factor sets it (:func:`vibroimpact.contact.restitution_from_loss_factor`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from sksundae.ida import IDA

from vibroimpact.model.contact import KelvinVoigtBumper
from vibroimpact.model.excitation import SweptSine
from vibroimpact.model.system import TwoDofSystem
from vibroimpact.model.validation import require_positive
from vibroimpact.engines.base import MODE_FREE, ImpactProblem, Trajectory, TrajectoryBuilder
from vibroimpact.engines.settings import SWEEP_SETTINGS, EngineSettings
from vibroimpact.engines.event_loop import QUADRATURES, moment_row, write_quadratures
from vibroimpact.engines.sundae import clear_event_records

__all__ = ["SWEEP_SETTINGS", "CompliantEngine", "SweepRecord", "absolute_tolerances"]

MODE_CONTACT = 2  # segment mode: absorber on the bumper
_STATUS_ROOT = 2  # IDA_ROOT_RETURN
_STATUS_ILL_INPUT = -22  # IDA_ILL_INPUT (CV_ILL_INPUT): among others, "Root found at and very near t"
#: Settings for the paper's swept-sine test. Against rtol 1e-9 runs of the 15 -> 45 Hz sweep, atol 1e-10 m is as
#: close as 1e-12 m (the default) and ~15 % cheaper; 1e-9 m saves another ~5 % but drifts 5-10x farther after the
#: regime change near 39.5 Hz (``vibroimpact.sweep_cost`` and tests/test_compliant.py measure both).

#: Largest number of output times handled by one ``IDA.solve`` call (bounds its output arrays).
_OUTPUTS_PER_CALL = 2048
#: Mode switches in a row without any progress in time before the run is declared stuck.
_MAX_SWITCHES_IN_PLACE = 100


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


class _BumperModel:
    """Residuals, Jacobians and events of each mode, and the right-hand side, of the system with a bumper."""

    def __init__(self, problem: ImpactProblem, bumper: KelvinVoigtBumper, with_moments: bool, sweep: SweptSine | None = None) -> None:
        s = problem.system
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
        q = self.problem.amplitude if self.sweep is None else self.sweep.amplitude
        w0, half_alpha, phase = self._w0, self._half_alpha, self.problem.phase

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


@dataclass(frozen=True, eq=False)
class SweepRecord:
    """A swept-sine run, sampled uniformly in time.

    Attributes
    ----------
    sweep : SweptSine
        The excitation.
    time : ndarray
        Sample times [s].
    x1, x2 : ndarray
        Displacements [m].
    base_force : ndarray
        Force on the base: suspension K1 X1 + B1 X1' plus bumper [N].
    contact_force : ndarray
        Bumper force [N] (0 outside contact).
    trajectory : Trajectory
        Contacts: ``impact_times`` (onsets) [s], ``impact_velocities`` [m s-1], ``impulses`` [N s] and
        ``contact_peaks`` (c, 2) = [peak force N, peak deceleration m s-2], one row per completed contact (a contact
        still open at the end is counted in ``stats["contacts"]`` only); ``segments`` (free and contact); ``stats``:
        ``steps`` (step attempts), ``rhs_calls`` (residual or right-hand-side evaluations), ``contacts``, ``events``
        (roots handled), ``solver_calls``, ``grazing`` (contacts caught at an apex).
    contact_fourier : ndarray of complex
        Running integral of F exp(-j theta) theta' dt from t = 0 to each sample [N], integrated with the motion:
        its increase over a window of whole cycles, divided by pi times the cycles, is the bumper force's fundamental.
    """

    sweep: SweptSine
    time: NDArray[np.float64]
    x1: NDArray[np.float64]
    x2: NDArray[np.float64]
    base_force: NDArray[np.float64]
    contact_force: NDArray[np.float64]
    trajectory: Trajectory
    contact_fourier: NDArray[np.complex128]


class CompliantEngine:
    """IDA with a Kelvin-Voigt bumper (see module docstring).

    Parameters
    ----------
    bumper_frequency : float
        Apparent natural frequency Omega_b / 2 pi [Hz], > 0.
    bumper_loss_factor : float
        xi_b [-], >= 0.
    settings : EngineSettings
        rtol, atol (of the displacements [m]; scaled for the other components, see :func:`absolute_tolerances`) and
        max_step. :data:`SWEEP_SETTINGS` suits the paper's swept-sine test.
    """

    name = "compliant"

    def __init__(self, bumper_frequency: float, bumper_loss_factor: float, settings: EngineSettings = EngineSettings()) -> None:
        self.frequency, self.loss_factor, self.settings = bumper_frequency, bumper_loss_factor, settings
        KelvinVoigtBumper(0.0, bumper_frequency, bumper_loss_factor)  # validates both

    def integrate(self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float, periods: int, moments: bool = False) -> Trajectory:
        """Integrate ``periods`` whole periods from ``state`` (X1, X2, X1', X2') at ``t_start`` [s]."""
        if periods < 0:
            raise ValueError(f"periods = {periods} is out of range: allowed [0, inf)")
        model = _BumperModel(problem, KelvinVoigtBumper(problem.clearance, self.frequency, self.loss_factor), moments)
        rec = TrajectoryBuilder(problem, moments)
        run = _Run(self, model, rec, float(t_start), state, problem.omega)
        rec.strobe(run.t, run.physical())
        previous = run.y[5:].copy()

        def strobes(times: NDArray[np.float64], ys: NDArray[np.float64], contact: bool) -> None:
            nonlocal previous
            for t, y in zip(times, ys):
                if moments:
                    rec.add_moments(moment_row(y[5:] - previous))
                    previous = y[5:].copy()
                rec.strobe(float(t), np.array([y[0], y[1] + problem.clearance, y[2], y[3]]))

        run.run(np.asarray(t_start + problem.period * np.arange(1, periods + 1), dtype=np.float64), strobes)
        return rec.build(run.stats())

    def sweep(
        self,
        system: TwoDofSystem,
        clearance: float,
        sweep: SweptSine,
        sample_rate: float,
        state: NDArray[np.float64] | None = None,
        progress: Callable[[float], None] | None = None,
    ) -> SweepRecord:
        """Swept-sine test (the paper's Simulink run): q sin(theta(t)) from t = 0 to the sweep's end, sampled.

        Parameters
        ----------
        system : TwoDofSystem
            The linear system.
        clearance : float
            Delta [m].
        sweep : SweptSine
            The excitation.
        sample_rate : float
            Output samples per second [Hz] (IDA interpolates; the step is set by the tolerances).
        state : ndarray, optional
            (X1, X2, X1', X2') at t = 0; rest by default.
        progress : callable, optional
            Receives the simulated time reached [s] after each block of samples.
        """
        require_positive("sample_rate", sample_rate)
        problem = ImpactProblem(system, clearance, 0.5, sweep.amplitude, sweep.start_frequency)  # forcing from `sweep`
        model = _BumperModel(problem, KelvinVoigtBumper(clearance, self.frequency, self.loss_factor), False, sweep)
        rec = TrajectoryBuilder(problem, False)
        omega_ref = 2.0 * math.pi * max(sweep.start_frequency, sweep.stop_frequency)
        run = _Run(self, model, rec, 0.0, np.zeros(4) if state is None else state, omega_ref)
        times = np.arange(0.0, sweep.duration, 1.0 / sample_rate)
        out = np.empty((times.size, 7))  # X1, X2, X1', X2', F, Fourier integral (real, -imaginary)
        filled = 0

        def samples(t: NDArray[np.float64], ys: NDArray[np.float64], contact: bool) -> None:
            nonlocal filled
            block = out[filled : filled + t.size]
            block[:, :4] = ys[:, :4]
            block[:, 1] += clearance
            block[:, 4] = model.k * ys[:, 1] + model.b * ys[:, 3] if contact else 0.0
            block[:, 5:] = ys[:, 5:7]
            filled += t.size
            if progress is not None:
                progress(float(t[-1]))

        run.run(times, samples)
        if filled != times.size:
            raise RuntimeError(f"the sweep produced {filled} of {times.size} samples")
        rec.strobe(run.t, run.physical())
        base_force = system.k1 * out[:, 0] + system.b1 * out[:, 2] + out[:, 4]
        fourier = out[:, 5] - 1j * out[:, 6]
        return SweepRecord(sweep, times, out[:, 0], out[:, 1], base_force, out[:, 4], rec.build(run.stats()), fourier)

    def solve(self, solver: Any, tspan: NDArray[np.float64], y0: NDArray[np.float64], yp0: NDArray[np.float64]) -> Any:
        """One solver call over ``tspan`` from a consistent (y0, y0')."""
        return solver.solve(tspan, y0, yp0)

    def first_step(self, model: _BumperModel, contact: bool, omega_ref: float) -> float:
        """First step after a (re)start [s]: sqrt(2 rtol) / (the mode's fastest angular frequency), a backward-Euler
        step of about the tolerance (h^2 |y''| / 2 ~ rtol |y|)."""
        s = model.problem.system
        natural = float(np.abs(np.linalg.eigvals(s.state_matrix)).max())
        fastest = max(math.sqrt(natural**2 + (model.k / s.m2 if contact else 0.0)), omega_ref)
        return math.sqrt(2.0 * self.settings.rtol) / fastest

    def _solver(self, model: _BumperModel, contact: bool, omega_ref: float) -> tuple[IDA, Any]:
        """The IDA solver of one mode and its event function."""
        events = model.events(contact)
        s = model.problem.system
        first = self.first_step(model, contact, omega_ref)
        options: dict[str, Any] = {
            "rtol": self.settings.rtol,
            "atol": absolute_tolerances(self.settings.atol, omega_ref, s.m2, model.quadratures),
            "max_num_steps": 1_000_000,
            "eventsfn": events,
            "num_events": 3 if contact else 2,  # see events()
            "jacfn": model.jacobian(contact),
            "first_step": first,
        }
        if self.settings.max_step > 0.0:
            options["max_step"] = self.settings.max_step
            options["first_step"] = min(first, self.settings.max_step)
        return IDA(model.residual(contact), **options), events


class _Run:
    """One integration: the state, one IDA solver per mode, and what happens at each switch and recorded root."""

    def __init__(self, engine: CompliantEngine, model: _BumperModel, rec: TrajectoryBuilder, t: float, state: NDArray[np.float64], omega_ref: float) -> None:
        self.engine, self.model, self.rec = engine, model, rec
        self.clearance = model.problem.clearance
        self.t = t
        self.y = np.zeros(model.size)
        self.y[:4] = np.asarray(state, dtype=float)
        self.y[1] -= self.clearance
        self.contact = model.enters(t, self.y)
        self.solvers = {mode: engine._solver(model, mode, omega_ref) for mode in (False, True)}
        self.counts = {"events": 0, "contacts": 0, "solver_calls": 0, "grazing": 0}
        self.onset, self.peak_force, self.peak_deceleration = (t, 0.0, 0.0), 0.0, 0.0
        if self.contact:
            self._begin_contact()
        self.rec.segment(self.t, MODE_CONTACT if self.contact else MODE_FREE, self.physical())

    def physical(self) -> NDArray[np.float64]:
        """(X1, X2, X1', X2') now."""
        return np.array([self.y[0], self.y[1] + self.clearance, self.y[2], self.y[3]])

    def stats(self) -> dict[str, int]:
        return self.counts | {"steps": self.model.steps, "rhs_calls": self.model.rhs_calls}

    def run(self, outputs: NDArray[np.float64], emit: Callable[[NDArray[np.float64], NDArray[np.float64], bool], None]) -> None:
        """Integrate to ``outputs[-1]``, handing the states at the increasing ``outputs`` (all after or at the
        current time) to ``emit(times, states, contact)`` in order, in blocks of one mode."""
        n, i, in_place, last_switch = outputs.size, 0, 0, math.nan
        while i < n:
            j, close = i, 16.0 * np.finfo(float).eps * max(1.0, abs(self.t))  # IDA refuses a first output closer than ~4 eps t
            while j < n and outputs[j] <= self.t + close:  # outputs at the current time: the current state
                j += 1
            if j > i:
                emit(outputs[i:j], np.broadcast_to(self.y, (j - i, self.y.size)), self.contact)
                i = j
                continue
            j = min(n, i + _OUTPUTS_PER_CALL)
            tspan = np.concatenate(([self.t], outputs[i:j]))
            midpoint = tspan.size == 2  # IDA.solve interpolates at given times only with three or more
            if midpoint:
                tspan = np.array([self.t, 0.5 * (self.t + outputs[i]), outputs[i]])
            solver, events = self.solvers[self.contact]
            self.counts["solver_calls"] += 1
            result = self.engine.solve(solver, tspan, self.y, self.model.derivative(self.t, self.y, self.contact))
            close_roots = self._close_roots(result)
            if result.status < 0 and not close_roots:
                raise RuntimeError(f"IDA failed at t = {float(result.t[-1])!r} s: {result.message}")
            times, states = result.t[1:], result.y[1:]
            stopped = result.status == _STATUS_ROOT  # on a terminal event: the last row is the root
            # on close roots the last row is the recorded root where the solver stopped: the run goes on from there
            rows, end_t, end_y = times.size - 1 if stopped or close_roots else times.size, float(times[-1]), states[-1]
            records = (result.i_events, result.t_events, result.y_events)
            clear_event_records(events)
            if records[0] is not None:
                rows, end_t, end_y, stopped = self._roots(records, times, rows, end_t, end_y, stopped)
            first = 1 if midpoint else 0
            if rows > first:
                emit(times[first:rows], states[first:rows], self.contact)
                i += rows - first
            if close_roots:
                in_place = in_place + 1 if end_t == last_switch else 0
                if in_place > _MAX_SWITCHES_IN_PLACE:
                    raise RuntimeError(f"IDA stops at close roots over and over at t = {end_t!r} s: {result.message}")
                last_switch = end_t
            self.t, self.y = end_t, np.array(end_y)
            if stopped:
                in_place = in_place + 1 if self.t == last_switch else 0
                if in_place > _MAX_SWITCHES_IN_PLACE:
                    raise RuntimeError(f"the contact switches mode over and over at t = {self.t!r} s")
                last_switch = self.t
                self._switch()

    def _close_roots(self, result: Any) -> bool:
        """The solver refused to go on from a recorded root because an event function is exactly 0 there and just
        after it ("Root found at and very near t", IDA_ILL_INPUT): in a long contact (the absorber pressed on the
        bumper) the deceleration's extremum event (jerk) hovers at round-off zero. Its last output row is that root,
        consistent; a restart from it is safe, since at a start SUNDIALS ignores a function that stays 0 until it
        moves. Any other failure is an error."""
        if result.status != _STATUS_ILL_INPUT or result.t_events is None or len(result.t_events) == 0:
            return False
        end = float(result.t[-1])
        return end > self.t and end == float(result.t_events[-1])

    def _roots(self, records: tuple[Any, Any, Any], times: NDArray[np.float64], rows: int, end_t: float, end_y: NDArray[np.float64], stopped: bool) -> tuple[int, float, NDArray[np.float64], bool]:
        """Handle the roots recorded in one solver call; return the output rows to keep and where the run goes on
        (a grazing contact cuts the call short at its apex)."""
        model = self.model
        for flags, t_root, y_root in zip(*records):
            if stopped and t_root == end_t and flags[0] != 0:
                break  # the terminal event: the caller switches mode
            self.counts["events"] += 1
            if self.contact:  # a largest force or deceleration
                self.peak_force = max(self.peak_force, model.force(y_root))
                self.peak_deceleration = max(self.peak_deceleration, -model.derivative(float(t_root), y_root, True)[3])
            elif y_root[1] >= 0.0:  # an apex at or beyond the bumper: a grazing contact the onset event missed
                self.counts["grazing"] += 1
                return int(np.searchsorted(times[:rows], t_root, side="right")), float(t_root), y_root, True
        return rows, end_t, end_y, stopped

    def _begin_contact(self) -> None:
        """Onset (time, entry speed, impulse integral) and the force and deceleration at first touch."""
        self.counts["contacts"] += 1
        self.onset = (self.t, float(self.y[3]), float(self.y[4]))
        self.peak_force = self.model.force(self.y)
        self.peak_deceleration = max(-self.model.derivative(self.t, self.y, True)[3], 0.0)

    def _switch(self) -> None:
        """Onset (or grazing apex) in flight, release in contact: change mode at the current state."""
        self.counts["events"] += 1
        if self.contact:  # release: the bumper would pull
            self.rec.contact_peaks(self.peak_force, self.peak_deceleration)
            self.rec.impact(self.onset[0], self.onset[1], float(self.y[4]) - self.onset[2], in_moments=False)
            self.contact = False
        else:
            self.contact = True
            self.y[1] = max(self.y[1], 0.0)
            self._begin_contact()
        self.rec.segment(self.t, MODE_CONTACT if self.contact else MODE_FREE, self.physical())
