"""The first run on a machine says what it waits for: with numba's cache cold, ``run-study`` compiles the kernels of
every compiled engine the scene runs (here the rigid stop's exact engine and the bumper's), once each, in the main
process, before its workers start, and says so in one line each; no point's wall time includes a compile; the next
run loads them from the cache and says nothing of it (slow tier: a cold compile takes ~30-60 s per engine)."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml

from vibroimpact import read_dataset

from tests.scene.test_scene import PAPER_SYSTEM_SPEC

ENGINES = ("exact", "compliant_exact")


@pytest.mark.slow
@pytest.mark.timeout(900)
def test_a_cold_cache_compiles_each_engine_once_says_so_and_times_no_compile(tmp_path: Path) -> None:
    scene = {
        "name": "first_run", "description": "exact steady states, rigid and bumper", "system": dict(PAPER_SYSTEM_SPEC),
        "excitation": {"amplitude": 10.0}, "stop": {"clearance": 0.003, "restitution": 0.2}, "bumper": {"frequency": 250.0},
        "sweep": {"frequency": [22.0, 25.0, 28.0, 31.0]}, "solutions": ["linear", "exact", "compliant_exact"],
        "quantities": ["x1_amplitude", "wall_time"], "report": False,
    }  # fmt: skip
    path = tmp_path / "first_run.yaml"
    path.write_text(yaml.safe_dump(scene), encoding="utf-8")
    environment = os.environ | {"NUMBA_CACHE_DIR": str(tmp_path / "numba")}  # a cold cache of this test's own

    def run(out: str) -> tuple[str, float, np.ndarray]:
        start = time.perf_counter()
        done = subprocess.run([sys.executable, "-m", "vibroimpact.cli", str(path), "--out", str(tmp_path / out), "--jobs", "2"],
                              env=environment, capture_output=True, text=True, timeout=800)  # fmt: skip
        assert done.returncode == 0, done.stderr
        wall = read_dataset(tmp_path / out / "first_run.nc")["wall_time"].sel(solution=["exact", "compliant_exact"]).values
        return done.stderr, time.perf_counter() - start, wall

    cold, cold_seconds, cold_wall = run("cold")
    warm, warm_seconds, warm_wall = run("warm")
    for engine in ENGINES:
        assert cold.count(f"compiling the {engine} engine's kernels") == 1, cold
        assert f"compiled the {engine} engine's kernels in" in cold, cold
    assert "compiling" not in warm, warm
    # a compile takes tens of seconds; a point of this scene some milliseconds (its slowest, both runs: < 2 s)
    assert np.nanmax(cold_wall) < 2.0, cold_wall
    assert np.nanmax(warm_wall) < 2.0, warm_wall
    print(f"first run {cold_seconds:.1f} s, next run {warm_seconds:.1f} s: the first costs {cold_seconds - warm_seconds:.1f} s more")
