"""Running a case on an engine, and everything measured about the run, in one record."""

from __future__ import annotations

import functools
import math
import time
from dataclasses import dataclass

import numpy as np

from vibroimpact.engines.base import Trajectory
from vibroimpact.analysis.pgf import solve_one_impact

from tests.engine_cases import linear_state, named
from .cases import CASES, RIGID, Expect, HardCase, build_engine
from .checks import (
    bumper_penetration_bound,
    compliant_contact_errors,
    contact_law_errors,
    energy_residual,
    flow_exceedances,
    length_scale,
    penetration,
    strobe_error,
    x1_fundamental,
)

__all__ = ["Run", "run_case", "exact_run", "measure"]

BY_ID = {case.id: case for case in CASES}


@dataclass(frozen=True)
class Run:
    """One engine's trajectory of one case and its wall time [s]."""

    case: HardCase
    engine: str
    trajectory: Trajectory
    seconds: float


def run_case(case: HardCase, engine: str) -> Run:
    solver = build_engine(engine)
    t0, state = case.start
    started = time.perf_counter()
    trajectory = solver.integrate(case.problem_for(engine), state, t0, case.periods, moments=True)
    return Run(case, engine, trajectory, time.perf_counter() - started)


@functools.lru_cache(maxsize=None)
def exact_run(case_id: str) -> Run:
    """The exact engine's run of a case (computed once per test session)."""
    return run_case(BY_ID[case_id], "exact")


def _stuck(trajectory: Trajectory) -> tuple[int, int, float]:
    return trajectory.stats["sticks"], trajectory.stats["releases"], trajectory.stuck_time


def measure(run: Run, expect: Expect, reference: Run | None) -> dict[str, float]:
    """Everything the table may ask about ``run``, against the exact run ``reference`` (None: no comparison).

    Only what ``expect`` asks for is measured where it costs (energy, flow penetration)."""
    case, trajectory, p = run.case, run.trajectory, run.case.problem
    rigid = run.engine in RIGID
    out: dict[str, float] = {"seconds": run.seconds, "impacts": float(trajectory.impact_times.size)}
    scale = length_scale(p)
    out["penetration"] = penetration(trajectory) / scale
    if rigid:
        out |= {f"law_{k}": v for k, v in contact_law_errors(trajectory).items()}
        if expect.penetration is not None:
            out["flow_exceedances"] = float(flow_exceedances(trajectory, expect.penetration * scale))
        if expect.energy is not None:
            out["energy"] = energy_residual(trajectory)
        out["sticks"], out["releases"], out["stuck_time"] = _stuck(trajectory)
    else:
        bumper = case.compliant_bumper()
        out |= {f"contact_{k}": v for k, v in compliant_contact_errors(trajectory, bumper.loss_factor).items()}
        out["penetration_bound"] = bumper_penetration_bound(trajectory, bumper.frequency) / scale
    if reference is not None:
        ref = reference.trajectory
        out["exact_impacts"] = float(ref.impact_times.size)
        if ref.impact_times.size == trajectory.impact_times.size and ref.impact_times.size:
            out["times"] = float(np.max(np.abs(trajectory.impact_times - ref.impact_times)))
        out["states"] = strobe_error(trajectory.strobe_states, ref.strobe_states)
        a, b = x1_fundamental(trajectory, case.measure_periods), x1_fundamental(ref, case.measure_periods)
        out["x1"] = abs(abs(a) - abs(b)) / abs(b) if b != 0 else abs(a)
        if rigid:
            sticks, releases, stuck_time = _stuck(ref)
            out["exact_sticks"], out["exact_releases"], out["exact_stuck_time"] = sticks, releases, stuck_time
    if case.reference is not None:
        out["reference"] = reference_error(run)
    return out


def reference_error(run: Run) -> float:
    """Distance of the run from the case's analytic reference (see ``HardCase.reference``)."""
    case, trajectory, p = run.case, run.trajectory, run.case.problem
    if case.reference == "linear":
        if trajectory.impact_times.size:
            return math.inf
        linear = np.array([linear_state(p, t) for t in trajectory.strobe_times])
        amplitude = np.abs(linear).max(axis=0)
        return float(np.max(np.abs(trajectory.strobe_states - linear) / amplitude))
    if case.reference == "pgf":
        orbit = solve_one_impact(named(p), omega=np.array([p.omega]), clearance=p.clearance, restitution=p.restitution, amplitude=p.amplitude)
        if trajectory.impulses.size != case.periods:
            return math.inf
        return float(np.max(np.abs(trajectory.impulses / orbit.impulse[0] - 1.0)))
    if case.reference == "scaled":
        assert case.scaled_from is not None
        original, factor = case.scaled_from
        t0, state = case.start
        big = build_engine("exact").integrate(original, state / factor, t0, case.periods)
        if big.impact_times.size != trajectory.impact_times.size:
            return math.inf
        times = float(np.max(np.abs(big.impact_times - trajectory.impact_times), initial=0.0)) / p.period
        return max(times, strobe_error(trajectory.strobe_states / factor, big.strobe_states))
    if case.reference == "touch":
        if trajectory.impact_times.size == 0:
            return math.inf
        return float(trajectory.impact_velocities[0]) / p.velocity_scale()
    raise ValueError(f"reference = {case.reference!r} is not known")
