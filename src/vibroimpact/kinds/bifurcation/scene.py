"""Bifurcation scenes: the header of every scene, the layout, and ``bifurcation`` (brute force, continued branches and
the two-parameter chart).

The layout is written as in stepped scenes (:mod:`vibroimpact.scene.layout_parse`, the same parsers): the paper's
named form (``system: {m1 ... b2}``, ``excitation: {amplitude}``, ``stop: {clearance}``: one upper stop on x2, the
force on x1), or the general one (``system: {mass, stiffness, damping, coordinates}``, ``excitation: {amplitude, on |
base_motion, static}``, ``stops: [...]``). Every stop is rigid and shares one clearance Delta > 0 (the chart varies
it) and one restitution: the diagrams' ``bifurcation.restitution`` (then no stop gives its own), or, without that
key, the value every stop gives.

``bifurcation.bumper: {frequency: [Omega_b / 2 pi, ...]}`` [Hz] makes every stop a Kelvin-Voigt bumper: for each
restitution and each bumper frequency, the branches of the layout with bumpers of that frequency and the loss factor
whose collision restitution is R (corrected eq. 26), started from the rigid stop's closed-form orbit continued in the
bumper's stiffness and continued on the bumper's exact stroboscopic map, and the brute force of that bumper (its
closed-form engine). ``bifurcation.reference: rigid`` adds the rigid stop's own diagram (branches, special points and
brute force) as the reference the bumpers' converge to, and the curves of the stiffest bumper's special points in its
stiffness (``studies/bifurcation_bumper.yaml``); ``none``, the default, runs the bumpers alone. No chart with bumpers.

Example (the shipped ``bifurcation``, shortened)::

    name: bifurcation
    system: {m1: 1.0, m2: 0.1, k1: 25000, k2: 4300, b1: 0.8, b2: 0.08}
    excitation: {amplitude: 10.0}
    stop: {clearance: 0.003}
    bifurcation:
      frequency: {start: 15.0, stop: 45.0}          # the band [Hz]
      restitution: [0.2, 0.8]
      brute_force: {step: 0.05, transient_periods: 300, strobes: 64, directions: [up, down]}
      continuation: {one_impact: true, period_doubling: true, grazing: true, linear: true, brute_force: true, max_steps: 2000}
      chart: {restitution: 0.2, clearance: {start: 0.001, stop: 0.006}, kinds: [fold, neimark_sacker, grazing]}

and with relative two-sided stops (``studies/bifurcation_relative_stop.yaml``)::

    system: {mass: [[1.0, 0.0], [0.0, 0.1]], stiffness: [[29300, -4300], [-4300, 4300]], damping: [[0.88, -0.08], [-0.08, 0.08]], coordinates: [x1, x2]}
    excitation: {amplitude: 10.0, on: x1}
    stops:
      - {between: [x2, x1], side: upper, clearance: 0.003}
      - {between: [x2, x1], side: lower, clearance: 0.003}
    bifurcation: {frequency: {start: 15.0, stop: 45.0}, restitution: [0.2], ...}

Every key is checked (unknown keys, wrong types and out-of-range values are reported together, each naming its key).
"""

from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import dataclass
from typing import Any, TypeVar

import numpy as np

from vibroimpact.scene.checker import Checker, SceneError
from vibroimpact.scene.declared import DERIVED, OPTIONAL, REQUIRED, Band, Grid, Key, Names, Section, Table
from vibroimpact.model.contact import place_effective_mass
from vibroimpact.model.layout import Layout, StopSpec
from vibroimpact.scene.header import open_scene
from vibroimpact.scene.layout_parse import parse_layout, static_drift
from vibroimpact.scene.schema import SWEEP_DIRECTIONS, Scene

__all__ = ["BIFURCATION_TOP_KEYS", "CHART_KINDS", "REFERENCES", "BIFURCATION", "BRUTE_FORCE", "CONTINUATION", "CHART", "BIFURCATION_STOP", "SECTIONS", "BruteForceSettings", "BranchSettings", "ChartSettings", "BifurcationSettings", "coordinate_label", "parse_bifurcation_scene"]


# --------------------------------------------------------------------------------------------------------------------
# What a bifurcation scene says, as frozen dataclasses: the brute force, the continued branches and the
# two-parameter chart (the parser, :mod:`vibroimpact.kinds.bifurcation.scene`, builds them from checked values).
# --------------------------------------------------------------------------------------------------------------------

#: Top-level keys of a bifurcation scene (``stop`` is the paper's stop on x2, ``stops`` any layout).
BIFURCATION_TOP_KEYS = {"name", "description", "system", "excitation", "stop", "stops", "bifurcation", "report"}
#: Special points whose curves the two-parameter chart can follow (the order of the CF flags of ``special_point_kind``).
CHART_KINDS = ("fold", "period_doubling", "neimark_sacker", "grazing")
#: Values of ``bifurcation.reference`` (with bumpers): the rigid stop's diagram beside the bumpers', or none.
REFERENCES = ("rigid", "none")
#: Most brute-force periods of one scene (frequencies x restitutions x directions x periods per point).
MAX_BRUTE_PERIODS = 50_000_000
_Settings = TypeVar("_Settings")


def coordinate_label(name: str) -> str:
    """How a bifurcation study's texts name a coordinate: ``X1`` for ``x1`` (a letter and digits, capitalised, as
    the paper writes them), any other name as it is (``floor2``)."""
    return name.upper() if re.fullmatch(r"[a-z][0-9]+", name) else name


#: ``bifurcation.brute_force``, declared (:mod:`vibroimpact.scene.declared`).
BRUTE_FORCE = Section("bifurcation.brute_force", (
    Key("step", float, "frequency step of the stepped sweeps", 0.05, 0.0, math.inf, "Hz", open_low=True),
    Key("transient_periods", int, "periods integrated and dropped at each frequency", 300, 0, 1_000_000),
    Key("strobes", int, "strobes (whole periods) kept at each frequency", 64, 1, 100_000),
    Key("directions", Names, "which ways the frequency is stepped, the end state carried to the next", ("up", "down"), choices=SWEEP_DIRECTIONS),
), "stepped sweeps of the time simulation (exact)")  # fmt: skip
#: ``bifurcation.continuation``, declared.
CONTINUATION = Section("bifurcation.continuation", (
    Key("one_impact", bool, "the closed-form impact orbit's branches, from both roots of eq. 16", True),
    Key("period_doubling", bool, "period-2 branches switched at every period doubling", True),
    Key("grazing", bool, "branches born at grazing points with another impact count", True),
    Key("linear", bool, "the impactless orbit wherever it fits inside every stop", True),
    Key("brute_force", bool, "branches seeded from the brute force's periodic strobes", True),
    Key("max_steps", int, "continuation steps per direction of a branch, at most", 2000, 1, 100_000),
    Key("max_step", float, "largest arclength step, in the continuation's scaled variables", 0.1, 1e-4, 1.0),
), "which branches are continued in frequency, and how far")  # fmt: skip
#: ``bifurcation.chart``, declared.
CHART = Section("bifurcation.chart", (
    Key("restitution", float, "R of the chart", 0.2, 0.0, 1.0),
    Key("clearance", Band, "clearance range of the chart", (1e-3, 6e-3), 0.0, 1.0, "m", open_low=True),
    Key("kinds", Names, "special points followed in (frequency, clearance)", CHART_KINDS, choices=CHART_KINDS),
    Key("max_steps", int, "continuation steps per direction of a curve, at most", 300, 1, 100_000),
    Key("frequency_step", float, "frequency step of the regime map's brute-force sweeps", 0.25, 0.0, math.inf, "Hz", open_low=True),
    Key("clearance_num", int, "clearances of the regime map, evenly spaced over the range", 12, 2, 1000),
    Key("transient_periods", int, "periods dropped at each point of the regime map", 300, 0, 1_000_000),
    Key("strobes", int, "periods kept for the classification at each point of the regime map", 128, 64, 100_000),
), "the two-parameter chart (frequency x clearance at one restitution)")  # fmt: skip
#: ``bifurcation``, declared; its mappings are declared sections of their own, or (the bumpers) checked by their parser.
BIFURCATION = Section("bifurcation", (
    Key("frequency", Band, "the band the diagrams span", REQUIRED, 0.0, math.inf, "Hz", open_low=True),
    Key("restitution", Grid, "R of each diagram, the same for every stop (derived: the stops' own)", DERIVED, 0.0, 1.0),
    Key("brute_force", Table, "stepped sweeps of the time simulation (bifurcation.brute_force)", OPTIONAL),
    Key("continuation", Table, "which branches are continued (bifurcation.continuation)", OPTIONAL),
    Key("chart", Table, "the two-parameter chart, frequency x clearance (bifurcation.chart); rigid stops only", OPTIONAL),
    Key("bumper", Table, "{frequency: [Hz, ...]} or {stiffness: [N/m, ...]}: Kelvin-Voigt bumpers' diagrams (default: the rigid stop's)", OPTIONAL),
    Key("reference", str, "rigid: the rigid stop's diagram beside the bumpers', as their reference", "none", choices=REFERENCES),
), "the diagrams: which band, which restitutions, which contact models")  # fmt: skip
#: The paper's ``stop`` of a bifurcation scene, declared (R is the diagrams', bifurcation.restitution).
BIFURCATION_STOP = Section("stop", (
    Key("clearance", float, "Delta, the stop's gap above the absorber x2", REQUIRED, 0.0, math.inf, "m", open_low=True),
), "the paper's stop above the absorber x2 (or 'stops': any layout)", form="bifurcation")  # fmt: skip
#: The sections of a bifurcation scene that are declared (``run-study --keys`` lists them).
SECTIONS = (BIFURCATION_STOP, BIFURCATION, BRUTE_FORCE, CONTINUATION, CHART)


@dataclass(frozen=True)
class BruteForceSettings:
    """Stepped sweeps of the time simulation (``exact``), the end state carried to the next frequency: the keys of
    :data:`BRUTE_FORCE` (``step`` [Hz], ``transient_periods``, ``strobes``, ``directions``: ``up`` and/or ``down``),
    checked by the scene's own checks."""

    step: float = BRUTE_FORCE.key("step").default
    transient_periods: int = BRUTE_FORCE.key("transient_periods").default
    strobes: int = BRUTE_FORCE.key("strobes").default
    directions: tuple[str, ...] = BRUTE_FORCE.key("directions").default

    def __post_init__(self) -> None:
        BRUTE_FORCE.validate(self)


@dataclass(frozen=True)
class BranchSettings:
    """Which branches are continued in frequency, and how far: the keys of :data:`CONTINUATION`.

    Attributes
    ----------
    one_impact : bool
        The branches of the closed-form impact orbit, started at both roots of eq. 16 (corrected): one impact per
        period on one stop, the symmetric two impacts per period on a two-sided stop; none where the layout has no
        closed form.
    period_doubling : bool
        Period-2 branches switched at every period doubling of a period-1 branch.
    grazing : bool
        Branches born at grazing points where an orbit with another (non-zero) impact count continues.
    linear : bool
        The impactless (linear) orbit wherever it fits inside every stop (closed form).
    brute_force : bool
        Branches seeded from the brute force: where a sweep's strobes repeat with a period k on an orbit no other
        branch passes through, that orbit continued as a fixed point of the k-period map.
    max_steps : int
        Most continuation steps per direction of a branch.
    max_step : float
        Largest arclength step, in the continuation's scaled variables [-].
    """

    one_impact: bool = CONTINUATION.key("one_impact").default
    period_doubling: bool = CONTINUATION.key("period_doubling").default
    grazing: bool = CONTINUATION.key("grazing").default
    linear: bool = CONTINUATION.key("linear").default
    brute_force: bool = CONTINUATION.key("brute_force").default
    max_steps: int = CONTINUATION.key("max_steps").default
    max_step: float = CONTINUATION.key("max_step").default

    def __post_init__(self) -> None:
        CONTINUATION.validate(self)


@dataclass(frozen=True)
class ChartSettings:
    """The two-parameter chart (frequency x clearance at one restitution): the keys of :data:`CHART`.

    Attributes
    ----------
    restitution : float
        R of the chart [-].
    clearance : (float, float)
        Clearance range [m].
    kinds : tuple of str
        Special points followed in (frequency, clearance), from :data:`CHART_KINDS`.
    max_steps : int
        Most continuation steps per direction of a curve.
    frequency_step : float
        Frequency step of the regime map's brute-force sweeps [Hz].
    clearance_num : int
        Clearances of the regime map (evenly spaced over the range).
    transient_periods, strobes : int
        Periods dropped, and kept for the classification, at each point of the regime map.
    """

    restitution: float = CHART.key("restitution").default
    clearance: tuple[float, float] = CHART.key("clearance").default
    kinds: tuple[str, ...] = CHART.key("kinds").default
    max_steps: int = CHART.key("max_steps").default
    frequency_step: float = CHART.key("frequency_step").default
    clearance_num: int = CHART.key("clearance_num").default
    transient_periods: int = CHART.key("transient_periods").default
    strobes: int = CHART.key("strobes").default

    def __post_init__(self) -> None:
        CHART.validate(self)

    @property
    def clearances(self) -> np.ndarray:
        """The regime map's clearances [m]."""
        return np.linspace(self.clearance[0], self.clearance[1], self.clearance_num)


@dataclass(frozen=True, eq=False)
class BifurcationSettings:
    """What a bifurcation study computes.

    Attributes
    ----------
    low, high : float
        The frequency band [Hz].
    restitution : tuple of float
        R of each bifurcation diagram [-].
    clearance : float
        Delta [m] shared by every stop.
    brute_force : BruteForceSettings
        Stepped sweeps up and down.
    branches : BranchSettings
        Continued branches.
    chart : ChartSettings or None
        The two-parameter chart (None: none).
    bumper_frequencies : tuple of float
        Omega_b / 2 pi of the bumpers every stop is made of, one diagram each [Hz] (empty: rigid stops).
    reference : str
        With bumpers, :data:`REFERENCES`: ``rigid`` adds the rigid stop's diagram as the convergence reference,
        ``none`` runs the bumpers alone; without bumpers ``none`` (the diagram is the rigid stop's).
    bumper_stiffnesses : tuple of float
        K_b of each bumper as the scene gave it [N m-1] (empty: given as frequencies), in the order of
        ``bumper_frequencies``.
    """

    low: float
    high: float
    restitution: tuple[float, ...]
    clearance: float
    brute_force: BruteForceSettings = BruteForceSettings()
    branches: BranchSettings = BranchSettings()
    chart: ChartSettings | None = None
    bumper_frequencies: tuple[float, ...] = ()
    reference: str = "none"
    bumper_stiffnesses: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        if not 0.0 < self.low < self.high:
            raise ValueError(f"frequency band ({self.low!r}, {self.high!r}): expected 0 < start < stop [Hz]")
        if self.reference not in REFERENCES:
            raise ValueError(f"reference = {self.reference!r} is not allowed: use one of {', '.join(REFERENCES)}")
        if self.bumper_stiffnesses and len(self.bumper_stiffnesses) != len(self.bumper_frequencies):
            raise ValueError(f"bumper_stiffnesses: expected {len(self.bumper_frequencies)} values (one per bumper frequency), got {len(self.bumper_stiffnesses)}")
        if self.reference != "none" and not self.bumper_frequencies:
            raise ValueError(f"reference = {self.reference!r}: a reference needs bumpers (without them the diagram is the rigid stop's)")

    @property
    def rigid(self) -> bool:
        """Does the study run the rigid stop's diagram (rigid stops, or bumpers with ``reference: rigid``)?"""
        return not self.bumper_frequencies or self.reference == "rigid"

    @property
    def models(self) -> tuple[float | None, ...]:
        """The contact models of the diagrams, each restitution's in this order: None for the rigid stop (when it
        runs), then Omega_b / 2 pi of each bumper [Hz]."""
        return ((None,) if self.rigid else ()) + self.bumper_frequencies

    @property
    def frequency(self) -> np.ndarray:
        """The brute-force frequency grid [Hz], increasing."""
        count = math.floor((self.high - self.low) / self.brute_force.step * (1.0 + 1e-12)) + 1
        return np.round(self.low + self.brute_force.step * np.arange(count), 10)

    @property
    def chart_frequency(self) -> np.ndarray:
        """The regime map's frequency grid [Hz] (empty without a chart)."""
        if self.chart is None:
            return np.zeros(0)
        count = math.floor((self.high - self.low) / self.chart.frequency_step * (1.0 + 1e-12)) + 1
        return np.round(self.low + self.chart.frequency_step * np.arange(count), 10)



def parse_bifurcation_scene(document: dict, text: str = "", source: str = "scene") -> Scene:
    """Validate a bifurcation scene's document (a mapping with ``bifurcation``) and build the :class:`Scene`; raise
    :class:`SceneError` listing all problems."""
    c, doc, name, description, report, scheduler = open_scene(document, BIFURCATION_TOP_KEYS, {"name", "system", "excitation", "bifurcation"}, "bifurcation")
    layout, amplitude, _ = parse_layout(c, doc)
    if layout is not None and static_drift(layout):
        c.fail("excitation.static", "the static force pushes the structure along a rigid-body mode: it has no steady state to follow")
    stops_give_restitution = isinstance(doc.get("stops"), list) and bool(doc["stops"]) and all(isinstance(e, dict) and "restitution" in e for e in doc["stops"])
    given = doc.get("bifurcation") if isinstance(doc.get("bifurcation"), dict) else {}
    spec = (BIFURCATION.read(c, doc["bifurcation"], partial=True) if "bifurcation" in doc else None) or {}
    if isinstance(doc.get("bifurcation"), dict) and not stops_give_restitution and "restitution" not in given:
        c.fail("bifurcation.restitution", f"required key is missing: the stops give none ({BIFURCATION.key('restitution').allowed()})")
    specs, clearance, own_restitution = _stops(c, doc, layout, "restitution" in given)
    low, high = spec.get("frequency") or (None, None)
    restitution = spec.get("restitution") if "restitution" in given else own_restitution
    brute = _settings(c, BRUTE_FORCE, spec.get("brute_force") or {}, BruteForceSettings)  # None: not given, or said already
    branches = _settings(c, CONTINUATION, spec.get("continuation") or {}, BranchSettings)
    chart = _settings(c, CHART, spec["chart"], ChartSettings) if spec.get("chart") is not None else None
    masses = None  # the mass each stop's bumper pushes [kg] (the paper's stop: M2)
    if layout is not None and specs is not None:
        masses = [item.effective_mass(layout.structure) for item in specs] if specs else [place_effective_mass((1, None, "upper"), layout.structure.mass_matrix)]
    read_bumpers = _bumpers(c, spec["bumper"], masses) if spec.get("bumper") is not None else ((), ())
    bumpers, stiffnesses = read_bumpers if read_bumpers is not None else (None, ())
    reference = spec.get("reference") or "none"
    if reference != "none" and "bumper" not in given:
        c.fail("bifurcation.reference", "a reference needs bifurcation.bumper: without bumpers the diagram is the rigid stop's")
        reference = "none"
    if bumpers and "chart" in given:
        c.fail("bifurcation.chart", "a chart follows the rigid stop's special points only: remove it, or bifurcation.bumper")
    if bumpers and restitution is not None and np.any(restitution <= 0.0):
        c.fail("bifurcation.restitution", "R = 0 needs an infinitely damped bumper: allowed (0, 1] with bifurcation.bumper")
    if brute is not None and low is not None and high is not None and restitution is not None:
        if brute.step > high - low:
            c.fail("bifurcation.brute_force.step", f"{brute.step:g} Hz is out of range: allowed (0, {high - low:g}] (the band's width)")
        else:
            models = len(bumpers or ()) + (1 if not bumpers or reference == "rigid" else 0)  # a diagram's brute force per contact model
            periods = (high - low) / brute.step * restitution.size * models * len(brute.directions) * (brute.transient_periods + brute.strobes)
            if periods > MAX_BRUTE_PERIODS:
                c.fail("bifurcation.brute_force", f"{periods:.3g} simulated periods is too many: allowed at most {MAX_BRUTE_PERIODS:.0e} (raise step, or fewer periods)")
    if chart is not None and low is not None and high is not None and chart.frequency_step > high - low:
        c.fail("bifurcation.chart.frequency_step", f"{chart.frequency_step:g} Hz is out of range: allowed (0, {high - low:g}] (the band's width)")
    if c.problems:
        raise SceneError(c.problems, source)
    assert layout is not None and specs is not None and amplitude is not None and isinstance(name, str) and clearance is not None
    assert low is not None and high is not None and restitution is not None and brute is not None and branches is not None
    settings = BifurcationSettings(low, high, tuple(float(r) for r in restitution), float(clearance), brute, branches, chart, tuple(bumpers or ()), reference, stiffnesses)
    return Scene(
        name=name,
        description=description,
        layout=layout.with_stops(specs) if specs else layout,
        amplitude=amplitude,
        kind="bifurcation",
        settings=settings,
        report=report,
        text=text,
        cluster_scheduler=scheduler,
    )


def _stops(c: Checker, doc: dict, layout: Layout | None, swept_restitution: bool) -> tuple[tuple[StopSpec, ...] | None, float | None, np.ndarray | None]:
    """The stops (``()``: the paper's stop on x2; None: unusable), their shared clearance Delta [m] and, when they give
    it and ``bifurcation.restitution`` does not (``swept_restitution`` False), their shared restitution as a grid.

    The returned stops take Delta and R from the study (their own values moved to the grid), as a stepped scene's
    shared values do (:mod:`vibroimpact.model.layout`)."""
    if "stop" not in doc and "stops" not in doc:
        c.fail("stop", "required: the paper's stop {clearance: Delta [m]} above the absorber x2, or 'stops' (any layout)")
        return None, None, None
    specs = layout.stops if layout is not None else None
    if "stops" not in doc:
        stop = BIFURCATION_STOP.read(c, doc["stop"], partial=True)
        return ((), stop["clearance"], None) if stop is not None else (None, None, None)
    if specs is None:
        return None, None, None
    ok = True
    for k, stop in enumerate(specs):
        entry = doc["stops"][k]
        if "bumper" in entry:
            c.fail(f"stops[{k}].bumper", "a bifurcation study's stops are rigid; bumpers beside them are given by bifurcation.bumper: {frequency: [Hz, ...]} or {stiffness: [N/m, ...]}")
            ok = False
        if stop.clearance is None:
            c.fail(f"stops[{k}].clearance", "required: Delta [m] in (0, inf), the same for every stop (the chart varies it)")
            ok = False
        elif not stop.clearance > 0.0:
            c.fail(f"stops[{k}].clearance", f"{stop.clearance!r} is out of range: allowed (0, inf) [m]")
            ok = False
        elif stop.clearance != specs[0].clearance and specs[0].clearance is not None:
            c.fail(f"stops[{k}].clearance", f"{stop.clearance:g} m differs from stops[0]'s {specs[0].clearance:g} m: a bifurcation study has one clearance Delta shared by every stop (the chart varies it)")
            ok = False
        if swept_restitution and stop.restitution is not None:
            c.fail(f"stops[{k}].restitution", "also given in bifurcation.restitution (the diagrams' values, for every stop): give it in one place only")
            ok = False
        elif not swept_restitution and stop.restitution is None:
            c.fail(f"stops[{k}].restitution", "required unless bifurcation.restitution gives the diagrams' values: R in [0, 1], the same for every stop")
            ok = False
        elif stop.restitution is not None and stop.restitution != specs[0].restitution and specs[0].restitution is not None:
            c.fail(f"stops[{k}].restitution", f"{stop.restitution:g} differs from stops[0]'s {specs[0].restitution:g}: a bifurcation diagram has one R shared by every stop")
            ok = False
    if not ok:
        return None, None, None
    own = None if swept_restitution else np.array([specs[0].restitution])
    shared = tuple(dataclasses.replace(spec, clearance=None, restitution=None) for spec in specs)
    return shared, specs[0].clearance, own


def _bumpers(c: Checker, value: Any, masses: list[float] | None) -> tuple[tuple[float, ...], tuple[float, ...]] | None:
    """``bifurcation.bumper``: {frequency: Omega_b / 2 pi [Hz]} or {stiffness: K_b [N/m]}, a list (or grid) of values
    > 0: the bumpers' frequencies [Hz] and the stiffnesses the scene gave (empty for the frequency form), converted
    with the stops' effective mass ``masses`` [kg] (which must be one: one frequency per bumper for every stop)."""
    spec = c.mapping("bifurcation.bumper", value, {"frequency", "stiffness"})
    forms = [key for key in ("frequency", "stiffness") if key in spec]
    if len(forms) != 1:
        c.fail("bifurcation.bumper", f"give exactly one of frequency (Omega_b / 2 pi [Hz]) or stiffness (K_b [N/m]), got {forms or 'neither'}")
        return None
    key = f"bifurcation.bumper.{forms[0]}"
    grid = c.grid(key, spec[forms[0]], 0.0, math.inf, False)
    if grid is None:
        return None
    if forms[0] == "frequency":
        return tuple(float(f) for f in grid), ()
    if not masses:
        return None  # (the layout failed: said already)
    if max(masses) - min(masses) > 1e-12 * max(masses):
        c.fail(key, f"the stops push different effective masses ({', '.join(f'{m:.6g}' for m in masses)} kg): one K_b gives each its own Omega_b; give bumper.frequency instead")
        return None
    mass = masses[0]
    return tuple(math.sqrt(float(k) / mass) / (2.0 * math.pi) for k in grid), tuple(float(k) for k in grid)


def _settings(c: Checker, section: Section, value: Any, kind: type[_Settings]) -> _Settings | None:
    """The settings dataclass ``kind`` of a declared ``section`` read from ``value`` (every key, defaults filled in);
    None with the problems recorded."""
    values = section.read(c, value)
    return kind(**values) if values is not None else None
