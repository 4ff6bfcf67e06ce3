"""The checker toolkit of scene parsing: collect every problem of a document, each naming its key, then fail once.

:class:`Checker` walks a parsed YAML document: each check records what is wrong (the key, what was given, the
allowed range) and returns the value or None, so that a parser reports every problem at once in one
:class:`SceneError`.
"""

from __future__ import annotations

import difflib
import math
from typing import Any

import numpy as np

from vibroimpact.scene.kinds import KINDS
from vibroimpact.scene.schema import MAX_GRID_POINTS

__all__ = ["SceneError", "Checker", "interval", "did_you_mean"]


class SceneError(ValueError):
    """A scene is invalid. ``problems`` lists every problem found, each naming its key."""

    #: Longest problem kept whole [characters]: a value quoted in a message is cut beyond it.
    MAX_PROBLEM = 400

    def __init__(self, problems: list[str], source: str = "scene") -> None:
        self.problems = [p if len(p) <= self.MAX_PROBLEM else f"{p[: self.MAX_PROBLEM]}... ({len(p)} characters)" for p in problems]
        super().__init__(f"invalid {source}:\n" + "\n".join(f"  - {p}" for p in self.problems))


def interval(low: float, high: float, low_inclusive: bool = True, high_inclusive: bool = True) -> str:
    """Interval in mathematical notation; an infinite end is always open."""
    opening = "[" if low_inclusive and math.isfinite(low) else "("
    closing = "]" if high_inclusive and math.isfinite(high) else ")"
    return f"{opening}{low:g}, {high:g}{closing}"


def did_you_mean(given: str, allowed: list[str] | tuple[str, ...] | set[str]) -> str:
    """``"; did you mean 'x'?"`` for the allowed name closest to ``given`` (difflib's ratio at least 0.6), else ``""``."""
    close = difflib.get_close_matches(given, sorted(allowed), n=1)
    return f"; did you mean {close[0]!r}?" if close else ""


class Checker:
    """Collects problems while walking a parsed YAML document."""

    def __init__(self) -> None:
        self.problems: list[str] = []

    def fail(self, key: str, message: str) -> None:
        """Record the problem ``message`` of ``key``."""
        self.problems.append(f"{key}: {message}")

    def fail_settings(self, section: str, error: Exception) -> None:
        """Record the validation error of a settings dataclass (``"tolerance: expected ..."`` or ``"tolerance = -1 is
        out of range ..."``) under ``section.<its key>``, the key said once."""
        text = str(error)
        head, _, rest = text.partition(" ")
        key = head.rstrip(":")
        self.fail(f"{section}.{key}", rest if head.endswith(":") and rest else text)

    def mapping(self, key: str, value: Any, allowed: set[str], required: frozenset[str] | set[str] = frozenset(), kind: str | None = None) -> dict:
        """``value`` as a mapping (``{}`` if it is none), reporting unknown and missing keys; ``kind`` names the kind of
        scene whose top level ``value`` is, so that a key it does not use is an error naming the kind (and the kind
        whose section it is, if it is one)."""
        if not isinstance(value, dict):
            self.fail(key, f"expected a mapping with keys {sorted(allowed)}, got {type(value).__name__}")
            return {}
        for unknown in sorted(set(map(str, value)) - allowed):
            if kind is None:
                self.fail(f"{key}.{unknown}" if key else unknown, f"unknown key (allowed: {', '.join(sorted(allowed))}){did_you_mean(unknown, allowed)}")
                continue
            owner = next((row.name for row in KINDS if row.section == unknown), None)
            whose = f"; it is the section of a {owner} scene" if owner is not None and owner != kind else ""
            self.fail(f"{key}.{unknown}" if key else unknown, f"unknown key: a {kind} scene does not use it{whose} (allowed: {', '.join(sorted(allowed))}){did_you_mean(unknown, allowed)}")
        for missing in sorted(required - set(value)):
            self.fail(f"{key}.{missing}" if key else missing, "required key is missing")
        return value

    def number(self, key: str, value: Any, low: float, high: float, low_inclusive: bool = True, high_inclusive: bool = True) -> float | None:
        """``value`` as a finite float inside the interval from ``low`` to ``high``, else None."""
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self.fail(key, f"expected a number, got {value!r} ({type(value).__name__})")
            return None
        number = float(value)
        ok_low = number >= low if low_inclusive else number > low
        ok_high = number <= high if high_inclusive else number < high
        if not (math.isfinite(number) and ok_low and ok_high):
            self.fail(key, f"{value!r} is out of range: allowed {interval(low, high, low_inclusive, high_inclusive)}")
            return None
        return number

    def integer(self, key: str, value: Any, low: int, high: int) -> int | None:
        """``value`` as an integer in [``low``, ``high``], else None."""
        if isinstance(value, bool) or not isinstance(value, int):
            self.fail(key, f"expected an integer, got {value!r} ({type(value).__name__})")
            return None
        if not low <= value <= high:
            self.fail(key, f"{value!r} is out of range: allowed [{low}, {high}]")
            return None
        return value

    def choices(self, key: str, value: Any, allowed: tuple[str, ...]) -> tuple[str, ...]:
        """The names of the non-empty list ``value`` that are ``allowed`` and not repeated, in the order given."""
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

