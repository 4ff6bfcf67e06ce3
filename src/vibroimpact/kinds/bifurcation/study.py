"""Bifurcation studies: every periodic orbit of a frequency band with its stability and special points, brute-force
sweeps up and down, and the two-parameter chart (frequency x clearance) with its regime map.

Output (``bifurcation.nc``; attributes from :data:`vibroimpact.kinds.bifurcation.variables.BIFURCATION_ATTRIBUTES`):

* dimension ``branch_point``: coordinates ``branch`` (integer label), ``branch_frequency`` [Hz] and
  ``branch_restitution``; variables ``<c>_amplitude`` [m] of every coordinate c of the structure (``x1_amplitude``,
  ``x2_amplitude`` for the paper's system), ``impulse`` [N s], ``floquet_modulus``, ``stable`` (flags),
  ``impacts_per_period``, ``period_multiplicity``, ``branch_origin`` (flags), the multipliers
  ``floquet_multiplier_real``/``_imag`` (branch_point, multiplier: 2N of them) and ``impact_velocity``
  (branch_point, orbit_impact);
* dimension ``special_point``: coordinates ``special_point_kind`` (CF flags ``fold period_doubling neimark_sacker
  grazing``), ``special_point_frequency`` [Hz], ``special_point_restitution``, ``special_point_branch``; the orbit's
  multipliers and measures there (``special_point_<c0>_amplitude`` of the first coordinate c0),
  ``special_point_note`` and ``special_point_branches`` (every branch it was found on: each point is listed once,
  :func:`~vibroimpact.kinds.bifurcation.branches.same_special_point`);
* brute force along (``restitution``, ``sweep``, ``frequency``, ``strobe``): ``brute_<c0>``, ``brute_<c0>_amplitude``
  of the first coordinate (``brute_x1``, ``brute_x1_amplitude`` for the paper's system);
  along (restitution, sweep, frequency, ``impact``): ``brute_impact_velocity`` (NaN-padded); along (restitution,
  sweep, frequency): ``brute_regime`` (flags), ``brute_period``, ``brute_impacts_per_period``,
  ``brute_lyapunov_exponent``;
* the chart: dimension ``chart_point`` with coordinates ``chart_curve``, ``chart_kind`` (flags as
  ``special_point_kind``), ``chart_frequency`` [Hz], ``chart_clearance`` [m]; the regime map ``chart_regime``
  (sweep, map_clearance, map_frequency) with ``chart_impacts_per_period`` and ``chart_period``.
* with bumpers, ``bumper_starts_without_orbit`` (absent otherwise): the closed-form starts a bumper has no orbit for,
  a line each, "R = <R>, bumper <Hz> Hz: the rigid stop's ... orbit at <f> Hz ... has no counterpart with this bumper:
  <where its continuation in the bumper's stiffness turns back>" (an answer, not a failure);
* the brute-force seeds that settle slowly (shooting from them did not converge), when any did: dimension
  ``slow_seed`` with what the motion from each reached (:mod:`vibroimpact.kinds.bifurcation.seed_report`);
* what failed, when anything did (attributes, absent otherwise): ``run_failures``, one line per kind of work and
  restitution, "<what failed>: <k> of <n> failed (<reasons>); <what it means for the results>", and
  ``run_failure_details``, every raw message (:mod:`vibroimpact.kinds.bifurcation.logs`); the console gets one line.

One netCDF group cannot hold ``frequency`` both as the brute force's dimension and as a coordinate of
``branch_point``, nor ``restitution`` as a dimension and a coordinate of ``special_point``: the branch and special
point coordinates carry the prefix of their dimension.

With ``bifurcation.bumper`` the branch and special points of every (restitution, bumper frequency) follow the rigid
stop's, each set continued on its own (stops that are Kelvin-Voigt bumpers of that Omega_b and the loss factor of
R), and both dimensions gain a coordinate ``branch_bumper_frequency`` / ``special_point_bumper_frequency`` [Hz]
(inf for the rigid stop's points); the brute force is the rigid stop's. Per restitution the stiffest bumper's folds,
period doublings and Neimark-Sacker points are followed in the bumper's stiffness
(:class:`~vibroimpact.kinds.bifurcation.stiffness.StiffnessCase`, alongside the branch sets): dimension
``stiffness_point`` with coordinates ``stiffness_curve``, ``stiffness_kind`` (flags), ``stiffness_restitution``,
``stiffness_frequency`` [Hz] and ``stiffness_bumper_frequency`` [Hz] (Omega_b / 2 pi at the curve point), each
curve's points in their order along it.

The scene's layout (the paper's named form or the general one: matrices, a load on any coordinate or a base motion,
a list of stops) becomes one general :class:`~vibroimpact.model.problem.ImpactProblem` per restitution
(:func:`diagram_problem`); every part of the study runs on it. The dataset's attributes describe that structure
(``system_coordinates``, the matrices flattened row by row, the load, ``stop_layout`` in words).
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from vibroimpact.engines.registry import BUMPER, RIGID, engine_for
from vibroimpact.model.collision import loss_factor_from_restitution
from vibroimpact.model.units import length_text
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.orbits.branch import SPECIAL_POINT_KINDS
from vibroimpact.kinds.bifurcation.scene import coordinate_label
from vibroimpact.scene.schema import Scene
from vibroimpact.scene.variables import COORDINATE_ATTRIBUTES, STABLE_ATTRIBUTES, flag_attributes
from vibroimpact.kinds.bifurcation.variables import BIFURCATION_ATTRIBUTES
from vibroimpact.kinds.bifurcation.branches import MAX_ORBIT_IMPACTS, ORIGINS
from vibroimpact.kinds.bifurcation.logs import Tally, chart_labels, continuation_log, failure_summary, numbered_across, relabel, sweep_tally, tallies
from vibroimpact.kinds.bifurcation.cases import BranchCase, ChartCase, SweepCase, Seed, sweep_seeds
from vibroimpact.kinds.bifurcation.seed_report import slow_seed_dataset
from vibroimpact.kinds.bifurcation.stiffness import SOFTER, STIFFER, StiffnessCase
from vibroimpact.runs.estimate import Costs, Estimate
from vibroimpact.runs.cluster import Progress
from vibroimpact.runs.runner import CaseResult, Runner
from vibroimpact.simulation.attractors import MAX_KEPT_IMPACTS, MAX_PERIOD, MOTION_CLASSES

__all__ = ["BifurcationStudy", "diagram_problem", "CONTINUATION_SECONDS", "CLOSED_FORM_SECONDS", "CHART_SECONDS", "STIFFNESS_SECONDS", "REPORT_FIGURES"]

#: Wall time of the continuation of one restitution's branches on the calibration machine [s], with the branches
#: seeded from the brute force (measured: 11-15 s for R = 0.2 and 0.8 at load ~2), and without (1.8-2.3 s).
CONTINUATION_SECONDS = 13.0
CLOSED_FORM_SECONDS = 3.0
#: Wall time of the chart's curves on the calibration machine [s] (measured: ~15 s).
CHART_SECONDS = 20.0
#: Measured time [s] of one restitution's curves in the bumper's stiffness (the stiffest bumper's branches again, then
#: its special points followed: 10.0 s for the shipped bifurcation_bumper's 4 kHz bumper, alone on the quiet machine;
#: the 31 s first written here was measured beside other work).
STIFFNESS_SECONDS = 10.0
#: Figures of the report: per restitution a diagram and the multipliers; the chart.
REPORT_FIGURES = 3
#: Cost of a brute-force period with moments and Jacobians, relative to a plain ``exact`` period [-].
BRUTE_FACTOR = 1.5


def diagram_problem(scene: Scene, restitution: float, clearance: float | None = None, bumper_frequency: float | None = None) -> ImpactProblem:
    """The problem a bifurcation diagram starts from: the scene's layout with every stop rigid of ``restitution``
    [-] (or, given ``bumper_frequency`` [Hz], a Kelvin-Voigt bumper of that Omega_b / 2 pi whose loss factor gives that
    restitution), the scene's clearance (or ``clearance`` [m]), and its load at the band's lower frequency (each part
    of the study moves it in frequency)."""
    settings = scene.settings
    assert settings is not None
    delta = settings.clearance if clearance is None else float(clearance)
    if bumper_frequency is None:
        return scene.layout.problem(scene.amplitude, settings.low, float(restitution), delta)
    return scene.layout.problem(scene.amplitude, settings.low, float(restitution), delta, True, float(bumper_frequency), loss_factor_from_restitution(float(restitution)))


class BifurcationStudy:
    """Branches, special points, brute force and the chart of a scene's ``bifurcation`` section."""

    name = "bifurcation"

    @staticmethod
    def engines(scene: Scene) -> tuple[str, ...]:
        """The continuation's and brute force's engine of each diagram (exact Jacobians for its contact law)."""
        return tuple(dict.fromkeys(_engine(fb) for _r, fb in _diagrams(scene)))

    def run(self, scene: Scene, progress: Progress | None, runner: Runner) -> xr.Dataset:
        """The study's dataset (module docstring); ``progress`` gets a line per stage and per branch set."""
        settings = scene.settings
        assert settings is not None
        say = progress if progress is not None else (lambda message: None)
        delta = settings.clearance
        options = tuple(sorted(vars(settings.branches).items()))
        brute = settings.brute_force
        chart = settings.chart
        diagrams = _diagrams(scene)
        sweeps = [SweepCase(diagram_problem(scene, r, bumper_frequency=fb), d, tuple(settings.frequency), brute.transient_periods, brute.strobes, engine=_engine(fb))
                  for r, fb in diagrams for d in brute.directions]  # fmt: skip
        maps = []
        if chart is not None:
            maps = [SweepCase(diagram_problem(scene, chart.restitution, float(c)), d, tuple(settings.chart_frequency), chart.transient_periods, chart.strobes) for c in chart.clearances for d in brute.directions]
        # the chart's curves (the longest case) first, alongside the sweeps; then the branches, seeded from the sweeps
        charted = [ChartCase(diagram_problem(scene, chart.restitution), settings.low, settings.high, chart.clearance, chart.kinds, chart.max_steps)] if chart else []
        say(f"brute force: {len(sweeps)} sweeps of {settings.frequency.size} frequencies" + (f", regime map: {len(maps)} sweeps of {settings.chart_frequency.size}" if maps else "")
            + (f"; the chart's curves (R = {chart.restitution:g})" if chart else ""))  # fmt: skip
        first = runner.map(charted + sweeps + maps)
        chart_result, swept = (first[0], first[1:]) if chart else (None, first)
        continuation = []
        for i, (r, fb) in enumerate(diagrams):
            seeds: list[Seed] = []
            if settings.branches.brute_force:  # every diagram's own sweeps, the bumpers' too
                for j, _direction in enumerate(brute.directions):
                    result = swept[i * len(brute.directions) + j]
                    seeds += sweep_seeds(settings.frequency, result["period"], result["impacts"], result["state"], j)
            continuation.append(BranchCase(diagram_problem(scene, r, bumper_frequency=fb), settings.low, settings.high, options, tuple(seeds)))
        stiffness = _stiffness_cases(scene, options) if settings.bumper_frequencies and settings.rigid else []
        say(f"continuing the branches of {', '.join(_label(r, fb) for r, fb in diagrams)}" + (", and following the stiffest bumper's special points in its stiffness" if stiffness else ""))
        mapped = runner.map(stiffness + continuation)  # the longest cases first
        curves, results = mapped[: len(stiffness)], numbered_across(mapped[len(stiffness) :])  # the dataset's labels
        for (r, fb), result in zip(diagrams, results):
            _say_notes(say, _label(r, fb), result)
        for r, result in zip(settings.restitution, curves):
            _say_notes(say, f"R = {r:g}, bumper stiffness", result)
        if chart_result is not None:
            same = [result for (r, _fb), result in zip(diagrams, results) if np.isclose(r, chart.restitution)]
            labels = chart_labels(chart_result, same[0] if same else None)
            chart_result = dict(chart_result, notes=np.array([relabel(str(note), labels) for note in chart_result["notes"]], dtype=str))
            _say_notes(say, f"chart {chart.restitution:g}", chart_result)
            results = [*results, chart_result]
        sets = len(diagrams)
        data = _branches(results[:sets], tuple(r for r, _fb in diagrams), scene.coordinates, scene.layout.load.base_motion,
                         tuple(fb for _r, fb in diagrams) if settings.bumper_frequencies else ())  # fmt: skip
        data = data.merge(_brute(swept[: len(sweeps)], scene, brute.directions, brute.strobes)).merge(slow_seed_dataset(results[:sets], tuple(r for r, _fb in diagrams)))
        if curves:
            data = data.merge(_stiffness(curves, settings.restitution))
        if chart is not None:
            data = data.merge(_chart(results[-1], swept[len(sweeps) :], chart.clearances, settings.chart_frequency, brute.directions))
        data = data.assign_coords(clearance=delta)
        for key in ("restitution", "frequency", "sweep", "clearance"):
            data[key].attrs.update(COORDINATE_ATTRIBUTES[key])
        data.attrs.update(_metadata(scene, results, swept[: len(sweeps)], curves))
        lines, details = failure_summary(_tallies(scene, results, swept, curves))
        if lines:
            data.attrs.update(run_failures=lines, run_failure_details=details)  # said in one line by run-study
        return data

    def estimate(self, scene: Scene, jobs: int, costs: Costs) -> Estimate:
        """Brute-force periods times the cost of an ``exact`` period, plus measured continuation times, on the
        calibration machine; the sweeps and the continuations are spread over ``jobs`` processes."""
        settings = scene.settings
        assert settings is not None
        brute = settings.brute_force
        per_model = settings.frequency.size * len(settings.restitution) * len(brute.directions) * (brute.transient_periods + brute.strobes)
        periods = per_model * len(settings.models)
        sweeps = sum(per_model * _period_cost(costs, _engine(fb)) for fb in settings.models)
        rigid = len(settings.restitution) if settings.rigid else 0
        continuation = [CONTINUATION_SECONDS if settings.branches.brute_force else CLOSED_FORM_SECONDS] * rigid
        continuation += [CLOSED_FORM_SECONDS] * (len(settings.restitution) * len(settings.bumper_frequencies))
        continuation += [STIFFNESS_SECONDS] * (rigid if settings.bumper_frequencies else 0)
        chart_seconds = 0.0
        if settings.chart is not None:
            chart = settings.chart
            mapped = settings.chart_frequency.size * chart.clearance_num * len(brute.directions) * (chart.transient_periods + chart.strobes)
            periods += mapped
            sweeps += mapped * _period_cost(costs, _engine(None))
            chart_seconds = CHART_SECONDS
        jobs = max(1, jobs)
        first = max(chart_seconds, (chart_seconds + sweeps) / jobs)  # the chart's curves run alongside the sweeps
        branches = max(max(continuation), sum(continuation) / jobs)  # then the branches, seeded from the sweeps
        report = costs.report_base + REPORT_FIGURES * len(settings.restitution) * costs.report_per_figure
        wall = costs.startup + first + branches + report
        parts = {"brute force and chart": first, "continuation": branches, "report": report}
        memory = costs.main_process_memory + (jobs - 1) * costs.worker_process_memory
        return Estimate(wall_time=wall, memory=memory, parts=parts, points={"brute force": f"{periods:,} periods", "continuation": f"{len(continuation)} continuations"})


def _period_cost(costs: Costs, engine: str) -> float:
    """Measured wall time of one brute-force period of ``engine`` [s] (a plain period's times :data:`BRUTE_FACTOR`)."""
    return costs.per_period_cost(engine, 0.0) * BRUTE_FACTOR


def _diagrams(scene: Scene) -> list[tuple[float, float | None]]:
    """(R, Omega_b / 2 pi [Hz] or None for the rigid stop) of every diagram, in the dataset's order: per restitution
    each contact model of :attr:`~vibroimpact.kinds.bifurcation.scene.BifurcationSettings.models`."""
    settings = scene.settings
    assert settings is not None
    return [(r, fb) for r in settings.restitution for fb in settings.models]


def _label(r: float, fb: float | None) -> str:
    """How the logs name a diagram: "R = 0.2", "R = 0.2, bumper 250 Hz"."""
    return f"R = {r:g}" + ("" if fb is None else f", bumper {fb:g} Hz")


def _engine(fb: float | None) -> str:
    """The brute force's engine of a diagram: the registry's engine with exact Jacobians for its contact law (the
    compiled exact engine for the rigid stop, the bumper's closed-form engine for a bumper)."""
    return engine_for(RIGID if fb is None else BUMPER, "exact_jacobians")


def _say_notes(say: Progress, where: str, result: CaseResult) -> None:
    """A case's notes, a line each, but its failures (the run's one line of failures says them)."""
    failed = set(result["failure_detail"].tolist())
    for note in result["notes"]:
        if note not in failed:
            say(f"  {where}: {note}")


def _tallies(scene: Scene, results: list[CaseResult], swept: list[CaseResult], curves: list[CaseResult]) -> list[Tally]:
    """What the run attempted and what failed (:func:`~vibroimpact.kinds.bifurcation.logs.failure_summary`): per
    restitution the branches, the seeds and the brute-force points; then the chart's branches, curves and regime map.
    ``results``: the branch cases, then the chart's case; ``swept``: the sweeps, then the regime map's."""
    settings = scene.settings
    assert settings is not None
    directions, chart = settings.brute_force.directions, settings.chart
    counted: list[Tally] = []
    for i, (r, fb) in enumerate(_diagrams(scene)):
        where = _label(r, fb)
        counted += tallies(results[i], where)
        sweeps = swept[i * len(directions) : (i + 1) * len(directions)]
        counted.append(sweep_tally("sweep", where, sweeps, [f"sweeping {d}" for d in directions], settings.frequency))
    for r, result in zip(settings.restitution, curves):
        counted += tallies(result, f"R = {r:g}")
    if chart is not None:
        where = f"R = {chart.restitution:g}"
        counted += tallies(results[-1], where)
        labels = [f"Delta = {length_text(c, '.4g', settings.clearance)}, sweeping {d}" for c in chart.clearances for d in directions]
        counted.append(sweep_tally("map", where, swept[len(_diagrams(scene)) * len(directions) :], labels, settings.chart_frequency))
    return counted


def coordinate_attributes(key: str, name: str, base_motion: bool = False) -> dict[str, str]:
    """Units and long name of a per-coordinate variable: the entry ``key`` of the attributes (written for X1) with
    ``X1`` replaced by coordinate ``name``'s label (:func:`coordinate_label`; unchanged for ``x1``)."""
    attrs = dict(BIFURCATION_ATTRIBUTES[key])
    label = coordinate_label(name)
    attrs["long_name"] = attrs["long_name"].replace("X1", label if label != name else f"coordinate {name}") + (" (relative to the base)" if base_motion else "")
    return attrs


def _branches(results: list[CaseResult], restitutions: tuple[float, ...], coordinates: tuple[str, ...], base_motion: bool, bumpers: tuple[float | None, ...] = ()) -> xr.Dataset:
    """branch_point and special_point variables of every branch set (``results`` :func:`numbered` across them), each
    of restitution ``restitutions[i]`` and, given ``bumpers``, bumpers of ``bumpers[i]`` Hz (None: the rigid stop)."""
    points: dict[str, list] = {}
    specials: dict[str, list] = {}
    size = len(coordinates)
    for i, (r, result) in enumerate(zip(restitutions, results)):
        n = result["frequency"].size
        if bumpers:
            fb = math.inf if bumpers[i] is None else float(bumpers[i])
            points.setdefault("bumper", []).append(np.full(n, fb))
            specials.setdefault("bumper", []).append(np.full(result["sp_frequency"].size, fb))
        points.setdefault("branch", []).append(result["branch"])
        points.setdefault("restitution", []).append(np.full(n, r))
        for name in ("origin", "frequency", "amplitudes", "impulse", "floquet_modulus", "stable", "impacts", "period", "multipliers_real", "multipliers_imag", "velocities"):
            points.setdefault(name, []).append(result[name])
        m = result["sp_frequency"].size
        specials.setdefault("branch", []).append(result["sp_branch"])
        specials.setdefault("restitution", []).append(np.full(m, r))
        for name in ("kind", "frequency", "amplitudes", "impulse", "floquet_modulus", "impacts", "period", "multipliers_real", "multipliers_imag", "note", "induced_by"):
            specials.setdefault(name, []).append(result[f"sp_{name}"])
        specials.setdefault("found_on", []).append(result["sp_found_on"])
    p = {k: np.concatenate(v) for k, v in points.items()}
    s = {k: np.concatenate(v) for k, v in specials.items()}
    a = BIFURCATION_ATTRIBUTES
    kind_flags = flag_attributes("kind of special point", SPECIAL_POINT_KINDS)
    bp, sp = ("branch_point",), ("special_point",)
    amplitudes = p["amplitudes"].reshape(-1, size)
    first = coordinates[0]
    extra = {}
    if bumpers:
        extra = {"branch_bumper_frequency": (bp, p["bumper"], a["branch_bumper_frequency"]), "special_point_bumper_frequency": (sp, s["bumper"], a["special_point_bumper_frequency"])}
    return xr.Dataset(
        {
            **{f"{c}_amplitude": (bp, amplitudes[:, i], coordinate_attributes("x1_amplitude", c, base_motion)) for i, c in enumerate(coordinates)},
            "impulse": (bp, p["impulse"], a["impulse"]),
            "floquet_modulus": (bp, p["floquet_modulus"], a["floquet_modulus"]),
            "stable": (bp, p["stable"].astype(np.int8), STABLE_ATTRIBUTES | {"long_name": "Floquet stability of the orbit"}),
            "impacts_per_period": (bp, p["impacts"] / p["period"], a["impacts_per_period"]),
            "period_multiplicity": (bp, p["period"].astype(np.int16), a["period_multiplicity"]),
            "branch_origin": (bp, p["origin"].astype(np.int8), flag_attributes("how the branch was found", ORIGINS)),
            "floquet_multiplier_real": (bp + ("multiplier",), p["multipliers_real"].reshape(-1, 2 * size), a["floquet_multiplier_real"]),
            "floquet_multiplier_imag": (bp + ("multiplier",), p["multipliers_imag"].reshape(-1, 2 * size), a["floquet_multiplier_imag"]),
            "impact_velocity": (bp + ("orbit_impact",), p["velocities"].reshape(-1, MAX_ORBIT_IMPACTS), a["impact_velocity"]),
            f"special_point_{first}_amplitude": (sp, s["amplitudes"].reshape(-1, size)[:, 0], coordinate_attributes("special_point_x1_amplitude", first, base_motion)),
            "special_point_impulse": (sp, s["impulse"], a["special_point_impulse"]),
            "special_point_floquet_modulus": (sp, s["floquet_modulus"], a["special_point_floquet_modulus"]),
            "special_point_impacts_per_period": (sp, s["impacts"] / np.maximum(s["period"], 1), a["special_point_impacts_per_period"]),
            "special_point_period_multiplicity": (sp, s["period"].astype(np.int16), a["special_point_period_multiplicity"]),
            "special_point_multiplier_real": (sp + ("multiplier",), s["multipliers_real"].reshape(-1, 2 * size), a["special_point_multiplier_real"]),
            "special_point_multiplier_imag": (sp + ("multiplier",), s["multipliers_imag"].reshape(-1, 2 * size), a["special_point_multiplier_imag"]),
            "special_point_note": (sp, s["note"].astype(str), a["special_point_note"]),
            "special_point_induced_by": (sp, s["induced_by"], a["special_point_induced_by"]),
            "special_point_branches": (sp, s["found_on"].astype(str), a["special_point_branches"]),
        },
        coords={
            "branch": (bp, p["branch"].astype(np.int32), a["branch"]),
            "branch_frequency": (bp, p["frequency"], a["branch_frequency"]),
            "branch_restitution": (bp, p["restitution"], a["branch_restitution"]),
            "special_point_kind": (sp, s["kind"].astype(np.int8), kind_flags),
            "special_point_frequency": (sp, s["frequency"], a["special_point_frequency"]),
            "special_point_restitution": (sp, s["restitution"], a["special_point_restitution"]),
            "special_point_branch": (sp, s["branch"].astype(np.int32), a["special_point_branch"]),
            **extra,
        },
    )


def _brute(results: list[CaseResult], scene: Scene, directions: tuple[str, ...], strobes: int) -> xr.Dataset:
    """Brute-force variables over (restitution, sweep, frequency[, strobe | impact])."""
    settings = scene.settings
    assert settings is not None
    bumpers = bool(settings.bumper_frequencies)
    shape = (len(settings.restitution), len(settings.models), len(directions)) if bumpers else (len(settings.restitution), len(directions))

    def stack(name: str) -> np.ndarray:
        values = np.array([r[name] for r in results])
        return values.reshape(shape + values.shape[1:])

    a = BIFURCATION_ATTRIBUTES
    grid = ("restitution", "bumper_frequency", "sweep", "frequency") if bumpers else ("restitution", "sweep", "frequency")
    models = {"bumper_frequency": ("bumper_frequency", np.array([math.inf if fb is None else fb for fb in settings.models]), BIFURCATION_ATTRIBUTES["bumper_frequency"])} if bumpers else {}
    regime = _regime_flags("brute force: what the motion is at each frequency")
    first, base = scene.coordinates[0], scene.layout.load.base_motion
    return xr.Dataset(
        {
            f"brute_{first}": (grid + ("strobe",), stack("strobe"), coordinate_attributes("brute_x1", first, base)),
            f"brute_{first}_amplitude": (grid + ("strobe",), stack("amplitude"), coordinate_attributes("brute_x1_amplitude", first, base)),
            "brute_impact_velocity": (grid + ("impact",), stack("velocity").reshape(shape + (-1, MAX_KEPT_IMPACTS)), a["brute_impact_velocity"]),
            "brute_impacts_per_period": (grid, stack("impacts"), a["brute_impacts_per_period"]),
            "brute_regime": (grid, stack("regime").astype(np.int8), regime),
            "brute_period": (grid, stack("period").astype(np.int16), a["brute_period"]),
            "brute_lyapunov_exponent": (grid, stack("lyapunov"), a["brute_lyapunov_exponent"]),
        },
        coords={"restitution": np.array(settings.restitution), **models, "sweep": list(directions), "frequency": settings.frequency,
                "strobe": ("strobe", np.arange(strobes, dtype=np.int32), a["strobe"])},
    )  # fmt: skip


def _chart(curves: CaseResult, results: list[CaseResult], clearances: np.ndarray, frequency: np.ndarray, directions: tuple[str, ...]) -> xr.Dataset:
    """The chart's curves (chart_point) and regime map (sweep, map_clearance, map_frequency)."""
    shape = (clearances.size, len(directions), frequency.size)
    a = BIFURCATION_ATTRIBUTES

    def stack(name: str) -> np.ndarray:
        return np.moveaxis(np.array([r[name] for r in results]).reshape(shape), 1, 0)

    regime = _regime_flags("regime map: what the brute-force motion is at each (clearance, frequency)")
    cp, grid = ("chart_point",), ("sweep", "map_clearance", "map_frequency")
    return xr.Dataset(
        {
            "chart_regime": (grid, stack("regime").astype(np.int8), regime),
            "chart_impacts_per_period": (grid, stack("impacts"), a["chart_impacts_per_period"]),
            "chart_period": (grid, stack("period").astype(np.int16), a["chart_period"]),
        },
        coords={
            "chart_curve": (cp, curves["curve"].astype(np.int32), a["chart_curve"]),
            "chart_kind": (cp, curves["kind"].astype(np.int8), flag_attributes("kind of special point the curve follows", SPECIAL_POINT_KINDS)),
            "chart_frequency": (cp, curves["frequency"], a["chart_frequency"]),
            "chart_clearance": (cp, curves["clearance"], a["chart_clearance"]),
            "map_clearance": ("map_clearance", clearances, a["map_clearance"]),
            "map_frequency": ("map_frequency", frequency, a["map_frequency"]),
        },
    )


def _stiffness_cases(scene: Scene, options: tuple[tuple[str, object], ...]) -> list[StiffnessCase]:
    """Per restitution, the curves of the stiffest bumper's special points in its stiffness
    (:class:`~vibroimpact.kinds.bifurcation.stiffness.StiffnessCase`), over :data:`STIFFER` times the stiffest bumper to
    the softest over :data:`SOFTER`, with the branches' own step settings."""
    settings = scene.settings
    assert settings is not None
    fbs, steps = settings.bumper_frequencies, dict(options)
    reach = (min(fbs) / SOFTER, max(fbs) * STIFFER)
    return [StiffnessCase(diagram_problem(scene, r, bumper_frequency=max(fbs)), settings.low, settings.high, reach, int(steps.get("max_steps", 2000)), float(steps.get("max_step", 0.1)))
            for r in settings.restitution]  # fmt: skip


def _stiffness(curves: list[CaseResult], restitutions: tuple[float, ...]) -> xr.Dataset:
    """The curves of special points in (frequency, bumper frequency) of every restitution (``stiffness_point``), their
    labels numbered across restitutions."""
    a = BIFURCATION_ATTRIBUTES
    offsets = np.cumsum([0] + [int(c["curve"].max()) + 1 if c["curve"].size else 0 for c in curves[:-1]])
    joined = {name: np.concatenate([c[name] for c in curves]) for name in ("kind", "frequency", "bumper_frequency")}
    labels = np.concatenate([c["curve"] + offset for c, offset in zip(curves, offsets)])
    restitution = np.concatenate([np.full(c["curve"].size, r) for c, r in zip(curves, restitutions)])
    sp = ("stiffness_point",)
    return xr.Dataset(coords={
        "stiffness_curve": (sp, labels.astype(np.int32), a["stiffness_curve"]),
        "stiffness_kind": (sp, joined["kind"].astype(np.int8), flag_attributes("kind of special point the curve follows", SPECIAL_POINT_KINDS)),
        "stiffness_restitution": (sp, restitution, a["stiffness_restitution"]),
        "stiffness_frequency": (sp, joined["frequency"], a["stiffness_frequency"]),
        "stiffness_bumper_frequency": (sp, joined["bumper_frequency"], a["stiffness_bumper_frequency"]),
    })  # fmt: skip


def _regime_flags(long_name: str) -> dict[str, object]:
    """CF flags of a motion class (:data:`MOTION_CLASSES`), with -1 where the engine failed."""
    return {"long_name": long_name, "units": "1", "flag_values": np.arange(-1, len(MOTION_CLASSES), dtype=np.int8), "flag_meanings": " ".join(("failed", *MOTION_CLASSES))}


def _metadata(scene: Scene, results: list[CaseResult], sweeps: list[CaseResult], curves: list[CaseResult]) -> dict[str, object]:
    settings = scene.settings
    assert settings is not None
    attrs: dict[str, object] = {
        **_layout_attributes(scene),
        "frequency_band_Hz": np.array([settings.low, settings.high]),
        "brute_force_transient_periods": settings.brute_force.transient_periods,
        "continuation_notes": continuation_log([_label(r, fb) for r, fb in _diagrams(scene)], results),
        "method_branches": "pseudo-arclength continuation of fixed points of the exact stroboscopic map (compiled exact engine, exact Jacobians), started from the closed-form impact orbit at both roots of eq. 16 (one impact per period; two on a symmetric two-sided stop; none where the layout has no closed form), at period doublings, at grazing points and from every periodic brute-force attractor no other branch passes through",
        "method_brute_force": f"compiled exact engine, stepped sweeps carrying the end state; strobes compared over periods 1-{MAX_PERIOD}, else the Lyapunov exponent from the exact Jacobians",
    }
    diagrams = _diagrams(scene)
    if settings.bumper_frequencies:
        lines = [f"R = {r:g}, bumper stiffness: {note}" for r, result in zip(settings.restitution, curves) for note in result["notes"]]
        attrs["continuation_notes"] = "\n".join([attrs["continuation_notes"], *lines])
        absent = [f"{_label(r, fb)}: {line}" for (r, fb), result in zip(diagrams, results) for line in result["absent"]]
        if absent:
            attrs["bumper_starts_without_orbit"] = absent
        attrs["bumper_frequencies_Hz"] = np.array(settings.bumper_frequencies)
        if settings.bumper_stiffnesses:  # the scene gave K_b [N/m]: its pages say so
            attrs["bumper_stiffnesses_N_per_m"] = np.array(settings.bumper_stiffnesses)
        attrs["bifurcation_reference"] = settings.reference
        attrs["method_brute_force"] = (f"each diagram's own contact law: the bumpers' with their closed-form engine ({_engine(settings.bumper_frequencies[0])}), "
                                       + (f"the rigid stop's with the compiled exact engine ({_engine(None)}); " if settings.rigid else "")
                                       + f"stepped sweeps carrying the end state; strobes compared over periods 1-{MAX_PERIOD}, else the Lyapunov exponent from the exact Jacobians")  # fmt: skip
        attrs["method_bumper"] = ("the same layout with every stop a Kelvin-Voigt bumper of each Omega_b / 2 pi and the loss factor whose collision restitution is R "
                                  "(corrected eq. 26): branches started from the rigid stop's closed-form orbit continued in the bumper period from a bumper "
                                  "64 times stiffer, continued on the exact stroboscopic map of the engine that gives exact Jacobians for bumpers; grazing: "
                                  "contact onset at tangency" + ("; the rigid stop's diagram is the reference (bifurcation.reference: rigid)" if settings.rigid else ""))  # fmt: skip
    if settings.chart is not None:
        attrs["chart_restitution"] = settings.chart.restitution
        attrs["chart_notes"] = "\n".join(str(n) for n in results[-1]["notes"])
    return attrs


def _layout_attributes(scene: Scene) -> dict[str, object]:
    """The structure, load and stops the study ran, written by the one writer of layout attributes
    (:meth:`~vibroimpact.model.layout.Layout.attributes`, read back by ``Layout.from_attributes``), and the
    excitation amplitude. The stops are described with the study's clearance and without a restitution: each diagram
    has its own."""
    base_motion = scene.layout.load.base_motion
    return scene.layout.attributes(np.array([]), np.array([scene.settings.clearance])) | {f"excitation_amplitude_{'m' if base_motion else 'N'}": scene.amplitude}
