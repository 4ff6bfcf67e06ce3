"""The wheel holds every subpackage: ``pyproject.toml`` lists its packages by name, so a new folder under
``src/vibroimpact/`` that is not listed installs without its modules (an editable install hides it; CI's installed
package found ``vibroimpact.grids`` missing)."""

from __future__ import annotations

import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_every_subpackage_is_listed_in_pyproject() -> None:
    listed = set(tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["setuptools"]["packages"])
    source = ROOT / "src"
    found = {".".join(init.parent.relative_to(source).parts) for init in (source / "vibroimpact").rglob("__init__.py")}
    assert found <= listed, f"packages missing from pyproject.toml: {sorted(found - listed)}"
