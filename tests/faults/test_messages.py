"""Messages that neither echo what is not a scene nor refuse what is a number (issue 34, item 8): a YAML error names
the file, line and column but never prints the line (the path may name any file: a scene symlinked to a password
file printed its hashes); numpy's numbers are numbers and a NaN phase is refused, like a NaN anywhere else."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.run_study_process import study_environment
from vibroimpact.model.excitation import HarmonicForce


@pytest.mark.faults
@pytest.mark.timeout(120)
def test_a_yaml_error_never_prints_the_file_s_lines(tmp_path: Path) -> None:
    secret = "root:$6$Xsecret.salt$hashedpasswordvalue:19000:0:99999:7:::"
    target = tmp_path / "shadow"
    target.write_text(f"{secret}\ndaemon:*:19000:0:99999:7:::\nbin: [*:19000\n", encoding="utf-8")
    scene = tmp_path / "scene.yaml"
    scene.symlink_to(target)
    done = subprocess.run([sys.executable, "-m", "vibroimpact.cli", str(scene), "--out", "out"], cwd=tmp_path, env=study_environment(),
                          capture_output=True, text=True, timeout=60)  # fmt: skip
    assert done.returncode == 2, done.stderr
    assert "not valid YAML" in done.stderr and "line 3" in done.stderr
    for piece in ("Xsecret", "hashedpassword", "daemon", "19000"):
        assert piece not in done.stderr, done.stderr


@pytest.mark.faults
def test_numpy_numbers_are_numbers_and_a_nan_phase_is_refused() -> None:
    for frequency in (np.float32(25.0), np.int64(25), np.float64(25.0), 25):
        force = HarmonicForce(np.int32(10), frequency)
        assert type(force.frequency) is float and force.frequency == pytest.approx(25.0) and type(force.amplitude) is float
    for phase in (math.nan, math.inf, np.float32("nan")):
        with pytest.raises(ValueError, match=r"^phase: expected a finite number"):
            HarmonicForce(10.0, 25.0, phase=phase)
    with pytest.raises(ValueError, match=r"^frequency: expected a number, got True"):
        HarmonicForce(10.0, True)  # a bool is not a frequency
