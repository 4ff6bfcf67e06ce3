"""Floquet stability of the closed-form impact orbits, and the regime flag of the output datasets.

The monodromy (saltation matrix x exact flow over the period) and the Floquet multipliers are computed by
:mod:`~vibroimpact.analysis.floquet`, below :mod:`~vibroimpact.analysis.impact_orbit` (whose orbits compute their own
multipliers with it), and are re-exported here: :func:`floquet_multipliers`, :func:`monodromy`,
:func:`half_period_jacobian`, :func:`saltation`. An orbit is asymptotically stable when all its multipliers lie inside
the unit circle (:func:`is_stable`, :data:`MARGINAL_MODULUS`).
"""

from __future__ import annotations

from enum import IntEnum

import numpy as np
from numpy.typing import NDArray, ArrayLike

from vibroimpact.analysis.floquet import floquet_multipliers, half_period_jacobian, monodromy, saltation
from vibroimpact.analysis.impact_orbit import ImpactOrbit

__all__ = ["floquet_multipliers", "is_stable", "monodromy", "half_period_jacobian", "saltation", "MARGINAL_MODULUS", "Regime", "classify", "regime_attributes"]

#: Distance of the largest |Floquet multiplier| from 1 [-] within which an orbit is marginal: on the unit circle to
#: round-off (a conservative orbit, the closed form of an undamped or R = 1 layout), neither stable nor unstable.
MARGINAL_MODULUS = 1e-9


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
