"""The closed-form solutions (``linear``, ``pgf``, ``pgf_paper``) of a scene over its grid: any structure, load and stops;
part of the frequency-grid study shared by the stepped and swept kinds.

Values are named after the scene's coordinates (``<name>_amplitude``, ``<name>_rms``) and stops: a per-stop quantity
(:data:`~vibroimpact.scene.schema.STOP_QUANTITIES`) has a leading axis of one entry per stop. The force on the base
is the suspension's, 1^T (K + j w C) X, plus that of the absolute stops ((1^T n_k) times the impulse train's
fundamental; a relative stop acts inside the structure). ``pgf`` is the closed-form impact orbit of
:func:`vibroimpact.analysis.impact_orbit.solve_impact_orbit`: one impact per period on one rigid stop, or two on a
symmetric two-sided stop (the scene checker refuses layouts without one, with the reason). ``pgf_paper`` is the same
orbit with the paper's fitted Green function and constant chi22'(0-) (:class:`~vibroimpact.analysis.paper_fit.PaperFit`),
where the scene has the paper's layout on its named system.
"""

from __future__ import annotations

import functools
from typing import Callable

import numpy as np

from vibroimpact.analysis.impact_orbit import ImpactOrbit, solve_impact_orbit
from vibroimpact.analysis.linear import base_force, linear_amplitudes
from vibroimpact.analysis.paper_fit import PaperFit
from vibroimpact.analysis.stability import Regime, classify, MARGINAL_MODULUS, floquet_multipliers
from vibroimpact.model.collision import peak_acceleration_factor
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.scene.schema import MOTION_QUANTITIES, STOP_QUANTITIES, Scene
from vibroimpact.scene.variables import STABLE_MARGINAL

__all__ = ["general_linear_values", "general_pgf_values", "first_problem", "broadcast_quantities", "stop_clearances", "coordinate_quantity"]

_IMPACT_REGIMES = (Regime.ONE_IMPACT, Regime.ONE_IMPACT_COEXISTING_LINEAR)
_LINEAR_REGIMES = (Regime.LINEAR, Regime.LINEAR_WITH_INADMISSIBLE_ONE_IMPACT, Regime.LINEAR_WITH_UNSTABLE_ONE_IMPACT)


def coordinate_quantity(quantity: str, name: str) -> str:
    """The scene's name of a per-coordinate quantity: ``x1_amplitude`` -> ``<name>_amplitude`` (also ``_rms``,
    ``one_impact_x1_amplitude``)."""
    return quantity.replace("x1", name, 1)


def stop_clearances(scene: Scene) -> np.ndarray:
    """Delta of every stop at every clearance of the grid [m], shape (clearance, K)."""
    return np.array([[spec.values(np.nan, float(d))[1] for spec in scene.layout.stops] for d in scene.settings.clearance])


def first_problem(scene: Scene) -> ImpactProblem:
    """The scene's problem at the first point of its grid (its lowest frequency, first restitution and clearance)."""
    return scene.layout.problem(scene.amplitude, float(scene.settings.all_frequencies[0]), float(scene.settings.restitution[0]), float(scene.settings.clearance[0]))


def _per_coordinate(scene: Scene, template: str, values: np.ndarray) -> dict[str, np.ndarray]:
    """{<name>_<template>: values[..., i]} for every coordinate."""
    return {coordinate_quantity(template, name): values[..., i] for i, name in enumerate(scene.coordinates)}


def general_linear_values(scene: Scene, omega: np.ndarray, shape: tuple[int, ...]) -> dict[str, np.ndarray]:
    """The linear steady state (no stop) at ``omega`` [rad s-1] (axes of the full grid), flagged where it crosses a
    stop; the scene's quantities broadcast to ``shape`` (per-stop ones to (K, *shape)). Where the harmonic response
    is ill-conditioned (near an undamped natural frequency, :attr:`LinearAmplitudes.conditioned
    <vibroimpact.analysis.linear.LinearAmplitudes.conditioned>`) the regime is ``failed`` and every value NaN, as
    the other closed forms'."""
    problem = first_problem(scene)
    linear = linear_amplitudes(problem, omega=omega)
    x = linear.amplitudes  # omega.shape + (N,)
    count = len(scene.layout.stops)
    clearances = stop_clearances(scene)[None, :, None, None, None, :]  # (1, nc, 1, 1, 1, K)
    fits = linear.fits(clearances)  # (1, nc, 1, 1, F)
    force = base_force(scene.layout.structure, omega, x)
    rms = np.sqrt(linear.static**2 + 0.5 * np.abs(x) ** 2)
    zero_or_nan = np.where(fits, 0.0, np.nan)
    zero = np.where(linear.conditioned, 0.0, np.nan)  # NaN where refused (ill-conditioned)
    regime = np.where(fits, Regime.LINEAR, Regime.LINEAR_EXCEEDS_CLEARANCE)
    values = {
        **_per_coordinate(scene, "x1_amplitude", np.abs(x)),
        **_per_coordinate(scene, "x1_rms", rms),
        **_per_coordinate(scene, "one_impact_x1_amplitude", np.full(x.shape, np.nan)),
        "force_amplitude": np.abs(force),
        "suspension_force_amplitude": np.abs(force),
        "impulse": np.broadcast_to(zero, (count, *shape)),
        "phase": np.full(shape, np.nan),
        "regime": np.where(linear.conditioned, regime, Regime.FAILED).astype(np.int8),
        "stable": np.full(shape, -1, dtype=np.int8),
        "floquet_modulus": np.full(shape, np.nan),
        "one_impact_force_amplitude": np.full(shape, np.nan),
        "one_impact_impulse": np.full((count, *shape), np.nan),
        "impacts_per_period": np.broadcast_to(zero, shape),
        "converged": np.full(shape, -1, dtype=np.int8),
        "peak_acceleration": np.broadcast_to(zero_or_nan, (count, *np.shape(zero_or_nan))),
        "peak_contact_force": np.broadcast_to(zero_or_nan, (count, *np.shape(zero_or_nan))),
        "wall_time": np.full(shape, np.nan),
        **{name: np.full(shape, np.nan) for name in MOTION_QUANTITIES},
    }
    return broadcast_quantities(scene, values, shape)


def broadcast_quantities(scene: Scene, values: dict[str, np.ndarray], shape: tuple[int, ...]) -> dict[str, np.ndarray]:
    """The scene's quantities, each broadcast to ``shape`` (per-stop ones to (K, *shape)), or to a larger shape where a
    value depends on more of the grid's axes (a peak estimate on the bumper axis)."""
    count = len(scene.layout.stops)
    out = {}
    for name in scene.settings.quantities:
        target = (count, *shape) if name in STOP_QUANTITIES else shape
        out[name] = np.broadcast_to(values[name], np.broadcast_shapes(target, np.shape(values[name])))
    return out


def general_pgf_values(scene: Scene, omega: np.ndarray, delta: np.ndarray, r: np.ndarray, shape: tuple[int, ...], solution: str = "pgf") -> dict[str, np.ndarray]:
    """The closed-form impact orbit at ``omega`` [rad s-1], clearance ``delta`` [m] and restitution ``r`` [-] where
    it is admissible (and stable), else the linear motion where that fits; NaN elsewhere.
    Where the Green function sums are ill-conditioned (near an undamped natural frequency, :attr:`ImpactOrbit.conditioned`)
    the regime is ``failed`` and every value NaN: the closed form is not valid there (the orbit is not known to be
    absent, so neither ``none`` nor ``linear`` would be honest).

    ``solution`` ``pgf_paper`` takes the paper's fitted Green function and constant chi22'(0-) (``ValueError`` if the
    scene does not have the paper's layout on its named system). Its orbits are not orbits of the real system (x2'(0-)
    is not the impact law's), so they have no Floquet analysis: ``floquet_modulus`` NaN, ``stable`` -1, and an
    admissible orbit is reported where the linear motion also fits."""
    problem = first_problem(scene)
    w, d, rr = np.broadcast_arrays(omega, delta, r)
    if solution not in ("pgf", "pgf_paper"):
        raise ValueError(f"solution = {solution!r}: the closed-form orbits are 'pgf' and 'pgf_paper'")
    green = PaperFit.of(problem) if solution == "pgf_paper" else None
    orbit = solve_impact_orbit(problem, omega=w, clearance=d, restitution=rr, green=green)
    linear = linear_amplitudes(problem, omega=w)
    fits = linear.fits(stop_clearances(scene)[None, :, None, None, None, :])
    settings = scene.settings.admissibility
    admissible = orbit.admissible(settings.relative_tolerance, settings.samples_per_period)
    regime = classify(np.broadcast_to(fits, w.shape), orbit.exists, admissible)
    modulus = np.where(admissible, np.max(np.abs(floquet_multipliers(orbit)), axis=-1), np.nan) if green is None else np.full(w.shape, np.nan)
    unstable = modulus > 1.0 + MARGINAL_MODULUS
    regime[(regime == Regime.ONE_IMPACT_COEXISTING_LINEAR) & unstable] = Regime.LINEAR_WITH_UNSTABLE_ONE_IMPACT
    regime[~np.broadcast_to(orbit.conditioned, regime.shape)] = Regime.FAILED  # ill-conditioned sums: values NaN
    regime[~np.broadcast_to(linear.conditioned, regime.shape) & ~np.isin(regime, _IMPACT_REGIMES)] = Regime.FAILED  # nor the linear motion known
    impact = np.isin(regime, _IMPACT_REGIMES)
    free = np.isin(regime, _LINEAR_REGIMES)
    count = len(scene.layout.stops)
    stops = orbit.layout.stops  # the orbit's stop(s): one, or the upper and lower of a pair

    def choose(impact_value: np.ndarray, linear_value: np.ndarray) -> np.ndarray:
        return np.where(impact, impact_value, np.where(free, linear_value, np.nan))

    harmonics = functools.cache(orbit.harmonics)
    rms = functools.cache(orbit.rms)
    orbit_base_force = functools.cache(orbit.base_force)

    def per_stop(values: np.ndarray) -> np.ndarray:
        out = np.zeros((count, *w.shape))
        out[list(stops)] = values
        return out

    def stable_flag() -> np.ndarray:
        flag = np.where(np.abs(modulus - 1.0) <= MARGINAL_MODULUS, STABLE_MARGINAL, modulus < 1.0)
        return np.where(impact & np.isfinite(modulus), flag, -1).astype(np.int8)

    linear_rms = np.sqrt(linear.static**2 + 0.5 * np.abs(linear.amplitudes) ** 2)
    peaks = functools.cache(lambda: _peak_estimates(scene, orbit, count))
    makers: dict[str, Callable[[], np.ndarray]] = {
        "regime": lambda: regime,
        "force_amplitude": lambda: choose(np.abs(orbit_base_force(False)), np.abs(base_force(scene.layout.structure, w, linear.amplitudes))),
        "suspension_force_amplitude": lambda: choose(np.abs(orbit_base_force(True)), np.abs(base_force(scene.layout.structure, w, linear.amplitudes))),
        "impulse": lambda: np.where(impact, per_stop(orbit.impulse), np.where(free, 0.0, np.nan)),
        "phase": lambda: np.where(impact, orbit.phase, np.nan),
        "floquet_modulus": lambda: modulus,
        "stable": stable_flag,
        "one_impact_force_amplitude": lambda: np.where(orbit.exists, np.abs(orbit_base_force(False)), np.nan),
        "one_impact_impulse": lambda: np.where(orbit.exists, per_stop(orbit.impulse), np.nan),
        "impacts_per_period": lambda: np.where(impact, float(orbit.impacts_per_period), np.where(free, 0.0, np.nan)),
        "converged": lambda: np.full(w.shape, -1, dtype=np.int8),
        "peak_contact_force": lambda: np.where(impact, peaks()[0], np.where(free, 0.0, np.nan)),
        "peak_acceleration": lambda: np.where(impact, peaks()[1], np.where(free, 0.0, np.nan)),
        "wall_time": lambda: np.full(w.shape, np.nan),
        **{name: (lambda: np.full(w.shape, np.nan)) for name in MOTION_QUANTITIES},
    }
    for i, name in enumerate(scene.coordinates):
        makers[coordinate_quantity("x1_amplitude", name)] = lambda i=i: choose(np.abs(harmonics()[..., i]), np.abs(linear.amplitudes[..., i]))
        makers[coordinate_quantity("x1_rms", name)] = lambda i=i: choose(rms()[..., i], linear_rms[..., i])
        makers[coordinate_quantity("one_impact_x1_amplitude", name)] = lambda i=i: np.where(orbit.exists, np.abs(harmonics()[..., i]), np.nan)
    return broadcast_quantities(scene, {q: makers[q]() for q in scene.settings.quantities}, shape)


def _peak_estimates(scene: Scene, orbit: ImpactOrbit, count: int) -> tuple[np.ndarray, np.ndarray]:
    """Peak bumper force [N] and peak deceleration of the stopped coordinate [m s-2] per stop, from the rigid impulse,
    on the grid's axes and the bumper's (a swept bumper frequency: one estimate per value).

    One collision of a bumper of the stop's effective mass, entered at J / (m_eff (1 + R)), peaks at
    Gamma(xi_b) Omega_b J / (1 + R); the deceleration is that force less the force the structure presses the stop with
    at the impact (the holding force n M^-1 (f - C x' - K x) m_eff, just before it), over m_eff (for the paper's layout
    the paper's estimate). The bumper is the orbit's first stop's own, else the grid's. NaN without a bumper.
    """
    spec = scene.layout.stops[orbit.layout.stops[0]]
    grid_frequency = scene.settings.bumper_frequency if scene.settings.bumper_frequency is not None else np.array([np.nan])
    frequency = np.array([spec.bumper_frequency]) if spec.bumper_frequency is not None else grid_frequency
    grid_losses = scene.settings.loss_factors()
    losses = np.array([spec.values(float(r), np.nan, np.nan, float(xi))[3] for r, xi in zip(scene.settings.restitution, grid_losses)])
    gamma = np.array([peak_acceleration_factor(xi) if np.isfinite(xi) else np.nan for xi in losses])[:, None, None, None, None]
    omega_b = 2.0 * np.pi * frequency[None, None, :, None, None]
    force = gamma * omega_b * orbit.impulse / (1.0 + orbit.restitution)  # (R, D, bumper, 1, F)
    structure = scene.layout.structure
    size = structure.size
    n = orbit.normal
    m_eff = orbit.layout.effective_mass
    minv_n = np.linalg.solve(structure.mass_matrix, n)
    with np.errstate(invalid="ignore"):
        before = orbit.state_before_impact()
        x, v = before[..., :size], before[..., size:]
        t = orbit.impact_time
        harmonic = (orbit.load * np.exp(1j * orbit.omega * t)[..., None]).real
        _, static = first_problem(scene).load()
        pressing = (harmonic + static - v @ structure.damping_matrix.T - x @ structure.stiffness_matrix.T) @ minv_n * m_eff
        acceleration = (force - pressing) / m_eff
    force_out, acceleration_out = np.full((count, *force.shape), np.nan), np.full((count, *force.shape), np.nan)
    force_out[list(orbit.layout.stops)] = force
    acceleration_out[list(orbit.layout.stops)] = acceleration
    return force_out, acceleration_out
