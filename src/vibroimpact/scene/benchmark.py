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

Method names are engines of :mod:`vibroimpact.engines.registry` (see :data:`~vibroimpact.scene.schema.BENCHMARK_METHODS`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from vibroimpact.engines.settings import STEPPED_TOLERANCES
from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop, loss_factor_from_restitution
from vibroimpact.model.excitation import HarmonicForce, SweptSine
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.scene.checker import Checker, SceneError
from vibroimpact.scene.schema import (
    BENCHMARK_METHODS,
    MAX_BENCHMARK_PERIODS,
    MAX_BUMPER_FREQUENCY,
    BenchmarkCase,
    BenchmarkScene,
    BenchmarkSettings,
    LadderSettings,
    Scene,
)
from vibroimpact.scene.sections import NAME, check_sweep_run, parse_header
from vibroimpact.simulation.settings import START_MODES

__all__ = ["BENCHMARK_TOP_KEYS", "parse_benchmark_scene"]

#: Top-level keys of a benchmark scene.
BENCHMARK_TOP_KEYS = {"name", "description", "system", "excitation", "benchmark", "report"}
_BENCHMARK_KEYS = {"duration", "methods", "tolerances", "atol_ratio", "repeats", "max_seconds", "cases", "ladder"}
_BENCHMARK_CASE_KEYS = {"name", "frequency", "restitution", "clearance", "clearance_below_linear", "start", "bumper_frequency", "swept_sine"}


def parse_benchmark_scene(document: dict, text: str = "", source: str = "scene") -> Scene:
    """Validate a benchmark scene's document (a mapping with ``benchmark``) and build the :class:`Scene`; raise
    :class:`SceneError` listing all problems."""
    c = Checker()
    doc = c.mapping("", document, BENCHMARK_TOP_KEYS, {"name", "system", "excitation", "benchmark"})
    name, description, system, amplitude, report = parse_header(c, doc)
    spec = c.mapping("benchmark", doc["benchmark"], _BENCHMARK_KEYS, {"duration", "methods", "tolerances", "cases"})
    duration = c.number("benchmark.duration", spec.get("duration"), 0.0, 1e5, low_inclusive=False) if "duration" in spec else None
    methods = c.choices("benchmark.methods", spec.get("methods"), BENCHMARK_METHODS) if "methods" in spec else ()
    tolerances = c.grid("benchmark.tolerances", spec.get("tolerances"), 1e-15, 1e-1, True) if "tolerances" in spec else None
    options: dict[str, Any] = {}
    if "atol_ratio" in spec:
        options["atol_ratio"] = c.number("benchmark.atol_ratio", spec["atol_ratio"], 1e-12, 1.0)
    if "repeats" in spec:
        options["repeats"] = c.integer("benchmark.repeats", spec["repeats"], 1, 100)
    if "max_seconds" in spec:
        options["max_seconds"] = c.number("benchmark.max_seconds", spec["max_seconds"], 0.0, 1e5, low_inclusive=False)
    if "ladder" in spec:
        options["ladder"] = _parse_ladder(c, spec["ladder"])
    cases = []
    raw_cases = spec.get("cases", [])
    if not isinstance(raw_cases, list) or not raw_cases:
        c.fail("benchmark.cases", "expected a non-empty list of cases {name, frequency, restitution, clearance | clearance_below_linear, start[, bumper_frequency] | swept_sine}")
        raw_cases = []
    names: list[str] = []
    for i, raw in enumerate(raw_cases):
        key = f"benchmark.cases[{i}]"
        case = c.mapping(key, raw, _BENCHMARK_CASE_KEYS, {"name", "restitution"})
        if "name" in case:
            if not (isinstance(case["name"], str) and NAME.match(case["name"])):
                c.fail(f"{key}.name", f"expected a name of letters, digits, '_', '-', '.', got {case['name']!r}")
            elif case["name"] in names:
                c.fail(f"{key}.name", f"{case['name']!r} is used by another case: names must be unique")
            names.append(str(case["name"]))
        swept = case.get("swept_sine")
        if "swept_sine" in case and not isinstance(swept, dict):
            c.fail(f"{key}.swept_sine", f"expected a mapping {{start, stop, rate, sample_rate}}, got {swept!r}")
            continue
        if swept is not None:
            spec_s = c.mapping(f"{key}.swept_sine", swept, {"start", "stop", "rate", "sample_rate"}, {"start", "stop", "rate"})
            f_start = c.number(f"{key}.swept_sine.start", spec_s.get("start"), 0.0, math.inf, low_inclusive=False) if "start" in spec_s else None
            f_stop = c.number(f"{key}.swept_sine.stop", spec_s.get("stop"), 0.0, math.inf, low_inclusive=False) if "stop" in spec_s else None
            rate = c.number(f"{key}.swept_sine.rate", spec_s.get("rate"), 0.0, math.inf, low_inclusive=False) if "rate" in spec_s else None
            sample_rate = c.number(f"{key}.swept_sine.sample_rate", spec_s.get("sample_rate", 2000.0), 0.0, 1e7, low_inclusive=False)
            if "frequency" in case or "start" in case:
                c.fail(key, "a swept_sine case sets its own frequencies and starts at rest: remove frequency and start")
            if "bumper_frequency" not in case:
                c.fail(f"{key}.bumper_frequency", "required by a swept_sine case (the compliant model): Omega_b / 2 pi [Hz] in (0, inf)")
            if f_start is not None and f_stop is not None and f_start == f_stop:
                c.fail(f"{key}.swept_sine.stop", "must differ from start")
                f_start = None
            if f_start is not None and f_stop is not None:  # the benchmark's running X1 fundamental uses 8-cycle windows
                rate, sample_rate = check_sweep_run(c, f"{key}.swept_sine", min(f_start, f_stop), max(f_start, f_stop), rate, sample_rate, 8)
            frequency = f_start
        else:
            if "frequency" not in case:
                c.fail(f"{key}.frequency", "required key is missing")
            if "start" not in case:
                c.fail(f"{key}.start", "required key is missing")
            frequency = c.number(f"{key}.frequency", case.get("frequency"), 0.0, math.inf, low_inclusive=False) if "frequency" in case else None
        restitution = c.number(f"{key}.restitution", case.get("restitution"), 0.0, 1.0) if "restitution" in case else None
        bumper = c.number(f"{key}.bumper_frequency", case["bumper_frequency"], 0.0, MAX_BUMPER_FREQUENCY, low_inclusive=False) if "bumper_frequency" in case else math.nan
        if bumper is not None and math.isfinite(bumper) and restitution == 0.0:
            c.fail(f"{key}.restitution", "R = 0 needs an infinitely damped bumper: use R > 0 with bumper_frequency")
        if ("clearance" in case) == ("clearance_below_linear" in case):
            c.fail(key, "give exactly one of 'clearance' [m] or 'clearance_below_linear' [m]")
            continue
        start = case.get("start", "rest")
        if start not in START_MODES:
            c.fail(f"{key}.start", f"{start!r} is not allowed: use rest, linear or pgf")
        if None in (frequency, restitution, system, amplitude, duration, bumper) or start not in START_MODES:
            continue
        assert system is not None and frequency is not None and amplitude is not None and duration is not None and restitution is not None and bumper is not None
        if "clearance" in case:
            clearance = c.number(f"{key}.clearance", case["clearance"], 0.0, math.inf)
        else:
            below = c.number(f"{key}.clearance_below_linear", case["clearance_below_linear"], -1.0, 1.0)
            linear = amplitude * abs(complex(system.receptances(2.0 * math.pi * frequency).h12))
            clearance = None if below is None else linear - below
            if clearance is not None and clearance < 0:
                c.fail(f"{key}.clearance_below_linear", f"{below:g} m exceeds the linear amplitude {linear:g} m")
                clearance = None
        if clearance is None:
            continue
        problem = ImpactProblem(system, RigidStop(clearance, restitution), HarmonicForce(amplitude, frequency))
        # the compliant model's bumper, with the loss factor that gives R (R = 0 with a bumper failed above)
        compliant = KelvinVoigtBumper(clearance, bumper, loss_factor_from_restitution(restitution)) if math.isfinite(bumper) and restitution > 0.0 else None
        if swept is not None:
            if None in (f_start, f_stop, rate, sample_rate):
                continue
            assert f_start is not None and f_stop is not None and rate is not None and sample_rate is not None
            sweep = SweptSine(amplitude, f_start, f_stop, rate)
            cases.append(BenchmarkCase(str(case["name"]), problem, "rest", 0, compliant, sweep, sample_rate))
        else:
            periods = max(1, round(duration * frequency))
            if periods > MAX_BENCHMARK_PERIODS:
                c.fail(f"{key}.frequency", f"{periods:,} periods per run (duration x frequency) is too many: allowed at most {MAX_BENCHMARK_PERIODS:,}")
                continue
            cases.append(BenchmarkCase(str(case["name"]), problem, start, periods, compliant))
    if c.problems:
        raise SceneError(c.problems, source)
    assert tolerances is not None and isinstance(name, str) and system is not None and amplitude is not None
    settings = BenchmarkSettings(methods=methods, tolerances=tuple(float(t) for t in tolerances[::-1]), **options)
    return Scene(
        name=name,
        description=description,
        system=system,
        amplitude=amplitude,
        frequency=np.array(sorted({case.problem.frequency for case in cases})),
        restitution=np.array(sorted({case.problem.restitution for case in cases})),
        clearance=np.array(sorted({case.problem.clearance for case in cases})),
        swept=(),
        solutions=(),
        quantities=(),
        benchmark=BenchmarkScene(tuple(cases), settings),
        report=report,
        text=text,
    )


def _parse_ladder(c: Checker, value: Any) -> LadderSettings | None:
    """``ladder: {frequency, restitution, clearance, bumper_frequencies, rtol, repeats}``."""
    spec = c.mapping("benchmark.ladder", value, {"frequency", "restitution", "clearance", "bumper_frequencies", "rtol", "repeats"}, {"frequency", "restitution", "clearance", "bumper_frequencies"})
    frequency = c.number("benchmark.ladder.frequency", spec["frequency"], 0.0, math.inf, low_inclusive=False) if "frequency" in spec else None
    restitution = c.number("benchmark.ladder.restitution", spec["restitution"], 0.0, 1.0, low_inclusive=False) if "restitution" in spec else None
    clearance = c.number("benchmark.ladder.clearance", spec["clearance"], 0.0, math.inf) if "clearance" in spec else None
    bumpers = c.grid("benchmark.ladder.bumper_frequencies", spec["bumper_frequencies"], 0.0, MAX_BUMPER_FREQUENCY, False) if "bumper_frequencies" in spec else None
    rtol = c.number("benchmark.ladder.rtol", spec.get("rtol", STEPPED_TOLERANCES[0]), 1e-14, 1e-2)
    repeats = c.integer("benchmark.ladder.repeats", spec.get("repeats", 3), 1, 100)
    if any(v is None for v in (frequency, restitution, clearance, bumpers, rtol, repeats)):
        return None
    assert frequency is not None and restitution is not None and clearance is not None and bumpers is not None and rtol is not None and repeats is not None
    return LadderSettings(frequency, restitution, clearance, tuple(float(b) for b in bumpers), rtol, repeats)
