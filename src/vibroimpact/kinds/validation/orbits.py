"""Validation cases checked by continuation of periodic orbits (the project's shooting and pseudo-arclength
continuation on the exact engine's stroboscopic map): Budd & Dux's ellipse and period doubling, the bouncing ball's
existence and period doubling, the grazing boundary of a forced oscillator.

Each continued point is an orbit of the exact map (its residual below the continuation's tolerance); special points
(folds, period doublings, grazings) are located by the continuation to a relative precision of 1e-10 in the
parameter. The closed forms are :mod:`vibroimpact.kinds.validation.formulas`.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from vibroimpact.engines.exact import ExactEngine
from vibroimpact.kinds.validation.formulas import CaseOutcome, Check, check
from vibroimpact.kinds.validation.formulas import (
    ball_existence,
    ball_multipliers,
    ball_period_doubling,
    ball_period_doubling_high_bounce,
    ball_state,
    budd_dux_constants,
    budd_dux_multipliers,
    budd_dux_period_doubling,
    budd_dux_velocities,
    budd_dux_state,
    grazing_amplitude,
)
from vibroimpact.kinds.validation.scene import BALL_TIME_SHIFT, ball_problem, ball_amplitude, budd_dux_problem, grazing_problem
from vibroimpact.kinds.validation.settings import BouncingBallCase, BuddDuxCase, GrazingCase
from vibroimpact.orbits.branch import Branch, PeriodicOrbit
from vibroimpact.orbits.continuation import ContinuationSettings, continue_branch
from vibroimpact.orbits.maps import ImpactMap
from vibroimpact.orbits.shooting import shoot

__all__ = ["brute_force", "MAX_KEPT_IMPACTS", "run_budd_dux", "run_bouncing_ball", "run_grazing", "multiplier_distance", "ELLIPSE_SAMPLES"]


# --------------------------------------------------------------------------------------------------------------------
# The bouncing ball's bifurcation diagram by brute force: Gamma stepped up, each point started from the last one's
# end state, the impacts of the last periods recorded (what the report draws behind the continued branch).
# --------------------------------------------------------------------------------------------------------------------

#: Impacts kept per brute-force point (the last ones; chattering can have many more).
MAX_KEPT_IMPACTS = 64


def brute_force(case: BouncingBallCase) -> xr.Dataset:
    """Impact speeds relative to the table, and the table's phase at each impact, over the last ``case.strobes``
    periods at each Gamma of the sweep.

    The sweep starts on the period-one orbit at the middle of its stable range, runs down to the low end, then
    restarts there and runs up to the high end (so that the period-one orbit is followed down to its fold and up
    through its doubling).
    """
    low, high = case.acceleration
    grid = np.round(low + case.brute_step * np.arange(int(math.floor((high - low) / case.brute_step * (1 + 1e-12))) + 1), 12)
    e, g = case.restitution, case.gravity
    omega = 2.0 * math.pi * case.frequency
    middle = 0.5 * (ball_existence(e) + ball_period_doubling(e))
    engine = ExactEngine()
    speeds = np.full((grid.size, MAX_KEPT_IMPACTS), np.nan)
    phases = np.full((grid.size, MAX_KEPT_IMPACTS), np.nan)
    counts = np.zeros(grid.size, dtype=np.int32)
    failed = np.zeros(grid.size, dtype=np.int8)
    start = ball_state(middle, e, g, omega, 0.5 / case.frequency)
    below = np.flatnonzero(grid < middle)[::-1]
    above = np.flatnonzero(grid >= middle)
    for order in (below, above):
        state = start.copy()
        for i in order:
            problem = ball_problem(case, float(grid[i]))
            periods = case.transient_periods + case.strobes
            try:
                run = engine.integrate(problem, state, 0.0, periods)
            except RuntimeError:  # the engine made no progress: the point stays blank, the next starts where this did
                failed[i] = 1
                continue
            recorded = run.impact_times >= run.strobe_times[case.transient_periods]
            kept = run.impact_velocities[recorded][-MAX_KEPT_IMPACTS:]
            speeds[i, : kept.size] = kept
            theta = problem.omega * run.impact_times[recorded][-MAX_KEPT_IMPACTS:] + BALL_TIME_SHIFT
            phases[i, : kept.size] = np.remainder(theta + np.pi, 2.0 * np.pi) - np.pi
            counts[i] = int(np.count_nonzero(recorded))
            state = np.array(run.final_state, dtype=float)
    return xr.Dataset(
        {
            "brute_impact_speed": (("brute_acceleration", "brute_impact"), speeds, {"units": "m s-1", "long_name": "impact speed relative to the table, last impacts of the recorded periods (NaN: fewer)"}),
            "brute_impact_phase": (("brute_acceleration", "brute_impact"), phases, {"units": "rad", "long_name": "table phase theta at those impacts (table at A sin theta), in [-pi, pi)"}),
            "brute_impacts": ("brute_acceleration", counts, {"units": "1", "long_name": "impacts in the recorded periods"}),
            "brute_failed": ("brute_acceleration", failed, {"units": "1", "long_name": "the engine made no progress at this point (left blank)",
                                                            "flag_values": np.array([0, 1], dtype=np.int8), "flag_meanings": "ran failed"}),
        },
        coords={"brute_acceleration": ("brute_acceleration", grid, {"units": "1", "long_name": "Gamma of the brute-force sweep"})},
    )

#: Points of the published ellipse drawn in the report.
ELLIPSE_SAMPLES = 721
#: Periods simulated before the impacting orbit of the grazing case is shot.
_SETTLE_PERIODS = 600
#: What the continuations detect.
_DETECT = ("fold", "period_doubling", "neimark_sacker", "grazing")
_STABLE = {"long_name": "Floquet stability of the continued orbit", "units": "1", "flag_values": np.array([0, 1], dtype=np.int8), "flag_meanings": "unstable stable"}


def multiplier_distance(computed: NDArray[np.complex128], published: NDArray[np.complex128]) -> float:
    """Largest distance from a computed multiplier to the nearest published one, over max(1, |published|) [-]."""
    published = np.asarray(published)
    return float(max(np.min(np.abs(published - mu)) / max(1.0, float(np.max(np.abs(published)))) for mu in np.asarray(computed)))


def _map(problem, parameter: str, low: float, high: float, scale: float) -> ImpactMap:
    """The exact stroboscopic map with ``parameter`` kept inside [low, high] and measured in units of ``scale``."""
    scales = np.array(ImpactMap.natural_scale(problem))
    scales[ImpactMap.parameter_names.index(parameter)] = scale
    return ImpactMap(problem, 1, ExactEngine(), bounds={parameter: (low, high)}, parameter_scale=scales)


def _special(branch: Branch, kind: str) -> float:
    """The parameter of the first special point of ``kind`` on ``branch`` (NaN: none)."""
    found = branch.special(kind)
    return float(found[0].value) if found else math.nan


def _impact_velocity(orbit: PeriodicOrbit) -> float:
    """The approach speed of the orbit's one impact (NaN unless it has exactly one)."""
    hybrid = orbit.hybrid
    return float(hybrid.min_impact_velocity) if hybrid is not None and hybrid.impacts == 1 else math.nan


def _worst(errors: NDArray[np.float64]) -> int:
    return int(np.nanargmax(errors)) if np.any(np.isfinite(errors)) else 0


# ------------------------------------------------------------------------------------------------ Budd & Dux
def run_budd_dux(case: BuddDuxCase, say=lambda message: None) -> CaseOutcome:
    """Continue the period-one orbit in sigma over ``case.clearance`` and compare it with the ellipse."""
    w, r = case.forcing_frequency, case.restitution
    low, high = case.clearance
    sigma0 = case.start_clearance
    v0 = float(budd_dux_velocities(sigma0, w, r)[1])
    problem = budd_dux_problem(case, sigma0)
    mapping = _map(problem, "clearance", low, high, 0.05)
    say(f"budd_dux: shooting at sigma = {sigma0:g}, then continuing over [{low:g}, {high:g}]")
    orbit = shoot(mapping, budd_dux_state(sigma0, v0, w, r, 0.0), mapping.parameters)
    branch = continue_branch(mapping, orbit, "clearance", ContinuationSettings(step=0.05, max_step=0.3, lower=low, upper=high, max_steps=case.max_steps, detect=_DETECT, stop_at_grazing=True))
    sigma = branch.values
    velocity = np.array([_impact_velocity(o) for o in branch.orbits])
    roots = budd_dux_velocities(sigma, w, r)
    published = np.where(np.abs(roots[:, 1] - velocity) <= np.abs(roots[:, 0] - velocity), roots[:, 1], roots[:, 0])
    v_error = np.abs(velocity - published) / np.abs(published)
    gamma, c, _period = budd_dux_constants(w, r)
    residual = np.abs((sigma + 0.5 * c * velocity) ** 2 + ((1.0 - r) * velocity / (2.0 * w)) ** 2 - gamma**2) / gamma**2
    mu_error = np.array([multiplier_distance(o.multipliers, budd_dux_multipliers(s, v, w, r)) if np.isfinite(v) else math.nan for o, s, v in zip(branch.orbits, sigma, velocity)])
    pd_sigma, pd_velocity = budd_dux_period_doubling(w, r)
    found = branch.special("period_doubling")
    tol = case.tolerance
    count = sigma.size
    k, j, m = _worst(v_error), _worst(residual), _worst(mu_error)
    rows: list[Check] = [
        check(f"impact velocity V on the ellipse (worst of {count} points)", published[k], velocity[k], tol, "1", f"at sigma = {sigma[k]:.6g}; the root of the ellipse nearest the computed V"),
        check(f"ellipse residual ((sigma + c V/2)^2 + ((1 - r) V/(2 w))^2) / gamma^2 - 1 (worst of {count})", 0.0, residual[j], tol, "1",
              f"at sigma = {sigma[j]:.6g}", error=residual[j]),  # fmt: skip
        check(f"Floquet multipliers against the impact map's (worst of {count})", 0.0, mu_error[m], tol, "1",
              "distance to the nearest closed-form multiplier, over max(1, |mu|); closed form: tr = (1 + r) sin T a / V - 2 r cos T, "
              "det = r^2 (derived here from Budd & Dux's orbit)", error=mu_error[m]),  # fmt: skip
        check("sigma at the period doubling", pd_sigma, _special(branch, "period_doubling"), tol, "1", "located by the continuation (1e-10 relative); closed form derived from the impact map"),
        check("V at the period doubling", pd_velocity, _impact_velocity(found[0].orbit) if found else math.nan, tol, "1", "the located orbit's impact speed"),
        check("clearance range continued", high - low, float(np.ptp(sigma)) if count else 0.0, tol, "1", f"the branch ends at the bounds of the scene's range ({branch.end})"),
    ]
    angle = np.linspace(0.0, 2.0 * np.pi, ELLIPSE_SAMPLES)
    # the ellipse in (sigma, V): sigma + c V / 2 = gamma cos(phi), (1 - r) V / (2 w) = gamma sin(phi)
    e_velocity = 2.0 * w * gamma * np.sin(angle) / (1.0 - r)
    e_sigma = gamma * np.cos(angle) - 0.5 * c * e_velocity
    data = xr.Dataset(
        {
            "impact_velocity": ("point", velocity, {"units": "1", "long_name": "impact velocity V of the continued period-one orbit (Budd & Dux's units)"}),
            "published_velocity": ("point", published, {"units": "1", "long_name": "V of the ellipse at the continued sigma (nearest root)"}),
            "floquet_modulus": ("point", branch.floquet_modulus, {"units": "1", "long_name": "largest |Floquet multiplier| of the continued orbit"}),
            "stable": ("point", branch.stable.astype(np.int8), _STABLE),
            "ellipse_velocity": ("ellipse_point", e_velocity, {"units": "1", "long_name": "V along Budd & Dux's ellipse"}),
        },
        coords={
            "clearance": ("point", sigma, {"units": "1", "long_name": "sigma, the stop's position (Budd & Dux's units)"}),
            "ellipse_clearance": ("ellipse_point", e_sigma, {"units": "1", "long_name": "sigma along Budd & Dux's ellipse"}),
        },
    )
    data.attrs.update({"period_doubling_clearance": pd_sigma, "period_doubling_velocity": pd_velocity, "forcing_frequency": w, "restitution": r})
    notes = (
        f"x'' + x = cos(w t) with w = {w:g}, r = {r:g}: gamma = 1/(1 - w^2) = {gamma:.10g}, c = (1 + r) sin T/(1 - cos T) = {c:.10g}, T = 2 pi / w.",
        f"The orbit was shot at sigma = {sigma0:g} from the closed form and continued in sigma with the exact engine's map (branch end: {branch.end}).",
        "The period doubling's closed form: (1 + r) sin T a / V = -(1 + r^2 - 2 r cos T) with a = c V (1 - w^2)/2 - w^2 sigma, on the ellipse "
        f"(derived here from the linearised impact map): sigma = {pd_sigma:.12g}, V = {pd_velocity:.12g}.",
    )
    return CaseOutcome("budd_dux", tuple(rows), data, notes)


# ------------------------------------------------------------------------------------------------ bouncing ball
def _impact_phase(mapping: ImpactMap, orbit: PeriodicOrbit) -> float:
    """The table's phase theta at the orbit's first impact (table at A sin(theta)) [rad], in (-pi, pi]."""
    problem = mapping.problem_at(orbit.parameters)
    run = mapping.engine.integrate(problem, orbit.state, 0.0, 1)
    if run.impact_times.size != 1:
        return math.nan
    return float(math.remainder(problem.omega * float(run.impact_times[0]) + BALL_TIME_SHIFT, 2.0 * math.pi))


def run_bouncing_ball(case: BouncingBallCase, say=lambda message: None, brute: bool = True) -> CaseOutcome:
    """Continue the ball's period-one orbit in the table amplitude, locate its fold and period doubling; a brute-force
    sweep of Gamma for the diagram."""
    from vibroimpact.kinds.validation.orbits import brute_force  # the diagram's sweep

    e, g, f = case.restitution, case.gravity, case.frequency
    omega, period = 2.0 * math.pi * f, 1.0 / f
    low, high = case.acceleration
    unit = case.mass * g  # amplitude [N] per unit of Gamma
    start = 0.5 * (ball_existence(e) + ball_period_doubling(e))
    problem = ball_problem(case, start)
    mapping = _map(problem, "amplitude", ball_amplitude(case, low), ball_amplitude(case, high), 0.05 * unit)
    say(f"bouncing_ball: shooting at Gamma = {start:.6g}, continuing over [{low:g}, {high:g}]")
    guess = ball_state(start, e, g, omega, 0.5 * period)  # the problem's t = 0 is the table's T / 2
    orbit = shoot(mapping, guess, mapping.parameters)
    settings = ContinuationSettings(step=0.05, max_step=0.2, lower=ball_amplitude(case, low), upper=ball_amplitude(case, high), max_steps=2000, detect=_DETECT, stop_at_grazing=True)
    branch = continue_branch(mapping, orbit, "amplitude", settings)
    gamma = branch.values / unit
    speed = np.array([_impact_velocity(o) for o in branch.orbits])
    theta = np.array([_impact_phase(mapping, o) for o in branch.orbits])
    published_theta = np.sign(theta) * np.arccos(np.clip(ball_existence(e) / gamma, -1.0, 1.0))
    published_speed = g * period / (1.0 + e)
    mu_error = np.array([multiplier_distance(o.multipliers, ball_multipliers(gm, e, th > 0.0)) if np.isfinite(th) else math.nan for o, gm, th in zip(branch.orbits, gamma, theta)])
    tol = case.tolerance
    count = gamma.size
    fold, doubling = _special(branch, "fold") / unit, _special(branch, "period_doubling") / unit
    k, j, m = _worst(np.abs(speed - published_speed) / published_speed), _worst(np.abs(theta - published_theta)), _worst(mu_error)
    rows: list[Check] = [
        check("Gamma where the period-one orbit begins (fold)", ball_existence(e), fold, tol, "1", "pi (1 - e)/(1 + e); located by the continuation (1e-10)"),
        check("Gamma of the period doubling", ball_period_doubling(e), doubling, tol, "1",
              "sqrt((pi (1-e)/(1+e))^2 + (2 (1+e^2)/(1+e)^2)^2): the exact table motion (derived here from the exact impact map)"),  # fmt: skip
        check("Gamma of the period doubling in Holmes' high-bounce map", ball_period_doubling_high_bounce(e), doubling, math.nan, "1",
              "informative: Holmes' map puts every impact at the table's mean position (Gamma sin theta = 1); the simulated table moves"),  # fmt: skip
        check(f"impact speed relative to the table, g T/(1 + e) (worst of {count})", published_speed, speed[k], tol, "m s-1", f"at Gamma = {gamma[k]:.6g}"),
        check(f"table phase theta at the impact (worst of {count})", published_theta[j], theta[j], tol, "rad", f"Gamma cos theta = pi (1 - e)/(1 + e) at Gamma = {gamma[j]:.6g}"),
        check(f"Floquet multipliers against the exact impact map's (worst of {count})", 0.0, mu_error[m], tol, "1",
              "tr = 1 + e^2 - (1 + e)^2 Gamma sin theta, det = e^2 (derived here)", error=mu_error[m]),  # fmt: skip
    ]
    data = xr.Dataset(
        {
            "impact_speed": ("point", speed, {"units": "m s-1", "long_name": "approach speed relative to the table of the continued period-one orbit"}),
            "impact_phase": ("point", theta, {"units": "rad", "long_name": "table phase theta at the impact (table at A sin theta)"}),
            "floquet_modulus": ("point", branch.floquet_modulus, {"units": "1", "long_name": "largest |Floquet multiplier| of the continued orbit"}),
            "stable": ("point", branch.stable.astype(np.int8), _STABLE),
        },
        coords={"acceleration": ("point", gamma, {"units": "1", "long_name": "Gamma = A w^2 / g of the continued orbit"})},
    )
    if brute:
        say(f"bouncing_ball: brute force over Gamma in [{low:g}, {high:g}] step {case.brute_step:g}")
        brute = brute_force(case)
        data = xr.merge([data, brute], combine_attrs="override")
    data.attrs.update({"existence_acceleration": ball_existence(e), "period_doubling_acceleration": ball_period_doubling(e),
                       "high_bounce_period_doubling_acceleration": ball_period_doubling_high_bounce(e), "restitution": e})  # fmt: skip
    notes = (
        f"The ball in table coordinates: a free mass with gravity -m g, the table's inertia m A w^2 sin(w t) as a harmonic force, a lower stop at 0 "
        f"(e = {e:g}, table {f:g} Hz, g = {g:g} m/s2). The problem's time is shifted by half a period so that the strobes fall between impacts.",
        "Holmes (1982) analyses the high-bounce approximation (impacts at the table's mean position, the table's velocity kept): "
        "it has the same existence threshold, but its period doubling is at Gamma sin theta = 1, "
        f"Gamma = {ball_period_doubling_high_bounce(e):.10g}. The simulated table moves, and the exact impact map (linearised here) doubles at "
        f"Gamma sin theta = 2 (1 + e^2)/(1 + e)^2, Gamma = {ball_period_doubling(e):.10g}: the formula of issue 12, checked to 1e-8; the high-bounce value is shown for comparison only.",
        f"Continuation from Gamma = {start:.6g} both ways (branch end: {branch.end}).",
    )
    if brute:
        blank = brute["brute_acceleration"].values[brute["brute_failed"].values == 1]
        notes += (f"Brute force: {brute.sizes['brute_acceleration']} values of Gamma, each {case.transient_periods} periods from the last end state, then "
                  f"{case.strobes} recorded; the sweep starts on the period-one orbit at Gamma = {start:.6g} and runs down, then up.",)  # fmt: skip
        if blank.size:
            notes += (f"The exact engine made no progress (more than 10 x max_impacts_per_period events in a period) at Gamma = "
                      f"{', '.join(f'{g:g}' for g in blank)}: left blank.",)  # fmt: skip
    return CaseOutcome("bouncing_ball", tuple(rows), data, notes)


# ------------------------------------------------------------------------------------------------ grazing
def run_grazing(case: GrazingCase, say=lambda message: None) -> CaseOutcome:
    """Locate where impacts begin from both sides: the non-impacting orbit continued up in the force amplitude until
    it touches the stop, and the impacting orbit (simulated at the top of the range, then shot) continued down until
    its impact speed vanishes; the second branch, which runs on below the grazing point, is drawn."""
    low, high = case.amplitude
    w = 2.0 * math.pi * case.frequency
    published = grazing_amplitude(case.clearance, case.mass, case.stiffness, case.damping, w)
    h = 1.0 / complex(case.stiffness - case.mass * w * w, case.damping * w)
    settings = ContinuationSettings(step=0.05, max_step=0.2, lower=low, upper=high, max_steps=2000, detect=_DETECT, stop_at_grazing=False)
    problem = grazing_problem(case, low)
    phasor = low * h * complex(math.cos(problem.phase), math.sin(problem.phase))
    mapping = _map(problem, "amplitude", low, high, 0.05 * published)
    say(f"grazing: continuing the linear orbit up from A = {low:g} N")
    rising = continue_branch(mapping, shoot(mapping, np.array([phasor.real, (1j * w * phasor).real]), mapping.parameters), "amplitude", settings, direction=1)
    say(f"grazing: the impacting orbit at A = {high:g} N (simulated {_SETTLE_PERIODS} periods, shot), continued down")
    top = grazing_problem(case, high)
    engine = ExactEngine()
    settled = engine.integrate(top, np.zeros(2), 0.0, _SETTLE_PERIODS).final_state
    mapping_top = _map(top, "amplitude", low, high, 0.05 * published)
    falling = continue_branch(mapping_top, shoot(mapping_top, settled, mapping_top.parameters), "amplitude", settings, direction=-1)
    tol = case.tolerance
    rows: list[Check] = []
    notes = [f"m = {case.mass:g} kg, k = {case.stiffness:g} N/m, c = {case.damping:g} N s/m, w / 2 pi = {case.frequency:g} Hz, d = {case.clearance:g} m, R = {case.restitution:g}."]
    for branch, side, how in ((rising, "from below", "the linear orbit's closest approach to the stop -> 0"), (falling, "from above", "the impacting orbit's impact speed -> 0")):
        grazings = branch.special("grazing")
        rows.append(check(f"force amplitude A where impacts begin, {side}", published, float(grazings[0].value) if grazings else math.nan, tol, "N",
                          f"d sqrt((k - m w^2)^2 + (c w)^2); located by the continuation: {how}"))  # fmt: skip
        notes.append(f"Continued {side} (branch end: {branch.end}): " + ("; ".join(f"{s.kind} at A = {s.value:.12g} N ({s.note})" for s in branch.special_points) or "no special point") + ".")
    amplitude = falling.values
    speed = np.array([float(o.hybrid.min_impact_velocity) if o.hybrid is not None and o.hybrid.impacts else 0.0 for o in falling.orbits])
    peak = np.array([_peak(case.clearance, o) for o in falling.orbits])
    linear = amplitude * abs(h)
    below = (amplitude < published) & np.isfinite(peak)
    error = np.abs(peak[below] - linear[below]) / linear[below]
    if error.size:
        k = _worst(error)
        rows.append(check(f"largest x of the orbits below the grazing amplitude, A |H| (worst of {error.size})", linear[below][k], peak[below][k], tol, "m",
                          "the linear steady state's amplitude (d plus the flight's closest approach to the stop)"))  # fmt: skip
    data = xr.Dataset(
        {
            "largest_displacement": ("point", peak, {"units": "m", "long_name": "largest x over the continued orbit (the stop if it impacts; else d plus the closest approach of its flight)"}),
            "impact_velocity": ("point", speed, {"units": "m s-1", "long_name": "impact speed of the continued orbit (0: no impact)"}),
            "floquet_modulus": ("point", falling.floquet_modulus, {"units": "1", "long_name": "largest |Floquet multiplier| of the continued orbit"}),
            "stable": ("point", falling.stable.astype(np.int8), _STABLE),
        },
        coords={"amplitude": ("point", amplitude, {"units": "N", "long_name": "force amplitude A of the continued orbit (from the top of the range down)"})},
    )
    data.attrs.update({"grazing_amplitude_N": published, "receptance_modulus_m_per_N": abs(h), "clearance_m": case.clearance})
    return CaseOutcome("grazing", tuple(rows), data, tuple(notes))


def _peak(clearance: float, orbit: PeriodicOrbit) -> float:
    """Largest displacement over one period of ``orbit`` [m]: the stop's position if it impacts, else the stop's
    position plus the closest approach of the free flight (found by the engine's root search, exact to round-off)."""
    hybrid = orbit.hybrid
    if hybrid is None:
        return math.nan
    return clearance if hybrid.impacts else clearance + float(hybrid.closest_approach)
