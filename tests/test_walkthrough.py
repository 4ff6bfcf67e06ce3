"""A notebook walk-through: the README's Python sections in order, then a general layout of a user's own, pasted into
one fresh interpreter in an empty folder, with only names imported from ``vibroimpact`` itself.

The general layout is a three-mass chain with named coordinates (``floor1``, ``floor2``, ``absorber``) and a rigid stop
on ``Stop(..., coordinate="absorber")``: its closed-form orbit at 20 Hz (existing, admissible, stable) is the exact
engine's steady state, every coordinate's fundamental within 1e-8 of the largest (measured: 1.3e-10). Every closed
form (the paper's system and a problem, one- and two-sided) returns the one orbit type, with ``frequency`` [Hz] beside
``omega`` [rad s-1], ``stable``, ``multipliers``, ``harmonics()`` and ``admissible()``; the linear response reports
names under ``coordinates`` as the time history does.
"""

from __future__ import annotations

import ast
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: A small restitution study for the README's "Output format" section to read (``results/restitution/restitution.nc``).
SETUP = """
from vibroimpact import parse_scene, run_study, write_dataset

scene = parse_scene({
    "name": "restitution", "system": {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0, "b1": 0.8, "b2": 0.08},
    "excitation": {"amplitude": 10.0}, "stop": {"clearance": 0.003},
    "sweep": {"restitution": [0.2], "frequency": [24.0, 25.0]}, "solutions": ["linear", "pgf", "exact"],
    "simulation": {"frequency": [24.0, 25.0]},
})
write_dataset(run_study(scene, progress=None), "results/restitution/restitution.nc")
"""

#: The user's own layout, after the README's sections.
GENERAL = """
import numpy as np
from vibroimpact import (PAPER_SYSTEM, HarmonicForce, ImpactOrbit, ImpactProblem, LinearStructure, RigidStop, Stop,
                         linear_response, solve_impact_orbit, solve_one_impact, solve_two_impacts, steady_state)

stiffness = np.array([[5e4, -2e4, 0.0], [-2e4, 2e4 + 4300.0, -4300.0], [0.0, -4300.0, 4300.0]])
chain = LinearStructure(np.diag([1.0, 0.8, 0.1]), stiffness, 1e-3 * stiffness, coordinates=("floor1", "floor2", "absorber"))
stop = Stop(RigidStop(clearance=2e-3, restitution=0.5), coordinate="absorber")
problem = ImpactProblem(chain, (stop,), HarmonicForce(amplitude=20.0, frequency=20.0, weights=(1.0, 0.0, 0.0)))
assert problem.stops[0].normal(3).tolist() == [0.0, 0.0, 1.0]  # the absorber, not the 0-based index 1 (floor2)

orbit = solve_one_impact(problem)
assert type(orbit) is ImpactOrbit and bool(orbit.exists) and bool(orbit.admissible()) and bool(orbit.stable)
assert abs(float(orbit.frequency) - 20.0) < 1e-12 and abs(float(orbit.omega) - 40.0 * np.pi) < 1e-12
assert orbit.multipliers.shape == (6,) and float(np.max(np.abs(orbit.multipliers))) < 1.0
steady = steady_state("exact", problem)
exact = np.array(steady.measures.displacements)
closed = orbit.harmonics(origin="problem")
error = float(np.max(np.abs(closed - exact)) / np.max(np.abs(exact)))
assert steady.converged and steady.multiplicity == 1 and error < 1e-8, error
print(f"general layout: closed form = exact steady state to {error:.1e}")

linear = linear_response(problem)  # no stop: names under coordinates, amplitudes under amplitudes
assert linear.coordinates == steady.history(periods=1).coordinates == ("floor1", "floor2", "absorber")
assert linear.amplitudes.shape == (3,) and abs(float(linear.frequency) - 20.0) < 1e-12

paper = ImpactProblem(PAPER_SYSTEM, (Stop(RigidStop(3e-3, 0.2), coordinate="x2"),), HarmonicForce(10.0, 25.0))
two_sided = ImpactProblem(PAPER_SYSTEM, (Stop(RigidStop(3e-3, 0.2), "x2"), Stop(RigidStop(3e-3, 0.2), "x2", side="lower")), HarmonicForce(10.0, 25.0))
orbits = [solve_one_impact(PAPER_SYSTEM, 25.0, 3e-3, 0.2, 10.0), solve_one_impact(paper), solve_impact_orbit(paper),
          solve_impact_orbit(PAPER_SYSTEM, 25.0, 3e-3, 0.2, 10.0), solve_two_impacts(two_sided)]
assert all(type(o) is ImpactOrbit for o in orbits), [type(o).__name__ for o in orbits]
assert abs(float(orbits[0].impulse) - float(orbits[1].impulse)) < 1e-12 and bool(orbits[0].stable) == bool(orbits[1].stable)
assert all(o.harmonics().shape[-1] == 2 and o.admissible().shape == () for o in orbits)
print("one orbit type:", sorted({type(o).__name__ for o in orbits}))
"""


def readme_python_blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", (ROOT / "README.md").read_text(), flags=re.S)


def notebook() -> str:
    return "\n".join([SETUP, *readme_python_blocks(), GENERAL])


def test_the_notebook_imports_only_public_names() -> None:
    import vibroimpact

    for node in ast.walk(ast.parse(notebook())):
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("vibroimpact"):
            assert node.module == "vibroimpact", f"from {node.module} import ...: not the public package"
            assert all(alias.name in vibroimpact.__all__ for alias in node.names), [alias.name for alias in node.names]
        if isinstance(node, ast.Import):
            assert all(alias.name in ("matplotlib.pyplot", "numpy", "xarray") for alias in node.names), [alias.name for alias in node.names]
    assert len(readme_python_blocks()) >= 3


@pytest.mark.slow  # 36 s: the README's sections again, in a fresh interpreter (the default tier runs each apart)
@pytest.mark.timeout(900)
def test_the_readme_and_a_general_layout_run_as_a_notebook(tmp_path: Path) -> None:
    env = {**os.environ, "MPLBACKEND": "Agg"}
    result = subprocess.run([sys.executable, "-c", notebook()], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=840)
    assert result.returncode == 0, result.stderr[-3000:]
    out = result.stdout
    assert "closed form:" in out and "exact engine:" in out and "fold" in out, out
    assert "general layout: closed form = exact steady state to" in out and "one orbit type: ['ImpactOrbit']" in out, out
    assert (tmp_path / "quick_start.png").stat().st_size > 10_000
