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

from numpy.typing import ArrayLike

from vibroimpact.analysis.impact_orbit import ImpactOrbit, closed_form_problem, solve_impact_orbit
from vibroimpact.analysis.paper_fit import PaperFit
from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.model.problem import ProblemLike

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


@suggest_keywords
def solve_one_impact(
    system: ProblemLike,
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
    paper's named system (m1 ... b2) is the paper's layout (one upper stop on x2, the force on x1; all five values
    needed). ``solve_one_impact(problem, frequency=None, clearance=None, restitution=None, amplitude=None)`` with an
    :class:`ImpactProblem` of any structure with one rigid stop (absolute or relative, upper or lower) takes the
    problem's own values where none are given; ``ValueError`` saying why where it does not apply (several stops, a
    bumper, a rigid-body mode; a symmetric two-sided stop is :func:`vibroimpact.solve_two_impacts`). The paper's
    system is a view of its problem (:func:`~vibroimpact.model.problem.problem_of`), not another solver.

    Parameters
    ----------
    system : ImpactProblem or the paper's named system
        The whole problem, or the paper's named system (its layout; then all five values are needed).
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
        The one orbit type of every closed form: impulse, phase, existence, ``frequency`` [Hz] and ``omega``
        [rad s-1], ``stable`` and ``multipliers`` (Floquet), ``harmonics()`` (x1 is column 0, x2 column 1 on the
        paper's layout), ``admissible()``, the motion.
    """
    variant = PgfVariant(variant)
    problem, _ = closed_form_problem(system, "solve_one_impact", frequency, clearance, restitution, amplitude, omega, two_sided=False)
    green = PaperFit.of(problem) if variant is PgfVariant.PAPER else None
    return solve_impact_orbit(problem, frequency, clearance, restitution, amplitude, omega=omega, green=green)
