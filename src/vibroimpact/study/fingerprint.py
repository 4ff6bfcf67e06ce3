"""A fingerprint of the code that computes: cache keys and datasets name the exact source they came from."""

from __future__ import annotations

import functools
import hashlib
import json
from pathlib import Path
from typing import Any

from vibroimpact import __version__

__all__ = ["source_hash", "case_key"]

_PACKAGE = Path(__file__).resolve().parents[1]  # the vibroimpact package


@functools.cache
def source_hash() -> str:
    """SHA-256 (hex) over the package's Python source files, their paths and contents, in a stable order.

    Any edit of the code changes it, whatever the version number says, so results cached by older code are not reused.
    """
    digest = hashlib.sha256()
    for path in sorted(_PACKAGE.rglob("*.py")):
        digest.update(path.relative_to(_PACKAGE).as_posix().encode())
        digest.update(b"\0")
        digest.update(path.read_bytes())
        digest.update(b"\0")
    return digest.hexdigest()


def case_key(content: dict[str, Any]) -> str:
    """A stable 24-hex-digit key of ``content`` (JSON-serialisable), the package version and its source hash."""
    text = json.dumps({"version": __version__, "source": source_hash(), "case": content}, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:24]
