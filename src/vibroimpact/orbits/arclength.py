"""The pseudo-arclength machinery shared by one- and two-parameter continuation.

Unknowns are scaled, ``z = (y / state_scale, p_free / parameter_scale_free)``, so arclength weighs a state and a
parameter by their typical sizes. The equations are ``F(z) = [(P(y; p) - y) / state_scale, g(y, p)]``: the fixed-point
condition plus, for a two-parameter continuation, one scalar test function ``g`` (fold, Neimark-Sacker, grazing).
With f free parameters there are n + f - 1 equations in n + f unknowns; the corrector adds the pseudo-arclength
condition ``t0 . (z - z_pred) = 0`` and runs Newton's method on the square system.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from vibroimpact.orbits.branch import MapEvaluation, ParametrisedMap, PeriodicOrbit
from vibroimpact.orbits.shooting import make_orbit, parameter_derivative

__all__ = ["ArclengthSystem", "Point", "TestFunction"]

#: A scalar function of a map evaluation at (y, p): the extra equation of a two-parameter continuation.
TestFunction = Callable[[MapEvaluation, NDArray[np.float64], NDArray[np.float64]], float]


@dataclass(frozen=True, eq=False)
class Point:
    """A corrected point of a continuation: scaled unknowns, the map's evaluation there, F's Jacobian and the tangent."""

    z: NDArray[np.float64]
    y: NDArray[np.float64]
    p: NDArray[np.float64]
    out: MapEvaluation
    residual: NDArray[np.float64]
    jacobian: NDArray[np.float64]
    tangent: NDArray[np.float64]
    iterations: int
    history: tuple[float, ...]

    def orbit(self, system: ParametrisedMap) -> PeriodicOrbit:
        """The periodic orbit at this point."""
        return make_orbit(system, self.y, self.p, self.out, self.history)


class ArclengthSystem:
    """F(z) = 0 for a map, its base parameter vector, the free parameters and optional extra test functions.

    Parameters
    ----------
    system : ParametrisedMap
        The map whose fixed points are continued (already iterated for period-k orbits).
    parameters : ndarray, shape (m,)
        Values of all parameters; the free ones are overwritten by the unknowns.
    free : tuple of int
        Indices of the free parameters (one for a branch, two for a curve of special points).
    extra : tuple of TestFunction
        ``len(free) - 1`` scalar equations g(out, y, p) = 0.
    """

    def __init__(self, system: ParametrisedMap, parameters: NDArray[np.float64], free: tuple[int, ...], extra: tuple[TestFunction, ...] = ()) -> None:
        if len(extra) != len(free) - 1:
            raise ValueError(f"{len(free)} free parameters need {len(free) - 1} extra equations, got {len(extra)}")
        self.system, self.free, self.extra = system, tuple(free), tuple(extra)
        self.base = np.array(parameters, dtype=float)
        self.n = system.dimension
        self.sy = np.asarray(system.state_scale, dtype=float)
        self.sp = np.asarray(system.parameter_scale, dtype=float)[list(self.free)]

    # ------------------------------------------------------------ coordinates
    def to_z(self, y: NDArray[np.float64], p: NDArray[np.float64]) -> NDArray[np.float64]:
        """Scaled unknowns of (y, p)."""
        return np.concatenate([np.asarray(y, dtype=float) / self.sy, np.asarray(p, dtype=float)[list(self.free)] / self.sp])

    def from_z(self, z: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(y, p) of scaled unknowns."""
        p = self.base.copy()
        p[list(self.free)] = z[self.n :] * self.sp
        return z[: self.n] * self.sy, p

    # ------------------------------------------------------------ equations
    def _extra_values(self, out: MapEvaluation, y: NDArray[np.float64], p: NDArray[np.float64]) -> list[float]:
        return [float(g(out, y, p)) for g in self.extra]

    def equations(self, z: NDArray[np.float64], columns: NDArray[np.float64] | None = None) -> tuple[NDArray[np.float64], NDArray[np.float64], MapEvaluation]:
        """F(z), dF/dz (shape (n + f - 1, n + f)) and the map's evaluation at z.

        ``columns`` (n, f): the scaled dP/dp columns to reuse (a chord step) instead of differencing them again.
        """
        y, p = self.from_z(z)
        out = self.system.evaluate(y, p)
        residual = np.concatenate([(out.image - y) / self.sy, self._extra_values(out, y, p)])
        jac = np.empty((residual.size, z.size))
        jac[: self.n, : self.n] = (out.jacobian - np.eye(self.n)) * self.sy[None, :] / self.sy[:, None]
        if columns is not None:
            jac[: self.n, self.n :] = columns
        elif np.all(np.isfinite(out.image)):
            self.fresh_columns(jac, y, p, out)
        if self.extra:
            base = residual[self.n :]
            for i in range(z.size):  # forward differences of the test functions: sqrt(eps) relative steps
                step = 1.5e-8 * max(1.0, abs(z[i]))
                zz = z.copy()
                zz[i] += step
                yy, pp = self.from_z(zz)
                jac[self.n :, i] = (np.array(self._extra_values(self.system.evaluate(yy, pp), yy, pp)) - base) / step
        return residual, jac, out

    def fresh_columns(self, jac: NDArray[np.float64], y: NDArray[np.float64], p: NDArray[np.float64], out: MapEvaluation) -> None:
        """Write the scaled dP/dp columns at (y, p) into ``jac``."""
        for j, index in enumerate(self.free):
            jac[: self.n, self.n + j] = parameter_derivative(self.system, y, p, index, out) * self.sp[j] / self.sy

    @staticmethod
    def tangent(jacobian: NDArray[np.float64], previous: NDArray[np.float64] | None) -> NDArray[np.float64]:
        """Unit null vector of dF/dz, oriented along ``previous`` (or any sign when there is none)."""
        if previous is None:
            t = np.linalg.svd(jacobian)[2][-1]
        else:
            bordered = np.vstack([jacobian, previous])
            rhs = np.zeros(bordered.shape[0])
            rhs[-1] = 1.0
            try:
                t = np.linalg.solve(bordered, rhs)
            except np.linalg.LinAlgError:
                t = np.linalg.svd(jacobian)[2][-1]
            if previous @ t < 0.0:
                t = -t
        return t / np.linalg.norm(t)

    def point(self, z: NDArray[np.float64], previous_tangent: NDArray[np.float64] | None) -> Point:
        """The point at z (assumed on the branch) with its tangent."""
        residual, jac, out = self.equations(z)
        y, p = self.from_z(z)
        return Point(z, y, p, out, residual, jac, self.tangent(jac, previous_tangent), 0, (float(np.max(np.abs(residual))),))

    def correct(
        self,
        predicted: NDArray[np.float64],
        direction: NDArray[np.float64],
        tolerance: float,
        max_iterations: int,
        signature: tuple[int, int] | None = None,
        anchor: NDArray[np.float64] | None = None,
    ) -> Point | None:
        """Newton's method on [F(z) = 0, direction . (z - predicted) = 0]; None when it does not converge.

        Converged when max |F| <= ``tolerance`` and the last Newton step was below ``100 * tolerance`` (scaled): the
        last step polishes the point to round-off, which matters next to a fold where the error in the state is the
        residual divided by the distance of a multiplier from 1.
        With a hybrid ``signature`` (impacts, sticks), every iterate is kept on the side of the grazing manifold where
        the map has that signature, by halving the step (from ``anchor``, a point on that side, for the first one):
        next to a grazing point the map's Jacobian grows like one over the slowest impact's speed and a full Newton
        step would jump to the other side, where the map is another function.
        """
        z = np.array(predicted, dtype=float)
        history: list[float] = []
        last_step = np.inf
        previous = anchor
        columns = None  # dP/dp is differenced at the first iterate and at the solution only (chord steps between)
        for iteration in range(max_iterations + 1):
            residual, jac, out = self.equations(z, columns)
            if signature is not None and previous is not None:
                for _ in range(40):
                    if out.hybrid is not None and out.hybrid.signature == signature:
                        break
                    z = previous + 0.5 * (z - previous)
                    residual, jac, out = self.equations(z, columns)
                else:
                    return None
            size = float(np.max(np.abs(residual))) if residual.size else 0.0
            history.append(size)
            if not np.isfinite(size) or not np.all(np.isfinite(jac)):
                return None
            if size <= tolerance and last_step <= 100.0 * tolerance:
                y, p = self.from_z(z)
                if columns is not None:
                    self.fresh_columns(jac, y, p, out)
                return Point(z, y, p, out, residual, jac, self.tangent(jac, direction), iteration, tuple(history))
            columns = jac[: self.n, self.n :].copy()
            if iteration == max_iterations or (iteration >= 3 and size > 2.0 * history[-2]):
                return None
            square = np.vstack([jac, direction])
            rhs = -np.concatenate([residual, [direction @ (z - predicted)]])
            try:
                step = np.linalg.solve(square, rhs)
            except np.linalg.LinAlgError:
                return None
            last_step = float(np.max(np.abs(step)))
            previous = z
            z = z + step
        return None
