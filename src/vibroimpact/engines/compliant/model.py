"""The Kelvin-Voigt bumper model (eq. 25, any structure and stops) as the compliant engines integrate it: residuals,
Jacobians and events of each contact mode.

Each stop k with a :class:`~vibroimpact.model.contact.KelvinVoigtBumper` pushes along -n_k with
lambda_k = K_k u_k + B_k n_k . x' while its penetration u_k = n_k . x - Delta_k >= 0 and lambda_k > 0 (eq. 25, the
bumper never pulls), K_k = m_k Omega_b^2 and B_k = 2 m_k xi_b Omega_b with the stop's effective mass m_k (M2 for the
paper's stop; a relative bumper acts on both bodies). The state is (w, v) of :mod:`..flow_layout` (the penetrations
in place of one coordinate each; (X1, X2 - Delta, X1', X2') for the paper's layout), the running integral of each
stop's force (impulses), then quadratures (:mod:`~vibroimpact.engines.compliant.model`): the harmonic moments of :mod:`..event_loop` when asked
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
from numba import njit
from numpy.typing import NDArray

from vibroimpact.engines.flow_layout import flow_layout
from vibroimpact.engines.numba_cache import stamp_with_callees
from vibroimpact.engines.rigid_kernels import pack_blocks, quadrature_count
from vibroimpact.model.contact import KelvinVoigtBumper
from vibroimpact.model.excitation import SweptSine
from vibroimpact.model.problem import ImpactProblem

__all__ = ["pack_mode", "bumper_rhs", "bumper_residual", "bumper_events", "force_kernel", "NONE", "SWEEP", "MOMENTS", "MODE_CONTACT", "BumperModel", "absolute_tolerances"]


# --------------------------------------------------------------------------------------------------------------------
# The bumper model of :mod:`~vibroimpact.engines.compliant.model` as compiled kernels over one flat parameter array per contact mode
# (:func:`pack_mode`): the right-hand side f(t, y) and the event functions, called by the residual and event callbacks
# the SUNDIALS solvers are given (each call from Python costs about as much as one line of Python arithmetic did,
# whatever the number of coordinates and stops).
# --------------------------------------------------------------------------------------------------------------------

#: Quadrature kinds.
NONE, SWEEP, MOMENTS = 0, 1, 2
_N, _K, _SIZE, _MASK, _QUAD, _SWEPT, _OMEGA, _W0, _HALF_ALPHA, _A, _C, _BR, _BI, _LAM, _LAM0, _NORMAL, _T, _TINV, _XOFF, _LENGTH = range(20)
_HEADER = 20


def pack_mode(n: int, k: int, size: int, mask: int, quadratures: int, swept: bool, omega: float, w0: float, half_alpha: float,
              a: NDArray[np.float64], c: NDArray[np.float64], b: NDArray[np.complex128], force_rows: NDArray[np.float64],
              force_constants: NDArray[np.float64], normals: NDArray[np.float64], t: NDArray[np.float64], t_inverse: NDArray[np.float64],
              offset: NDArray[np.float64]) -> NDArray[np.float64]:
    """The parameter array of one contact mode (``mask``: bit k set while stop k's bumper pushes).

    ``a``, ``c``, ``b``: the mode's flow y' = A y + c + forcing, forcing Re(b e^{jwt}) (harmonic, w = ``omega``) or
    Re(b) sin(theta(t)) (a sweep, theta = t (w0 + half_alpha t)); ``force_rows`` and ``force_constants``: the bumper
    force K_k u_k + B_k n_k . v of each stop as a row over (w, v) plus a constant [N].
    """
    blocks = [a.ravel(), c, b.real.copy(), b.imag.copy(), force_rows.ravel(), force_constants, normals.ravel(), t.ravel(), t_inverse.ravel(), offset]
    header = np.zeros(_HEADER)
    header[:_A] = n, k, size, mask, quadratures, float(swept), omega, w0, half_alpha
    return pack_blocks(header, _A, _LENGTH, blocks)


@njit(cache=True)
def force_kernel(y: NDArray[np.float64], p: NDArray[np.float64], stop: int) -> float:  # pragma: no cover - compiled
    """K_k u_k + B_k n_k . v [N]: the force stop ``stop``'s bumper exerts in contact (negative: it would pull)."""
    n2 = 2 * int(p[_N])
    row = int(p[_LAM]) + stop * n2
    value = p[int(p[_LAM0]) + stop]
    for j in range(n2):
        value += p[row + j] * y[j]
    return value


@njit(cache=True)
def bumper_rhs(t: float, y: NDArray[np.float64], f: NDArray[np.float64], p: NDArray[np.float64]) -> None:  # pragma: no cover - compiled
    """f(t, y) of the mode into ``f``."""
    n = int(p[_N])
    k_count = int(p[_K])
    n2 = 2 * n
    mask = int(p[_MASK])
    swept = p[_SWEPT] != 0.0
    a0, c0, br0, bi0 = int(p[_A]), int(p[_C]), int(p[_BR]), int(p[_BI])
    if swept:
        theta = t * (p[_W0] + p[_HALF_ALPHA] * t)
        c, s = math.cos(theta), math.sin(theta)
        for i in range(n2):
            acc = p[c0 + i] + p[br0 + i] * s
            for j in range(n2):
                acc += p[a0 + i * n2 + j] * y[j]
            f[i] = acc
    else:
        wt = p[_OMEGA] * t
        c, s = math.cos(wt), math.sin(wt)
        for i in range(n2):
            acc = p[c0 + i] + p[br0 + i] * c - p[bi0 + i] * s
            for j in range(n2):
                acc += p[a0 + i * n2 + j] * y[j]
            f[i] = acc
    quadratures = int(p[_QUAD])
    q = n2 + k_count
    for k in range(k_count):
        force = force_kernel(y, p, k) if (mask >> k) & 1 else 0.0
        f[n2 + k] = force
        if quadratures == 1:
            rate = force * (p[_W0] + 2.0 * p[_HALF_ALPHA] * t)
            f[q + 2 * k] = rate * c
            f[q + 2 * k + 1] = rate * s
        elif quadratures == 2:
            f[q + 2 * n + 2 * k] = force * c
            f[q + 2 * n + 2 * k + 1] = force * s
    if quadratures == 2:
        tinv, xoff = int(p[_TINV]), int(p[_XOFF])
        for i in range(n):
            x = p[xoff + i]
            for j in range(n):
                x += p[tinv + i * n + j] * y[j]
            f[q + 2 * i] = x * c
            f[q + 2 * i + 1] = x * s
            f[q + 2 * n + 2 * k_count + i] = x * x


@njit(cache=True)
def bumper_residual(t: float, y: NDArray[np.float64], yp: NDArray[np.float64], res: NDArray[np.float64], p: NDArray[np.float64]) -> None:  # pragma: no cover
    """The residual y' - f(t, y) into ``res``."""
    bumper_rhs(t, y, res, p)
    for i in range(res.size):
        res[i] = yp[i] - res[i]


@njit(cache=True)
def bumper_events(t: float, y: NDArray[np.float64], yp: NDArray[np.float64], out: NDArray[np.float64], p: NDArray[np.float64]) -> None:  # pragma: no cover
    """The mode's event functions: first one terminal event per stop (onset in flight, release in contact), then the
    recorded ones of each stop in turn (in flight its apex, n_k . v falling; in contact its force rate, falling,
    and the jerk of n_k . x, rising). Rates use the y' given (IDA's interpolant) for the accelerations."""
    n = int(p[_N])
    k_count = int(p[_K])
    n2 = 2 * n
    mask = int(p[_MASK])
    a0, normal, tt = int(p[_A]), int(p[_NORMAL]), int(p[_T])
    slot = k_count
    for k in range(k_count):
        row = int(p[_LAM]) + k * n2
        stiffness_part = p[int(p[_LAM0]) + k]
        for j in range(n):
            stiffness_part += p[row + j] * y[j]
        force = force_kernel(y, p, k)
        if (mask >> k) & 1:
            out[k] = -force
            # force rate: the stiffness row times w' = T v, the damping row times v' (IDA's)
            rate = 0.0
            for j in range(n):
                w_rate = 0.0
                for m in range(n):
                    w_rate += p[tt + j * n + m] * y[n + m]
                rate += p[row + j] * w_rate + p[row + n + j] * yp[n + j]
            # jerk of n . x: n . d(v')/dt with d(v')/dt = A_v (w', v') + the forcing's rate
            jerk = 0.0
            for i in range(n):
                weight = p[normal + k * n + i]
                if weight == 0.0:
                    continue
                acc = _forcing_rate(t, p, n + i)
                for j in range(n):
                    w_rate = 0.0
                    for m in range(n):
                        w_rate += p[tt + j * n + m] * y[n + m]
                    acc += p[a0 + (n + i) * n2 + j] * w_rate + p[a0 + (n + i) * n2 + n + j] * yp[n + j]
                jerk += weight * acc
            out[slot] = rate
            out[slot + 1] = jerk
            slot += 2
        else:
            # onset: K u short of the bumper; within its reach (u >= 0) the force it would exert (K u + B n . v)
            out[k] = force if stiffness_part >= 0.0 else stiffness_part
            speed = 0.0
            for j in range(n):
                speed += p[normal + k * n + j] * y[n + j]
            out[slot] = speed
            slot += 1


@njit(cache=True)
def _forcing_rate(t: float, p: NDArray[np.float64], i: int) -> float:  # pragma: no cover - compiled
    """d/dt of row i's forcing: -w (Re b sin + Im b cos)(wt), or Re b cos(theta) theta' for a sweep."""
    br, bi = p[int(p[_BR]) + i], p[int(p[_BI]) + i]
    if br == 0.0 and bi == 0.0:
        return 0.0
    if p[_SWEPT] != 0.0:
        theta = t * (p[_W0] + p[_HALF_ALPHA] * t)
        return br * math.cos(theta) * (p[_W0] + 2.0 * p[_HALF_ALPHA] * t)
    wt = p[_OMEGA] * t
    return -p[_OMEGA] * (br * math.sin(wt) + bi * math.cos(wt))

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


stamp_with_callees(globals())  # its kernels read no other module today; one that does is stamped with its source
