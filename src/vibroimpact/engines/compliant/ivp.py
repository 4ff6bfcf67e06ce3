"""The compliant-bumper swept-sine test through ``scipy.integrate.solve_ivp``: a cross-check of the IDA engine.

Written independently of :mod:`~vibroimpact.engines.compliant.ida` and :mod:`~vibroimpact.engines.compliant.model` (its own right-hand side, in the physical coordinates
(x, x'), its own events and restarts), so that agreement between the two means something. The model is the same, on
any structure with any stops (normal n_k, clearance Delta_k, effective mass m_k): the Kelvin-Voigt bumper of eq. 25
of stop k pushes along -n_k with F_k = K_k (n_k . x - Delta_k) + B_k n_k . x' (K_k = m_k Omega_b^2,
B_k = 2 m_k xi_b Omega_b) from the moment n_k . x reaches Delta_k until F_k falls to zero (for the paper's layout
n = e_2, F = K (X2 - Delta) + B X2'). A *mode* is the set of stops in contact. The loop a user of SciPy would write:

* a stop in free flight: a terminal event on n_k . x - Delta_k (rising) and a recorded one on n_k . x' (falling, the
  apex); an apex at n_k . x >= Delta_k is a contact whose two crossings fell inside one step: the run restarts there;
* a stop in contact: a terminal event on F_k (falling), recorded ones on dF_k/dt (falling, largest force) and on the
  jerk of n_k . x (rising, largest deceleration);
* each terminal event restarts ``solve_ivp`` in the new mode; the samples come from ``t_eval`` (each method's dense
  output).

The state carries each stop's force integral and the Fourier integral of its force against the sweep's phase, so
the record has the same impulses and ``contact_fourier`` as :meth:`.ida.CompliantEngine.sweep`. Implicit methods get
the mode's constant Jacobian (the Fourier rows excepted: they vary with time; solve_ivp's finite differences fill
them when ``jac`` is omitted, so it is given without them).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.integrate import solve_ivp

from vibroimpact.engines.base import MODE_FREE, SweepRecord, TrajectoryBuilder, check_run
from vibroimpact.engines.compliant.ida import base_force
from vibroimpact.engines.compliant.model import MODE_CONTACT
from vibroimpact.engines.settings import SWEEP_SETTINGS
from vibroimpact.model.contact import KelvinVoigtBumper
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.structure import require_positive

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
        Structure, :class:`~vibroimpact.model.contact.KelvinVoigtBumper` stops and a
        :class:`~vibroimpact.model.excitation.SweptSine` excitation.
    sample_rate : float
        Output samples per second [Hz]; the samples are those of the IDA engine, ``arange(0, duration, 1 / rate)``.
    method : str
        One of :data:`IVP_METHODS`.
    rtol : float
        Relative tolerance.
    atol : float
        Absolute tolerance of the displacements [m]; velocities get ``atol`` times the sweep's highest angular
        frequency w, each force integral that times the stop's effective mass m_k, its Fourier integrals that times w
        again (as IDA's).
    state : ndarray, optional
        (x_1 ... x_N, x_1' ... x_N') at t = 0 [m, m s-1]; rest by default.

    Returns
    -------
    SweepRecord
        Samples, contacts (onsets, entry speeds, impulses, peaks) and ``stats``: ``nfev``, ``njev``, ``nlu`` (summed
        over the calls), ``solver_calls``, ``contacts``, ``events``, ``grazing``; ``rhs_calls`` = ``nfev``.
    """
    if method not in IVP_METHODS:
        raise ValueError(f"method = {method!r} is not allowed: use one of {', '.join(IVP_METHODS)}")
    check_run(f"solve_ivp_{method}", problem, KelvinVoigtBumper)
    sweep = problem.sweep
    require_positive("sample_rate", sample_rate)
    run = _IvpRun(problem, method, rtol, atol)
    n, count = run.n, run.count
    times = np.arange(0.0, sweep.duration, 1.0 / sample_rate)
    start = np.zeros(2 * n) if state is None else np.asarray(state, dtype=float)
    if start.shape != (2 * n,):
        raise ValueError(f"state: expected {2 * n} values (x and x' of {n} coordinates), got shape {start.shape}")
    samples = run.run(np.concatenate([start, np.zeros(3 * count)]), times)
    forces = samples[:, 2 * n + 3 * count :].copy()
    fourier = samples[:, 2 * n + count : 2 * n + 3 * count]
    return SweepRecord(
        sweep=sweep,
        time=times,
        displacements=samples[:, :n].copy(),
        base_force=base_force(problem, samples[:, : 2 * n], forces),
        contact_forces=forces,
        trajectory=run.rec.build(run.stats | {"rhs_calls": run.stats["nfev"]}),
        contact_fourier=fourier[:, 0::2] - 1j * fourier[:, 1::2],
    )


class _IvpRun:
    """State, events and restarts of one solve_ivp sweep. State: x, x' (N each), the integral of each stop's force F_k
    (K), then per stop the integrals of F_k cos(theta) theta' and F_k sin(theta) theta' (2 K)."""

    def __init__(self, problem: ImpactProblem, method: str, rtol: float, atol: float) -> None:
        structure, sweep, stops = problem.structure, problem.sweep, problem.stops
        n, count = problem.size, len(stops)
        self.n, self.count = n, count
        self.sweep, self.method, self.rtol = sweep, method, rtol
        self.deltas = problem.clearances()
        mass = structure.mass_matrix
        self.normals = problem.normals()
        masses = np.array([stop.effective_mass(mass) for stop in stops])
        self.k = np.array([stop.law.stiffness(m) for stop, m in zip(stops, masses)])  # type: ignore[union-attr]
        self.b = np.array([stop.law.damping(m) for stop, m in zip(stops, masses)])  # type: ignore[union-attr]
        self.minv = np.linalg.inv(mass)
        self.stiffness, self.damping = structure.stiffness_matrix, structure.damping_matrix
        harmonic, self.static = problem.load()
        self.weights = harmonic.real  # the sweep's q times its distribution over the coordinates [N]
        w = 2.0 * math.pi * max(sweep.start_frequency, sweep.stop_frequency)
        self.atol = np.concatenate([np.full(n, atol), np.full(n, atol * w), atol * w * masses, np.repeat(atol * w * w * masses, 2)])
        self.rec = TrajectoryBuilder(problem, False)
        self.stats = {"nfev": 0, "njev": 0, "nlu": 0, "solver_calls": 0, "contacts": 0, "events": 0, "grazing": 0}
        size = 2 * n + 3 * count
        free = np.zeros((size, size))
        free[:n, n : 2 * n] = np.eye(n)
        free[n : 2 * n, :n] = -self.minv @ self.stiffness
        free[n : 2 * n, n : 2 * n] = -self.minv @ self.damping
        self._free = free
        self._jacobians: dict[int, NDArray[np.float64]] = {}

    def active(self, mask: int) -> list[int]:
        """The stops in contact in the mode ``mask``."""
        return [k for k in range(self.count) if (mask >> k) & 1]

    def jacobian(self, mask: int) -> NDArray[np.float64]:
        """The mode's constant Jacobian (the Fourier rows left out)."""
        if mask not in self._jacobians:
            n = self.n
            matrix = self._free.copy()
            for k in self.active(mask):
                push = np.concatenate([self.k[k] * self.normals[k], self.b[k] * self.normals[k]])  # d F_k / d (x, x')
                matrix[n : 2 * n, : 2 * n] -= np.outer(self.minv @ self.normals[k], push)
                matrix[2 * n + k, : 2 * n] = push
            self._jacobians[mask] = matrix
        return self._jacobians[mask]

    def push(self, y: NDArray[np.float64], k: int) -> float:
        """K_k (n_k . x - Delta_k) + B_k n_k . x' [N]."""
        n, normal = self.n, self.normals[k]
        return float(self.k[k] * (normal @ y[:n] - self.deltas[k]) + self.b[k] * (normal @ y[n : 2 * n]))

    def rhs(self, mask: int) -> Callable[[float, NDArray[np.float64]], NDArray[np.float64]]:
        k, c, minv, normals = self.stiffness, self.damping, self.minv, self.normals
        weights, static = self.weights, self.static
        f0, alpha = self.sweep.start_frequency, self.sweep.alpha
        push_of, n, count = self.push, self.n, self.count
        active = self.active(mask)

        def f(t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
            theta = 2.0 * math.pi * (f0 * t + 0.5 * alpha * t * t)
            pushes = np.zeros(count)
            force = weights * math.sin(theta) + static - k @ y[:n] - c @ y[n : 2 * n]
            for stop in active:
                pushes[stop] = push_of(y, stop)
                force = force - normals[stop] * pushes[stop]
            speed = 2.0 * math.pi * (f0 + alpha * t)  # theta'
            a = minv @ force
            fourier = np.empty(2 * count)
            fourier[0::2] = pushes * math.cos(theta) * speed
            fourier[1::2] = pushes * math.sin(theta) * speed
            return np.concatenate([y[n : 2 * n], a, pushes, fourier])

        return f

    def events(self, mask: int, f: Callable[[float, NDArray[np.float64]], NDArray[np.float64]]) -> tuple[list[Callable[..., float]], list[tuple[int, str]]]:
        """The mode's events, terminal first (one per stop: onset or release), then the recorded ones of each stop
        (apex; or force rate and jerk), and their (stop, role)."""
        stiffness, damping, minv, weights = self.stiffness, self.damping, self.minv, self.weights
        f0, alpha, n = self.sweep.start_frequency, self.sweep.alpha, self.n
        terminal: list[Callable[..., float]] = []
        recorded: list[Callable[..., float]] = []
        roles: list[tuple[int, str]] = []
        later: list[tuple[int, str]] = []
        for stop in range(self.count):
            normal, delta, kk, bb = self.normals[stop], self.deltas[stop], self.k[stop], self.b[stop]
            if (mask >> stop) & 1:

                def release(t: float, y: NDArray[np.float64], stop: int = stop) -> float:
                    return self.push(y, stop)

                def force_rate(t: float, y: NDArray[np.float64], normal: NDArray[np.float64] = normal, kk: float = kk, bb: float = bb) -> float:
                    return float(kk * (normal @ y[n : 2 * n]) + bb * (normal @ f(t, y)[n : 2 * n]))

                def jerk(t: float, y: NDArray[np.float64], normal: NDArray[np.float64] = normal, kk: float = kk, bb: float = bb) -> float:
                    d = f(t, y)
                    theta = 2.0 * math.pi * (f0 * t + 0.5 * alpha * t * t)
                    rate = kk * (normal @ y[n : 2 * n]) + bb * (normal @ d[n : 2 * n])
                    force_rate = weights * math.cos(theta) * 2.0 * math.pi * (f0 + alpha * t) - stiffness @ y[n : 2 * n] - damping @ d[n : 2 * n] - normal * rate
                    for other in self.active(mask):  # the other bumpers' force rates
                        if other != stop:
                            other_normal = self.normals[other]
                            force_rate = force_rate - other_normal * (self.k[other] * (other_normal @ y[n : 2 * n]) + self.b[other] * (other_normal @ d[n : 2 * n]))
                    return float(normal @ (minv @ force_rate))

                release.terminal, release.direction = True, -1.0  # type: ignore[attr-defined]
                force_rate.terminal, force_rate.direction = False, -1.0  # type: ignore[attr-defined]
                jerk.terminal, jerk.direction = False, 1.0  # type: ignore[attr-defined]
                terminal.append(release)
                recorded += [force_rate, jerk]
                roles.append((stop, "release"))
                later += [(stop, "rate"), (stop, "jerk")]
            else:

                def onset(t: float, y: NDArray[np.float64], normal: NDArray[np.float64] = normal, delta: float = delta) -> float:
                    return float(normal @ y[:n] - delta)

                def apex(t: float, y: NDArray[np.float64], normal: NDArray[np.float64] = normal) -> float:
                    return float(normal @ y[n : 2 * n])

                onset.terminal, onset.direction = True, 1.0  # type: ignore[attr-defined]
                apex.terminal, apex.direction = False, -1.0  # type: ignore[attr-defined]
                terminal.append(onset)
                recorded.append(apex)
                roles.append((stop, "onset"))
                later.append((stop, "apex"))
        return terminal + recorded, roles + later

    def run(self, y: NDArray[np.float64], times: NDArray[np.float64]) -> NDArray[np.float64]:
        """Integrate over the samples ``times`` from ``y`` at t = 0; rows x, x', the 3 K integrals, each F_k."""
        n, count = self.n, self.count
        width = 2 * n + 3 * count
        out = np.empty((times.size, width + count))
        t, samples, i = 0.0, times.size, 0
        mask = sum(1 << k for k in range(count) if self.normals[k] @ y[:n] >= self.deltas[k] and self.push(y, k) > 0.0)
        modes: dict[int, tuple[Callable[..., NDArray[np.float64]], list[Callable[..., float]], list[tuple[int, str]], Callable[..., NDArray[np.float64]]]] = {}

        def mode(m: int) -> tuple[Callable[..., NDArray[np.float64]], list[Callable[..., float]], list[tuple[int, str]], Callable[..., NDArray[np.float64]]]:
            if m not in modes:
                function = self.rhs(m)
                events, roles = self.events(m, function)
                modes[m] = (function, events, roles, self._constant(self.jacobian(m)))  # LSODA takes callables only
            return modes[m]

        onsets: dict[int, dict[str, Any]] = {k: self._begin(t, y, k, mode(mask)[0]) for k in self.active(mask)}
        self.rec.segment(t, MODE_CONTACT if mask else MODE_FREE, y[: 2 * n])
        while i < samples:
            while i < samples and times[i] <= t:  # samples at the current time
                out[i] = self._sample(y, mask)
                i += 1
            if i == samples:
                break
            j = min(samples, i + _SAMPLES_PER_CALL)
            function, events, roles, jacobian = mode(mask)
            options: dict[str, Any] = {"jac": jacobian} if self.method in _IMPLICIT else {}
            sol = solve_ivp(function, (t, times[j - 1]), y, method=self.method, t_eval=times[i:j], events=events, rtol=self.rtol, atol=self.atol, **options)
            if sol.status < 0:
                raise RuntimeError(f"solve_ivp ({self.method}) failed after t = {t!r} s: {sol.message}")
            self.stats["solver_calls"] += 1
            for name in ("nfev", "njev", "nlu"):
                self.stats[name] += int(getattr(sol, name))
            kept, switching = len(sol.t), []  # (t is an empty list when no sample was reached)
            if sol.status == 1:  # a terminal event: the stops whose event ended the call
                fired = [e for e in range(count) if len(sol.t_events[e])]
                end = max(float(sol.t_events[e][-1]) for e in fired)
                switching = [roles[e][0] for e in fired if float(sol.t_events[e][-1]) == end]
                t, y = end, sol.y_events[fired[[float(sol.t_events[e][-1]) for e in fired].index(end)]][-1].copy()
            else:
                t, y = float(sol.t[-1]), sol.y[:, -1].copy()
            late: list[tuple[float, int, NDArray[np.float64]]] = []
            for e in range(count, len(events)):
                stop, role = roles[e]
                for tr, yr in zip(sol.t_events[e], sol.y_events[e]):
                    self.stats["events"] += 1
                    if role == "rate":  # largest force and deceleration: at the recorded roots, and at onset
                        onsets[stop]["peaks"][0] = max(onsets[stop]["peaks"][0], self.push(yr, stop))
                    elif role == "jerk":
                        onsets[stop]["peaks"][1] = max(onsets[stop]["peaks"][1], -float(self.normals[stop] @ function(tr, yr)[n : 2 * n]))
                    elif self.normals[stop] @ yr[:n] >= self.deltas[stop]:  # an apex at or past the bumper: a missed contact
                        late.append((float(tr), stop, yr))
            if late:
                self.stats["grazing"] += 1
                first = min(late, key=lambda item: item[0])
                t, y, switching = first[0], first[2].copy(), [first[1]]
                kept = int(np.searchsorted(sol.t, t, side="right"))
            if kept:
                block = out[i : i + kept]
                block[:, :width] = sol.y[:, :kept].T
                for k in range(count):
                    block[:, width + k] = self.k[k] * (block[:, :n] @ self.normals[k] - self.deltas[k]) + self.b[k] * (block[:, n : 2 * n] @ self.normals[k]) if (mask >> k) & 1 else 0.0
            i += kept
            if switching:
                self.stats["events"] += 1
                for k in switching:
                    if (mask >> k) & 1:
                        onset = onsets.pop(k)
                        self.rec.contact_peaks(*onset["peaks"], stop=k)
                        self.rec.impact(onset["t"], onset["v"], float(y[2 * n + k]) - onset["impulse"], in_moments=False, stop=k)
                    mask ^= 1 << k
                for k in switching:
                    if (mask >> k) & 1:
                        onsets[k] = self._begin(t, y, k, mode(mask)[0])
                self.rec.segment(t, MODE_CONTACT if mask else MODE_FREE, y[: 2 * n])
        self.rec.strobe(t, y[: 2 * n])
        return out

    @staticmethod
    def _constant(matrix: NDArray[np.float64]) -> Callable[[float, NDArray[np.float64]], NDArray[np.float64]]:
        return lambda t, y: matrix

    def _begin(self, t: float, y: NDArray[np.float64], stop: int, contact_rhs: Callable[[float, NDArray[np.float64]], NDArray[np.float64]]) -> dict[str, Any]:
        """Stop ``stop``'s contact starts: its onset time, entry speed, force integral, and the force and
        deceleration now (``contact_rhs``: the right-hand side of the mode with it in contact)."""
        self.stats["contacts"] += 1
        n, normal = self.n, self.normals[stop]
        gap = self.deltas[stop] - float(normal @ y[:n])
        if gap > 0.0:  # the located root short of the stop by round-off: onto it along the stopped coordinate
            y[:n] += gap * normal / float(normal @ normal)
        return {"t": t, "v": float(normal @ y[n : 2 * n]), "impulse": float(y[2 * n + stop]), "peaks": [self.push(y, stop), max(-float(normal @ contact_rhs(t, y)[n : 2 * n]), 0.0)]}

    def _sample(self, y: NDArray[np.float64], mask: int) -> NDArray[np.float64]:
        forces = [self.push(y, k) if (mask >> k) & 1 else 0.0 for k in range(self.count)]
        return np.concatenate([y[: 2 * self.n + 3 * self.count], forces])
