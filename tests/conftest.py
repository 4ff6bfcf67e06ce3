"""Shared fixtures: the paper's system (eq. 24) and its excitation."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from vibroimpact.model.system import PAPER_SYSTEM, TwoDofSystem

if TYPE_CHECKING:
    import xarray as xr

#: Excitation amplitude q of the paper's example [N].
PAPER_AMPLITUDE = 10.0
#: Clearance of the paper's example [m].
PAPER_CLEARANCE = 3e-3


def pytest_sessionstart(session: pytest.Session) -> None:
    """Compile the exact engine's numba core and the exact bumper's loop, with their batch entries, once, in the controlling process, before the
    xdist workers start: with a cold cache (a fresh clone) every worker would otherwise compile them at once (~30 s
    and ~30 s of CPU each); they load them from numba's on-disk cache instead. The two compile side by side, the loop
    in a child process (on a quiet 2-core machine ~30 s of wall time instead of ~40 s one after the other). Nothing
    happens where the cache holds them (a check of their indexes)."""
    import os
    import subprocess
    import sys

    if os.environ.get("PYTEST_XDIST_WORKER") is None:
        from vibroimpact.engines.registry import engine_spec
        from vibroimpact.runs.run import prepare_engines

        bumper = engine_spec("compliant_exact")
        child = None if bumper.kernels_cached(True) else subprocess.Popen([sys.executable, "-c", "from vibroimpact.runs.run import prepare_engines; prepare_engines(['compliant_exact'], batched=['compliant_exact'])"])
        prepare_engines(["exact"], batched=["exact"])
        if child is not None and child.wait() != 0:
            bumper.prepare_kernels(True)  # compiling here says why it failed


@pytest.fixture
def system() -> TwoDofSystem:
    """The paper's numerical example, eq. 24."""
    return PAPER_SYSTEM


@pytest.fixture(scope="session")
def small_bifurcation(tmp_path_factory: pytest.TempPathFactory) -> "xr.Dataset":
    """The small bifurcation study (``tests/kinds/bifurcation/test_bifurcation.py::SMALL``) run once for the whole test
    run and read back from its netCDF file: its dataset tests and its page tests share it, whichever workers run them
    (the first worker to need it runs it under a file lock; the others read its file)."""
    import fcntl
    import os

    from tests.kinds.bifurcation.test_bifurcation import SMALL
    from vibroimpact.runs.run import read_dataset, run_study, write_dataset
    from vibroimpact.scene import parse_scene

    # the run's folder: shared by the xdist workers (their base folders' parent); without xdist the base folder itself,
    # since its parent (/tmp/pytest-of-<user>) outlives the run and is shared by every checkout of the machine
    base = tmp_path_factory.getbasetemp()
    shared = base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base
    path = shared / "small_bifurcation.nc"
    with open(shared / "small_bifurcation.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not path.exists():
            write_dataset(run_study(parse_scene(SMALL), progress=None), path)
    return read_dataset(path)  # the file's labels back on their dimensions
