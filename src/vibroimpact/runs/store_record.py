"""The record of a study store's grid metadata, and the setting aside of a store that cannot be used.

A grid's values prove themselves by their blocks' checksums; what the export makes of them depends as much on each
array's metadata (``.zarray``: shape, chunks, dtype, fill value, compressor, filters, order) and attributes
(``.zattrs``: dimensions, units, flags, any CF attribute). When the grid begins, :func:`read_record` copies those
files of every grid array, with the grid's plan and list of variables; the copy and its digest (:func:`record_digest`)
are the last thing written, so a grid without them was cut off while being created. A rerun compares every file with
the record and writes back what differs (:func:`restore`): an edited dtype, a lost ``.zarray``, a truncated ``.zattrs``
are rebuilt, never exported; the values are then checked against their checksums as before.

zarr does its I/O on an event loop of its own, in a thread: a Ctrl-C while the run waits for a read or a write
leaves that I/O going on without it. :func:`settle_io` lets it end before the process does (an interpreter that
exits first destroys it half-way and prints asyncio's "Task was destroyed but it is pending!" after the run's last
line: the faults tier, once in 153).

A store that a rerun cannot use at all (its root attributes lost or unreadable, an unreadable array beside the grid's)
is set aside (:func:`set_aside`: renamed, never deleted) and the work is done again. A kept store's consolidated
metadata, a copy for readers, is checked against the files (:func:`consolidated_damage`) and written again.
"""

from __future__ import annotations

import asyncio
import hashlib
import json
import os
import time
from pathlib import Path
from typing import Any

__all__ = ["METADATA_FILES", "read_record", "record_digest", "restore", "set_aside", "check_members_readable", "consolidated_damage", "settle_io"]

#: An array's metadata files in zarr format 2.
METADATA_FILES = (".zarray", ".zattrs")


def _canonical(value: Any) -> str:
    """One text for equal JSON values (keys sorted, no spaces)."""
    return json.dumps(value, sort_keys=True, separators=(",", ":"))


def read_record(path: Path, names: list[str], plan: dict[str, Any]) -> dict[str, Any]:
    """The metadata files of the arrays ``names`` of the store at ``path`` (parsed JSON), and ``plan`` (the root's
    attributes that say how the grid is laid out: its shape, a block's shape, its variables).

    Raises
    ------
    OSError, ValueError
        When a file cannot be read or parsed (the grid was just written: it cannot happen but on a failing disk).
    """
    arrays: dict[str, dict[str, Any]] = {}
    for name in names:
        arrays[name] = {file: json.loads((path / name / file).read_text()) for file in METADATA_FILES if (path / name / file).exists()}
    return {"plan": plan, "arrays": arrays}


def record_digest(record: Any) -> str:
    """SHA-256 (hex) of a record: a record edited or cut off no longer matches the digest written with it."""
    return hashlib.sha256(_canonical(record).encode()).hexdigest()


def restore(path: Path, record: dict[str, Any]) -> list[str]:
    """Write back every metadata file of ``record`` that differs from the store's at ``path`` (lost, unreadable,
    edited); return the names of the arrays rebuilt, sorted.

    Each file is replaced atomically (written beside, then renamed), so a kill while restoring leaves each file
    either damaged as before or whole.
    """
    rebuilt = set()
    for name, files in record["arrays"].items():
        for file, content in files.items():
            target = path / name / file
            try:
                same = _canonical(json.loads(target.read_text())) == _canonical(content)
            except (OSError, ValueError):
                same = False
            if not same:
                target.parent.mkdir(parents=True, exist_ok=True)
                temporary = target.with_name(f"{file}.restoring-{os.getpid()}")
                temporary.write_text(json.dumps(content, indent=4, sort_keys=True))
                os.replace(temporary, target)
                rebuilt.add(name)
    return sorted(rebuilt)


def set_aside(path: Path) -> Path:
    """Rename the store ``path`` to ``<name>.damaged-<date>T<time>`` beside it (a second one that second gets a
    number) and return the new path: nothing is deleted, and the next run starts afresh."""
    stamp = time.strftime("%Y%m%dT%H%M%S")
    for attempt in range(1000):
        aside = path.with_name(f"{path.name}.damaged-{stamp}" + (f"-{attempt}" if attempt else ""))
        if not aside.exists():
            os.replace(path, aside)
            return aside
    raise FileExistsError(f"{path}: 1000 stores set aside in one second; remove some")


def check_members_readable(path: Path, skip: tuple[str, ...] = ()) -> None:
    """Check that every array or group in the root of the store at ``path`` (but those named in ``skip``, whose
    metadata their owner mends) has readable metadata.

    Raises
    ------
    ValueError
        Naming the first member whose ``.zarray``, ``.zgroup`` or ``.zattrs`` cannot be parsed.
    """
    for member in sorted(path.iterdir()):
        if member.name in skip:
            continue
        for file in (*METADATA_FILES, ".zgroup"):
            try:
                text = (member / file).read_text() if member.is_dir() and (member / file).exists() else None
                if text is not None:
                    json.loads(text)
            except (OSError, ValueError) as error:
                raise ValueError(f"{member.name}/{file} is unreadable: {error}") from None


def consolidated_damage(path: Path) -> str | None:
    """What is wrong with the consolidated metadata (``.zmetadata``) of the kept store at ``path``, a copy of every
    array's own ``.zarray``, ``.zattrs`` and ``.zgroup`` for readers (a run reads the files themselves): ``"is lost"``,
    ``"is unreadable"``, ``"differs from the arrays' own metadata (KEYS)"``, or None where it is whole."""
    try:
        recorded = json.loads((path / ".zmetadata").read_text())["metadata"]
        files = {member.relative_to(path).as_posix() for member in path.rglob(".z*") if member.name in (".zarray", ".zattrs", ".zgroup")}
        differ = sorted(key for key in files | set(recorded) if key not in recorded or key not in files or json.loads((path / key).read_text()) != recorded[key])
    except FileNotFoundError:
        return "is lost"
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return "is unreadable"
    if differ:
        return f"differs from the arrays' own metadata ({', '.join(differ[:3])}{' ...' if len(differ) > 3 else ''})"
    return None


def settle_io(timeout: float = 10.0) -> bool:
    """Wait (up to ``timeout`` [s]) for the reads and writes zarr's event loop is still doing for a call that an
    interrupt cut off; say whether they all ended. A write that ends here is still unproved (its case's checksum or
    its block's flag comes in a later call): the next run checks it as it checks any other."""
    from zarr.core.sync import sync  # zarr's own event loop, the one its synchronous API runs on

    async def others_ended() -> bool:
        others = [task for task in asyncio.all_tasks() if task is not asyncio.current_task()]
        if not others:
            return True
        _done, pending = await asyncio.wait(others, timeout=timeout)
        return not pending

    return bool(sync(others_ended()))
