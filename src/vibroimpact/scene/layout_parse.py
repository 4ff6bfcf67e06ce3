"""Reading the general scene format: a structure given by matrices, a load on any coordinate, any stops.

Example (the paper's masses with Ormondroyd and Den Hartog's relative stop of 1928)::

    system:
      mass: [[1.0, 0.0], [0.0, 0.1]]                          # [kg]
      stiffness: [[29300.0, -4300.0], [-4300.0, 4300.0]]      # [N/m]
      damping: [[0.88, -0.08], [-0.08, 0.08]]                 # [N s/m]
      coordinates: [x1, x2]                                   # optional; default x1, x2, ...
    excitation:
      amplitude: 10.0          # harmonic force [N] on `on` (a name or a list of weights), or base displacement [m]
      on: x1
      static: [0.0, 0.0]       # optional constant force per coordinate [N]
      # base_motion: true      # amplitude [m] of the base; coordinates relative to the base
    stops:
      - {between: [x2, x1], side: upper, clearance: 0.003, restitution: 0.2}   # x2 - x1 <= 3 mm
      # {coordinate: x2, side: lower, clearance: 0.003, restitution: 0.2, bumper: {frequency: 250.0}}

The named form ``system: {m1, m2, k1, k2, b1, b2}`` and ``stop: {clearance, restitution}`` stay valid and mean what
they always meant. Every function records each problem in the :class:`~vibroimpact.scene.checker.Checker`, naming
its key and the allowed values, and returns None where a value is unusable.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from vibroimpact.analysis.layout import layout_refusal
from vibroimpact.model.contact import SIDES, place_effective_mass
from vibroimpact.model.structure import LinearStructure, stiffness_modes
from vibroimpact.model.system import TwoDofSystem
from vibroimpact.scene.bumper_parse import BUMPER, BumperSpec, parse_bumper
from vibroimpact.scene.checker import Checker
from vibroimpact.scene.declared import DERIVED, OPTIONAL, REQUIRED, Free, Key, Section, Table
from vibroimpact.model.layout import PAPER_STOP, Layout, LoadSpec, StopSpec, build_stops

__all__ = ["NAMED_SYSTEM", "MATRIX_SYSTEM", "EXCITATION", "STOP_ROW", "LAYOUT_SECTIONS", "NAMED_SYSTEM_KEYS", "MATRIX_SYSTEM_KEYS", "EXCITATION_KEYS", "STOP_KEYS", "LayoutSection", "parse_layout", "parse_structure", "parse_load", "parse_stops", "parse_sweep_stops", "parse_stop_layout", "document_names", "check_layout_solutions", "pgf_refusal", "static_drift"]

#: ``system`` in the paper's named form, declared (:mod:`vibroimpact.scene.declared`).
NAMED_SYSTEM = Section("system", (
    Key("m1", float, "the primary mass", REQUIRED, 0.0, math.inf, "kg", open_low=True),
    Key("m2", float, "the absorber's mass", REQUIRED, 0.0, math.inf, "kg", open_low=True),
    Key("k1", float, "the primary's suspension", REQUIRED, 0.0, math.inf, "N m-1", open_low=True),
    Key("k2", float, "the absorber's spring", REQUIRED, 0.0, math.inf, "N m-1", open_low=True),
    Key("b1", float, "the primary's damping", 0.0, 0.0, math.inf, "N s m-1"),
    Key("b2", float, "the absorber's damping", 0.0, 0.0, math.inf, "N s m-1"),
), "the paper's two masses: a primary on its suspension, an absorber on the primary", form="the paper's named form")  # fmt: skip
#: ``system`` by its matrices, declared: their shapes and values are the structure's own checks.
MATRIX_SYSTEM = Section("system", (
    Key("mass", Free, "M: a list of N rows of N numbers", REQUIRED, unit="kg"),
    Key("stiffness", Free, "K: a list of N rows of N numbers", REQUIRED, unit="N m-1"),
    Key("damping", Free, "B: a list of N rows of N numbers (derived: none)", OPTIONAL, unit="N s m-1"),
    Key("coordinates", Free, "a name per row: [x1, x2, ...] (derived: x1 ... xN)", OPTIONAL),
), "any linear structure of N degrees of freedom", form="matrices")  # fmt: skip
#: ``excitation``, declared.
EXCITATION = Section("excitation", (
    Key("amplitude", float, "q, the harmonic force's amplitude (a base motion: the base's displacement, m)", REQUIRED, 0.0, math.inf, "N", open_low=True),
    Key("on", Free, "where the force acts: a coordinate's name, or a weight per coordinate (derived: the first coordinate)", OPTIONAL),
    Key("static", Free, "a constant force per coordinate [N] (derived: none)", OPTIONAL),
    Key("base_motion", bool, "the base moves by amplitude [m] and loads every coordinate through its mass", False),
), "the load: q cos(w t) on a coordinate, weighted, or a base motion")  # fmt: skip
#: One entry of ``stops``, declared: where it acts and the values it gives (the others come from the sweep).
STOP_ROW = Section("stops[k]", (
    Key("coordinate", Free, "the coordinate's name, for a stop against the base (or between)", OPTIONAL),
    Key("between", Free, "[a, b]: two coordinates' names, for a stop on the gap a - b (or coordinate)", OPTIONAL),
    Key("side", str, "upper: x <= Delta, lower: x >= -Delta", "upper", choices=tuple(SIDES)),
    Key("clearance", float, "Delta (negative: a preload; derived: the scene's or the sweep's)", DERIVED, unit="m"),
    Key("restitution", float, "R (derived: the scene's or the sweep's)", DERIVED, 0.0, 1.0),
    Key("bumper", Table, "a Kelvin-Voigt bumper on this stop (bumper)", OPTIONAL),
), "one stop of any layout: where it acts, and its own values")  # fmt: skip
#: The layout's declared sections (``run-study --keys`` lists them after the header's).
LAYOUT_SECTIONS = (NAMED_SYSTEM, MATRIX_SYSTEM, EXCITATION, STOP_ROW, BUMPER)
#: Keys of the paper's named system.
NAMED_SYSTEM_KEYS = NAMED_SYSTEM.names
#: Keys of a system given by matrices.
MATRIX_SYSTEM_KEYS = MATRIX_SYSTEM.names
#: Keys of the excitation section.
EXCITATION_KEYS = set(EXCITATION.names)
#: Keys of one entry of ``stops``.
STOP_KEYS = set(STOP_ROW.names)
#: Most stops of one scene.
MAX_STOPS = 16
#: Most coordinates of a structure written in a scene.
MAX_COORDINATES = 64


class LayoutSection(NamedTuple):
    """What :func:`parse_layout` read: the layout (None where a part is unusable), the excitation amplitude (None
    where unusable) and the structure's coordinates (None where the structure is unusable; known even when the
    stops are not, so that what depends on the names alone is still checked)."""

    layout: Layout | None
    amplitude: float | None
    coordinates: tuple[str, ...] | None


def parse_layout(c: Checker, doc: dict) -> LayoutSection:
    """The scene's layout and excitation amplitude, in either form: ``system`` (named {m1 ... b2} or matrices),
    ``excitation`` (``amplitude``, and ``on``, ``static``, ``base_motion``) and ``stops`` (any layout) or ``stop`` (the
    paper's stop above the absorber x2, whose values the kind reads). The named form is sugar for the same
    :class:`~vibroimpact.model.layout.Layout`; every problem is recorded in ``c``."""
    structure = parse_structure(c, doc["system"]) if "system" in doc else None
    names = tuple(structure.coordinates) if structure is not None else document_names(doc.get("system"))
    amplitude, load = parse_load(c, doc["excitation"], names) if "excitation" in doc else (None, None)
    specs = parse_stop_layout(c, doc, structure)
    coordinates = tuple(structure.coordinates) if structure is not None else None
    if structure is None or ("stops" in doc and specs is None):
        return LayoutSection(None, amplitude, coordinates)
    try:
        return LayoutSection(Layout(structure, load or LoadSpec(), specs or (PAPER_STOP,)), amplitude, coordinates)
    except (TypeError, ValueError) as error:
        c.fail("stops", str(error))
        return LayoutSection(None, amplitude, coordinates)


def parse_structure(c: Checker, value: Any) -> TwoDofSystem | LinearStructure | None:
    """``system``: the named form {m1, m2, k1, k2, b1, b2} or matrices {mass, stiffness, damping, coordinates}."""
    if isinstance(value, dict) and any(key in value for key in MATRIX_SYSTEM_KEYS):
        return _matrix_structure(c, value)
    return _named_system(c, value)


def _named_system(c: Checker, value: Any) -> TwoDofSystem | None:
    read = NAMED_SYSTEM.read(c, value, partial=True)
    if read is None:
        return None
    numbers = {key: read[key] for key in NAMED_SYSTEM_KEYS if key in value and read[key] is not None}  # as given: the defaults are the model's
    if not {"m1", "m2", "k1", "k2"} <= set(numbers) or len(numbers) < len(value.keys() & set(NAMED_SYSTEM_KEYS)):
        return None
    system = TwoDofSystem(**numbers)
    try:
        system.check_ratios()
    except ValueError as error:  # ratios beyond double precision (model/system.py), named
        _record(c, "system", error)
        return None
    return system


def _matrix_structure(c: Checker, value: dict) -> LinearStructure | None:
    named = sorted(set(map(str, value)) & set(NAMED_SYSTEM_KEYS))
    if named:
        c.fail("system", f"give either the named form (m1, m2, k1, k2, b1, b2) or matrices (mass, stiffness, damping, coordinates), not both: remove {', '.join(named)}")
        return None
    MATRIX_SYSTEM.read(c, value, partial=True)
    spec = {key: value[key] for key in MATRIX_SYSTEM_KEYS if key in value}
    if not {"mass", "stiffness"} <= set(spec):
        return None
    ok = True
    for key in ("mass", "stiffness", "damping"):
        if key in spec and not _is_matrix(spec[key]):
            c.fail(f"system.{key}", f"expected a square matrix: a list of N rows of N numbers [SI], got {spec[key]!r}")
            ok = False
    rows = spec["mass"]
    if ok and not 1 <= len(rows) <= MAX_COORDINATES:
        c.fail("system.mass", f"{len(rows)} coordinates is out of range: allowed [1, {MAX_COORDINATES}]")
        ok = False
    names: tuple[str, ...] = ()
    if "coordinates" in spec:
        given = spec["coordinates"]
        if not isinstance(given, list) or not all(isinstance(name, str) for name in given):
            c.fail("system.coordinates", f"expected a list of names (one per row of system.mass), got {given!r}")
            ok = False
        else:
            names = tuple(given)
    if not ok:
        return None
    try:
        structure = LinearStructure(mass=rows, stiffness=spec["stiffness"], damping=spec.get("damping", ()), coordinates=names)
        structure.check_dynamic_range()
        return structure
    except ValueError as error:
        _record(c, "system", error)
        return None


def _is_matrix(value: Any) -> bool:
    """A list of lists of numbers (not booleans); shape and values are the structure's own checks."""
    return isinstance(value, list) and bool(value) and all(
        isinstance(row, list) and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in row) for row in value
    )


def _record(c: Checker, default_key: str, error: ValueError) -> None:
    """A model's ValueError (``"key: message"``) as a scene problem under that key."""
    text = str(error)
    key, _, message = text.partition(": ")
    if message and " " not in key:
        c.fail(key, message)
    else:
        c.fail(default_key, text)


def parse_load(c: Checker, value: Any, names: tuple[str, ...] | None) -> tuple[float | None, LoadSpec | None]:
    """``excitation: {amplitude, on, static, base_motion}`` -> (amplitude, load); the load is None for the paper's
    force on the primary mass (only ``amplitude`` given). ``names``: the structure's coordinates (None: unknown)."""
    read = EXCITATION.read(c, value, partial=True)
    if read is None:
        return None, None
    spec = {key: value[key] for key in EXCITATION_KEYS if key in value}
    amplitude = read["amplitude"]
    if not set(spec) & (EXCITATION_KEYS - {"amplitude"}):
        return amplitude, None
    base_motion = bool(read["base_motion"])  # a wrong one (None) is said already
    if base_motion and "on" in spec:
        c.fail("excitation.on", "a base motion loads every coordinate through its mass: remove 'on' (amplitude is the base displacement [m])")
    weights = None
    if "on" in spec and names is not None and not base_motion:
        weights = _weights(c, spec["on"], names)
    static = _vector(c, "excitation.static", spec["static"], names, "constant force per coordinate [N]") if "static" in spec else None
    return amplitude, LoadSpec(weights=weights, static=static, base_motion=base_motion)


def _weights(c: Checker, on: Any, names: tuple[str, ...]) -> tuple[float, ...] | None:
    if isinstance(on, str):
        if on not in names:
            c.fail("excitation.on", f"{on!r} is not a coordinate of the system: allowed {', '.join(names)} (or a list of {len(names)} weights)")
            return None
        return tuple(1.0 if name == on else 0.0 for name in names)
    weights = _vector(c, "excitation.on", on, names, "weight per coordinate [-], or a coordinate's name")
    if weights is not None and not any(weights):
        c.fail("excitation.on", "every weight is zero: the harmonic load would vanish")
        return None
    return weights


def _vector(c: Checker, key: str, value: Any, names: tuple[str, ...] | None, what: str) -> tuple[float, ...] | None:
    if not isinstance(value, list) or not all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in value):
        c.fail(key, f"expected a list of finite numbers ({what}), got {value!r}")
        return None
    if names is not None and len(value) != len(names):
        c.fail(key, f"expected {len(names)} values (one per coordinate: {', '.join(names)}), got {len(value)}")
        return None
    return tuple(float(x) for x in value)


def parse_stops(c: Checker, value: Any, names: tuple[str, ...] | None, key: str = "stops", mass: np.ndarray | None = None) -> tuple[StopSpec, ...] | None:
    """``stops`` (or the list at ``key``): a non-empty list of {coordinate | between, side, clearance, restitution,
    bumper}; None if unusable. ``mass``: the structure's mass matrix M [kg], which converts a bumper given in
    physical units with its stop's effective mass (None: the structure is unusable).

    Values a stop does not give come from the sweep (or the scene's ``bumper`` section); which stop needs which
    value is checked by the caller, who knows what is swept.
    """
    if not isinstance(value, list) or not value:
        c.fail(key, "expected a non-empty list of stops, each {coordinate: NAME | between: [NAME, NAME], side: upper | lower, clearance: [m], restitution: [0, 1]}")
        return None
    if len(value) > MAX_STOPS:
        c.fail(key, f"{len(value)} stops is too many: allowed at most {MAX_STOPS}")
        return None
    specs: list[StopSpec | None] = [_stop(c, f"{key}[{k}]", entry, names, mass) for k, entry in enumerate(value)]
    if any(spec is None for spec in specs):
        return None
    places = [(s.coordinate, s.other, s.side) for s in specs if s is not None]
    for k, place in enumerate(places):
        if place in places[:k]:
            c.fail(f"{key}[{k}]", f"acts where {key}[{places.index(place)}] acts (same coordinates and side): merge them")
            return None
    return tuple(s for s in specs if s is not None)


def _stop(c: Checker, key: str, entry: Any, names: tuple[str, ...] | None, mass: np.ndarray | None) -> StopSpec | None:
    read = STOP_ROW.at(key).read(c, entry, partial=True)
    if read is None:
        return None
    spec = {name: entry[name] for name in STOP_KEYS if name in entry}
    where = [k for k in ("coordinate", "between") if k in spec]
    if len(where) != 1:
        c.fail(key, "give exactly one of 'coordinate: NAME' (a stop against the base) or 'between: [NAME, NAME]' (a relative stop)")
        return None
    side = read["side"]
    coordinate = other = None
    if names is not None:
        if "coordinate" in spec:
            coordinate = _index(c, f"{key}.coordinate", spec["coordinate"], names)
        else:
            pair = spec["between"]
            if not isinstance(pair, list) or len(pair) != 2:
                c.fail(f"{key}.between", f"expected two coordinate names [a, b] (the gap is on a - b), got {pair!r}")
            else:
                coordinate = _index(c, f"{key}.between[0]", pair[0], names)
                other = _index(c, f"{key}.between[1]", pair[1], names)
                if coordinate is not None and coordinate == other:
                    c.fail(f"{key}.between", f"the two coordinates must differ, got {pair[0]!r} twice")
                    coordinate = None
    clearance, restitution = read["clearance"], read["restitution"]
    bumper = BumperSpec()
    if "bumper" in spec:
        if read["bumper"] is None:
            return None  # not a mapping: said
        placed = mass is not None and side is not None and coordinate is not None and ("between" not in spec or other is not None)
        effective_mass = place_effective_mass((coordinate, other, side), mass) if placed else None  # type: ignore[arg-type]
        parsed = parse_bumper(c, f"{key}.bumper", spec["bumper"], effective_mass)
        if parsed is None:
            return None
        bumper = parsed
    failed = (
        names is None or side is None or coordinate is None or ("between" in spec and other is None)
        or ("clearance" in spec and clearance is None) or ("restitution" in spec and restitution is None)
    )  # fmt: skip
    if failed:
        return None
    assert coordinate is not None and side is not None
    return StopSpec(coordinate, other, side, clearance, restitution, bumper.frequency, bumper.loss_factor, bumper.stiffness, bumper.damping)


def _index(c: Checker, key: str, name: Any, names: tuple[str, ...]) -> int | None:
    if not isinstance(name, str) or name not in names:
        c.fail(key, f"{name!r} is not a coordinate of the system: allowed {', '.join(names)}")
        return None
    return names.index(name)


def parse_sweep_stops(c: Checker, value: Any, count: int | None) -> tuple[int, ...] | None:
    """``sweep.stop``: the index (or list of indices) of the stops that swept restitution, clearance and bumper values
    apply to (default: every stop)."""
    indices = value if isinstance(value, list) else [value]
    if not indices or not all(isinstance(i, int) and not isinstance(i, bool) for i in indices):
        c.fail("sweep.stop", f"expected a stop index or a list of them (0-based, in the order of stops), got {value!r}")
        return None
    if count is not None:
        for i in indices:
            if not 0 <= i < count:
                c.fail("sweep.stop", f"{i} is out of range: allowed [0, {count - 1}] (the scene has {count} stops)")
                return None
    if len(set(indices)) != len(indices):
        c.fail("sweep.stop", f"an index is repeated: {indices}")
        return None
    return tuple(sorted(indices))


def document_names(value: Any) -> tuple[str, ...] | None:
    """The coordinate names a ``system`` section gives even when its matrices are invalid (so that the excitation
    and the stops are still checked against them): ``coordinates``, else x1 ... xN from the rows of ``mass``."""
    if not isinstance(value, dict):
        return None
    if not any(key in value for key in MATRIX_SYSTEM_KEYS):
        return ("x1", "x2")
    given = value.get("coordinates")
    if isinstance(given, list) and given and all(isinstance(name, str) for name in given):
        return tuple(given)
    rows = value.get("mass")
    return tuple(f"x{i + 1}" for i in range(len(rows))) if isinstance(rows, list) and rows else None


def parse_stop_layout(c: Checker, doc: dict, system: TwoDofSystem | LinearStructure | None) -> tuple[StopSpec, ...] | None:
    """The scene's ``stops`` (None: the paper's ``stop`` section, or unusable); refuses ``stop`` and ``stops``
    together, and the paper's ``stop`` on a structure that is not two masses."""
    if "stops" in doc and "stop" in doc:
        c.fail("stop", "give either 'stop' (the paper's stop above the absorber x2) or 'stops' (any layout), not both")
        return None
    if "stops" in doc:
        if system is None:
            return parse_stops(c, doc["stops"], document_names(doc.get("system")))
        return parse_stops(c, doc["stops"], tuple(system.coordinates), mass=system.mass_matrix)
    if system is not None and system.size != 2:
        c.fail("stops", f"required for a structure of {system.size} coordinates: the 'stop' section means the paper's stop above the absorber of two masses")
    return None


# --------------------------------------------------------------------------------------------------------------------
# Which solutions a general scene's layout admits, each refusal with its reason (checked before any work).
# --------------------------------------------------------------------------------------------------------------------

def pgf_refusal(layout: Layout, restitution: np.ndarray | None = None, clearance: np.ndarray | None = None) -> str | None:
    """Why the closed-form (PGF) solution does not apply to this layout at some corner of the grid, None where it
    applies everywhere: stops without room (:meth:`Layout.check_room`), else :func:`.layout_refusal` (one rigid stop
    or a symmetric two-sided stop, no rigid-body mode). The grid's R [-] and Delta [m] go to the stops that give
    none (a two-sided stop's sides must be equal; NaN: not judged)."""
    r_grid = np.array([np.nan]) if restitution is None else restitution
    d_grid = np.array([np.nan]) if clearance is None else clearance
    corners = {(float(r), float(d)) for r in (r_grid[0], r_grid[-1]) for d in (d_grid[0], d_grid[-1])}
    for r, d in sorted(corners):
        try:
            layout.check_room(d)
        except ValueError as error:  # reported where it is checked (check_layout_solutions)
            return str(error)
        reason = layout_refusal(layout, r, d)
        if reason is not None:
            return reason
    return None


def static_drift(layout: Layout) -> bool:
    """Does the static force push the structure along a rigid-body mode (no static equilibrium without stops)?"""
    load, structure = layout.load, layout.structure
    if load.static is None or not any(load.static):
        return False
    free = stiffness_modes(structure.stiffness_matrix).rigid
    if not free.shape[1]:
        return False
    static = np.asarray(load.static)
    return bool(np.max(np.abs(free.T @ static)) > 1e-12 * float(np.max(np.abs(static))))


def check_layout_solutions(c: Checker, solutions: tuple[str, ...], layout: Layout, swept_sine: bool, restitution: np.ndarray | None = None, clearance: np.ndarray | None = None) -> None:
    """Record the solutions (and swept-sine tests: any layout, but a force, not a base motion) a scene asks for that
    its layout does not admit, and stops that leave a coordinate no room (two opposite stops whose clearances sum to
    <= 0 at a corner of the grid)."""
    for d in sorted({float(clearance[0]), float(clearance[-1])} if clearance is not None and clearance.size else {float("nan")}):
        try:
            layout.check_room(d)
        except ValueError as error:
            c.fail("stops", str(error).removeprefix("stops: ") + (f" (at clearance {d:g} m of the grid)" if not np.isnan(d) else ""))
            break
    if "pgf_paper" in solutions and layout.paper_view() is None:
        c.fail("solutions", "pgf_paper is the paper's own route for its layout (a two-mass chain x1, x2 as {m1 ... b2}; one upper stop on x2; force on x1): use pgf")
    if "pgf" in solutions and (reason := pgf_refusal(layout, restitution, clearance)) is not None:
        c.fail("solutions", f"pgf does not apply to this layout: {reason}")
    if "linear" in solutions and static_drift(layout):
        c.fail("solutions", "linear does not apply: the static force pushes the structure along a rigid-body mode, so it has no steady state without its stops")
    if swept_sine and layout.load.base_motion:
        c.fail("excitation.base_motion", "a swept-sine test drives a force q sin(theta(t)) on the coordinates ('on'): a swept base motion is not supported; use base_motion: false")
