"""The ``regime`` flag of the output datasets: which kind of steady motion a value describes.

Stored as an integer variable with CF ``flag_values`` / ``flag_meanings`` attributes.
"""

from __future__ import annotations

from enum import IntEnum

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["Regime", "classify", "regime_attributes"]


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
    #: Time-domain solutions: a converged periodic motion other than one impact per period (several impacts,
    #: sticking, or a period of several excitation periods).
    PERIODIC_IMPACTS = 8
    #: Time-domain solutions: no periodic steady state within the allowed periods, and the evidence (Lyapunov exponent,
    #: strobe spectrum, rotation number) does not decide between quasi-periodic and chaotic motion; values are
    #: averages over the measured window.
    IRREGULAR = 9
    #: Swept-sine tests: contacts occurred within the estimator's window. A sweep is a slow transient, not a steady
    #: state: ``impacts_per_period`` says how many contacts per cycle.
    SWEPT_CONTACT = 10
    #: Time-domain solutions: the integrator failed at this point (the error went to stderr); values are NaN.
    FAILED = 11
    #: Time-domain solutions: no periodic steady state, and the motion is quasi-periodic: its largest Lyapunov exponent
    #: (``lyapunov_exponent`` [1/period]) is 0 within its error and the strobes lie on a closed curve (line spectrum,
    #: regular rotation number); values are averages over the measured window.
    QUASI_PERIODIC = 12
    #: Time-domain solutions: no periodic steady state, and the motion is chaotic: its largest Lyapunov exponent is
    #: positive beyond its error; values are averages over the measured window.
    CHAOTIC = 13


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
