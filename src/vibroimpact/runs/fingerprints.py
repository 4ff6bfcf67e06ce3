"""What stored work is keyed and checked by: the fingerprint of the code that computes (:func:`source_hash`), the
keys of finished cases (:func:`case_key`), a store's fingerprint of its scene's values and the code
(:func:`store_fingerprint`), and the digest of the values a block or a case wrote (:func:`values_digest`). Results
of other code or other values are never reused (:mod:`vibroimpact.runs.store`, which re-exports these names).
"""

from __future__ import annotations

import functools
import hashlib
import json
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from vibroimpact import __version__

__all__ = ["source_hash", "case_key", "store_fingerprint", "fingerprinted_values", "fingerprint_of", "changed_keys", "code_fingerprint", "values_digest", "NOT_IN_FINGERPRINT"]


# --------------------------------------------------------------------------------------------------------------------
# A fingerprint of the code that computes: cache keys and datasets name the exact source they came from.
# --------------------------------------------------------------------------------------------------------------------

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


def values_digest(arrays: list[tuple[str, NDArray[np.generic]]]) -> bytes:
    """SHA-256 of named arrays: each name, dtype, shape and C-order bytes, in the given order.

    A block's or a case's values read back from the store must give the digest they were written with: a lost chunk
    (read as the fill value), a truncated or swapped one, all change it.
    """
    digest = hashlib.sha256()
    for name, values in arrays:
        array = np.ascontiguousarray(values)
        digest.update(f"{name}\0{array.dtype.str}\0{array.shape}\0".encode())
        digest.update(array.tobytes())
    return digest.digest()


#: Top-level scene keys that change no number: a store survives their edits (where the work runs, the page's words).
NOT_IN_FINGERPRINT = ("cluster", "description", "report")


def fingerprinted_values(scene_text: str) -> str:
    """The part of a scene a store's results depend on, as text: its values without comments nor the keys of
    :data:`NOT_IN_FINGERPRINT`, keys sorted (the text itself where it is no YAML mapping). A store records it beside
    its fingerprint, so that a rerun can tell a changed scene (and which keys changed) from an edited fingerprint."""
    import yaml

    try:
        document = yaml.safe_load(scene_text)
    except yaml.YAMLError:
        document = None
    if isinstance(document, dict):
        return yaml.safe_dump({key: value for key, value in document.items() if key not in NOT_IN_FINGERPRINT}, sort_keys=True)
    return scene_text


def fingerprint_of(code: str, values: str) -> str:
    """The fingerprint of the values text ``values`` (:func:`fingerprinted_values`) computed by the code ``code``
    (:func:`code_fingerprint`): 24 hex digits."""
    return hashlib.sha256(f"{code}\0{values}".encode()).hexdigest()[:24]


def store_fingerprint(scene_text: str) -> str:
    """What a store's results depend on: the scene's values (not its comments, nor the keys of
    :data:`NOT_IN_FINGERPRINT`), the package version and the package's source (:func:`code_fingerprint`)."""
    return fingerprint_of(code_fingerprint(), fingerprinted_values(scene_text))


def changed_keys(before: str, after: str, most: int = 4) -> str:
    """The keys whose values differ between two values texts (:func:`fingerprinted_values`), dotted
    (``design.band.stop``), at most ``most`` named and the rest counted; ``""`` where none can be named."""
    import yaml

    def flat(document: Any, prefix: str = "") -> dict[str, Any]:
        if isinstance(document, dict) and document:
            return {path: value for key, item in document.items() for path, value in flat(item, f"{prefix}{key}.").items()}
        return {prefix.rstrip("."): document}

    try:
        old, new = flat(yaml.safe_load(before)), flat(yaml.safe_load(after))
    except yaml.YAMLError:
        return ""
    differ = sorted(key for key in old.keys() | new.keys() if key and (key not in old or key not in new or old[key] != new[key]))
    if not differ:
        return ""
    named = ", ".join(differ[:most])
    return named + (f" and {len(differ) - most} more" if len(differ) > most else "")


def code_fingerprint() -> str:
    """The package version and its source (:func:`source_hash`): results of other code are not reused."""
    return hashlib.sha256(f"{__version__}\0{source_hash()}".encode()).hexdigest()[:24]
