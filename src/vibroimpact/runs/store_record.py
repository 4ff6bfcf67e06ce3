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
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import zarr

__all__ = ["METADATA_FILES", "read_record", "record_digest", "restore", "set_aside", "check_members_readable", "consolidated_damage", "settle_io", "LEDGER", "ledger_path", "ledger_names", "add_to_ledger", "forget_ledger", "count_cases", "finished_work"]

#: The store's list of the cases it finished, one name a line, appended as each is sealed (``.<name>.zarr.finished``
#: beside the store: zarr warns of any file in its hierarchy that is none of its own): a case gone from the store (its
#: folder removed or lost) is then told from one never computed. It goes when its store goes or starts afresh.
LEDGER = ".finished"
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


def ledger_path(path: Path) -> Path:
    """Where the list of the cases the store at ``path`` finished is kept (:data:`LEDGER`)."""
    return path.with_name(f".{path.name}{LEDGER}")


def ledger_names(path: Path) -> set[str]:
    """The names of the cases the store at ``path`` finished (empty where it has no list). A line cut off by a kill
    names no case."""
    try:
        return set(ledger_path(path).read_text(encoding="utf-8").splitlines())
    except (OSError, UnicodeDecodeError):
        return set()


def add_to_ledger(path: Path, name: str) -> None:
    """Record beside the store at ``path`` that the case ``name`` is finished (after its checksum is written)."""
    with open(ledger_path(path), "a", encoding="utf-8") as ledger:
        ledger.write(name + "\n")


def forget_ledger(path: Path) -> None:
    """Remove the list of finished cases of the store at ``path`` (the store is gone, or starts afresh)."""
    ledger_path(path).unlink(missing_ok=True)


def count_cases(group: Any) -> int:
    """Finished cases in the ``cases`` group: arrays with their checksum, and (written by older code) groups marked
    complete."""
    return sum(1 for _name, case in group.arrays() if case.attrs.get("checksum")) + sum(1 for _name, case in group.groups() if case.attrs.get("complete"))


def finished_work(path: Path, block_done: str, cases_group: str, zarr_format: int) -> str:
    """'N finished blocks and M finished cases' of the store at ``path`` (what discarding it costs), read part by part
    so that a damaged root does not hide them: its flags of finished blocks (the array ``block_done``) and its
    ``cases_group``."""
    blocks = cases = 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # zarr warns of what it cannot recognise: counted as nothing
        try:
            blocks = int(np.asarray(zarr.open_array(str(path / block_done), mode="r", zarr_format=zarr_format)[...]).astype(bool).sum())
        except Exception:  # noqa: BLE001 - none, or damaged
            pass
        try:
            group = zarr.open_group(str(path / cases_group), mode="r", zarr_format=zarr_format)
            cases = count_cases(group)
        except Exception:  # noqa: BLE001 - none, or damaged
            pass
    return f"{blocks} finished blocks and {cases} finished cases"
