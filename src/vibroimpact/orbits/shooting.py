"""Shooting: periodic orbits as zeros of ``P^k(y) - y``, by damped Newton with the map's exact Jacobian.

The residual is measured in the map's scaled variables, ``r = (P^k(y) - y) / state_scale``. Each Newton step solves
``(dP^k/dy - I) dy = -(P^k(y) - y)`` and is damped by halving until ``|r|`` decreases (Armijo condition on the
2-norm). The Floquet multipliers are the eigenvalues of the monodromy ``dP^k/dy`` at the solution.

Sticking phases. While the absorber is stuck its position and velocity are pinned to the stop, so the map's Jacobian
loses rank (the multipliers include zeros: the stuck phase forgets those directions). That does not hurt Newton, whose
matrix is ``dP^k/dy - I``, singular only for a multiplier equal to 1. Orbits with sticking are therefore handled;
``ShootingSettings(allow_sticking=False)`` refuses them with a :class:`ShootingError` that says why, for callers that
need a map smooth in every direction (e.g. the continuation of a grazing point).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from vibroimpact.analysis.impact_orbit import ROOTS, ImpactOrbit, solve_impact_orbit
from vibroimpact.analysis.layout import closed_form_refusal
from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.structure import require_count, require_in_range, require_positive
from vibroimpact.orbits.branch import Iterated, MapEvaluation, ParametrisedMap, PeriodicOrbit

__all__ = ["ShootingSettings", "ShootingError", "shoot", "make_orbit", "parameter_derivative", "scaled_residual", "closed_form_state", "with_impulse", "section_phase"]

#: Finite-difference step for dP/dp, relative to max(|p|, parameter_scale): sqrt(eps) balances the O(h) truncation of
#: a one-sided difference against its O(eps / h) round-off, leaving ~sqrt(eps) ~ 1.5e-8 relative error. dP/dp only
#: steers Newton's corrector and the predictor (the points themselves are exact zeros of P(y) - y), and a one-sided
#: difference costs one map evaluation instead of two and can stay on one side of a grazing point.
FD_RELATIVE_STEP = float(np.sqrt(np.finfo(float).eps))


@dataclass(frozen=True)
class ShootingSettings:
    """How Newton's method looks for a fixed point of ``P^k``.

    Parameters
    ----------
    tolerance : float
        Converged when max |P^k(y) - y| / state_scale <= tolerance [-].
    max_iterations : int
        Newton iterations before giving up.
    min_damping : float
        Smallest step fraction of the line search before the iteration is declared stuck [-].
    allow_sticking : bool
        Accept orbits with sticking phases (see the module docstring); False raises ``ShootingError`` for them.
    """

    tolerance: float = 1e-11
    max_iterations: int = 40
    min_damping: float = 1.0 / 1024.0
    allow_sticking: bool = True

    def __post_init__(self) -> None:
        require_positive("tolerance", self.tolerance)
        require_in_range("max_iterations", self.max_iterations, 1, 10_000)
        require_in_range("min_damping", self.min_damping, 1e-12, 1.0)


class ShootingError(RuntimeError):
    """Newton's method did not find a periodic orbit; ``residual_history`` holds the scaled residual per iterate."""

    def __init__(self, message: str, residual_history: tuple[float, ...] = ()) -> None:
        history = ", ".join(f"{r:.3g}" for r in residual_history[-12:])
        super().__init__(f"{message} (scaled residual history: [{history}])" if residual_history else message)
        self.residual_history = residual_history


def scaled_residual(out: MapEvaluation, y: NDArray[np.float64], scale: NDArray[np.float64]) -> NDArray[np.float64]:
    """(P(y) - y) / scale."""
    return (out.image - y) / scale


def parameter_derivative(system: ParametrisedMap, y: NDArray[np.float64], p: NDArray[np.float64], index: int, out: MapEvaluation | None = None) -> NDArray[np.float64]:
    """dP/dp_index at (y, p): the map's own derivative if it gives one, else a one-sided difference.

    The step is ``FD_RELATIVE_STEP * max(|p_i|, parameter_scale_i)`` (see :data:`FD_RELATIVE_STEP`). Next to a grazing
    point the perturbed map can have another impact count (it is not differentiable across): then the difference is
    taken on the other side, halving the step until one side has ``out``'s impact count.
    """
    if out is not None and out.parameter_jacobian is not None:
        return np.asarray(out.parameter_jacobian)[:, index]
    if out is None:
        out = system.evaluate(y, p)
    step = FD_RELATIVE_STEP * max(abs(float(p[index])), float(system.parameter_scale[index]))
    signature = out.hybrid.signature if out.hybrid is not None else None
    for _ in range(30):
        for sign in (1.0, -1.0):
            moved = p.copy()
            moved[index] += sign * step
            other = system.evaluate(y, moved)
            if signature is None or (other.hybrid is not None and other.hybrid.signature == signature):
                return (other.image - out.image) / (moved[index] - p[index])
        step *= 0.5
    return (other.image - out.image) / (moved[index] - p[index])


def make_orbit(system: ParametrisedMap, y: NDArray[np.float64], p: NDArray[np.float64], out: MapEvaluation, history: tuple[float, ...] = ()) -> PeriodicOrbit:
    """The :class:`PeriodicOrbit` at a converged fixed point ``y`` whose evaluation is ``out``."""
    multipliers = np.linalg.eigvals(out.jacobian).astype(complex)
    multipliers = multipliers[np.argsort(-np.abs(multipliers), kind="stable")]
    residual = float(np.max(np.abs(scaled_residual(out, y, system.state_scale))))
    period = system.times if isinstance(system, Iterated) else 1
    return PeriodicOrbit(np.array(y, dtype=float), np.array(p, dtype=float), tuple(system.parameter_names), period, out.jacobian, multipliers, out.hybrid, residual, history)


def _solve(matrix: NDArray[np.float64], rhs: NDArray[np.float64]) -> NDArray[np.float64]:
    """Solve, falling back to least squares when the matrix is singular (a multiplier exactly 1)."""
    try:
        return np.linalg.solve(matrix, rhs)
    except np.linalg.LinAlgError:
        return np.linalg.lstsq(matrix, rhs, rcond=None)[0]


@suggest_keywords
def shoot(system: ParametrisedMap, guess: ArrayLike, parameters: ArrayLike, period: int = 1, settings: ShootingSettings = ShootingSettings()) -> PeriodicOrbit:
    """A period-``period`` orbit of ``system`` near ``guess``: a zero of ``P^k(y) - y`` by damped Newton.

    Parameters
    ----------
    system : ParametrisedMap
        The map P (e.g. the stroboscopic map of an impacting system over one excitation period,
        :class:`~vibroimpact.orbits.maps.ImpactMap`, or a bumper engine's compiled period,
        :class:`~vibroimpact.orbits.bumper_map.CompiledPeriodMap`).
    guess : array_like, shape (n,)
        Starting state (e.g. the closed-form one-impact orbit, or the previous point of a sweep).
    parameters : array_like, shape (m,)
        The parameter vector p.
    period : int
        k >= 1: the orbit repeats after k map iterations.
    settings : ShootingSettings
        Tolerance, iteration limit, line search and the sticking policy.

    Returns
    -------
    PeriodicOrbit
        The orbit with its monodromy, Floquet multipliers and hybrid information.

    Raises
    ------
    ShootingError
        No convergence (with the residual history), a non-finite map value, or a sticking orbit when
        ``settings.allow_sticking`` is False.
    """
    require_count("period", period, why=" (excitation periods)")
    p = np.array(parameters, dtype=float)
    y = np.array(guess, dtype=float)
    for name, values, size in (("guess", y, getattr(system, "dimension", y.size)), ("parameters", p, len(getattr(system, "parameter_names", p)))):
        if values.shape != (size,):
            raise ValueError(f"{name}: expected {size} values, got {values.tolist()!r}")
        if not np.all(np.isfinite(values)):  # said of the input, not as a map that failed; a failed seed's state is one
            raise ShootingError(f"the {name} is not finite: no orbit can be shot from it")
    mapping: ParametrisedMap = Iterated(system, period) if period != 1 else system
    scale = np.asarray(mapping.state_scale, dtype=float)
    identity = np.eye(y.size)
    out = mapping.evaluate(y, p)
    r = scaled_residual(out, y, scale)
    history = [float(np.max(np.abs(r)))]
    for iteration in range(settings.max_iterations + 1):  # every iterate checked, the last one too
        if not np.all(np.isfinite(r)):
            raise ShootingError("the map returned a non-finite state", tuple(history))
        if not np.all(np.isfinite(out.jacobian)):  # e.g. an impact at zero speed: its saltation matrix is singular
            raise ShootingError("the map's Jacobian is not finite (an impact at zero speed?)", tuple(history))
        if history[-1] <= settings.tolerance:
            if out.hybrid is not None and out.hybrid.sticks and not settings.allow_sticking:
                raise ShootingError(
                    f"the orbit found has {out.hybrid.sticks} sticking phase(s) per period: while stuck the map forgets the "
                    "absorber's position and velocity, so its Jacobian has rank < n and the orbit's smooth dependence on "
                    "them is lost; allow_sticking=True accepts such orbits (their multipliers include zeros)",
                    tuple(history),
                )
            return make_orbit(mapping, y, p, out, tuple(history))
        if iteration == settings.max_iterations:
            break
        step = _solve(out.jacobian - identity, -(out.image - y))
        norm = float(np.linalg.norm(r))
        damping = 1.0
        while True:
            trial = y + damping * step
            trial_out = mapping.evaluate(trial, p)
            trial_r = scaled_residual(trial_out, trial, scale)
            if np.all(np.isfinite(trial_r)) and np.linalg.norm(trial_r) <= (1.0 - 1e-4 * damping) * norm:
                break
            damping *= 0.5
            if damping < settings.min_damping:
                raise ShootingError(f"the line search failed: no step down to {settings.min_damping:g} of Newton's decreases the residual", tuple(history))
        y, out, r = trial, trial_out, trial_r
        history.append(float(np.max(np.abs(r))))
    raise ShootingError(f"no convergence in {settings.max_iterations} Newton iterations", tuple(history))


# --------------------------------------------------------------------------------------------------------------------
# Closed-form starts for shooting and continuation: the impact orbit's state at the strobe, another root, a strobe
# phase clear of the impacts.
# --------------------------------------------------------------------------------------------------------------------

@suggest_keywords
def closed_form_state(problem: ImpactProblem, orbit: ImpactOrbit | None = None, root: str = "+") -> NDArray[np.float64]:
    """The state (x, x') at t = 0 of ``problem``'s time on its closed-form impact orbit (any structure), shape (2N,).

    Parameters
    ----------
    problem : ImpactProblem
        One rigid stop, or a symmetric two-sided pair, on a structure without rigid-body modes, harmonic force.
    orbit : ImpactOrbit, optional
        A scalar orbit of this problem (solved with ``root`` when omitted).
    root : {'+', '-'}
        Which root of the impulse equation, when solving.

    Returns
    -------
    ndarray
        NaN where the orbit does not exist (no real root with J >= 0).
    """
    if orbit is None:
        orbit = solve_impact_orbit(problem, root=root)
    if not bool(np.all(orbit.exists)):
        return np.full(2 * problem.size, np.nan)
    return np.asarray(orbit.state_at(np.zeros(np.shape(orbit.omega) + (1,))), dtype=float).reshape(-1)


def with_impulse(solution: ImpactOrbit, impulse: ArrayLike) -> ImpactOrbit:
    """A closed-form orbit with another root J [N s] of its impulse equation (its phase follows from the impact
    conditions, eq. 15 with n^T H F, m_eff and chi_u)."""
    c = (1.0 / (solution.layout.effective_mass * (1.0 + solution.restitution)) + solution.chi_rate_before) / solution.omega
    a = solution.linear_amplitude
    delta = solution.clearance - solution.static_offset
    impulse = np.asarray(impulse, dtype=float)
    phase = np.arctan2(-impulse * c / a, (delta + impulse * solution.chi0) / a)
    return dataclasses.replace(solution, impulse=impulse, phase=np.asarray(phase, dtype=float), exists=np.asarray(impulse >= 0.0))


def section_phase(problem: ImpactProblem, frequencies: ArrayLike, clearances: ArrayLike | None = None, amplitudes: ArrayLike | None = None) -> float:
    """A force phase [rad] that keeps the strobe (t = 0 mod T) away from the closed-form orbits' impacts.

    Where an impact crosses the strobe time the fixed point of the stroboscopic map jumps between the states just
    before and just after it, and a continuation cannot follow. The impact instants of both roots of the impulse
    equation (both stops' impacts, T/2 apart, for a two-sided stop), as fractions of the period, are found over
    ``frequencies`` [Hz] from the closed form; the phase puts the strobe in the middle of the widest gap between them.
    Use it as the problem's force phase (``dataclasses.replace(problem.harmonic, phase=...)``). ``clearances`` and
    ``amplitudes`` (broadcast against ``frequencies``; the problem's when omitted) cover a continuation in those
    parameters. 0 where no closed form applies (start
    from a simulated state and :func:`vibroimpact.orbits.maps.resection` instead) or no orbit exists.
    """
    f = np.asarray(frequencies, dtype=float)
    if closed_form_refusal(problem) is not None:
        return 0.0
    fractions = []
    for root in ROOTS:
        orbit = solve_impact_orbit(problem, omega=2.0 * np.pi * f, clearance=clearances, restitution=None, amplitude=amplitudes, root=root)
        # the impact time includes the problem's phase: measure it against a force of phase 0
        base = ((orbit.impact_time + problem.phase / orbit.omega) / orbit.period) % 1.0
        fractions.append(base[orbit.exists])
        if orbit.two_sided:
            fractions.append((base[orbit.exists] + 0.5) % 1.0)
    points = np.sort(np.concatenate(fractions))
    if points.size == 0:
        return 0.0
    gaps = np.diff(np.concatenate([points, [points[0] + 1.0]]))
    k = int(np.argmax(gaps))
    return float(2.0 * np.pi * ((points[k] + 0.5 * gaps[k]) % 1.0))
