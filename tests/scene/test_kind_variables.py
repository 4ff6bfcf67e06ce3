"""A variable only one kind writes is declared in that kind's folder (``kinds/<kind>/variables.py``); the scene layer's
table (:mod:`vibroimpact.scene.variables`) keeps those more than one kind shares."""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

import pytest

import vibroimpact.scene.variables as shared

PACKAGE = Path(__file__).resolve().parents[2] / "src" / "vibroimpact"
#: Each kind's own variables, by the folder that declares them.
OWN = {
    "bifurcation": ("BIFURCATION_ATTRIBUTES",),
    "benchmark": ("BENCHMARK_ATTRIBUTES", "LADDER_ATTRIBUTES", "SWEEP_COST_ATTRIBUTES"),
    "swept": ("SWEEP_STAT_ATTRIBUTES", "SWEEP_TIME_ATTRIBUTES", "swept_attributes", "running_attributes"),
}


def imports_from(module: str) -> list[tuple[Path, str]]:
    """(importing file, imported name) of every ``from <module> import name`` in the package."""
    found = []
    for path in PACKAGE.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and node.module == module:
                found += [(path, alias.name) for alias in node.names]
    return found


@pytest.mark.parametrize("kind", list(OWN))
def test_a_kinds_variables_are_declared_and_read_in_its_own_folder(kind: str) -> None:
    """The kind's module declares its variables (in its ``__all__``), the shared table does not, and only modules of
    the kind's folder import them."""
    module = importlib.import_module(f"vibroimpact.kinds.{kind}.variables")
    assert set(OWN[kind]) <= set(module.__all__)
    assert all(hasattr(module, name) for name in OWN[kind])
    assert not any(hasattr(shared, name) for name in OWN[kind])
    readers = imports_from(f"vibroimpact.kinds.{kind}.variables")
    assert readers, f"no module of kinds/{kind} reads its variables"
    assert all(path.parent == PACKAGE / "kinds" / kind for path, _ in readers), readers


def test_no_module_reads_a_kinds_variables_from_the_shared_table() -> None:
    """Nothing imports from the scene layer's table a name it no longer has (every name it exports exists)."""
    owned = {name for names in OWN.values() for name in names}
    read = {name for _, name in imports_from("vibroimpact.scene.variables")}
    assert read, "the shared table has readers"
    assert not read & owned
    assert read <= set(shared.__all__)
    assert all(hasattr(shared, name) for name in shared.__all__)
