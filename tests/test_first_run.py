"""The first run on a machine says what it waits for: with numba's cache cold, ``run-study`` compiles the exact
engine's core once, in the main process, before its workers start, and says so in one line; the next run loads it
from the cache and says nothing of it (slow tier: a cold compile takes ~30-50 s)."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

from tests.scene.test_scene import PAPER_SYSTEM_SPEC

COMPILING = "compiling the exact engine's core"


@pytest.mark.slow
@pytest.mark.timeout(600)
def test_a_cold_cache_compiles_once_and_says_so(tmp_path: Path) -> None:
    scene = {
        "name": "first_run", "description": "three exact steady states", "system": dict(PAPER_SYSTEM_SPEC),
        "excitation": {"amplitude": 10.0}, "stop": {"clearance": 0.003, "restitution": 0.2},
        "sweep": {"frequency": [22.0, 25.0, 28.0]}, "solutions": ["linear", "exact"], "report": False,
    }  # fmt: skip
    path = tmp_path / "first_run.yaml"
    path.write_text(yaml.safe_dump(scene), encoding="utf-8")
    environment = os.environ | {"NUMBA_CACHE_DIR": str(tmp_path / "numba")}  # a cold cache of this test's own

    def run(out: str) -> tuple[str, float]:
        start = time.perf_counter()
        done = subprocess.run([sys.executable, "-m", "vibroimpact.cli", str(path), "--out", str(tmp_path / out), "--jobs", "2"],
                              env=environment, capture_output=True, text=True, timeout=500)  # fmt: skip
        assert done.returncode == 0, done.stderr
        return done.stderr, time.perf_counter() - start

    cold, cold_seconds = run("cold")
    warm, warm_seconds = run("warm")
    assert cold.count(COMPILING) == 1, cold
    assert "compiled the exact engine's core in" in cold
    assert COMPILING not in warm, warm
    print(f"first run {cold_seconds:.1f} s, next run {warm_seconds:.1f} s: the first costs {cold_seconds - warm_seconds:.1f} s more")
