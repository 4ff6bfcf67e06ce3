"""Smooth maps whose fixed points and bifurcations are known in closed form, for testing the orbits layer."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from vibroimpact.orbits.branch import MapEvaluation


class FoldMap:
    """x -> x + p - x^2: fixed points +-sqrt(p), a fold at p = 0, a period doubling of +sqrt(p) at p = 1."""

    dimension = 1
    parameter_names = ("p",)
    state_scale = np.array([1.0])
    parameter_scale = np.array([1.0])

    def evaluate(self, y: NDArray, p: NDArray) -> MapEvaluation:
        x = y[0]
        return MapEvaluation(np.array([x + p[0] - x * x]), np.array([[1.0 - 2.0 * x]]), np.array([[1.0]]))


class LogisticMap:
    """x -> r x (1 - x): fixed point 1 - 1/r with multiplier 2 - r (period doubling at r = 3)."""

    dimension = 1
    parameter_names = ("r",)
    state_scale = np.array([1.0])
    parameter_scale = np.array([1.0])

    def evaluate(self, y: NDArray, p: NDArray) -> MapEvaluation:
        x, r = y[0], p[0]
        return MapEvaluation(np.array([r * x * (1.0 - x)]), np.array([[r * (1.0 - 2.0 * x)]]), None)  # dP/dp by differences


class HenonMap:
    """(x, y) -> (1 - a x^2 + y, b x): fold at a = -(1 - b)^2 / 4, period doubling at a = 3 (1 - b)^2 / 4."""

    dimension = 2
    parameter_names = ("a", "b")
    state_scale = np.array([1.0, 1.0])
    parameter_scale = np.array([1.0, 1.0])

    def evaluate(self, y: NDArray, p: NDArray) -> MapEvaluation:
        x, v = y
        a, b = p
        image = np.array([1.0 - a * x * x + v, b * x])
        jacobian = np.array([[-2.0 * a * x, 1.0], [b, 0.0]])
        return MapEvaluation(image, jacobian, np.array([[-x * x, 0.0], [0.0, x]]))

    @staticmethod
    def fixed_points(a: float, b: float) -> NDArray:
        """x of both fixed points."""
        root = np.sqrt((1.0 - b) ** 2 + 4.0 * a)
        return np.array([(-(1.0 - b) + root) / (2.0 * a), (-(1.0 - b) - root) / (2.0 * a)])


class DelayedLogisticMap:
    """(x, y) -> (r x (1 - y), s x): fixed point y* = 1 - 1/r, x* = y* / s; det J = r - 1, trace 1.

    A Neimark-Sacker bifurcation at r = 2 for every s > 0, multipliers exp(+-i pi / 3).
    """

    dimension = 2
    parameter_names = ("r", "s")
    state_scale = np.array([1.0, 1.0])
    parameter_scale = np.array([1.0, 1.0])

    def evaluate(self, y: NDArray, p: NDArray) -> MapEvaluation:
        x, v = y
        r, s = p
        image = np.array([r * x * (1.0 - v), s * x])
        jacobian = np.array([[r * (1.0 - v), -r * x], [s, 0.0]])
        return MapEvaluation(image, jacobian, np.array([[x * (1.0 - v), 0.0], [0.0, x]]))


class NeutralSaddleMap:
    """(x, y) -> (p x + x^2, 2 y): fixed point 0 with real multipliers p and 2, whose product crosses 1 at p = 1/2."""

    dimension = 2
    parameter_names = ("p",)
    state_scale = np.array([1.0, 1.0])
    parameter_scale = np.array([1.0])

    def evaluate(self, y: NDArray, p: NDArray) -> MapEvaluation:
        x, v = y
        return MapEvaluation(np.array([p[0] * x + x * x, 2.0 * v]), np.array([[p[0] + 2.0 * x, 0.0], [0.0, 2.0]]), np.array([[x], [0.0]]))
