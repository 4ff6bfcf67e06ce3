"""The symmetric two-impacts-per-period orbit of a two-sided stop: :func:`solve_two_impacts`, the closed form of
:func:`vibroimpact.analysis.impact_orbit.solve_impact_orbit` on such a layout, with its derivation."""

from __future__ import annotations

from numpy.typing import ArrayLike

from vibroimpact.analysis.impact_orbit import ImpactOrbit, closed_form_problem, solve_impact_orbit
from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.model.problem import ProblemLike

__all__ = ["solve_two_impacts"]


@suggest_keywords
def solve_two_impacts(
    problem: ProblemLike,
    frequency: ArrayLike | None = None,
    clearance: ArrayLike | None = None,
    restitution: ArrayLike | None = None,
    amplitude: ArrayLike | None = None,
    root: str = "+",
    *,
    omega: ArrayLike | None = None,
) -> ImpactOrbit:
    """The symmetric two-impacts-per-period orbit of a two-sided stop, vectorised.

    Parameters
    ----------
    problem : ImpactProblem or the paper's named system
        Structure without rigid-body modes, two rigid stops forming a symmetric pair, harmonic force (the paper's
        system is a view of its one-stop layout: refused with the reason, as any one-stop problem).
    frequency : array_like, optional
        f [Hz], > 0; default the problem's.
    clearance : array_like, optional
        Delta [m] of both sides, > 0; default the problem's.
    restitution : array_like, optional
        R [-] of both sides; default the problem's.
    amplitude : array_like, optional
        q [N] (base motion: Y [m]); default the problem's.
    root : {'+', '-'}
        Which root of the impulse equation.
    omega : array_like, optional
        w [rad s-1] instead of ``frequency`` (keyword only).

    Raises
    ------
    ValueError
        Naming why the layout has no such orbit (one stop: use :func:`vibroimpact.solve_one_impact`).

    Returns
    -------
    ImpactOrbit
        The one orbit type of every closed form (``two_sided`` True): ``frequency`` [Hz], ``omega`` [rad s-1],
        ``stable``, ``multipliers``, ``harmonics()``, ``admissible()``.

    Notes
    -----
    The symmetric two-impacts-per-period orbit of a two-sided stop, in closed form by antiperiodic Green functions.

    Layout: two rigid stops on the same coordinate (or relative coordinate) u = n . x, the upper one u <= Delta and the
    lower one u >= -Delta, with the same clearance Delta > 0 and restitution R, under a harmonic load Re(F e^{jwt}) and no
    static load on u (n . K^-1 F0 = 0). The structure has no rigid-body mode (:mod:`vibroimpact.analysis.layout`).

    Symmetry. The map x -> 2 x_s - x, x' -> -x' (x_s = K^-1 F0) together with t -> t + T/2 turns the equations of
    motion into themselves (the harmonic load changes sign) and swaps the two stops. An orbit that is its own image,
    x(t + T/2) - x_s = -(x(t) - x_s), hits the upper stop at t = 0 (u = Delta, approaching with u'(0-) > 0) and the lower
    one at t = T/2 (u = -Delta, u'(T/2-) = -u'(0-) < 0) with the same impulse J: the impulses are -J n at t = 0, T, ...
    and +J n at T/2, 3T/2, ..., i.e. the train -J n sum_k (-1)^k delta(t - k T/2).

    Motion. Superposing the linear steady state and the response to that train (h(t) the impulse response of H(s) n)::

        x(t) = Re(H F e^{j(wt + phi - theta)}) + x_s - J psi(t),     psi(t) = sum_{m >= 0} (-1)^m h(t + m T/2)

    For 0 <= t <= T/2, with h(t) = sum_k r_k e^{p_k t}, the geometric series gives the antiperiodic Green function
    (:func:`vibroimpact.analysis.greens.green_vector`)::

        psi(t) = sum_k r_k e^{p_k t} / (1 + e^{p_k T/2}),       psi(t + T/2) = -psi(t)

    It is finite wherever 1 + e^{p T/2} != 0, i.e. except at an undamped resonance with w / Omega = 2 / (odd integer).
    Let u = n . x, a e^{j theta} = n^T H F, psi_u = n . psi, psi0 = psi_u(0). By antiperiodicity psi_u'(0-) =
    -psi_u'(T/2-), and the jump psi_u'(0+) - psi_u'(0-) = n^T M^-1 n = 1/m_eff (the delta at t = 0 has weight +1).

    Impact conditions at t = 0 (the one at T/2 follows by symmetry)::

        u(0) = a cos(phi) - J psi0 = Delta
        u'(0-) = -a w sin(phi) - J psi_u'(0-) = J / (m_eff (1 + R))      (Newton's law of restitution, impulse J)

    so, exactly as the one-impact orbit with chi replaced by psi::

        cos(phi) = (Delta + J psi0) / a,     sin(phi) = -J c / a,     c = [1 / (m_eff (1 + R)) + psi_u'(0-)] / w
        (c^2 + psi0^2) J^2 + 2 Delta psi0 J + Delta^2 - a^2 = 0

    Existence: a real root J >= 0. Admissibility: -Delta <= u(t) <= Delta over 0 < t < T/2 (then over the whole period
    by symmetry). Stability: the monodromy over T from just after the upper impact is S_u exp(A T/2) S_l exp(A T/2)
    (:func:`vibroimpact.analysis.stability.monodromy`); the orbit is the fixed point of the half-period map
    y -> mirror(flow_{T/2}(y)) whose Jacobian -S_u exp(A T/2) has the monodromy as its square
    (:func:`~vibroimpact.analysis.stability.half_period_jacobian`): its multiplier -1 marks the symmetry-breaking
    pitchfork, where asymmetric two-impact orbits branch off.

    Fundamental harmonic: the train's first Fourier amplitude is 4 J / T (two impulses of opposite sign half a period
    apart add at odd harmonics), so X = H F e^{j(phi - theta)} - (4 J / T) H n.

    Checks (tests/analysis/test_two_sided.py): the reconstructed motion satisfies the impact conditions at both stops
    and is a fixed point of an independent integration (scipy, events on both gaps); the monodromy equals the
    finite-difference Jacobian of that integration; a stable orbit attracts a perturbed start.
    """
    problem, _ = closed_form_problem(problem, "solve_two_impacts", frequency, clearance, restitution, amplitude, omega, two_sided=True)
    return solve_impact_orbit(problem, frequency, clearance, restitution, amplitude, root, omega=omega)
