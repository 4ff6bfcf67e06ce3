"""Measurements of a trajectory that the hard cases and the property tests assert on.

Every function here measures; :func:`contact_law_errors` and :func:`penetration` are also what the property tests
use, so a table case and a random case are judged by the same code.
"""

from __future__ import annotations

import math

import numpy as np

from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.contact import restitution_from_loss_factor
from vibroimpact.engines.base import MODE_FREE, MODE_STUCK, Trajectory
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.engines.compliant.ida import MODE_CONTACT
from vibroimpact.engines.linear_flow import HarmonicLinearFlow, first_crossing

from tests.engine_cases import energy_budget, named

__all__ = [
    "length_scale",
    "contact_law_errors",
    "compliant_contact_errors",
    "penetration",
    "flow_exceedances",
    "energy_residual",
    "bumper_penetration_bound",
    "x1_fundamental",
    "strobe_error",
]


def length_scale(problem: ImpactProblem) -> float:
    """Delta + velocity_scale / w [m]: the size of the motion, for relative position tolerances."""
    return problem.clearance + problem.velocity_scale() / problem.omega


def _after_states(trajectory: Trajectory) -> tuple[np.ndarray, np.ndarray]:
    """State and mode just after each impact: the segment that starts at the impact's time (the final strobe for an
    impact at the very end, whose zero-length segment the trajectory drops)."""
    starts = trajectory.segments[:, 0]
    index = np.searchsorted(starts, trajectory.impact_times)
    states = np.empty((trajectory.impact_times.size, 4))
    modes = np.empty(trajectory.impact_times.size)
    for k, (i, t) in enumerate(zip(index, trajectory.impact_times)):
        if i < starts.size and starts[i] == t:
            states[k], modes[k] = trajectory.segment_states[i], trajectory.segments[i, 2]
        elif t == trajectory.strobe_times[-1]:
            states[k], modes[k] = trajectory.final_state, MODE_FREE if trajectory.final_state[3] != 0.0 else MODE_STUCK  # exact: a stuck absorber's velocity is set to 0
        else:
            raise AssertionError(f"impact at t = {t!r} s starts no segment")
    return states, modes


def contact_law_errors(trajectory: Trajectory) -> dict[str, float]:
    """Rigid stop: worst violations of the contact law over the impacts (all 0 when it holds exactly).

    ``position``: |X2+ - Delta| [m]; ``speed``: how many pre-impact speeds are not > 0 (inf: not finite); ``velocity``: |X2'+ - (-R X2'-)| / X2'- (or |X2'+| / X2'- for an impact ending in sticking);
    ``impulse``: |J - M2 (X2'- - X2'+)| / J with X2'+ = -R X2'- or 0; velocity and impulse errors below the engines'
    velocity resolution (``EngineSettings.sticking_velocity`` of the velocity scale, times M2) do not count.
    """
    p = trajectory.problem
    before = trajectory.impact_velocities
    if before.size == 0:
        return {"position": 0.0, "speed": 0.0, "velocity": 0.0, "impulse": 0.0}
    if not np.all(np.isfinite(before)) or not np.all(np.isfinite(trajectory.impulses)):
        return {"position": math.inf, "speed": math.inf, "velocity": math.inf, "impulse": math.inf}
    after, modes = _after_states(trajectory)
    sticks = modes == MODE_STUCK
    expected_after = np.where(sticks, 0.0, -p.restitution * before)
    expected_impulse = named(p).m2 * (before - expected_after)
    # the engines' stated velocity resolution (EngineSettings.sticking_velocity): a rebound slower than it may end
    # the chatter in sticking (measured: a solve_ivp rebound at 1.2x the threshold returned within round-off time)
    floor = EngineSettings().sticking_velocity * p.velocity_scale()
    return {
        "position": float(np.max(np.abs(after[:, 1] - p.clearance))),
        "speed": float(np.sum(before <= 0.0)),
        "velocity": float(np.max(np.maximum(np.abs(after[:, 3] - expected_after) - floor, 0.0) / before)),
        "impulse": float(np.max(np.maximum(np.abs(trajectory.impulses - expected_impulse) - named(p).m2 * floor, 0.0) / expected_impulse)),
    }


def compliant_contact_errors(trajectory: Trajectory, loss_factor: float, strong: float = 0.1) -> dict[str, float]:
    """Compliant bumper: per contact, entry speed >= 0 (``speed``: how many are not), impulse > 0 (``impulse_sign``:
    how many are not), contacts still open at the end (``unreleased``), and for the contacts entered faster than
    ``strong`` times the velocity scale the exit speed ratio -X2'+ / X2'- against R(xi_b) (``restitution``, absolute)
    and the impulse against M2 (X2'- - X2'+) (``impulse``, relative: the absorber spring's force over the short
    contact is the difference). Slow contacts are dominated by the spring and have no restitution of their own."""
    p = trajectory.problem
    before, impulses = trajectory.impact_velocities, trajectory.impulses
    errors = {"speed": 0.0, "impulse_sign": 0.0, "restitution": 0.0, "impulse": 0.0, "unreleased": float(trajectory.stats["contacts"] - before.size)}
    if before.size == 0:
        return errors
    contact = trajectory.segments[:, 2] == MODE_CONTACT
    # a contact begun at the surface enters at a positive speed; one resumed within the bumper's reach (after a
    # release that left the absorber inside it) may begin with any speed
    at_surface = trajectory.segment_states[contact, 1][: before.size] <= p.clearance
    entering = before[: at_surface.size][at_surface]
    errors["speed"] = float(np.sum(entering < -1e-12 * p.velocity_scale()))  # 0 from rest on the surface
    errors["impulse_sign"] = float(np.sum(impulses <= 0.0))
    # the segment after each contact segment starts at its release
    release = np.flatnonzero(contact[:-1]) + 1
    exits = trajectory.segment_states[release, 3]
    entries = before[: exits.size]
    strong_ones = entries > strong * p.velocity_scale()
    if np.any(strong_ones):
        ratio = -exits[strong_ones] / entries[strong_ones]
        errors["restitution"] = float(np.max(np.abs(ratio - restitution_from_loss_factor(loss_factor))))
        momentum = named(p).m2 * (entries[strong_ones] - exits[strong_ones])
        errors["impulse"] = float(np.max(np.abs(impulses[: exits.size][strong_ones] - momentum) / momentum))
    return errors


def penetration(trajectory: Trajectory) -> float:
    """Largest X2 - Delta over the strobes and segment starts [m] (negative: never at the stop)."""
    x2 = np.concatenate([trajectory.strobe_states[:, 1], trajectory.segment_states[:, 1]])
    return float(x2.max() - trajectory.problem.clearance)


def flow_exceedances(trajectory: Trajectory, tolerance: float) -> int:
    """How many free segments' exact flow, from the segment's start state, passes Delta + ``tolerance`` [m] before
    the segment ends.

    For an integrator this is where a missed contact shows: the flight it did not stop goes through the stop (the
    exact flow from its event states differs from its steps by the integration error only). The search is the exact
    engine's guaranteed root bracketing, so no excursion is missed however short (a grazing one lasts microseconds).
    """
    p, s = trajectory.problem, named(trajectory.problem)
    flow = HarmonicLinearFlow(s.state_matrix, np.array([0, 0, p.amplitude * np.exp(1j * p.phase) / s.m1, 0]), np.zeros(4), p.omega)
    level = p.clearance + tolerance
    count = 0
    for (start, end, mode), state in zip(trajectory.segments, trajectory.segment_states):
        if mode != MODE_FREE:
            continue
        if state[1] > level:
            count += 1
            continue
        gap = flow.start(start, state).observable(np.array([0.0, 1.0, 0.0, 0.0]), -level)
        count += first_crossing(gap, start, end, 1e-3 * tolerance) is not None
    return count


def energy_residual(trajectory: Trajectory) -> float:
    """|change - (work - dissipation - impact loss)| / max(|work|, |change|, tiny) [-]."""
    budget = energy_budget(trajectory)
    balance = budget["work"] - budget["dissipation"] - budget["impact_loss"]
    scale = max(abs(budget["work"]), abs(budget["change"]), abs(budget["dissipation"]), 1e-300)
    return abs(budget["change"] - balance) / scale


def x1_fundamental(trajectory: Trajectory, periods: int) -> complex:
    """Fundamental-harmonic complex amplitude of X1 over the last ``periods`` periods [m] (needs moments)."""
    periods = min(periods, trajectory.moments.shape[0])
    total = trajectory.moments[-periods:, 0].sum()
    return complex(2.0 * total / (periods * trajectory.problem.period))


def strobe_error(trial: np.ndarray, reference: np.ndarray) -> float:
    """Largest |trial - reference| over strobes, as a fraction of each component's largest |reference| [-]."""
    scale = np.abs(reference).max(axis=0)
    scale = np.where(scale > 0.0, scale, 1.0)
    return float(np.max(np.abs(trial - reference) / scale))


def bumper_penetration_bound(trajectory: Trajectory, frequency: float) -> float:
    """How far a bumper of Omega_b = 2 pi ``frequency`` may be entered [m]: the fastest entry speed / Omega_b (the
    depth of a free collision) plus the largest static load on it, K2 times the length scale plus q, over its
    stiffness M2 Omega_b^2 (a pressed contact)."""
    p = trajectory.problem
    omega_b = 2 * math.pi * frequency
    speed = float(trajectory.impact_velocities.max()) if trajectory.impact_velocities.size else 0.0
    static = (named(p).k2 * length_scale(p) + p.amplitude) / (named(p).m2 * omega_b**2)
    return speed / omega_b + static
