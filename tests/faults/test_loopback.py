"""Nothing of a local run listens beyond loopback (issue 34, item 7): the scheduler, the workers and the dask
dashboard (which shows worker addresses, local paths, memory and call stacks) bind 127.0.0.1 unless
``$VIBROIMPACT_DASHBOARD`` moves the dashboard, and a malformed address is refused before anything starts."""

from __future__ import annotations

import ipaddress
import subprocess
import sys
import time
from pathlib import Path

import psutil
import pytest

from tests.run_study_process import start_run_study, stored_blocks, study_environment
from tests.test_cli import _slow_scene
from vibroimpact.runs.cluster import DASHBOARD_VARIABLE


def _listening(pid: int) -> set[tuple[str, int]]:
    """The TCP addresses the process ``pid`` and its descendants listen on."""
    addresses = set()
    try:
        parent = psutil.Process(pid)
        for process in [parent, *parent.children(recursive=True)]:
            for connection in process.net_connections(kind="tcp"):
                if connection.status == psutil.CONN_LISTEN:
                    addresses.add((connection.laddr.ip, connection.laddr.port))
    except psutil.NoSuchProcess:
        pass
    return addresses


@pytest.mark.faults
@pytest.mark.timeout(480)
def test_a_local_run_listens_on_loopback_only(tmp_path: Path) -> None:
    run = start_run_study([str(_slow_scene(tmp_path)), "--out", "out", "--jobs", "2"], tmp_path)
    seen: set[tuple[str, int]] = set()
    deadline = time.monotonic() + 180.0
    while stored_blocks(tmp_path / "out" / "interrupted.zarr") == 0 and run.poll() is None and time.monotonic() < deadline:
        seen |= _listening(run.pid)
        time.sleep(0.1)
    seen |= _listening(run.pid)  # the workers are up: a block is done
    run.communicate(timeout=300)
    assert run.returncode == 0
    assert len(seen) >= 5, seen  # the scheduler (and its dashboard), two nannies, two workers
    assert all(ipaddress.ip_address(host).is_loopback for host, _port in seen), sorted(seen)


@pytest.mark.faults
@pytest.mark.timeout(120)
@pytest.mark.parametrize("value", ["8787", "localhost:port", "127.0.0.1:99999"])
def test_a_malformed_dashboard_address_is_refused_before_anything_starts(tmp_path: Path, value: str) -> None:
    scene = _slow_scene(tmp_path)
    done = subprocess.run([sys.executable, "-m", "vibroimpact.cli", str(scene), "--out", "out", "--jobs", "2"], cwd=tmp_path,
                          env=study_environment() | {DASHBOARD_VARIABLE: value}, capture_output=True, text=True, timeout=100)  # fmt: skip
    assert done.returncode == 2, done.stderr
    assert done.stderr.strip().splitlines() == [f"run-study: error: ${DASHBOARD_VARIABLE} = {value!r}: allowed HOST:PORT with a port in [0, 65535] (e.g. 127.0.0.1:8787; ':8787' listens on every interface)"]
    assert not (tmp_path / "out").exists()
