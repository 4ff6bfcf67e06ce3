"""The largest stable response of a design with Kelvin-Voigt bumpers over a band: the design search's fast objective
where the stops are bumpers (issue 32), the compliant counterpart of :func:`~vibroimpact.analysis.band_worst.
closed_form_worst`.

A bumper has no closed-form orbit, but its rigid twin (the same stops, rigid, with the bumper's restitution) has, and
the bumper's period-1 orbit tends to it as the bumper stiffens (:mod:`vibroimpact.orbits.bumper_map`). So each root
of the rigid closed form is followed along the scan: at every frequency the bumper's stroboscopic map (exact flow,
exact Jacobian) is shot from the orbit found at the previous frequency, else from the rigid twin's closed-form orbit
there, and kept where it converges with a contact per period; its Floquet multipliers say whether it is stable, one
exact integration over its period gives |X| (the fundamental harmonic) and the impulse of its contact. The contact-free
motion is the linear closed form, as for a rigid stop. The largest stable |X| of each motion is refined between the
scan points either side by a bounded scalar search, each trial shot from the nearest orbit found: the maximum's
frequency to ``tolerance``, not to a scan step.

What this cannot see is what the rigid screen cannot see: period-k and multi-contact orbits and non-periodic
attractors, the band's share where no motion it knows is stable (:attr:`BandWorst.uncovered`), with the rigid screen's
guess there (the rigid twin's closed-form orbits that exist, stable or not).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import minimize_scalar

from vibroimpact.analysis.band_worst import MOTIONS, BandWorst, contact_free_curve, existing_impact_curve, refine_maximum, scan_frequencies, uncovered_share
from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.analysis.layout import closed_form_refusal
from vibroimpact.analysis.measures import Measure, as_measure
from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.orbits.branch import PeriodicOrbit
from vibroimpact.orbits.bumper_map import CompiledPeriodMap
from vibroimpact.orbits.maps import ImpactMap
from vibroimpact.orbits.shooting import ShootingError, ShootingSettings, shoot

__all__ = ["bumper_worst", "bumper_at", "bumper_curves", "rigid_twin", "bumper_screen_refusal", "BUMPER_SCAN", "BUMPER_SPACING"]

#: Evenly spaced frequencies of the bumper screen's scan (each a shot orbit per root, where the rigid screen solves a
#: closed form).
BUMPER_SCAN = 61
#: Largest step of the bumper screen's scan relative to the frequency [-] where the structure can resonate (free,
#: locked and bumper-engaged modes, the contact region: :func:`~vibroimpact.analysis.scan_grid.scan_frequencies`).
#: Coarser than the closed forms' 1 %, since each point is a shot orbit per root: the resolution the shipped scan has
#: over the design scenes' band (61 points over 15-45 Hz: 0.5 Hz, 3.3 % of 15 Hz), so those scans stay as they were,
#: and a wider band gets that resolution where it steps over a resonance (a 250 Hz bumper over 15-450 Hz: 93 points).
BUMPER_SPACING = 0.035
#: Newton's tolerance of the screen's shots (scaled residual) [-] and its iterations: from the previous frequency's
#: orbit 3-6 converge; a shot that needs more is at an orbit's end (grazing, a fold), where the screen gives up.
_SHOOTING = ShootingSettings(tolerance=1e-10, max_iterations=12)
#: A shot orbit is stable when its largest Floquet multiplier is below 1 - this [-] (the closed forms' margin).
_MARGIN = 1e-9


def rigid_twin(problem: ImpactProblem) -> ImpactProblem:
    """``problem`` with each Kelvin-Voigt bumper replaced by a rigid stop of the same clearance and restitution: the
    limit of infinite bumper stiffness, whose closed-form orbits start the bumper's."""
    stops = tuple(dataclasses.replace(stop, law=RigidStop(stop.law.clearance, stop.law.restitution)) if isinstance(stop.law, KelvinVoigtBumper) else stop for stop in problem.stops)
    return ImpactProblem(problem.system, stops, problem.harmonic)


def bumper_screen_refusal(problem: ImpactProblem) -> str | None:
    """Why :func:`bumper_worst` does not apply to ``problem``, or None: its stops must all be bumpers, and their rigid
    twin must have the closed forms (one stop, or a symmetric pair; no free mass)."""
    if not problem.stops or not all(isinstance(stop.law, KelvinVoigtBumper) for stop in problem.stops):
        return "the bumper screen needs every stop to be a Kelvin-Voigt bumper"
    return closed_form_refusal(rigid_twin(problem))


@dataclasses.dataclass(frozen=True, eq=False)
class _Point:
    """One shot bumper orbit on the scan: its state at t = 0, contacts per period, |X| [m], impulse of its largest
    contact [N s], stable."""

    state: NDArray[np.float64]
    contacts: int
    amplitude: float
    impulse: float
    stable: bool


def _measured(system: ImpactMap, problem: ImpactProblem, orbit: PeriodicOrbit, measure: int | Measure) -> _Point | None:
    """The orbit's ``measure`` (of the fundamental harmonics over its period, as :func:`~vibroimpact.orbits.orbit_measures.orbit_measures`
    gives it), stability and (stable orbits) the largest impulse of one whole contact, or None where it has no contact
    (a contact-free orbit: the linear closed form's). The impulse is taken over two periods, so that a contact under
    way at the strobe is also seen whole, not only its part after it."""
    if orbit.impacts < 1:
        return None
    stable = orbit.floquet_modulus < 1.0 - _MARGIN
    trajectory = system.engine.integrate(problem, orbit.state, 0.0, 2 if stable else 1, moments=True)
    n, k = problem.size, len(problem.stops)
    moments = trajectory.moments[0]
    amplitude = float(as_measure(measure, problem).of_harmonics(problem, problem.omega, moments[:n], moments[n : n + k])) * 2.0 / problem.period
    impulse = (float(np.max(np.abs(trajectory.impulses))) if trajectory.impulses.size else 0.0) if stable else math.nan
    return _Point(orbit.state, orbit.impacts, amplitude, impulse, stable)


def _shot(system: CompiledPeriodMap, seeds: list[NDArray[np.float64]], p: NDArray[np.float64], measure: Measure) -> _Point | None:
    """The first seed's orbit that converges with a contact per period, measured (None: none does): Newton on the
    engine's compiled period (:class:`~vibroimpact.orbits.bumper_map.CompiledPeriodMap`)."""
    problem = system.problem_at(p)
    for seed in seeds:
        try:
            orbit = shoot(system, seed, p, settings=_SHOOTING)
        except (ShootingError, ValueError):  # no orbit from this seed; a problem the engine refuses
            continue
        point = _measured(system, problem, orbit, measure)
        if point is not None:
            return point
    return None


def _maps(problem: ImpactProblem) -> tuple[CompiledPeriodMap, ImpactMap]:
    """The bumper problem's map (its engine's compiled period) and its rigid twin's."""
    return CompiledPeriodMap(problem), ImpactMap(rigid_twin(problem))


def _rigid_seeds(twin: ImpactMap, f: NDArray[np.float64], root: str) -> NDArray[np.float64]:
    """The rigid twin's closed-form orbit state of ``root`` at each frequency ``f`` [Hz], shape (F, 2N) (NaN rows where
    it does not exist): one vectorised solve for the whole scan."""
    orbit = solve_impact_orbit(twin.problem, frequency=f, root=root)
    states = np.asarray(orbit.state_at(np.zeros(np.shape(orbit.omega) + (1,))), dtype=float).reshape(f.size, -1)
    exists = np.all(np.asarray(orbit.exists, dtype=bool).reshape(f.size, -1), axis=1)
    return np.where(exists[:, None], states, np.nan)


def _track(system: CompiledPeriodMap, twin: ImpactMap, f: NDArray[np.float64], root: str, measure: Measure) -> list[_Point | None]:
    """The bumper orbit of one root along the scan: each shot from the previous one found, else (or where that
    fails) from the rigid twin's closed form (solved for the whole scan once one is needed)."""
    p = np.array(system.parameters, dtype=float)
    points: list[_Point | None] = []
    previous: _Point | None = None
    seeds: NDArray[np.float64] | None = None
    for i, frequency in enumerate(f):
        p[0] = frequency
        found = _shot(system, [previous.state], p.copy(), measure) if previous is not None else None
        if found is None:
            seeds = _rigid_seeds(twin, f, root) if seeds is None else seeds
            found = _shot(system, [seeds[i]], p.copy(), measure) if np.all(np.isfinite(seeds[i])) else None
        previous = found
        points.append(found)
    return points


def bumper_worst(problem: ImpactProblem, band: tuple[float, float], measure: int | Measure = 0, scan: int = BUMPER_SCAN, tolerance: float = 1e-7) -> BandWorst:
    """The largest stable ``measure`` over ``band`` [Hz] among the contact-free motion and the period-1
    bumper orbits grown from the rigid twin's closed forms (module docstring).

    Parameters
    ----------
    problem : ImpactProblem
        Kelvin-Voigt bumpers whose rigid twin has the closed forms (:func:`bumper_screen_refusal`).
    band, measure, scan, tolerance
        As :func:`~vibroimpact.analysis.band_worst.closed_form_worst` (``scan``: evenly spaced shot orbits per root,
        more where they are coarser than :data:`BUMPER_SPACING` of the frequency around the structure's resonances).
    """
    f = scan_frequencies(band, scan, problem, spacing=BUMPER_SPACING)
    reason = bumper_screen_refusal(problem)
    if reason is not None:
        raise ValueError(reason)
    system, twin = _maps(problem)
    measure = as_measure(measure, problem)
    free, free_everywhere = contact_free_curve(problem, f, measure)
    covered = np.isfinite(free)
    best = (0.0, math.nan, MOTIONS[0], 0)
    if np.any(covered):
        k = int(np.nanargmax(free))
        best = (float(free[k]), float(f[k]), MOTIONS[1], 0)  # the contact-free maximum: the linear closed form's, refined below
        best = max(best, (*refine_maximum(problem, f, k, float(free[k]), measure, None, tolerance), MOTIONS[1], 0), key=lambda b: b[0])
    impulse = 0.0
    for root in ("+", "-"):
        track = _track(system, twin, f, root, measure)
        x = np.array([pt.amplitude if pt is not None and pt.stable else np.nan for pt in track])
        stable_impulses = [pt.impulse for pt in track if pt is not None and pt.stable]
        impulse = max([impulse, *stable_impulses])
        covered |= np.isfinite(x)
        if not np.any(np.isfinite(x)):
            continue
        k = int(np.nanargmax(x))
        value, where = _refine(system, f, track, k, measure, tolerance)
        if value > best[0]:
            best = (value, where, MOTIONS[2], track[k].contacts)  # type: ignore[union-attr]
    estimate, estimate_frequency = 0.0, math.nan
    if not covered.all():  # the rigid screen's guess there: the rigid twin's impact orbits that exist, else contact-free
        guess = np.fmax.reduce([existing_impact_curve(twin.problem, f, measure, root) for root in ("+", "-")])
        there = np.where(np.isfinite(guess), guess, free_everywhere)[~covered]
        k = int(np.argmax(there))
        estimate, estimate_frequency = float(there[k]), float(f[~covered][k])
    return BandWorst(best[0], best[1], best[2], best[3], uncovered_share(f, covered), estimate, estimate_frequency, impulse)


def _refine(system: CompiledPeriodMap, f: NDArray[np.float64], track: list[_Point | None], k: int, measure: Measure, tolerance: float) -> tuple[float, float]:
    """The largest stable |X| of the orbit ``track[k]`` between the scan points either side, each trial shot from the
    nearest scanned orbit (never below the scanned value)."""
    point = track[k]
    assert point is not None
    best = (point.amplitude, float(f[k]))
    a, b = float(f[max(k - 1, 0)]), float(f[min(k + 1, f.size - 1)])
    p = np.array(system.parameters, dtype=float)

    def negative(frequency: float) -> float:
        nearest = min((j for j in (k - 1, k, k + 1) if 0 <= j < f.size and track[j] is not None), key=lambda j: abs(f[j] - frequency))
        p[0] = frequency
        trial = _shot(system, [track[nearest].state], p.copy(), measure)  # type: ignore[union-attr]
        return -trial.amplitude if trial is not None and trial.stable else 0.0

    found = minimize_scalar(negative, bounds=(a, b), method="bounded", options={"xatol": tolerance * b})
    if -float(found.fun) > best[0]:
        best = (-float(found.fun), float(found.x))
    return best


def bumper_curves(problem: ImpactProblem, f: NDArray[np.float64], measure: int | Measure = 0) -> dict[str, tuple[NDArray[np.float64], NDArray[np.int8]]]:
    """Each root's bumper orbit along frequencies ``f`` [Hz] (ascending; grown as in :func:`bumper_worst`): the
    ``measure`` where one was found (NaN elsewhere) and its state (1 stable, 0 unstable, -1 none)."""
    system, twin = _maps(problem)
    measure = as_measure(measure, problem)
    out = {}
    for root in ("+", "-"):
        track = _track(system, twin, np.asarray(f, dtype=float), root, measure)
        x = np.array([pt.amplitude if pt is not None else np.nan for pt in track])
        state = np.array([-1 if pt is None else int(pt.stable) for pt in track], dtype=np.int8)
        out[root] = (x, state)
    return out


def bumper_at(problem: ImpactProblem, frequency: float, measure: int | Measure = 0) -> BandWorst:
    """The largest stable ``measure`` at one ``frequency`` [Hz] among the contact-free motion and the
    bumper orbits shot from each root of the rigid twin's closed form (an absorber's operating point)."""
    f = np.array([float(frequency)])
    system, twin = _maps(problem)
    measure = as_measure(measure, problem)
    free = contact_free_curve(problem, f, measure)[0]
    best = (float(free[0]), float(frequency), MOTIONS[1], 0) if math.isfinite(free[0]) else (0.0, math.nan, MOTIONS[0], 0)
    covered = math.isfinite(free[0])
    for root in ("+", "-"):
        point = _track(system, twin, f, root, measure)[0]
        if point is not None and point.stable:
            covered = True
            if point.amplitude > best[0]:
                best = (point.amplitude, float(frequency), MOTIONS[2], point.contacts)
    return BandWorst(best[0], best[1], best[2], best[3], 0.0 if covered else 1.0)
