"""Floquet stability of the one-impact periodic orbit: monodromy = saltation matrix x exact flow over the period.

Between impacts the state y = (X1, X2, X1', X2') obeys y' = A y + b(t), so a perturbation is carried over the
period by exp(A T). The impact at X2 = Delta (surface normal n = e2) with the reset y+ = D y-, D = diag(1, 1, 1, -R),
adds the saltation matrix (Leine & Nijmeijer; di Bernardo et al.)::

    S = D + (f(y+) - D f(y-)) n^T / (n^T f(y-))

which accounts for the shift of the impact time. The monodromy from just after one impact to just after the next is
``S exp(A T)``; the orbit is asymptotically stable when all its eigenvalues (Floquet multipliers) lie inside the
unit circle.

Any structure (:class:`~vibroimpact.analysis.impact_orbit.ImpactOrbit`, 2N x 2N): the state is y = (x, x'), the
stop's gap Delta - n . x has the gradient -(n, 0), the reset is x'+ = x'- - (1 + R) m_eff M^-1 n n^T x'-, i.e.
D = blockdiag(I, I - (1 + R) m_eff M^-1 n n^T), and the same saltation formula with n^T f -> (n, 0) . f gives
S. One impact per period: monodromy S exp(A T). The symmetric two-sided orbit: S_u exp(A T/2) S_l exp(A T/2), the
lower impact at T/2 with the normal -n and the mirrored state (2 x_s - x, -x'); :func:`half_period_jacobian` is the
Jacobian -S exp(A T/2) of the half-period map y -> mirror(flow(y)), whose fixed point the symmetric orbit is: its
multiplier -1 is a symmetry-breaking pitchfork (the full multiplier +1), +1 a fold.
"""

from __future__ import annotations

from enum import IntEnum

import numpy as np
from numpy.typing import NDArray, ArrayLike

from vibroimpact.analysis.impact_orbit import ImpactOrbit

__all__ = ["floquet_multipliers", "is_stable", "monodromy", "half_period_jacobian", "saltation", "MARGINAL_MODULUS", "Regime", "classify", "regime_attributes"]

#: Distance of the largest |Floquet multiplier| from 1 [-] within which an orbit is marginal: on the unit circle to
#: round-off (a conservative orbit, the closed form of an undamped or R = 1 layout), neither stable nor unstable.
MARGINAL_MODULUS = 1e-9


def _flow(state_matrix: NDArray[np.float64], duration: NDArray[np.float64]) -> NDArray[np.float64]:
    """exp(A t) for every duration, shape duration.shape + (2N, 2N), from one eigendecomposition."""
    eigenvalues, vectors = np.linalg.eig(state_matrix)
    inverse = np.linalg.inv(vectors)
    growth = np.exp(eigenvalues * np.asarray(duration)[..., None])
    return np.real(np.einsum("ij,...j,jk->...ik", vectors, growth, inverse))


def saltation(orbit: ImpactOrbit, lower: bool = False) -> NDArray[np.float64]:
    """The saltation matrix of the orbit's (upper, or lower) impact, shape S + (2N, 2N)."""
    layout = orbit.layout
    structure = layout.structure
    size = structure.size
    minv = np.linalg.inv(structure.mass_matrix)
    n = -layout.normal if lower else layout.normal
    before, after = orbit.state_before_impact(), orbit.state_after_impact()
    t_impact = orbit.impact_time
    static_load = structure.stiffness_matrix @ orbit.static
    if lower:  # the mirror image half a period later: x - x_s and x' change sign, so does the harmonic load
        mirror = np.concatenate([-np.ones(size), -np.ones(size)])
        shift = np.concatenate([2.0 * orbit.static, np.zeros(size)])
        before, after = before * mirror + shift, after * mirror + shift
        t_impact = t_impact + orbit.period / 2.0
    force = (orbit.load * np.exp(1j * orbit.omega * t_impact)[..., None]).real + static_load
    a = structure.state_matrix

    def field(y: NDArray) -> NDArray:
        return y @ a.T + np.concatenate([np.zeros_like(force), force @ minv.T], axis=-1)

    kick = (1.0 + orbit.restitution)[..., None, None] * layout.effective_mass * np.outer(minv @ n, n)
    reset = np.broadcast_to(np.eye(2 * size), orbit.omega.shape + (2 * size, 2 * size)).copy()
    reset[..., size:, size:] -= kick
    f_before, f_after = field(before), field(after)
    jump = f_after - np.einsum("...ij,...j->...i", reset, f_before)
    gradient = np.concatenate([n, np.zeros(size)])
    with np.errstate(divide="ignore", invalid="ignore"):
        return reset + jump[..., :, None] * gradient[None, :] / (f_before @ gradient)[..., None, None]


def monodromy(orbit: ImpactOrbit) -> NDArray[np.float64]:
    """The monodromy matrix from just after the (upper) impact over one period, shape S + (2N, 2N)."""
    a = orbit.layout.structure.state_matrix
    upper = saltation(orbit)
    if not orbit.two_sided:
        return upper @ _flow(a, orbit.period)
    half = _flow(a, orbit.period / 2.0)
    return upper @ half @ saltation(orbit, lower=True) @ half


def half_period_jacobian(orbit: ImpactOrbit) -> NDArray[np.float64]:
    """Two-sided orbits: -S exp(A T/2), the Jacobian of the half-period map (module docstring); monodromy = its square."""
    if not orbit.two_sided:
        raise ValueError("half_period_jacobian: the orbit is not the symmetric two-sided one")
    return -saltation(orbit) @ _flow(orbit.layout.structure.state_matrix, orbit.period / 2.0)


def floquet_multipliers(solution: ImpactOrbit) -> NDArray[np.complex128]:
    """Floquet multipliers of each impact orbit, shape S + (2N,), sorted by decreasing modulus; NaN where no orbit
    exists.

    Parameters
    ----------
    solution : ImpactOrbit
        Any structure's orbit, one- or two-sided (:func:`vibroimpact.analysis.impact_orbit.solve_impact_orbit`,
        :func:`vibroimpact.analysis.pgf.solve_one_impact`).
    """
    matrix = monodromy(solution)
    size = matrix.shape[-1]
    out = np.full(solution.omega.shape + (size,), np.nan, dtype=complex)
    ok = solution.exists & np.all(np.isfinite(matrix), axis=(-2, -1))
    if np.any(ok):
        values = np.linalg.eigvals(matrix[ok])
        out[ok] = np.take_along_axis(values, np.argsort(-np.abs(values), axis=-1, kind="stable"), axis=-1)
    return out


def is_stable(solution: ImpactOrbit) -> NDArray[np.bool_]:
    """True where the orbit exists and all Floquet multipliers satisfy |mu| < 1: :attr:`ImpactOrbit.stable
    <vibroimpact.analysis.impact_orbit.ImpactOrbit.stable>`."""
    return solution.stable


# --------------------------------------------------------------------------------------------------------------------
# The ``regime`` flag of the output datasets: which kind of steady motion a value describes.
# --------------------------------------------------------------------------------------------------------------------

class Regime(IntEnum):
    """Regime of the steady-state motion at one point of a study."""

    #: The solution was not computed at this point (time-domain solutions off their own frequency grid).
    NOT_COMPUTED = -1

    #: No contact: the linear response stays inside the clearance and no one-impact solution exists.
    LINEAR = 0
    #: Admissible one-impact-per-period motion; the linear response would cross the stop.
    ONE_IMPACT = 1
    #: Admissible one-impact motion although the linear response also fits: two regimes coexist (hysteresis);
    #: the one-impact values are reported.
    ONE_IMPACT_COEXISTING_LINEAR = 2
    #: The linear response fits; a one-impact solution of eqs. 15-16 exists but penetrates the stop.
    LINEAR_WITH_INADMISSIBLE_ONE_IMPACT = 3
    #: The linear response crosses the stop and the only one-impact solution penetrates it: values are NaN.
    NONE_INADMISSIBLE_ONE_IMPACT = 4
    #: The linear response crosses the stop and no one-impact solution exists: values are NaN.
    NONE = 5
    #: Solution ``linear`` only: the response without a stop (Delta -> infinity) crosses the clearance.
    LINEAR_EXCEEDS_CLEARANCE = 6
    #: The linear response fits and an admissible one-impact orbit exists but is unstable (Floquet, ``pgf``): the
    #: motion that persists is the linear one, whose values are reported.
    LINEAR_WITH_UNSTABLE_ONE_IMPACT = 7
    #: Time-domain solutions: a converged periodic motion with impacts other than one impact per period (several
    #: impacts, sticking between them, or a period of several excitation periods).
    PERIODIC_IMPACTS = 8
    #: Time-domain solutions: no periodic steady state within the allowed periods, and the evidence (Lyapunov exponent,
    #: strobe spectrum, rotation number) does not decide between quasi-periodic and chaotic motion; values are
    #: averages over the measured window.
    IRREGULAR = 9
    #: Swept-sine tests: contacts occurred within the estimator's window. A sweep is a slow transient, not a steady
    #: state: ``impacts_per_period`` says how many contacts per cycle.
    SWEPT_CONTACT = 10
    #: The solution could not be computed at this point; values are NaN. Time-domain solutions: the integrator failed
    #: (the error went to stderr). Closed forms (``linear``, ``pgf``, ``pgf_paper``): the sums are ill-conditioned,
    #: near an undamped or nearly undamped natural frequency (:data:`vibroimpact.analysis.greens.GREEN_CONDITION_LIMIT`):
    #: the closed form is not valid there, and whether an orbit exists is unknown.
    FAILED = 11
    #: Time-domain solutions: no periodic steady state, and the motion is quasi-periodic: its largest Lyapunov exponent
    #: (``lyapunov_exponent`` [1/period]) is 0 within its error and the strobes lie on a closed curve (line spectrum,
    #: regular rotation number); values are averages over the measured window.
    QUASI_PERIODIC = 12
    #: Time-domain solutions: no periodic steady state, and the motion is chaotic: its largest Lyapunov exponent is
    #: positive beyond its error; values are averages over the measured window.
    CHAOTIC = 13
    #: Time-domain solutions: a converged motion without impacts in which a stop holds the structure (a preloading
    #: stop whose contact force the excitation never lifts it from): periodic and impact-free, but not the linear
    #: motion.
    HELD_ON_STOP = 14


def classify(linear_fits: ArrayLike, exists: ArrayLike, admissible: ArrayLike) -> NDArray[np.int8]:
    """Regime flag from three boolean arrays (broadcast together).

    Parameters
    ----------
    linear_fits : array_like of bool
        The linear steady state stays inside the clearance, q |H12| <= Delta.
    exists : array_like of bool
        A one-impact solution of eqs. 15-16 exists (real root, J >= 0).
    admissible : array_like of bool
        That solution keeps X2(t) <= Delta over the whole period.
    """
    fits, found, ok = np.broadcast_arrays(
        np.asarray(linear_fits, bool), np.asarray(exists, bool), np.asarray(admissible, bool) & np.asarray(exists, bool)
    )
    flag = np.full(fits.shape, Regime.NONE, dtype=np.int8)
    flag[~fits & found & ~ok] = Regime.NONE_INADMISSIBLE_ONE_IMPACT
    flag[~fits & ok] = Regime.ONE_IMPACT
    flag[fits & ok] = Regime.ONE_IMPACT_COEXISTING_LINEAR
    flag[fits & found & ~ok] = Regime.LINEAR_WITH_INADMISSIBLE_ONE_IMPACT
    flag[fits & ~found] = Regime.LINEAR
    return flag


def regime_attributes() -> dict[str, object]:
    """CF attributes of the ``regime`` variable."""
    return {
        "long_name": "steady-state regime",
        "units": "1",
        "flag_values": np.array([int(r) for r in Regime], dtype=np.int8),
        "flag_meanings": " ".join(r.name.lower() for r in Regime),
    }
