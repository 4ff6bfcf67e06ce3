"""An independent integration of the Kelvin-Voigt bumper model for the tests of ``compliant_exact``: scipy's DOP853
at rtol 1e-12 with explicit mode switching by events, written from the model's statement alone (eq. 25: stop k pushes
with F_k = K_k d_k + B_k n_k . x' while d_k = n_k . x - Delta_k >= 0 and F_k > 0; K_k = m_k Omega_b^2,
B_k = 2 m_k xi_b Omega_b, m_k = 1 / (n_k . M^-1 n_k)), using none of the package's engine code.

Each stop is free below its bumper (event: d rising through 0), free beyond it (after a release with the bumper
still compressed: F rising through 0 is an onset, d falling through 0 ends the phase) or in contact (F falling
through 0 releases it; F' falling through 0 marks a largest force). Quadratures integrate each coordinate's and each
force's Fourier integral, x e^{-jwt} and F e^{-jwt}, and each force (the impulse), period by period.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

from vibroimpact.model.problem import ImpactProblem

__all__ = ["ReferenceRun", "reference_run"]

BELOW, BEYOND, CONTACT = 0, 1, 2


@dataclass
class ReferenceRun:
    """What :func:`reference_run` found: strobes (periods + 1, 2 N); per period the Fourier integrals of the
    coordinates (periods, N) and of the forces (periods, K), complex; contacts completed (onset time, stop, impulse,
    largest force) in order; every onset (time, stop)."""

    strobes: np.ndarray
    coordinates: np.ndarray
    forces: np.ndarray
    contacts: list[tuple[float, int, float, float]] = field(default_factory=list)
    onsets: list[tuple[float, int]] = field(default_factory=list)


def reference_run(problem: ImpactProblem, state: np.ndarray, t0: float, periods: int, rtol: float = 1e-12) -> ReferenceRun:
    """Integrate ``periods`` periods from ``state`` at ``t0`` (see module docstring)."""
    structure = problem.structure
    mass, stiffness, damping = structure.mass_matrix, structure.stiffness_matrix, structure.damping_matrix
    size, count = problem.size, len(problem.stops)
    inverse = np.linalg.inv(mass)
    normals = np.array([stop.normal(size) for stop in problem.stops]).reshape(count, size)
    clearances = np.array([stop.clearance for stop in problem.stops])
    effective = 1.0 / np.einsum("ki,ij,kj->k", normals, inverse, normals)
    k_b = np.array([effective[k] * stop.law.omega**2 for k, stop in enumerate(problem.stops)])
    b_b = np.array([2.0 * effective[k] * stop.law.loss_factor * stop.law.omega for k, stop in enumerate(problem.stops)])
    harmonic, static = problem.load()
    omega = problem.omega
    n = 2 * size
    quadratures = 2 * size + 3 * count  # Re, Im of x_i e^{-jwt}; Re, Im of F_k e^{-jwt}; F_k

    def gap(y: np.ndarray, k: int) -> float:
        return float(normals[k] @ y[:size] - clearances[k])

    def force(y: np.ndarray, k: int) -> float:
        return k_b[k] * gap(y, k) + b_b[k] * float(normals[k] @ y[size:n])

    phases = []
    for k in range(count):
        d, f = gap(state, k), force(state, k)
        phases.append(CONTACT if d >= 0.0 and f > 0.0 else BEYOND if d > 0.0 else BELOW)

    def forces(y: np.ndarray) -> np.ndarray:
        return np.array([force(y, k) if phases[k] == CONTACT else 0.0 for k in range(count)])

    def acceleration(t: float, y: np.ndarray) -> np.ndarray:
        load = static + (harmonic * complex(math.cos(omega * t), math.sin(omega * t))).real
        return inverse @ (load - stiffness @ y[:size] - damping @ y[size:n] - normals.T @ forces(y))

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        rotor = complex(math.cos(omega * t), -math.sin(omega * t))
        f = forces(y)
        out = np.empty(n + quadratures)
        out[:size], out[size:n] = y[size:n], acceleration(t, y)
        out[n : n + 2 * size : 2], out[n + 1 : n + 2 * size : 2] = y[:size] * rotor.real, y[:size] * rotor.imag
        q = n + 2 * size
        out[q : q + 2 * count : 2], out[q + 1 : q + 2 * count : 2] = f * rotor.real, f * rotor.imag
        out[q + 2 * count :] = f
        return out

    def event(kind: str, k: int):  # type: ignore[no-untyped-def]
        if kind == "gap":
            function = lambda t, y: gap(y, k)  # noqa: E731
        elif kind == "force":
            function = lambda t, y: force(y, k)  # noqa: E731
        else:  # the force's rate, K n . x' + B n . x''
            function = lambda t, y: k_b[k] * float(normals[k] @ y[size:n]) + b_b[k] * float(normals[k] @ acceleration(t, y))  # noqa: E731
        return function

    atol = np.concatenate([np.full(size, 1e-15), np.full(size, 1e-13), np.full(quadratures, 1e-18)])
    t, y = float(t0), np.concatenate([np.asarray(state, dtype=float), np.zeros(quadratures)])
    run = ReferenceRun(np.zeros((periods + 1, n)), np.zeros((periods, size), complex), np.zeros((periods, count), complex))
    run.strobes[0] = state
    peaks = [force(y, k) if phases[k] == CONTACT else 0.0 for k in range(count)]
    starts = [(t, y[n + 2 * size + 2 * count + k]) if phases[k] == CONTACT else (math.nan, 0.0) for k in range(count)]
    impulse_slot = n + 2 * size + 2 * count
    for p in range(1, periods + 1):
        t_end = t0 + p * problem.period
        while t < t_end:
            events, roles = [], []
            for k in range(count):
                watched = {BELOW: [("gap", 1.0, "onset")], BEYOND: [("force", 1.0, "onset"), ("gap", -1.0, "below")], CONTACT: [("force", -1.0, "release"), ("rate", -1.0, "peak")]}[phases[k]]
                for kind, direction, role in watched:
                    function = event(kind, k)
                    function.direction, function.terminal = direction, role != "peak"  # type: ignore[attr-defined]
                    events.append(function)
                    roles.append((k, role))
            step = solve_ivp(rhs, (t, t_end), y, method="DOP853", rtol=rtol, atol=atol, events=events, dense_output=True)
            for (k, role), times in zip(roles, step.t_events):
                if role == "peak":
                    for time in times:
                        peaks[k] = max(peaks[k], force(step.sol(time), k))
            t, y = float(step.t[-1]), step.y[:, -1].copy()
            if step.status != 1:
                break
            k, role = next(roles[i] for i, times in enumerate(step.t_events) if times.size and roles[i][1] != "peak")
            if role == "onset":
                phases[k] = CONTACT
                run.onsets.append((t, k))
                starts[k], peaks[k] = (t, y[impulse_slot + k]), force(y, k)
            elif role == "below":
                phases[k] = BELOW
            else:
                run.contacts.append((starts[k][0], k, y[impulse_slot + k] - starts[k][1], peaks[k]))
                phases[k] = BEYOND if gap(y, k) > 0.0 else BELOW
        run.strobes[p] = y[:n]
        q = y[n:]
        run.coordinates[p - 1] = q[0 : 2 * size : 2] + 1j * q[1 : 2 * size : 2]
        run.forces[p - 1] = q[2 * size : 2 * size + 2 * count : 2] + 1j * q[2 * size + 1 : 2 * size + 2 * count : 2]
        y[n : n + 2 * size + 2 * count] = 0.0  # the Fourier integrals restart; the impulse integrals run on
    return run
