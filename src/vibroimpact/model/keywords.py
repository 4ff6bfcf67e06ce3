"""A misspelt keyword argument of a public settings class names the closest one (``ContinuationSettings(mx_steps=5)``:
``did you mean 'max_steps'?``), where Python itself only says that the keyword is unexpected."""

from __future__ import annotations

import dataclasses
import difflib
import functools
from typing import Any, TypeVar

__all__ = ["suggest_keywords"]

T = TypeVar("T")


def suggest_keywords(cls: type[T]) -> type[T]:
    """Class decorator (above ``@dataclass``): an unknown keyword argument raises TypeError naming the class, the
    allowed keywords and the closest one."""
    names = [field.name for field in dataclasses.fields(cls) if field.init]  # type: ignore[arg-type]
    init = cls.__init__

    @functools.wraps(init)
    def checked(self: Any, *args: Any, **kwargs: Any) -> None:
        unknown = [name for name in kwargs if name not in names]
        if unknown:
            close = difflib.get_close_matches(unknown[0], names, n=1, cutoff=0.6)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise TypeError(f"{cls.__name__}: unknown keyword {', '.join(map(repr, unknown))} (allowed: {', '.join(names)}){hint}")
        init(self, *args, **kwargs)

    cls.__init__ = checked  # type: ignore[method-assign]
    return cls
