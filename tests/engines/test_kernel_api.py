"""The compiled kernels' modules as an API: what another module imports of them has a public name and is in their
``__all__``, and their ``__all__`` lists nothing else (issue 30, item 5).

Read from the source of ``src/`` and ``tests/`` (every ``from X import name``, every ``X.name`` of a module imported
as X, at any depth, and the registry's ``module:Class`` targets), so a new use of a private name fails here.
"""

from __future__ import annotations

import ast
import importlib
from collections import defaultdict
from pathlib import Path

import pytest

from vibroimpact.engines.registry import ENGINES

ROOT = Path(__file__).resolve().parents[2]
#: The modules whose names other modules import: the compiled loops, their kernels and their Python faces.
KERNEL_MODULES = tuple(
    f"vibroimpact.engines.{name}"
    for name in (
        "exact", "exact_core", "exact_matrices", "exact_pieces", "exact_roots", "exact_moments", "exact_flows", "rigid_kernels",
        "flow_layout", "linear_flow", "kernel_arguments", "compliant.exact_loop", "compliant.exact",
    )
)  # fmt: skip


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT / "src" if path.is_relative_to(ROOT / "src") else ROOT).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _uses() -> dict[str, dict[str, set[str]]]:
    """Per kernel module, the names other modules use of it, each with the modules that use it."""
    uses: dict[str, dict[str, set[str]]] = defaultdict(lambda: defaultdict(set))
    for path in sorted((ROOT / "src").rglob("*.py")) + sorted((ROOT / "tests").rglob("*.py")):
        here = _module_name(path)
        tree = ast.parse(path.read_text(encoding="utf-8"))
        aliases: dict[str, str] = {}  # a local name bound to a kernel module
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.module:
                for alias in node.names:
                    if f"{node.module}.{alias.name}" in KERNEL_MODULES:
                        aliases[alias.asname or alias.name] = f"{node.module}.{alias.name}"
                    elif node.module in KERNEL_MODULES and node.module != here:
                        uses[node.module][alias.name].add(here)
            elif isinstance(node, ast.Import):
                aliases.update({alias.asname: alias.name for alias in node.names if alias.asname and alias.name in KERNEL_MODULES})
        for node in ast.walk(tree):
            if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and aliases.get(node.value.id, here) != here:
                uses[aliases[node.value.id]][node.attr].add(here)
    for name, spec in ENGINES.items():
        module, _, attribute = spec.target.partition(":")
        if module in KERNEL_MODULES:
            uses[module][attribute].add(f"registry ({name})")
    return uses


USES = _uses()


def test_the_scan_sees_the_known_uses() -> None:
    """Uses through each form the scan reads: a from-import, a module's attribute, a registry target."""
    assert "vibroimpact.engines.compliant.exact_loop" in USES["vibroimpact.engines.exact_pieces"]["piece_state"]
    assert "vibroimpact.engines.exact" in USES["vibroimpact.engines.exact_core"]["run_periods_until"]
    assert "registry (compliant_exact)" in USES["vibroimpact.engines.compliant.exact"]["CompliantExactEngine"]


def test_no_module_uses_a_private_name_of_a_kernel_module() -> None:
    private = {f"{module}.{name}": sorted(users) for module, names in USES.items() for name, users in names.items() if name.startswith("_")}
    assert not private, f"give these a public name (and list them in __all__): {private}"


@pytest.mark.parametrize("module", KERNEL_MODULES)
def test_all_lists_exactly_what_other_modules_use(module: str) -> None:
    listed = importlib.import_module(module).__all__
    assert len(listed) == len(set(listed)), f"{module}.__all__ repeats a name"
    used = set(USES[module])
    assert set(listed) == used, f"{module}: used but not in __all__ {sorted(used - set(listed))}, in __all__ but used nowhere else {sorted(set(listed) - used)}"
