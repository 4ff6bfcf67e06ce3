"""numba keys a cached compiled function on its own source file only; the compiled loops call kernels of other files
(a piece of flow, the root search, the moments, the exact loop's Jacobian helpers) and read constants of other files
(numba freezes them into the machine code), so each loop's cache stamp also carries those files' sources: an edit of
a kernel or of a constant recompiles its readers, never a stale copy."""

from __future__ import annotations

import hashlib
import importlib
import json
import os
import pkgutil
import subprocess
import sys
import types
from collections.abc import Iterator
from pathlib import Path

import pytest

from vibroimpact import engines
from vibroimpact.engines import exact_core, exact_matrices, exact_moments, exact_pieces, exact_roots, rigid_kernels, sundae
from vibroimpact.engines.compliant import exact_loop, model
from vibroimpact.engines.numba_cache import compiled_functions, kernel_modules


def _sources(*modules: object) -> str:
    """SHA-256 of the modules' files, in that order, computed here."""
    digest = hashlib.sha256()
    for module in modules:
        digest.update(Path(module.__file__).read_bytes())  # type: ignore[attr-defined]
    return digest.hexdigest()


def test_each_loop_finds_every_file_whose_kernels_it_compiles() -> None:
    assert kernel_modules(vars(exact_loop)) == [exact_matrices, exact_moments, exact_pieces, exact_roots]  # the matrix helpers exact_core shares
    assert kernel_modules(vars(exact_core)) == [exact_matrices, exact_moments, exact_pieces, exact_roots]
    assert kernel_modules(vars(exact_moments)) == [exact_pieces]
    assert kernel_modules(vars(exact_roots)) == [exact_pieces]  # its root search holds exact_pieces.ZERO, a constant
    assert kernel_modules(vars(rigid_kernels)) == [sundae]  # its kernels read sundae's intrinsics
    assert kernel_modules(vars(exact_pieces)) == [] and kernel_modules(vars(model)) == []


def test_every_compiled_function_carries_its_callees_sources_in_its_stamp() -> None:
    readers = ((exact_loop, (exact_matrices, exact_moments, exact_pieces, exact_roots)), (exact_core, (exact_matrices, exact_moments, exact_pieces, exact_roots)), (exact_moments, (exact_pieces,)), (exact_roots, (exact_pieces,)))
    for module, callees in readers:
        functions = compiled_functions(vars(module))
        assert len(functions) >= 5, module.__name__
        for function in functions:
            stamp = function._cache._cache_file._source_stamp
            assert isinstance(stamp, tuple) and stamp[-1] == _sources(*callees), f"{module.__name__}.{function.py_func.__name__}"
    for function in compiled_functions(vars(exact_pieces)):
        assert not isinstance(function._cache._cache_file._source_stamp[-1], str), "a module that reads no other keeps numba's own stamp"


def test_every_module_whose_kernels_read_another_is_stamped() -> None:
    """Each engine module with compiled functions that read another module calls the stamp (one that forgot would be
    served stale machine code after an edit of what it reads)."""
    stamped = []
    for info in pkgutil.walk_packages(engines.__path__, "vibroimpact.engines."):
        module = importlib.import_module(info.name)
        read = kernel_modules(vars(module))
        for function in compiled_functions(vars(module)) if read else []:
            assert function._cache._cache_file._source_stamp[-1] == _sources(*read), f"{info.name}.{function.py_func.__name__}"
            stamped.append(info.name)
    assert {"vibroimpact.engines.exact_roots", "vibroimpact.engines.rigid_kernels", "vibroimpact.engines.compliant.exact_loop"} <= set(stamped)


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


#: A package of kernels that read constants of other modules, every way the stamp follows: imported by name, through
#: a module that re-exports it (a relative import), as a module's attribute; and a constant of their own that another
#: module also defines, bound to the very same object (a small integer), which no other module's edit may recompile.
_PACKAGE = {
    "__init__.py": "",
    "consts.py": "SCALE = 2.0\nSTATUS = 0\n",
    "again.py": "from .consts import SCALE  # a re-export\n",
    "kernels.py": (
        "from numba import njit\n\n"
        "from kpkg import consts\n"
        "from kpkg.again import SCALE as AGAIN\n"
        "from kpkg.consts import SCALE\n"
        "from vibroimpact.engines.numba_cache import stamp_with_callees\n\n"
        "@njit(cache=True)\ndef by_name(x):\n    return SCALE * x\n\n"
        "@njit(cache=True)\ndef re_exported(x):\n    return AGAIN * x\n\n"
        "@njit(cache=True)\ndef by_attribute(x):\n    return consts.SCALE * x\n\n"
        "stamp_with_callees(globals())\n"
    ),
    "own.py": (
        "from numba import njit\n\n"
        "from kpkg.consts import SCALE  # imported, never read by a kernel\n"
        "from vibroimpact.engines.numba_cache import stamp_with_callees\n\n"
        "STATUS = 0\n\n"
        "@njit(cache=True)\ndef status(x):\n    return STATUS + x\n\n"
        "stamp_with_callees(globals())\n"
    ),
}


@pytest.fixture
def kernel_package(tmp_path: Path) -> Iterator[Path]:
    """:data:`_PACKAGE` written under ``tmp_path`` as ``kpkg``, importable; unloaded afterwards."""
    (tmp_path / "kpkg").mkdir()
    for name, source in _PACKAGE.items():
        (tmp_path / "kpkg" / name).write_text(source, encoding="utf-8")
    sys.path.insert(0, str(tmp_path))
    try:
        yield tmp_path
    finally:
        sys.path.remove(str(tmp_path))
        for name in [name for name in sys.modules if name == "kpkg" or name.startswith("kpkg.")]:
            del sys.modules[name]


def test_constants_are_found_in_the_modules_that_define_them(kernel_package: Path) -> None:
    """Homes come from the import statements: a re-export and its source both; a module's own constant is its own,
    although another module binds the same object to the same name."""
    kernels = importlib.import_module("kpkg.kernels")
    own = importlib.import_module("kpkg.own")
    consts, again = sys.modules["kpkg.consts"], sys.modules["kpkg.again"]
    assert own.STATUS is consts.STATUS  # what identity alone could not tell apart
    assert kernel_modules(vars(kernels)) == [again, consts]
    assert kernel_modules(vars(own)) == []
    for name, found in (("by_name", [consts]), ("re_exported", [again, consts]), ("by_attribute", [consts])):
        alone = {key: value for key, value in vars(kernels).items() if key != "stamp_with_callees" and (not hasattr(value, "py_func") or key == name)}
        assert kernel_modules(alone) == found, name


_RUN = """
import json
from kpkg import kernels, own
values = [kernels.by_name(3.0), kernels.re_exported(3.0), kernels.by_attribute(3.0), float(own.status(3))]
misses = [sum(f.stats.cache_misses.values()) for f in (kernels.by_name, kernels.re_exported, kernels.by_attribute, own.status)]
print(json.dumps([values, misses]))
"""


def _run_kernels(folder: Path) -> tuple[list[float], list[int]]:
    """The kernels' values at 3 and how many each compiled, in a fresh interpreter with its numba cache in ``folder``
    (and this very package, wherever it was imported from)."""
    paths = [str(folder), str(Path(engines.__file__).parents[2]), os.environ.get("PYTHONPATH", "")]
    env = {**os.environ, "NUMBA_CACHE_DIR": str(folder / "numba_cache"), "PYTHONPATH": os.pathsep.join(paths)}
    done = subprocess.run([sys.executable, "-B", "-c", _RUN], cwd=folder, env=env, capture_output=True, text=True, check=True, timeout=240)
    values, misses = json.loads(done.stdout.splitlines()[-1])
    return values, misses


def test_an_edited_constant_recompiles_its_readers_and_nothing_else(kernel_package: Path) -> None:
    """numba freezes a global constant into the machine code: after an edit of the module that defines it, every kernel
    that reads it compiles again and gives the new value (numba's own stamp would load the old code from the cache);
    with nothing edited, nothing compiles."""
    values, misses = _run_kernels(kernel_package)
    assert values == pytest.approx([6.0, 6.0, 6.0, 3.0], rel=1e-12) and misses == [1, 1, 1, 1]
    values, misses = _run_kernels(kernel_package)
    assert values == pytest.approx([6.0, 6.0, 6.0, 3.0], rel=1e-12) and misses == [0, 0, 0, 0]  # all from the cache
    (kernel_package / "kpkg" / "consts.py").write_text("SCALE = 2.5\nSTATUS = 0\n", encoding="utf-8")
    values, misses = _run_kernels(kernel_package)
    assert values == pytest.approx([7.5, 7.5, 7.5, 3.0], rel=1e-12) and misses == [1, 1, 1, 0]
