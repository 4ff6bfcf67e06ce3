"""NLvib's method, written here (NLvib is MATLAB): harmonic balance with the alternating frequency-time scheme for
a linear chain with one unilateral spring, continued in the excitation frequency by pseudo-arclength.

The displacement is a Fourier series of H harmonics, x(tau) = Q_0 + sum_k Q_ck cos(k tau) + Q_sk sin(k tau) with tau =
Omega t; the spring's force k_s max(w . x - gap, 0) w is sampled at N points of a period and projected back (the AFT
scheme of Krack & Gross, *Harmonic Balance for Nonlinear Vibration Problems*, 2019, ch. 3 and NLvib's
``HB_residual``), and every harmonic's balance K Q - (k Omega)^2 M Q + k Omega D (quadrature) + F_nl - F_ex = 0 is
solved with its exact Jacobian. The curve is followed as NLvib's ``solve_and_continue`` does: a tangent predictor of
arclength ``ds`` and Newton corrections orthogonal to it, from the linear response at the start frequency.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["UnilateralChain", "HarmonicBalanceCurve", "harmonic_balance_curve"]


@dataclass(frozen=True)
class UnilateralChain:
    """M x'' + D x' + K x + k_s max(w . x - gap, 0) w = f cos(Omega t)."""

    mass: NDArray[np.float64]
    damping: NDArray[np.float64]
    stiffness: NDArray[np.float64]
    force: NDArray[np.float64]
    direction: NDArray[np.float64]
    spring: float
    gap: float


@dataclass(frozen=True)
class HarmonicBalanceCurve:
    """Points of the continued curve: ``omega`` [rad/s], ``coefficients`` (points, 2H + 1, n) ordered Q_0, Q_c1..H,
    Q_s1..H, and ``contact`` (whether the spring acts somewhere on the period)."""

    omega: NDArray[np.float64]
    coefficients: NDArray[np.float64]
    contact: NDArray[np.bool_]

    def fundamental(self, coordinate: int) -> NDArray[np.float64]:
        """|Q_1| of ``coordinate`` at every point (the amplitude NLvib's example 03 plots)."""
        harmonics = (self.coefficients.shape[1] - 1) // 2
        return np.hypot(self.coefficients[:, 1, coordinate], self.coefficients[:, 1 + harmonics, coordinate])

    def folds(self, window: int = 10, prominence: float = 5e-5) -> list[float]:
        """The frequencies [rad/s] where the contact part turns back: a point whose Omega is the largest or least of
        the ``window`` points on either side and stands out from both ends of that window by ``prominence``, relative;
        of such points closer than ``window`` apart, the most extreme. (The sampled contact makes the balance
        piecewise smooth, with a kink wherever a sample enters or leaves contact: the points zigzag in Omega by ~1e-5
        relative, which a turn of the whole curve outlasts.)"""
        found: list[int] = []
        for k in range(window, self.omega.size - window):
            around = self.omega[k - window : k + window + 1]
            if not self.contact[k] or self.omega[k] not in (around.max(), around.min()):
                continue
            if min(abs(self.omega[k] - around[0]), abs(self.omega[k] - around[-1])) > prominence * self.omega[k]:
                found.append(k)
        groups: list[list[int]] = []
        for k in found:
            if groups and k - groups[-1][-1] <= window:
                groups[-1].append(k)
            else:
                groups.append([k])
        return [float(self.omega[g[0]]) for g in groups]


def harmonic_balance_curve(system: UnilateralChain, harmonics: int, samples: int, start: float, end: float, step: float, max_steps: int = 5000) -> HarmonicBalanceCurve:
    """The curve from ``start`` to ``end`` [rad/s] (module docstring), ``step`` the arclength of a step."""
    M, D, K = system.mass, system.damping, system.stiffness
    n, H = M.shape[0], harmonics
    tau = 2.0 * np.pi * np.arange(samples) / samples
    k = np.arange(1, H + 1)
    E = np.column_stack([np.ones(samples), np.cos(np.outer(tau, k)), np.sin(np.outer(tau, k))])
    P = np.vstack([np.ones(samples) / samples, 2.0 / samples * np.cos(np.outer(k, tau)), 2.0 / samples * np.sin(np.outer(k, tau))])
    ww = np.outer(system.direction, system.direction)
    excitation = np.zeros((2 * H + 1, n))
    excitation[1] = system.force

    def balance(z: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        Q, omega = z[:-1].reshape(2 * H + 1, n), z[-1]
        gap = E @ Q @ system.direction - system.gap
        residual = P @ np.outer(system.spring * np.maximum(gap, 0.0), system.direction) - excitation
        linear = np.zeros((2 * H + 1, n, 2 * H + 1, n))
        linear[0, :, 0, :] = K
        derivative = np.zeros((2 * H + 1, n))
        residual[0] += K @ Q[0]
        for j in range(1, H + 1):
            w = j * omega
            A = K - w * w * M
            c, s = Q[j], Q[H + j]
            residual[j] += A @ c + w * D @ s
            residual[H + j] += A @ s - w * D @ c
            linear[j, :, j, :], linear[j, :, H + j, :] = A, w * D
            linear[H + j, :, H + j, :], linear[H + j, :, j, :] = A, -w * D
            derivative[j] = -2.0 * w * j * M @ c + j * D @ s
            derivative[H + j] = -2.0 * w * j * M @ s - j * D @ c
        jacobian = np.kron(P @ (E * (system.spring * (gap > 0.0))[:, None]), ww) + linear.reshape((2 * H + 1) * n, (2 * H + 1) * n)
        return residual.ravel(), np.column_stack([jacobian, derivative.ravel()])

    def tangent(jacobian: NDArray[np.float64], previous: NDArray[np.float64]) -> NDArray[np.float64]:
        t = np.linalg.solve(np.vstack([jacobian, previous]), np.concatenate([np.zeros(jacobian.shape[0]), [1.0]]))
        return t / np.linalg.norm(t)

    Q1 = np.linalg.solve(K - start**2 * M + 1j * start * D, system.force)
    Q = np.zeros((2 * H + 1, n))
    Q[1], Q[H + 1] = Q1.real, -Q1.imag
    z = np.concatenate([Q.ravel(), [start]])
    direction = np.zeros(z.size)
    direction[-1] = np.sign(end - start)
    t = tangent(balance(z)[1], direction)
    points = [z.copy()]
    for _ in range(max_steps):
        predicted = z + step * t
        trial = predicted.copy()
        for _ in range(30):
            residual, jacobian = balance(trial)
            change = np.linalg.solve(np.vstack([jacobian, t]), -np.concatenate([residual, [t @ (trial - predicted)]]))
            trial += change
            if np.max(np.abs(change)) <= 1e-12:
                break
        t = tangent(balance(trial)[1], t)
        z = trial
        points.append(z.copy())
        if (z[-1] - end) * np.sign(end - start) >= 0.0:
            break
    array = np.array(points)
    coefficients = array[:, :-1].reshape(len(points), 2 * H + 1, n)
    contact = np.array([np.max(E @ c @ system.direction) > system.gap for c in coefficients])
    return HarmonicBalanceCurve(array[:, -1], coefficients, contact)
