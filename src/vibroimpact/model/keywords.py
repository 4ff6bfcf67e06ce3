"""A misspelt keyword argument of a public class or function names the allowed ones and the closest
(``ContinuationSettings(mx_steps=5)``: ``did you mean 'max_steps'?``), where Python itself only says that the keyword
is unexpected."""

from __future__ import annotations

import dataclasses
import difflib
import functools
import inspect
from collections.abc import Callable, Iterable, Mapping
from typing import Any, TypeVar

__all__ = ["suggest_keywords", "check_keywords", "checked_options", "keyword_names"]

T = TypeVar("T")


def keyword_names(target: Callable[..., Any]) -> tuple[str, ...]:
    """The names ``target`` takes as keywords: a dataclass's init fields, else the signature's named parameters (of
    ``__init__`` for a class, without ``self``)."""
    if isinstance(target, type) and dataclasses.is_dataclass(target):
        return tuple(field.name for field in dataclasses.fields(target) if field.init)
    function = target.__init__ if isinstance(target, type) else target
    kinds = (inspect.Parameter.POSITIONAL_OR_KEYWORD, inspect.Parameter.KEYWORD_ONLY)
    names = [p.name for p in inspect.signature(function).parameters.values() if p.kind in kinds]
    return tuple(names[1:] if isinstance(target, type) else names)


def check_keywords(owner: str, given: Iterable[str], allowed: Iterable[str]) -> None:
    """Raise TypeError naming ``owner``, the unknown keywords among ``given``, the ``allowed`` ones and the closest."""
    names = list(allowed)
    unknown = [name for name in given if name not in names]
    if unknown:
        close = difflib.get_close_matches(unknown[0], names, n=1, cutoff=0.6)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise TypeError(f"{owner}: unknown keyword {', '.join(map(repr, unknown))} (allowed: {', '.join(names)}){hint}")


def suggest_keywords(target: T) -> T:
    """Decorator of a public function, or of a class (above ``@dataclass``): an unknown keyword argument raises
    TypeError naming the function or class, the allowed keywords and the closest one (:func:`check_keywords`), before
    any work. A function that takes ``**kwargs`` is given back unchanged: it says itself what it takes."""
    function: Any = target.__init__ if isinstance(target, type) else target  # type: ignore[misc]
    if any(p.kind is inspect.Parameter.VAR_KEYWORD for p in inspect.signature(function).parameters.values()):
        return target
    ordered = keyword_names(target)  # type: ignore[arg-type]
    names = frozenset(ordered)
    owner = getattr(target, "__name__", repr(target))

    @functools.wraps(function)
    def checked(*args: Any, **kwargs: Any) -> Any:
        if not names.issuperset(kwargs):
            check_keywords(owner, kwargs, ordered)
        return function(*args, **kwargs)

    if isinstance(target, type):
        target.__init__ = checked  # type: ignore[misc]
        return target
    return checked  # type: ignore[return-value]


def checked_options(owner: str, options: Mapping[str, Any], callee: Callable[..., Any]) -> None:
    """Refuse ``options`` meant for ``callee`` that it does not take (:func:`check_keywords`), naming ``owner``."""
    check_keywords(owner, options, keyword_names(callee))
