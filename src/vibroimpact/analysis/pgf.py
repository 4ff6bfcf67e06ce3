"""Closed-form one-impact-per-period solution by periodic Green functions (seed paper eqs. 8, 12-23).

Time is measured from the impact: the absorber reaches the stop, X2(0) = Delta, once per period T = 2 pi / w. With
``a = q |H12(j w)|`` and the impact phase ``phi`` (the paper's phi + psi12) the motion is (eq. 8)::

    X2(t) = a cos(w t + phi) - J chi22(t),     X1(t) = q |H11| cos(w t + psi11 + phi - psi12) - J chi12(t)

The impact conditions X2(0) = Delta and J = M2 (1 + R) X2'(0-) give (eq. 15, corrected)::

    sin(phi) = -J c / a,   cos(phi) = (Delta + J chi0) / a,   c = [1 / (M2 (1 + R)) + chi22'(0-)] / w

with chi0 = chi22(0), so ``(c^2 + chi0^2) J^2 + 2 Delta chi0 J + Delta^2 - a^2 = 0`` (eq. 16, corrected bracket).
The paper replaces chi22'(0-) by -1/(2 M2), which turns c into (1 - R) / (2 (1 + R) M2 w).

Two variants, both the one closed form of :func:`~vibroimpact.analysis.impact_orbit.solve_impact_orbit` (an
:class:`~vibroimpact.analysis.impact_orbit.ImpactOrbit`, which holds that form for any structure and stop):

* ``pgf``: exact poles and residues of H22 and the exact chi22'(0-).
* ``pgf_paper``: the paper's curve-fitted modal parameters (eq. 10 with Omega fixed, eq. 14) and its constant
  chi22'(0-) = -1/(2 M2) (:class:`~vibroimpact.analysis.paper_fit.PaperFit`, its layout only). Near the linear
  resonances chi22'(0-) is far from that constant, which produces the spurious spikes of the paper's figures 5-8.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

import numpy as np
from numpy.typing import ArrayLike, NDArray

from vibroimpact.analysis.greens import GREEN_CONDITION_LIMIT, green_condition, periodic_green
from vibroimpact.analysis.impact_orbit import ImpactOrbit, solve_impact_orbit
from vibroimpact.analysis.paper_fit import PaperFit
from vibroimpact.analysis.layout import closed_form_layout
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce, angular_frequency, check_closed_form_inputs
from vibroimpact.model.modal import PoleResidueModel, exact_pole_residue, fit_modal_parameters
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import Receptances, TwoDofSystem

__all__ = ["PgfVariant", "solve_one_impact", "AdmissibilitySettings"]


class PgfVariant(str, Enum):
    """Which Green function and which chi22'(0-) the closed-form solution uses."""

    EXACT = "pgf"
    PAPER = "pgf_paper"


@dataclass(frozen=True)
class AdmissibilitySettings:
    """How X2(t) <= Delta is checked over the period.

    Attributes
    ----------
    samples_per_period : int
        Uniform samples of X2(t) per period before refining the largest one by Newton steps on X2'(t) = 0.
    edge_samples : int
        Geometrically spaced samples next to each end of the period (1e-9 T ... 1e-2 T), where a slow
        rebound (small R) could cross the stop again right after the impact.
    relative_tolerance : float
        X2(t) may exceed Delta by this fraction of (Delta + q |H12|) [-] (round-off allowance).
    chunk_points : int
        Frequency points evaluated at once (bounds memory).
    """

    samples_per_period: int = 512
    edge_samples: int = 24
    relative_tolerance: float = 1e-9
    chunk_points: int = 2048


@dataclass(frozen=True, eq=False)
class OneImpactSolution:
    """One-impact periodic solutions at a set of points (all arrays share one broadcast shape).

    Attributes
    ----------
    omega : ndarray
        Excitation angular frequency w [rad s-1].
    clearance : ndarray
        Delta [m].
    restitution : ndarray
        R [-].
    amplitude : float
        Excitation force amplitude q [N].
    receptances : Receptances
        H11, H12, H22 at ``omega`` [m N-1].
    impulse : ndarray
        Impact impulse J [N s] (the stable, '+' root of eq. 16); NaN where no real root exists.
    phase : ndarray
        Impact phase phi (the paper's varphi + psi12) [rad]; NaN where no solution exists.
    exists : ndarray of bool
        A real root with J >= 0 exists (the paper's existence conditions |sin phi| <= 1, J >= 0), where the closed
        form is well-conditioned (``condition``).
    chi0 : ndarray
        chi22(0) [m N-1 s-1] as used by the variant.
    chi_rate_before : ndarray
        chi22'(0-) [m N-1 s-2] as used by the variant.
    green22, green12 : PoleResidueModel
        Models whose periodic Green functions reconstruct X2(t) and X1(t).
    system : TwoDofSystem
        The linear system.
    condition : ndarray
        kappa of the periodic sums of both models [-] (:func:`~vibroimpact.analysis.greens.green_condition`); beyond
        :data:`~vibroimpact.analysis.greens.GREEN_CONDITION_LIMIT` (near an undamped natural frequency) ``exists`` is
        False and J, phi are NaN: the closed form is not evaluated there.
    """

    omega: NDArray[np.float64]
    clearance: NDArray[np.float64]
    restitution: NDArray[np.float64]
    amplitude: float
    receptances: Receptances
    impulse: NDArray[np.float64]
    phase: NDArray[np.float64]
    exists: NDArray[np.bool_]
    chi0: NDArray[np.float64]
    chi_rate_before: NDArray[np.float64]
    green22: PoleResidueModel
    green12: PoleResidueModel
    system: TwoDofSystem
    condition: NDArray[np.float64]

    @property
    def conditioned(self) -> NDArray[np.bool_]:
        """Where the closed form is evaluated: condition <= GREEN_CONDITION_LIMIT."""
        return self.condition <= GREEN_CONDITION_LIMIT

    @property
    def period(self) -> NDArray[np.float64]:
        """Excitation period T [s]."""
        return 2.0 * np.pi / self.omega

    @property
    def linear_amplitude_x2(self) -> NDArray[np.float64]:
        """Amplitude of the absorber's linear steady state, q |H12| [m]."""
        return self.amplitude * np.abs(self.receptances.h12)

    @property
    def pre_impact_velocity(self) -> NDArray[np.float64]:
        """X2'(0-) = J / (M2 (1 + R)) [m s-1]."""
        return self.impulse / (self.system.m2 * (1.0 + self.restitution))

    # ------------------------------------------------------------ time signals
    def x2(self, t: ArrayLike, derivative: int = 0) -> NDArray[np.float64]:
        """Reconstructed X2(t) of eq. 8 (or a time derivative) for 0 <= t <= T [m s-derivative].

        ``t`` has the solution's shape plus trailing sample axes, e.g. ``t[..., None] * period[..., None]``; it
        must broadcast against ``omega[..., None]`` (one trailing axis).
        """
        return self._signal(t, derivative, np.abs(self.receptances.h12), 0.0, self.green22)

    def x1(self, t: ArrayLike, derivative: int = 0) -> NDArray[np.float64]:
        """Reconstructed X1(t) of eq. 8 (or a time derivative) for 0 <= t <= T [m s-derivative]."""
        h11, h12 = self.receptances.h11, self.receptances.h12
        return self._signal(t, derivative, np.abs(h11), np.angle(h11) - np.angle(h12), self.green12)

    def _signal(self, t: ArrayLike, derivative: int, gain: NDArray, shift: NDArray | float, green: PoleResidueModel) -> NDArray[np.float64]:
        tt = np.asarray(t, dtype=float)
        w = self.omega[..., None]
        angle = w * tt + (self.phase + shift)[..., None] + derivative * np.pi / 2.0
        linear = self.amplitude * gain[..., None] * w**derivative * np.cos(angle)
        return linear - self.impulse[..., None] * periodic_green(green, w, tt, derivative)

    # ------------------------------------------------------ fundamental harmonics
    def x1_harmonic(self) -> NDArray[np.complex128]:
        """Complex amplitude of the fundamental harmonic of X1, eq. 17 [m] (time origin at the impact)."""
        h = self.receptances
        rotation = np.exp(1j * self.phase) * np.conj(h.h12) / np.abs(h.h12)
        return self.amplitude * h.h11 * rotation - self._impulse_rate() * h.h12

    def x2_harmonic(self) -> NDArray[np.complex128]:
        """Complex amplitude of the fundamental harmonic of X2, eq. 18 [m]."""
        h = self.receptances
        return self.amplitude * np.abs(h.h12) * np.exp(1j * self.phase) - self._impulse_rate() * h.h22

    def suspension_force_harmonic(self) -> NDArray[np.complex128]:
        """Fundamental harmonic of the force through the suspension K1 X1 + B1 X1', eq. 21 [N]."""
        return (self.system.k1 + 1j * self.omega * self.system.b1) * self.x1_harmonic()

    def force_harmonic(self) -> NDArray[np.complex128]:
        """Fundamental harmonic of the total force on the base, suspension plus impacts, eq. 23 [N]."""
        return self.suspension_force_harmonic() + self._impulse_rate()

    def _impulse_rate(self) -> NDArray[np.float64]:
        """2 J / T: the fundamental-harmonic amplitude of the impulse train [N]."""
        return 2.0 * self.impulse / self.period

    # ------------------------------------------------------------ admissibility
    def max_overshoot(self, settings: AdmissibilitySettings = AdmissibilitySettings()) -> NDArray[np.float64]:
        """Largest X2(t) - Delta over the open period 0 < t < T [m]; NaN where no solution exists.

        Uniform and edge samples locate the maximum, Newton steps on X2'(t) = 0 refine it. For R = 0 the absorber
        leaves the stop with zero velocity, so the sign of X2''(0+) decides: a positive value means it is pushed
        into the stop at once (it would stick), reported as +inf.
        """
        shape = self.omega.shape
        result = np.full(shape, np.nan)
        flat_index = np.flatnonzero(self.exists)
        if flat_index.size == 0:
            return result
        edges = np.logspace(-9.0, -2.0, settings.edge_samples)
        fractions = np.unique(np.concatenate([np.linspace(0.0, 1.0, settings.samples_per_period + 1)[1:-1], edges, 1.0 - edges]))
        out = result.reshape(-1)
        for start in range(0, flat_index.size, settings.chunk_points):
            idx = flat_index[start : start + settings.chunk_points]
            out[idx] = self._subset(idx)._max_overshoot_all(fractions)
        return out.reshape(shape)

    def admissible(self, settings: AdmissibilitySettings = AdmissibilitySettings()) -> NDArray[np.bool_]:
        """True where the solution exists and X2(t) <= Delta over the whole period (within the tolerance)."""
        overshoot = self.max_overshoot(settings)
        scale = self.clearance + self.linear_amplitude_x2
        with np.errstate(invalid="ignore"):
            return self.exists & (overshoot <= settings.relative_tolerance * scale)

    def _max_overshoot_all(self, fractions: NDArray[np.float64]) -> NDArray[np.float64]:
        period = self.period[..., None]
        t = fractions * period
        gap = self.x2(t) - self.clearance[..., None]
        k = np.argmax(gap, axis=-1)
        rows = np.arange(gap.shape[0])
        best = gap[rows, k]
        # refine the sampled maximum: Newton on X2'(t) = 0 inside the neighbouring samples
        lo = fractions[np.maximum(k - 1, 0)] * period[:, 0]
        hi = fractions[np.minimum(k + 1, fractions.size - 1)] * period[:, 0]
        tk = t[rows, k]
        for _ in range(8):
            slope = self.x2(tk[:, None], 1)[:, 0]
            curvature = self.x2(tk[:, None], 2)[:, 0]
            with np.errstate(divide="ignore", invalid="ignore"):
                step = np.where(curvature < 0.0, -slope / curvature, 0.0)
            tk = np.clip(tk + step, lo, hi)
        refined = self.x2(tk[:, None])[:, 0] - self.clearance
        best = np.maximum(best, refined)
        sticking = (self.restitution == 0.0) & (self.x2(np.zeros((rows.size, 1)), 2)[:, 0] > 0.0)
        return np.where(sticking, np.inf, best)

    def rms(self, nodes: int = 64, chunk_points: int = 2048) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """RMS of the reconstructed X1(t) and X2(t) over the period [m]; NaN where no solution exists.

        Gauss-Legendre quadrature of x^2 over the open period: the orbit is smooth on [0, T] (its only kink, the
        impact, is at the ends), so ``nodes`` = 64 is exact to round-off (it agrees with 128 nodes to 1e-15, where the
        512-sample trapezoidal rule used before was second order at the kink, ~1e-6, and ~8x dearer).
        """
        shape = self.omega.shape
        x1_rms, x2_rms = np.full(shape, np.nan), np.full(shape, np.nan)
        flat_index = np.flatnonzero(self.exists)
        points, weights = np.polynomial.legendre.leggauss(nodes)
        fractions, weights = (points + 1.0) / 2.0, weights / 2.0
        out1, out2 = x1_rms.reshape(-1), x2_rms.reshape(-1)
        for start in range(0, flat_index.size, chunk_points):
            idx = flat_index[start : start + chunk_points]
            part = self._subset(idx)
            t = fractions * part.period[..., None]
            out1[idx] = np.sqrt(part.x1(t) ** 2 @ weights)
            out2[idx] = np.sqrt(part.x2(t) ** 2 @ weights)
        return x1_rms, x2_rms

    def _subset(self, flat_index: NDArray[np.intp]) -> "OneImpactSolution":
        def pick(a: NDArray) -> NDArray:
            return np.broadcast_to(a, self.omega.shape).reshape(-1)[flat_index]

        h = self.receptances
        return OneImpactSolution(
            omega=pick(self.omega),
            clearance=pick(self.clearance),
            restitution=pick(self.restitution),
            amplitude=self.amplitude,
            receptances=Receptances(pick(h.h11), pick(h.h12), pick(h.h22)),
            impulse=pick(self.impulse),
            phase=pick(self.phase),
            exists=pick(self.exists),
            chi0=pick(self.chi0),
            chi_rate_before=pick(self.chi_rate_before),
            green22=self.green22,
            green12=self.green12,
            system=self.system,
            condition=pick(self.condition),
        )


def stable_impulse_root(a: NDArray, b: NDArray, discriminant: NDArray, constant: NDArray) -> NDArray[np.float64]:
    """The '+' root of ``a J^2 + 2 b J + constant = 0`` without cancellation; NaN where the discriminant < 0.

    ``discriminant`` is ``b^2 - a * constant`` computed by the caller in a cancellation-free form.
    """
    with np.errstate(invalid="ignore", divide="ignore"):
        root = np.sqrt(discriminant)
        direct = (-b + root) / a
        conjugate = -constant / (root + b)
        impulse = np.where(b >= 0.0, np.where(root + b > 0.0, conjugate, 0.0), direct)
    return np.where(discriminant >= 0.0, impulse, np.nan)


def green_models(system: TwoDofSystem, variant: PgfVariant) -> tuple[PoleResidueModel, PoleResidueModel]:
    """Pole-residue models for chi22 and chi12 of a variant (the paper fits H22 only; chi12 is exact in both)."""
    green12 = exact_pole_residue(system, 1, 2)
    if variant is PgfVariant.EXACT:
        return exact_pole_residue(system, 2, 2), green12
    return fit_modal_parameters(system).to_pole_residue(), green12


def solve_one_impact(
    system: TwoDofSystem | ImpactProblem,
    frequency: ArrayLike | None = None,
    clearance: ArrayLike | None = None,
    restitution: ArrayLike | None = None,
    amplitude: ArrayLike | None = None,
    variant: PgfVariant | str = PgfVariant.EXACT,
    *,
    omega: ArrayLike | None = None,
) -> ImpactOrbit:
    """The one-impact-per-period orbit (eqs. 15-16, corrected), vectorised: the closed form of
    :func:`~vibroimpact.analysis.impact_orbit.solve_impact_orbit` for one rigid stop.

    Two forms, one result. ``solve_one_impact(system, frequency, clearance, restitution, amplitude, variant)`` with the
    paper's :class:`TwoDofSystem` is the paper's layout (one upper stop on x2, the force on x1; all five values
    needed). ``solve_one_impact(problem, frequency=None, clearance=None, restitution=None, amplitude=None)`` with an
    :class:`ImpactProblem` of any structure with one rigid stop (absolute or relative, upper or lower) takes the
    problem's own values where none are given; ``ValueError`` saying why where it does not apply (several stops, a
    bumper, a rigid-body mode; a symmetric two-sided stop is :func:`vibroimpact.analysis.impact_orbit.solve_two_impacts`).

    Parameters
    ----------
    system : TwoDofSystem or ImpactProblem
        The linear system (paper's layout), or the whole problem.
    frequency : array_like
        Excitation frequency f [Hz], > 0 (``ValueError`` otherwise).
    clearance : array_like
        Clearance Delta of the stop [m]; broadcast against ``frequency``.
    restitution : array_like
        Restitution ratio R [-], 0 <= R <= 1; broadcast against ``frequency``.
    amplitude : array_like
        Excitation force amplitude q [N].
    variant : PgfVariant or {'pgf', 'pgf_paper'}
        Exact Green function and chi22'(0-), or the paper's fitted modes and constant chi22'(0-)
        (:class:`~vibroimpact.analysis.paper_fit.PaperFit`: the paper's layout only, ``ValueError`` elsewhere).
    omega : array_like, optional
        Excitation angular frequency w [rad s-1] instead of ``frequency`` (keyword only).

    Returns
    -------
    ImpactOrbit
        Impulse, phase, existence, motion, harmonics (x1 is coordinate 0, x2 coordinate 1 on the paper's layout).
    """
    variant = PgfVariant(variant)
    if isinstance(system, ImpactProblem):
        problem = system
        if closed_form_layout(problem).two_sided:
            raise ValueError("contact: the stops form a symmetric two-sided stop, whose closed form has two impacts per period: use analysis.two_sided.solve_two_impacts")
    else:
        if (frequency is None and omega is None) or clearance is None or restitution is None or amplitude is None:
            raise TypeError("solve_one_impact(system, frequency, clearance, restitution, amplitude): the paper's form needs all five")
        check_closed_form_inputs(clearance, restitution, amplitude)
        # the paper's layout; its stop and force are placeholders: the values given replace them
        problem = ImpactProblem(system, RigidStop(0.0, 0.0), HarmonicForce(1.0, 1.0))
    green = PaperFit.of(problem) if variant is PgfVariant.PAPER else None
    return solve_impact_orbit(problem, frequency, clearance, restitution, amplitude, omega=omega, green=green)


def _paper_route(system: TwoDofSystem, omega: ArrayLike, clearance: ArrayLike, restitution: ArrayLike, amplitude: float) -> OneImpactSolution:
    """The paper's own route on its named system, as the study values take it (to be replaced by the option)."""
    w, delta, r = (np.asarray(x, dtype=float) for x in np.broadcast_arrays(omega, clearance, restitution))
    green22, green12 = green_models(system, PgfVariant.PAPER)
    h = system.receptances(w)
    chi0 = periodic_green(green22, w, 0.0)
    chi_rate_before = np.full_like(w, -1.0 / (2.0 * system.m2))
    c = (1.0 / (system.m2 * (1.0 + r)) + chi_rate_before) / w
    a_lin = amplitude * np.abs(h.h12)
    quad_a = c**2 + chi0**2
    quad_b = delta * chi0
    constant = delta**2 - a_lin**2
    discriminant = quad_a * a_lin**2 - (c * delta) ** 2  # = quad_b^2 - quad_a * constant, without cancellation
    impulse = stable_impulse_root(quad_a, quad_b, discriminant, constant)
    condition = green_condition(np.concatenate([green22.poles, green12.poles]), w)
    exists = np.isfinite(impulse) & (impulse >= 0.0) & (condition <= GREEN_CONDITION_LIMIT)
    with np.errstate(invalid="ignore", divide="ignore"):
        phase = np.where(exists, np.arctan2(-impulse * c / a_lin, (delta + impulse * chi0) / a_lin), np.nan)
    return OneImpactSolution(
        omega=w,
        clearance=delta,
        restitution=r,
        amplitude=float(amplitude),
        receptances=h,
        impulse=np.where(exists, impulse, np.nan),
        phase=phase,
        exists=exists,
        chi0=chi0,
        chi_rate_before=chi_rate_before,
        green22=green22,
        green12=green12,
        system=system,
        condition=condition,
    )
