"""Closed-form impact orbits of any linear structure: one impact per period on one rigid stop, or the symmetric
two impacts per period on a two-sided stop (derivation of the latter in :func:`vibroimpact.analysis.two_sided.solve_two_impacts`, public as
:func:`vibroimpact.solve_two_impacts`).

The structure ``M x'' + C x' + K x = Re(F e^{jwt}) + F0 - n lambda(t)`` has its stop's coordinate u = n . x (n the
stop's normal: e_i, -e_i, +-(e_i - e_j)) and gap Delta - u. With time measured from an (upper) impact, u(0) = Delta,
and the impulses J acting along -n, the motion is the linear steady state plus the response to the impulse train::

    x(t) = Re(H F e^{j(wt + phi - theta)}) + K^-1 F0 - J chi(t),      u(t) = a cos(wt + phi) + u_s - J chi_u(t)

with H = (K - w^2 M + jwC)^-1, a e^{j theta} = n^T H F (replaces the paper's q H12), u_s = n^T K^-1 F0, chi the
periodic Green function of H(s) n (every coordinate) and chi_u = n . chi, whose transform is n^T H(s) n (replaces
H22). The velocity of u jumps by -J n^T M^-1 n = -J / m_eff at an impact (1/m_eff replaces 1/M2), so chi_u'(0+) -
chi_u'(0-) = 1/m_eff. The impact conditions u(0) = Delta and J = m_eff (1 + R) u'(0-) give the paper's eqs. 15-16
with M2 -> m_eff and Delta -> Delta - u_s::

    sin(phi) = -J c / a,   cos(phi) = (Delta - u_s + J chi0) / a,   c = [1 / (m_eff (1 + R)) + chi_u'(0-)] / w
    (c^2 + chi0^2) J^2 + 2 (Delta - u_s) chi0 J + (Delta - u_s)^2 - a^2 = 0

For the two-sided stop chi becomes the antiperiodic psi (impulses +-J every T/2, :mod:`~vibroimpact.analysis.greens`) and u_s = 0.
Everything is vectorised over (frequency, clearance, restitution, amplitude) arrays; :func:`solve_impact_orbit` is
the solver, :class:`ImpactOrbit` the solution with reconstruction, admissibility, harmonics and states.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike, NDArray

from vibroimpact.analysis.floquet import floquet_multipliers
from vibroimpact.analysis.greens import GREEN_CONDITION_LIMIT, green_condition, green_vector, periodic_green
from vibroimpact.analysis.layout import ClosedFormLayout, closed_form_layout, harmonic_load
from vibroimpact.analysis.linear import base_force as suspension_force
from vibroimpact.analysis.paper_fit import PaperFit
from vibroimpact.model.excitation import angular_frequency, check_closed_form_inputs
from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.model.modal import ModalResponse, impulse_modes
from vibroimpact.model.problem import ImpactProblem, ProblemLike, problem_of

__all__ = ["ImpactOrbit", "solve_impact_orbit", "closed_form_problem", "impulse_roots", "ROOTS"]

#: The two roots of the impulse equation: '+' (the paper's, the one that is stable where either is) and '-'.
ROOTS = ("+", "-")


def impulse_roots(a: NDArray, b: NDArray, discriminant: NDArray, constant: NDArray, root: str = "+") -> NDArray[np.float64]:
    """A root of ``a J^2 + 2 b J + constant = 0`` without cancellation; NaN where the discriminant < 0.

    ``discriminant`` is ``b^2 - a * constant`` computed by the caller without cancellation. '+' is (-b + sqrt)/a,
    '-' is (-b - sqrt)/a, each taken from the conjugate form where the direct one would cancel.
    """
    if root not in ROOTS:
        raise ValueError(f"root = {root!r}: allowed {list(ROOTS)}")
    with np.errstate(invalid="ignore", divide="ignore"):
        r = np.sqrt(discriminant)
        if root == "+":
            impulse = np.where(b >= 0.0, np.where(r + b > 0.0, -constant / (r + b), 0.0), (-b + r) / a)
        else:
            impulse = np.where(b > 0.0, (-b - r) / a, np.where(r - b > 0.0, constant / (r - b), 0.0))
    return np.where(discriminant >= 0.0, impulse, np.nan)


@suggest_keywords
@dataclass(frozen=True, eq=False)
class ImpactOrbit:
    """Closed-form impact orbits at a set of points (arrays share one broadcast shape S).

    Attributes
    ----------
    layout : ClosedFormLayout
        Structure, normal n, stop indices, m_eff; ``layout.two_sided`` for the symmetric pair.
    omega, clearance, restitution, amplitude : ndarray, shape S
        w [rad s-1], Delta [m], R [-], q [N] (or base amplitude [m]).
    load : ndarray of complex, shape S + (N,)
        F: the harmonic load per coordinate in the problem's time [N].
    response : ndarray of complex, shape S + (N,)
        H F: the linear steady state's complex amplitudes [m].
    impulse_response : ndarray of complex, shape S + (N,)
        H n: response to a unit harmonic force along n [m N-1].
    static : ndarray, shape (N,)
        K^-1 F0 [m].
    impulse : ndarray, shape S
        J [N s] of each impact (NaN where no orbit exists).
    phase : ndarray, shape S
        phi [rad]: u's linear part is a cos(w t + phi) with t from the impact.
    exists : ndarray of bool, shape S
        A real root with J >= 0 where the closed form is well-conditioned (:attr:`conditioned`).
    chi0, chi_rate_before : ndarray, shape S
        chi_u(0) [m N-1 s-1] and chi_u'(0-) [m N-1 s-2] (psi for the two-sided stop).
    modes : ModalResponse
        Poles and residues of H(s) n.
    condition : ndarray, shape S
        kappa of the Green function sums [-] (:func:`~vibroimpact.analysis.greens.green_condition`): beyond
        :data:`~vibroimpact.analysis.greens.GREEN_CONDITION_LIMIT` (within ~1.6e-5 relative of an undamped natural
        frequency) the orbit is not evaluated: ``exists`` is False and J, phi are NaN there, whatever the root.
    """

    layout: ClosedFormLayout
    omega: NDArray[np.float64]
    clearance: NDArray[np.float64]
    restitution: NDArray[np.float64]
    amplitude: NDArray[np.float64]
    load: NDArray[np.complex128]
    response: NDArray[np.complex128]
    impulse_response: NDArray[np.complex128]
    static: NDArray[np.float64]
    impulse: NDArray[np.float64]
    phase: NDArray[np.float64]
    exists: NDArray[np.bool_]
    chi0: NDArray[np.float64]
    chi_rate_before: NDArray[np.float64]
    modes: ModalResponse
    condition: NDArray[np.float64]

    # --------------------------------------------------------------- scalars
    @property
    def frequency(self) -> NDArray[np.float64]:
        """f = w / (2 pi) [Hz], the excitation frequency of every point (:attr:`omega` is w [rad s-1])."""
        return self.omega / (2.0 * np.pi)

    @cached_property
    def multipliers(self) -> NDArray[np.complex128]:
        """Floquet multipliers [-] of every orbit, shape S + (2N,), sorted by decreasing modulus; NaN where no orbit
        exists (:func:`~vibroimpact.analysis.floquet.floquet_multipliers`; computed once, on first use)."""
        return floquet_multipliers(self)

    @property
    def stable(self) -> NDArray[np.bool_]:
        """True where the orbit exists and every Floquet multiplier lies inside the unit circle, |mu| < 1, shape S
        (admissibility is :meth:`admissible`; an orbit that penetrates a stop is no motion, whatever its multipliers)."""
        moduli = np.abs(self.multipliers)
        return self.exists & np.all(np.isfinite(moduli), axis=-1) & np.all(np.nan_to_num(moduli, nan=np.inf) < 1.0, axis=-1)

    @property
    def conditioned(self) -> NDArray[np.bool_]:
        """Where the closed form is evaluated: condition <= GREEN_CONDITION_LIMIT (False where the sums are
        ill-conditioned, near an undamped natural frequency; the orbit there is unknown, not absent)."""
        return self.condition <= GREEN_CONDITION_LIMIT

    @property
    def two_sided(self) -> bool:
        """The symmetric two-impacts orbit (impacts alternate between the upper and lower stop every T/2)."""
        return self.layout.two_sided

    @property
    def normal(self) -> NDArray[np.float64]:
        """n of the (upper) stop."""
        return self.layout.normal

    @property
    def period(self) -> NDArray[np.float64]:
        """T = 2 pi / w [s]."""
        return 2.0 * np.pi / self.omega

    @property
    def window(self) -> NDArray[np.float64]:
        """Time between impacts [s]: T, or T/2 for the two-sided stop."""
        return self.period / 2.0 if self.two_sided else self.period

    @property
    def impacts_per_period(self) -> int:
        """1, or 2 for the two-sided stop."""
        return 2 if self.two_sided else 1

    @property
    def gap_response(self) -> NDArray[np.complex128]:
        """n^T H F: the stopped coordinate's linear complex amplitude [m]."""
        return self.response @ self.normal

    @property
    def linear_amplitude(self) -> NDArray[np.float64]:
        """a = |n^T H F| [m]."""
        return np.abs(self.gap_response)

    @property
    def static_offset(self) -> float:
        """u_s = n . K^-1 F0 [m]."""
        return float(self.normal @ self.static)

    @property
    def pre_impact_velocity(self) -> NDArray[np.float64]:
        """u'(0-) = J / (m_eff (1 + R)) [m s-1]."""
        return self.impulse / (self.layout.effective_mass * (1.0 + self.restitution))

    @property
    def impact_time(self) -> NDArray[np.float64]:
        """When the (upper) impact happens in the problem's time, modulo T [s]: w t_i = phi - theta."""
        return np.mod((self.phase - np.angle(self.gap_response)) / self.omega, self.period)

    # ----------------------------------------------------------- time signals
    def displacement(self, t: ArrayLike, derivative: int = 0) -> NDArray[np.float64]:
        """x(t) of every coordinate (or a time derivative), 0 <= t <= T from the impact, shape S + (m, N).

        ``t`` has shape S + (m,) (broadcast against ``omega[..., None]``). t = 0 is just after the impact, t = T just
        before the next; for the two-sided stop t = T/2 is just before the lower impact.
        """
        tt = np.asarray(t, dtype=float)
        w = self.omega[..., None]
        angle = w * tt + (self.phase - np.angle(self.gap_response))[..., None]
        rotation = (1j * w) ** derivative * np.exp(1j * angle)
        linear = (self.response[..., None, :] * rotation[..., None]).real
        if derivative == 0:
            linear = linear + self.static
        sign = 1.0
        local = tt
        if self.two_sided:
            half = self.window[..., None]
            later = tt > half
            local = np.where(later, tt - half, tt)
            sign = np.where(later, -1.0, 1.0)[..., None]
        green = green_vector(self.modes, w, local, derivative, self.two_sided)
        return linear - sign * self.impulse[..., None, None] * green

    def coordinate(self, t: ArrayLike, derivative: int = 0, paired: bool = False) -> NDArray[np.float64]:
        """u(t) = n . x(t) of the (upper) stop (or a derivative), shape S + (m,); ``paired``: conjugate terms summed
        once (:func:`~vibroimpact.analysis.greens.periodic_green`: faster, equal to round-off, not bit for bit)."""
        tt = np.asarray(t, dtype=float)
        w = self.omega[..., None]
        angle = w * tt + self.phase[..., None] + derivative * np.pi / 2.0
        linear = self.linear_amplitude[..., None] * w**derivative * np.cos(angle)
        if derivative == 0:
            linear = linear + self.static_offset
        sign, local = 1.0, tt
        if self.two_sided:
            half = self.window[..., None]
            later = tt > half
            local, sign = np.where(later, tt - half, tt), np.where(later, -1.0, 1.0)
        return linear - sign * self.impulse[..., None] * periodic_green(self.modes.output(self.normal), w, local, derivative, self.two_sided, paired)

    def state(self, t: ArrayLike) -> NDArray[np.float64]:
        """(x, x') at times ``t`` from the impact, shape S + (m, 2N)."""
        return np.concatenate([self.displacement(t), self.displacement(t, 1)], axis=-1)

    def state_after_impact(self) -> NDArray[np.float64]:
        """(x, x') just after the (upper) impact, shape S + (2N,)."""
        return self.state(np.zeros(self.omega.shape + (1,)))[..., 0, :]

    def state_before_impact(self) -> NDArray[np.float64]:
        """(x, x') just before the (upper) impact, shape S + (2N,)."""
        return self.state(self.period[..., None])[..., 0, :]

    def state_at(self, t: ArrayLike) -> NDArray[np.float64]:
        """(x, x') at the problem's time(s) ``t`` [s] (shape S + (m,)), shape S + (m, 2N)."""
        tau = np.mod(np.asarray(t, dtype=float) - self.impact_time[..., None], self.period[..., None])
        return self.state(tau)

    # ------------------------------------------------------------- harmonics
    def harmonics(self, origin: str = "impact") -> NDArray[np.complex128]:
        """Complex amplitude of each coordinate's fundamental harmonic [m], shape S + (N,).

        The impulse train's fundamental is 2 J / T (one impact) or 4 J / T (alternating every T/2), along -n, so
        X = H F e^{j(phi - theta)} - (k J / T) H n with k = 2 or 4. ``origin``: ``impact`` (time from the impact, as
        the paper's eqs. 17-18) or ``problem`` (the problem's time, the phase of the load included).
        """
        if origin not in ("impact", "problem"):
            raise ValueError(f"origin = {origin!r}: allowed ['impact', 'problem']")
        rotation = np.exp(1j * (self.phase - np.angle(self.gap_response)))
        rate = (4.0 if self.two_sided else 2.0) * self.impulse / self.period
        out = self.response * rotation[..., None] - rate[..., None] * self.impulse_response
        if origin == "problem":
            out = out * np.exp(-1j * self.omega * self.impact_time)[..., None]
        return out

    def base_force(self, suspension_only: bool = False) -> NDArray[np.complex128]:
        """Fundamental of the force on the base [N], shape S: 1^T (K + j w C) X (:func:`.linear.base_force`) plus, unless
        ``suspension_only``, (1^T n) k J / T of the stop's impulses (k as in :meth:`harmonics`; 0 for a relative stop)."""
        force = suspension_force(self.layout.structure, self.omega, self.harmonics())
        rate = (4.0 if self.two_sided else 2.0) * self.impulse / self.period
        return force if suspension_only else force + float(np.sum(self.normal)) * rate

    def take(self, index: ArrayLike) -> "ImpactOrbit":
        """The points at flat indices ``index`` of the broadcast shape, as a 1-D solution."""
        flat = np.asarray(index, dtype=np.intp)
        shape = self.omega.shape

        def pick(a: NDArray, tail: int = 0) -> NDArray:
            full = np.broadcast_to(a, shape + a.shape[a.ndim - tail :])
            return full.reshape((-1,) + a.shape[a.ndim - tail :])[flat]

        return dataclasses.replace(
            self, omega=pick(self.omega), clearance=pick(self.clearance), restitution=pick(self.restitution), amplitude=pick(self.amplitude),
            load=pick(self.load, 1), response=pick(self.response, 1), impulse_response=pick(self.impulse_response, 1),
            impulse=pick(self.impulse), phase=pick(self.phase), exists=pick(self.exists), chi0=pick(self.chi0), chi_rate_before=pick(self.chi_rate_before),
            condition=pick(self.condition),
        )  # fmt: skip

    def _chunked(self, function: "Callable[[ImpactOrbit], NDArray]", tail: tuple[int, ...], chunk: int = 1024) -> NDArray[np.float64]:
        """``function`` of the existing points, a chunk at a time (bounds memory); NaN elsewhere, shape S + tail."""
        out = np.full((int(np.prod(self.omega.shape, dtype=int)),) + tail, np.nan)
        index = np.flatnonzero(self.exists)
        for start in range(0, index.size, chunk):
            part = index[start : start + chunk]
            out[part] = function(self.take(part))
        return out.reshape(self.omega.shape + tail)

    def rms(self, nodes: int = 64) -> NDArray[np.float64]:
        """RMS of each coordinate over the period [m], shape S + (N,); NaN where no orbit exists.

        Gauss-Legendre over each smooth piece between impacts (exact to round-off, see the paper's ``rms``).
        """
        points, weights = np.polynomial.legendre.leggauss(nodes)
        fractions, weights = (points + 1.0) / 2.0, weights / 2.0
        pieces = self.impacts_per_period
        fractions = np.concatenate([(fractions + k) / pieces for k in range(pieces)])
        weights = np.concatenate([weights / pieces] * pieces)

        def rms(part: ImpactOrbit) -> NDArray[np.float64]:
            x = part.displacement(fractions * part.period[..., None])
            return np.sqrt(np.einsum("...mi,m->...i", x**2, weights))

        return self._chunked(rms, (self.layout.structure.size,))

    # ---------------------------------------------------------- admissibility
    def max_overshoot(self, samples: int = 512, edge_samples: int = 24) -> NDArray[np.float64]:
        """Largest penetration of a stop between impacts [m]: max over the open window of u - Delta (and, two-sided,
        -Delta - u); NaN where no orbit exists, +inf where R = 0 and the stop pushes u on at once (it would stick).

        Uniform samples plus geometric ones next to the ends locate the maximum; Newton steps refine it.
        """
        edges = np.logspace(-9.0, -2.0, edge_samples)
        fractions = np.unique(np.concatenate([np.linspace(0.0, 1.0, samples + 1)[1:-1], edges, 1.0 - edges]))
        return self._chunked(lambda part: part._max_overshoot(fractions), ())

    def _max_overshoot(self, fractions: NDArray[np.float64]) -> NDArray[np.float64]:
        window = self.window[..., None]
        t = fractions * window
        u = self.coordinate(t, paired=True)  # the samples only locate the maximum, which the Newton steps refine
        delta = self.clearance[..., None]
        excess = u - delta
        if self.two_sided:
            excess = np.maximum(excess, -delta - u)
        k = np.argmax(np.nan_to_num(excess, nan=-np.inf), axis=-1)
        best = np.take_along_axis(excess, k[..., None], axis=-1)[..., 0]
        lo = np.take_along_axis(t, np.maximum(k - 1, 0)[..., None], axis=-1)
        hi = np.take_along_axis(t, np.minimum(k + 1, fractions.size - 1)[..., None], axis=-1)
        tk = np.take_along_axis(t, k[..., None], axis=-1)
        # refine u's maximum, or (two-sided, where the lower stop is nearer) its minimum
        side = np.sign(np.take_along_axis(u, k[..., None], axis=-1)) if self.two_sided else np.ones(k.shape + (1,))
        for _ in range(8):
            slope, curvature = side * self.coordinate(tk, 1, paired=True), side * self.coordinate(tk, 2, paired=True)
            with np.errstate(divide="ignore", invalid="ignore"):
                step = np.where(curvature < 0.0, -slope / curvature, 0.0)
            tk = np.clip(tk + np.nan_to_num(step), lo, hi)
        refined = side * self.coordinate(tk) - delta
        best = np.maximum(best, refined[..., 0])
        sticking = (self.restitution == 0.0) & (self.coordinate(np.zeros(self.omega.shape + (1,)), 2)[..., 0] > 0.0)
        return np.where(sticking, np.inf, best)

    def admissible(self, relative_tolerance: float = 1e-9, samples: int = 512) -> NDArray[np.bool_]:
        """True where the orbit exists and stays off the stops between impacts (within relative_tolerance of
        |Delta| + a + |u_s|)."""
        overshoot = self.max_overshoot(samples)
        scale = np.abs(self.clearance) + self.linear_amplitude + abs(self.static_offset)
        with np.errstate(invalid="ignore"):
            return self.exists & (overshoot <= relative_tolerance * scale)

    def with_root(self, root: str) -> "ImpactOrbit":
        """The same points with the other root of the impulse equation ('+' or '-')."""
        impulse, phase, exists = _impulse_and_phase(self.omega, self.clearance - self.static_offset, self.restitution,
                                                    self.layout.effective_mass, self.linear_amplitude, self.chi0, self.chi_rate_before, root, self.conditioned)  # fmt: skip
        return dataclasses.replace(self, impulse=impulse, phase=phase, exists=exists)


def _impulse_and_phase(w: NDArray, delta: NDArray, r: NDArray, m_eff: float, a: NDArray, chi0: NDArray, rate: NDArray, root: str,
                       conditioned: NDArray) -> tuple[NDArray, NDArray, NDArray]:  # fmt: skip
    c = (1.0 / (m_eff * (1.0 + r)) + rate) / w
    quad_a = c**2 + chi0**2
    constant = delta**2 - a**2
    discriminant = quad_a * a**2 - (c * delta) ** 2
    impulse = impulse_roots(quad_a, delta * chi0, discriminant, constant, root)
    exists = np.isfinite(impulse) & (impulse >= 0.0) & (a > 0.0) & conditioned
    with np.errstate(invalid="ignore", divide="ignore"):
        phase = np.where(exists, np.arctan2(-impulse * c / a, (delta + impulse * chi0) / a), np.nan)
    return np.where(exists, impulse, np.nan), phase, exists


#: Why a closed form refuses a layout of the other form (by :attr:`ClosedFormLayout.two_sided`), naming its solver.
_OTHER_FORM = {
    False: "contact: one stop has no two-sided symmetric orbit; its closed form is vibroimpact.solve_one_impact(problem)",
    True: "contact: the stops form a symmetric two-sided stop, whose closed form has two impacts per period: use vibroimpact.solve_two_impacts(problem)",
}


def closed_form_problem(system: ProblemLike, call: str, frequency: ArrayLike | None, clearance: ArrayLike | None, restitution: ArrayLike | None,
                        amplitude: ArrayLike | None, omega: ArrayLike | None = None, two_sided: bool | None = None) -> tuple[ImpactProblem, ClosedFormLayout]:  # fmt: skip
    """The problem a closed form solves (:func:`~vibroimpact.model.problem.problem_of`: the paper's named system needs
    every value) and its layout (:func:`.layout.closed_form_layout`), for :func:`solve_impact_orbit` and the solvers of
    one form, ``solve_one_impact`` (``two_sided`` False) and ``solve_two_impacts`` (True).

    Raises
    ------
    TypeError
        As :func:`~vibroimpact.model.problem.problem_of`, naming ``call``.
    ValueError
        The layout has no closed form (the reason), or is not of the form ``two_sided`` asks (naming the other solver).
    """
    problem = problem_of(system, call, frequency=frequency if omega is None else omega, clearance=clearance, restitution=restitution, amplitude=amplitude)
    layout = closed_form_layout(problem)
    if two_sided is not None and layout.two_sided != two_sided:
        raise ValueError(_OTHER_FORM[layout.two_sided])
    return problem, layout


@suggest_keywords
def solve_impact_orbit(
    problem: ProblemLike,
    frequency: ArrayLike | None = None,
    clearance: ArrayLike | None = None,
    restitution: ArrayLike | None = None,
    amplitude: ArrayLike | None = None,
    root: str = "+",
    *,
    omega: ArrayLike | None = None,
    green: PaperFit | None = None,
) -> ImpactOrbit:
    """The closed-form impact orbit of ``problem`` (one stop, or a symmetric two-sided stop), vectorised.

    Parameters
    ----------
    problem : ImpactProblem or the paper's named system
        Structure, rigid stop(s) and harmonic force (:func:`.layout.closed_form_layout` says whether a closed form
        applies: ``ValueError`` with the reason otherwise); the paper's named system is a view of its layout
        (:func:`~vibroimpact.model.problem.problem_of`: give frequency, clearance, restitution and amplitude).
    frequency : array_like, optional
        f [Hz], > 0; default the problem's.
    clearance : array_like, optional
        Delta [m] of the stop (both sides of a pair); default the problem's.
    restitution : array_like, optional
        R [-] in [0, 1]; default the problem's.
    amplitude : array_like, optional
        q [N] (base motion: Y [m]); default the problem's.
    root : {'+', '-'}
        Which root of the impulse equation.
    omega : array_like, optional
        w [rad s-1] instead of ``frequency`` (keyword only).
    green : PaperFit, optional
        The paper's fitted chi22 and constant chi22'(0-) instead of the exact ones (``pgf_paper``; its layout only,
        :mod:`~vibroimpact.analysis.paper_fit`).

    Returns
    -------
    ImpactOrbit
        Impulse, phase, existence, ``frequency`` [Hz] beside ``omega`` [rad s-1], ``stable`` and ``multipliers``
        (Floquet), :meth:`~ImpactOrbit.harmonics`, :meth:`~ImpactOrbit.admissible`, the motion.
    """
    problem, layout = closed_form_problem(problem, "solve_impact_orbit", frequency, clearance, restitution, amplitude, omega)
    check_closed_form_inputs(clearance, restitution, amplitude)
    w, delta, r, q = (np.asarray(x, dtype=float) for x in np.broadcast_arrays(
        angular_frequency(frequency, omega, problem.omega), layout.clearance if clearance is None else clearance,
        layout.restitution if restitution is None else restitution, problem.amplitude if amplitude is None else amplitude))  # fmt: skip
    if layout.two_sided and np.any(delta <= 0.0):
        raise ValueError("clearance: a two-sided stop needs Delta > 0 (room between its sides)")
    structure, n = layout.structure, layout.normal
    load = harmonic_load(problem, w, q)
    h = structure.receptance_matrix(w)
    response = np.einsum("...ij,...j->...i", h, load)
    impulse_response = h @ n
    _, static_load = problem.load()
    static = np.linalg.solve(structure.stiffness_matrix, static_load) if np.any(static_load) else np.zeros(structure.size)
    modes = impulse_modes(structure, n) if green is None else green.modes(problem)
    model = modes.output(n)
    anti = layout.two_sided
    period = 2.0 * np.pi / w
    chi0 = periodic_green(model, w, 0.0, 0, anti)
    if anti:  # psi'(0-) = -psi'(T/2-): antiperiodic
        rate = -periodic_green(model, w, period / 2.0, 1, True)
    else:
        rate = periodic_green(model, w, period, 1) if green is None else green.rate_before(w)
    a = np.abs(response @ n)
    condition = green_condition(modes.poles, w, anti)
    impulse, phase, exists = _impulse_and_phase(w, delta - float(n @ static), r, layout.effective_mass, a, chi0, rate, root, condition <= GREEN_CONDITION_LIMIT)
    return ImpactOrbit(layout, w, delta, r, q, load, response, impulse_response, static, impulse, phase, exists, chi0, rate, modes, condition)
