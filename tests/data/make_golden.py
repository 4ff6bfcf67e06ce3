"""Regenerate the golden dataset after an intended change of results: ``python tests/data/make_golden.py``.

Say in the commit message why the numbers changed.
"""

from pathlib import Path

from vibroimpact.scene import load_scene
from vibroimpact.runs.run import write_dataset
from vibroimpact.runs.run import run_study

HERE = Path(__file__).parent

if __name__ == "__main__":
    dataset = run_study(load_scene(HERE / "golden_small.yaml"))
    print(write_dataset(dataset, HERE / "golden_small.nc"))
