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
from typing import Any

from vibroimpact.model.stops import SIDES
from vibroimpact.model.structure import LinearStructure
from vibroimpact.model.system import TwoDofSystem
from vibroimpact.scene.checker import Checker
from vibroimpact.scene.layout import LoadSpec, StopSpec

__all__ = ["NAMED_SYSTEM_KEYS", "MATRIX_SYSTEM_KEYS", "EXCITATION_KEYS", "STOP_KEYS", "parse_structure", "parse_load", "parse_stops", "parse_sweep_stops", "is_general", "parse_stop_layout", "document_names"]

#: Keys of the paper's named system.
NAMED_SYSTEM_KEYS = ("m1", "m2", "k1", "k2", "b1", "b2")
#: Keys of a system given by matrices.
MATRIX_SYSTEM_KEYS = ("mass", "stiffness", "damping", "coordinates")
#: Keys of the excitation section.
EXCITATION_KEYS = {"amplitude", "on", "static", "base_motion"}
#: Keys of one entry of ``stops``.
STOP_KEYS = {"coordinate", "between", "side", "clearance", "restitution", "bumper"}
#: Most stops of one scene.
MAX_STOPS = 16
#: Most coordinates of a structure written in a scene.
MAX_COORDINATES = 64


def is_general(document: dict) -> bool:
    """Does the document use the general form (matrices, a load beyond a force on the primary mass, or ``stops``)?"""
    system = document.get("system")
    excitation = document.get("excitation")
    matrices = isinstance(system, dict) and any(key in system for key in MATRIX_SYSTEM_KEYS)
    load = isinstance(excitation, dict) and any(key in excitation for key in EXCITATION_KEYS - {"amplitude"})
    return matrices or load or "stops" in document


def parse_structure(c: Checker, value: Any) -> TwoDofSystem | LinearStructure | None:
    """``system``: the named form {m1, m2, k1, k2, b1, b2} or matrices {mass, stiffness, damping, coordinates}."""
    if isinstance(value, dict) and any(key in value for key in MATRIX_SYSTEM_KEYS):
        return _matrix_structure(c, value)
    return _named_system(c, value)


def _named_system(c: Checker, value: Any) -> TwoDofSystem | None:
    spec = c.mapping("system", value, set(NAMED_SYSTEM_KEYS), {"m1", "m2", "k1", "k2"})
    numbers: dict[str, float] = {}
    for key in NAMED_SYSTEM_KEYS:
        if key in spec:
            number = c.number(f"system.{key}", spec[key], 0.0, math.inf, low_inclusive=key.startswith("b"))
            if number is not None:
                numbers[key] = number
    if not {"m1", "m2", "k1", "k2"} <= set(numbers) or len(numbers) < len(spec.keys() & set(NAMED_SYSTEM_KEYS)):
        return None
    return TwoDofSystem(**numbers)


def _matrix_structure(c: Checker, value: dict) -> LinearStructure | None:
    named = sorted(set(map(str, value)) & set(NAMED_SYSTEM_KEYS))
    if named:
        c.fail("system", f"give either the named form (m1, m2, k1, k2, b1, b2) or matrices (mass, stiffness, damping, coordinates), not both: remove {', '.join(named)}")
        return None
    spec = c.mapping("system", value, set(MATRIX_SYSTEM_KEYS), {"mass", "stiffness"})
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
        return LinearStructure(mass=rows, stiffness=spec["stiffness"], damping=spec.get("damping", ()), coordinates=names)
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
    spec = c.mapping("excitation", value, EXCITATION_KEYS, {"amplitude"})
    amplitude = c.number("excitation.amplitude", spec["amplitude"], 0.0, math.inf, low_inclusive=False) if "amplitude" in spec else None
    if not set(spec) & (EXCITATION_KEYS - {"amplitude"}):
        return amplitude, None
    base_motion = spec.get("base_motion", False)
    if not isinstance(base_motion, bool):
        c.fail("excitation.base_motion", f"expected true or false, got {base_motion!r}")
        base_motion = False
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


def parse_stops(c: Checker, value: Any, names: tuple[str, ...] | None) -> tuple[StopSpec, ...] | None:
    """``stops``: a non-empty list of {coordinate | between, side, clearance, restitution, bumper}; None if unusable.

    Values a stop does not give come from the sweep (or the scene's ``bumper`` section); which stop needs which
    value is checked by the caller, who knows what is swept.
    """
    if not isinstance(value, list) or not value:
        c.fail("stops", "expected a non-empty list of stops, each {coordinate: NAME | between: [NAME, NAME], side: upper | lower, clearance: [m], restitution: [0, 1]}")
        return None
    if len(value) > MAX_STOPS:
        c.fail("stops", f"{len(value)} stops is too many: allowed at most {MAX_STOPS}")
        return None
    specs: list[StopSpec | None] = [_stop(c, f"stops[{k}]", entry, names) for k, entry in enumerate(value)]
    if any(spec is None for spec in specs):
        return None
    places = [(s.coordinate, s.other, s.side) for s in specs if s is not None]
    for k, place in enumerate(places):
        if place in places[:k]:
            c.fail(f"stops[{k}]", f"acts where stops[{places.index(place)}] acts (same coordinates and side): merge them")
            return None
    return tuple(s for s in specs if s is not None)


def _stop(c: Checker, key: str, entry: Any, names: tuple[str, ...] | None) -> StopSpec | None:
    spec = c.mapping(key, entry, STOP_KEYS)
    if not isinstance(entry, dict):
        return None
    where = [k for k in ("coordinate", "between") if k in spec]
    if len(where) != 1:
        c.fail(key, "give exactly one of 'coordinate: NAME' (a stop against the base) or 'between: [NAME, NAME]' (a relative stop)")
        return None
    side = spec.get("side", "upper")
    if side not in SIDES:
        c.fail(f"{key}.side", f"{side!r} is not allowed: use upper (x <= Delta) or lower (x >= -Delta)")
        side = None
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
    clearance = c.number(f"{key}.clearance", spec["clearance"], -math.inf, math.inf, False, False) if "clearance" in spec else None
    restitution = c.number(f"{key}.restitution", spec["restitution"], 0.0, 1.0) if "restitution" in spec else None
    frequency = loss = None
    if "bumper" in spec:
        bumper = c.mapping(f"{key}.bumper", spec["bumper"], {"frequency", "loss_factor"})
        frequency = c.number(f"{key}.bumper.frequency", bumper["frequency"], 0.0, 1e6, low_inclusive=False) if "frequency" in bumper else None
        loss = c.number(f"{key}.bumper.loss_factor", bumper["loss_factor"], 0.0, 1e3) if "loss_factor" in bumper else None
        if "frequency" in bumper and frequency is None:
            return None
    failed = (
        names is None or side is None or coordinate is None or ("between" in spec and other is None)
        or ("clearance" in spec and clearance is None) or ("restitution" in spec and restitution is None)
        or ("bumper" in spec and isinstance(spec["bumper"], dict) and "loss_factor" in spec["bumper"] and loss is None)
    )  # fmt: skip
    if failed:
        return None
    assert coordinate is not None and side is not None
    return StopSpec(coordinate, other, side, clearance, restitution, frequency, loss)


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
        return parse_stops(c, doc["stops"], document_names(doc.get("system")) if system is None else tuple(system.coordinates))
    if system is not None and system.size != 2:
        c.fail("stops", f"required for a structure of {system.size} coordinates: the 'stop' section means the paper's stop above the absorber of two masses")
    return None
