"""An integrator of the paper's 2-DOF absorber on a rigid stop, independent of the package's code (numpy and scipy
only: nothing of vibroimpact is imported here), to confirm the package's design answers.

The model, written from its statement alone:

* primary m1 on spring k1 and dashpot b1 to the base, absorber m2 coupled to it by k2, b2;
* the harmonic force F cos(omega t + phase) on the primary (the package's convention, HarmonicForce: q cos(2 pi f t
  + phase); with phase = -pi/2 it is F sin(omega t)); the strobes are at t = k T, T = 2 pi / omega;
* a rigid stop, momentary impacts with Newton's restitution R (0 <= R <= 1). Two layouts:

  - ``"absolute"`` (the paper's, and the package's ``Stop(coordinate=1, other=None, side='upper')``): a stop on the
    base bounds the absorber, x2 <= clearance. At impact x2' -> -R x2' (impulse m2 (1 + R) v on the absorber from
    the base: the momentum of m1 + m2 is *not* conserved, the base takes it); x1, x2, x1' are continuous.
    While stuck (x2 = clearance, x2' = 0) the stop holds the absorber with H = k2 (x1 - clearance) + b2 x1' >= 0
    and the primary moves alone; the absorber leaves when H falls through 0.
  - ``"relative"``: a stop carried by the primary bounds x2 - x1 <= clearance. At impact the relative velocity
    u = x2' - x1' -> -R u and the momentum m1 x1' + m2 x2' is conserved. While stuck the two masses move as one,
    m1 + m2 on k1, b1; the contact force H = -(k2 clearance + m2 a) with a = (F(t) - k1 x1 - b1 x1') / (m1 + m2)
    must stay >= 0; they separate when H falls through 0.

* chattering: an impact whose approach speed is at most ``sticking_velocity`` (or any impact with R = 0) ends in
  sticking if the stop must push to hold the contact (H > 0); otherwise the bounce is applied as it is.

scipy.integrate.solve_ivp (DOP853 by default, rtol 1e-11, atol 1e-15 on positions, 1e-13 on velocities) integrates
one excitation period at a time; a terminal event on the gap (rising through a penetration of 1e-13 clearance, far
above the round-off of a state put on the stop, so that a restart there finds no root at its own start) stops it at
each impact, the impact map is applied (the stopped coordinate put exactly on the stop) and the integration restarts
there. The step is limited (``max_step``, T / 32 by default) so that a near-grazing contact is less likely to be
stepped over (roots are found only as sign changes between steps: a grazing touch shorter than a step can still be
missed; no extremum check is made). An impact's time is accurate to ~1e-10 s plus 1e-17 m over its approach speed.

API (for further tests): ``Params(m1, m2, k1, k2, b1, b2, F, clearance, R, phase=0.0, layout="absolute")``;
``settle(params, frequency_Hz, start_state, transient_periods, measured_periods, **options) -> Settled``;
``run_periods(params, frequency_Hz, start_state, periods, harmonics=True)`` (settle without a transient);
``linear_receptance``, ``linear_x1_amplitude``, ``linear_steady_state``; ``detect_period(strobe_states)``.

Per period, the first Fourier harmonic of x1 is computed from the dense output by Gauss-Legendre quadrature on each
smooth piece (between impacts / releases, subdivided to at most T / 16): a = (2/T) int x1 cos(wt), b = (2/T) int x1
sin(wt), |X1| = sqrt(a^2 + b^2).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields

import numpy as np
from numpy.typing import NDArray
from scipy.integrate import solve_ivp

__all__ = [
    "Params",
    "ImpactRecord",
    "Settled",
    "as_params",
    "linear_receptance",
    "linear_x1_amplitude",
    "linear_steady_state",
    "run_periods",
    "settle",
    "detect_period",
]

ABSOLUTE, RELATIVE = "absolute", "relative"


@dataclass(frozen=True)
class Params:
    """The structure [kg, N/m, N s/m], force amplitude F [N] and phase [rad], the stop (clearance [m], restitution R)."""

    m1: float
    m2: float
    k1: float
    k2: float
    b1: float
    b2: float
    F: float
    clearance: float
    R: float
    phase: float = 0.0
    layout: str = ABSOLUTE

    def __post_init__(self) -> None:
        if self.layout not in (ABSOLUTE, RELATIVE):
            raise ValueError(f"layout = {self.layout!r}: use {ABSOLUTE!r} or {RELATIVE!r}")
        if not 0.0 <= self.R <= 1.0:
            raise ValueError(f"R = {self.R!r} outside [0, 1]")


def as_params(params: Params | Mapping) -> Params:
    """``params`` itself, or a Params from a mapping with its field names."""
    if isinstance(params, Params):
        return params
    names = {f.name for f in fields(Params)}
    return Params(**{k: v for k, v in params.items() if k in names})


@dataclass
class ImpactRecord:
    """One impact: time [s], the state (x1, x2, x1', x2') just before and just after, the approach speed (> 0) of the
    stopped coordinate, whether it ended in sticking, the impulse on the absorber from the stop [N s] (negative:
    the stop pushes the absorber back) and the gap at the event (its residual, ~1e-15)."""

    t: float
    before: NDArray[np.float64]
    after: NDArray[np.float64]
    approach: float
    sticks: bool
    impulse: float
    gap_residual: float


@dataclass
class Settled:
    """What :func:`settle` measured over the measured periods.

    x1_amplitudes : (n,) per-period |X1| [m] (first harmonic of x1 over each period).
    x1_harmonics : (n,) complex a - j b per period [m] (x1 ~ Re(c e^{j w t}), c = a - j b).
    strobe_times, strobe_states : (n + 1,), (n + 1, 4): t = k T and (x1, x2, x1', x2') there, from the first
        measured period's start to the end.
    impacts_per_period : (n,) int.
    impacts : every ImpactRecord in the measured periods.
    transient_impacts : the transient's ImpactRecords (for the impact-law test).
    transient_strobe_states : (transient + 1, 4) the strobes of the transient, from t = 0 (its last row is
        strobe_states[0]).
    releases : (time) of every release from sticking in the measured periods.
    sticking_time : total time spent stuck in the measured periods [s].
    period : T [s].
    """

    x1_amplitudes: NDArray[np.float64]
    x1_harmonics: NDArray[np.complex128]
    strobe_times: NDArray[np.float64]
    strobe_states: NDArray[np.float64]
    impacts_per_period: NDArray[np.int64]
    impacts: list[ImpactRecord] = field(default_factory=list)
    transient_impacts: list[ImpactRecord] = field(default_factory=list)
    releases: list[float] = field(default_factory=list)
    sticking_time: float = 0.0
    period: float = math.nan
    transient_strobe_states: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 4)))

    @property
    def end_state(self) -> NDArray[np.float64]:
        return self.strobe_states[-1].copy()


# ---------------------------------------------------------------------------------------------------------- linear


def _matrices(p: Params) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    m = np.array([[p.m1, 0.0], [0.0, p.m2]])
    c = np.array([[p.b1 + p.b2, -p.b2], [-p.b2, p.b2]])
    k = np.array([[p.k1 + p.k2, -p.k2], [-p.k2, p.k2]])
    return m, c, k


def linear_receptance(params: Params | Mapping, omega: float) -> NDArray[np.complex128]:
    """H(omega) = (K - omega^2 M + j omega C)^-1, the 2 x 2 receptance matrix [m/N]."""
    m, c, k = _matrices(as_params(params))
    return np.linalg.inv(k - omega**2 * m + 1j * omega * c)


def linear_x1_amplitude(params: Params | Mapping, frequency_hz: float) -> float:
    """|X1| = F |H11(omega)| of the contact-free steady state [m]."""
    p = as_params(params)
    return float(p.F * abs(linear_receptance(p, 2.0 * math.pi * frequency_hz)[0, 0]))


def linear_steady_state(params: Params | Mapping, frequency_hz: float, t: float = 0.0) -> NDArray[np.float64]:
    """(x1, x2, x1', x2') of the contact-free steady state at time t: x = Re(H f e^{j(wt + phase)}), f = (F, 0)."""
    p = as_params(params)
    w = 2.0 * math.pi * frequency_hz
    amplitude = linear_receptance(p, w)[:, 0] * p.F * np.exp(1j * (w * t + p.phase))
    return np.concatenate([amplitude.real, (1j * w * amplitude).real])


# ---------------------------------------------------------------------------------------------------------- dynamics


class _Model:
    def __init__(self, p: Params, frequency_hz: float) -> None:
        self.p = p
        self.omega = 2.0 * math.pi * frequency_hz
        self.period = 1.0 / frequency_hz

    def force(self, t: float) -> float:
        return self.p.F * math.cos(self.omega * t + self.p.phase)

    # free flight: y = (x1, x2, v1, v2)
    def free_rhs(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        p = self.p
        x1, x2, v1, v2 = y
        coupling = p.k2 * (x2 - x1) + p.b2 * (v2 - v1)
        a1 = (self.force(t) - p.k1 * x1 - p.b1 * v1 + coupling) / p.m1
        a2 = -coupling / p.m2
        return np.array([v1, v2, a1, a2])

    def gap(self, y: NDArray[np.float64]) -> float:
        """Signed gap, <= 0 allowed."""
        if self.p.layout == ABSOLUTE:
            return float(y[1] - self.p.clearance)
        return float(y[1] - y[0] - self.p.clearance)

    def approach(self, y: NDArray[np.float64]) -> float:
        return float(y[3]) if self.p.layout == ABSOLUTE else float(y[3] - y[2])

    # stuck: y = (x1, v1); full state rebuilt by full_stuck
    def stuck_rhs(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        p = self.p
        x1, v1 = y
        if p.layout == ABSOLUTE:
            a1 = (self.force(t) - p.k1 * x1 - p.b1 * v1 + p.k2 * (p.clearance - x1) - p.b2 * v1) / p.m1
        else:
            a1 = (self.force(t) - p.k1 * x1 - p.b1 * v1) / (p.m1 + p.m2)
        return np.array([v1, a1])

    def holding_force(self, t: float, y: NDArray[np.float64]) -> float:
        """Force the stop must exert to keep the contact closed (> 0: pushed into the stop, stays stuck)."""
        p = self.p
        x1, v1 = y[0], y[1] if len(y) == 2 else y[2]
        if p.layout == ABSOLUTE:
            return float(p.k2 * (x1 - p.clearance) + p.b2 * v1)
        a = (self.force(t) - p.k1 * x1 - p.b1 * v1) / (p.m1 + p.m2)
        return float(-(p.k2 * p.clearance + p.m2 * a))

    def full_stuck(self, y: NDArray[np.float64]) -> NDArray[np.float64]:
        x1, v1 = y
        if self.p.layout == ABSOLUTE:
            return np.array([x1, self.p.clearance, v1, 0.0])
        return np.array([x1, x1 + self.p.clearance, v1, v1])

    def project(self, y: NDArray[np.float64]) -> NDArray[np.float64]:
        """y with the stopped coordinate put exactly on the stop."""
        out = y.copy()
        out[1] = self.p.clearance if self.p.layout == ABSOLUTE else y[0] + self.p.clearance
        return out

    def bounce(self, y: NDArray[np.float64], sticks: bool) -> tuple[NDArray[np.float64], float]:
        """State after the impact and the impulse on the absorber [N s]."""
        p = self.p
        out = y.copy()
        if p.layout == ABSOLUTE:
            out[1] = p.clearance
            out[3] = 0.0 if sticks else -p.R * y[3]
            return out, p.m2 * (out[3] - y[3])
        u = y[3] - y[2]
        u_after = 0.0 if sticks else -p.R * u
        total = p.m1 + p.m2
        vc = (p.m1 * y[2] + p.m2 * y[3]) / total
        out[2] = vc - p.m2 / total * u_after
        out[3] = vc + p.m1 / total * u_after
        out[1] = y[0] + p.clearance
        return out, p.m2 * (out[3] - y[3])


# ---------------------------------------------------------------------------------------------------------- run

_GL_NODES, _GL_WEIGHTS = np.polynomial.legendre.leggauss(16)


def _harmonic_piece(sol, t0: float, t1: float, omega: float, max_piece: float, index: int) -> complex:
    """int_{t0}^{t1} x_index(t) e^{-j w t} dt by Gauss-Legendre on sub-intervals of at most max_piece."""
    if t1 <= t0:
        return 0.0j
    n = max(1, math.ceil((t1 - t0) / max_piece))
    edges = np.linspace(t0, t1, n + 1)
    half = 0.5 * np.diff(edges)
    mid = 0.5 * (edges[:-1] + edges[1:])
    times = (mid[:, None] + half[:, None] * _GL_NODES[None, :]).ravel()
    weights = (half[:, None] * _GL_WEIGHTS[None, :]).ravel()
    x = sol(times)[index]
    return complex(np.sum(weights * x * np.exp(-1j * omega * times)))


class _Runner:
    def __init__(self, p: Params, frequency_hz: float, rtol: float, atol: float, method: str, max_step: float | None,
                 sticking_velocity: float, max_impacts_per_period: int) -> None:  # fmt: skip
        self.model = _Model(p, frequency_hz)
        self.rtol, self.method = rtol, method
        self.atol_free = np.array([atol, atol, atol * 100.0, atol * 100.0])
        self.atol_stuck = self.atol_free[[0, 2]]
        self.max_step = self.model.period / 32.0 if max_step is None else max_step
        self.sticking_velocity = sticking_velocity
        self.max_impacts = max_impacts_per_period
        self.stuck = False

        model = self.model

        # the event fires at a penetration of 1e-13 clearance (1e-17 m for 0.1 mm): far above the round-off of a
        # state put on the stop (a few ulps of x2), so a restart there (after a plastic impact, a touch or a
        # release, gap'' <= 0) cannot find a spurious root at its own start and loop without advancing
        offset = 1e-13 * max(abs(p.clearance), 1e-6)
        self.gap_offset = offset

        def gap_event(t: float, y: NDArray[np.float64]) -> float:
            return model.gap(y) - offset

        gap_event.terminal, gap_event.direction = True, 1.0  # type: ignore[attr-defined]

        def release_event(t: float, y: NDArray[np.float64]) -> float:
            return model.holding_force(t, y)

        release_event.terminal, release_event.direction = True, -1.0  # type: ignore[attr-defined]
        self.gap_event, self.release_event = gap_event, release_event

    def one_period(self, t_start: float, state: NDArray[np.float64], harmonic: bool):
        """Integrate [t_start, t_start + T]: end state, c = (2/T) int x1 e^{-jwt}, impacts, releases, stuck time."""
        model = self.model
        t_end = t_start + model.period
        t, y = t_start, np.array(state, dtype=float)
        impacts: list[ImpactRecord] = []
        releases: list[float] = []
        stuck_time = 0.0
        moment = 0.0j
        piece = model.period / 16.0
        stalled = 0
        while True:
            if t >= t_end - 1e-14 * model.period:
                break
            if self.stuck:
                sol = solve_ivp(model.stuck_rhs, (t, t_end), y[[0, 2]], method=self.method,
                                rtol=self.rtol, atol=self.atol_stuck, max_step=self.max_step, events=self.release_event,
                                dense_output=harmonic)  # fmt: skip
                if sol.status < 0:
                    raise RuntimeError(f"solve_ivp failed while stuck at t = {t!r}: {sol.message}")
                t_next = float(sol.t[-1])
                if harmonic:
                    moment += _harmonic_piece(sol.sol, t, t_next, model.omega, piece, 0)
                stuck_time += t_next - t
                y = model.full_stuck(sol.y[:, -1])
                if sol.status == 1:  # released
                    releases.append(t_next)
                    self.stuck = False
                t = t_next
                continue
            sol = solve_ivp(model.free_rhs, (t, t_end), y, method=self.method, rtol=self.rtol, atol=self.atol_free,
                            max_step=self.max_step, events=self.gap_event, dense_output=harmonic)  # fmt: skip
            if sol.status < 0:
                raise RuntimeError(f"solve_ivp failed at t = {t!r}: {sol.message}")
            t_next = float(sol.t[-1])
            if harmonic:
                moment += _harmonic_piece(sol.sol, t, t_next, model.omega, piece, 0)
            y = sol.y[:, -1].copy()
            t = t_next
            if t_next - t <= 1e-12 * model.period:
                stalled += 1
                if stalled > 1000:
                    raise RuntimeError(f"no progress at t = {t!r} (state {y!r}): 1000 events in a row at the same time")
            else:
                stalled = 0
            if sol.status == 1:  # impact
                v = model.approach(y)
                if v <= 0.0:  # a touch: put back on the stop, nothing else
                    y = model.project(y)
                    continue
                chattering = v <= self.sticking_velocity or model.p.R == 0.0 or len(impacts) >= self.max_impacts  # exact: R = 0 is a parsed input (a plastic stop)
                sticks = chattering and model.holding_force(t, y) > 0.0
                after, impulse = model.bounce(y, sticks)
                impacts.append(ImpactRecord(t, y.copy(), after.copy(), v, sticks, impulse, model.gap(y)))
                y = after
                if sticks:
                    self.stuck = True
        if self.stuck and len(y) == 2:
            y = model.full_stuck(y)
        return y, 2.0 / model.period * moment, impacts, releases, stuck_time


def run_periods(params: Params | Mapping, frequency_hz: float, start_state, periods: int, harmonics: bool = True, *,
                rtol: float = 1e-11, atol: float = 1e-15, method: str = "DOP853", max_step: float | None = None,
                sticking_velocity: float = 1e-6, max_impacts_per_period: int = 10_000) -> Settled:  # fmt: skip
    """Integrate ``periods`` periods from ``start_state`` (x1, x2, x1', x2') at t = 0 and measure every one of them."""
    return settle(params, frequency_hz, start_state, 0, periods, harmonics_in_transient=False, rtol=rtol, atol=atol, method=method,
                  max_step=max_step, sticking_velocity=sticking_velocity, max_impacts_per_period=max_impacts_per_period,
                  harmonics=harmonics)  # fmt: skip


def settle(params: Params | Mapping, frequency_hz: float, start_state, transient_periods: int, measured_periods: int, *,
           rtol: float = 1e-11, atol: float = 1e-15, method: str = "DOP853", max_step: float | None = None,
           sticking_velocity: float = 1e-6, max_impacts_per_period: int = 10_000, harmonics: bool = True,
           harmonics_in_transient: bool = False) -> Settled:  # fmt: skip
    """From ``start_state`` (x1, x2, x1', x2') [m, m/s] at t = 0, drop ``transient_periods`` periods, then measure
    ``measured_periods`` periods: per-period fundamental |X1|, strobes at t = k T (k = transient ... transient +
    measured), impacts. A start state on the stop with the stop pushing (holding force > 0, zero approach speed) is
    integrated free: the first impact event decides."""
    p = as_params(params)
    runner = _Runner(p, frequency_hz, rtol, atol, method, max_step, sticking_velocity, max_impacts_per_period)
    period = runner.model.period
    state = np.array(start_state, dtype=float).reshape(4)
    transient_impacts: list[ImpactRecord] = []
    transient_strobes = np.zeros((transient_periods + 1, 4))
    transient_strobes[0] = state
    for k in range(transient_periods):
        state, _, impacts, _, _ = runner.one_period(k * period, state, harmonics_in_transient)
        transient_impacts.extend(impacts)
        transient_strobes[k + 1] = state
    n = measured_periods
    strobes = np.zeros((n + 1, 4))
    strobes[0] = state
    coefficients = np.zeros(n, dtype=complex)
    counts = np.zeros(n, dtype=np.int64)
    all_impacts: list[ImpactRecord] = []
    all_releases: list[float] = []
    stuck_total = 0.0
    for i in range(n):
        k = transient_periods + i
        state, c, impacts, releases, stuck = runner.one_period(k * period, state, harmonics)
        strobes[i + 1] = state
        coefficients[i] = c
        counts[i] = len(impacts)
        all_impacts.extend(impacts)
        all_releases.extend(releases)
        stuck_total += stuck
    times = (transient_periods + np.arange(n + 1)) * period
    return Settled(np.abs(coefficients), coefficients, times, strobes, counts, all_impacts, transient_impacts, all_releases, stuck_total, period,
                   transient_strobes)


def detect_period(strobe_states: NDArray[np.float64], max_period: int = 32, rtol: float = 1e-6) -> int:
    """The least k (<= max_period) with strobe[i + k] = strobe[i] for every i of the record (positions to rtol of
    the largest |position|, velocities to rtol of the largest |velocity|); 0 if none."""
    s = np.asarray(strobe_states)
    scale = np.concatenate([np.full(2, np.max(np.abs(s[:, :2]))), np.full(2, np.max(np.abs(s[:, 2:])))])
    scale = np.where(scale > 0.0, scale, 1.0)
    for k in range(1, min(max_period, s.shape[0] - 1) + 1):
        if np.all(np.abs(s[k:] - s[:-k]) <= rtol * scale):
            return k
    return 0
