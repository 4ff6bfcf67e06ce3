"""Ctrl-C stops a long compiled run at once (issue 34, item 4): the ``exact`` and ``compliant_exact`` engines' loops
run in a helper thread that releases the interpreter and reads a stop flag at every step, so the waiting thread takes
the KeyboardInterrupt and the loop returns at its next step (before: Ctrl-C waited for the whole run, e.g. 10^6
periods, ~15 s of the exact engine, ~30-50 s of the bumper's).

Each case runs in its own process, started as a terminal's foreground job (SIGINT restored: pytest-xdist's workers
ignore it, and a child inherits that), whose run would last ~2 minutes (or 8e6 periods) uninterrupted; it must exit
within the wait's timeout of the SIGINT."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from vibroimpact.engines.interruptible import THREADED_PERIODS, call_interruptibly

pytestmark = pytest.mark.faults

#: A 1-dof oscillator from its linear steady state. ``exact``: its rigid stop 1e-9 (relative) beyond its reach, no
#: impact, but the root search refines every approach (~10 us a period), 16 bytes a period kept. ``compliant_exact``:
#: its bumper at half its reach, two contacts a period (~30 us a period, ~300 bytes a period kept).
CASE = textwrap.dedent(
    """
    import sys, time
    import numpy as np
    from vibroimpact.analysis.linear import linear_response
    from vibroimpact.engines.registry import make_engine
    from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop, Stop
    from vibroimpact.model.excitation import HarmonicForce
    from vibroimpact.model.problem import ImpactProblem
    from vibroimpact.model.structure import LinearStructure
    from vibroimpact.simulation.history import time_history

    name = sys.argv[2]
    structure = LinearStructure(mass=[[1.0]], stiffness=[[1e4]], damping=[[1.0]])
    def problem(clearance):
        law = RigidStop(clearance, 0.5) if name == "exact" else KelvinVoigtBumper(clearance, 100.0, 0.3)
        return ImpactProblem(structure, (Stop(law, coordinate=0),), HarmonicForce(10.0, 10.0))
    linear = linear_response(problem(1.0))
    reach = float(np.abs(linear.stop_amplitudes[0]) + linear.stop_static[0])
    start = np.concatenate([linear.static + linear.amplitudes.real, (2j * np.pi * 10.0 * linear.amplitudes).real])
    case = problem(reach * (1.0 + 1e-9) if name == "exact" else 0.5 * reach)
    engine = make_engine(name)
    began = time.perf_counter()
    engine.integrate(case, start, 0.0, 20_000)  # loads the compiled loop and measures its rate
    periods = int(min(120.0 / ((time.perf_counter() - began) / 20_000), 8e6))  # ~2 minutes uninterrupted
    print("computing", periods, flush=True)
    try:
        if sys.argv[1] == "integrate":
            engine.integrate(case, start, 0.0, periods)
        else:
            time_history(engine, case, start, 0.0, [0.0, periods * case.period])
    except KeyboardInterrupt:
        print("interrupted", flush=True)
        sys.exit(130)
    sys.exit("the run finished: it was not interrupted")
    """
)


@pytest.mark.timeout(600)
@pytest.mark.parametrize("engine", ["exact", "compliant_exact"])
@pytest.mark.parametrize("entry", ["integrate", "time_history"])
def test_ctrl_c_stops_a_long_compiled_run_at_once(entry: str, engine: str) -> None:
    run = subprocess.Popen(
        [sys.executable, "-c", CASE, entry, engine],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    try:
        line = run.stdout.readline()  # type: ignore[union-attr]
        assert line.startswith("computing"), line + run.stderr.read()  # type: ignore[union-attr]
        try:
            run.wait(timeout=1.0)  # into the long run
        except subprocess.TimeoutExpired:
            pass
        os.killpg(run.pid, signal.SIGINT)
        run.wait(timeout=20)  # uninterrupted: ~120 s; a run that ignores Ctrl-C fails here
        out, err = run.communicate()
    finally:
        if run.poll() is None:
            run.kill()
            run.communicate()
    assert run.returncode == 130 and out.strip() == "interrupted", (run.returncode, out, err[-3000:])


def test_a_short_call_runs_in_the_calling_thread_and_a_long_one_gives_its_value_and_errors() -> None:
    import threading

    def where(cancel: np.ndarray) -> tuple[str, int]:
        return threading.current_thread().name, int(cancel[0])

    assert call_interruptibly(where, THREADED_PERIODS - 1) == (threading.current_thread().name, 0)
    name, flag = call_interruptibly(where, THREADED_PERIODS)
    expected = "vibroimpact-compiled-loop" if threading.current_thread() is threading.main_thread() else threading.current_thread().name
    assert (name, flag) == (expected, 0)

    def fails(cancel: np.ndarray) -> None:
        raise ValueError("from the loop")

    with pytest.raises(ValueError, match="from the loop"):
        call_interruptibly(fails, THREADED_PERIODS)
