"""Scene keys declared once: each key's type, range, unit, default and one line of documentation, from which the
check, its messages, "did you mean" and the grammar reference all come.

A :class:`Section` is a mapping of a scene (``design.search``, ``design.certify``) whose keys are :class:`Key` rows.
Its :meth:`Section.read` checks a parsed YAML value against them and returns every key's value, the defaults
filled in: a YAML boolean is a boolean and an integer an integer (no string is silently truthy, ``4.5`` is no
population), a value out of range is refused with the range, an unknown key with the closest declared one, and a key
that only another key's choice reads (``population`` with ``method: grid``) is refused rather than ignored. What it
returns is exactly the section's keys, so a settings dataclass built from it (``Settings(**values)``) reads every
declared key by construction (tests/scene/test_declared.py walks each section into its settings).

YAML 1.2 booleans only: the scene reader gives ``no``, ``off`` and ``'false'`` as strings, which a boolean key refuses.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

from vibroimpact.scene.checker import Checker, did_you_mean, interval

__all__ = ["Key", "Section", "REQUIRED", "DERIVED", "OPTIONAL", "Names", "Band", "Grid", "Table", "Rows", "Free", "reference_table"]


class _Required:
    """The default of a key that has none: the scene must give it."""

    def __repr__(self) -> str:
        return "REQUIRED"


#: The default of a key the scene must give.
REQUIRED: Any = _Required()


class _Derived:
    """The default of a key whose value, where the scene does not give it, follows from other keys (its doc says how)."""

    def __repr__(self) -> str:
        return "DERIVED"


#: The default of a key whose value the kind derives where the scene does not give it (read as None).
DERIVED: Any = _Derived()


class _Optional:
    """The default of a mapping or a list the scene may leave out: its own keys' defaults then hold, or the study goes
    without it (a bumper, a cluster, a concept's stops)."""

    def __repr__(self) -> str:
        return "OPTIONAL"


#: The default of a mapping or a list the scene may leave out (read as None; its doc says what holds without it).
OPTIONAL: Any = _Optional()

class Names:
    """The type of a key whose value is a non-empty list of names from its choices, none repeated (read as a tuple)."""


class Band:
    """The type of a key whose value is a band ``{start, stop}``, both in the key's range, start below stop (read as
    the tuple ``(start, stop)``)."""


class Grid:
    """The type of a key whose value is a grid: a list of values or ``{start, stop, step | num}`` in the key's range
    (read as the sorted values, an array)."""


class Table:
    """The type of a key whose value is a mapping its own parser checks entry by entry (its doc names the form)."""


class Rows:
    """The type of a key whose value is a non-empty list of mappings its own parser checks row by row (its doc names
    a row's keys)."""


class Free:
    """The type of a key whose value takes more than one form (a coordinate's name or a list of weights, a matrix):
    its own parser checks it, and its doc names the forms."""


#: The YAML type each Python type of a key is written as, in messages and in the reference.
_TYPE_NAMES = {bool: "boolean (true or false)", int: "integer", float: "number", str: "string", Names: "list of names", Band: "band {start, stop}",
               Grid: "grid: [values] or {start, stop, step | num}", Table: "mapping", Rows: "non-empty list of mappings", Free: "as its meaning says"}
_ARTICLES = {bool: "a", int: "an", float: "a", str: "a", Names: "a", Band: "a", Grid: "a", Table: "a", Rows: "a", Free: "a"}


@dataclass(frozen=True)
class Key:
    """One key of a scene section.

    Attributes
    ----------
    name : str
        As written in the scene.
    type : type
        ``bool``, ``int``, ``float``, ``str``, :class:`Names`, :class:`Band`, :class:`Grid`, :class:`Table`,
        :class:`Rows` or :class:`Free`; an integer is accepted where a number is asked, never the reverse (``1e5``
        is a number in YAML 1.2, no count), and a boolean is no number.
    doc : str
        One line: what the key sets.
    default : object
        Its value where the scene does not give it; :data:`REQUIRED`: the scene must; :data:`DERIVED`: the kind
        derives it from other keys; :data:`OPTIONAL` (a mapping or a list): absent, its own keys' defaults hold or
        the study goes without it.
    low, high : float
        The allowed range, both ends included unless ``open_low`` (numbers, bands and grids; +-inf: unbounded, open).
    unit : str
        Its unit in brackets' words (``"Hz"``, ``"m"``; ``""`` for a pure number or a name).
    choices : tuple of str
        The allowed names (``str`` and :class:`Names` keys only; empty: any name).
    read_when : tuple of (str, str), optional
        (another key, its value): this key is read only where the other has that value; given otherwise it is refused.
    open_low, open_high : bool
        Whether ``low`` (a step, a frequency: above 0) or ``high`` (a restitution below 1) itself is refused.
    """

    name: str
    type: type
    doc: str
    default: Any = REQUIRED
    low: float = -math.inf
    high: float = math.inf
    unit: str = ""
    choices: tuple[str, ...] = ()
    read_when: tuple[str, str] | None = None
    open_low: bool = False
    open_high: bool = False

    def __post_init__(self) -> None:
        if self.type not in _TYPE_NAMES:
            raise TypeError(f"Key {self.name!r}: type {self.type!r} is not one of bool, int, float, str, Names, Band, Grid, Table, Rows, Free")
        if self.choices and self.type not in (str, Names):
            raise TypeError(f"Key {self.name!r}: choices are names, for a str or Names key only")
        if self.type is Names and not self.choices:
            raise TypeError(f"Key {self.name!r}: a Names key lists its choices")
        if (self.open_low or self.open_high) and self.type not in (float, Band, Grid):
            raise TypeError(f"Key {self.name!r}: an open end is for numbers, bands and grids (a count's range is whole numbers)")
        if self.default is OPTIONAL and self.type not in (Table, Rows, Free):
            raise TypeError(f"Key {self.name!r}: OPTIONAL is the default of a mapping or a list; a value the kind derives is DERIVED")
        if self.default is DERIVED and self.type in (Table, Rows):
            raise TypeError(f"Key {self.name!r}: a mapping or a list the scene may leave out is OPTIONAL")
        if not any(self.default is marker for marker in (REQUIRED, DERIVED, OPTIONAL)) and self.check(Checker(), self.name, self.as_written(self.default)) is None:
            raise ValueError(f"Key {self.name!r}: its default {self.default!r} fails its own check")

    def allowed(self) -> str:
        """What the key accepts, in words: its type, then its range or its choices."""
        if self.type is Names:
            return f"list of names from {', '.join(self.choices)}"
        if self.choices:
            return f"one of {', '.join(self.choices)}"
        kind = _TYPE_NAMES[self.type]
        if self.type is int and math.isfinite(self.low) and math.isfinite(self.high):
            return f"{kind} in [{int(self.low)}, {int(self.high)}]"
        if self.type in (int, float, Band, Grid) and (math.isfinite(self.low) or math.isfinite(self.high)):
            return f"{kind} in {interval(self.low, self.high, not self.open_low, not self.open_high)}" + (f" [{self.unit}]" if self.unit else "")
        return kind + (f" [{self.unit}]" if self.unit else "")

    def as_written(self, value: Any) -> Any:
        """``value`` of the key as a scene writes it: a band's ``(start, stop)`` as ``{start, stop}``, names as a
        list; anything else as it is."""
        if self.type is Band and isinstance(value, tuple) and len(value) == 2:
            return {"start": value[0], "stop": value[1]}
        if self.type is Names and isinstance(value, tuple):
            return list(value)
        if self.type is Grid and hasattr(value, "tolist"):
            return value.tolist()
        return value

    def check(self, c: Checker, where: str, value: Any) -> Any:
        """``value`` if the key accepts it (an integer given for a number as a float), else None with the problem
        recorded in ``c`` under ``where``."""
        wrong = f"expected {_ARTICLES[self.type]} {_TYPE_NAMES[self.type]}, got {value!r} ({type(value).__name__})"
        if self.type is bool:
            if not isinstance(value, bool):
                c.fail(where, wrong + ("; YAML 1.2 booleans are true and false" if isinstance(value, str) else ""))
                return None
            return value
        if self.type is str:
            if not isinstance(value, str):
                c.fail(where, wrong)
                return None
            if self.choices and value not in self.choices:
                c.fail(where, f"{value!r} is not allowed: allowed {', '.join(self.choices)}{did_you_mean(value, self.choices)}")
                return None
            return value
        if self.type is int:
            return c.integer(where, value, self.low, self.high)  # type: ignore[arg-type]
        if self.type is Names:
            chosen = c.choices(where, value, self.choices)
            return chosen if chosen and len(chosen) == len(value) else None
        if self.type is Band:
            band = c.mapping(where, value, {"start", "stop"}, {"start", "stop"})
            if set(map(str, band)) != {"start", "stop"}:
                return None
            start = c.number(f"{where}.start", band["start"], self.low, self.high, not self.open_low, not self.open_high)
            stop = c.number(f"{where}.stop", band["stop"], self.low, self.high, not self.open_low, not self.open_high)
            if start is None or stop is None:
                return None
            if stop <= start:
                c.fail(f"{where}.stop", f"{stop:g} must be greater than start = {start:g}")
                return None
            return (start, stop)
        if self.type is Grid:
            return c.grid(where, value, self.low, self.high, not self.open_low)  # a grid's top is closed
        if self.type is Free:
            return value
        if self.type is Rows:
            if not isinstance(value, list) or not value:
                c.fail(where, f"{wrong}: {self.doc}")
                return None
            return value
        if self.type is Table:
            if not isinstance(value, dict):
                c.fail(where, f"{wrong}: {self.doc}")
                return None
            return value
        return c.number(where, value, self.low, self.high, not self.open_low, not self.open_high)


@dataclass(frozen=True)
class Section:
    """A mapping of a scene whose keys are declared (:class:`Key`), checked and read by :meth:`read`.

    Attributes
    ----------
    path : str
        Where it is in a scene, dotted (``design.search``); ``""``: the scene's top level (the shared header).
    keys : tuple of Key
        Its keys, in the order the reference lists them.
    doc : str
        One line: what the section sets.
    others : str
        One line on the keys the kind names beyond the declared ones (a spread per scalar, a limit per measure), which
        its own parser checks; ``""``: none, every other key is refused here.
    form : str
        Which form of the mapping at ``path`` it declares, where there are more than one (the named system, its
        matrices); ``""``: the only one.
    """

    path: str
    keys: tuple[Key, ...]
    doc: str
    others: str = ""
    form: str = ""

    def __post_init__(self) -> None:
        names = [key.name for key in self.keys]
        if len(set(names)) != len(names):
            raise ValueError(f"section {self.path}: a key is declared twice in {names}")
        for key in self.keys:
            if key.read_when is not None:
                other = self.key(key.read_when[0])
                if key.read_when[1] not in other.choices:
                    raise ValueError(f"section {self.path}: {key.name} is read when {key.read_when[0]} is {key.read_when[1]!r}, not one of its choices")

    def at(self, path: str) -> "Section":
        """The same section read at another place of a scene (a bumper at ``stops[2].bumper``): its messages name it."""
        return dataclasses.replace(self, path=path)

    def misspelt(self, name: str) -> bool:
        """Whether ``name``, not declared, is close to a declared key (``sample`` for ``samples``): refused as a
        misspelling even where the section takes other keys of its kind's (:attr:`others`)."""
        return name not in self.names and bool(did_you_mean(name, self.names))

    def where(self, name: str) -> str:
        """The dotted place of the key ``name`` in a scene (the top level's keys: their names alone)."""
        return f"{self.path}.{name}" if self.path else name

    @property
    def names(self) -> tuple[str, ...]:
        """The declared keys' names."""
        return tuple(key.name for key in self.keys)

    def key(self, name: str) -> Key:
        """The declared key ``name``."""
        for key in self.keys:
            if key.name == name:
                return key
        raise KeyError(f"section {self.path} declares no key {name!r} (its keys: {', '.join(self.names)})")

    def read(self, c: Checker, value: Any, partial: bool = False) -> dict[str, Any] | None:
        """Every declared key's value from the parsed ``value`` (None or a mapping), defaults filled in; None, with
        every problem recorded in ``c`` (each naming its key), where anything is wrong. ``partial``: where keys are
        wrong, the others' values all the same (a wrong or missing key's None), so that checks across keys can still
        say their problems at once; None only where ``value`` is no mapping. A section the scene does not give is read
        from ``{}`` (its defaults); one it gives as ``null`` is refused as no mapping."""
        if not isinstance(value, dict):
            c.fail(self.path, f"expected a mapping with keys {', '.join(self.names)}, got {value!r} ({type(value).__name__})")
            return None
        before = len(c.problems)
        for given in value:
            if str(given) not in self.names and (not self.others or self.misspelt(str(given))):
                c.fail(self.where(str(given)), f"unknown key (allowed: {', '.join(self.names)}){did_you_mean(str(given), self.names)}")
        read: dict[str, Any] = {}
        for key in self.keys:
            where = self.where(key.name)
            if key.name in value:
                read[key.name] = key.check(c, where, value[key.name])
            elif key.default is REQUIRED:
                c.fail(where, f"required key is missing ({key.doc}; {key.allowed()})")
                read[key.name] = None
            elif key.default is DERIVED or key.default is OPTIONAL:
                read[key.name] = None
            else:
                read[key.name] = key.default
        for key in self.keys:
            if key.read_when is None or key.name not in value:
                continue
            other, wanted = key.read_when
            chosen = read.get(other)
            if chosen is not None and chosen != wanted:
                c.fail(self.where(key.name), f"not read with {other}: {chosen} (only with {other}: {wanted}); remove it or choose {other}: {wanted}")
        return read if partial or len(c.problems) == before else None

    def validate(self, settings: Any) -> None:
        """Check the attributes of a settings dataclass built from Python (each declared key's attribute, written as
        a scene writes it) by the scene's own checks; raise ValueError naming every problem, as the scene does."""
        c = Checker()
        for key in self.keys:
            key.check(c, key.name, key.as_written(getattr(settings, key.name)))
        if c.problems:
            raise ValueError("; ".join(c.problems))

    def reference(self) -> list[str]:
        """The section's rows of the grammar reference: ``| key | allowed | default | what it sets |`` (markdown)."""
        rows = []
        for key in self.keys:
            default = {id(REQUIRED): "required", id(DERIVED): "derived", id(OPTIONAL): "optional"}.get(id(key.default)) or _written(key.as_written(key.default))
            when = f" (read with {key.read_when[0]}: {key.read_when[1]})" if key.read_when else ""
            rows.append(f"| `{self.where(key.name)}` | {key.allowed()} | {default} | {key.doc}{when} |")
        if self.others:
            rows.append(f"| `{self.where('<name>')}` | number | - | {self.others} |")
        return rows


def _written(value: Any) -> str:
    """A default as YAML writes it (``true``, ``[up, down]``, ``{start: 0.001, stop: 0.006}``)."""
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, list):
        return "[" + ", ".join(_written(item) for item in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{name}: {_written(item)}" for name, item in value.items()) + "}"
    if value == "":
        return '""'
    return f"{value:g}" if isinstance(value, float) else str(value)


def reference_table(sections: tuple[Section, ...] | list[Section]) -> str:
    """The grammar reference of ``sections`` (markdown): per section its one line, then a row per key with what it
    accepts, its default and what it sets (``run-study --keys``)."""
    lines: list[str] = []
    for section in sections:
        title = (f"`{section.path}`" if section.path else "the top level") + (f" ({section.form})" if section.form else "")
        lines += [f"### {title}: {section.doc}", "", "| key | allowed | default | what it sets |", "|---|---|---|---|"]
        lines += [*section.reference(), ""]
    return "\n".join(lines)
