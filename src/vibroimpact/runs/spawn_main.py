"""A study run from a plain script, as a notebook user writes it: no ``if __name__ == "__main__":`` guard.

A local cluster's workers are spawned processes, and ``multiprocessing`` runs the parent's main module again in each
(to find what the parent defined there). A script that calls ``run_study(scene, jobs=2)`` at its top level then
calls it again in every worker as it starts, each of which starts a cluster of its own: the run printed "starting 2
worker processes" three times and waited for 10 minutes at 3 % CPU. The workers need nothing of the script (every
task is a function of this package), so while they start the script is kept from them
(:func:`workers_without_main`): the package's own entry points (``run-study``, ``python -m vibroimpact...``) are
guarded and are run again as before. A worker that dask starts again later (after one died) does run the script:
there :func:`refuse_in_a_spawned_import` stops the study's call in one line saying what to write.
"""

from __future__ import annotations

import multiprocessing
import sys
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

__all__ = ["GUARD", "workers_without_main", "refuse_in_a_spawned_import"]

#: What a script that runs a study with worker processes should write.
GUARD = 'if __name__ == "__main__":'


def _ours(main: object) -> bool:
    """Whether the main module is one of the package's guarded entry points (the ``run-study`` command, ``python -m
    vibroimpact.cli``)."""
    spec = getattr(main, "__spec__", None)
    if spec is not None and str(getattr(spec, "name", "")).split(".")[0] == "vibroimpact":
        return True
    path = getattr(main, "__file__", None)
    return isinstance(path, str) and Path(path).name == "run-study"


@contextmanager
def workers_without_main() -> Iterator[None]:
    """Worker processes spawned within the block do not run the parent's main module (a user's script, which may call
    the study again unguarded): its ``__file__`` and ``__spec__``, from which ``multiprocessing`` finds it, are put
    aside and given back after. A notebook's main module has neither (nothing to do); the package's entry points
    keep theirs."""
    main = sys.modules.get("__main__")
    if main is None or _ours(main):
        yield
        return
    kept = {name: main.__dict__[name] for name in ("__file__", "__spec__") if name in main.__dict__}
    main.__dict__.pop("__file__", None)
    main.__dict__["__spec__"] = None
    try:
        yield
    finally:
        main.__dict__.pop("__spec__", None)
        main.__dict__.update(kept)


def refuse_in_a_spawned_import(call: str) -> None:
    """Raise RuntimeError if this process is a spawned child still preparing, which is when it runs its parent's
    script (as ``__mp_main__``): a study called at a script's top level, run again by a worker that dask restarted."""
    if getattr(multiprocessing.current_process(), "_inheriting", False):  # a spawned child, preparing: running the parent's main
        raise RuntimeError(f"{call} was called while a worker process ran your script again (a worker restarted): put the call under {GUARD} "
                           "so that only the script's own process runs it")
