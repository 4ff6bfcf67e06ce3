"""Engine ``compliant``: the Kelvin-Voigt bumper of eq. 25 (:mod:`~vibroimpact.engines.compliant.model`) through SUNDIALS IDA (scikit-sundae).

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
:data:`~vibroimpact.engines.settings.SWEEP_SETTINGS`, 12 s with atol 1e-12; the earlier loop of one ``IDA.step`` per output and per root took
16 s with every record cleared and ~155 s as it was, its steps slowing down as the ``_yp`` records piled up.
Profiled, ~75 % of the time is inside ``IDA.solve`` outside the Python callbacks (SUNDIALS, and scikit-sundae
wrapping the arrays of every callback), the rest in the residual and event functions; there are ~1.1 residual
calls per step attempt (the model is linear and the Jacobian exact).

Tolerances: ``settings.rtol`` is the relative tolerance; ``settings.atol`` is the absolute tolerance of the
displacements [m], and the other components get the same tolerance in their own units (:func:`absolute_tolerances`).
With ``atol`` a small fraction of the motion's amplitude the error test no longer asks for a relative accuracy of
each component as it crosses zero. The paper's swept-sine test uses :data:`~vibroimpact.engines.settings.SWEEP_SETTINGS` (rtol 1e-6, atol 1e-10 m).

Each contact is recorded as an impact (onset time, entry speed, impulse = integral of F) with its peak force and
peak deceleration (``Trajectory.contact_peaks``). The bumper is the problem's contact (a
:class:`~vibroimpact.model.contact.KelvinVoigtBumper`); its loss factor sets the restitution of a collision
(:func:`vibroimpact.model.contact.restitution_from_loss_factor`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray
from sksundae.cvode import CVODE
from sksundae.ida import IDA

from vibroimpact.engines.base import MODE_FREE, SweepRecord, Trajectory, TrajectoryBuilder, check_run
from vibroimpact.engines.compliant.model import MODE_CONTACT, BumperModel, absolute_tolerances
from vibroimpact.engines.event_loop import moment_row
from vibroimpact.engines.registry import BUMPER_INTEGRATOR, Capabilities
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.engines.sundae import clear_event_records, solver_messages
from vibroimpact.model.contact import KelvinVoigtBumper
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.structure import require_positive

__all__ = ["CompliantEngine", "base_force", "CompliantCvodeEngine"]

_STATUS_ROOT = 2  # IDA_ROOT_RETURN
_STATUS_ILL_INPUT = -22  # IDA_ILL_INPUT (CV_ILL_INPUT): among others, "Root found at and very near t"
#: Largest number of output times handled by one ``IDA.solve`` call (bounds its output arrays).
_OUTPUTS_PER_CALL = 2048
#: Mode switches in a row without any progress in time before the run is declared stuck.
_MAX_SWITCHES_IN_PLACE = 100


class CompliantEngine:
    """IDA with Kelvin-Voigt bumpers, the problem's stops (see module docstring): a stepping and a sweeping engine.

    Parameters
    ----------
    settings : EngineSettings
        rtol, atol (of the displacements [m]; scaled for the other components, see :func:`absolute_tolerances`) and
        max_step. :data:`~vibroimpact.engines.settings.SWEEP_SETTINGS` suits the paper's swept-sine test.
    """

    name = "compliant"
    #: what it can do when built directly (:func:`~vibroimpact.engines.registry.make_engine` sets its registry row's)
    capabilities: Capabilities = BUMPER_INTEGRATOR

    def __init__(self, settings: EngineSettings = EngineSettings()) -> None:
        self.settings = settings

    def integrate(self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float, periods: int, moments: bool = False) -> Trajectory:
        """Integrate ``periods`` whole periods from ``state`` (x_1 ... x_N, x_1' ... x_N') at ``t_start`` [s]."""
        return self._integrate(problem, state, t_start, periods, moments, None)[0]

    def sample(self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float, periods: int, times: NDArray[np.float64]) -> tuple[Trajectory, NDArray[np.float64]]:
        """Integrate ``periods`` periods from ``state`` at ``t_start`` [s] and give the states (x, x') at ``times`` [s]
        (inside the run, increasing), shape (n, 2 N) [m, m s-1]: the solver's own interpolation (the times join the
        strobe times as outputs of its calls), the state after a mode switch at the switch's time."""
        times = np.asarray(times, dtype=float).reshape(-1)
        t_end = float(t_start) + periods * problem.period
        if times.size and (np.any(np.diff(times) < 0.0) or times[0] < t_start or times[-1] > t_end):
            raise ValueError(f"times: expected increasing times inside the run [{t_start!r}, {t_end!r}] s, got [{times.min()!r}, {times.max()!r}] s")
        return self._integrate(problem, state, t_start, periods, False, times)  # type: ignore[return-value]

    def _integrate(
        self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float, periods: int, moments: bool, samples: NDArray[np.float64] | None
    ) -> tuple[Trajectory, NDArray[np.float64] | None]:
        """:meth:`integrate`, also giving the states at the times ``samples`` if given."""
        check_run(self.name, problem, KelvinVoigtBumper, periods)
        model = BumperModel(problem, moments)
        rec = TrajectoryBuilder(problem, moments)
        run = _Run(self, model, rec, float(t_start), state, problem.omega)
        rec.strobe(run.t, run.physical())
        first, n, count = model.first_quadrature, problem.size, model.stop_count
        previous = run.y[first:].copy()

        def strobes(times: NDArray[np.float64], ys: NDArray[np.float64], contact: int) -> None:
            nonlocal previous
            for t, y in zip(times, ys):
                if moments:
                    rec.add_moments(moment_row(y[first:] - previous, n, count))
                    previous = y[first:].copy()
                rec.strobe(float(t), model.layout.physical(y))

        boundaries = np.asarray(t_start + problem.period * np.arange(1, periods + 1), dtype=np.float64)
        if samples is None:
            run.run(boundaries, strobes)
            return rec.build(run.stats()), None
        # the sample times join the boundaries as outputs, once each: an output row is a strobe where a boundary
        # falls on its time, and the state of every sample at its time
        sampled = np.empty((samples.size, 2 * n))
        merged, inverse = np.unique(np.concatenate([boundaries, samples]), return_inverse=True)
        strobe_at = np.zeros(merged.size, dtype=bool)
        strobe_at[inverse[: boundaries.size]] = True
        sample_rows = inverse[boundaries.size :]  # increasing, as the samples are
        done = 0

        def outputs(times: NDArray[np.float64], ys: NDArray[np.float64], contact: int) -> None:
            nonlocal done
            chosen = strobe_at[done : done + times.size]
            if np.any(chosen):
                strobes(times[chosen], ys[chosen], contact)
            lo, hi = np.searchsorted(sample_rows, [done, done + times.size])
            for slot in range(lo, hi):
                sampled[slot] = model.layout.physical(ys[sample_rows[slot] - done])
            done += times.size

        run.run(merged, outputs)
        return rec.build(run.stats()), sampled

    def sweep(
        self, problem: ImpactProblem, sample_rate: float, state: NDArray[np.float64] | None = None, progress: Callable[[float], None] | None = None
    ) -> SweepRecord:
        """Swept-sine test (the paper's Simulink run): q sin(theta(t)) from t = 0 to the sweep's end, sampled.

        Any structure and stops (each a bumper): the record holds every coordinate, each stop's contact force and
        its Fourier integral, and the force on the base (:func:`base_force`).

        Parameters
        ----------
        problem : ImpactProblem
            Structure, bumpers and a :class:`~vibroimpact.model.excitation.SweptSine` excitation.
        sample_rate : float
            Output samples per second [Hz] (IDA interpolates; the step is set by the tolerances).
        state : ndarray, optional
            (x_1 ... x_N, x_1' ... x_N') at t = 0 [m, m s-1]; rest (zeros) by default.
        progress : callable, optional
            Receives the simulated time reached [s] after each block of samples.
        """
        check_run(self.name, problem, KelvinVoigtBumper)
        sweep = problem.sweep
        require_positive("sample_rate", sample_rate)
        model = BumperModel(problem, False)
        rec = TrajectoryBuilder(problem, False)
        n, count = problem.size, model.stop_count
        omega_ref = 2.0 * math.pi * max(sweep.start_frequency, sweep.stop_frequency)
        run = _Run(self, model, rec, 0.0, np.zeros(2 * n) if state is None else state, omega_ref)
        times = np.arange(0.0, sweep.duration, 1.0 / sample_rate)
        # x, x', each stop's force, each stop's Fourier integral (real, -imaginary)
        out = np.empty((times.size, 2 * n + 3 * count))
        forces, fourier = 2 * n, 2 * n + count
        filled, first = 0, model.first_quadrature
        layout = model.layout

        def samples(t: NDArray[np.float64], ys: NDArray[np.float64], contact: int) -> None:
            nonlocal filled
            block = out[filled : filled + t.size]
            block[:, :n] = ys[:, :n] @ layout.t_inverse.T + layout.offset
            block[:, n : 2 * n] = ys[:, n : 2 * n]
            for k in range(count):
                block[:, forces + k] = ys[:, : 2 * n] @ model.force_rows[k] + model.force_constants[k] if (contact >> k) & 1 else 0.0
            block[:, fourier:] = ys[:, first : first + 2 * count]
            filled += t.size
            if progress is not None:
                progress(float(t[-1]))

        run.run(times, samples)
        if filled != times.size:
            raise RuntimeError(f"the sweep produced {filled} of {times.size} samples")
        rec.strobe(run.t, run.physical())
        contact = out[:, forces:fourier]
        integrals = out[:, fourier:]
        return SweepRecord(sweep, times, out[:, :n], base_force(problem, out[:, : 2 * n], contact), contact, rec.build(run.stats()), integrals[:, 0::2] - 1j * integrals[:, 1::2])

    def solve(self, solver: Any, tspan: NDArray[np.float64], y0: NDArray[np.float64], yp0: NDArray[np.float64]) -> Any:
        """One solver call over ``tspan`` from a consistent (y0, y0')."""
        return solver.solve(tspan, y0, yp0)

    def first_step(self, model: BumperModel, contact: int, omega_ref: float) -> float:
        """First step after a (re)start [s]: sqrt(2 rtol) / (the mode's fastest angular frequency), a backward-Euler
        step of about the tolerance (h^2 |y''| / 2 ~ rtol |y|)."""
        natural = float(np.abs(np.linalg.eigvals(model.problem.structure.state_matrix)).max())
        bumpers = [model.k[k] / model.layout.masses[k] for k in range(model.stop_count) if (int(contact) >> k) & 1]
        fastest = max(math.sqrt(natural**2 + max(bumpers, default=0.0)), omega_ref)
        return math.sqrt(2.0 * self.settings.rtol) / fastest

    def _solver(self, model: BumperModel, contact: int, omega_ref: float) -> tuple[IDA, Any]:
        """The IDA solver of one mode and its event function."""
        events = model.events(contact)
        first = self.first_step(model, contact, omega_ref)
        options: dict[str, Any] = {
            "rtol": self.settings.rtol,
            "atol": absolute_tolerances(self.settings.atol, omega_ref, model.layout.masses, model.quadratures, model.layout.size),
            "max_num_steps": 1_000_000,
            "eventsfn": events,
            "num_events": model.event_count(contact),
            "jacfn": model.jacobian(contact),
            "first_step": first,
        }
        if self.settings.max_step > 0.0:
            options["max_step"] = self.settings.max_step
            options["first_step"] = min(first, self.settings.max_step)
        return IDA(model.residual(contact), **options), events


def _last(said: list[str]) -> str:
    """The last of SUNDIALS' messages in a solver call, for the failure's one line (``''`` if it said nothing)."""
    return f" (SUNDIALS: {said[-1]})" if said else ""


def base_force(problem: ImpactProblem, states: NDArray[np.float64], contact: NDArray[np.float64]) -> NDArray[np.float64]:
    """Force on the base [N] from samples of (x, x') (rows) and of each stop's contact force (rows of K): the springs
    and dashpots to the ground, 1^T (K x + C x'), plus each stop's force on the base, (1^T n_k) lambda_k (+lambda_k
    for an upper absolute stop, -lambda_k for a lower one; a relative stop loads only the structure). For the paper's
    layout K1 X1 + B1 X1' + F."""
    structure, n = problem.structure, problem.size
    ground = np.concatenate([structure.stiffness_matrix.sum(axis=0), structure.damping_matrix.sum(axis=0)])
    return states[:, : 2 * n] @ ground + contact @ problem.normals().sum(axis=1)


class _Run:
    """One integration: the state, one IDA solver per contact mode, and what happens at each switch and recorded root."""

    def __init__(self, engine: CompliantEngine, model: BumperModel, rec: TrajectoryBuilder, t: float, state: NDArray[np.float64], omega_ref: float) -> None:
        self.engine, self.model, self.rec, self.omega_ref = engine, model, rec, omega_ref
        n = model.layout.size
        state = np.asarray(state, dtype=float)
        if state.shape != (2 * n,):
            raise ValueError(f"state: expected {2 * n} values (x and x' of {n} coordinates), got shape {state.shape}")
        self.t = t
        self.y = np.zeros(model.size)
        self.y[: 2 * n] = model.layout.internal(state)
        self.contact = model.enters(t, self.y)
        self.solvers: dict[int, tuple[IDA, Any]] = {}
        self.counts = {"events": 0, "contacts": 0, "solver_calls": 0, "grazing": 0}
        count = model.stop_count
        self.onsets: list[tuple[float, float, float]] = [(t, 0.0, 0.0)] * count
        self.peak_force, self.peak_deceleration = [0.0] * count, [0.0] * count
        for k in range(count):
            if (self.contact >> k) & 1:
                self._begin_contact(k)
        self.rec.segment(self.t, MODE_CONTACT if self.contact else MODE_FREE, self.physical(), stop=self._segment_stop())

    def solver(self, mode: int) -> tuple[IDA, Any]:
        """The solver of a contact mode (made on first use)."""
        if mode not in self.solvers:
            self.solvers[mode] = self.engine._solver(self.model, mode, self.omega_ref)
        return self.solvers[mode]

    def physical(self) -> NDArray[np.float64]:
        """(x, x') now."""
        return self.model.layout.physical(self.y)

    def _segment_stop(self) -> int:
        """The stop in contact for the segment record (the lowest one if several, -1 in flight)."""
        return (self.contact & -self.contact).bit_length() - 1 if self.contact else -1

    def stats(self) -> dict[str, int]:
        return self.counts | {"steps": self.model.steps, "rhs_calls": self.model.rhs_calls}

    def run(self, outputs: NDArray[np.float64], emit: Callable[[NDArray[np.float64], NDArray[np.float64], int], None]) -> None:
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
            solver, events = self.solver(self.contact)
            self.counts["solver_calls"] += 1
            with solver_messages() as said:  # SUNDIALS' own words on each error, handled ones too: not printed
                result = self.engine.solve(solver, tspan, self.y, self.model.derivative(self.t, self.y, self.contact))
            close_roots = self._close_roots(result)
            if result.status < 0 and not close_roots:
                raise RuntimeError(f"IDA failed at t = {float(result.t[-1])!r} s: {result.message}{_last(said)}")
            times, states = result.t[1:], result.y[1:]
            stopped = result.status == _STATUS_ROOT  # on a terminal event: the last row is the root
            # on close roots the last row is the recorded root where the solver stopped: the run goes on from there
            rows, end_t, end_y = times.size - 1 if stopped or close_roots else times.size, float(times[-1]), states[-1]
            records = (result.i_events, result.t_events, result.y_events)
            clear_event_records(events)
            switching = 0
            if records[0] is not None:
                rows, end_t, end_y, stopped, switching = self._roots(records, times, rows, end_t, end_y, stopped)
            first = 1 if midpoint else 0
            if rows > first:
                emit(times[first:rows], states[first:rows], self.contact)
                i += rows - first
            if close_roots:
                in_place = in_place + 1 if end_t == last_switch else 0
                if in_place > _MAX_SWITCHES_IN_PLACE:
                    raise RuntimeError(f"IDA stops at close roots over and over at t = {end_t!r} s: {result.message}{_last(said)}")
                last_switch = end_t
            self.t, self.y = end_t, np.array(end_y)
            if stopped:
                in_place = in_place + 1 if self.t == last_switch else 0
                if in_place > _MAX_SWITCHES_IN_PLACE:
                    raise RuntimeError(f"the contact switches mode over and over at t = {self.t!r} s")
                last_switch = self.t
                self._switch(switching)

    def _close_roots(self, result: Any) -> bool:
        """The solver refused to go on from a recorded root because an event function is exactly 0 there and just
        after it ("Root found at and very near t", IDA_ILL_INPUT): in a long contact (a structure pressed on the
        bumper) the deceleration's extremum event (jerk) hovers at round-off zero. Its last output row is that root,
        consistent; a restart from it is safe, since at a start SUNDIALS ignores a function that stays 0 until it
        moves. Any other failure is an error."""
        if result.status != _STATUS_ILL_INPUT or result.t_events is None or len(result.t_events) == 0:
            return False
        end = float(result.t[-1])
        return end > self.t and end == float(result.t_events[-1])

    def _roots(self, records: tuple[Any, Any, Any], times: NDArray[np.float64], rows: int, end_t: float, end_y: NDArray[np.float64],
               stopped: bool) -> tuple[int, float, NDArray[np.float64], bool, int]:
        """Handle the roots recorded in one solver call; return the output rows to keep, where the run goes on (a
        grazing contact cuts the call short at its apex), and the stops whose mode switches there (a bit mask)."""
        model, count = self.model, self.model.stop_count
        roles = model.event_roles(self.contact)
        for flags, t_root, y_root in zip(*records):
            terminal = [k for k in range(count) if flags[k] != 0]
            if stopped and t_root == end_t and terminal:
                return rows, end_t, end_y, stopped, sum(1 << k for k in terminal)  # the terminal event: the caller switches
            self.counts["events"] += 1
            for index in range(count, len(roles)):
                if flags[index] == 0:
                    continue
                stop, role = roles[index]
                if role == "apex":
                    if model.layout.penetration(y_root, stop) >= 0.0:  # an apex at or beyond the bumper: a grazing contact the onset event missed
                        self.counts["grazing"] += 1
                        return int(np.searchsorted(times[:rows], t_root, side="right")), float(t_root), y_root, True, 1 << stop
                else:  # a largest force or deceleration
                    self.peak_force[stop] = max(self.peak_force[stop], model.force(y_root, stop))
                    self.peak_deceleration[stop] = max(self.peak_deceleration[stop], model.deceleration(float(t_root), y_root, self.contact, stop))
        return rows, end_t, end_y, stopped, 0

    def _begin_contact(self, stop: int) -> None:
        """Onset (time, entry speed, impulse integral) and the force and deceleration at first touch."""
        self.counts["contacts"] += 1
        model = self.model
        self.onsets[stop] = (self.t, model.layout.approach(self.y, stop), float(self.y[model.states + stop]))
        self.peak_force[stop] = model.force(self.y, stop)
        self.peak_deceleration[stop] = max(model.deceleration(self.t, self.y, self.contact, stop), 0.0)

    def _switch(self, stops: int) -> None:
        """Onset (or grazing apex) in flight, release in contact, of each stop in the mask ``stops``: change mode at
        the current state."""
        self.counts["events"] += 1
        model = self.model
        for k in range(model.stop_count):
            if not (stops >> k) & 1:
                continue
            if (self.contact >> k) & 1:  # release: the bumper would pull
                self.rec.contact_peaks(self.peak_force[k], self.peak_deceleration[k], stop=k)
                onset = self.onsets[k]
                self.rec.impact(onset[0], onset[1], float(self.y[model.states + k]) - onset[2], in_moments=False, stop=k)
                self.contact &= ~(1 << k)
            else:
                self.contact |= 1 << k
                if model.layout.penetration(self.y, k) < 0.0:
                    model.layout.close(self.y, k)
                self._begin_contact(k)
        self.rec.segment(self.t, MODE_CONTACT if self.contact else MODE_FREE, self.physical(), stop=self._segment_stop())


# --------------------------------------------------------------------------------------------------------------------
# The compliant-bumper model of :mod:`~vibroimpact.engines.compliant.model` (engine :mod:`~vibroimpact.engines.compliant.ida`) through SUNDIALS CVODE instead of IDA.
# --------------------------------------------------------------------------------------------------------------------

class CompliantCvodeEngine(CompliantEngine):
    """The Kelvin-Voigt bumper through CVODE (``settings.method``: ``adams`` or ``bdf``); see :class:`CompliantEngine`."""

    def __init__(self, settings: EngineSettings = EngineSettings()) -> None:
        super().__init__(settings)
        self.name = f"compliant_cvode_{settings.method}"

    def solve(self, solver: Any, tspan: NDArray[np.float64], y0: NDArray[np.float64], yp0: NDArray[np.float64]) -> Any:
        """One CVODE call over ``tspan`` (an ODE solver needs no y0')."""
        return solver.solve(tspan, y0)

    def _solver(self, model: BumperModel, contact: int, omega_ref: float) -> tuple[Any, Any]:
        residual = model.residual(contact)
        zero = np.zeros(model.size)

        def rhs(t: float, y: NDArray[np.float64], yp: NDArray[np.float64]) -> None:
            residual(t, y, zero, yp)  # yp <- 0 - f(t, y)
            np.negative(yp, out=yp)

        events = model.events(contact)
        derivative = np.empty(model.size)

        def cvode_events(t: float, y: NDArray[np.float64], out: NDArray[np.float64]) -> None:
            rhs(t, y, derivative)
            events(t, y, derivative, out)

        cvode_events.terminal = events.terminal  # type: ignore[attr-defined]
        cvode_events.direction = events.direction  # type: ignore[attr-defined]
        options: dict[str, Any] = {
            "method": "Adams" if self.settings.method == "adams" else "BDF",
            "rtol": self.settings.rtol,
            "atol": absolute_tolerances(self.settings.atol, omega_ref, model.layout.masses, model.quadratures, model.layout.size),
            "max_num_steps": 1_000_000,
            "eventsfn": cvode_events,
            "num_events": model.event_count(contact),
            "first_step": self.first_step(model, contact, omega_ref),  # CVODE's own guess collapsed at contact onsets
        }
        if self.settings.max_step > 0.0:
            options["max_step"] = self.settings.max_step
            options["first_step"] = min(options["first_step"], self.settings.max_step)
        return CVODE(rhs, **options), cvode_events
