"""numba keys a cached compiled function on its own source file only; the compiled loops call kernels of other files
(a piece of flow, the root search, the moments, the exact loop's Jacobian helpers), so each loop's cache stamp also
carries those files' sources: an edit of a kernel recompiles its callers, never a stale copy."""

from __future__ import annotations

import hashlib
import sys
import types
from pathlib import Path

import pytest

from vibroimpact.engines import exact_core, exact_moments, exact_pieces, exact_roots
from vibroimpact.engines.compliant import exact_loop
from vibroimpact.engines.numba_cache import compiled_functions, kernel_modules


def _sources(*modules: object) -> str:
    """SHA-256 of the modules' files, in that order, computed here."""
    digest = hashlib.sha256()
    for module in modules:
        digest.update(Path(module.__file__).read_bytes())  # type: ignore[attr-defined]
    return digest.hexdigest()


def test_each_loop_finds_every_file_whose_kernels_it_compiles() -> None:
    assert kernel_modules(vars(exact_loop)) == [exact_core, exact_moments, exact_pieces, exact_roots]  # exact_core's through transition_matrix, and on
    assert kernel_modules(vars(exact_core)) == [exact_moments, exact_pieces, exact_roots]
    assert kernel_modules(vars(exact_moments)) == [exact_pieces]
    assert kernel_modules(vars(exact_pieces)) == [] and kernel_modules(vars(exact_roots)) == []


def test_every_compiled_function_carries_its_callees_sources_in_its_stamp() -> None:
    for module, callees in ((exact_loop, (exact_core, exact_moments, exact_pieces, exact_roots)), (exact_core, (exact_moments, exact_pieces, exact_roots)), (exact_moments, (exact_pieces,))):
        functions = compiled_functions(vars(module))
        assert len(functions) >= 5, module.__name__
        for function in functions:
            stamp = function._cache._cache_file._source_stamp
            assert isinstance(stamp, tuple) and stamp[-1] == _sources(*callees), f"{module.__name__}.{function.py_func.__name__}"
    for function in compiled_functions(vars(exact_pieces)) + compiled_functions(vars(exact_roots)):
        assert not isinstance(function._cache._cache_file._source_stamp[-1], str), "a module without callees keeps numba's own stamp"


class _Dispatcher:
    """What :mod:`vibroimpact.engines.numba_cache` reads of a numba dispatcher: its Python function and a cache."""

    def __init__(self, function: object) -> None:
        self.py_func = function
        self._cache = None


def test_callees_are_found_through_other_modules(monkeypatch: pytest.MonkeyPatch) -> None:
    """A kernel reached only through another module's kernel (a -> b -> c) is a callee of a as well: its machine code
    is in a's."""
    modules = {name: types.ModuleType(name) for name in ("fake_a", "fake_b", "fake_c")}
    sources = {"fake_c": "def leaf():\n    return 1\n", "fake_b": "def middle():\n    return leaf()\n", "fake_a": "def top():\n    return middle()\n"}
    for name, source in sources.items():
        exec(compile(source, f"{name}.py", "exec"), vars(modules[name]))  # noqa: S102 - a fixed test snippet
        monkeypatch.setitem(sys.modules, name, modules[name])
    vars(modules["fake_c"])["leaf"] = _Dispatcher(vars(modules["fake_c"])["leaf"])
    vars(modules["fake_b"])["leaf"] = vars(modules["fake_c"])["leaf"]
    vars(modules["fake_b"])["middle"] = _Dispatcher(vars(modules["fake_b"])["middle"])
    vars(modules["fake_a"])["middle"] = vars(modules["fake_b"])["middle"]
    vars(modules["fake_a"])["top"] = _Dispatcher(vars(modules["fake_a"])["top"])
    assert kernel_modules(vars(modules["fake_a"])) == [modules["fake_b"], modules["fake_c"]]
    assert kernel_modules(vars(modules["fake_c"])) == []
