"""Checks of physical parameters that raise a ``ValueError`` naming the field, its value and the allowed range."""

from __future__ import annotations

import math

__all__ = ["require_finite", "require_positive", "require_non_negative", "require_in_range"]


def _number(name: str, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"{name}: expected a number, got {value!r} ({type(value).__name__})")
    number = float(value)
    if not math.isfinite(number):
        raise ValueError(f"{name}: expected a finite number, got {value!r}")
    return number


def require_finite(name: str, value: object) -> float:
    """Return ``value`` as float if it is a finite number, else raise ``ValueError`` naming ``name``."""
    return _number(name, value)


def require_positive(name: str, value: object) -> float:
    """Return ``value`` as float if it is a finite number > 0, else raise ``ValueError`` naming ``name``."""
    number = _number(name, value)
    if number <= 0.0:
        raise ValueError(f"{name} = {value!r} is out of range: allowed (0, inf)")
    return number


def require_non_negative(name: str, value: object) -> float:
    """Return ``value`` as float if it is a finite number >= 0, else raise ``ValueError`` naming ``name``."""
    number = _number(name, value)
    if number < 0.0:
        raise ValueError(f"{name} = {value!r} is out of range: allowed [0, inf)")
    return number


def require_in_range(name: str, value: object, low: float, high: float) -> float:
    """Return ``value`` as float if low <= value <= high, else raise ``ValueError`` naming ``name``."""
    number = _number(name, value)
    if not low <= number <= high:
        raise ValueError(f"{name} = {value!r} is out of range: allowed [{low:g}, {high:g}]")
    return number
