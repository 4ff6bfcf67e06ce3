"""A study called at a plain script's top level (no ``if __name__ == "__main__":``), as a notebook user writes it:
the local cluster's workers do not run the script again as they start (it hung for 10 minutes: each worker started a
cluster of its own), and a worker process that runs it all the same (one dask restarts) is refused in one line.
The whole run from an unguarded script is the cluster tier's (tests/cluster/test_unguarded_script.py)."""

from __future__ import annotations

import subprocess
import sys
import types
from pathlib import Path

import pytest

from vibroimpact.runs.spawn_main import GUARD, workers_without_main

_TINY = """
from vibroimpact.scene.reader import parse_scene
SCENE = parse_scene({"name": "tiny", "system": {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0, "b1": 0.8, "b2": 0.08},
    "excitation": {"amplitude": 10.0}, "stop": {"clearance": 0.003, "restitution": 0.2},
    "sweep": {"frequency": {"start": 20.0, "stop": 30.0, "step": 5.0}}, "solutions": ["linear", "pgf"]})
"""

_SPAWNING = _TINY + """
import multiprocessing
from vibroimpact import run_study
print("ran", float(run_study(SCENE, progress=None)["x1_amplitude"].max()), flush=True)  # unguarded, as users write it


def nothing():
    pass


if __name__ == "__main__":  # a spawned child runs the script again (its main module), as a restarted worker does
    child = multiprocessing.get_context("spawn").Process(target=nothing)
    child.start()
    child.join()
    print("child exit", child.exitcode, flush=True)
"""


def test_a_worker_that_runs_the_script_again_is_refused_in_one_line_saying_what_to_write(tmp_path: Path) -> None:
    script = tmp_path / "unguarded.py"
    script.write_text(_SPAWNING)
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stdout.count("ran ") == 1 and "child exit 1" in done.stdout, done.stdout  # the parent's call ran; the child's was refused
    assert f"run_study was called while a worker process ran your script again (a worker restarted): put the call under {GUARD}" in done.stderr


def test_the_script_is_kept_from_the_workers_while_they_start_and_given_back(monkeypatch: pytest.MonkeyPatch) -> None:
    script = types.ModuleType("__main__")
    script.__file__ = "/home/user/analysis.py"
    script.__spec__ = None
    monkeypatch.setitem(sys.modules, "__main__", script)
    with workers_without_main():
        assert not hasattr(script, "__file__") and script.__spec__ is None  # multiprocessing finds no main to run again
    assert script.__file__ == "/home/user/analysis.py" and script.__spec__ is None
    entry = types.ModuleType("__main__")
    entry.__file__ = "/venv/bin/run-study"  # the package's guarded command keeps its own
    monkeypatch.setitem(sys.modules, "__main__", entry)
    with workers_without_main():
        assert entry.__file__ == "/venv/bin/run-study"
    monkeypatch.setitem(sys.modules, "__main__", script)
    with pytest.raises(ValueError), workers_without_main():  # given back whatever ends the block
        raise ValueError
    assert script.__file__ == "/home/user/analysis.py"

