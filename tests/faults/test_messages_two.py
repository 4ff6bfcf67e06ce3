"""Smaller misuse cases of issue 34, item 8: a dask scheduler without workers is refused in one line within a bounded
wait, leaving no store (before: ``TimeoutError: No valid workers found`` after 30-46 s, exit 1, an empty store left);
a chattering IDA run says its failure in one line, not in SUNDIALS' ~2 800 lines of ``[IDASolve, Error: -22]``."""

from __future__ import annotations

import sys
import threading
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from vibroimpact import cli
from vibroimpact.engines.compliant import ida
from vibroimpact.engines.registry import make_engine
from vibroimpact.engines.sundae import solver_messages
from vibroimpact.model.contact import KelvinVoigtBumper, loss_factor_from_restitution
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.runs import cluster, runner
from vibroimpact.runs.cluster import ClusterLost
from vibroimpact.runs.runner import Runner

from tests.cluster.conftest import running_cluster
from tests.test_cli_runner import _scene_file

pytestmark = pytest.mark.faults


@pytest.fixture
def idle_scheduler(tmp_path: Path) -> Iterator[str]:
    """The address of a ``dask scheduler`` on loopback with no worker; killed at the end of the test."""
    with running_cluster(tmp_path / "dask", 0) as cluster:
        yield cluster.address


@pytest.mark.timeout(180)
def test_a_scheduler_without_workers_is_refused_in_one_line_and_leaves_no_store(tmp_path: Path, idle_scheduler: str, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr(cluster, "WORKER_WAIT", 1.0, raising=False)  # the bounded wait for a worker to join [s]
    out = tmp_path / "out"
    code = cli.main([str(_scene_file(tmp_path)), "--scheduler", idle_scheduler, "--out", str(out)])
    err = capsys.readouterr().err
    assert code == cli.EXIT_BAD_INPUT, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"run-study: error: cannot use the dask scheduler at {idle_scheduler}"), err
    assert f"it has no workers: none joined within 1 s (start some with 'dask worker {idle_scheduler}'" in lines[0], err
    assert not out.exists()


@pytest.mark.timeout(180)
def test_a_runner_on_a_scheduler_without_workers_gives_up_naming_it(idle_scheduler: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """The check at run time (the workers gone between the command's check and the work, or ``run_study`` called
    with a scheduler): :class:`ClusterLost` naming the scheduler, not dask's ``TimeoutError`` of the broadcast."""
    monkeypatch.setattr(runner, "NO_WORKER_TIMEOUT", 1.0)
    with Runner(scheduler=idle_scheduler, progress=False) as work:
        with pytest.raises(ClusterLost, match=rf"^the dask scheduler at {idle_scheduler} has no workers: none joined within 1 s$"):
            work.run_tasks(_twice, np.arange(3.0), [1.0], [1.0], "points", lambda _index, _result: None)


def _twice(shared: np.ndarray, item: float, _report: object) -> np.ndarray:
    return shared * item * 2.0


def _chattering() -> ImpactProblem:
    """The paper's system at 10 Hz on a 100 kHz bumper at zero clearance, R = 0.01: IDA meets ~30 close roots in 30
    periods (an event function at round-off zero at a recorded root, IDA_ILL_INPUT), each handled by a restart."""
    return ImpactProblem(PAPER_SYSTEM, KelvinVoigtBumper(0.0, 100_000.0, loss_factor_from_restitution(0.01)), HarmonicForce(10.0, 10.0))


@pytest.mark.timeout(120)
def test_a_chattering_ida_run_prints_nothing_of_sundials(capfd: pytest.CaptureFixture[str]) -> None:
    run = make_engine("compliant").integrate(_chattering(), np.zeros(4), 0.0, 30)
    out, err = capfd.readouterr()
    assert run.strobe_times.size == 31 and run.stats["contacts"] > 30
    assert "IDASolve" not in out + err and not out.strip(), (out + err)[:2000]


@pytest.mark.timeout(120)
def test_a_failing_ida_run_says_sundials_reason_in_its_one_line(monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr(ida, "_MAX_SWITCHES_IN_PLACE", -1)  # the first close root counts as stuck
    with pytest.raises(RuntimeError) as failure:
        make_engine("compliant").integrate(_chattering(), np.zeros(4), 0.0, 30)
    message = str(failure.value)
    assert message.startswith("IDA stops at close roots over and over at t = ") and "\n" not in message, message
    assert "(SUNDIALS: [IDASolve, Error: -22] Root found at and very near t = " in message, message
    out, err = capfd.readouterr()
    assert "IDASolve" not in out + err, (out + err)[:2000]


def test_solver_messages_keep_only_the_calling_thread_s_output(capsys: pytest.CaptureFixture[str]) -> None:
    stdout = sys.stdout
    with solver_messages() as said:
        print("[IDASolve, Error: -22] kept")
        other = threading.Thread(target=print, args=("another thread's line",))
        other.start()
        other.join()
    assert said == ["[IDASolve, Error: -22] kept"] and sys.stdout is stdout
    assert capsys.readouterr().out == "another thread's line\n"


@pytest.mark.timeout(180)
def test_workers_gone_after_the_check_leave_one_line_and_no_empty_store(tmp_path: Path, idle_scheduler: str, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    """The scheduler's workers gone between the command's check and the work: one line naming the scheduler, exit 1,
    and no store of nothing left behind."""
    monkeypatch.setattr(cli, "unreachable", lambda _address: None)  # the check passed: the workers left since
    monkeypatch.setattr(runner, "NO_WORKER_TIMEOUT", 1.0)
    out = tmp_path / "out"
    code = cli.main([str(_scene_file(tmp_path)), "--scheduler", idle_scheduler, "--out", str(out)])
    err = capsys.readouterr().err
    assert code == cli.EXIT_FAILURE, err
    assert err.strip().splitlines()[-1] == f"run-study: the dask scheduler at {idle_scheduler} has no workers: none joined within 1 s: nothing had finished yet; run the same command to start again", err
    assert "Traceback" not in err and not (out / "tiny.zarr").exists()


def test_standard_output_while_a_solver_runs_is_still_the_terminal_s() -> None:
    """While an IDA call captures its thread's output, ``sys.stdout`` answers as the stream it replaced: its file
    descriptor, encoding, whether it is a terminal (io.TextIOBase's own answers were None, False and an error)."""
    stream = sys.stdout
    with solver_messages():
        assert sys.stdout is not stream
        assert sys.stdout.encoding == stream.encoding and sys.stdout.isatty() == stream.isatty() and sys.stdout.writable()
        try:
            expected: int | None = stream.fileno()
        except (OSError, ValueError):
            expected = None
        if expected is not None:
            assert sys.stdout.fileno() == expected
