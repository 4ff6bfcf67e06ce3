"""The output folder's files: written atomically (:func:`atomic_path`), and claimed by one study at a time
(:func:`claim_output`)."""

from __future__ import annotations

import fcntl
import os
import socket
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

__all__ = ["atomic_path", "OutputBusy", "claim_output"]


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
