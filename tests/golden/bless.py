"""Write the golden files again: ``python -m tests.golden.bless [NAME ...]`` (default: every golden scene).

Only on purpose: say in the commit message why the numbers or the pages changed (``CHANGES.md`` for a re-bless of
the whole suite).
"""

from __future__ import annotations

import os
import sys

from tests.golden.arithmetic import PINS, pinned

if __name__ == "__main__" and not pinned():  # before numpy is loaded: this process again, in the pinned arithmetic
    os.execve(sys.executable, [sys.executable, "-m", "tests.golden.bless", *sys.argv[1:]], {**os.environ, **PINS})

import tempfile  # noqa: E402
from pathlib import Path  # noqa: E402

from tests.golden.golden import DATA, compute, identical, read_back, scene_names, written  # noqa: E402
from vibroimpact.runs.run import write_dataset  # noqa: E402


def bless(name: str) -> None:
    """Write ``name``'s golden files (in the pinned arithmetic, :mod:`tests.golden.arithmetic`); a dataset identical to the blessed one, types included, is left as it is (its
    file would differ only by the ``history`` stamp)."""
    with tempfile.TemporaryDirectory() as folder:
        dataset, text = compute(name, Path(folder))
        target = DATA / f"{name}.nc"
        same = target.exists() and identical(written(dataset, Path(folder)), read_back(target))
    if not same:
        write_dataset(dataset, target)
    page = DATA / f"{name}.txt"
    if text is None:
        page.unlink(missing_ok=True)
    else:
        page.write_text(text, encoding="utf-8")
    print(f"blessed {name}{' (dataset unchanged)' if same else ''}", flush=True)


if __name__ == "__main__":
    for name in sys.argv[1:] or scene_names():
        bless(name)
