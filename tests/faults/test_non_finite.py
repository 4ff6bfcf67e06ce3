"""No engine hangs on a NaN or an infinity (issue 34, item 4): each refuses a non-finite start state or time at its
entry with a ValueError naming the argument, through ``integrate`` and ``steady_state(start=(t, y))``. Each case runs in
its own process with a deadline, so that an engine spinning in a compiled loop fails the test instead of hanging the
tier (before: alive at 100 % CPU 15 s after Ctrl-C)."""

from __future__ import annotations

import subprocess
import sys
import textwrap

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
