"""``run-study`` as a separate process, the way a terminal runs it, and what its zarr store has finished: shared by the
command-line tests and the ``cluster`` tier."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np

from vibroimpact.runs.cluster import SCHEDULER_VARIABLE


def study_environment(scheduler: str | None = None) -> dict[str, str]:
    """This process's environment for ``run-study``, with ``VIBROIMPACT_SCHEDULER`` set to ``scheduler`` (None: unset,
    whatever the machine running the tests has set)."""
    environment = {name: value for name, value in os.environ.items() if name != SCHEDULER_VARIABLE}
    return environment | ({SCHEDULER_VARIABLE: scheduler} if scheduler is not None else {})


def start_run_study(arguments: list[str], folder: Path, scheduler_variable: str | None = None, module: str = "vibroimpact.cli") -> subprocess.Popen[str]:
    """``run-study ARGUMENTS`` in ``folder`` (``VIBROIMPACT_SCHEDULER``: ``scheduler_variable``), in its own process
    group as a terminal's foreground job (SIGINT handled as in an interactive shell, even where the tests' own process
    ignores it, as pytest-xdist's workers do), stdout and stderr piped; ``module``: the one run as ``python -m``
    (``vibroimpact.entry``: the ``run-study`` command's own entry point)."""
    return subprocess.Popen(
        [sys.executable, "-m", module, *arguments],
        cwd=folder,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=study_environment(scheduler_variable),
        start_new_session=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )


def stored_blocks(store: Path) -> int:
    """Blocks flagged done in the zarr store at ``store`` (0 before the store or its flags exist)."""
    import zarr

    try:
        return int(np.asarray(zarr.open_group(str(store), mode="r")["block_done"][...]).sum())
    except (FileNotFoundError, KeyError, ValueError, zarr.errors.GroupNotFoundError):
        return 0
