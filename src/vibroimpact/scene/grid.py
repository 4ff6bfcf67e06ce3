"""The grammar of a scene over parameter grids, shared by two kinds: stepped steady states (``stepped``) and swept-sine
tests (``swept``, a scene with a ``swept_sine`` section). Its settings (:class:`GridSettings`) are the
:attr:`~vibroimpact.scene.schema.Scene.settings` of both; each kind's parser
(:mod:`vibroimpact.kinds.stepped.scene`, :mod:`vibroimpact.kinds.swept.scene`) reads its scenes with
:func:`parse_grid_scene`.

Each ``_parse_*`` function checks one section of the document with a :class:`~vibroimpact.scene.checker.Checker`
(recording every problem, returning None where a value is unusable); :func:`parse_grid_scene` puts them together.
The header (:mod:`vibroimpact.scene.header`) and the layout (:func:`vibroimpact.scene.layout_parse.parse_layout`) are
every kind's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from vibroimpact.analysis.pgf import AdmissibilitySettings
from vibroimpact.engines.registry import BUMPER, engine_spec
from vibroimpact.model.bumper_limit import bumper_refusal
from vibroimpact.model.layout import Layout
from vibroimpact.model.collision import MAX_LOSS_FACTOR, MIN_BUMPER_RESTITUTION, loss_factor_from_restitution, restitution_from_loss_factor
from vibroimpact.model.excitation import SweptSine
from vibroimpact.model.modal import underdamped_mode_count
from vibroimpact.scene.bumper_parse import BUMPER as BUMPER_SECTION, PHYSICAL_KEYS, scene_bumper
from vibroimpact.scene.checker import Checker, SceneError, interval
from vibroimpact.scene.declared import DERIVED, OPTIONAL, REQUIRED, Free, Grid, Key, Names, Section, Table
from vibroimpact.scene.header import check_sweep_run, open_scene
from vibroimpact.scene.layout_parse import check_layout_solutions, parse_layout, parse_sweep_stops
from vibroimpact.scene.stop_grids import stop_grids
from vibroimpact.scene.schema import (
    ENGINE_CONTACT,
    ENGINE_SOLUTIONS,
    MAX_STUDY_POINTS,
    MAX_SWEEP_SAMPLES,
    QUANTITIES,
    SIMULATION_STARTS,
    SOLUTIONS,
    SWEEP_DIRECTIONS,
    SWEEPABLE,
    Scene,
    quantities_for,
)
from vibroimpact.scene.simulation import SimulationSettings, parse_simulation

__all__ = ["GridSettings", "SweptSineSettings", "GRID_TOP", "SWEEP", "GRID_STOP", "GRID_SETTINGS", "SWEPT_SINE", "ADMISSIBILITY", "TOP_KEYS", "parse_grid_scene"]



def _swept(name: str, default: Any = DERIVED) -> Key:
    """The declared grid of the parameter table's row ``name`` (its range, its unit)."""
    row = SWEEPABLE[name]
    return Key(name, Grid, f"the {row.long_name} values swept", default, row.low, row.high, "" if row.unit == "1" else row.unit, open_low=not row.low_inclusive)


def _fixed(name: str) -> Key:
    """The declared one value of the parameter table's row ``name``, where it is not swept."""
    row = SWEEPABLE[name]
    return Key(name, float, f"the {row.long_name}, unless swept (sweep.{name})", DERIVED, row.low, row.high, "" if row.unit == "1" else row.unit,
               open_low=not row.low_inclusive, open_high=not row.high_inclusive)  # fmt: skip


#: A grid scene's own top-level keys, declared (:mod:`vibroimpact.scene.declared`); the header's and the layout's
#: (system, excitation, stops, bumper) are declared with them.
GRID_TOP = Section("", (
    Key("sweep", Table, "the grids swept: frequency, and any of restitution, clearance, bumper_frequency, bumper_loss_factor (sweep)", REQUIRED),
    Key("solutions", Names, "what is computed at every point: closed forms (linear, pgf, pgf_paper) and engines", REQUIRED, choices=SOLUTIONS),
    Key("quantities", Free, "a list of output names from the layout's (x1_amplitude ... for the paper's coordinates; default: every one)", OPTIONAL),
    Key("stop", Table, "{clearance, restitution}: the paper's stop above the absorber x2 (or 'stops': any layout)", OPTIONAL),
    Key("settings", Table, "{admissibility: ...}: the closed forms' settings (settings.admissibility)", OPTIONAL),
    Key("simulation", Table, "the time-domain solutions' settings (simulation)", OPTIONAL),
    Key("swept_sine", Table, "a swept-sine test instead of stepped steady states (swept_sine)", OPTIONAL),
), "a stepped or swept scene's own keys", form="stepped and swept")  # fmt: skip
#: ``sweep``, declared: the grids, and which stops they move.
SWEEP = Section("sweep", (
    *(_swept(name, REQUIRED if name == "frequency" else DERIVED) for name in SWEEPABLE),
    Key("stop", Free, "which stops the swept restitution, clearance and bumper apply to: an index of 'stops' or a list of them (default: every stop)", OPTIONAL),
), "the grids the study runs over (every combination)")  # fmt: skip
#: The paper's ``stop`` of a grid scene, declared.
GRID_STOP = Section("stop", (_fixed("clearance"), _fixed("restitution")), "the paper's stop above the absorber x2", form="stepped and swept")
#: ``settings``, declared.
GRID_SETTINGS = Section("settings", (Key("admissibility", Table, "how the closed form's X2(t) <= Delta is checked (settings.admissibility)", OPTIONAL),),
                        "the closed forms' settings")  # fmt: skip
#: Top-level keys of a grid scene.
TOP_KEYS = {*GRID_TOP.names, "system", "excitation", "stops", "bumper"}
#: Simulation keys that only stepped steady states use.
_STEADY_ONLY_KEYS = {"frequency", "start", "tolerance", "max_periods", "measure_periods", "irregular_measure_periods", "lyapunov_periods", "subset"}
#: Where an unswept parameter is given instead (``frequency`` is always swept).
_FIXED_PLACE = {"restitution": ("stop", "restitution"), "clearance": ("stop", "clearance"), "bumper_frequency": ("bumper", "frequency"), "bumper_loss_factor": ("bumper", "loss_factor")}


#: ``swept_sine``, declared (:mod:`vibroimpact.scene.declared`); :class:`SweptSineSettings` in this order.
SWEPT_SINE = Section("swept_sine", (
    Key("start", float, "the sweep's lower end", REQUIRED, 0.0, math.inf, "Hz", open_low=True),
    Key("stop", float, "the sweep's upper end (a sweep down runs from it to start)", REQUIRED, 0.0, math.inf, "Hz", open_low=True),
    Key("rate", float, "|alpha|, how fast the frequency moves", REQUIRED, 0.0, math.inf, "Hz s-1", open_low=True),
    Key("directions", Names, "which ways it sweeps", SWEEP_DIRECTIONS, choices=SWEEP_DIRECTIONS),
    Key("sample_rate", float, "output samples per second of the simulated signals", 1000.0, 0.0, 1e7, "Hz", open_low=True),
    Key("window_cycles", int, "cycles of the excitation in the running estimators' window", 8, 1, 10_000),
    Key("initial_state", str, "linear: each run starts on the linear steady state (where it fits), rest: at rest", "linear", choices=("linear", "rest")),
), "a swept-sine test (the paper's Simulink run) instead of stepped steady states")  # fmt: skip
#: ``settings.admissibility``, declared: how the closed form's X2(t) <= Delta is checked.
ADMISSIBILITY = Section("settings.admissibility", (
    Key("samples_per_period", int, "uniform samples of X2(t) per period before the largest is refined", AdmissibilitySettings.samples_per_period, 16, 1_000_000),
    Key("relative_tolerance", float, "how far X2(t) may exceed Delta, a fraction of (Delta + q |H12|)", AdmissibilitySettings.relative_tolerance, 0.0, 1e-2),
), "the closed forms' admissibility check")  # fmt: skip


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
    directions: tuple[str, ...] = SWEPT_SINE.key("directions").default
    sample_rate: float = SWEPT_SINE.key("sample_rate").default
    window_cycles: int = SWEPT_SINE.key("window_cycles").default
    initial_state: str = SWEPT_SINE.key("initial_state").default

    def sweep(self, amplitude: float, direction: str) -> SweptSine:
        """The excitation of one direction."""
        low, high = self.start_frequency, self.stop_frequency
        return SweptSine(amplitude, low, high, self.rate) if direction == "up" else SweptSine(amplitude, high, low, self.rate)


@dataclass(frozen=True, eq=False)
class GridSettings:
    """What a grid scene computes: its solutions over a grid of frequencies, restitutions, clearances and bumpers.

    Attributes
    ----------
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
    sweep_stops : tuple of int or None
        The stops that swept restitution, clearance and bumper values apply to; None: every stop.
    """

    frequency: np.ndarray
    restitution: np.ndarray
    clearance: np.ndarray
    swept: tuple[str, ...]
    solutions: tuple[str, ...]
    quantities: tuple[str, ...]
    admissibility: AdmissibilitySettings = field(default_factory=AdmissibilitySettings)
    simulation: SimulationSettings | None = None
    bumper_frequency: np.ndarray | None = None
    bumper_loss_factor: np.ndarray | None = None
    swept_sine: SweptSineSettings | None = None
    sweep_stops: tuple[int, ...] | None = None

    def loss_factors(self) -> np.ndarray:
        """The bumper's xi_b for each restitution of the grid [-] (NaN where none gives it, R = 0)."""
        if self.bumper_loss_factor is not None:
            return np.broadcast_to(self.bumper_loss_factor, self.restitution.shape).astype(float)
        return np.array([loss_factor_from_restitution(r) if r > 0.0 else np.nan for r in self.restitution])

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


def parse_grid_scene(document: dict, text: str = "", source: str = "scene") -> Scene:
    """Validate a grid scene's document (a mapping) and build the :class:`Scene`; raise :class:`SceneError` listing
    all problems."""
    moved = isinstance(document, dict) and document.get("report") == "design_map"  # the stepped kind's old design-map page
    c, doc, name, description, report, scheduler = open_scene({**document, "report": True} if moved else document, TOP_KEYS, {"name", "system", "excitation"},
                                                   "swept" if isinstance(document, dict) and "swept_sine" in document else "stepped")  # fmt: skip
    own = GRID_TOP.read(c, {key: doc[key] for key in GRID_TOP.names if key in doc}, partial=True) or {}  # sweep and solutions required
    if moved:
        c.fail("report", "the design map is the design kind's grid search: a scene with a 'design' section and 'search: {method: grid, points: N}' (studies/design_map.yaml)")
    layout, amplitude, coordinates = parse_layout(c, doc)

    sweep = _given(c, SWEEP, own.get("sweep"))  # each grid checked by its declaration (None where wrong), sweep.stop as given
    physical = isinstance(doc.get("bumper"), dict) and bool(doc["bumper"].keys() & PHYSICAL_KEYS)  # K_b [N/m], B_b [N s/m]
    fixed = {"stop": _given(c, GRID_STOP, own.get("stop")), "bumper": _given(c, BUMPER_SECTION, doc.get("bumper")) if "bumper" in doc and not physical else {}}
    if physical:
        fixed["bumper"], layout = scene_bumper(c, doc["bumper"], sweep, layout, "stops" in doc)
    solutions = own.get("solutions") or ()
    specs = layout.stops if layout is not None and "stops" in doc else None
    targets = None
    if "stop" in sweep:
        if "stops" not in doc:
            c.fail("sweep.stop", "names which of the scene's stops the swept values apply to: only with a 'stops' list")
        else:
            targets = parse_sweep_stops(c, sweep["stop"], len(specs) if specs else None)
    sweep = {key: value for key, value in sweep.items() if key != "stop"}
    derived_restitution = "bumper_loss_factor" in sweep
    bumper_solutions = [name for name in solutions if ENGINE_CONTACT.get(name) == BUMPER]
    grids: dict[str, np.ndarray | None] = {}
    for key, row in SWEEPABLE.items():
        low, high, low_inclusive = row.low, row.high, row.low_inclusive
        section, field_name = _FIXED_PLACE.get(key, ("", ""))
        place = f"{section}.{field_name}"
        given_fixed = field_name in fixed.get(section, {})
        if key in sweep:
            if given_fixed:
                c.fail(place, f"also swept in sweep.{key}: give it in one place only")
            grids[key] = sweep[key]
        elif given_fixed:
            value = fixed[section][field_name] if section == "stop" or not physical else c.number(place, fixed[section][field_name], low, high, low_inclusive)
            grids[key] = None if value is None else np.array([value])
        elif key == "restitution" and derived_restitution:
            continue  # R(xi_b) of the swept loss factors
        elif (key == "restitution" or key == "clearance") and "stops" not in doc:
            c.fail(place, f"required unless swept (sweep.{key}); allowed range {interval(low, high, low_inclusive)}")
    if derived_restitution and "restitution" in grids and "stops" not in doc:
        c.fail("sweep.bumper_loss_factor", "sweeping the bumper's loss factor sets the restitution R(xi_b): do not also give restitution")
    if derived_restitution and (xi := grids.get("bumper_loss_factor")) is not None:
        grids["restitution"] = np.array([restitution_from_loss_factor(x) for x in xi])
    needs_bumper = bool(bumper_solutions) or "swept_sine" in doc
    if "stops" in doc:
        if specs is not None:
            specs = stop_grids(c, specs, grids, sweep, {k: v for k, v in fixed["bumper"].items() if not isinstance(v, bool) and isinstance(v, (int, float))}, targets, needs_bumper)
    else:
        if needs_bumper and "bumper_frequency" not in sweep and "bumper" not in doc:
            c.fail("bumper", "required by the compliant solution and swept-sine tests: {frequency: Omega_b / 2 pi [Hz], loss_factor: xi_b (optional)}")
        elif "bumper" in doc and "bumper_frequency" not in sweep and "frequency" not in fixed["bumper"] and not physical:
            c.fail("bumper.frequency", "required unless swept (sweep.bumper_frequency): Omega_b / 2 pi [Hz] in (0, inf), or bumper.stiffness [N/m] in (0, inf)")
        if bumper_solutions and "bumper_loss_factor" not in grids and (r := grids.get("restitution")) is not None and np.any(r < MIN_BUMPER_RESTITUTION):
            least = "R = 0 needs an infinitely damped bumper" if np.any(r == 0.0) else f"R = {float(np.min(r)):g} needs a bumper more damped than loss factor {MAX_LOSS_FACTOR:g}"
            c.fail("stop.restitution", f"{least} for the compliant solution: give bumper.loss_factor, or sweep R >= {MIN_BUMPER_RESTITUTION:.2g}")
    if layout is not None and (specs is not None or "stops" not in doc):
        layout = layout.with_stops(specs) if specs is not None else layout
        check_layout_solutions(c, solutions, layout, "swept_sine" in doc, grids.get("restitution"), grids.get("clearance"))
        exact_bumpers = [name for name in bumper_solutions if engine_spec(name).capabilities.exact_flow]
        if exact_bumpers and not c.problems:
            where = "sweep.bumper_frequency" if "bumper_frequency" in sweep else "bumper.frequency" if "bumper" in doc else "stops"
            _check_bumper_stiffness(c, where, exact_bumpers, layout, grids)

    sizes = [g.size for g in grids.values() if g is not None]
    if len(sizes) >= 3 and math.prod(sizes) > MAX_STUDY_POINTS:
        c.fail("sweep", f"{math.prod(sizes):,} points (product of the swept grids) is too many: allowed at most {MAX_STUDY_POINTS:,}")
    if "pgf_paper" in solutions and layout is not None and (named := layout.paper_view()) is not None and (modes := underdamped_mode_count(named)) != 2:
        c.fail("solutions", f"pgf_paper needs two underdamped modes (the paper's eq. 10 fit); this system has {modes}")
    allowed = quantities_for(coordinates) if coordinates is not None else QUANTITIES
    if len(set(allowed)) != len(allowed):
        clashing = sorted({q for q in allowed if allowed.count(q) > 1})
        c.fail("system.coordinates", f"names that make output names clash ({', '.join(clashing)}): rename them (e.g. not 'force')")
    quantities = c.choices("quantities", own["quantities"], allowed) if own.get("quantities") is not None else allowed
    if "regime" not in quantities:
        quantities = (*quantities, "regime")

    admissibility = AdmissibilitySettings()
    if (settings := own.get("settings")) is not None and (values := GRID_SETTINGS.read(c, settings)) is not None and values["admissibility"] is not None:
        if (values := ADMISSIBILITY.read(c, values["admissibility"])) is not None:
            admissibility = AdmissibilitySettings(**values)

    simulation = None
    engines = [name for name in solutions if name in ENGINE_SOLUTIONS]
    # the sections as the top level read them: one that is no mapping was said there, once, and is not read again
    swept_sine = _parse_swept_sine(c, own["swept_sine"], engines, grids.get("frequency")) if own.get("swept_sine") is not None else None
    if (given := own.get("simulation")) is not None:
        if not engines:
            c.fail("simulation", f"given, but no time-domain solution ({', '.join(ENGINE_SOLUTIONS)}) is asked for")
        elif (main_grid := grids.get("frequency")) is not None:
            if "swept_sine" in doc:
                for key in sorted(set(given) & _STEADY_ONLY_KEYS):
                    c.fail(f"simulation.{key}", "not used by a swept-sine test (it sets stepped steady states): remove it")
            swept_axes = {key: grid for key, grid in grids.items() if key in sweep and key != "frequency"}
            simulation = parse_simulation(c, given, main_grid, swept="swept_sine" in doc, engines=engines, axes=swept_axes)
    elif engines and (main_grid := grids.get("frequency")) is not None:
        simulation = parse_simulation(c, {}, main_grid, swept="swept_sine" in doc)

    if c.problems:
        raise SceneError(c.problems, source)
    frequency, restitution, clearance = grids["frequency"], grids["restitution"], grids["clearance"]
    # guaranteed when no problem was recorded
    assert layout is not None and amplitude is not None and isinstance(name, str)
    assert frequency is not None and restitution is not None and clearance is not None
    order = ("bumper_loss_factor", "restitution", "clearance", "bumper_frequency")
    swept = tuple(k for k in order if k in sweep) + ("frequency",)
    grid = GridSettings(
        frequency=frequency, restitution=restitution, clearance=clearance, swept=swept, solutions=solutions, quantities=quantities,
        admissibility=admissibility, simulation=simulation, bumper_frequency=grids.get("bumper_frequency"),
        bumper_loss_factor=grids.get("bumper_loss_factor"), swept_sine=swept_sine, sweep_stops=targets,
    )
    return Scene(
        name=name, description=description, layout=layout, amplitude=amplitude, kind="stepped" if swept_sine is None else "swept", settings=grid,
        report=report, text=text, cluster_scheduler=scheduler,
    )


def _given(c: Checker, section: Section, value: Any) -> dict[str, Any]:
    """The keys of ``section`` the scene gives in ``value`` (None: the section is absent), each checked by its
    declaration (None where wrong: it is still given, for the checks of where a value may be given); unknown keys
    are refused with the closest declared one."""
    if value is None:
        return {}
    read = section.read(c, value, partial=True)
    return {key: read[key] for key in section.names if key in value} if read is not None else {}


def _check_bumper_stiffness(c: Checker, where: str, names: list[str], layout: Layout, grids: dict[str, np.ndarray | None]) -> None:
    """Record at ``where`` a bumper too stiff for the structure for the exact-flow bumper solutions ``names``
    (:func:`~vibroimpact.model.bumper_limit.bumper_refusal`), judged at the grid's stiffest bumper: the engines would
    refuse every point in contact."""
    frequencies, losses = grids.get("bumper_frequency"), grids.get("bumper_loss_factor")
    restitution, clearance = grids.get("restitution"), grids.get("clearance")
    try:
        problem = layout.problem(
            1.0, 1.0, float(np.max(restitution)) if restitution is not None else math.nan, float(clearance[0]) if clearance is not None else math.nan,
            bumper=True, bumper_frequency=float(np.max(frequencies)) if frequencies is not None else math.nan,
            loss_factor=float(losses[0]) if losses is not None else math.nan,
        )  # fmt: skip
    except ValueError:
        return  # a stop without its values: said where they are checked
    if (refusal := bumper_refusal(problem)) is not None:
        c.fail(where, f"{'/'.join(names)}: {refusal}")


def _parse_swept_sine(c: Checker, value: Any, engines: list[str], grid: np.ndarray | None) -> SweptSineSettings | None:
    """``swept_sine: {start, stop, rate, directions, sample_rate, window_cycles, initial_state}`` (frequencies [Hz],
    rate [Hz s-1]); every problem is reported."""
    if engines != ["compliant"]:
        c.fail("solutions", f"a swept-sine test runs the compliant solution only (and needs it): got {engines or 'none'}")
    spec = SWEPT_SINE.read(c, value, partial=True)  # the checks across keys below still say their problems
    if spec is None:
        return None
    start, stop, rate, directions, sample_rate, cycles, initial = (spec[key] for key in SWEPT_SINE.names)
    if start is None or stop is None:
        return None
    if stop <= start:
        c.fail("swept_sine.stop", f"{stop:g} must be greater than start = {start:g} (directions say which way it runs)")
        return None
    rate, sample_rate = check_sweep_run(c, "swept_sine", start, stop, rate, sample_rate, cycles, " or swept_sine.window_cycles")
    if grid is not None and not np.any((grid >= start) & (grid <= stop)):
        c.fail("sweep.frequency", f"no frequency of the grid lies in the swept band [{start:g}, {stop:g}] Hz, where the running estimates are reported")
    if rate is None or sample_rate is None or cycles is None or directions is None or initial is None:
        return None
    return SweptSineSettings(start, stop, rate, directions, sample_rate, cycles, initial)
