"""Engine ``compliant``: the Kelvin-Voigt bumper of eq. 25 through SUNDIALS IDA (scikit-sundae).

The equations of motion are written as the residual ``y' - f(t, y)`` of the state (X1, u, X1', X2') with the gap
u = X2 - Delta, then the running integral of the bumper force (impulses), then the harmonic-moment quadratures of
:mod:`.event_loop` (whose contact-force channel integrates the bumper force itself). A contact-mode flag keeps the residual smooth: in contact the bumper force
F = K u + B X2' acts on the absorber, outside it does not, and the switches are events:

* onset, free flight: the gap rising through zero (an apex event, X2' falling through zero, guards grazing contacts
  as in ``momentary``);
* release, in contact: F falling through zero (eq. 25: the bumper never pulls);
* peaks, in contact: dF/dt falling through zero (largest force) and the absorber's jerk rising through zero (largest
  deceleration); they are recorded and integration goes on.

Each mode switch re-initialises IDA with consistent y' = f(t, y). A Jacobian callback returns the mode's constant
``cj I - df/dy``. Each contact is recorded as an impact (onset time, entry speed, impulse = integral of F) with its
peak force and deceleration. The restitution of ``ImpactProblem`` is not used: the bumper's loss factor sets it
(:func:`vibroimpact.contact.restitution_from_loss_factor`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
from numpy.typing import NDArray
from sksundae.ida import IDA

from ..contact import KelvinVoigtBumper
from ..excitation import SweptSine
from ..system import TwoDofSystem
from .base import MODE_FREE, EngineSettings, ImpactProblem, Trajectory, TrajectoryBuilder
from ..validation import require_positive
from .sundae import clear_event_records
from .event_loop import QUADRATURES, moment_row, write_quadratures

__all__ = ["CompliantEngine", "SweepRecord"]

MODE_CONTACT = 2  # segment mode: absorber on the bumper
_STATUS_TSTOP, _STATUS_ROOT = 1, 2


class _BumperModel:
    """Right-hand side, residual, Jacobian and events of the system with a Kelvin-Voigt bumper."""

    def __init__(self, problem: ImpactProblem, bumper: KelvinVoigtBumper, with_moments: bool, sweep: SweptSine | None = None) -> None:
        s = problem.system
        self.problem, self.with_moments, self.sweep = problem, with_moments, sweep
        self.size = 5 + (QUADRATURES if with_moments else 0)  # (X1, u, X1', X2', integral of F) + moments
        self.contact = False
        self.rhs_calls = 0
        self.k, self.b = bumper.stiffness(s.m2), bumper.damping(s.m2)
        self._buffer = np.empty(self.size)  # reused by the residual and the events: no allocation per call
        if sweep is None:
            q, w, phase = problem.amplitude, problem.omega, problem.phase
            self._external: Callable[[float], float] = lambda t: q * math.cos(w * t + phase)
        else:
            q, f0, half_alpha = sweep.amplitude, sweep.start_frequency, 0.5 * sweep.alpha
            self._external = lambda t: q * math.sin(2.0 * math.pi * t * (f0 + half_alpha * t))
        self._c = (s.m1, s.m2, s.k1, s.k2, s.b1, s.b2, problem.amplitude, problem.omega, problem.phase, problem.clearance)
        base = np.zeros((self.size, self.size))
        base[:4, :4] = s.state_matrix
        self._jacobian = {False: base, True: base.copy()}
        self._jacobian[True][3, 1] -= self.k / s.m2
        self._jacobian[True][3, 3] -= self.b / s.m2
        self._jacobian[True][4, 1] += self.k
        self._jacobian[True][4, 3] += self.b

    def force(self, y: NDArray[np.float64]) -> float:
        """Bumper force on the absorber in contact mode, K u + B X2' [N] (may be negative: then it releases)."""
        return self.k * y[1] + self.b * y[3]

    def rhs(self, t: float, y: NDArray[np.float64], yp: NDArray[np.float64]) -> None:
        self.rhs_calls += 1
        m1, m2, k1, k2, b1, b2, q, w, phase, delta = self._c
        x1, gap, v1, v2 = y[0], y[1], y[2], y[3]
        spring = k2 * (x1 - gap - delta) + b2 * (v1 - v2)
        bumper = self.k * gap + self.b * v2 if self.contact else 0.0
        yp[0] = v1
        yp[1] = v2
        yp[2] = (self._external(t) - k1 * x1 - b1 * v1 - spring) / m1
        yp[3] = (spring - bumper) / m2
        yp[4] = bumper
        if self.with_moments:
            write_quadratures(yp, 5, t, w, x1, gap + delta, bumper)

    def derivative(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        yp = np.empty(self.size)
        self.rhs(t, y, yp)
        return yp

    def residual(self, t: float, y: NDArray[np.float64], yp: NDArray[np.float64], res: NDArray[np.float64]) -> None:
        self.rhs(t, y, self._buffer)
        np.subtract(yp, self._buffer, out=res)

    def jacobian(self, t: float, y: NDArray[np.float64], yp: NDArray[np.float64], res: NDArray[np.float64], cj: float, jj: NDArray[np.float64]) -> None:
        """d(res)/dy + cj d(res)/dy' = cj I - df/dy (quadrature rows: their dependence on the state is left out,
        which only slows Newton's convergence on those rows, never the solution)."""
        jj[:, :] = -self._jacobian[self.contact]
        jj[np.diag_indices(self.size)] += cj

    def events(self, t: float, y: NDArray[np.float64], yp: NDArray[np.float64], out: NDArray[np.float64]) -> None:
        """[gap (rising), force (falling), apex X2' (falling), dF/dt (falling), jerk of X2 (rising)]."""
        if self.contact:
            f = self._buffer
            self.rhs(t, y, f)
            force_rate = self.k * y[3] + self.b * f[3]
            s = self.problem.system
            jerk = (s.k2 * (y[2] - y[3]) + s.b2 * (f[2] - f[3]) - force_rate) / s.m2
            out[0], out[1], out[2], out[3], out[4] = -1.0, self.force(y), 1.0, force_rate, jerk
        else:
            out[0], out[1], out[2], out[3], out[4] = y[1], 1.0, y[3], 1.0, -1.0


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
        Contacts (onset times, entry speeds, impulses, peaks) and segments.
    """

    sweep: SweptSine
    time: NDArray[np.float64]
    x1: NDArray[np.float64]
    x2: NDArray[np.float64]
    base_force: NDArray[np.float64]
    contact_force: NDArray[np.float64]
    trajectory: Trajectory


class CompliantEngine:
    """IDA with a Kelvin-Voigt bumper (see module docstring).

    Parameters
    ----------
    bumper_frequency : float
        Apparent natural frequency Omega_b / 2 pi [Hz], > 0.
    bumper_loss_factor : float
        xi_b [-], >= 0.
    settings : EngineSettings
        rtol, atol and max_step.
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
        run = _Run(self, model, rec, float(t_start), state)
        rec.strobe(run.t, run.physical())
        quadratures = run.y[5:].copy()
        for k in range(1, periods + 1):
            boundary = t_start + k * problem.period
            while True:
                result = run.solver.step(boundary, method="onestep", tstop=boundary)
                run.counts["steps"] += 1
                if result.status < 0:
                    raise RuntimeError(f"IDA failed at t = {result.t!r} s: {result.message}")
                run.t, run.y = float(result.t), np.array(result.y)
                if result.status == _STATUS_TSTOP:
                    break
                if result.status == _STATUS_ROOT:
                    run.on_root(np.asarray(result.i_events[-1]))
            if moments:
                q = run.y[5:] - quadratures
                quadratures = run.y[5:].copy()
                rec.add_moments(moment_row(q))
            rec.strobe(run.t, run.physical())
        return rec.build(run.counts | {"rhs_calls": model.rhs_calls})

    def sweep(self, system: TwoDofSystem, clearance: float, sweep: SweptSine, sample_rate: float, state: NDArray[np.float64] | None = None) -> SweepRecord:
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
        """
        require_positive("sample_rate", sample_rate)
        problem = ImpactProblem(system, clearance, 0.5, sweep.amplitude, sweep.start_frequency)  # forcing from `sweep`
        model = _BumperModel(problem, KelvinVoigtBumper(clearance, self.frequency, self.loss_factor), False, sweep)
        rec = TrajectoryBuilder(problem, False)
        run = _Run(self, model, rec, 0.0, np.zeros(4) if state is None else state)
        times = np.arange(0.0, sweep.duration, 1.0 / sample_rate)
        out = np.empty((times.size, 5))
        for i, sample in enumerate(times):
            while run.t < sample:
                result = run.solver.step(float(sample))
                run.counts["steps"] += 1
                if result.status < 0:
                    raise RuntimeError(f"IDA failed at t = {result.t!r} s: {result.message}")
                run.t, run.y = float(result.t), np.array(result.y)
                if result.status == _STATUS_ROOT:
                    run.on_root(np.asarray(result.i_events[-1]))
                    continue
                break
            bumper = model.force(run.y) if model.contact else 0.0
            out[i] = [run.y[0], run.y[1] + clearance, run.y[2], run.y[3], bumper]
        rec.strobe(run.t, run.physical())
        base_force = system.k1 * out[:, 0] + system.b1 * out[:, 2] + out[:, 4]
        return SweepRecord(sweep, times, out[:, 0], out[:, 1], base_force, out[:, 4], rec.build(run.counts | {"rhs_calls": model.rhs_calls}))

    def _solver(self, model: _BumperModel) -> IDA:
        def events(t: float, y: NDArray[np.float64], yp: NDArray[np.float64], out: NDArray[np.float64]) -> None:
            model.events(t, y, yp, out)

        events.terminal = [True] * 5  # type: ignore[attr-defined]
        events.direction = [1, -1, -1, -1, 1]  # type: ignore[attr-defined]
        self._events = events
        options: dict[str, Any] = {
            "rtol": self.settings.rtol,
            "atol": self.settings.atol,
            "max_num_steps": 1_000_000,
            "eventsfn": events,
            "num_events": 5,
            "jacfn": model.jacobian,
        }
        if self.settings.max_step > 0.0:
            options["max_step"] = self.settings.max_step
        return IDA(model.residual, **options)


class _Run:
    """One IDA integration: the state, the solver, and what happens at each event (onset, release, peaks)."""

    def __init__(self, engine: CompliantEngine, model: _BumperModel, rec: TrajectoryBuilder, t: float, state: NDArray[np.float64]) -> None:
        self.model, self.rec = model, rec
        self.clearance = model.problem.clearance
        self.t = t
        self.y = np.zeros(model.size)
        self.y[:4] = np.asarray(state, dtype=float)
        self.y[1] -= self.clearance
        model.contact = bool(self.y[1] >= 0.0 and model.force(self.y) > 0.0)
        self.solver = engine._solver(model)
        self._events = engine._events
        self.counts = {"events": 0, "contacts": 0, "steps": 0}
        self.onset, self.peak_force, self.peak_deceleration = (t, 0.0, 0.0), 0.0, 0.0
        if model.contact:
            self._begin_contact()
        self.restart()

    def physical(self) -> NDArray[np.float64]:
        """(X1, X2, X1', X2') now."""
        return np.array([self.y[0], self.y[1] + self.clearance, self.y[2], self.y[3]])

    def restart(self) -> None:
        """Re-initialise IDA at the current state with consistent y' = f(t, y), and open a segment."""
        clear_event_records(self._events)
        result = self.solver.init_step(self.t, self.y, self.model.derivative(self.t, self.y))
        if result.status < 0:
            raise RuntimeError(f"IDA could not start at t = {self.t!r} s: {result.message}")
        self.rec.segment(self.t, MODE_CONTACT if self.model.contact else MODE_FREE, self.physical())

    def _begin_contact(self) -> None:
        """Onset (time, entry speed, impulse integral) and the force and deceleration at first touch."""
        self.counts["contacts"] += 1
        self.onset = (self.t, float(self.y[3]), float(self.y[4]))
        self.peak_force = self.model.force(self.y)
        self.peak_deceleration = max(-self.model.derivative(self.t, self.y)[3], 0.0)

    def on_root(self, fired: NDArray[np.int_]) -> None:
        """Handle the events that stopped IDA at the current time; restart it if the mode changed."""
        clear_event_records(self._events)
        self.counts["events"] += 1
        model, y = self.model, self.y
        if model.contact and fired[1] != 0:  # release: the bumper would pull
            self.rec.contact_peaks(self.peak_force, self.peak_deceleration)
            self.rec.impact(self.onset[0], self.onset[1], float(y[4]) - self.onset[2], in_moments=False)
            model.contact = False
        elif model.contact:  # a force or deceleration maximum: record it, integration goes on
            self.peak_force = max(self.peak_force, model.force(y))
            self.peak_deceleration = max(self.peak_deceleration, -model.derivative(self.t, y)[3])
            return
        elif fired[0] != 0 or (fired[2] != 0 and y[1] >= 0.0):  # onset (or a tangent touch at an apex)
            model.contact = True
            y[1] = max(y[1], 0.0)
            self._begin_contact()
        else:
            return  # an apex short of the bumper
        self.restart()
