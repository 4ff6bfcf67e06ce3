"""No engine hangs on a NaN or an infinity (issue 34, item 4): each refuses a non-finite start state or time at its
entry with a ValueError naming the argument, through ``integrate`` and ``steady_state(start=(t, y))``. Each case runs in
its own process with a deadline, so that an engine spinning in a compiled loop fails the test instead of hanging the
tier (before: alive at 100 % CPU 15 s after Ctrl-C). And ``linear`` refuses an undamped resonance as the other closed
forms do (below)."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

CASE = textwrap.dedent(
    """
    import math, sys
    import numpy as np
    from vibroimpact.engines.registry import make_engine
    from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop
    from vibroimpact.model.excitation import HarmonicForce
    from vibroimpact.model.problem import ImpactProblem
    from vibroimpact.model.system import PAPER_SYSTEM
    from vibroimpact.simulation.steady import steady_state

    engine, where, what = sys.argv[1:4]
    contact = KelvinVoigtBumper(0.003, 300.0, 0.3) if engine.startswith("compliant") else RigidStop(0.003, 0.5)
    problem = ImpactProblem(PAPER_SYSTEM, contact, HarmonicForce(10.0, 25.0))
    bad = {"nan": math.nan, "inf": math.inf}[what]
    state, t_start = np.zeros(4), 0.0
    if where == "state":
        state[1] = bad
    else:
        t_start = bad
    try:
        if len(sys.argv) > 4:
            steady_state(engine, problem, start=(t_start, state))
        else:
            make_engine(engine).integrate(problem, state, t_start, 3)
    except ValueError as error:
        print(error)
        sys.exit(0)
    sys.exit(f"no ValueError: {engine} accepted {where} = {what}")
    """
)


@pytest.mark.faults
@pytest.mark.timeout(600)
@pytest.mark.parametrize("engine", ["exact", "exact_python", "compliant_exact", "momentary"])
@pytest.mark.parametrize(("where", "what"), [("state", "nan"), ("state", "inf"), ("t_start", "nan"), ("t_start", "inf")])
@pytest.mark.parametrize("entry", ["integrate", "steady_state"])
def test_a_non_finite_start_is_refused_at_once(engine: str, where: str, what: str, entry: str) -> None:
    arguments = [sys.executable, "-c", CASE, engine, where, what] + (["steady"] if entry == "steady_state" else [])
    done = subprocess.run(arguments, capture_output=True, text=True, timeout=240)  # a hang fails here (compiles included)
    assert done.returncode == 0, done.stderr[-3000:]
    message = done.stdout.strip()
    assert message.startswith("state: expected finite values" if where == "state" else "t_start = "), message


# ---------------------------------------------------------------------------------------------------------------------
# ``linear`` at an undamped resonance (issue 34, item 4): before, 1.45e12 m from linear_response and a 1.4e12 m
# x1_amplitude in a scene's dataset (regime linear_exceeds_clearance) at F0; now refused in the band every other closed
# form and every engine refuses (condition > 1e4, within ~1.6e-5 of an undamped natural frequency): NaN, regime failed.

#: The paper's system with b1 = b2 = 0 and its first natural frequency [Hz] (tests/analysis/test_closed_form_limits.py).
UNDAMPED_SPEC = {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0, "b1": 0.0, "b2": 0.0}
F0 = 23.02212512577005
#: Relative detunings from F0: the closed forms evaluate -1e-4 and 1e-4 (condition 1.6e3) and refuse the others.
DETUNINGS = (-1e-4, -1e-9, 0.0, 1e-9, 1e-4)
REFUSED = [d not in (-1e-4, 1e-4) for d in DETUNINGS]


def _undamped_problem(frequency: float = F0) -> object:
    from vibroimpact.model.contact import RigidStop
    from vibroimpact.model.excitation import HarmonicForce
    from vibroimpact.model.problem import ImpactProblem
    from vibroimpact.model.system import TwoDofSystem

    return ImpactProblem(TwoDofSystem(**UNDAMPED_SPEC), RigidStop(0.003, 0.2), HarmonicForce(10.0, frequency))


@pytest.mark.faults
def test_linear_response_refuses_the_undamped_resonance_band_as_the_engines_do() -> None:
    from vibroimpact import linear_response
    from vibroimpact.model.structure import resonance_refusal
    from vibroimpact.model.system import TwoDofSystem

    problem = _undamped_problem()
    frequency = F0 * (1.0 + np.array(DETUNINGS))
    linear = linear_response(problem, frequency)
    assert linear.conditioned.tolist() == [not r for r in REFUSED]
    assert np.all(linear.condition[REFUSED] > 1e4) and np.all(linear.condition[[not r for r in REFUSED]] < 2e3)
    assert np.all(np.isnan(linear.amplitudes[REFUSED])) and np.all(np.isnan(linear.stop_amplitudes[REFUSED]))
    assert np.all(np.isnan(linear.force[REFUSED])) and not np.any(linear.fits([0.003])[REFUSED])
    evaluated = linear.amplitudes[[not r for r in REFUSED]]
    assert np.all(np.isfinite(evaluated)) and np.all(np.abs(evaluated) < 10.0)  # 1.7 m and 3.4 m at 1e-4 (kappa 1.6e3)
    # the same band as the engines' (:func:`resonance_refusal`, the exact engines' and the steady states' refusal)
    poles = np.linalg.eigvals(problem.structure.state_matrix)  # type: ignore[attr-defined]
    assert [resonance_refusal(poles, 2.0 * np.pi * f) is not None for f in frequency] == REFUSED
    # the paper's system as a view of its problem: the same
    assert np.all(np.isnan(linear_response(TwoDofSystem(**UNDAMPED_SPEC), F0, 10.0).amplitudes))


@pytest.mark.faults
def test_a_scene_s_linear_solution_is_failed_with_nan_values_at_an_undamped_resonance(tmp_path: Path) -> None:
    import copy

    from tests.scene.test_scene import base_scene, write_yaml
    from vibroimpact import cli
    from vibroimpact.analysis.stability import Regime
    from vibroimpact.runs.run import read_dataset

    document = copy.deepcopy(base_scene())
    document["system"] = dict(UNDAMPED_SPEC)
    document["sweep"] = {"frequency": [F0 * (1.0 + d) for d in DETUNINGS]}
    document["solutions"] = ["linear", "pgf"]
    out = tmp_path / "out"
    assert cli.main([str(write_yaml(tmp_path / "undamped.yaml", document)), "--out", str(out), "--jobs", "1", "--no-report"]) == 0
    data = read_dataset(out / "tiny.nc").squeeze()
    refused = np.array(REFUSED)
    for solution in ("linear", "pgf"):
        values = data.sel(solution=solution)
        assert np.all(values["regime"].values[refused] == Regime.FAILED), (solution, values["regime"].values)
        assert not np.any(values["regime"].values[~refused] == Regime.FAILED), (solution, values["regime"].values)
        for name in ("x1_amplitude", "x2_amplitude", "x1_rms", "force_amplitude", "impulse", "impacts_per_period"):
            assert np.all(np.isnan(values[name].values[..., refused])), (solution, name)
            assert np.all(np.isfinite(values[name].values[..., ~refused])), (solution, name)
