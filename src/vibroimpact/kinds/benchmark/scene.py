"""Benchmark scenes: the header of every scene plus ``benchmark`` (cases, methods, tolerances, the model ladder).

Example (the shipped ``accuracy_cost``, shortened)::

    name: accuracy_cost
    system: {m1: 1.0, m2: 0.1, k1: 25000, k2: 4300, b1: 0.8, b2: 0.08}
    excitation: {amplitude: 10.0}
    benchmark:
      duration: 2.0
      methods: [momentary_adams, compliant_ida, solve_ivp_DOP853]
      tolerances: [1.0e-4, 1.0e-6, 1.0e-8]
      cases:
        - {name: one_impact, frequency: 25.0, restitution: 0.2, clearance: 0.003, start: pgf, bumper_frequency: 1000}

The structure, load and stops are written as in stepped scenes (:mod:`vibroimpact.scene.layout_parse`): the paper's
named form above (its stop above the absorber), or matrices with named coordinates, ``excitation: {amplitude, on,
static, base_motion}`` and a ``stops`` list. A case's ``restitution``, ``clearance`` (or ``clearance_below_linear``:
that far inside each stop's linear reach |n . X| + n . x0) and ``bumper_frequency`` go to the stops that do not give
their own (each stop's loss factor follows its restitution); they are required where a stop takes them, refused where
none does. Method names are engines of :mod:`vibroimpact.engines.registry` (see
:data:`~vibroimpact.scene.schema.BENCHMARK_METHODS`).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

from vibroimpact.analysis.linear import linear_reach
from vibroimpact.engines.registry import BUMPER, RIGID, engine_spec
from vibroimpact.engines.settings import ATOL_RATIO, STEPPED_TOLERANCES
from vibroimpact.model.excitation import SweptSine
from vibroimpact.model.layout import Layout, LoadSpec, StopSpec, build_stops
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.contact import Stop
from vibroimpact.model.parameters import MAX_BUMPER_FREQUENCY
from vibroimpact.scene.checker import Checker, SceneError
from vibroimpact.scene.declared import DERIVED, OPTIONAL, REQUIRED, Grid, Key, Names, Rows, Section, Table
from vibroimpact.scene.header import NAME, check_sweep_run, open_scene
from vibroimpact.scene.layout_parse import parse_layout
from vibroimpact.scene.schema import (
    BENCHMARK_METHODS,
    MAX_BENCHMARK_PERIODS,
    Scene,
)
from vibroimpact.simulation.settings import START_MODES

__all__ = ["BenchmarkScene", "BenchmarkCase", "BenchmarkSettings", "LadderSettings", "BENCHMARK_TOP_KEYS", "parse_benchmark_scene"]

#: Top-level keys of a benchmark scene.
BENCHMARK_TOP_KEYS = {"name", "description", "system", "excitation", "stops", "benchmark", "report"}
#: ``benchmark``, declared (:mod:`vibroimpact.scene.declared`): a case's keys and the ladder's are checked by their own.
BENCHMARK = Section("benchmark", (
    Key("duration", float, "time simulated per run", REQUIRED, 0.0, 1e5, "s", open_low=True),
    Key("methods", Names, "the methods timed", REQUIRED, choices=BENCHMARK_METHODS),
    Key("tolerances", Grid, "relative tolerances of the integrators (atol = rtol x atol_ratio)", REQUIRED, 1e-15, 1e-1),
    Key("atol_ratio", float, "absolute tolerance per unit of relative tolerance", ATOL_RATIO, 1e-12, 1.0, "m"),
    Key("repeats", int, "runs per point (their median wall time)", 3, 1, 100),
    Key("max_seconds", float, "a method's tighter tolerances are skipped once one of its runs took longer", 60.0, 0.0, 1e5, "s", open_low=True),
    Key("cases", Rows, "{name, frequency, restitution, clearance | clearance_below_linear, start[, bumper_frequency] | swept_sine} each", REQUIRED),
    Key("ladder", Table, "{frequency, bumper_frequencies[, restitution, clearance, rtol, repeats]}: one point through every model", OPTIONAL),
), "what to time, against the exact references")  # fmt: skip
#: ``benchmark.ladder``, declared: restitution and clearance go to the stops that give none (required where one does).
LADDER = Section("benchmark.ladder", (
    Key("frequency", float, "the excitation frequency of the ladder's point", REQUIRED, 0.0, math.inf, "Hz", open_low=True),
    Key("restitution", float, "R of the stops that give none (derived: the stops' own)", DERIVED, 0.0, 1.0, open_low=True),
    Key("clearance", float, "Delta of the stops that give none (derived: the stops' own)", DERIVED, 0.0, math.inf, "m"),
    Key("bumper_frequencies", Grid, "Omega_b / 2 pi of the compliant models", REQUIRED, 0.0, MAX_BUMPER_FREQUENCY, "Hz", open_low=True),
    Key("rtol", float, "tolerance of the integrators (atol = rtol x atol_ratio)", STEPPED_TOLERANCES[0], 1e-14, 1e-2),
    Key("repeats", int, "runs per model (their median wall time)", 3, 1, 100),
), "one frequency point through every model, from the closed form to ever stiffer bumpers")  # fmt: skip
#: One entry of ``benchmark.cases``, declared: a stepped case (frequency, start) or a swept one (swept_sine); the
#: values the stops give themselves are not the case's.
CASE_ROW = Section("benchmark.cases[k]", (
    Key("name", str, "the case's name in the dataset (letters, digits, '_', '-', '.'; unique)", REQUIRED),
    Key("frequency", float, "the excitation frequency (a stepped case)", DERIVED, 0.0, math.inf, "Hz", open_low=True),
    Key("restitution", float, "R of the stops that give none", DERIVED, 0.0, 1.0),
    Key("clearance", float, "Delta of the stops that give none (or clearance_below_linear)", DERIVED, 0.0, math.inf, "m"),
    Key("clearance_below_linear", float, "Delta that far inside the linear amplitude at the frequency (or clearance)", DERIVED, -1.0, 1.0, "m"),
    Key("start", str, "where each run starts (required for a stepped case; a swept case starts at rest)", DERIVED, choices=tuple(START_MODES)),
    Key("bumper_frequency", float, "Omega_b / 2 pi of the compliant methods' bumpers (derived: none, no compliant method)", DERIVED, 0.0, MAX_BUMPER_FREQUENCY,
        "Hz", open_low=True),
    Key("swept_sine", Table, "{start, stop, rate[, sample_rate]}: a swept case instead (benchmark.cases[k].swept_sine)", OPTIONAL),
), "one benchmark run: the problem, where it starts and how long it lasts")  # fmt: skip
#: A swept case's sweep, declared.
CASE_SWEEP = Section("benchmark.cases[k].swept_sine", (
    Key("start", float, "the frequency the sweep starts at", REQUIRED, 0.0, math.inf, "Hz", open_low=True),
    Key("stop", float, "the frequency it ends at (below start: a sweep down)", REQUIRED, 0.0, math.inf, "Hz", open_low=True),
    Key("rate", float, "|alpha|, how fast the frequency moves", REQUIRED, 0.0, math.inf, "Hz s-1", open_low=True),
    Key("sample_rate", float, "output samples per second", 2000.0, 0.0, 1e7, "Hz", open_low=True),
), "a swept case's sweep, driven by q sin(theta(t))")  # fmt: skip
#: The sections of a benchmark scene that are declared (``run-study --keys`` lists them).
SECTIONS = (BENCHMARK, LADDER, CASE_ROW, CASE_SWEEP)


@dataclass(frozen=True)
class LadderSettings:
    """One frequency point through every model, from the closed form to ever stiffer bumpers.

    Attributes
    ----------
    frequency : float
        Excitation frequency [Hz].
    restitution : float
        R [-] (the bumpers get the loss factor that gives it).
    clearance : float
        Delta [m].
    bumper_frequencies : tuple of float
        Omega_b / 2 pi of the compliant models [Hz].
    rtol : float
        Tolerance of the integrators (atol = rtol x the scene's atol_ratio); default: that of stepped steady states.
    repeats : int
        Runs per model (median wall time).
    problem : ImpactProblem
        The scene's structure, load and rigid stops at this point (the stops' own values where they give them; NaN
        ``restitution``, ``clearance`` where every stop does); required.
    compliant : tuple of tuple of Stop
        The same stops as bumpers, one layout per bumper frequency (loss factors from each stop's restitution).
    """

    frequency: float
    restitution: float
    clearance: float
    bumper_frequencies: tuple[float, ...]
    rtol: float = LADDER.key("rtol").default
    repeats: int = LADDER.key("repeats").default
    problem: ImpactProblem | None = None
    compliant: tuple[tuple[Stop, ...], ...] = ()

    def __post_init__(self) -> None:
        if self.problem is None:
            raise ValueError("problem: the ladder needs its structure, load and rigid stops (an ImpactProblem)")
        if len(self.compliant) != len(self.bumper_frequencies):
            raise ValueError(f"compliant: expected one bumper layout per bumper frequency ({len(self.bumper_frequencies)}), got {len(self.compliant)}")


@dataclass(frozen=True)
class BenchmarkCase:
    """One benchmark run: the problem, where it starts and how long it lasts.

    Attributes
    ----------
    name : str
        Label of the case.
    problem : ImpactProblem
        Structure, rigid stops and harmonic load (a swept case: at its start frequency), for the rigid-stop methods
        and the start of every stepped run.
    start : str
        ``rest``, ``linear`` or ``pgf`` (see :func:`vibroimpact.simulation.steady.start_state`: ``pgf`` is the closed-form
        orbit where the layout has one, else the linear start); swept cases start at rest.
    periods : int
        Whole periods integrated (stepped cases).
    bumper : tuple of Stop or None
        The compliant model's stops, the rigid ones as Kelvin-Voigt bumpers (each loss factor gives its stop's
        restitution); None: no compliant methods.
    sweep : SweptSine or None
        A swept-sine case of the compliant model.
    sample_rate : float
        Output samples per second of a swept case [Hz].
    """

    name: str
    problem: ImpactProblem
    start: str
    periods: int
    bumper: tuple[Stop, ...] | None = None
    sweep: SweptSine | None = None
    sample_rate: float = 2000.0

    def runs(self, method: str) -> bool:
        """Whether ``method`` applies to this case."""
        spec = engine_spec(method)
        contact = spec.contact
        if self.sweep is not None:
            return (contact == BUMPER and spec.capabilities.sweeps) or method.startswith("solve_ivp_")
        return contact == RIGID or (contact == BUMPER and self.bumper is not None)


@dataclass(frozen=True)
class BenchmarkSettings:
    """What to compare.

    Attributes
    ----------
    methods : tuple of str
        Names of :data:`BENCHMARK_METHODS`.
    tolerances : tuple of float
        Relative tolerances; atol = rtol * ``atol_ratio`` [m, m s-1].
    atol_ratio : float
        Absolute tolerance per unit of relative tolerance [m].
    repeats : int
        Runs per point (median wall time).
    max_seconds : float
        The largest run time allowed: tighter tolerances of a method are skipped once a run took longer [s].
    ladder : LadderSettings or None
        The model-cost ladder to measure as well.
    """

    methods: tuple[str, ...]
    tolerances: tuple[float, ...]
    atol_ratio: float = BENCHMARK.key("atol_ratio").default
    repeats: int = BENCHMARK.key("repeats").default
    max_seconds: float = BENCHMARK.key("max_seconds").default
    ladder: LadderSettings | None = None


@dataclass(frozen=True, eq=False)
class BenchmarkScene:
    """A benchmark scene's cases and settings (run by :mod:`vibroimpact.kinds.benchmark.study`)."""

    cases: tuple[BenchmarkCase, ...]
    settings: BenchmarkSettings



@dataclasses.dataclass(frozen=True, eq=False)
class _Layout:
    """What every case of a scene shares: the scene's layout (its stops as given, with their own values) and the
    excitation amplitude."""

    layout: Layout
    amplitude: float

    @property
    def load(self) -> LoadSpec:
        """The layout's load."""
        return self.layout.load

    @property
    def specs(self) -> tuple[StopSpec, ...]:
        """The layout's stops."""
        return self.layout.stops

    def taking(self, field: str) -> list[int]:
        """The stops that take ``field`` (``restitution``, ``clearance``, ``bumper_frequency``) from the case."""
        return [k for k, spec in enumerate(self.specs) if getattr(spec, field) is None]

    def takes(self, field: str) -> bool:
        """Does some stop take ``field`` from the case?"""
        return bool(self.taking(field))


def parse_benchmark_scene(document: dict, text: str = "", source: str = "scene") -> Scene:
    """Validate a benchmark scene's document (a mapping with ``benchmark``) and build the :class:`Scene`; raise
    :class:`SceneError` listing all problems."""
    c, doc, name, description, report, scheduler = open_scene(document, BENCHMARK_TOP_KEYS, {"name", "system", "excitation", "benchmark"}, "benchmark")
    parsed, amplitude, _ = parse_layout(c, doc)
    layout = _Layout(parsed, amplitude) if parsed is not None and amplitude is not None else None
    spec = (BENCHMARK.read(c, doc["benchmark"], partial=True) if "benchmark" in doc else None) or {}
    duration, methods, tolerances = spec.get("duration"), spec.get("methods") or (), spec.get("tolerances")
    options: dict[str, Any] = {key: spec[key] for key in ("atol_ratio", "repeats", "max_seconds") if spec.get(key) is not None}
    if spec.get("ladder") is not None:
        options["ladder"] = _parse_ladder(c, spec["ladder"], layout)
    cases = []
    raw_cases = spec.get("cases") or []
    case_names: list[str] = []
    for i, raw in enumerate(raw_cases):
        case = _parse_case(c, f"benchmark.cases[{i}]", raw, case_names, layout, duration)
        if case is not None:
            cases.append(case)
    if c.problems:
        raise SceneError(c.problems, source)
    assert tolerances is not None and isinstance(name, str) and layout is not None
    settings = BenchmarkSettings(methods=methods, tolerances=tuple(float(t) for t in tolerances[::-1]), **options)
    return Scene(
        name=name,
        description=description,
        layout=layout.layout,
        amplitude=layout.amplitude,
        kind="benchmark",
        settings=BenchmarkScene(tuple(cases), settings),
        report=report,
        text=text,
        cluster_scheduler=scheduler,
    )


def _own_or_case(c: Checker, key: str, case: dict[str, Any], layout: _Layout, field: str, words: str) -> bool:
    """Whether the case must give ``field`` (some stop takes it); a case value no stop takes is refused."""
    needed = layout.takes(field)
    given = field in case or (field == "clearance" and "clearance_below_linear" in case)
    if not needed and given:
        c.fail(key, f"every stop of 'stops' gives its own {words}: remove the case's {field if field in case else 'clearance_below_linear'}")
    return needed


def _parse_case(c: Checker, key: str, raw: Any, names: list[str], layout: _Layout | None, duration: float | None) -> BenchmarkCase | None:
    """One entry of ``benchmark.cases``, checked; None where it is unusable (every problem recorded)."""
    read = CASE_ROW.at(key).read(c, raw, partial=True)
    if read is None:
        return None
    case = {name: raw[name] for name in CASE_ROW.names if name in raw}
    if "name" in case and read["name"] is not None:
        if not NAME.match(case["name"]):
            c.fail(f"{key}.name", f"expected a name of letters, digits, '_', '-', '.', got {case['name']!r}")
        elif case["name"] in names:
            c.fail(f"{key}.name", f"{case['name']!r} is used by another case: names must be unique")
        names.append(str(case["name"]))
    swept = case.get("swept_sine")
    if "swept_sine" in case and read["swept_sine"] is None:
        return None  # no mapping: said
    needs = {"restitution": True, "clearance": True, "bumper_frequency": swept is not None}
    if layout is not None:
        needs = {field: _own_or_case(c, key, case, layout, field, words) for field, words in (("restitution", "restitution"), ("clearance", "clearance"), ("bumper_frequency", "bumper frequency"))}
    f_start = f_stop = rate = sample_rate = None
    if swept is not None:
        sweep = CASE_SWEEP.at(f"{key}.swept_sine").read(c, swept, partial=True) or {}
        f_start, f_stop, rate, sample_rate = (sweep.get(name) for name in ("start", "stop", "rate", "sample_rate"))
        if "frequency" in case or "start" in case:
            c.fail(key, "a swept_sine case sets its own frequencies and starts at rest: remove frequency and start")
        if "bumper_frequency" not in case and needs["bumper_frequency"]:
            c.fail(f"{key}.bumper_frequency", "required by a swept_sine case (the compliant model): Omega_b / 2 pi [Hz] in (0, inf)")
        if layout is not None and layout.load.base_motion:
            c.fail(f"{key}.swept_sine", "a swept-sine case drives a force q sin(theta(t)): a swept base motion (excitation.base_motion) is not supported")
            return None
        if f_start is not None and f_stop is not None and f_start == f_stop:
            c.fail(f"{key}.swept_sine.stop", "must differ from start")
            f_start = None
        if f_start is not None and f_stop is not None:  # the benchmark's running fundamental uses 8-cycle windows
            rate, sample_rate = check_sweep_run(c, f"{key}.swept_sine", min(f_start, f_stop), max(f_start, f_stop), rate, sample_rate, 8)
        frequency = f_start
    else:
        if "frequency" not in case:
            c.fail(f"{key}.frequency", "required key is missing")
        if "start" not in case:
            c.fail(f"{key}.start", "required key is missing")
        frequency = read["frequency"]
    if needs["restitution"] and "restitution" not in case:
        c.fail(f"{key}.restitution", "required key is missing")
    restitution = read["restitution"] if "restitution" in case else math.nan
    bumper = read["bumper_frequency"] if "bumper_frequency" in case else math.nan
    if bumper is not None and math.isfinite(bumper) and restitution == 0.0:
        c.fail(f"{key}.restitution", "R = 0 needs an infinitely damped bumper: use R > 0 with bumper_frequency")
    if needs["clearance"] and ("clearance" in case) == ("clearance_below_linear" in case):
        c.fail(key, "give exactly one of 'clearance' [m] or 'clearance_below_linear' [m]")
        return None
    start = read["start"] if "start" in case else "rest"  # None: said; a stepped case without it is said above
    clearance = read["clearance"] if "clearance" in case else math.nan
    below = read["clearance_below_linear"] if "clearance_below_linear" in case else math.nan
    if None in (frequency, restitution, layout, duration, bumper, clearance, below) or start not in START_MODES:
        return None
    assert frequency is not None and restitution is not None and layout is not None and duration is not None and bumper is not None and clearance is not None and below is not None
    stops = _case_stops(c, key, layout, frequency, restitution, clearance, below, bumper)
    if stops is None:
        return None
    rigid, compliant = stops
    load = layout.load
    problem = layout.layout.problem_with(rigid, load.force(layout.amplitude, frequency))
    name = str(case["name"])
    if swept is not None:
        if None in (f_start, f_stop, rate, sample_rate):
            return None
        assert f_start is not None and f_stop is not None and rate is not None and sample_rate is not None
        sweep = SweptSine(layout.amplitude, f_start, f_stop, rate, weights=load.weights, static=load.static)
        return BenchmarkCase(name, problem, "rest", 0, compliant, sweep, sample_rate)
    periods = max(1, round(duration * frequency))
    if periods > MAX_BENCHMARK_PERIODS:
        c.fail(f"{key}.frequency", f"{periods:,} periods per run (duration x frequency) is too many: allowed at most {MAX_BENCHMARK_PERIODS:,}")
        return None
    return BenchmarkCase(name, problem, start, periods, compliant)


def _case_stops(c: Checker, key: str, layout: _Layout, frequency: float, restitution: float, clearance: float, below: float, bumper: float) -> tuple[tuple[Stop, ...], tuple[Stop, ...] | None] | None:
    """The rigid stops of a case and its bumpers (None where a stop has no bumper frequency: no compliant methods).

    ``below``: a clearance that far inside each stop's linear reach, |n . X| + n . x0 at ``frequency``, for the stops
    taking the case's clearance (NaN: ``clearance`` instead). Problems are recorded under ``key``."""
    specs = layout.specs
    try:
        if math.isfinite(below):
            reach = linear_reach(layout.layout, layout.amplitude, frequency)  # the linear steady state: no stop values
            chosen = []
            for k, spec in enumerate(specs):
                if spec.clearance is None:
                    if not math.isfinite(reach[k]):  # the linear response's refused band at an undamped resonance
                        c.fail(f"{key}.frequency", f"{frequency:g} Hz: the linear amplitude is unbounded there (an undamped natural frequency), so "
                               "clearance_below_linear has nothing to measure from: give clearance [m] or another frequency")
                        return None
                    if reach[k] - below < 0.0:
                        of = f" of stop {k}" if len(specs) > 1 else ""
                        c.fail(f"{key}.clearance_below_linear", f"{below:g} m exceeds the linear amplitude{of} {reach[k]:g} m")
                        return None
                    spec = dataclasses.replace(spec, clearance=float(reach[k] - below))
                chosen.append(spec)
            specs = tuple(chosen)
        rigid = build_stops(specs, False, restitution, clearance)
        layout.layout.with_stops(specs).check_room(clearance)  # the stops' room between each other
    except ValueError as error:
        c.fail(key, str(error))
        return None
    compliant = None
    values = [spec.values(restitution, clearance, bumper) for spec in specs]
    if all(math.isfinite(fb) for _, _, fb, _ in values):
        # R = 0 needs an infinitely damped bumper: no compliant model (the case's own R = 0 is reported by the caller)
        undamped = [k for k, (_, _, _, xi) in enumerate(values) if not math.isfinite(xi)]
        for k in undamped:
            if specs[k].restitution is not None:
                c.fail(f"stops[{k}].restitution", "R = 0 needs an infinitely damped bumper for the compliant methods: give the stop's bumper.loss_factor, or R > 0")
        if not undamped:
            compliant = build_stops(specs, True, restitution, clearance, bumper)
    return rigid, compliant


def _parse_ladder(c: Checker, value: Any, layout: _Layout | None) -> LadderSettings | None:
    """``ladder: {frequency, restitution, clearance, bumper_frequencies, rtol, repeats}``; restitution and clearance
    go to the stops that give none (required where one does)."""
    needed = {field for field in ("restitution", "clearance") if layout is None or layout.takes(field)}
    spec = LADDER.read(c, value, partial=True)
    if spec is None:
        return None
    for field in sorted(needed - set(value)):
        c.fail(f"benchmark.ladder.{field}", f"required key is missing: a stop gives no {field} ({LADDER.key(field).allowed()})")
    frequency, bumpers, rtol, repeats = spec["frequency"], spec["bumper_frequencies"], spec["rtol"], spec["repeats"]
    restitution = spec["restitution"] if "restitution" in value else math.nan
    clearance = spec["clearance"] if "clearance" in value else math.nan
    if layout is not None:
        for field in ("restitution", "clearance"):
            if field in value and field not in needed:
                c.fail(f"benchmark.ladder.{field}", f"every stop of 'stops' gives its own {field}: remove it")
    if any(v is None for v in (frequency, restitution, clearance, bumpers, rtol, repeats, layout)) or not needed <= set(value):
        return None
    assert frequency is not None and restitution is not None and clearance is not None and bumpers is not None and rtol is not None and repeats is not None and layout is not None
    try:
        rigid = build_stops(layout.specs, False, restitution, clearance)
        problem = layout.layout.problem_with(rigid, layout.load.force(layout.amplitude, frequency))
        compliant = tuple(build_stops(layout.specs, True, restitution, clearance, float(b)) for b in bumpers)
    except ValueError as error:
        c.fail("benchmark.ladder", str(error))
        return None
    return LadderSettings(frequency, restitution, clearance, tuple(float(b) for b in bumpers), rtol, repeats, problem, compliant)
