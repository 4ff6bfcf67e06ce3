"""The bouncing ball's bifurcation diagram by brute force: Gamma stepped up, each point started from the last one's
end state, the impacts of the last periods recorded (what the report draws behind the continued branch)."""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from vibroimpact.engines.exact import ExactEngine
from vibroimpact.scene.validation_problems import ball_problem
from vibroimpact.scene.validation_settings import BouncingBallCase
from vibroimpact.study.validation_formulas import ball_existence, ball_period_doubling, ball_state

__all__ = ["brute_force", "MAX_KEPT_IMPACTS"]

#: Impacts kept per brute-force point (the last ones; chattering can have many more).
MAX_KEPT_IMPACTS = 64


def brute_force(case: BouncingBallCase) -> xr.Dataset:
    """Impact speeds relative to the table over the last ``case.strobes`` periods at each Gamma of the sweep.

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
    counts = np.zeros(grid.size, dtype=np.int32)
    start = ball_state(middle, e, g, omega, 0.5 / case.frequency)
    below = np.flatnonzero(grid < middle)[::-1]
    above = np.flatnonzero(grid >= middle)
    for order in (below, above):
        state = start.copy()
        for i in order:
            problem = ball_problem(case, float(grid[i]))
            periods = case.transient_periods + case.strobes
            run = engine.integrate(problem, state, 0.0, periods)
            recorded = run.impact_times >= run.strobe_times[case.transient_periods]
            kept = run.impact_velocities[recorded][-MAX_KEPT_IMPACTS:]
            speeds[i, : kept.size] = kept
            counts[i] = int(np.count_nonzero(recorded))
            state = np.array(run.final_state, dtype=float)
    return xr.Dataset(
        {
            "brute_impact_speed": (("brute_acceleration", "brute_impact"), speeds, {"units": "m s-1", "long_name": "impact speed relative to the table, last impacts of the recorded periods (NaN: fewer)"}),
            "brute_impacts": ("brute_acceleration", counts, {"units": "1", "long_name": "impacts in the recorded periods"}),
        },
        coords={"brute_acceleration": ("brute_acceleration", grid, {"units": "1", "long_name": "Gamma of the brute-force sweep"})},
    )
