"""The names the README tells users to import resolve, from the package itself, in a fresh interpreter."""

from __future__ import annotations

import subprocess
import sys

import vibroimpact


def test_every_public_name_resolves() -> None:
    missing = [name for name in vibroimpact.__all__ if getattr(vibroimpact, name, None) is None]
    assert not missing, f"public names that do not resolve: {missing}"


def test_importing_the_package_loads_no_layer() -> None:
    """``import vibroimpact`` is light: the layers load when a public name is first used."""
    code = "import sys, vibroimpact; print(sorted(m for m in sys.modules if m.startswith('vibroimpact.')))"
    loaded = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
    assert loaded == "[]", loaded
