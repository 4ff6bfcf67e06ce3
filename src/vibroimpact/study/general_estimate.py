"""What ``--estimate`` assumes of a stepped scene's layout (any structure, load and stops).

The costs were measured on the paper's layout (N = 2 coordinates, K = 1 stop; the closed forms by its named route).
For N coordinates and K stops:

* an engine's cost per simulated period is scaled by (N / 2)^2 K: each step propagates 2N x 2N matrices (exact:
  eigenvector products; integrators: a Jacobian of that size, solved densely at this size) and checks every stop's
  gap (event functions, root bracketing);
* a closed form's cost per grid point by 1.3 (N / 2)^2 (the general closed form, matrices instead of the named
  receptances: 7.3 s against 5.8 s for 30 000 points of the paper's layout, measured) and by K for ``linear``;
  ``pgf_paper`` is still the named route (factor 1);
* the periods each point integrates are predicted as for the paper's layout where a closed form applies (none where
  the linear motion stays clear of every stop, a short transient where a stable closed-form orbit exists, the full
  search elsewhere); where none applies (several stops that are not a symmetric pair, a free mass), a point whose
  linear motion crosses a stop is assumed to settle after the short transient with 3 chances in 4 and to need the full
  search otherwise (:data:`UNKNOWN_WANDERING`: a guess, stated, not measured).
"""

from __future__ import annotations

import numpy as np

from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.analysis.layout import closed_form_refusal
from vibroimpact.analysis.linear import linear_amplitudes
from vibroimpact.analysis.stability import floquet_multipliers
from vibroimpact.scene.schema import Scene
from vibroimpact.study.general_values import scene_problem, stop_clearances

__all__ = ["engine_scale", "closed_form_scale", "general_orbit_outlook", "UNKNOWN_WANDERING", "CLOSED_FORM_FACTOR"]

#: Share of impacting points assumed never to settle where no closed form says which orbits are stable.
UNKNOWN_WANDERING = 0.25
#: Cost of the general closed form per point over the named one's, on the paper's layout (measured).
CLOSED_FORM_FACTOR = 1.3


def engine_scale(scene: Scene) -> float:
    """(N / 2)^2 K: an engine's cost per period relative to the paper's layout's."""
    return (scene.system.size / 2.0) ** 2 * len(scene.stop_specs)


def closed_form_scale(scene: Scene, solution: str) -> float:
    """A closed form's cost per grid point relative to the one measured on the paper's layout by its named route."""
    if solution == "pgf_paper":
        return 1.0
    size = (scene.system.size / 2.0) ** 2
    return CLOSED_FORM_FACTOR * size * (len(scene.stop_specs) if solution == "linear" else 1.0)


def general_orbit_outlook(scene: Scene, frequencies: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """(fits, admissible, stable, wandering share) over (restitution, clearance, frequency) for a general scene.

    ``fits``: the linear motion stays clear of every stop; ``admissible``/``stable``: a closed-form orbit exists, stays
    off the stops, is stable (all False without a closed form); the share of impacting points without a closed form
    assumed never to settle (0 where a closed form applies).
    """
    problem = scene_problem(scene, float(frequencies[0]), float(scene.restitution[0]), float(scene.clearance[0]))
    omega = 2.0 * np.pi * frequencies[None, None, :]
    clearances = stop_clearances(scene)[None, :, None, :]  # (1, nc, 1, K)
    fits = np.broadcast_to(linear_amplitudes(problem, omega).fits(clearances), (scene.restitution.size, scene.clearance.size, frequencies.size))
    shape = fits.shape
    if closed_form_refusal(problem) is not None:
        return fits, np.zeros(shape, dtype=bool), np.zeros(shape, dtype=bool), UNKNOWN_WANDERING
    orbit = solve_impact_orbit(problem, omega, scene.clearance[None, :, None], scene.restitution[:, None, None])
    admissible = np.broadcast_to(orbit.admissible(), shape)
    stable = np.zeros(shape, dtype=bool)
    if admissible.any():
        modulus = np.max(np.abs(floquet_multipliers(orbit)), axis=-1)
        stable = admissible & (modulus < 1.0)
    return fits, admissible, stable, 0.0
