"""Validation studies (kind ``validation``): one published closed form per scene, reproduced by the project.

``run-study studies/validation/<case>.yaml`` runs the case (:mod:`~vibroimpact.kinds.validation.orbits`: continuation of periodic
orbits; :mod:`~vibroimpact.kinds.validation.study`: simulated runs) and writes ``<name>.nc``: a table of compared quantities
(dimension ``check``: ``quantity``, ``published``, ``computed``, ``relative_error``, ``tolerance``, ``passed``; see
:mod:`~vibroimpact.kinds.validation.formulas`) and the data of the case's figure, with the case's name and source in the attributes.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from types import MappingProxyType
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import NDArray
from scipy.linalg import matrix_balance

from vibroimpact.engines.base import MODE_STUCK, Trajectory
from vibroimpact.engines.registry import ENGINES, make_engine
from vibroimpact.engines.settings import ATOL_RATIO, EngineSettings
from vibroimpact.kinds.validation.formulas import CaseOutcome, Check, check, zeno_sticking_bounds, zeno_sticking_deficit, zeno_time, outcome_dataset
from vibroimpact.kinds.validation.orbits import run_bouncing_ball, run_budd_dux, run_grazing
from vibroimpact.kinds.validation.scene import relative_stop_problem, zeno_problem
from vibroimpact.kinds.validation.settings import RelativeStopCase, ZenoCase, ValidationSettings
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.runs.estimate import Costs, Estimate
from vibroimpact.runs.runner import Runner

__all__ = ["run_zeno", "run_relative_stop", "FreeFlight", "free_flight", "INTEGRATOR_ALLOWANCE", "ROUND_OFF_EVENTS", "ValidationStudy", "run_validation", "RUNNERS", "CASE_SECONDS"]


# --------------------------------------------------------------------------------------------------------------------
# Validation cases checked on simulated runs: the Zeno time of a dropped ball, engine by engine, and the impacts of
# a relative stop one by one.
# --------------------------------------------------------------------------------------------------------------------

#: Engines whose event times are exact to round-off: those computing the exact flow.
EXACT_ENGINES = tuple(name for name, spec in ENGINES.items() if spec.capabilities.exact_flow)
#: Round-off allowance of an exact engine's sticking time, per impact, in units of eps x t_Z [-].
ROUND_OFF_EVENTS = 64.0
#: Allowance of an integrator's sticking time, in units of atol / (v_s (1 - e)) [-]: an event's time is off by about
#: the position tolerance over the impact speed, and the speeds fall geometrically to v_s (measured: 0.3-0.4 of
#: this at rtol 1e-10 with CVODE; solve_ivp's methods land within 1e-15 of it, their flight being a parabola).
INTEGRATOR_ALLOWANCE = 10.0
#: Samples of the exact run's height drawn in the report.
_TRACE_SAMPLES = 1500


def run_zeno(case: ZenoCase, say=lambda message: None) -> CaseOutcome:
    """Drop the ball with every engine of ``case`` and compare the sticking time with the Zeno time."""
    problem = zeno_problem(case)
    e, g, h = case.restitution, case.gravity, case.height
    t_zeno = zeno_time(h, g, e)
    v_s = case.sticking_velocity * problem.velocity_scale()
    low, high = zeno_sticking_bounds(e, g, v_s)
    deficit = zeno_sticking_deficit(h, g, e, v_s)
    periods = int(math.ceil(1.25 * t_zeno * case.frequency)) + 1
    start = np.array([h, 0.0])
    settings = EngineSettings(rtol=case.rtol, atol=case.rtol * ATOL_RATIO, sticking_velocity=case.sticking_velocity)
    rows: list[Check] = []
    times, counts, trace = [], [], None
    atol = case.rtol * ATOL_RATIO
    for name in case.engines:
        say(f"zeno: {name}")
        engine = make_engine(name, settings)
        run = engine.integrate(problem, start, 0.0, periods)
        t_stick, impacts = _sticking(run)
        times.append(t_stick)
        counts.append(impacts)
        if name in EXACT_ENGINES:
            own = max(ROUND_OFF_EVENTS * max(impacts, 1) * np.finfo(float).eps, case.tolerance)
            why = f"round-off of {impacts} event times (at least the scene's tolerance)"
        else:
            own = INTEGRATOR_ALLOWANCE * atol / (v_s * (1.0 - e)) / t_zeno
            why = f"{INTEGRATOR_ALLOWANCE:g} atol / (v_s (1 - e)): an event's time is off by about atol over the impact speed, summed down to v_s"
        rows.append(check(f"Zeno time, {name}", t_zeno, t_stick, high / t_zeno + own, "s",
                          f"sticking bound 2 e v_s / (g (1 - e)) / t_Z = {high / t_zeno:.2e} plus the engine's precision {own:.1e}; {impacts} impacts"))  # fmt: skip
        rows.append(check(f"t_Z minus the bounces left out, {name}", t_zeno - deficit, t_stick, own, "s",
                          f"published: t_Z - 2 e v_n / (g (1 - e)), v_n the first impact speed <= v_s; tolerance: {why}"))  # fmt: skip
        if trace is None and hasattr(engine, "dense"):
            trace = _trace(engine, run, t_zeno)
    data = xr.Dataset(
        {
            "sticking_time": ("engine", np.array(times), {"units": "s", "long_name": "start of the engine's first sticking segment (the ball comes to rest)"}),
            "impacts_before_sticking": ("engine", np.array(counts, dtype=np.int32), {"units": "1", "long_name": "impacts up to and including the one that sticks"}),
        },
        coords={"engine": ("engine", np.array(case.engines, dtype=str), {"long_name": "rigid-stop engine"})},
    )
    if trace is not None:
        data["trace_height"] = ("trace_time", trace[1], {"units": "m", "long_name": "height of the ball above the table (first exact engine)"})
        data = data.assign_coords(trace_time=("trace_time", trace[0], {"units": "s", "long_name": "time of the height trace"}))
    data.attrs.update({"zeno_time_s": t_zeno, "sticking_velocity_m_s": v_s, "deficit_low_s": low, "deficit_high_s": high, "predicted_deficit_s": deficit})
    notes = (
        f"Zeno time sqrt(2 h / g) (1 + e) / (1 - e) = {t_zeno:.12g} s (h = {h:g} m, g = {g:g} m/s2, e = {e:g}).",
        f"Sticking velocity v_s = {case.sticking_velocity:g} x the velocity scale g / w = {v_s:.4g} m/s: an engine misses the bounces after the first impact "
        f"no faster than v_s, {low:.3g} to {high:.3g} s ({high / t_zeno:.2e} of the Zeno time).",
        f"Integrators run at rtol = {case.rtol:g}, atol = {case.rtol * ATOL_RATIO:g} m; their events are located to about atol over the impact speed, "
        f"so their tolerance adds {INTEGRATOR_ALLOWANCE:g} atol / (v_s (1 - e)) to the bound.",
    )
    return CaseOutcome("zeno", tuple(rows), data, notes)


def _sticking(run: Trajectory) -> tuple[float, int]:
    """(start of the first sticking segment [s], impacts up to it); (NaN, all impacts) if the ball never sticks."""
    stuck = np.flatnonzero(run.segments[:, 2] == MODE_STUCK) if run.segments.size else np.array([], dtype=int)
    if stuck.size == 0:
        return math.nan, int(run.impact_times.size)
    t_stick = float(run.segments[stuck[0], 0])
    return t_stick, int(np.count_nonzero(run.impact_times <= t_stick))


def _trace(engine, run: Trajectory, t_zeno: float) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
    """Height of the ball over 1.1 Zeno times (the engine's own dense output)."""
    if not hasattr(engine, "dense"):
        return None
    times = np.linspace(0.0, min(1.1 * t_zeno, float(run.strobe_times[-1])), _TRACE_SAMPLES)
    return times, np.asarray(engine.dense(run, times))[:, 0]


# ------------------------------------------------------------------------------------------------ relative stop
#: What is recorded of each impact of the relative stop: name -> (units, long name).
_IMPACT_COLUMNS = {
    "impact_time": ("s", "time of the impact"),
    "approach_velocity": ("m s-1", "relative approach velocity n.x'(t-) (independent propagation)"),
    "relative_velocity_after": ("m s-1", "relative velocity n.x'(t+) after the impact (engine)"),
    "relative_velocity_expected": ("m s-1", "-R n.x'(t-) (0 where the impact sticks)"),
    "momentum_before": ("kg m s-1", "total momentum m1 x1' + m2 x2' before the impact (independent propagation)"),
    "momentum_after": ("kg m s-1", "total momentum after the impact (engine)"),
    "impulse_expected": ("N s", "m_eff (n.x'(t-) - n.x'(t+)) from the independent state"),
    "impulse_recorded": ("N s", "impulse recorded by the engine"),
    "gap_before": ("m", "gap Delta - n.x(t-) at the impact (independent propagation)"),
    "momentum_error": ("1", "|change of total momentum| over m1 |x1'| + m2 |x2'|"),
    "restitution_error": ("1", "|n.x'(t+) + R n.x'(t-)| over |n.x'(t-)|"),
    "impulse_error": ("1", "|recorded - expected impulse| over m_eff |n.x'(t-)|"),
    "position_error": ("1", "largest of |gap at the impact| and |x(t+) - x(t-)|, over Delta"),
}
class FreeFlight:
    """The free flight of a problem by the matrix exponential of its forced flow, independent of the engines.

    y' = A y + Re(b e^{jwt}) + b0 is written as Y' = M Y with Y = (y, cos wt, sin wt, 1), and exp(M dt) is computed
    by scaling and squaring a Taylor series of the balanced matrix in plain numpy (scipy's expm calls a threaded
    BLAS whose start-up costs 20 ms a call on a busy machine; this agrees with it to 1e-13 here).
    """

    def __init__(self, problem: ImpactProblem) -> None:
        a, b, b0 = problem.first_order()
        n, w = a.shape[0], problem.omega
        m = np.zeros((n + 3, n + 3))
        m[:n, :n] = a
        m[:n, n], m[:n, n + 1], m[:n, n + 2] = b.real, -b.imag, b0
        m[n, n + 1], m[n + 1, n] = -w, w
        self.matrix, self.size, self.omega = m, n, w

    def __call__(self, state: NDArray[np.float64], t0: float, t1: float) -> NDArray[np.float64]:
        """The state at ``t1`` of the free flight from ``state`` at ``t0``."""
        w = self.omega
        y = np.concatenate([np.asarray(state, dtype=float), [math.cos(w * t0), math.sin(w * t0), 1.0]])
        return (_expm(self.matrix * (t1 - t0)) @ y)[: self.size]


def _expm(m: NDArray[np.float64]) -> NDArray[np.float64]:
    """exp(m) by scaling and squaring a Taylor series of the balanced matrix."""
    balanced, (scale, _permutation) = matrix_balance(m, permute=False, separate=True)
    norm = float(np.linalg.norm(balanced, 1))
    squarings = max(0, int(math.ceil(math.log2(norm))) + 1) if norm > 0.0 else 0
    x = balanced / 2.0**squarings
    term = np.eye(m.shape[0])
    result = term.copy()
    for k in range(1, 40):
        term = term @ x / k
        result += term
        if np.linalg.norm(term, 1) <= 1e-17 * np.linalg.norm(result, 1):
            break
    for _ in range(squarings):
        result = result @ result
    return scale[:, None] * result / scale[None, :]


def free_flight(problem: ImpactProblem, state: NDArray[np.float64], t0: float, t1: float) -> NDArray[np.float64]:
    """The state at ``t1`` of the free flight from ``state`` at ``t0`` (:class:`FreeFlight`)."""
    return FreeFlight(problem)(state, t0, t1)


def run_relative_stop(case: RelativeStopCase, say=lambda message: None) -> CaseOutcome:
    """A long ``exact`` run of the relative stop, every impact checked (module docstring)."""
    problem = relative_stop_problem(case)
    flight = FreeFlight(problem)
    say(f"relative stop: {case.periods} periods")
    run = make_engine("exact").integrate(problem, np.zeros(4), 0.0, case.periods)
    stop = problem.stops[0]
    n = stop.normal(2)
    masses = problem.structure.mass_matrix
    m_eff = stop.effective_mass(masses)
    starts = run.segments[:, 0] if run.segments.size else np.zeros(0)
    columns: dict[str, list[float]] = {name: [] for name in _IMPACT_COLUMNS}
    for t, impulse in zip(run.impact_times, run.impulses):
        after = np.flatnonzero(starts == t)
        if after.size == 0 or after[0] == 0:
            for name in _IMPACT_COLUMNS:
                columns[name].append(float(t) if name == "impact_time" else math.nan)
            continue
        first, last = int(after[0]), int(after[-1])  # several events at one instant: the flight ends before the first
        before = flight(run.segment_states[first - 1], float(starts[first - 1]), float(t))
        post = run.segment_states[last]
        v_minus, v_plus = before[2:], post[2:]
        approach = float(n @ v_minus)
        sticks = abs(float(n @ v_plus)) < 1e-12 * abs(approach)
        expected = 0.0 if sticks else -case.restitution * approach
        weight = float(np.abs(np.diag(masses)) @ np.abs(v_minus))
        values = {
            "impact_time": float(t), "approach_velocity": approach, "relative_velocity_after": float(n @ v_plus), "relative_velocity_expected": expected,
            "momentum_before": float(np.sum(masses @ v_minus)), "momentum_after": float(np.sum(masses @ v_plus)),
            "impulse_expected": m_eff * (approach - expected), "impulse_recorded": float(impulse),
            "gap_before": case.clearance - float(n @ before[:2]),
            "momentum_error": abs(float(np.sum(masses @ (v_plus - v_minus)))) / weight,
            "restitution_error": abs(float(n @ v_plus) - expected) / abs(approach),
            "impulse_error": abs(impulse - m_eff * (approach - expected)) / (m_eff * abs(approach)),
            "position_error": max(abs(case.clearance - float(n @ before[:2])), float(np.max(np.abs(post[:2] - before[:2])))) / case.clearance,
        }  # fmt: skip
        for name in _IMPACT_COLUMNS:
            columns[name].append(values[name])
    table = {name: np.array(values, dtype=float) for name, values in columns.items()}
    count = table["impact_time"].size
    tol = case.tolerance
    rows_out: list[Check] = [check("impacts in the run", math.nan, count, math.nan, "1", f"{case.periods} periods of {case.frequency:g} Hz from rest")]

    def worst(error: str) -> int:
        values = table[error]
        return int(np.nanargmax(values)) if np.any(np.isfinite(values)) else 0

    if count and np.all(np.isfinite(table["momentum_error"])):
        k = worst("momentum_error")
        rows_out.append(check(f"momentum m1 x1' + m2 x2' after an impact (worst of {count})", table["momentum_before"][k], table["momentum_after"][k], tol, "kg m s-1",
                              "error relative to m1 |x1'| + m2 |x2'| before the impact", error=table["momentum_error"][k]))  # fmt: skip
        k = worst("restitution_error")
        rows_out.append(check(f"relative velocity n.x' after an impact (worst of {count})", table["relative_velocity_expected"][k], table["relative_velocity_after"][k], tol, "m s-1",
                              "published: -R n.x'(t-); error relative to |n.x'(t-)|", error=table["restitution_error"][k]))  # fmt: skip
        k = worst("impulse_error")
        rows_out.append(check(f"impulse of an impact (worst of {count})", table["impulse_expected"][k], table["impulse_recorded"][k], tol, "N s",
                              "published: m_eff (n.x'(t-) - n.x'(t+)), the engine's record", error=table["impulse_error"][k]))  # fmt: skip
        k = worst("position_error")
        rows_out.append(check(f"gap at the impact, displacements kept (worst of {count})", 0.0, table["gap_before"][k], tol, "m",
                              "|Delta - n.x(t-)| and |x(t+) - x(t-)| over Delta", error=table["position_error"][k]))  # fmt: skip
    else:
        rows_out.append(check("every impact checked", 1.0, 0.0, tol, "1", "no impact, or an impact without its flight: choose a larger amplitude or a smaller clearance"))
    data = xr.Dataset(
        {name: ("impact", table[name], {"units": _IMPACT_COLUMNS[name][0], "long_name": _IMPACT_COLUMNS[name][1]}) for name in _IMPACT_COLUMNS if name != "impact_time"},
        coords={"impact_time": ("impact", table["impact_time"], {"units": "s", "long_name": _IMPACT_COLUMNS["impact_time"][1]})},
    )
    last = np.linspace(max(0.0, run.strobe_times[-1] - 5.0 / case.frequency), run.strobe_times[-1], 600)
    which = np.clip(np.searchsorted(starts, last, side="right") - 1, 0, None)
    states = np.array([flight(run.segment_states[j], float(starts[j]), float(t)) for j, t in zip(which, last)])
    data["trace_relative_displacement"] = ("trace_time", states[:, :2] @ n, {"units": "m", "long_name": "x2 - x1 over the last 5 periods (the flights propagated from the run's segments)"})
    data = data.assign_coords(trace_time=("trace_time", last, {"units": "s", "long_name": "time of the trace"}))
    data.attrs.update({"clearance_m": case.clearance, "restitution": case.restitution, "effective_mass_kg": m_eff})
    notes = (
        f"Stop x2 - x1 <= {case.clearance * 1e3:g} mm between the absorber and the primary mass (Ormondroyd & Den Hartog's layout), R = {case.restitution:g}; "
        f"force {case.amplitude:g} N at {case.frequency:g} Hz on the primary mass; effective mass m1 m2 / (m1 + m2) = {m_eff:.6g} kg.",
        "The state before each impact is propagated from the start of the flight that ends there by the matrix exponential of the forced flow "
        "(independent of the engine's eigenvectors); the state after it is the engine's.",
    )
    return CaseOutcome("relative_stop", tuple(rows_out), data, notes)

#: Each case's run: (case settings, progress) -> outcome.
RUNNERS: MappingProxyType[str, Callable[..., CaseOutcome]] = MappingProxyType(
    {"budd_dux": run_budd_dux, "bouncing_ball": run_bouncing_ball, "zeno": run_zeno, "grazing": run_grazing, "relative_stop": run_relative_stop}
)
#: Wall time of each shipped case [s] (measured at load ~7 on the 2-core machine: 1.1, 3.8, 0.6, 2.5, 0.8-3.3 s; the
#: numba cache warm).
CASE_SECONDS = MappingProxyType({"budd_dux": 1.5, "bouncing_ball": 4.0, "zeno": 1.0, "grazing": 2.5, "relative_stop": 2.0})
#: Figures of a validation page.
REPORT_FIGURES = 1


def run_validation(settings: ValidationSettings, progress: Callable[[str], None] | None = None) -> xr.Dataset:
    """Run a validation case and gather its dataset (module docstring; its header is
    :func:`~vibroimpact.runs.run.run_study`'s)."""
    say = progress if progress is not None else (lambda message: None)
    outcome = RUNNERS[settings.name](settings.case, say)
    attrs = {"validation_source": settings.source}
    passed = sum(c.passed for c in outcome.checks)
    checks = sum(not c.informative for c in outcome.checks)
    say(f"{settings.name}: {passed} of {checks} checks passed")
    return outcome_dataset(outcome, attrs)


class ValidationStudy:
    """The ``validation`` kind of study."""

    name = "validation"

    @staticmethod
    def engines(scene: Any) -> tuple[str, ...]:
        """The case's engines (the Zeno case lists them; the others run the exact engine)."""
        return tuple(getattr(scene.settings.case, "engines", ("exact",)))

    def run(self, scene, progress: Callable[[str], None] | None, runner: Runner) -> xr.Dataset:
        """The scene's dataset (module docstring); one process (each case takes seconds). Every case has a layout
        (:func:`~vibroimpact.kinds.validation.scene.case_layout`), recorded as every kind records its own
        (:meth:`~vibroimpact.model.layout.Layout.attributes`): its stop at the case's restitution and clearance (the
        Budd-Dux case's continued range of clearances: swept; the bouncing ball's and Zeno's table: 0)."""
        dataset = run_validation(scene.settings, progress)
        case = scene.settings.case
        clearance = np.atleast_1d(np.asarray(getattr(case, "clearance", 0.0), dtype=float))
        dataset.attrs.update(scene.layout.attributes(np.array([case.restitution]), clearance))
        return dataset

    def estimate(self, scene, jobs: int, costs: Costs) -> Estimate:
        """The case's measured time plus the report, on the calibration machine."""
        work = CASE_SECONDS[scene.settings.name]
        report = costs.report_base + REPORT_FIGURES * costs.report_per_figure
        return Estimate(wall_time=costs.startup + work + report, memory=costs.main_process_memory, parts={scene.settings.name: work, "report": report})
