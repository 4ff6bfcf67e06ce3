"""The Kelvin-Voigt bumper model (eq. 25, any structure and stops) as the compliant engines integrate it: residuals,
Jacobians and events of each contact mode.

Each stop k with a :class:`~vibroimpact.model.contact.KelvinVoigtBumper` pushes along -n_k with
lambda_k = K_k u_k + B_k n_k . x' while its penetration u_k = n_k . x - Delta_k >= 0 and lambda_k > 0 (eq. 25, the
bumper never pulls), K_k = m_k Omega_b^2 and B_k = 2 m_k xi_b Omega_b with the stop's effective mass m_k (M2 for the
paper's stop; a relative bumper acts on both bodies). The state is (w, v) of :mod:`..flow_layout` (the penetrations
in place of one coordinate each; (X1, X2 - Delta, X1', X2') for the paper's layout), the running integral of each
stop's force (impulses), then quadratures (:mod:`.kernels`): the harmonic moments of :mod:`..event_loop` when asked
(their contact-force channels integrate the bumper forces themselves), or for a sweep the Fourier integral of each
force against the sweep's own phase, integral of F exp(-j theta) theta' dt (the force is a pulse far shorter than the
output sampling: it cannot be summed from samples). A *mode* is the set of stops in contact (bit k of an int); each
has its own solver, residual, Jacobian ``cj I - df/dy`` and events, so every residual is smooth; the switches are
events, per stop:

* free: the penetration rising through zero, or within the bumper's reach (after a release with u > 0) the force it
  would exert rising through zero (onset, terminal), and the apex, n_k . x' falling through zero (recorded only): an
  apex at u >= 0 is a grazing contact whose two crossings fell inside one step; the run goes back to that apex and
  the contact starts there;
* contact: -lambda_k rising through zero (release, terminal), d lambda_k / dt falling through zero (largest force)
  and the jerk of n_k . x rising through zero (largest deceleration), both recorded only.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from vibroimpact.engines.compliant.kernels import MOMENTS, NONE, SWEEP, bumper_events, bumper_residual, bumper_rhs, force_kernel, pack_mode
from vibroimpact.engines.flow_layout import flow_layout
from vibroimpact.engines.rigid_kernels import quadrature_count
from vibroimpact.model.contact import KelvinVoigtBumper
from vibroimpact.model.excitation import SweptSine
from vibroimpact.model.problem import ImpactProblem

__all__ = ["MODE_CONTACT", "BumperModel", "absolute_tolerances"]

MODE_CONTACT = 2  # segment mode: a bumper pushing

_KINDS = {"none": NONE, "sweep": SWEEP, "moments": MOMENTS}


def absolute_tolerances(atol: float, omega_ref: float, masses: NDArray[np.float64] | float, quadratures: str = "none", size: int = 2) -> NDArray[np.float64]:
    """Per-component absolute tolerances of the compliant engines' state.

    ``atol`` [m] applies to the displacements (w); the velocities get ``atol * omega_ref`` [m s-1], each force
    integral ``atol * omega_ref * m_k`` [N s] (a momentum). Quadratures: the sweep's Fourier integrals of the forces
    [N] ``atol * omega_ref**2 * m_k``; the harmonic moments of the displacements [m s] ``atol / omega_ref``, of the
    forces ``atol * m_k`` [N s], of the squares [m2 s] ``1e-3 * atol / omega_ref`` (millimetre amplitudes).

    Parameters
    ----------
    atol : float
        Absolute tolerance of the displacements [m].
    omega_ref : float
        Angular frequency of the motion [rad s-1] (the excitation's, or the sweep's highest).
    masses : ndarray or float
        Effective mass of each stop [kg] (M2 for the paper's stop).
    quadratures : {'none', 'sweep', 'moments'}
        The states after the force integrals: none, the sweep's Fourier integrals, or the moments.
    size : int
        N, the number of coordinates.
    """
    masses = np.atleast_1d(np.asarray(masses, dtype=float))
    v = atol * omega_ref
    tolerances = [atol] * size + [v] * size + list(v * masses)
    if quadratures == "sweep":
        for mass in masses:
            tolerances += [v * omega_ref * mass] * 2
    elif quadratures == "moments":
        d = atol / omega_ref
        tolerances += [d] * (2 * size)
        for mass in masses:
            tolerances += [atol * mass] * 2
        tolerances += [1e-3 * d] * size
    elif quadratures != "none":
        raise ValueError(f"quadratures = {quadratures!r} is not allowed: use 'none', 'sweep' or 'moments'")
    return np.array(tolerances)


class BumperModel:
    """Residuals, Jacobians and events of each contact mode, and the right-hand side, of a structure with bumpers.

    Attributes
    ----------
    layout : FlowLayout
        Coordinates and flows (:mod:`..flow_layout`).
    k, b : ndarray, shape (K,)
        Bumper stiffness K_k [N m-1] and damping B_k [N s m-1] of each stop.
    size : int
        Number of states.
    """

    def __init__(self, problem: ImpactProblem, with_moments: bool) -> None:
        sweep = problem.excitation if isinstance(problem.excitation, SweptSine) else None
        if with_moments and sweep is not None:
            raise ValueError("harmonic moments are for a harmonic force, not a sweep")
        laws = [stop.law for stop in problem.stops]
        for index, law in enumerate(laws):
            if not isinstance(law, KelvinVoigtBumper):
                raise TypeError(f"stop {index}'s contact = {law!r} is not a KelvinVoigtBumper")
        self.problem, self.sweep = problem, sweep
        self.layout = layout = flow_layout(problem)
        n, count = layout.size, layout.stop_count
        self.stop_count, self.states = count, 2 * n
        self.quadratures = "sweep" if sweep is not None else "moments" if with_moments else "none"
        self.first_quadrature = 2 * n + count
        extra = {"none": 0, "sweep": 2 * count, "moments": quadrature_count(n, count)}[self.quadratures]
        self.size = 2 * n + count + extra
        self.k = np.array([law.stiffness(m) for law, m in zip(laws, layout.masses)])  # type: ignore[union-attr]
        self.b = np.array([law.damping(m) for law, m in zip(laws, layout.masses)])  # type: ignore[union-attr]
        #: [residual calls, step attempts (distinct residual times), last residual time]
        self.counter: list[float] = [0, 0, math.nan]
        if sweep is None:
            self._w0, self._half_alpha = problem.omega, 0.0
        else:  # theta(t) = t (w0 + pi alpha t), theta'(t) = w0 + 2 pi alpha t
            self._w0, self._half_alpha = 2.0 * math.pi * sweep.start_frequency, math.pi * sweep.alpha
        self.force_rows = np.hstack([self.k[:, None] * layout.gap_rows, self.b[:, None] * layout.normals])
        self.force_constants = self.k * layout.gap_constants
        self._mass = problem.structure.mass_matrix
        self._modes: dict[int, tuple[NDArray[np.float64], NDArray[np.float64]]] = {}

    # ------------------------------------------------------------------ modes
    def mode(self, mask: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(parameters, minus the Jacobian d f / d y without the moment rows' state dependence) of a mode."""
        mask = int(mask)
        if mask not in self._modes:
            layout = self.layout
            n, count = layout.size, self.stop_count
            active = tuple(k for k in range(count) if (mask >> k) & 1)
            a, c = layout.bumper_mode(self._mass, active, self.k, self.b)
            b = layout.free[2]
            kind = _KINDS[self.quadratures]
            parameters = pack_mode(n, count, self.size, mask, kind, self.sweep is not None, layout.omega, self._w0, self._half_alpha, a, c, b,
                                   self.force_rows, self.force_constants, layout.normals, layout.t, layout.t_inverse, layout.offset)
            jacobian = np.zeros((self.size, self.size))
            jacobian[: 2 * n, : 2 * n] = a
            for k in active:
                jacobian[2 * n + k, : 2 * n] = self.force_rows[k]
            self._modes[mask] = (parameters, -jacobian)
        return self._modes[mask]

    @property
    def rhs_calls(self) -> int:
        return int(self.counter[0])

    @property
    def steps(self) -> int:
        return int(self.counter[1])

    def force(self, y: NDArray[np.float64], stop: int = 0) -> float:
        """Bumper force of ``stop`` in contact, K_k u_k + B_k n_k . x' [N] (may be negative: then it releases)."""
        return float(force_kernel(np.ascontiguousarray(y, dtype=float), self.mode(0)[0], stop))

    def derivative(self, t: float, y: NDArray[np.float64], mask: int) -> NDArray[np.float64]:
        """f(t, y) of the mode ``mask`` (restarts, peaks, moments)."""
        f = np.empty(self.size)
        bumper_rhs(t, np.ascontiguousarray(y, dtype=float), f, self.mode(mask)[0])
        return f

    def deceleration(self, t: float, y: NDArray[np.float64], mask: int, stop: int) -> float:
        """-n_k . x'' [m s-2] in the mode ``mask``: the stopped coordinate's deceleration."""
        n = self.layout.size
        return float(-(self.layout.normals[stop] @ self.derivative(t, y, mask)[n : 2 * n]))

    def enters(self, t: float, y: NDArray[np.float64]) -> int:
        """The mode a run started in state y at time t begins in: the stops at or beyond their bumper (u >= 0) whose
        force is > 0. A force of exactly 0 (at rest on the bumper, as from rest with Delta = 0, or an elastic bumper
        touched at u = 0) is decided by the penetration's first non-zero time derivative in free flight: the onset
        event cannot see a penetration that is 0 at the start and then only rises, so a free start would go through
        the bumper. The derivatives follow y^(k+1) = A y^(k) + F^(k)(t) (a sweep's force is taken as harmonic at its
        instantaneous frequency and phase, exact to first order, which decides every start but a tie)."""
        layout = self.layout
        mask = 0
        for k in range(self.stop_count):
            if layout.penetration(y, k) < 0.0:
                continue
            force = self.force(y, k)
            if force > 0.0 or (force == 0.0 and self._rises(t, y, k)):
                mask |= 1 << k
        return mask

    def _rises(self, t: float, y: NDArray[np.float64], stop: int) -> bool:
        layout = self.layout
        n = layout.size
        a, c, b = layout.free
        if self.sweep is None:
            omega, angle, amplitude = self.problem.omega, self.problem.omega * t, b
        else:  # Re(b) sin(theta) = Re(b e^{j (theta - pi / 2)})
            omega, angle = self._w0 + 2.0 * self._half_alpha * t, t * (self._w0 + self._half_alpha * t) - 0.5 * math.pi
            amplitude = b.real.astype(complex)
        size = float(np.abs(a).max())
        rate = np.array(y[: 2 * n], dtype=float)
        scale = float(np.abs(rate).max()) + float(np.abs(c).max())
        forcing_scale = float(np.abs(amplitude).max())
        row = np.concatenate([layout.gap_rows[stop], np.zeros(n)])
        for order in range(6):
            forcing = (amplitude * complex(0.0, omega) ** order * complex(math.cos(angle), math.sin(angle))).real
            rate = a @ rate + forcing + (c if order == 0 else 0.0)  # y^(order + 1)
            scale = size * scale + forcing_scale * omega**order
            value = float(row @ rate)
            if abs(value) > 1e-12 * scale:
                return value > 0.0
        return False

    # ---------------------------------------------------- solver callbacks
    def residual(self, mask: int) -> Callable[..., None]:
        """The residual y' - f(t, y) of one mode (compiled kernel; counts calls and distinct times)."""
        parameters, counter = self.mode(mask)[0], self.counter

        def residual(t: float, y: NDArray[np.float64], yp: NDArray[np.float64], res: NDArray[np.float64]) -> None:
            counter[0] += 1
            if t != counter[2]:
                counter[1] += 1
                counter[2] = t
            bumper_residual(t, y, yp, res, parameters)

        return residual

    def jacobian(self, mask: int) -> Callable[..., None]:
        """d(res)/dy + cj d(res)/dy' = cj I - df/dy; exact but for the moment rows (their dependence on the state is
        left out, which only slows Newton's convergence on those rows, never the solution)."""
        minus = self.mode(mask)[1]
        identity = np.eye(self.size)
        n = self.layout.size
        q = self.first_quadrature
        active = [k for k in range(self.stop_count) if (mask >> k) & 1] if self.sweep is not None else []
        rows = self.force_rows
        w0, half_alpha = self._w0, self._half_alpha

        def jacobian(t: float, y: NDArray[np.float64], yp: NDArray[np.float64], res: NDArray[np.float64], cj: float, jj: NDArray[np.float64]) -> None:
            np.multiply(identity, cj, out=jj)
            jj += minus
            if active:  # rows of F_k cos(theta) theta' and F_k sin(theta) theta'
                theta, rate = t * (w0 + half_alpha * t), w0 + 2.0 * half_alpha * t
                c, s = math.cos(theta) * rate, math.sin(theta) * rate
                for k in active:
                    jj[q + 2 * k, : 2 * n] = -c * rows[k]
                    jj[q + 2 * k + 1, : 2 * n] = -s * rows[k]

        return jacobian

    def event_count(self, mask: int) -> int:
        """Event functions of a mode: one terminal per stop, then two recorded per stop in contact, one per free stop."""
        contact = bin(int(mask) & ((1 << self.stop_count) - 1)).count("1")
        return self.stop_count + 2 * contact + (self.stop_count - contact)

    def event_roles(self, mask: int) -> list[tuple[int, str]]:
        """(stop, role) of each event function of a mode: ``onset``, ``release``, ``apex``, ``rate``, ``jerk``."""
        roles = [(k, "release" if (mask >> k) & 1 else "onset") for k in range(self.stop_count)]
        for k in range(self.stop_count):
            roles += [(k, "rate"), (k, "jerk")] if (mask >> k) & 1 else [(k, "apex")]
        return roles

    def events(self, mask: int) -> Callable[..., None]:
        """The event function of one mode, with its ``terminal`` and ``direction`` attributes (:meth:`event_roles`;
        compiled kernel). The rates use the y' that IDA passes (its interpolant's derivative): a root of a rate is
        located to the solution's accuracy, and the peak values are then evaluated from the state at the root, where
        an error in the time only enters to second order."""
        parameters = self.mode(mask)[0]

        def events(t: float, y: NDArray[np.float64], yp: NDArray[np.float64], out: NDArray[np.float64]) -> None:
            bumper_events(t, y, yp, out, parameters)

        roles = self.event_roles(mask)
        events.terminal = [role in ("onset", "release") for _, role in roles]  # type: ignore[attr-defined]
        events.direction = [{"onset": 1, "release": 1, "apex": -1, "rate": -1, "jerk": 1}[role] for _, role in roles]  # type: ignore[attr-defined]
        return events
