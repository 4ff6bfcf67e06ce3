"""numba's disk cache and kernels in other files: a stamp that makes an edit of a callee recompile its callers.

numba keys a cached compiled function on its own source file only (numba PR #8396, unmerged): a function that calls
compiled kernels of another module has their machine code inside its own, and after an edit of that module it would
load the stale copy from the cache. :func:`stamp_with_callees` adds a hash of those modules' sources to the cache
stamp of every compiled function of a module (numba compares a cache index's stamp with the one it computes, so a
changed callee invalidates the index). It runs as the module is imported, before anything of it compiles or loads,
and finds the callees itself (:func:`kernel_modules`): a kernel moved to another file cannot be forgotten.
"""

from __future__ import annotations

import hashlib
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

__all__ = ["callee_digest", "compiled_functions", "kernel_modules", "stamp_with_callees"]


def _is_compiled(value: object) -> bool:
    """Whether ``value`` is a numba dispatcher (``@njit``, cached or not)."""
    return hasattr(value, "py_func") and hasattr(value, "_cache")


def compiled_functions(namespace: dict[str, Any]) -> list[Any]:
    """The numba dispatchers defined in the module whose globals are ``namespace`` (not those it imports)."""
    name = namespace["__name__"]
    return [value for value in namespace.values() if _is_compiled(value) and value.py_func.__module__ == name]


def kernel_modules(namespace: dict[str, Any]) -> list[ModuleType]:
    """The other modules whose compiled functions the compiled functions of the module whose globals are
    ``namespace`` call, directly or through others (their global names), sorted by name."""
    own = namespace["__name__"]
    found: dict[str, ModuleType] = {}
    pending = [namespace]
    while pending:
        space = pending.pop()
        for function in compiled_functions(space):
            for name in function.py_func.__code__.co_names:
                value = space.get(name)
                if not _is_compiled(value):
                    continue
                module = value.py_func.__module__
                if module != own and module not in found:
                    found[module] = sys.modules[module]
                    pending.append(vars(found[module]))
    return [found[name] for name in sorted(found)]


def callee_digest(callees: list[ModuleType]) -> str:
    """SHA-256 of the modules' source files, in the order given (hex)."""
    digest = hashlib.sha256()
    for module in callees:
        digest.update(Path(str(module.__file__)).read_bytes())
    return digest.hexdigest()


def stamp_with_callees(namespace: dict[str, Any]) -> None:
    """Stamp every cached compiled function of the module whose globals are ``namespace`` with the
    :func:`callee_digest` of its :func:`kernel_modules` (none: nothing to do). Private numba attributes: where they
    are missing the stamp stays numba's own (tests/engines/test_numba_cache.py checks that it is not)."""
    callees = kernel_modules(namespace)
    if not callees:
        return
    digest = callee_digest(callees)
    for function in compiled_functions(namespace):
        cache_file = getattr(getattr(function, "_cache", None), "_cache_file", None)
        if cache_file is not None and hasattr(cache_file, "_source_stamp"):
            cache_file._source_stamp = (cache_file._source_stamp, digest)
