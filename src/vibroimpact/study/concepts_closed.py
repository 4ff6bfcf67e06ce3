"""The closed forms of each absorber concept on the fine frequency grid: the linear steady state (no stop, or a stop
it does not reach), and the impact orbit where a closed form applies, with its admissibility and Floquet stability.

Every layout, the paper's included, uses the closed form :func:`vibroimpact.analysis.impact_orbit.solve_impact_orbit`
(one stop, absolute or relative, or a symmetric two-sided stop) with
:func:`vibroimpact.analysis.stability.floquet_multipliers`. Where no closed
form applies the values are NaN and ``note`` says why: the simulations and the continuation cover those concepts.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.analysis.stability import MARGINAL_MODULUS, floquet_multipliers
from vibroimpact.scene.concepts import Concept
from vibroimpact.simulation.layout import base_force

__all__ = ["ClosedForms", "closed_forms", "MARGINAL_MODULUS"]


@dataclass(frozen=True)
class ClosedForms:
    """A concept's closed forms at ``frequency``.

    Attributes
    ----------
    frequency : ndarray, shape (F,)
        [Hz].
    linear_x1, linear_base_force : ndarray, shape (F,)
        |X1| [m] and |base force| [N] of the linear steady state without a stop (fundamental amplitudes).
    linear_fits : ndarray of bool, shape (F,)
        The linear motion stays clear of every stop (always true without one): it is then a stable steady state.
    impact_x1, impact_base_force : ndarray, shape (F,)
        The same of the closed-form impact orbit where it exists and is admissible; NaN elsewhere.
    impact_stable : ndarray of int8, shape (F,)
        1 stable, 0 unstable, -1 no admissible orbit or stability unknown.
    impacts_per_period : int
        Of the impact orbit (1; 2 for a two-sided stop); 0 without one.
    note : str
        Why no impact orbit is given, if none is.
    """

    frequency: NDArray[np.float64]
    linear_x1: NDArray[np.float64]
    linear_base_force: NDArray[np.float64]
    linear_fits: NDArray[np.bool_]
    impact_x1: NDArray[np.float64]
    impact_base_force: NDArray[np.float64]
    impact_stable: NDArray[np.int8]
    impacts_per_period: int = 0
    note: str = ""


def closed_forms(concept: Concept, amplitude: float, frequency: NDArray[np.float64]) -> ClosedForms:
    """Linear and impact closed forms of ``concept`` under q = ``amplitude`` [N] on the primary mass."""
    f = np.asarray(frequency, dtype=float)
    w = 2.0 * np.pi * f
    structure = concept.system.structure
    load = np.zeros(structure.size, dtype=complex)
    load[0] = amplitude
    x = structure.receptance_matrix(w) @ load
    base = base_force(structure, w, x)
    fits = np.ones(f.shape, dtype=bool)
    for stop in concept.stops:
        fits &= np.abs(x @ stop.normal(structure.size)) <= stop.clearance
    nan = np.full(f.shape, np.nan)
    empty = ClosedForms(f, np.abs(x[:, 0]), np.abs(base), fits, nan, nan, np.full(f.shape, -1, dtype=np.int8))
    if not concept.stops:
        return empty
    return _orbit(concept, amplitude, empty)


def _orbit(concept: Concept, amplitude: float, linear: ClosedForms) -> ClosedForms:
    """The general closed form (one stop, or a symmetric two-sided pair) with its Floquet multipliers; a layout that
    has none (e.g. two stops on different coordinates) gets a note instead."""
    problem = concept.problem(amplitude, float(linear.frequency[0]))
    try:
        orbit = solve_impact_orbit(problem, omega=2.0 * np.pi * linear.frequency)
    except ValueError as error:
        return _with_note(linear, f"no closed form: {error}")
    admissible = orbit.admissible()
    harmonics = orbit.harmonics()
    x1 = np.where(admissible, np.abs(harmonics[..., 0]), np.nan)
    w = orbit.omega
    rate = orbit.impacts_per_period * 2.0 * orbit.impulse / orbit.period
    through = float(np.sum(orbit.normal))  # 1^T n: 0 for a relative stop, whose impulses stay inside the structure
    # time from the impact: the base feels (1^T n) J at t = 0 and, two-sided, -(1^T n) J at T/2: fundamental k J / T
    base = base_force(concept.system.structure, w, harmonics) + through * rate
    force = np.where(admissible, np.abs(base), np.nan)
    stable = np.full(w.shape, -1, dtype=np.int8)
    index = np.flatnonzero(admissible)
    if index.size:
        modulus = np.max(np.abs(floquet_multipliers(orbit.take(index))), axis=-1)
        stable[index] = np.where(modulus < 1.0 - MARGINAL_MODULUS, 1, 0)
    return ClosedForms(linear.frequency, linear.linear_x1, linear.linear_base_force, linear.linear_fits, x1, force, stable, orbit.impacts_per_period)


def _with_note(linear: ClosedForms, note: str) -> ClosedForms:
    return ClosedForms(linear.frequency, linear.linear_x1, linear.linear_base_force, linear.linear_fits, linear.impact_x1, linear.impact_base_force, linear.impact_stable, 0, note)
