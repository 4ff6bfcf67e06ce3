"""Scenes that compare absorber concepts: one primary mass, one absorber mass, several ways of damping or stopping the
absorber, side by side over one frequency band.

Example (the shipped ``absorber_concepts``, shortened)::

    name: absorber_concepts
    system: {m1: 1.0, m2: 0.1, k1: 25000.0, k2: 4300.0, b1: 0.8, b2: 0.08}   # the paper's, lightly damped absorber
    excitation: {amplitude: 10.0}                                          # q [N] on the primary mass
    frequency: {start: 15.0, stop: 45.0, step: 0.01}                       # closed forms [Hz]
    simulation: {frequency: {start: 15.0, stop: 45.0, step: 0.5}}          # time-domain steady states [Hz]
    bumper: {frequency: 250.0}            # each rigid stop's Kelvin-Voigt twin (same clearance, loss factor from R)
    continuation: {max_steps: 400}
    concepts:
      - {name: den_hartog, label: "(a) Den Hartog", absorber: {stiffness: den_hartog, damping: den_hartog}}
      - {name: paper_stop, label: "(b) absolute stop", stops: [{coordinate: x2, side: upper, clearance: 0.003, restitution: 0.2}]}
      - {name: stop_1928, label: "(c) relative stop", stops: [{between: [x2, x1], side: upper, clearance: 0.003, restitution: 0.2}]}

Each concept keeps m1, k1, b1 and m2; ``absorber`` may replace k2 and b2 (a number, or ``den_hartog``: Den Hartog's
optimum, :mod:`vibroimpact.model.absorber`), and ``stops`` lists rigid stops: ``coordinate: x2`` against the base, or
``between: [x2, x1]`` (on x2 - x1), ``side: upper`` (coordinate <= clearance) or ``lower`` (>= -clearance). The
anti-resonance band of the comparison is where the scene's own system, without a stop, keeps |X1| below the static
deflection q / k1, around the absorber's anti-resonance sqrt(k2 / m2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from vibroimpact.engines.settings import EngineSettings
from vibroimpact.model.layout import Layout
from vibroimpact.scene.header import NAME, open_scene
from vibroimpact.scene.layout_parse import parse_layout
from vibroimpact.scene.simulation import parse_simulation
from vibroimpact.model.absorber import den_hartog_absorber
from vibroimpact.model.collision import loss_factor_from_restitution
from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop, Stop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem, System
from vibroimpact.scene.layout_parse import parse_stops
from vibroimpact.scene.declared import DERIVED, OPTIONAL, REQUIRED, Free, Grid, Key, Rows, Section, Table
from vibroimpact.scene.checker import Checker, SceneError
from vibroimpact.simulation.settings import SteadySettings

__all__ = ["CONTINUATION", "CONCEPTS_TOP", "CONCEPTS_BUMPER", "CONCEPT_ROW", "CONCEPT_ABSORBER", "SECTIONS", "Concept", "ConceptsSettings", "bumper_twin", "CONCEPTS_TOP_KEYS", "parse_concepts", "parse_concepts_scene", "MAX_CONCEPTS"]


# --------------------------------------------------------------------------------------------------------------------
# What a concepts scene builds: the concepts and the settings of the study (dataclasses; they import nothing from the
# scene layer, so that :mod:`~vibroimpact.scene.schema` can name them without a circle of imports; :mod:`~vibroimpact.kinds.concepts.scene` parses them).
# --------------------------------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Concept:
    """One absorber concept: the system it has and the stops it adds.

    Attributes
    ----------
    name : str
        Short, file-name-safe name (the dataset's ``concept`` coordinate).
    label : str
        What the report calls it.
    system : LinearStructure or the paper's named system
        The paper's named system (m1 ... b2 of the scene's layout, :meth:`~vibroimpact.model.layout.Layout.paper_view`)
        with this concept's k2 and b2.
    stops : tuple of Stop
        Rigid stops (none: the linear absorber).
    absorber : str
        How k2 and b2 were chosen, in words.
    """

    name: str
    label: str
    system: System
    stops: tuple[Stop, ...] = ()
    absorber: str = ""

    def describe_stops(self) -> str:
        """E.g. ``x2 <= 3 mm, R = 0.2``; ``no stop``."""
        if not self.stops:
            return "no stop"
        return "; ".join(f"{stop.describe(self.system.coordinates)}, R = {stop.law.restitution:g}" for stop in self.stops if isinstance(stop.law, RigidStop))

    def problem(self, amplitude: float, frequency: float, phase: float = 0.0, bumper_frequency: float | None = None) -> ImpactProblem:
        """The concept's impact problem at ``frequency`` [Hz]: its rigid stops, or (``bumper_frequency`` [Hz]) each
        stop's Kelvin-Voigt twin of the same clearance whose loss factor gives its restitution; ``ValueError`` for a
        concept without a stop."""
        if not self.stops:
            raise ValueError(f"concept {self.name!r} has no stop: its steady state is the linear one")
        laws = [stop.law if bumper_frequency is None else bumper_twin(stop.law, bumper_frequency) for stop in self.stops]
        force = HarmonicForce(amplitude, frequency, phase)
        stops = tuple(Stop(law, stop.coordinate, stop.other, stop.side) for law, stop in zip(laws, self.stops))
        return ImpactProblem(self.system, stops, force)


def bumper_twin(law: Any, bumper_frequency: float) -> KelvinVoigtBumper:
    """The Kelvin-Voigt bumper of a rigid stop: same clearance, Omega_b / 2 pi = ``bumper_frequency`` [Hz], the loss
    factor whose one collision restitutes R (:func:`loss_factor_from_restitution`)."""
    if not isinstance(law, RigidStop):
        raise TypeError(f"expected a RigidStop, got {law!r}")
    return KelvinVoigtBumper(law.clearance, bumper_frequency, loss_factor_from_restitution(law.restitution))


#: ``continuation``, declared (:mod:`vibroimpact.scene.declared`).
CONTINUATION = Section("continuation", (
    Key("enabled", bool, "continue each concept's branches from its closed-form and simulated orbits", True),
    Key("max_steps", int, "points per continued branch and direction, at most (0: none)", 400, 0, 100_000),
), "the concepts' continued branches")  # fmt: skip
#: A concepts scene's own top-level keys, declared (the header's and the layout's are declared with them).
CONCEPTS_TOP = Section("", (
    Key("frequency", Grid, "the closed forms' frequencies", REQUIRED, 0.0, math.inf, "Hz", open_low=True),
    Key("concepts", Rows, "the concepts compared, {name, label, absorber, stops} each (concepts[k]); at most 12", REQUIRED),
    Key("simulation", Table, "the time-domain steady states' settings (simulation; default: every 61st frequency)", OPTIONAL),
    Key("bumper", Table, "{frequency: Hz}: each rigid stop's Kelvin-Voigt twin, its loss factor from R (default: none)", OPTIONAL),
    Key("continuation", Table, "the concepts' continued branches (continuation)", OPTIONAL),
), "a concepts scene's own keys", form="concepts")  # fmt: skip
#: ``bumper`` of a concepts scene, declared.
CONCEPTS_BUMPER = Section("bumper", (
    Key("frequency", float, "Omega_b / 2 pi of each rigid stop's Kelvin-Voigt twin (same clearance, loss factor from R)", REQUIRED, 0.0, 1e6, "Hz", open_low=True),
), "the bumper twins of the concepts' rigid stops", form="concepts")  # fmt: skip
#: A row of ``concepts``, declared.
CONCEPT_ROW = Section("concepts[k]", (
    Key("name", str, "the concept's name, file-name safe (the dataset's concept coordinate)", REQUIRED),
    Key("label", str, "what the page calls it (default: its name)", DERIVED),
    Key("absorber", Table, "{stiffness, damping}: k2 and b2 replaced (concepts[k].absorber; default: the scene's)", OPTIONAL),
    Key("stops", Rows, "rigid stops in the shared stops grammar, each with clearance > 0 and restitution > 0 (default: none, the linear absorber)", OPTIONAL),
), "one absorber concept")  # fmt: skip
#: ``concepts[k].absorber``, declared.
CONCEPT_ABSORBER = Section("concepts[k].absorber", (
    Key("stiffness", Free, "k2: a number > 0 [N m-1], or den_hartog (Den Hartog's tuning)", OPTIONAL),
    Key("damping", Free, "b2: a number >= 0 [N s m-1], or den_hartog (Den Hartog's optimum damping)", OPTIONAL),
), "the concept's absorber spring and damper")  # fmt: skip
#: The sections of a concepts scene that are declared (``run-study --keys`` lists them).
SECTIONS = (CONCEPTS_TOP, CONCEPTS_BUMPER, CONTINUATION, CONCEPT_ROW, CONCEPT_ABSORBER)


@dataclass(frozen=True, eq=False)
class ConceptsSettings:
    """Everything a concepts study computes from.

    Attributes
    ----------
    system : LinearStructure or the paper's named system
        The scene's named system (its layout's paper view): the reference of the anti-resonance band and the base of every concept.
    amplitude : float
        q [N] on the primary mass.
    concepts : tuple of Concept
        In the order of the scene.
    frequency : ndarray
        Closed-form grid [Hz].
    simulation_frequency : ndarray
        Time-domain grid [Hz] (steady states of the exact engine and of the bumper twins).
    engine : EngineSettings
        Tolerances of the integrators (the bumper's IDA).
    steady : SteadySettings
        Convergence and measurement of the steady states.
    bumper_frequency : float
        Omega_b / 2 pi of every bumper twin [Hz]; NaN: no bumper runs.
    continuation_steps : int
        Most points per continued branch and direction; 0: no continuation.
    """

    system: System
    amplitude: float
    concepts: tuple[Concept, ...]
    frequency: np.ndarray
    simulation_frequency: np.ndarray
    engine: EngineSettings = field(default_factory=EngineSettings)
    steady: SteadySettings = field(default_factory=SteadySettings)
    bumper_frequency: float = math.nan
    continuation_steps: int = CONTINUATION.key("max_steps").default

    @property
    def static_deflection(self) -> float:
        """q / k1 [m]: the primary's deflection under the force amplitude held still."""
        return self.amplitude / self.system.k1

#: Top-level keys of a concepts scene.
CONCEPTS_TOP_KEYS = {*CONCEPTS_TOP.names, "system", "excitation"}
_SIMULATION_KEYS = frozenset({"frequency", "rtol", "atol", "tolerance", "max_periods", "measure_periods", "irregular_measure_periods"})
#: Simulation keys of other kinds that a concepts scene does not use: refused with the reason, never ignored.
_UNUSED_SIMULATION_KEYS = {
    "lyapunov_periods": "a concepts scene does not classify non-periodic motion (its steady states march, then measure "
    "irregular_measure_periods); stepped scenes do",
}
#: Most concepts of one scene (a table row and a panel each).
MAX_CONCEPTS = 12
#: Most time-domain frequencies per concept.
MAX_SIMULATION_POINTS = 2000


def parse_concepts(document: Any, source: str = "scene") -> tuple[str, str, bool, ConceptsSettings, str | None]:
    """Check a concepts scene's document and return (name, description, report, settings, the cluster's scheduler);
    :class:`SceneError` listing every problem otherwise."""
    c, doc, name, description, report, scheduler = open_scene(document, CONCEPTS_TOP_KEYS, {"name", "system", "excitation"}, "concepts")
    layout, amplitude, _ = parse_layout(c, doc)
    system = layout.paper_view() if layout is not None else None  # the absorber concepts are variants of the paper's layout
    if layout is not None and system is None:
        c.fail("system", "a concepts scene needs the paper's layout: the two-mass chain (a primary mass on its suspension, an absorber on the primary) as {m1, m2, k1, k2, b1, b2} or its matrices with coordinates [x1, x2], the force on x1")
    own = CONCEPTS_TOP.read(c, {key: doc[key] for key in CONCEPTS_TOP.names if key in doc}, partial=True) or {}  # frequency, concepts required
    frequency = own.get("frequency")
    # the sections as the top level read them: one that is no mapping was said there, once, and is not read again
    simulation = _simulation(c, own.get("simulation") or {}, frequency)
    bumper = CONCEPTS_BUMPER.read(c, own["bumper"]) if own.get("bumper") is not None else None
    bumper_frequency = bumper["frequency"] if bumper is not None else math.nan
    continuation = CONTINUATION.read(c, own.get("continuation") or {}) or {}
    steps = continuation.get("max_steps", 0) if continuation.get("enabled") else 0
    concepts = _concepts(c, own["concepts"], system) if own.get("concepts") is not None and system is not None else ()
    if c.problems:
        raise SceneError(c.problems, source)
    assert isinstance(name, str) and system is not None and amplitude is not None and frequency is not None and simulation is not None
    sim_frequency, engine, steady = simulation
    settings = ConceptsSettings(system, amplitude, concepts, frequency, sim_frequency, engine, steady, bumper_frequency, steps)
    return name, description, report, settings, scheduler


def parse_concepts_scene(document: Any, text: str = "", source: str = "scene") -> Any:
    """The :class:`~vibroimpact.scene.schema.Scene` of a concepts scene (its ``concepts`` attribute holds the
    :class:`ConceptsSettings`; :attr:`Scene.kind` is then ``concepts``)."""
    from vibroimpact.scene.schema import Scene

    name, description, report, settings, scheduler = parse_concepts(document, source)
    return Scene(
        name=name, description=description, layout=Layout(settings.system), amplitude=settings.amplitude, kind="concepts", settings=settings, report=report, text=text,
        cluster_scheduler=scheduler,
    )  # fmt: skip


def _simulation(c: Checker, value: Any, frequency: np.ndarray | None) -> tuple[np.ndarray, EngineSettings, SteadySettings] | None:
    if isinstance(value, dict):
        for key in sorted(set(value) & set(_UNUSED_SIMULATION_KEYS)):
            c.fail(f"simulation.{key}", f"not used by the concepts kind: {_UNUSED_SIMULATION_KEYS[key]}")
        value = {key: item for key, item in value.items() if key not in _UNUSED_SIMULATION_KEYS}
    thinned = frequency[:: max(1, frequency.size // 61)] if frequency is not None else None
    settings = parse_simulation(c, value, thinned, allowed=_SIMULATION_KEYS)
    if settings is None:
        return None
    if settings.frequency.size > MAX_SIMULATION_POINTS:
        c.fail("simulation.frequency", f"{settings.frequency.size} points is too many: allowed at most {MAX_SIMULATION_POINTS} (raise the step)")
        return None
    return settings.frequency, settings.engine, settings.steady


def _concepts(c: Checker, value: Any, system: System) -> tuple[Concept, ...]:
    if len(value) > MAX_CONCEPTS:
        c.fail("concepts", f"{len(value)} concepts is too many: allowed at most {MAX_CONCEPTS}")
        return ()
    concepts: list[Concept] = []
    for i, entry in enumerate(value):
        key = f"concepts[{i}]"
        spec = CONCEPT_ROW.at(key).read(c, entry)
        if spec is None:
            continue
        name = spec["name"]
        if not NAME.match(name):
            c.fail(f"{key}.name", f"expected a file-name-safe string (letters, digits, '_', '-', '.'), got {name!r}")
            continue
        if name in [concept.name for concept in concepts]:
            c.fail(f"{key}.name", f"{name!r} is used twice: names must be unique")
            continue
        label = spec["label"] if spec["label"] is not None else name
        built = _absorber(c, f"{key}.absorber", spec["absorber"] if spec["absorber"] is not None else {}, system)
        stops = _stops(c, f"{key}.stops", spec["stops"], system.coordinates) if spec["stops"] is not None else ()
        if built is not None and stops is not None:
            concepts.append(Concept(name, label, built[0], stops, built[1]))
    return tuple(concepts)


def _absorber(c: Checker, key: str, value: Any, system: System) -> tuple[System, str] | None:
    spec = CONCEPT_ABSORBER.at(key).read(c, value)
    if spec is None:
        return None
    spec = {part: item for part, item in spec.items() if item is not None}
    optimum = den_hartog_absorber(system.m1, system.k1, system.m2)
    chosen = {"stiffness": system.k2, "damping": system.b2}
    words = {"stiffness": f"k2 = {system.k2:g} N/m", "damping": f"b2 = {system.b2:g} N s/m"}
    for part, (low_inclusive, best, unit, why) in {
        "stiffness": (False, optimum.stiffness, "N/m", f"Den Hartog's tuning f = 1/(1 + mu) = {optimum.tuning:.4f}"),
        "damping": (True, optimum.damping, "N s/m", f"Den Hartog's zeta = sqrt(3 mu / (8 (1 + mu)^3)) = {optimum.damping_ratio:.4f}"),
    }.items():
        if part not in spec:
            continue
        item = spec[part]
        if item == "den_hartog":
            chosen[part], words[part] = best, f"{'k2' if part == 'stiffness' else 'b2'} = {best:.4g} {unit} ({why})"
        else:
            number = c.number(f"{key}.{part}", item, 0.0, math.inf, low_inclusive=low_inclusive) if not isinstance(item, str) else None
            if isinstance(item, str):
                c.fail(f"{key}.{part}", f"{item!r} is not allowed: a number [{unit}] or den_hartog")
            if number is None:
                return None
            chosen[part], words[part] = number, f"{'k2' if part == 'stiffness' else 'b2'} = {number:g} {unit}"
    built = system.with_absorber(chosen["stiffness"], chosen["damping"])
    try:
        built.check_ratios()
    except ValueError as error:  # a ratio beyond double precision (model/system.py)
        c.fail(key, str(error).partition(": ")[2])
        return None
    return built, ", ".join(words.values())


def _stops(c: Checker, key: str, value: Any, names: tuple[str, ...]) -> tuple[Stop, ...] | None:
    """A concept's rigid stops in the shared ``stops`` grammar (:func:`~vibroimpact.scene.layout_parse.parse_stops`),
    each giving its clearance (> 0) and restitution (> 0: the bumper twin's loss factor follows from it); a concept's
    bumper is the scene's ``bumper`` section, not a stop's."""
    specs = parse_stops(c, value, names, key)
    if specs is None:
        return None
    usable = True
    for k, spec in enumerate(specs):
        here = f"{key}[{k}]"
        if spec.clearance is None or spec.clearance <= 0.0:
            c.fail(f"{here}.clearance", "a concept's stop gives its clearance, > 0 [m] (a concepts scene sweeps none)")
            usable = False
        if spec.restitution is None or spec.restitution <= 0.0:
            c.fail(f"{here}.restitution", "a concept's stop gives its restitution, in (0, 1] (the bumper twin's loss factor follows from it)")
            usable = False
        if spec.bumper_frequency is not None or spec.bumper_loss_factor is not None:
            c.fail(f"{here}.bumper", "a concept's bumper twins are the scene's 'bumper' section: remove this stop's bumper")
            usable = False
    if not usable:
        return None
    return tuple(spec.stop(RigidStop(float(spec.clearance), float(spec.restitution))) for spec in specs)  # type: ignore[arg-type]
