"""The bouncing ball's bifurcation diagram by brute force: Gamma stepped up, each point started from the last one's
end state, the impacts of the last periods recorded (what the report draws behind the continued branch)."""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from vibroimpact.engines.exact import ExactEngine
from vibroimpact.scene.validation_problems import BALL_TIME_SHIFT, ball_problem
from vibroimpact.scene.validation_settings import BouncingBallCase
from vibroimpact.study.validation_formulas import ball_existence, ball_period_doubling, ball_state

__all__ = ["brute_force", "MAX_KEPT_IMPACTS"]

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
