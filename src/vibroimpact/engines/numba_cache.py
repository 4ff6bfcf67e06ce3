"""numba's disk cache and kernels in other files: a stamp that makes an edit of any module a kernel reads recompile it.

numba keys a cached compiled function on its own source file only (numba PR #8396, unmerged), yet its machine code
holds more: the compiled functions it calls from other modules, and the global values it reads (numba freezes a
module-level number, tuple or array into the code as a constant), imported from other modules. After an edit of
one of those modules the stale copy would load from the cache. :func:`stamp_with_callees` adds a hash of those
modules' sources to the cache stamp of every compiled function of a module (numba compares a cache index's stamp with
the one it computes, so a changed module invalidates the index). It runs as the module is imported, before anything
of it compiles or loads, and finds the modules itself (:func:`kernel_modules`): a kernel or a constant moved to
another file cannot be forgotten.

Where an imported constant comes from is read from the import statements (``ast``) of the module that reads it, not
looked up by identity among the loaded modules: a constant has no ``__module__``, and identity cannot tell a module's
own ``STATUS_OK = 0`` from another module's (small integers and short strings are shared objects), nor the module
that defines a value from those that re-export it; ``from X import NAME`` names its home, and a re-export's own
``from Y import NAME`` is followed to Y (X and Y are both stamped). The homes stamped are those of the kernel's own
package (``vibroimpact.*``; numpy's, numba's and the standard library's are not edited in place). Not seen: a value
bound otherwise than by a ``from`` import (``NAME = other.NAME``), and numba ``cfunc`` callbacks, which compile (or
load) as they are defined, before any stamp.
"""

from __future__ import annotations

import ast
import hashlib
import sys
from pathlib import Path
from types import CodeType, ModuleType
from typing import Any

__all__ = ["callee_digest", "compiled_functions", "kernel_modules", "stamp_with_callees"]


def _is_compiled(value: object) -> bool:
    """Whether ``value`` is a numba dispatcher (``@njit``, cached or not)."""
    return hasattr(value, "py_func") and hasattr(value, "_cache")


def compiled_functions(namespace: dict[str, Any]) -> list[Any]:
    """The numba dispatchers defined in the module whose globals are ``namespace`` (not those it imports)."""
    name = namespace["__name__"]
    return [value for value in namespace.values() if _is_compiled(value) and value.py_func.__module__ == name]


def _names(code: CodeType) -> set[str]:
    """The global and attribute names a function's code reads, its nested functions' included."""
    names = set(code.co_names)
    for constant in code.co_consts:
        if isinstance(constant, CodeType):
            names |= _names(constant)
    return names


def _from_imports(namespace: dict[str, Any]) -> dict[str, tuple[str, str]]:
    """The names the module whose globals are ``namespace`` binds by ``from X import name [as local]`` (anywhere in its
    source, relative imports resolved): local name -> (X, name). Empty without a source file."""
    path = namespace.get("__file__")
    try:
        tree = ast.parse(Path(str(path)).read_text(encoding="utf-8")) if path else None
    except (OSError, SyntaxError, ValueError):
        tree = None
    found: dict[str, tuple[str, str]] = {}
    package = (namespace.get("__package__") or "").split(".")
    for node in ast.walk(tree) if tree is not None else ():
        if isinstance(node, ast.ImportFrom):
            base = package[: len(package) - node.level + 1] if node.level else []
            home = ".".join(base + ([node.module] if node.module else []))
            found.update({alias.asname or alias.name: (home, alias.name) for alias in node.names})
    return found


class _Walk:
    """The modules the compiled functions of one module read (see :func:`kernel_modules`)."""

    def __init__(self, own: str) -> None:
        self.own = own
        self.package = own.partition(".")[0]
        self.found: dict[str, ModuleType] = {}
        self.followed: set[str] = {own}
        self.pending: list[dict[str, Any]] = []
        self.imports: dict[str, dict[str, tuple[str, str]]] = {}

    def _in_package(self, name: str) -> bool:
        return name == self.package or name.startswith(self.package + ".")

    def _add(self, module: ModuleType, follow: bool) -> None:
        """Stamp with ``module``; ``follow``: walk its compiled functions too (it holds a callee)."""
        if module.__name__ != self.own:
            self.found[module.__name__] = module
        if follow and module.__name__ not in self.followed:
            self.followed.add(module.__name__)
            self.pending.append(vars(module))

    def _callee(self, value: Any) -> None:
        self._add(sys.modules[value.py_func.__module__], True)

    def _home(self, space: dict[str, Any], name: str) -> None:
        """Stamp with the module ``space`` imports ``name`` from, and the one that module imports it from, and on."""
        seen = set()
        while space["__name__"] not in seen:
            seen.add(space["__name__"])
            imports = self.imports.setdefault(space["__name__"], _from_imports(space))
            if name not in imports:
                return
            home, name = imports[name]
            module = sys.modules.get(home)
            if module is None or not self._in_package(home):
                return
            self._add(module, False)
            space = vars(module)

    def _attributes(self, module: ModuleType, names: set[str], seen: set[str]) -> None:
        """``module.NAME`` (and ``module.sub.NAME``): stamp with ``module`` and the homes of the names it imports."""
        if module.__name__ in seen or not self._in_package(module.__name__):
            return
        seen.add(module.__name__)
        self._add(module, False)
        for name in names & set(vars(module)):
            value = vars(module)[name]
            if _is_compiled(value):
                self._callee(value)
            elif isinstance(value, ModuleType):
                self._attributes(value, names, seen)
            else:
                self._home(vars(module), name)

    def run(self, namespace: dict[str, Any]) -> list[ModuleType]:
        self.pending.append(namespace)
        while self.pending:
            space = self.pending.pop()
            for function in compiled_functions(space):
                names = _names(function.py_func.__code__)
                for name in names & set(space):
                    value = space[name]
                    if _is_compiled(value):
                        self._callee(value)
                    elif isinstance(value, ModuleType):
                        self._attributes(value, names, set())
                    else:
                        self._home(space, name)
        return [self.found[name] for name in sorted(self.found)]


def kernel_modules(namespace: dict[str, Any]) -> list[ModuleType]:
    """The other modules whose source the compiled functions of the module whose globals are ``namespace`` read,
    sorted by name: the modules of the compiled functions they call (by name or as ``module.function``), directly or
    through others, and the homes of the other global values they read (imported constants, read by name or as
    ``module.NAME``; of the package's modules only, see the module docstring)."""
    return _Walk(namespace["__name__"]).run(namespace)


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
