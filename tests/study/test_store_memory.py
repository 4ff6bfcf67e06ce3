"""Bounded memory (slow tier): a closed-form study of 10^6 points streams its blocks into the store and exports them
chunk by chunk, so its main process peaks like a 10^5-point study's with blocks of the same size (50 000 points),
far below the dataset it writes."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
import xarray as xr
import yaml

from tests.study.test_estimate import small_scene


def _run(folder: Path, restitutions: int, clearances: int) -> xr.Dataset:
    document = small_scene() | {
        "name": f"grid{restitutions}x{clearances}",
        "sweep": {
            "restitution": {"start": 0.0, "stop": 0.9, "num": restitutions},
            "clearance": {"start": 0.001, "stop": 0.005, "num": clearances},
            "frequency": {"start": 15.0, "stop": 45.0, "num": 1000},
        },
        "solutions": ["linear", "pgf"],
    }
    document.pop("stop")
    document.pop("simulation")
    scene = folder / f"{document['name']}.yaml"
    scene.write_text(yaml.safe_dump(document))
    subprocess.run([sys.executable, "-m", "vibroimpact.cli", str(scene), "--out", str(folder / document["name"]), "--jobs", "2"], check=True, capture_output=True, timeout=1200)
    return xr.open_dataset(folder / document["name"] / f"{document['name']}.nc")


@pytest.mark.slow
@pytest.mark.timeout(1500)
def test_the_main_process_does_not_grow_with_the_grid(tmp_path: Path) -> None:
    small = _run(tmp_path, 2, 50)  # 10^5 points: two blocks
    big = _run(tmp_path, 100, 10)  # 10^6 points: every quantity of two solutions, ~0.4 GB in memory
    growth = float(big.attrs["run_peak_memory_bytes"]) - float(small.attrs["run_peak_memory_bytes"])
    with big:
        size = big.nbytes
    assert size > 3e8
    assert growth < 0.1 * size, f"main process peak grew by {growth / 1e6:.0f} MB for a dataset of {size / 1e6:.0f} MB"
