"""The output folder's files: written atomically (:func:`atomic_path`), claimed by one study at a time
(:func:`claim_output`), and a finished run's dataset recognised by a rerun (:func:`finished_run`)."""

from __future__ import annotations

import fcntl
import os
import socket
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

__all__ = ["atomic_path", "OutputBusy", "claim_output", "finished_run"]


def finished_run(path: Path, scene_text: str) -> tuple[bool, str]:
    """Whether the dataset at ``path`` is a finished run of the scene ``scene_text`` by this code (the same values,
    not counting comments, description, report or cluster, and the same package source), and why not where it is not.

    Returns
    -------
    (bool, str)
        (True, "") where it is; (False, the reason in words) where it is not; (False, "") where there is no dataset.
    """
    if not path.exists():
        return False, ""
    from vibroimpact import __version__
    from vibroimpact.runs.fingerprints import changed_keys, fingerprinted_values, source_hash, store_fingerprint

    try:
        import netCDF4

        with netCDF4.Dataset(path) as handle:
            attrs = {name: handle.getncattr(name) for name in ("scene", "vibroimpact_version", "vibroimpact_source_sha256") if name in handle.ncattrs()}
    except OSError as error:
        return False, f"it cannot be read ({error})"
    if "scene" not in attrs:
        return False, "it records no scene"
    if attrs.get("vibroimpact_version") != __version__ or attrs.get("vibroimpact_source_sha256") != source_hash():
        return False, "other code made it (another vibroimpact version or source)"
    if store_fingerprint(str(attrs["scene"])) != store_fingerprint(scene_text):
        keys = changed_keys(fingerprinted_values(str(attrs["scene"])), fingerprinted_values(scene_text))
        return False, f"the scene's values changed since it was made{f' ({keys})' if keys else ''}"
    return True, ""


@contextmanager
def atomic_path(path: Path, suffix: str = ".tmp") -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on success it replaces ``path`` (mode 0644), on failure it is removed.

    ``suffix`` is the temporary file's ending (``.npz`` for ``numpy.savez``, which would otherwise add one).
    """
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix, dir=path.parent)
    os.close(handle)
    temporary = Path(name)
    try:
        yield temporary
        os.chmod(temporary, 0o644)
        os.replace(temporary, path)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise


class OutputBusy(RuntimeError):
    """Another study is writing the same output folder."""


@contextmanager
def claim_output(out_dir: Path) -> Iterator[Path]:
    """Hold an exclusive lock on ``out_dir/.run-study.lock`` while a study writes there.

    The lock is the operating system's (``flock``): it goes with the process, so a run that was killed leaves nothing
    to clean up, and two runs can never both hold it. The file says who holds it.

    Raises
    ------
    OutputBusy
        When another process holds it (its process id, host and start time are named).
    """
    lock = out_dir / ".run-study.lock"
    while True:
        handle = os.open(lock, os.O_CREAT | os.O_RDWR, 0o644)
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(handle)
            owner = _lock_owner(lock)
            who = f"process {owner[0]} on {owner[1]}, since {owner[2]}" if owner else "another process"
            raise OutputBusy(f"{out_dir} is being written by another run-study ({who}); wait for it to finish or choose another --out") from None
        try:
            same = os.fstat(handle).st_ino == os.stat(lock).st_ino
        except FileNotFoundError:
            same = False
        if same:
            break
        os.close(handle)  # the file was removed by its last holder between our open and our lock: take the new one
    os.ftruncate(handle, 0)
    os.write(handle, f"{os.getpid()} {socket.gethostname()} {time.strftime('%Y-%m-%dT%H:%M:%S')}\n".encode())
    try:
        yield lock
    finally:
        lock.unlink(missing_ok=True)  # while still locked: a waiting run then locks a removed file, sees it, retries
        os.close(handle)


def _lock_owner(lock: Path) -> tuple[int, str, str] | None:
    try:
        pid, host, since = lock.read_text().split()
        return int(pid), host, since
    except (OSError, ValueError):
        return None
