"""Design scenes: the header of every scene, the layout with its own design (the stops' clearance and restitution,
the structure's values), and ``design``: which scalars to choose, within which bounds, to minimise what over which
band, under which mistuning, and compared with what.

The layout is written as in every scene (:mod:`vibroimpact.scene.layout_parse`): the paper's named form
(``system: {m1 ... b2}``, ``stop: {clearance, restitution}``: one stop above the absorber x2) or the general one
(``system: {mass, stiffness, damping, coordinates}``, ``stops: [...]``, each giving its clearance and restitution;
every stop shares them: one stop, or a symmetric two-sided pair, the layouts with a closed-form impact orbit). The
values the scene gives are *its design*: the page compares the optimum with it (the paper's scene: the paper's
design). Example (``studies/design_vs_linear.yaml``, shortened)::

    system: {m1: 1.0, m2: 0.1, k1: 25000, k2: 4300, b1: 0.8, b2: 0.08}
    excitation: {amplitude: 10.0}
    stop: {clearance: 0.003, restitution: 0.2}
    design:
      variables: {clearance: [0.5e-3, 8e-3], restitution: [0.0, 0.9], k2: [1000.0, 8000.0], b2: [0.0, 20.0]}
      band: {start: 15.0, stop: 45.0}                   # [Hz]
      objective: x1_amplitude                           # |X| of a coordinate (<name>_amplitude) or force_amplitude
      constraints: {operating: {frequency: 33.0, x1_amplitude: 0.05e-3}}   # the notch must survive
      robust: {k1: 0.05, samples: 32, seed: 1}          # +-5 % of k1, a seeded Latin hypercube
      compare: linear_optimum                           # the H-infinity optimum linear absorber of the same mass
      search: {method: differential_evolution, population: 8, generations: 25, seed: 1, polish: true}
      certify: {candidates: 1}

A variable is ``clearance`` [m], ``restitution`` [-], ``bumper_stiffness`` [N m-1] (stops with bumpers) or any layout
scalar (``k2``, ``b2``, ``m2``, ``spring[x1,x2]``, ``mass[x3]``, ...): a row of the parameter table
(:mod:`vibroimpact.model.parameters`), which gives its unit, its allowed bounds (a design narrows only the clearance,
to (0, inf), and a bumper's restitution, to (0, 1]) and how a mistuning spreads it. A mistuning (``robust``) names the
same scalars: a structural one by a relative spread (0.05: +-5 %), ``clearance`` [m] and ``restitution`` [-] by an
absolute one; ``samples`` points of a seeded Latin hypercube
over the spreads, plus the nominal design, and the objective is their worst (``quantile: 1``) or a stated quantile.
Every key is checked (unknown keys, wrong types and out-of-range values are reported together, each naming its key).
"""

from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import dataclass
from typing import Any

from vibroimpact.analysis.measures import Measure, measure, measure_names
from vibroimpact.model.layout import PAPER_STOP, Layout
from vibroimpact.model.parameters import BUMPER_STIFFNESS, LAYOUT_FORMS, MAX_RELATIVE_SPREAD, PARAMETERS, Parameter, parameter
from vibroimpact.model.structure import require_in_range
from vibroimpact.scene.checker import Checker, SceneError, did_you_mean
from vibroimpact.scene.declared import OPTIONAL, REQUIRED, Band, Key, Section, Table
from vibroimpact.scene.header import open_scene
from vibroimpact.scene.layout_parse import parse_layout
from vibroimpact.scene.schema import Scene

__all__ = ["DESIGN_TOP_KEYS", "DESIGN_STOP", "DESIGN", "ROBUST", "CONSTRAINTS", "OPERATING", "SEARCH", "CERTIFY", "SECTIONS", "STOP_VARIABLES", "BUMPER_VARIABLE", "METHODS", "COMPARISONS", "Variable", "Mistuning", "SearchSettings", "DesignSettings", "parse_design_scene", "safe_name"]

#: Top-level keys of a design scene.
DESIGN_TOP_KEYS = {"name", "description", "system", "excitation", "stop", "stops", "design", "report", "cluster"}
#: Design variables of the stops (every other variable is the bumpers' stiffness or a layout scalar).
STOP_VARIABLES = ("clearance", "restitution")
#: The bumpers' stiffness K_b [N m-1], a variable where the stops have bumpers (their loss factor follows R).
BUMPER_VARIABLE = BUMPER_STIFFNESS
#: Searches: a global search then a local polish, or every point of a grid over the variables (a map).
METHODS = ("differential_evolution", "grid")
#: What the optimum is compared with: the best linear absorber of the same mass (the paper's two masses), or nothing.
COMPARISONS = ("linear_optimum", "none")
#: ``design``, declared (:mod:`vibroimpact.scene.declared`); its mappings are declared sections of their own or
#: checked by their own parsers (the variables, whose names are the layout's).
DESIGN = Section("design", (
    Key("variables", Table, "{scalar: [low, high]}: what the search chooses (clearance, restitution, bumper_stiffness or a layout scalar; at most 6)",
        REQUIRED),
    Key("band", Band, "the band whose worst stable motion is judged", REQUIRED, 0.0, math.inf, "Hz", open_low=True),
    Key("objective", str, "what is minimised, the worst stable motion's over the band: <coordinate>_amplitude [m] or force_amplitude [N]", "x1_amplitude"),
    Key("constraints", Table, "{operating: {frequency, <measure>: largest value}} (design.constraints)", OPTIONAL),
    Key("robust", Table, "{<scalar>: spread, samples, seed, quantile}: the mistuning (design.robust)", OPTIONAL),
    Key("compare", str, "what the optimum is compared with: the best linear absorber of the same mass, or nothing", "none", choices=COMPARISONS),
    Key("search", Table, "how candidates are chosen (design.search)", OPTIONAL),
    Key("certify", Table, "which candidates are certified (design.certify)", OPTIONAL),
), "which scalars to choose, within which bounds, to minimise what over which band")  # fmt: skip
#: ``design.robust``, declared: the spreads are the scalars' own keys.
ROBUST = Section("design.robust", (
    Key("samples", int, "Latin-hypercube samples of the mistuning (required with a spread)", 0, 0, 4096),
    Key("seed", int, "the Latin hypercube's seed", 1, 0, 2**31 - 1),
    Key("quantile", float, "the objective over the samples: 1 their worst, less a quantile", 1.0, 0.0, 1.0, open_low=True),
), "the mistuning the objective is judged over",
    others="a spread per scalar: relative for a structural one (0.05: +-5 %), absolute for clearance [m] and restitution [-]")  # fmt: skip
#: ``design.constraints``, declared.
CONSTRAINTS = Section("design.constraints", (
    Key("operating", Table, "{frequency, <measure>: largest value}: the notch that must survive (design.constraints.operating)", OPTIONAL),
), "what every design must keep")  # fmt: skip
#: ``design.constraints.operating``, declared: the limit is the measure's own key.
OPERATING = Section("design.constraints.operating", (
    Key("frequency", float, "the operating frequency", REQUIRED, 0.0, math.inf, "Hz", open_low=True),
), "the operating point's limit, judged as the objective is (its worst case over the mistuning)",
    others="one largest value of a measure, > 0: <coordinate>_amplitude [m] or force_amplitude [N]")  # fmt: skip
_EVOLUTION = ("method", "differential_evolution")
#: ``design.search``, declared (:mod:`vibroimpact.scene.declared`): the keys of one method are refused with the other.
SEARCH = Section("design.search", (
    Key("method", str, "how candidates are chosen: a global search then a local polish, or every point of a grid", "differential_evolution", choices=METHODS),
    Key("population", int, "members of each generation per design variable", 8, 4, 100, read_when=_EVOLUTION),
    Key("generations", int, "generations at most", 25, 1, 1000, read_when=_EVOLUTION),
    Key("seed", int, "the search's random seed", 1, 0, 2**31 - 1, read_when=_EVOLUTION),
    Key("polish", bool, "a Nelder-Mead polish of the best candidate after the search", True, read_when=_EVOLUTION),
    Key("points", int, "grid points per design variable", 12, 2, 200, read_when=("method", "grid")),
), "how candidates are chosen")  # fmt: skip
#: ``design.certify``, declared.
CERTIFY = Section("design.certify", (
    Key("candidates", int, "the best candidates certified by continuation, brute force and the tolerance box's corners", 1, 0, 20),
), "which candidates are certified")  # fmt: skip
#: The paper's ``stop`` of a design scene, declared: the design's starting values (a variable moves them).
DESIGN_STOP = Section("stop", (
    Key("clearance", float, "Delta, the stop's gap above the absorber x2", REQUIRED, 0.0, math.inf, "m", open_low=True),
    Key("restitution", float, "R of each impact (above 0 with a bumper)", REQUIRED, 0.0, 1.0),
    Key("bumper", Table, "{frequency: Hz} or {stiffness: N/m}: a Kelvin-Voigt bumper whose loss factor follows R (default: a rigid stop)", OPTIONAL),
), "the paper's stop above the absorber x2 (or 'stops': one, or a symmetric pair)", form="design")  # fmt: skip
#: The sections of a design scene that are declared (``run-study --keys`` lists them).
SECTIONS = (DESIGN_STOP, DESIGN, CONSTRAINTS, OPERATING, ROBUST, SEARCH, CERTIFY)
#: Most evaluations of one scene's search (candidates x mistuning samples).
MAX_EVALUATIONS = 2_000_000


def safe_name(name: str) -> str:
    """A variable's name as a netCDF-safe suffix: ``spring[x1,x2]`` -> ``spring_x1_x2``."""
    return re.sub(r"\W+", "_", name).strip("_")


@dataclass(frozen=True)
class Variable:
    """A design variable and its bounds.

    Attributes
    ----------
    name : str
        ``clearance``, ``restitution`` or a layout scalar (module docstring).
    low, high : float
        Bounds [unit], low < high.
    unit : str
        UDUNITS string (``m``, ``1``, ``N m-1``, ``N s m-1``, ``kg``).
    """

    name: str
    low: float
    high: float
    unit: str

    def __post_init__(self) -> None:
        if not (math.isfinite(self.low) and math.isfinite(self.high) and self.low < self.high):
            raise ValueError(f"variable {self.name!r}: bounds [{self.low!r}, {self.high!r}] must be finite with low < high")


@dataclass(frozen=True)
class Mistuning:
    """How far one scalar may be from the drawing.

    Attributes
    ----------
    name : str
        As a :class:`Variable` names it.
    spread : float
        Half-width: relative [-] for a structural scalar (0.05: +-5 %), absolute [m] or [-] for ``clearance`` and
        ``restitution``.
    relative : bool
        The spread is relative.
    """

    name: str
    spread: float
    relative: bool

    def __post_init__(self) -> None:
        limit = MAX_RELATIVE_SPREAD if self.relative else math.inf
        if not 0.0 < require_in_range(f"robust.{self.name}", self.spread, 0.0, limit):
            raise ValueError(f"robust.{self.name} = {self.spread!r} is out of range: allowed (0, {limit:g}]")


@dataclass(frozen=True)
class SearchSettings:
    """How candidates are chosen: ``method`` of :data:`METHODS`; for differential evolution ``population`` (members
    per variable) and ``generations``, seeded, then a local polish; for a grid ``points`` per variable."""

    method: str = SEARCH.key("method").default
    population: int = SEARCH.key("population").default
    generations: int = SEARCH.key("generations").default
    seed: int = SEARCH.key("seed").default
    polish: bool = SEARCH.key("polish").default
    points: int = SEARCH.key("points").default

    def __post_init__(self) -> None:
        SEARCH.validate(self)  # the scene's own checks: a string is no boolean, 4.5 no population


@dataclass(frozen=True)
class DesignSettings:
    """What a design scene asks (module docstring).

    Attributes
    ----------
    variables : tuple of Variable
        What is chosen, and within which bounds.
    band : (float, float)
        [Hz].
    measure : Measure
        What the objective judges: a row of the measure table (:mod:`vibroimpact.analysis.measures`), |X| of a
        coordinate or the force to the base.
    objective : str
        Its name, ``<coordinate>_amplitude`` or ``force_amplitude``.
    operating : (float, float) or None
        (frequency [Hz], largest allowed value of ``constraint`` there [its unit]): the absorber's notch must survive,
        on the same worst-case basis as the objective; None: no constraint.
    mistuning : tuple of Mistuning
        The robustness spreads (empty: the nominal design alone).
    samples : int
        Latin-hypercube samples of the mistuning (the nominal design is evaluated besides them).
    seed : int
        Of the Latin hypercube.
    quantile : float
        The objective over the samples: 1 their worst, less a quantile.
    compare : str
        One of :data:`COMPARISONS`.
    search : SearchSettings
    certified : int
        At most this many distinct candidates (best screened first) have their worst case certified by continuation
        and brute force, one at a time until no later candidate can beat the best certified one.
    clearance, restitution : float
        The scene's own design of the stops: Delta [m], R [-].
    bumper_frequency : float or None
        Omega_b / 2 pi [Hz] of the stops' Kelvin-Voigt bumpers (their loss factor the exact inverse of R); None: rigid
        stops.
    constraint : Measure or None
        What the operating constraint judges (None: |X1|, the primary's notch).
    """

    variables: tuple[Variable, ...]
    band: tuple[float, float]
    measure: Measure
    objective: str
    operating: tuple[float, float] | None
    mistuning: tuple[Mistuning, ...]
    samples: int
    seed: int
    quantile: float
    compare: str
    search: SearchSettings
    certified: int
    clearance: float
    restitution: float
    bumper_frequency: float | None = None
    constraint: Measure | None = None

    def __post_init__(self) -> None:
        if not self.variables:
            raise ValueError("variables: give at least one design variable")
        if not 0.0 < self.band[0] < self.band[1]:
            raise ValueError(f"band = {self.band!r} must be 0 < start < stop [Hz]")
        if not 0.0 < require_in_range("quantile", self.quantile, 0.0, 1.0):
            raise ValueError(f"quantile = {self.quantile!r} is out of range: allowed (0, 1]")
        if self.compare not in COMPARISONS:
            raise ValueError(f"compare: {self.compare!r} is not one of {COMPARISONS}")

    @property
    def names(self) -> tuple[str, ...]:
        """The variables' names, in order."""
        return tuple(v.name for v in self.variables)


def parse_design_scene(document: dict, text: str = "", source: str = "scene") -> Scene:
    """Validate a design scene's document (a mapping with ``design``) and build the :class:`Scene`; raise
    :class:`SceneError` listing all problems."""
    c, doc, name, description, report, scheduler = open_scene(document, DESIGN_TOP_KEYS, {"name", "system", "excitation", "design"}, "design")
    layout, amplitude, coordinates = parse_layout(c, doc)
    clearance, restitution, bumper = _stop_values(c, doc, layout)
    spec = (DESIGN.read(c, doc["design"], partial=True) if "design" in doc else None) or {}
    variables = _variables(c, spec["variables"], layout, bumper) if spec.get("variables") is not None else ()
    band = spec.get("band")
    objective_measure = _objective(c, spec.get("objective") or DESIGN.key("objective").default, coordinates)
    operating, constraint = _operating(c, spec.get("constraints") or {}, coordinates, band)
    _check_measures(c, layout, (("design.objective", objective_measure), ("design.constraints.operating", constraint)))
    mistuning, samples, seed, quantile = _robust(c, spec.get("robust") or {}, layout, bumper)
    compare = spec.get("compare") or DESIGN.key("compare").default
    if compare == "linear_optimum" and layout is not None and layout.paper_view() is None:
        c.fail("design.compare", "linear_optimum is the optimum absorber of the paper's two masses (system: {m1 ... b2}); this structure is not one: use none")
    elif compare == "linear_optimum" and objective_measure.coordinate not in (None, 0):
        c.fail("design.compare", f"linear_optimum minimises the objective's {objective_measure.name} over linear absorbers of the same mass, and it has no minimum: "
                                 "the absorber's own motion falls without end as its spring and dashpot are loosened (a detached absorber moves least): use none")
    search = _search(c, spec.get("search"))
    certified = _certify(c, spec.get("certify"))
    if search is not None and variables and samples is not None:
        count = (search.points ** len(variables) if search.method == "grid" else search.population * len(variables) * (search.generations + 1) * 2) * (samples + 1)
        if count > MAX_EVALUATIONS:
            c.fail("design.search", f"{count:.3g} closed-form evaluations is too many: allowed at most {MAX_EVALUATIONS:.0e} (fewer points, generations or samples)")
    if c.problems:
        raise SceneError(c.problems, source)
    assert layout is not None and amplitude is not None and isinstance(name, str) and band is not None and search is not None
    assert clearance is not None and restitution is not None and samples is not None and seed is not None and quantile is not None and certified is not None
    settings = DesignSettings(variables, band, objective_measure, objective_measure.name, operating, mistuning, samples, seed, quantile, str(compare), search, certified, clearance,
                              restitution, bumper, constraint)  # fmt: skip
    return Scene(name=name, description=description, layout=layout, amplitude=amplitude, kind="design", settings=settings, report=report, text=text,
                 cluster_scheduler=scheduler)


def _stop_values(c: Checker, doc: dict, layout: Layout | None) -> tuple[float | None, float | None, float | None]:
    """The stops' shared clearance [m], restitution [-] and bumper Omega_b / 2 pi [Hz] (None: rigid stops): the
    paper's ``stop`` gives them, or every entry of ``stops`` gives the same. A bumper's loss factor is the exact
    inverse of the restitution (a design variable moves both), so it gives its stiffness or frequency alone."""
    if "stop" not in doc and "stops" not in doc:
        c.fail("stop", "required: the paper's stop {clearance: Delta [m], restitution: R} above the absorber x2, or 'stops' (one, or a symmetric pair)")
        return None, None, None
    if "stops" not in doc:
        stop = DESIGN_STOP.read(c, doc["stop"], partial=True)
        if stop is None:
            return None, None, None
        clearance, restitution = stop["clearance"], stop["restitution"]
        bumper = _bumper(c, "stop.bumper", stop["bumper"], layout) if stop["bumper"] is not None else None
        if bumper is not None and restitution is not None and restitution <= 0.0:
            c.fail("stop.restitution", "0 with a bumper: a bumper's restitution must be above 0 (R = 0 needs an infinite loss factor): allowed (0, 1]")
        return clearance, restitution, bumper
    if layout is None:
        return None, None, None
    values = [(spec.clearance, spec.restitution) for spec in layout.stops]
    if any(v is None for pair in values for v in pair) or len(set(values)) != 1:
        c.fail("stops", "every stop of a design scene gives the same clearance and restitution (the design's; the variables move them together)")
        return None, None, None
    bumpers = {spec.bumper_frequency for spec in layout.stops}
    if len(bumpers) != 1 or any(spec.bumper_loss_factor is not None or spec.bumper_damping is not None for spec in layout.stops):
        c.fail("stops", "every stop of a design scene is rigid, or every one has a bumper of the same frequency (or stiffness) without its own loss factor or damping (the restitution gives it)")
        return None, None, None
    bumper = bumpers.pop()
    if bumper is not None and float(values[0][1]) <= 0.0:  # type: ignore[arg-type]
        c.fail("stops", "restitution 0 with bumpers: a bumper's restitution must be above 0 (R = 0 needs an infinite loss factor): allowed (0, 1]")
        return None, None, None
    return float(values[0][0]), float(values[0][1]), bumper  # type: ignore[arg-type]


def _bumper(c: Checker, key: str, value: Any, layout: Layout | None) -> float | None:
    """The design's bumper Omega_b / 2 pi [Hz] from ``{frequency: Hz}`` or ``{stiffness: N/m}`` (the paper's stop,
    effective mass m2)."""
    if isinstance(value, dict) and set(value) & {"loss_factor", "damping"}:
        c.fail(key, f"{', '.join(sorted(set(value) & {'loss_factor', 'damping'}))}: a design's bumper takes its loss from the restitution (a variable may move it): give frequency [Hz] or stiffness [N/m] alone")
        return None
    from vibroimpact.scene.bumper_parse import parse_bumper

    mass = PAPER_STOP.effective_mass(layout.structure) if layout is not None else None
    spec = parse_bumper(c, key, value, mass)
    if spec is None:
        return None
    if spec.frequency is None:
        c.fail(key, "give frequency [Hz] or stiffness [N/m]")
    return spec.frequency


def _variables(c: Checker, value: Any, layout: Layout | None, bumper: float | None) -> tuple[Variable, ...]:
    spec = value if isinstance(value, dict) and value else None
    if spec is None:
        c.fail("design.variables", f"expected a mapping of at least one name to [low, high], got {value!r}")
        return ()
    out = []
    for key, bounds in spec.items():
        name = str(key)
        row = _design_row(c, f"design.variables.{name}", name, layout, bumper)
        if row is None:
            continue
        if not (isinstance(bounds, list) and len(bounds) == 2):
            c.fail(f"design.variables.{name}", f"expected [low, high], got {bounds!r}")
            continue
        low_value = c.number(f"design.variables.{name}[0]", bounds[0], row.low, row.high, row.low_inclusive, row.high_inclusive)
        high_value = c.number(f"design.variables.{name}[1]", bounds[1], row.low, row.high, low_inclusive=False, high_inclusive=row.high_inclusive)
        if low_value is None or high_value is None:
            continue
        if not low_value < high_value:
            c.fail(f"design.variables.{name}", f"low = {low_value:g} must be below high = {high_value:g}")
            continue
        out.append(Variable(name, low_value, high_value, row.unit))
    if len(out) > 6:
        c.fail("design.variables", f"{len(out)} variables: allowed at most 6 (a global search in more dimensions needs more evaluations than a study should)")
    return tuple(out)


def _design_row(c: Checker, key: str, name: str, layout: Layout | None, bumper: float | None = None) -> Parameter | None:
    """The parameter table's row of the design scalar ``name`` (None, with a problem recorded, if a design cannot
    choose it): ``clearance`` narrowed to (0, inf) (the closed forms' stops are apart from the structure), ``restitution``
    to (0, 1] on bumpers (R = 0 needs an infinite loss factor), ``bumper_stiffness`` where the stops have bumpers
    (``bumper``: their Omega_b / 2 pi [Hz]), or a layout scalar the structure has."""
    if name in STOP_VARIABLES:
        row = PARAMETERS[name]
        if name == "clearance":
            return dataclasses.replace(row, low=0.0, low_inclusive=False)
        return row if bumper is None else dataclasses.replace(row, low_inclusive=False)
    if name == BUMPER_VARIABLE:
        if bumper is None:
            c.fail(key, f"{name}: the stops are rigid; give the stop a bumper (stop: {{clearance, restitution, bumper: {{stiffness: K_b [N/m]}}}}) to choose its stiffness")
            return None
        return PARAMETERS[name]
    if not LAYOUT_FORMS.match(name.replace(" ", "")):
        c.fail(key, f"unknown design variable {name!r}: allowed clearance, restitution, bumper_stiffness (a stop with a bumper), or a layout scalar (k2, b2, m2, ... on the paper's system; mass[a], spring[a,b], dashpot[a], stiffness[a,b], damping[a] on any)")
        return None
    if layout is None:
        return None
    from vibroimpact.model.problem import ImpactProblem  # model layer: reading a scene loads no solver

    try:
        problem = layout.problem(1.0, 1.0, 0.5, 1.0)
        return parameter(name, problem) if isinstance(problem, ImpactProblem) else None
    except ValueError as error:
        c.fail(key, str(error))
        return None


def _objective(c: Checker, value: Any, coordinates: tuple[str, ...] | None) -> Measure:
    names = coordinates or ("x1", "x2")
    allowed = measure_names(names)
    if value not in allowed:
        c.fail("design.objective", f"{value!r} is not allowed: use one of {', '.join(allowed)} (|X| of a coordinate or the force to the base, the worst stable motion's over the band)")
        return measure(allowed[0], names)
    return measure(str(value), names)


def _operating(c: Checker, value: Any, coordinates: tuple[str, ...] | None, band: tuple[float, float] | None) -> tuple[tuple[float, float] | None, Measure | None]:
    """(frequency [Hz], largest allowed value [its unit]) of the operating constraint and the measure it limits (any
    row of the measure table: |X1| keeps the primary's notch)."""
    constraints = CONSTRAINTS.read(c, value)
    if constraints is None or constraints["operating"] is None:
        return None, None
    names = coordinates or ("x1", "x2")
    limits = measure_names(names)
    spec = constraints["operating"]
    read = OPERATING.read(c, spec, partial=True)
    limit_keys = [str(k) for k in spec if str(k) not in OPERATING.names and not OPERATING.misspelt(str(k))]
    for unknown in (k for k in limit_keys if k not in limits):
        c.fail(f"design.constraints.operating.{unknown}", f"unknown key (allowed: frequency, {', '.join(limits)}){did_you_mean(unknown, ('frequency', *limits))}")
    limit_keys = [k for k in limit_keys if k in limits]
    if len(limit_keys) != 1:
        c.fail("design.constraints.operating", f"give the frequency [Hz] and one largest amplitude [m] or force [N] ({', '.join(limits)})")
        return None, None
    frequency = read["frequency"] if read is not None else None
    limit = c.number(f"design.constraints.operating.{limit_keys[0]}", spec[limit_keys[0]], 0.0, math.inf, low_inclusive=False)
    limited = measure(limit_keys[0], names)
    return ((frequency, limit) if frequency is not None and limit is not None else None), limited


def _check_measures(c: Checker, layout: Layout | None, rows: tuple[tuple[str, Measure | None], ...]) -> None:
    """Each measure can be read on the layout's problem (the force to the base is refused under a base motion)."""
    if layout is None:
        return
    from vibroimpact.model.problem import ImpactProblem  # model layer: reading a scene loads no solver

    problem = layout.problem(1.0, 1.0, 0.5, 1.0)
    for key, row in rows:
        reason = row.refusal(problem) if row is not None and isinstance(problem, ImpactProblem) else None
        if reason is not None:
            c.fail(key, reason)


def _robust(c: Checker, value: Any, layout: Layout | None, bumper: float | None = None) -> tuple[tuple[Mistuning, ...], int | None, int | None, float | None]:
    read = ROBUST.read(c, value, partial=True)
    if read is None:
        return (), None, None, None
    spreads = [str(k) for k in value if str(k) not in ROBUST.names and not ROBUST.misspelt(str(k))]  # a misspelling is said by the read
    if spreads and "samples" not in value:
        c.fail("design.robust.samples", "required with a spread: how many Latin-hypercube samples (e.g. 32)")
    samples, seed, quantile = read["samples"], read["seed"], read["quantile"]
    out = []
    for name in spreads:
        row = _design_row(c, f"design.robust.{name}", name, layout, bumper)
        if row is None:
            continue
        number = c.number(f"design.robust.{name}", value[name], 0.0, row.spread_limit, low_inclusive=False, high_inclusive=not row.relative_spread)
        if number is not None:
            out.append(Mistuning(name, number, row.relative_spread))
    if out and samples == 0:
        c.fail("design.robust.samples", "0 samples of a mistuning: give at least 1 (a Latin hypercube over the spreads)")
    return tuple(out), samples if out else 0, seed, quantile


def _search(c: Checker, value: Any) -> SearchSettings | None:
    values = SEARCH.read(c, value if value is not None else {})  # None: not given, or said already
    return SearchSettings(**values) if values is not None else None


def _certify(c: Checker, value: Any) -> int | None:
    values = CERTIFY.read(c, value if value is not None else {})
    return values["candidates"] if values is not None else None
