"""The compliant-bumper swept-sine test through ``scipy.integrate.solve_ivp``: a cross-check of the IDA engine.

Written independently of :mod:`.ida` and :mod:`.model` (its own right-hand side, in the physical coordinates x1, x2, x1', x2',
its own events and restarts), so that agreement between the two means something. The model is the same, on any
two-coordinate structure with one stop (normal n, clearance Delta, effective mass m): the Kelvin-Voigt bumper of
eq. 25 pushes along -n with F = K (n . x - Delta) + B n . x' (K = m Omega_b^2, B = 2 m xi_b Omega_b) from the moment
n . x reaches Delta until F falls to zero (for the paper's layout n = e_2, F = K (X2 - Delta) + B X2'). The loop a
user of SciPy would write:

* free flight: ``solve_ivp`` with a terminal event on n . x - Delta (rising) and a recorded one on n . x' (falling,
  the apex); an apex at n . x >= Delta is a contact whose two crossings fell inside one step: the run restarts there;
* contact: a terminal event on F (falling), recorded ones on dF/dt (falling, largest force) and on the jerk
  (rising, largest deceleration);
* each terminal event restarts ``solve_ivp`` in the other mode; the samples come from ``t_eval`` (each method's
  dense output).

The state carries the force integral and the Fourier integral of the force against the sweep's phase, so the record
has the same impulses and ``contact_fourier`` as :meth:`.ida.CompliantEngine.sweep`. Implicit methods get the
mode's constant Jacobian (the Fourier rows excepted: they vary with time; solve_ivp's finite differences fill them
when ``jac`` is omitted, so it is given without them).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.integrate import solve_ivp

from vibroimpact.engines.base import MODE_FREE, SweepRecord, TrajectoryBuilder, check_run
from vibroimpact.engines.compliant.ida import base_force, check_sweep_layout
from vibroimpact.engines.compliant.model import MODE_CONTACT
from vibroimpact.engines.settings import SWEEP_SETTINGS
from vibroimpact.model.contact import KelvinVoigtBumper
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.validation import require_positive

__all__ = ["IVP_METHODS", "solve_ivp_sweep"]

#: The methods of ``solve_ivp`` (all of them can run this model; the implicit ones get the Jacobian).
IVP_METHODS = ("RK23", "RK45", "DOP853", "Radau", "BDF", "LSODA")
_IMPLICIT = ("Radau", "BDF", "LSODA")
#: Samples per ``solve_ivp`` call at most (a long free flight is cut into calls of this many samples).
_SAMPLES_PER_CALL = 4096


def solve_ivp_sweep(
    problem: ImpactProblem,
    sample_rate: float,
    method: str = "LSODA",
    rtol: float = SWEEP_SETTINGS.rtol,
    atol: float = SWEEP_SETTINGS.atol,
    state: NDArray[np.float64] | None = None,
) -> SweepRecord:
    """The swept-sine test of :meth:`.ida.CompliantEngine.sweep`, integrated with ``solve_ivp``.

    Parameters
    ----------
    problem : ImpactProblem
        System, :class:`~vibroimpact.model.contact.KelvinVoigtBumper` and
        :class:`~vibroimpact.model.excitation.SweptSine` excitation.
    sample_rate : float
        Output samples per second [Hz]; the samples are those of the IDA engine, ``arange(0, duration, 1 / rate)``.
    method : str
        One of :data:`IVP_METHODS`.
    rtol : float
        Relative tolerance.
    atol : float
        Absolute tolerance of the displacements [m]; velocities get ``atol`` times the sweep's highest angular
        frequency w, the force integral that times M2, its Fourier integral that times w again (as IDA's).
    state : ndarray, optional
        (X1, X2, X1', X2') at t = 0; rest by default.

    Returns
    -------
    SweepRecord
        Samples, contacts (onsets, entry speeds, impulses, peaks) and ``stats``: ``nfev``, ``njev``, ``nlu`` (summed
        over the calls), ``solver_calls``, ``contacts``, ``events``, ``grazing``; ``rhs_calls`` = ``nfev``.
    """
    if method not in IVP_METHODS:
        raise ValueError(f"method = {method!r} is not allowed: use one of {', '.join(IVP_METHODS)}")
    check_run(f"solve_ivp_{method}", problem, KelvinVoigtBumper)
    check_sweep_layout(f"solve_ivp_{method}", problem)
    sweep = problem.sweep
    require_positive("sample_rate", sample_rate)
    run = _IvpRun(problem, method, rtol, atol)
    times = np.arange(0.0, sweep.duration, 1.0 / sample_rate)
    start = np.zeros(4) if state is None else np.asarray(state, dtype=float)
    samples = run.run(np.concatenate([start, np.zeros(3)]), times)
    force = samples[:, 7]
    return SweepRecord(
        sweep=sweep,
        time=times,
        x1=samples[:, 0].copy(),
        x2=samples[:, 1].copy(),
        base_force=base_force(problem, samples[:, :4], force),
        contact_force=force.copy(),
        trajectory=run.rec.build(run.stats | {"rhs_calls": run.stats["nfev"]}),
        contact_fourier=samples[:, 5] - 1j * samples[:, 6],
    )


class _IvpRun:
    """State, events and restarts of one solve_ivp sweep. State: X1, X2, X1', X2', integral of F, and the integrals
    of F cos(theta) theta' and F sin(theta) theta'."""

    def __init__(self, problem: ImpactProblem, method: str, rtol: float, atol: float) -> None:
        structure, bumper, sweep, stop = problem.structure, problem.bumper, problem.sweep, problem.stops[0]
        self.delta, self.sweep, self.method, self.rtol = problem.clearance, sweep, method, rtol
        mass = structure.mass_matrix
        self.normal = stop.normal(2)
        m = stop.effective_mass(mass)
        self.k, self.b = bumper.stiffness(m), bumper.damping(m)
        self.minv = np.linalg.inv(mass)
        self.stiffness, self.damping = structure.stiffness_matrix, structure.damping_matrix
        harmonic, self.static = problem.load()
        self.weights = harmonic.real  # the sweep's q times its distribution over the coordinates [N]
        w = 2.0 * math.pi * max(sweep.start_frequency, sweep.stop_frequency)
        self.atol = np.array([atol, atol, atol * w, atol * w, atol * w * m, atol * w * w * m, atol * w * w * m])
        self.rec = TrajectoryBuilder(problem, False)
        self.stats = {"nfev": 0, "njev": 0, "nlu": 0, "solver_calls": 0, "contacts": 0, "events": 0, "grazing": 0}
        free = np.zeros((7, 7))
        free[0, 2] = free[1, 3] = 1.0
        free[2:4, :2] = -self.minv @ self.stiffness
        free[2:4, 2:4] = -self.minv @ self.damping
        contact = free.copy()
        push = np.concatenate([self.k * self.normal, self.b * self.normal])  # d F / d (x, x')
        contact[2:4, :4] -= np.outer(self.minv @ self.normal, push)
        contact[4, :4] = push
        self.jacobians = {False: free, True: contact}

    def push(self, y: NDArray[np.float64]) -> float:
        """K (n . x - Delta) + B n . x' [N]."""
        n = self.normal
        return float(self.k * (n[0] * y[0] + n[1] * y[1] - self.delta) + self.b * (n[0] * y[2] + n[1] * y[3]))

    def rhs(self, contact: bool) -> Callable[[float, NDArray[np.float64]], NDArray[np.float64]]:
        k, c, minv, n = self.stiffness, self.damping, self.minv, self.normal
        weights, static = self.weights, self.static
        f0, alpha = self.sweep.start_frequency, self.sweep.alpha
        push_of = self.push

        def f(t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
            theta = 2.0 * math.pi * (f0 * t + 0.5 * alpha * t * t)
            push = push_of(y) if contact else 0.0
            force = weights * math.sin(theta) + static - k @ y[:2] - c @ y[2:4] - n * push
            speed = 2.0 * math.pi * (f0 + alpha * t)  # theta'
            a = minv @ force
            return np.array([y[2], y[3], a[0], a[1], push, push * math.cos(theta) * speed, push * math.sin(theta) * speed])

        return f

    def events(self, contact: bool, f: Callable[[float, NDArray[np.float64]], NDArray[np.float64]]) -> list[Callable[..., float]]:
        """Terminal first, then the recorded ones (see the module docstring)."""
        delta, k, b, n = self.delta, self.k, self.b, self.normal
        stiffness, damping, minv, weights = self.stiffness, self.damping, self.minv, self.weights
        f0, alpha = self.sweep.start_frequency, self.sweep.alpha

        def onset(t: float, y: NDArray[np.float64]) -> float:
            return float(n @ y[:2] - delta)

        def apex(t: float, y: NDArray[np.float64]) -> float:
            return float(n @ y[2:4])

        def release(t: float, y: NDArray[np.float64]) -> float:
            return self.push(y)

        def force_rate(t: float, y: NDArray[np.float64]) -> float:
            return float(k * (n @ y[2:4]) + b * (n @ f(t, y)[2:4]))

        def jerk(t: float, y: NDArray[np.float64]) -> float:
            d = f(t, y)
            theta = 2.0 * math.pi * (f0 * t + 0.5 * alpha * t * t)
            rate = k * (n @ y[2:4]) + b * (n @ d[2:4])
            force_rate = weights * math.cos(theta) * 2.0 * math.pi * (f0 + alpha * t) - stiffness @ y[2:4] - damping @ d[2:4] - n * rate
            return float(n @ (minv @ force_rate))

        onset.terminal, onset.direction = True, 1.0  # type: ignore[attr-defined]
        apex.terminal, apex.direction = False, -1.0  # type: ignore[attr-defined]
        release.terminal, release.direction = True, -1.0  # type: ignore[attr-defined]
        force_rate.terminal, force_rate.direction = False, -1.0  # type: ignore[attr-defined]
        jerk.terminal, jerk.direction = False, 1.0  # type: ignore[attr-defined]
        return [release, force_rate, jerk] if contact else [onset, apex]

    def run(self, y: NDArray[np.float64], times: NDArray[np.float64]) -> NDArray[np.float64]:
        """Integrate over the samples ``times`` from ``y`` at t = 0; rows X1, X2, X1', X2', the three integrals, F."""
        out = np.empty((times.size, 8))
        t, n, i = 0.0, times.size, 0
        contact = bool(self.normal @ y[:2] >= self.delta and self.push(y) > 0.0)
        functions = {mode: self.rhs(mode) for mode in (False, True)}
        events = {mode: self.events(mode, functions[mode]) for mode in (False, True)}
        jacobians = {mode: self._constant(self.jacobians[mode]) for mode in (False, True)}  # LSODA takes callables only
        onset: dict[str, Any] = self._begin(t, y, functions[True]) if contact else {}
        self.rec.segment(t, MODE_CONTACT if contact else MODE_FREE, y[:4])
        while i < n:
            while i < n and times[i] <= t:  # samples at the current time
                out[i] = self._sample(y, contact)
                i += 1
            if i == n:
                break
            j = min(n, i + _SAMPLES_PER_CALL)
            options: dict[str, Any] = {"jac": jacobians[contact]} if self.method in _IMPLICIT else {}
            sol = solve_ivp(functions[contact], (t, times[j - 1]), y, method=self.method, t_eval=times[i:j], events=events[contact], rtol=self.rtol, atol=self.atol, **options)
            if sol.status < 0:
                raise RuntimeError(f"solve_ivp ({self.method}) failed after t = {t!r} s: {sol.message}")
            self.stats["solver_calls"] += 1
            for name in ("nfev", "njev", "nlu"):
                self.stats[name] += int(getattr(sol, name))
            kept, switch = len(sol.t), sol.status == 1  # (t is an empty list when no sample was reached)
            if switch:
                t, y = float(sol.t_events[0][-1]), sol.y_events[0][-1].copy()
            else:
                t, y = float(sol.t[-1]), sol.y[:, -1].copy()
            if contact:  # largest force and deceleration: at the recorded roots, and at onset
                for which, column in ((1, 0), (2, 1)):
                    for tr, yr in zip(sol.t_events[which], sol.y_events[which]):
                        self.stats["events"] += 1
                        value = self.push(yr) if column == 0 else -float(self.normal @ functions[True](tr, yr)[2:4])
                        onset["peaks"][column] = max(onset["peaks"][column], value)
            else:  # an apex at or past the bumper: a missed contact
                self.stats["events"] += len(sol.t_events[1])
                late = [(tr, yr) for tr, yr in zip(sol.t_events[1], sol.y_events[1]) if self.normal @ yr[:2] >= self.delta]
                if late:
                    self.stats["grazing"] += 1
                    t, y, switch = float(late[0][0]), late[0][1].copy(), True
                    kept = int(np.searchsorted(sol.t, t, side="right"))
            if kept:
                block = out[i : i + kept]
                block[:, :7] = sol.y[:, :kept].T
                block[:, 7] = self.k * (block[:, :2] @ self.normal - self.delta) + self.b * (block[:, 2:4] @ self.normal) if contact else 0.0
            i += kept
            if switch:
                self.stats["events"] += 1
                if contact:
                    self.rec.contact_peaks(*onset["peaks"])
                    self.rec.impact(onset["t"], onset["v"], float(y[4]) - onset["impulse"], in_moments=False)
                else:
                    onset = self._begin(t, y, functions[True])
                contact = not contact
                self.rec.segment(t, MODE_CONTACT if contact else MODE_FREE, y[:4])
        self.rec.strobe(t, y[:4])
        return out

    @staticmethod
    def _constant(matrix: NDArray[np.float64]) -> Callable[[float, NDArray[np.float64]], NDArray[np.float64]]:
        return lambda t, y: matrix

    def _begin(self, t: float, y: NDArray[np.float64], contact_rhs: Callable[[float, NDArray[np.float64]], NDArray[np.float64]]) -> dict[str, Any]:
        """A contact starts: its onset time, entry speed, force integral, and the force and deceleration now."""
        self.stats["contacts"] += 1
        gap = self.delta - float(self.normal @ y[:2])
        if gap > 0.0:  # the located root short of the stop by round-off: onto it along the stopped coordinate
            y[:2] += gap * self.normal / float(self.normal @ self.normal)
        return {"t": t, "v": float(self.normal @ y[2:4]), "impulse": float(y[4]), "peaks": [self.push(y), max(-float(self.normal @ contact_rhs(t, y)[2:4]), 0.0)]}

    def _sample(self, y: NDArray[np.float64], contact: bool) -> NDArray[np.float64]:
        force = self.push(y) if contact else 0.0
        return np.concatenate([y[:7], [force]])
