"""``run_study(scene, jobs=2)`` at the top level of a plain script, no ``if __name__ == "__main__":`` guard (how a
notebook user writes it): it printed "starting 2 worker processes" three times and then nothing for 10 minutes, each
worker running the script again and starting a cluster of its own. Now the workers start without the script
(:mod:`vibroimpact.runs.spawn_main`) and the script answers as the serial run does."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.cluster

#: Longest the unguarded script may take here, however loaded the machine [s] (~15 s quiet: two workers' imports).
SCRIPT_TIMEOUT = 240.0

_SCRIPT = """
import sys
from vibroimpact import run_study
from vibroimpact.scene.reader import parse_scene
scene = parse_scene({"name": "tiny", "system": {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0, "b1": 0.8, "b2": 0.08},
    "excitation": {"amplitude": 10.0}, "stop": {"clearance": 0.003, "restitution": 0.2},
    "sweep": {"frequency": {"start": 20.0, "stop": 30.0, "step": 1.0}}, "solutions": ["linear", "pgf", "exact"]})
dataset = run_study(scene, jobs=int(sys.argv[1]), progress=None)
print("script ran")
print(repr(dataset["x1_amplitude"].values.tolist()))
"""


def test_an_unguarded_script_with_two_workers_answers_as_the_serial_run(tmp_path: Path) -> None:
    script = tmp_path / "notebook_style.py"
    script.write_text(_SCRIPT)
    answers = {}
    for jobs in (1, 2):
        done = subprocess.run([sys.executable, str(script), str(jobs)], capture_output=True, text=True, timeout=SCRIPT_TIMEOUT, cwd=tmp_path)
        assert done.returncode == 0, done.stderr
        lines = done.stdout.splitlines()
        assert lines.count("script ran") == 1, done.stdout  # the workers did not run the script again
        answers[jobs] = lines[-1]
    assert answers[2] == answers[1]  # the same values, to the last digit
