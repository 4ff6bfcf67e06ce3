"""YAML scenes: what system, stop and excitation to study, over which grids, by which solutions.

A scene is read with ``yaml.safe_load`` and checked completely before any work starts: every unknown key, wrong
type or out-of-range value is reported (all of them at once, each naming its key and the allowed range) in one
:class:`SceneError`. Example (all values SI, frequencies in Hz)::

    name: restitution
    system: {m1: 1.0, m2: 0.1, k1: 25000, k2: 4300, b1: 0.8, b2: 0.08}
    excitation: {amplitude: 10.0}
    stop: {clearance: 0.003}
    sweep:
      restitution: [0.0, 0.2, 0.4, 0.6, 0.8]
      frequency: {start: 15.0, stop: 45.0, step: 0.005}
    solutions: [linear, pgf, pgf_paper]
"""

from __future__ import annotations

import importlib.resources
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

import numpy as np
import yaml

from vibroimpact.benchmarks.accuracy import BENCHMARK_METHODS, BenchmarkCase, BenchmarkSettings, LadderSettings
from vibroimpact.engines.base import ImpactProblem
from vibroimpact.engines.settings import STEPPED_TOLERANCES, SWEPT_TOLERANCES, EngineSettings
from vibroimpact.model.excitation import SweptSine
from vibroimpact.model.modal import underdamped_mode_count
from vibroimpact.analysis.pgf import AdmissibilitySettings
from vibroimpact.simulation.settings import SteadySettings
from vibroimpact.model.system import TwoDofSystem

__all__ = ["Scene", "SceneError", "SweptSineSettings", "load_scene", "parse_scene", "SOLUTIONS", "ENGINE_SOLUTIONS", "QUANTITIES", "SWEEPABLE", "GRID_DIMS"]

#: Solutions a scene can ask for.
SOLUTIONS = ("linear", "pgf", "pgf_paper", "momentary", "exact", "compliant")
#: Solutions computed by time integration (they need the ``simulation`` section's settings).
ENGINE_SOLUTIONS = ("momentary", "exact", "compliant")
#: Directions of a swept-sine test.
SWEEP_DIRECTIONS = ("up", "down")
#: How a simulation starts at each frequency.
SIMULATION_STARTS = ("linear", "pgf", "rest", "sweep_up", "sweep_down")
#: Quantities a scene can ask for (``regime`` is always written: it says what the others mean).
QUANTITIES = (
    "x1_amplitude",
    "x2_amplitude",
    "force_amplitude",
    "suspension_force_amplitude",
    "impulse",
    "phase",
    "regime",
    "stable",
    "floquet_modulus",
    "one_impact_x1_amplitude",
    "one_impact_x2_amplitude",
    "one_impact_force_amplitude",
    "one_impact_impulse",
    "impacts_per_period",
    "converged",
    "x1_rms",
    "x2_rms",
    "peak_acceleration",
    "peak_contact_force",
    "wall_time",
)
#: Parameters that can be swept, with their units and allowed ranges (low, high, low inclusive).
SWEEPABLE = {
    "frequency": ("Hz", 0.0, math.inf, False),
    "restitution": ("1", 0.0, 1.0, True),
    "clearance": ("m", 0.0, math.inf, True),
    "bumper_frequency": ("Hz", 0.0, 1e6, False),
    "bumper_loss_factor": ("1", 0.0, 1e3, True),
}
#: Where an unswept parameter is given instead (``frequency`` is always swept).
_FIXED_PLACE = {"restitution": ("stop", "restitution"), "clearance": ("stop", "clearance"), "bumper_frequency": ("bumper", "frequency"), "bumper_loss_factor": ("bumper", "loss_factor")}
#: Dimension order of a study's grid (unswept ones are squeezed out of the dataset).
GRID_DIMS = ("restitution", "clearance", "bumper_frequency", "sweep", "frequency")
_T = TypeVar("_T")
MAX_GRID_POINTS = 1_000_000
#: Largest study: restitution x clearance x frequency points (each solution holds a few arrays of this size).
MAX_STUDY_POINTS = 10_000_000
#: Most output samples of one swept-sine run (7 floats each, plus the estimators' temporaries: ~1 GB).
MAX_SWEEP_SAMPLES = 10_000_000
#: Stiffest bumper accepted [Hz] (tested to 100 kHz; contact then lasts microseconds).
MAX_BUMPER_FREQUENCY = 1e6
#: Most periods of one benchmark run.
MAX_BENCHMARK_PERIODS = 1_000_000


class SceneError(ValueError):
    """A scene is invalid. ``problems`` lists every problem found, each naming its key."""

    def __init__(self, problems: list[str], source: str = "scene") -> None:
        self.problems = list(problems)
        super().__init__(f"invalid {source}:\n" + "\n".join(f"  - {p}" for p in self.problems))


@dataclass(frozen=True, eq=False)
class SimulationSettings:
    """How the time-domain solutions (``momentary``, ``exact``) are run.

    Attributes
    ----------
    frequency : ndarray
        Frequencies simulated [Hz] (a coarser grid than the analytic one, merged into the dataset's axis).
    start : str
        One of :data:`SIMULATION_STARTS`.
    engine : EngineSettings
        Integrator tolerances and method.
    steady : SteadySettings
        Convergence and measurement of the steady state.
    """

    frequency: np.ndarray
    start: str = "pgf"
    engine: EngineSettings = field(default_factory=EngineSettings)
    steady: SteadySettings = field(default_factory=SteadySettings)


@dataclass(frozen=True)
class SweptSineSettings:
    """A swept-sine test (the paper's Simulink run, section 5) instead of stepped steady states.

    Attributes
    ----------
    start_frequency, stop_frequency : float
        Ends of the sweep [Hz] (a sweep down runs from ``stop_frequency`` to ``start_frequency``).
    rate : float
        |alpha| [Hz s-1].
    directions : tuple of str
        Some of ``up``, ``down``.
    sample_rate : float
        Output samples per second of the simulated signals [Hz].
    window_cycles : int
        Cycles of the excitation in the running estimators' window.
    initial_state : str
        ``linear``: each run starts on the linear steady state at its first frequency (where it fits inside the
        clearance; else at rest), so no start-up transient shows; ``rest``: at rest, like a bench test.
    """

    start_frequency: float
    stop_frequency: float
    rate: float
    directions: tuple[str, ...] = SWEEP_DIRECTIONS
    sample_rate: float = 1000.0
    window_cycles: int = 8
    initial_state: str = "linear"

    def sweep(self, amplitude: float, direction: str) -> SweptSine:
        """The excitation of one direction."""
        low, high = self.start_frequency, self.stop_frequency
        return SweptSine(amplitude, low, high, self.rate) if direction == "up" else SweptSine(amplitude, high, low, self.rate)


@dataclass(frozen=True, eq=False)
class BenchmarkScene:
    """A benchmark scene's cases and settings (see :mod:`vibroimpact.benchmark`)."""

    cases: tuple[BenchmarkCase, ...]
    settings: BenchmarkSettings


@dataclass(frozen=True, eq=False)
class Scene:
    """A validated scene.

    Attributes
    ----------
    name : str
        Scene name; output goes to ``<out>/<name>.nc``.
    description : str
        Free text.
    system : TwoDofSystem
        The linear system.
    amplitude : float
        Excitation force amplitude q [N].
    frequency : ndarray
        Excitation frequencies [Hz], increasing.
    restitution : ndarray
        Restitution ratios R [-]; one value unless swept.
    clearance : ndarray
        Clearances Delta [m]; one value unless swept.
    swept : tuple of str
        Parameters that are dimensions of the output, in dimension order (``frequency`` last).
    solutions : tuple of str
        Solutions to compute.
    quantities : tuple of str
        Quantities to write.
    admissibility : AdmissibilitySettings
        Settings of the X2(t) <= Delta check.
    simulation : SimulationSettings or None
        Settings of the time-domain solutions, when the scene asks for any.
    bumper_frequency : ndarray or None
        Omega_b / 2 pi of the compliant bumper [Hz] (one value unless swept); None without a bumper.
    bumper_loss_factor : ndarray or None
        xi_b [-]: one value, or one per ``restitution`` when ``bumper_loss_factor`` is swept (``restitution`` then
        holds R(xi_b), eq. 26 corrected); None: each restitution's own loss factor (the exact inverse of R(xi_b)).
    swept_sine : SweptSineSettings or None
        When given, the time-domain solutions are swept-sine tests, not stepped steady states.
    report : bool
        Whether ``run-study`` writes the comparison report.
    text : str
        The YAML source, stored in the output's attributes.
    """

    name: str
    description: str
    system: TwoDofSystem
    amplitude: float
    frequency: np.ndarray
    restitution: np.ndarray
    clearance: np.ndarray
    swept: tuple[str, ...]
    solutions: tuple[str, ...]
    quantities: tuple[str, ...]
    admissibility: AdmissibilitySettings = field(default_factory=AdmissibilitySettings)
    simulation: SimulationSettings | None = None
    benchmark: BenchmarkScene | None = None
    bumper_frequency: np.ndarray | None = None
    bumper_loss_factor: np.ndarray | None = None
    swept_sine: SweptSineSettings | None = None
    report: bool = True
    text: str = ""

    def loss_factors(self) -> np.ndarray:
        """The bumper's xi_b for each restitution of the grid [-] (NaN where none gives it, R = 0)."""
        from vibroimpact.model.contact import loss_factor_from_restitution

        if self.bumper_loss_factor is not None:
            return np.broadcast_to(self.bumper_loss_factor, self.restitution.shape).astype(float)
        return np.array([loss_factor_from_restitution(r) if r > 0.0 else np.nan for r in self.restitution])

    @property
    def kind(self) -> str:
        """What kind of study the scene is: ``benchmark``, ``swept`` (swept-sine tests) or ``stepped`` (steady states).

        The one place that decides it; everything else dispatches on this name.
        """
        if self.benchmark is not None:
            return "benchmark"
        return "stepped" if self.swept_sine is None else "swept"

    @property
    def sweep_directions(self) -> tuple[str, ...]:
        """Directions of the swept-sine test; ``()`` for stepped steady states."""
        return () if self.swept_sine is None else self.swept_sine.directions

    @property
    def all_frequencies(self) -> np.ndarray:
        """The dataset's frequency axis: the analytic grid merged with the simulation grid [Hz]."""
        if self.simulation is None:
            return self.frequency
        return np.union1d(self.frequency, self.simulation.frequency)


# ----------------------------------------------------------------------------- checking helpers
def _interval(low: float, high: float, low_inclusive: bool = True, high_inclusive: bool = True) -> str:
    """Interval in mathematical notation; an infinite end is always open."""
    opening = "[" if low_inclusive and math.isfinite(low) else "("
    closing = "]" if high_inclusive and math.isfinite(high) else ")"
    return f"{opening}{low:g}, {high:g}{closing}"


class _UniqueKeyLoader(yaml.SafeLoader):
    """``yaml.SafeLoader`` that refuses a key repeated in one mapping (PyYAML silently keeps the last one) and reads
    YAML 1.2 numbers such as ``3e-3`` as floats (YAML 1.1, PyYAML's default, reads them as strings)."""

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        seen: set[Any] = set()
        for key_node, _value_node in node.value:
            key = self.construct_object(key_node, deep=deep)
            if key in seen:
                raise yaml.constructor.ConstructorError(None, None, f"key {key!r} is repeated", key_node.start_mark)
            seen.add(key)
        return super().construct_mapping(node, deep=deep)


_UniqueKeyLoader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"),
    list("-+0123456789"),
)


def read_yaml(text: str) -> Any:
    """Parse YAML safely (no Python objects), rejecting repeated keys."""
    return yaml.load(text, Loader=_UniqueKeyLoader)  # noqa: S506 - a SafeLoader subclass
class _Checker:
    """Collects problems while walking a parsed YAML document."""

    def __init__(self) -> None:
        self.problems: list[str] = []

    def fail(self, key: str, message: str) -> None:
        self.problems.append(f"{key}: {message}")

    def mapping(self, key: str, value: Any, allowed: set[str], required: frozenset[str] | set[str] = frozenset()) -> dict:
        if not isinstance(value, dict):
            self.fail(key, f"expected a mapping with keys {sorted(allowed)}, got {type(value).__name__}")
            return {}
        for unknown in sorted(set(map(str, value)) - allowed):
            self.fail(f"{key}.{unknown}" if key else unknown, f"unknown key (allowed: {', '.join(sorted(allowed))})")
        for missing in sorted(required - set(value)):
            self.fail(f"{key}.{missing}" if key else missing, "required key is missing")
        return value

    def number(self, key: str, value: Any, low: float, high: float, low_inclusive: bool = True, high_inclusive: bool = True) -> float | None:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self.fail(key, f"expected a number, got {value!r} ({type(value).__name__})")
            return None
        number = float(value)
        ok_low = number >= low if low_inclusive else number > low
        ok_high = number <= high if high_inclusive else number < high
        if not (math.isfinite(number) and ok_low and ok_high):
            self.fail(key, f"{value!r} is out of range: allowed {_interval(low, high, low_inclusive, high_inclusive)}")
            return None
        return number

    def integer(self, key: str, value: Any, low: int, high: int) -> int | None:
        if isinstance(value, bool) or not isinstance(value, int):
            self.fail(key, f"expected an integer, got {value!r} ({type(value).__name__})")
            return None
        if not low <= value <= high:
            self.fail(key, f"{value!r} is out of range: allowed [{low}, {high}]")
            return None
        return value

    def choices(self, key: str, value: Any, allowed: tuple[str, ...]) -> tuple[str, ...]:
        if not isinstance(value, list) or not value:
            self.fail(key, f"expected a non-empty list of names from {list(allowed)}, got {value!r}")
            return ()
        chosen: list[str] = []
        for i, item in enumerate(value):
            if item not in allowed:
                self.fail(f"{key}[{i}]", f"unknown name {item!r} (allowed: {', '.join(allowed)})")
            elif item in chosen:
                self.fail(f"{key}[{i}]", f"{item!r} is listed twice")
            else:
                chosen.append(item)
        return tuple(chosen)

    def grid(self, key: str, value: Any, low: float, high: float, low_inclusive: bool) -> np.ndarray | None:
        """A list of values or {start, stop, step} / {start, stop, num}; returns sorted unique values."""

        def check(k: str, v: Any) -> float | None:
            return self.number(k, v, low, high, low_inclusive)

        if isinstance(value, list):
            if not value:
                self.fail(key, "empty grid: give at least one value")
                return None
            numbers = [check(f"{key}[{i}]", v) for i, v in enumerate(value)]
            if any(n is None for n in numbers):
                return None
            values = np.array(numbers, dtype=float)
            if np.unique(values).size != values.size:
                self.fail(key, "repeated values in the grid")
                return None
            return np.sort(values)
        if isinstance(value, dict):
            spec = self.mapping(key, value, {"start", "stop", "step", "num"}, {"start", "stop"})
            if "step" in spec and "num" in spec or ("step" not in spec and "num" not in spec):
                self.fail(key, "give exactly one of 'step' or 'num' with 'start' and 'stop'")
                return None
            if "start" not in spec or "stop" not in spec:
                return None  # already reported as missing
            start = check(f"{key}.start", spec["start"])
            stop = check(f"{key}.stop", spec["stop"])
            if start is None or stop is None:
                return None
            if stop <= start:
                self.fail(f"{key}.stop", f"{stop:g} must be greater than start = {start:g}")
                return None
            if "step" in spec:
                step = self.number(f"{key}.step", spec["step"], 0.0, stop - start, low_inclusive=False)
                if step is None:
                    return None
                count = math.floor((stop - start) / step * (1.0 + 1e-12)) + 1
            else:
                num = self.integer(f"{key}.num", spec["num"], 2, MAX_GRID_POINTS)
                if num is None:
                    return None
                count, step = num, (stop - start) / (num - 1)
            if count > MAX_GRID_POINTS:
                self.fail(key, f"{count} points is too many: allowed at most {MAX_GRID_POINTS}")
                return None
            # integer multiples of the step, rounded to 12 significant digits of the grid's scale, keep values exact
            # decimals where the step is one (0.005 Hz) without collapsing tiny clearances
            decimals = 12 - math.floor(math.log10(max(abs(start), abs(stop))))
            values = np.round(start + step * np.arange(count), decimals)
            if np.unique(values).size != values.size:
                self.fail(key, f"step {step:g} is below the grid's resolution")
                return None
            return values
        self.fail(key, f"expected a list of values or a mapping {{start, stop, step|num}}, got {type(value).__name__}")
        return None


# ----------------------------------------------------------------------------- the parser
_TOP_KEYS = {"name", "description", "system", "excitation", "stop", "bumper", "sweep", "swept_sine", "solutions", "quantities", "settings", "simulation", "report"}
#: Simulation keys that only stepped steady states use.
_STEADY_ONLY_KEYS = {"frequency", "start", "tolerance", "max_periods", "measure_periods", "irregular_measure_periods"}
_BENCHMARK_KEYS = {"duration", "methods", "tolerances", "atol_ratio", "repeats", "max_seconds", "cases", "ladder"}
_BENCHMARK_CASE_KEYS = {"name", "frequency", "restitution", "clearance", "clearance_below_linear", "start", "bumper_frequency", "swept_sine"}
_SIMULATION_KEYS = {"frequency", "start", "method", "rtol", "atol", "max_step", "tolerance", "max_periods", "measure_periods", "irregular_measure_periods"}
_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")


def parse_scene(document: Any, text: str = "", source: str = "scene") -> Scene:
    """Validate a parsed YAML document and build the :class:`Scene`; raise :class:`SceneError` listing all problems."""
    c = _Checker()
    if not isinstance(document, dict):
        what = "an empty document" if document is None else f"a {type(document).__name__}"
        raise SceneError([f"scene: expected a mapping with keys {sorted(_TOP_KEYS)}, got {what}"], source)
    if "benchmark" in document:
        return _parse_benchmark_scene(c, document, text, source)
    doc = c.mapping("", document, _TOP_KEYS, {"name", "system", "excitation", "sweep", "solutions"})

    name, description, system, amplitude, report = _parse_header(c, doc)

    sweep = c.mapping("sweep", doc.get("sweep", {}), set(SWEEPABLE), {"frequency"}) if "sweep" in doc else {}
    fixed = {
        "stop": c.mapping("stop", doc["stop"], {"clearance", "restitution"}) if "stop" in doc else {},
        "bumper": c.mapping("bumper", doc["bumper"], {"frequency", "loss_factor"}) if "bumper" in doc else {},
    }
    solutions = c.choices("solutions", doc["solutions"], SOLUTIONS) if "solutions" in doc else ()
    derived_restitution = "bumper_loss_factor" in sweep
    grids: dict[str, np.ndarray | None] = {}
    for key, (_units, low, high, low_inclusive) in SWEEPABLE.items():
        section, field_name = _FIXED_PLACE.get(key, ("", ""))
        place = f"{section}.{field_name}"
        given_fixed = field_name in fixed.get(section, {})
        if key in sweep:
            if given_fixed:
                c.fail(place, f"also swept in sweep.{key}: give it in one place only")
            grids[key] = c.grid(f"sweep.{key}", sweep[key], low, high, low_inclusive)
        elif given_fixed:
            value = c.number(place, fixed[section][field_name], low, high, low_inclusive)
            grids[key] = None if value is None else np.array([value])
        elif key == "restitution" and derived_restitution:
            continue  # R(xi_b) of the swept loss factors
        elif key == "restitution" or key == "clearance":
            c.fail(place, f"required unless swept (sweep.{key}); allowed range {_interval(low, high, low_inclusive)}")
    if derived_restitution and "restitution" in grids:
        c.fail("sweep.bumper_loss_factor", "sweeping the bumper's loss factor sets the restitution R(xi_b): do not also give restitution")
    if derived_restitution and (xi := grids.get("bumper_loss_factor")) is not None:
        from vibroimpact.model.contact import restitution_from_loss_factor

        grids["restitution"] = np.array([restitution_from_loss_factor(x) for x in xi])
    needs_bumper = "compliant" in solutions or "swept_sine" in doc
    if needs_bumper and "bumper_frequency" not in sweep and "bumper" not in doc:
        c.fail("bumper", "required by the compliant solution and swept-sine tests: {frequency: Omega_b / 2 pi [Hz], loss_factor: xi_b (optional)}")
    elif "bumper" in doc and "bumper_frequency" not in sweep and "frequency" not in fixed["bumper"]:
        c.fail("bumper.frequency", "required unless swept (sweep.bumper_frequency): Omega_b / 2 pi [Hz] in (0, inf)")
    if "compliant" in solutions and "bumper_loss_factor" not in grids and (r := grids.get("restitution")) is not None and np.any(r == 0.0):
        c.fail("stop.restitution", "R = 0 needs an infinitely damped bumper for the compliant solution: give bumper.loss_factor, or sweep R > 0")

    sizes = [g.size for g in grids.values() if g is not None]
    if len(sizes) >= 3 and math.prod(sizes) > MAX_STUDY_POINTS:
        c.fail("sweep", f"{math.prod(sizes):,} points (product of the swept grids) is too many: allowed at most {MAX_STUDY_POINTS:,}")
    if "pgf_paper" in solutions and system is not None and (modes := underdamped_mode_count(system)) != 2:
        c.fail("solutions", f"pgf_paper needs two underdamped modes (the paper's eq. 10 fit); this system has {modes}")
    quantities = c.choices("quantities", doc["quantities"], QUANTITIES) if "quantities" in doc else QUANTITIES
    if "regime" not in quantities:
        quantities = (*quantities, "regime")

    admissibility = AdmissibilitySettings()
    if "settings" in doc:
        settings = c.mapping("settings", doc["settings"], {"admissibility"})
        if "admissibility" in settings:
            adm = c.mapping("settings.admissibility", settings["admissibility"], {"samples_per_period", "relative_tolerance"})
            kwargs: dict[str, Any] = {}
            if "samples_per_period" in adm:
                kwargs["samples_per_period"] = c.integer("settings.admissibility.samples_per_period", adm["samples_per_period"], 16, 1_000_000)
            if "relative_tolerance" in adm:
                kwargs["relative_tolerance"] = c.number("settings.admissibility.relative_tolerance", adm["relative_tolerance"], 0.0, 1e-2)
            if None not in kwargs.values():
                admissibility = AdmissibilitySettings(**kwargs)

    simulation = None
    engines = [name for name in solutions if name in ENGINE_SOLUTIONS]
    swept_sine = _parse_swept_sine(c, doc["swept_sine"], engines, grids.get("frequency")) if "swept_sine" in doc else None
    if "simulation" in doc:
        if not engines:
            c.fail("simulation", f"given, but no time-domain solution ({', '.join(ENGINE_SOLUTIONS)}) is asked for")
        elif (main_grid := grids.get("frequency")) is not None:
            if "swept_sine" in doc:
                for key in sorted(set(doc["simulation"]) & _STEADY_ONLY_KEYS if isinstance(doc["simulation"], dict) else ()):
                    c.fail(f"simulation.{key}", "not used by a swept-sine test (it sets stepped steady states): remove it")
            simulation = _parse_simulation(c, doc["simulation"], main_grid, "swept_sine" in doc)
    elif engines and (main_grid := grids.get("frequency")) is not None:
        simulation = _parse_simulation(c, {}, main_grid, "swept_sine" in doc)

    if c.problems:
        raise SceneError(c.problems, source)
    frequency, restitution, clearance = grids["frequency"], grids["restitution"], grids["clearance"]
    # guaranteed when no problem was recorded
    assert system is not None and amplitude is not None and isinstance(name, str)
    assert frequency is not None and restitution is not None and clearance is not None
    order = ("bumper_loss_factor", "restitution", "clearance", "bumper_frequency")
    swept = tuple(k for k in order if k in sweep) + ("frequency",)
    return Scene(
        name=name,
        description=description,
        system=system,
        amplitude=amplitude,
        frequency=frequency,
        restitution=restitution,
        clearance=clearance,
        swept=swept,
        solutions=solutions,
        quantities=quantities,
        admissibility=admissibility,
        simulation=simulation,
        bumper_frequency=grids.get("bumper_frequency"),
        bumper_loss_factor=grids.get("bumper_loss_factor"),
        swept_sine=swept_sine,
        report=report,
        text=text,
    )


def _parse_swept_sine(c: _Checker, value: Any, engines: list[str], grid: np.ndarray | None) -> SweptSineSettings | None:
    """``swept_sine: {start, stop, rate, directions, sample_rate, window_cycles, initial_state}`` (frequencies [Hz],
    rate [Hz s-1]); every problem is reported."""
    spec = c.mapping("swept_sine", value, {"start", "stop", "rate", "directions", "sample_rate", "window_cycles", "initial_state"}, {"start", "stop", "rate"})
    if engines != ["compliant"]:
        c.fail("solutions", f"a swept-sine test runs the compliant solution only (and needs it): got {engines or 'none'}")
    start = c.number("swept_sine.start", spec["start"], 0.0, math.inf, low_inclusive=False) if "start" in spec else None
    stop = c.number("swept_sine.stop", spec["stop"], 0.0, math.inf, low_inclusive=False) if "stop" in spec else None
    rate = c.number("swept_sine.rate", spec["rate"], 0.0, math.inf, low_inclusive=False) if "rate" in spec else None
    directions = c.choices("swept_sine.directions", spec["directions"], SWEEP_DIRECTIONS) if "directions" in spec else SWEEP_DIRECTIONS
    sample_rate = c.number("swept_sine.sample_rate", spec.get("sample_rate", 1000.0), 0.0, 1e7, low_inclusive=False)
    cycles = c.integer("swept_sine.window_cycles", spec.get("window_cycles", 8), 1, 10_000)
    initial = spec.get("initial_state", "linear")
    if initial not in ("linear", "rest"):
        c.fail("swept_sine.initial_state", f"{initial!r} is not allowed: use linear or rest")
    if start is None or stop is None:
        return None
    if stop <= start:
        c.fail("swept_sine.stop", f"{stop:g} must be greater than start = {start:g} (directions say which way it runs)")
        return None
    rate, sample_rate = _check_sweep_run(c, "swept_sine", start, stop, rate, sample_rate, cycles, " or swept_sine.window_cycles")
    if grid is not None and not np.any((grid >= start) & (grid <= stop)):
        c.fail("sweep.frequency", f"no frequency of the grid lies in the swept band [{start:g}, {stop:g}] Hz, where the running estimates are reported")
    if rate is None or sample_rate is None or cycles is None or not directions or initial not in ("linear", "rest"):
        return None
    return SweptSineSettings(start, stop, rate, directions, sample_rate, cycles, initial)


def _check_sweep_run(c: _Checker, key: str, low: float, high: float, rate: float | None, sample_rate: float | None, cycles: int | None, window_hint: str = "") -> tuple[float | None, float | None]:
    """Limits of one swept-sine run between ``low`` and ``high`` [Hz], shared by scenes and benchmark cases: 20 output
    samples per cycle at the top, at most :data:`MAX_SWEEP_SAMPLES` samples, and room for two estimator windows of
    ``cycles`` cycles. Returns (rate, sample_rate), each None where it failed."""
    if sample_rate is not None and sample_rate < 20.0 * high:
        c.fail(f"{key}.sample_rate", f"{sample_rate:g} Hz is too coarse for {high:g} Hz: allowed [{20.0 * high:g}, 1e+07] (20 samples per cycle)")
        sample_rate = None
    if rate is not None:
        duration = (high - low) / rate
        if sample_rate is not None and duration * sample_rate > MAX_SWEEP_SAMPLES:
            c.fail(f"{key}.rate", f"{duration:g} s at {sample_rate:g} samples/s is {duration * sample_rate:.3g} samples per run: allowed at most {MAX_SWEEP_SAMPLES:.0e} (raise the rate or lower {key}.sample_rate)")
            rate = None
        elif cycles is not None and 2.0 * cycles / low >= duration:
            c.fail(f"{key}.rate", f"the sweep lasts {duration:g} s, shorter than two {cycles}-cycle estimator windows at {low:g} Hz ({2.0 * cycles / low:g} s): lower the rate{window_hint}")
            rate = None
    return rate, sample_rate


def _parse_header(c: _Checker, doc: dict) -> tuple[Any, str, TwoDofSystem | None, float | None, bool]:
    """What every scene has: name, description, system, excitation amplitude and the report switch."""
    name = doc.get("name")
    if "name" in doc and not (isinstance(name, str) and _NAME.match(name)):
        c.fail("name", f"expected a file-name-safe string (letters, digits, '_', '-', '.'), got {name!r}")
    description = doc.get("description", "")
    if not isinstance(description, str):
        c.fail("description", f"expected a string, got {type(description).__name__}")
    system = _parse_system(c, doc.get("system")) if "system" in doc else None
    amplitude = None
    if "excitation" in doc:
        excitation = c.mapping("excitation", doc["excitation"], {"amplitude"}, {"amplitude"})
        if "amplitude" in excitation:
            amplitude = c.number("excitation.amplitude", excitation["amplitude"], 0.0, math.inf, low_inclusive=False)
    report = doc.get("report", True)
    if not isinstance(report, bool):
        c.fail("report", f"expected true or false, got {report!r}")
    return name, description, system, amplitude, bool(report)


def _parse_benchmark_scene(c: _Checker, document: dict, text: str, source: str) -> Scene:
    """A benchmark scene: system, excitation amplitude and ``benchmark`` (cases, methods, tolerances)."""
    doc = c.mapping("", document, {"name", "description", "system", "excitation", "benchmark", "report"}, {"name", "system", "excitation", "benchmark"})
    name, description, system, amplitude, report = _parse_header(c, doc)
    spec = c.mapping("benchmark", doc["benchmark"], _BENCHMARK_KEYS, {"duration", "methods", "tolerances", "cases"})
    duration = c.number("benchmark.duration", spec.get("duration"), 0.0, 1e5, low_inclusive=False) if "duration" in spec else None
    methods = c.choices("benchmark.methods", spec.get("methods"), tuple(BENCHMARK_METHODS)) if "methods" in spec else ()
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
            if not (isinstance(case["name"], str) and _NAME.match(case["name"])):
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
                rate, sample_rate = _check_sweep_run(c, f"{key}.swept_sine", min(f_start, f_stop), max(f_start, f_stop), rate, sample_rate, 8)
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
        if start not in ("rest", "linear", "pgf"):
            c.fail(f"{key}.start", f"{start!r} is not allowed: use rest, linear or pgf")
        if None in (frequency, restitution, system, amplitude, duration, bumper) or start not in ("rest", "linear", "pgf"):
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
        problem = ImpactProblem(system, clearance, restitution, amplitude, frequency)
        if swept is not None:
            if None in (f_start, f_stop, rate, sample_rate):
                continue
            assert f_start is not None and f_stop is not None and rate is not None and sample_rate is not None
            sweep = SweptSine(amplitude, f_start, f_stop, rate)
            cases.append(BenchmarkCase(str(case["name"]), problem, "rest", 0, bumper, sweep, sample_rate))
        else:
            periods = max(1, round(duration * frequency))
            if periods > MAX_BENCHMARK_PERIODS:
                c.fail(f"{key}.frequency", f"{periods:,} periods per run (duration x frequency) is too many: allowed at most {MAX_BENCHMARK_PERIODS:,}")
                continue
            cases.append(BenchmarkCase(str(case["name"]), problem, start, periods, bumper))
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


def _parse_ladder(c: _Checker, value: Any) -> LadderSettings | None:
    """``ladder: {frequency, restitution, clearance, bumper_frequencies, rtol, repeats}``."""
    spec = c.mapping("benchmark.ladder", value, {"frequency", "restitution", "clearance", "bumper_frequencies", "rtol", "repeats"}, {"frequency", "restitution", "clearance", "bumper_frequencies"})
    frequency = c.number("benchmark.ladder.frequency", spec["frequency"], 0.0, math.inf, low_inclusive=False) if "frequency" in spec else None
    restitution = c.number("benchmark.ladder.restitution", spec["restitution"], 0.0, 1.0, low_inclusive=False) if "restitution" in spec else None
    clearance = c.number("benchmark.ladder.clearance", spec["clearance"], 0.0, math.inf) if "clearance" in spec else None
    bumpers = c.grid("benchmark.ladder.bumper_frequencies", spec["bumper_frequencies"], 0.0, MAX_BUMPER_FREQUENCY, False) if "bumper_frequencies" in spec else None
    rtol = c.number("benchmark.ladder.rtol", spec.get("rtol", 1e-8), 1e-14, 1e-2)
    repeats = c.integer("benchmark.ladder.repeats", spec.get("repeats", 3), 1, 100)
    if any(v is None for v in (frequency, restitution, clearance, bumpers, rtol, repeats)):
        return None
    assert frequency is not None and restitution is not None and clearance is not None and bumpers is not None and rtol is not None and repeats is not None
    return LadderSettings(frequency, restitution, clearance, tuple(float(b) for b in bumpers), rtol, repeats)




def _parse_simulation(c: _Checker, value: Any, default_frequency: np.ndarray, swept: bool = False) -> SimulationSettings | None:
    spec = dict(c.mapping("simulation", value, _SIMULATION_KEYS))
    rtol, atol = SWEPT_TOLERANCES if swept else STEPPED_TOLERANCES
    if "rtol" in spec and "atol" not in spec and isinstance(spec["rtol"], (int, float)) and not isinstance(spec["rtol"], bool):
        spec["atol"] = spec["rtol"] * (atol / rtol)  # the ratio the guidance was measured with: atol = rtol x 1e-4 m
    spec.setdefault("rtol", rtol)
    spec.setdefault("atol", atol)
    frequency: np.ndarray | None = c.grid("simulation.frequency", spec["frequency"], 0.0, math.inf, False) if "frequency" in spec else default_frequency
    start = spec.get("start", "pgf")
    if start not in SIMULATION_STARTS:
        c.fail("simulation.start", f"{start!r} is not allowed: use one of {', '.join(SIMULATION_STARTS)}")
    engine_kwargs = {k: spec[k] for k in ("method", "rtol", "atol", "max_step") if k in spec}
    steady_kwargs = {k: spec[k] for k in ("tolerance", "max_periods", "measure_periods", "irregular_measure_periods") if k in spec}
    engine = _settings(c, EngineSettings, engine_kwargs)
    steady = _settings(c, SteadySettings, steady_kwargs)
    if frequency is None or start not in SIMULATION_STARTS or engine is None or steady is None:
        return None
    return SimulationSettings(frequency=frequency, start=start, engine=engine, steady=steady)


def _settings(c: _Checker, kind: type[_T], kwargs: dict[str, Any]) -> _T | None:
    """Build a settings dataclass, turning its validation errors into scene problems under ``simulation.``."""
    for key, item in kwargs.items():
        if isinstance(item, bool) or not isinstance(item, (int, float, str)):
            c.fail(f"simulation.{key}", f"expected a number or name, got {item!r}")
            return None
    try:
        return kind(**kwargs)
    except (ValueError, TypeError) as error:
        c.fail("simulation." + str(error).split(" ")[0], str(error))
        return None


def _parse_system(c: _Checker, value: Any) -> TwoDofSystem | None:
    spec = c.mapping("system", value, {"m1", "m2", "k1", "k2", "b1", "b2"}, {"m1", "m2", "k1", "k2"})
    numbers: dict[str, float] = {}
    for key in ("m1", "m2", "k1", "k2", "b1", "b2"):
        if key in spec:
            number = c.number(f"system.{key}", spec[key], 0.0, math.inf, low_inclusive=key.startswith("b"))
            if number is not None:
                numbers[key] = number
    if not {"m1", "m2", "k1", "k2"} <= set(numbers) or len(numbers) < len(spec.keys() & {"m1", "m2", "k1", "k2", "b1", "b2"}):
        return None
    return TwoDofSystem(**numbers)


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file; raise :class:`SceneError` (or ``OSError`` if it cannot be read)."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as error:
        raise SceneError([f"not UTF-8 text: {error}"], str(path)) from None
    try:
        document = read_yaml(text)
    except yaml.YAMLError as error:
        for mark in (getattr(error, "context_mark", None), getattr(error, "problem_mark", None)):
            if mark is not None:
                mark.name = str(path)  # PyYAML names a parsed string "<unicode string>"
        raise SceneError([f"not valid YAML: {error}"], str(path)) from None
    return parse_scene(document, text=text, source=str(path))


def find_scene(name: str | Path) -> Path:
    """Locate a scene: the path as given, else ``studies/<name>`` in the working directory, else the shipped one.

    A bare name may omit ``.yaml``. A local file wins over a shipped scene of the same name.

    Raises
    ------
    FileNotFoundError
        Naming every place looked at, each once.
    """
    given = Path(name)
    if given.is_dir():
        raise IsADirectoryError(f"scene {given} is a directory, not a YAML file")
    candidates = [given]
    if not given.is_absolute():
        candidates.append(Path.cwd() / "studies" / given)
        candidates.append(shipped_studies_dir() / given.name)
    if given.suffix not in (".yaml", ".yml"):
        candidates += [c.with_name(c.name + ".yaml") for c in list(candidates)]
    unique: dict[Path, Path] = {}
    for candidate in candidates:
        unique.setdefault(candidate.resolve(), candidate)  # in a checkout ./studies is the shipped folder
    for candidate in unique.values():
        if candidate.is_file():
            return candidate
    raise FileNotFoundError("scene not found; looked at: " + ", ".join(str(p) for p in unique.values()))


def shipped_studies_dir() -> Path:
    """The shipped scenes: package data ``vibroimpact/studies`` (in a checkout, its top-level ``studies/``)."""
    return Path(str(importlib.resources.files("vibroimpact.studies")))


def shipped_studies() -> list[tuple[str, str]]:
    """Name and one-line description of every shipped scene, sorted by name (a scene that fails to load says so)."""
    listing = []
    for path in sorted(shipped_studies_dir().glob("*.yaml")):
        try:
            document = read_yaml(path.read_text(encoding="utf-8"))
            description = str(document.get("description", "")) if isinstance(document, dict) else ""
        except (OSError, UnicodeDecodeError, yaml.YAMLError) as error:
            description = f"(unreadable: {error})"
        listing.append((path.stem, " ".join(description.split())))
    return listing
