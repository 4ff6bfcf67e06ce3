"""The ``design`` kind under faults (issue 50, item 4): a design run interrupted at any of its stages, or whose kept
store is damaged, is finished by the rerun of the same command with the dataset an undisturbed run writes, bit for
bit, and never a traceback.

A design run's work goes through :meth:`vibroimpact.runs.runner.Runner.map` as cases (no grid blocks): each search
generation's candidates, each polish step's, the certificates; every finished case is kept in the store
``<out>/<name>.zarr/cases`` and given back to the rerun, which must then reach the same candidates in the same order
and the same recommendation. The stages are known from outside by what the run says on stderr
(:mod:`vibroimpact.kinds.design.study`): the search's generations are progress bars of ``N/8 designs`` after
``design: differential evolution ...``, the polish says ``design: polish 10/80 evaluations``, the certification begins
after ``design: 98 candidates evaluated in ...`` (a bar of ``0/2 designs``: the two certificates), the page is the
bar ``report [...] 0/1 page``.

Interrupts (:data:`_INTERRUPTS`): each stage meets one way of stopping, and each way of stopping one stage or two,
rather than the cross product (16 interrupted runs and reruns of 40-120 s each at this machine's load would cost this
tier ~10 minutes; the stages share their code path, ``Runner.map``, and the signals theirs, ``cli.main``'s handlers):
Ctrl-C (SIGINT to the process group, as a terminal sends it) in a search generation with ``--jobs 1``; SIGTERM (to the
study's process alone, as a batch system sends it) in the polish; SIGKILL of the whole group (an OOM kill, a power
cut) in the certification with ``--jobs 2``; and, in one run with ``--jobs 2``, SIGKILL of one worker process in the
certification (its tasks are the longest; dask runs the lost one again and the run goes on: the dataset it writes
before its page is compared too), then Ctrl-C on the page (the workers are in the group). A Ctrl-C in the
certification with the linear optimum still computing in the study's process is held by a test of its own
(:func:`test_an_interrupt_in_the_certification_does_not_wait_for_the_linear_optimum`).

Damage to a kept store (:data:`_DAMAGE`): each kind of file a design run's store holds, a case's chunk (a flipped bit),
its checksum (``.zattrs``), its ``.zarray``, the root's consolidated ``.zmetadata`` (edited, removed) and a whole case
removed. The run reads every case's own files (never the consolidated copy) and proves its values by their checksum:
a damaged chunk, checksum or ``.zarray`` is said (``1 damaged case of 2 ... is computed again``), a case whose checksum
file is lost too (``stored without its checksum``), and a lost, edited or unreadable consolidated ``.zmetadata`` (rewritten
when the store is kept); a whole case removed is said as gone (``1 case of 2 that the store had finished is gone from
it``), told from one never computed by the store's list of the cases it finished.

Bit for bit: every variable's bytes, dtype, dimensions and attributes and every attribute of the file
(:func:`_digests`), read from the netCDF file with the netCDF library's masking and scaling off, but for what times or
records the run itself (:data:`_TIMED`, :data:`_RUN_HISTORY`).
"""

from __future__ import annotations

import fcntl
import hashlib
import json
import os
import shutil
import signal
import subprocess
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import netCDF4
import numpy as np
import pytest

from tests.run_study_process import start_run_study

NAME = "tiny_design"
#: design_rigid_stop.yaml shrunk: a third of its band, one Latin-hypercube sample (with the nominal design and the box's
#: two corners: 4 samples), 4 members a variable, 2 generations, the polish and one certified candidate; one
#: undisturbed run with ``--jobs 1`` takes ~25 s on a quiet 2-core machine (98 candidates, 2 certificates, the page).
SCENE = f"""\
name: {NAME}
description: design_rigid_stop shrunk for the faults tier
system: {{m1: 1.0, m2: 0.1, k1: 25000.0, k2: 4300.0, b1: 0.8, b2: 0.08}}
excitation: {{amplitude: 10.0}}
stop: {{clearance: 0.003, restitution: 0.2}}
design:
  variables:
    clearance: [0.0005, 0.008]
    restitution: [0.0, 0.9]
  band: {{start: 28.0, stop: 36.0}}
  objective: x1_amplitude
  constraints: {{operating: {{frequency: 33.0, x1_amplitude: 0.00005}}}}
  robust: {{clearance: 0.0002, samples: 1, seed: 1}}
  compare: linear_optimum
  search: {{method: differential_evolution, population: 4, generations: 2, seed: 1, polish: true}}
  certify: {{candidates: 1}}
"""

#: The variables that time the run (units ``s``: the wall times of the search, the certification and the box, and each
#: certificate's parts): every run measures its own, and a rerun gives back the times the first run stored with its
#: cases. :func:`test_the_undisturbed_run_times_only_what_is_excluded` holds this list to the variables in seconds.
_TIMED = frozenset({
    "search_wall_time", "certification_wall_time", "box_wall_time", "certificate_continuation_time", "certificate_brute_time",
    "certificate_screen_time", "certificate_wall_time", "certificate_operating_time", "certificate_sweep_time",
})  # fmt: skip
#: The file's attributes that record when and how the run was made (cli._run, runs.run.run_study and write_dataset):
#: its wall time, its jobs and where they ran, its processes' peak memory and the time the file was written. Every
#: other ``run_*`` attribute (``run_failures``, ``run_warnings``) is a result and is compared.
_RUN_HISTORY = frozenset({"history", "run_wall_time_s", "run_jobs", "run_scheduler", "run_peak_memory_bytes", "run_peak_memory_worker_bytes"})


def _canonical(value: Any) -> Any:
    """``value`` (a netCDF attribute) as JSON that keeps every bit: arrays and numbers as their dtype and bytes."""
    if isinstance(value, (np.ndarray, np.generic)):
        array = np.asarray(value)
        if array.dtype.kind in "OUS":
            return {"dtype": array.dtype.kind, "text": [str(item) for item in array.ravel()]}
        return {"dtype": array.dtype.str, "shape": list(array.shape), "bytes": array.tobytes().hex()}
    if isinstance(value, (int, float)):
        return _canonical(np.asarray(value))
    return str(value)


def _digests(path: Path) -> dict[str, str]:
    """SHA-256 of every variable (its dimensions, dtype, shape, bytes as stored and attributes) and of every
    attribute of every group of the netCDF file at ``path``, by name; those of :data:`_TIMED` and
    :data:`_RUN_HISTORY` left out."""
    digests: dict[str, str] = {}

    def walk(group: Any, where: str) -> None:
        for name in group.ncattrs():
            if name not in _RUN_HISTORY:
                digests[f"{where}attribute {name}"] = hashlib.sha256(json.dumps(_canonical(group.getncattr(name))).encode()).hexdigest()
        for name, variable in group.variables.items():
            if name in _TIMED:
                continue
            variable.set_auto_maskandscale(False)
            values = np.asarray(variable[...])
            attrs = {key: _canonical(variable.getncattr(key)) for key in variable.ncattrs()}
            described = {"dims": list(variable.dimensions), "dtype": values.dtype.str, "shape": list(values.shape), "attrs": attrs}
            header = json.dumps(described, sort_keys=True)
            raw = values.tobytes() if values.dtype.kind != "O" else "\0".join(str(item) for item in values.ravel()).encode()
            digests[f"{where}variable {name}"] = hashlib.sha256(header.encode() + b"\0" + raw).hexdigest()
        for name, child in group.groups.items():
            walk(child, f"{where}{name}/")

    with netCDF4.Dataset(path) as handle:
        walk(handle, "/")
    return digests


def _assert_identical(path: Path, undisturbed: dict[str, str], err: str) -> None:
    digests = _digests(path)
    differ = sorted(key for key in undisturbed.keys() | digests.keys() if digests.get(key) != undisturbed.get(key))
    assert differ == [], err


# -- running the study ---------------------------------------------------------------------------------------------


@dataclass
class Run:
    """A ``run-study`` process and what it has said on stderr so far (progress bars split at their ``\\r``)."""

    process: subprocess.Popen[str]
    lines: list[str]
    reader: threading.Thread

    def said(self, text: str, after: str = "") -> int:
        """How many lines holding ``text`` it has said (after its first line holding ``after``, if given)."""
        lines = list(self.lines)
        start = next((i for i, line in enumerate(lines) if after in line), len(lines)) if after else 0
        return sum(1 for line in lines[start:] if text in line)

    def wait_until(self, said: Callable[["Run"], bool], timeout: float = 240.0) -> None:
        """Return once ``said(self)``; fail if the run ends or ``timeout`` passes first."""
        deadline = time.monotonic() + timeout
        while not said(self):
            assert self.process.poll() is None, f"the run ended before the moment: {self.err()}"
            if time.monotonic() > deadline:  # not a speed: a moment that never comes (pytest-timeout would say less)
                pytest.fail(f"the moment was not reached within {timeout:.0f} s: {self.err()}")
            time.sleep(0.02)

    def finish(self, timeout: float = 300.0) -> tuple[int, str]:
        """Its exit status and everything it said on stderr, once it ends."""
        self.process.wait(timeout=timeout)
        self.reader.join(timeout=10)
        for stream in (self.process.stdout, self.process.stderr):
            if stream is not None:
                stream.close()
        return self.process.returncode, self.err()

    def err(self) -> str:
        return "".join(self.lines)


def _start(scene: Path, out: Path, jobs: int, *extra: str) -> Run:
    """``run-study SCENE --out OUT --jobs JOBS`` as a terminal starts it (its own process group), stdout discarded as
    it comes, stderr collected line by line."""
    process = start_run_study([str(scene), "--out", str(out), "--jobs", str(jobs), *extra], out.parent)
    lines: list[str] = []
    reader = threading.Thread(target=lambda: lines.extend(iter(process.stderr.readline, "")), daemon=True)  # type: ignore[union-attr]
    reader.start()
    threading.Thread(target=lambda: process.stdout.read(), daemon=True).start()  # type: ignore[union-attr]
    return Run(process, lines, reader)


def _run_to_the_end(scene: Path, out: Path, jobs: int, *extra: str) -> str:
    """Run the study to its end; its stderr, which must say no traceback, after exit status 0."""
    returncode, err = _start(scene, out, jobs, *extra).finish()
    assert returncode == 0 and "Traceback" not in err, err
    return err


@dataclass(frozen=True)
class Undisturbed:
    """The undisturbed run: the scene file every run of this module shares (a store records its scene file's path and
    refuses another's), its output folder (with its kept store) and its dataset's digests."""

    scene: Path
    out: Path
    digests: dict[str, str]


@pytest.fixture(scope="module")
def undisturbed(tmp_path_factory: pytest.TempPathFactory, worker_id: str) -> Undisturbed:
    """Run the scene once, undisturbed, with ``--jobs 1 --keep-zarr``: once for every pytest-xdist worker (the first
    to come runs it under a lock, the others read its output)."""
    root = tmp_path_factory.getbasetemp() if worker_id == "master" else tmp_path_factory.getbasetemp().parent
    folder = root / "design_faults_undisturbed"
    with open(root / "design_faults_undisturbed.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not (folder / "finished").exists():
            shutil.rmtree(folder, ignore_errors=True)
            folder.mkdir()
            (folder / f"{NAME}.yaml").write_text(SCENE)
            _run_to_the_end(folder / f"{NAME}.yaml", folder / "out", 1, "--keep-zarr")
            (folder / "finished").write_text("")
    return Undisturbed(folder / f"{NAME}.yaml", folder / "out", _digests(folder / "out" / f"{NAME}.nc"))


@pytest.mark.faults
@pytest.mark.timeout(300)
def test_the_undisturbed_run_times_only_what_is_excluded(undisturbed: Undisturbed) -> None:
    """What the comparison leaves out is what times the run: every variable in seconds, and nothing else."""
    with netCDF4.Dataset(undisturbed.out / f"{NAME}.nc") as handle:
        in_seconds = {name for name, variable in handle.variables.items() if getattr(variable, "units", "") == "s"}
        attributes = set(handle.ncattrs())
    assert in_seconds == _TIMED
    assert _RUN_HISTORY - {"run_peak_memory_worker_bytes"} <= attributes  # --jobs 1: no worker
    assert len(undisturbed.digests) > 100


# -- interrupts ----------------------------------------------------------------------------------------------------


#: The stages: the moment the run has reached one (from what it said) and what it must not have said yet (the next
#: stage's first line), so that the signal is known to have come within the stage.
_STAGES: dict[str, tuple[Callable[[Run], bool], str]] = {
    # the first generation is done (its 8 candidates stored, its bar full): the next is being evaluated; 3 of ~1 s each
    "search generation": (lambda run: run.said("8/8 designs", after="differential evolution") >= 1, "design: polish"),
    # 20 of the polish's 80 evaluations (~7 s with --jobs 1)
    "polish": (lambda run: run.said("design: polish 20/80") >= 1, "candidates evaluated in"),
    # the certificates' bar has begun (~8 s with --jobs 1, ~10 s with --jobs 2); the signal comes 1 s later
    "certification": (lambda run: run.said("0/2 designs", after="candidates evaluated in") >= 1, "certified candidate 1"),
    # the dataset is written and its page is being drawn (~1-3 s)
    "page": (lambda run: run.said("report [") >= 1, "1/1 page"),
}
#: How long after its stage begins each interrupt comes [s].
_DELAY = {"search generation": 0.0, "polish": 0.0, "certification": 1.0, "page": 0.0}


def _worker_processes(pid: int) -> list[int]:
    """The dask worker processes of the local cluster of the study ``pid`` (the nannies, in the study's process, spawn
    them as its children), from ``/proc``."""
    children = []
    for task in Path(f"/proc/{pid}/task").iterdir():
        try:
            children += [int(child) for child in (task / "children").read_text().split()]
        except OSError:  # a thread that ended meanwhile
            pass
    workers = []
    for child in children:
        try:
            if b"multiprocessing.spawn" in Path(f"/proc/{child}/cmdline").read_bytes():  # not the resource tracker
                workers.append(child)
        except OSError:  # a process that ended meanwhile
            pass
    return workers


def _sigint(run: Run) -> None:
    os.killpg(run.process.pid, signal.SIGINT)  # a terminal's Ctrl-C reaches the whole foreground group


def _sigterm(run: Run) -> None:
    run.process.send_signal(signal.SIGTERM)  # a batch system's end of time: to the study's process alone


def _sigkill(run: Run) -> None:
    os.killpg(run.process.pid, signal.SIGKILL)  # the study and its workers at once


def _kill_a_worker(run: Run) -> None:
    workers = _worker_processes(run.process.pid)
    assert len(workers) == 2, f"workers {workers}: {run.err()}"
    os.kill(workers[0], signal.SIGKILL)


#: How each interrupt ends the run: its exit status and the start of its last line on stderr (None: whatever a kill
#: leaves; a worker's death: the run goes on and ends well).
_ENDINGS: dict[str, tuple[int, str | None]] = {
    "SIGINT": (130, "interrupted: "),
    "SIGTERM": (143, "terminated (SIGTERM): "),
    "SIGKILL": (-signal.SIGKILL, None),
    "SIGKILL of a worker": (0, None),
}
_SIGNALS: dict[str, Callable[[Run], None]] = {"SIGINT": _sigint, "SIGTERM": _sigterm, "SIGKILL": _sigkill, "SIGKILL of a worker": _kill_a_worker}
#: The runs interrupted: (stage, interrupt) in the order they come, ``--jobs``, and whether the page is drawn (the
#: runs stopped before it go without, ``--no-report``, and so does their rerun: the same command). Every stage and every
#: interrupt at least once (the module's docstring says why no more); the worker's death and the Ctrl-C on the page
#: share one run: the dataset written before the page is that of a run whose worker died.
_INTERRUPTS: dict[str, tuple[list[tuple[str, str]], int, bool]] = {
    "search generation: SIGINT": ([("search generation", "SIGINT")], 1, False),
    "polish: SIGTERM": ([("polish", "SIGTERM")], 1, False),
    "certification: SIGKILL": ([("certification", "SIGKILL")], 2, False),
    "certification: SIGKILL of a worker, page: SIGINT": ([("certification", "SIGKILL of a worker"), ("page", "SIGINT")], 2, True),
}
#: The worker processes are found in ``/proc`` (:func:`_worker_processes`).
_NEEDS_PROC = pytest.mark.skipif(not os.path.isdir("/proc"), reason="a local cluster's worker processes are found in /proc")


@pytest.mark.faults
@pytest.mark.timeout(600)
@pytest.mark.parametrize("case", [pytest.param(case, marks=[_NEEDS_PROC] if "worker" in case else []) for case in _INTERRUPTS])
def test_an_interrupted_design_run_is_finished_by_the_rerun_bit_for_bit(tmp_path: Path, undisturbed: Undisturbed, case: str) -> None:
    steps, jobs, page = _INTERRUPTS[case]
    out = tmp_path / "out"
    command = (undisturbed.scene, out, jobs) + (() if page else ("--no-report",))
    run = _start(*command)
    for stage, interrupt in steps:
        reached, next_stage = _STAGES[stage]
        run.wait_until(reached)
        time.sleep(_DELAY[stage])
        assert run.said(next_stage) == 0, f"the {interrupt} came after the {stage}: {run.err()}"
        _SIGNALS[interrupt](run)
    returncode, err = run.finish()
    if stage == "page":  # the dataset is written before the page is drawn: the disturbed run's own
        _assert_identical(out / f"{NAME}.nc", undisturbed.digests, err)
    status, last = _ENDINGS[interrupt]
    assert returncode == status, err
    if returncode >= 0:  # a process killed says nothing more
        assert "Traceback" not in err and "KeyboardInterrupt" not in err and "leaked semaphore" not in err, err
    if last is not None:
        final = err.rstrip().splitlines()[-1]
        kept = f" kept in {out}/{NAME}.zarr; run the same command to resume"
        assert final.startswith(last) and " finished case" in final and final.endswith(kept), err
    assert (out / f"{NAME}.nc").exists() == (stage == "page"), err
    err = _run_to_the_end(*command)
    assert "resumed: " in err and " cases reused from " in err, err  # the finished cases were given back
    assert not (out / f"{NAME}.zarr").exists(), err  # the store goes once the dataset is written
    _assert_identical(out / f"{NAME}.nc", undisturbed.digests, err)


# -- damage to a kept store ----------------------------------------------------------------------------------------


def _a_case(store: Path, engine: str) -> Path:
    """The first (by name) of the store's finished cases of ``engine`` (``certification``: a certificate,
    ``closed_form``: a screened candidate's samples)."""
    return sorted((store / "cases").glob(f"{engine}-*"))[0]


def _flip_a_bit(path: Path) -> None:
    data = bytearray(path.read_bytes())
    data[len(data) // 2] ^= 0x10
    path.write_bytes(bytes(data))


def _edit_json(path: Path, change: Callable[[dict[str, Any]], None]) -> None:
    document = json.loads(path.read_text())
    change(document)
    path.write_text(json.dumps(document, indent=2))


def _other_checksum(document: dict[str, Any]) -> None:
    document["checksum"] = hashlib.sha256(document["checksum"].encode()).hexdigest()  # well formed, another value


#: Each kind of file of a kept design store, damaged as a disk, a tool or a hand leaves it: the damage and what the
#: rerun must say of it (None: nothing is said; see each entry's comment).
_DAMAGE: dict[str, tuple[Callable[[Path], None], str | None]] = {
    # a certificate's packed result: the chunk fails its checksum, the certificate is computed again
    "a bit flipped in a certificate's chunk": (
        lambda store: _flip_a_bit(_a_case(store, "certification") / "0"),
        "1 damaged case of 2 (values failing their checksum, or unreadable metadata) is computed again"),
    "a candidate's checksum edited": (lambda store: _edit_json(_a_case(store, "closed_form") / ".zattrs", _other_checksum), "1 damaged case of "),
    "a candidate's .zarray edited (dtype)": (
        lambda store: _edit_json(_a_case(store, "closed_form") / ".zarray", lambda m: m.update(dtype="<u2")), "1 damaged case of "),
    "a candidate's .zattrs (checksum) removed": (lambda store: (_a_case(store, "closed_form") / ".zattrs").unlink(),
                                                 "stored without its checksum (cut off before it was written, or it was lost) is computed again"),
    # the root's consolidated metadata (written for readers of a kept store; the run reads every array's own files)
    ".zmetadata edited": (lambda store: _edit_json(store / ".zmetadata", lambda m: m["metadata"].update({"cases/.zgroup": {"zarr_format": 3}})),
                          "/.zmetadata: the store's consolidated metadata differs from the arrays' own metadata (cases/.zgroup)"),
    ".zmetadata removed": (lambda store: (store / ".zmetadata").unlink(), "/.zmetadata: the store's consolidated metadata is lost"),
    # a finished case gone whole: the store's list of the cases it finished tells it from one never computed
    "a certificate removed": (lambda store: shutil.rmtree(_a_case(store, "certification")), "1 case of 2 that the store had finished is gone from it (removed): computed again"),
}


@pytest.mark.faults
@pytest.mark.timeout(300)
@pytest.mark.parametrize("damage", list(_DAMAGE))
def test_a_damaged_kept_design_store_is_rerun_bit_for_bit(tmp_path: Path, undisturbed: Undisturbed, damage: str) -> None:
    out = tmp_path / "out"
    shutil.copytree(undisturbed.out, out)
    store = out / f"{NAME}.zarr"
    cases = sum(1 for case in (store / "cases").iterdir() if case.is_dir())
    spoil, said = _DAMAGE[damage]
    spoil(store)
    err = _run_to_the_end(undisturbed.scene, out, 1, "--keep-zarr", "--no-report")  # the dataset is written before the page
    if said is not None:
        assert said in err, err
    resumed = next(line for line in err.splitlines() if line.startswith("resumed: "))
    recomputed = ".zmetadata" not in damage  # one case computed again, but for the consolidated copy
    assert resumed == f"resumed: {cases - recomputed} of {cases} cases reused from {store}", err
    _assert_identical(out / f"{NAME}.nc", undisturbed.digests, err)
    kept = {case.name for case in (store / "cases").iterdir() if case.is_dir()}
    consolidated = json.loads((store / ".zmetadata").read_text())["metadata"]  # kept again, whole, its metadata consolidated anew
    assert len(kept) == cases and {key.split("/")[1] for key in consolidated if key.startswith("cases/") and key.endswith("/.zarray")} == kept
    assert consolidated["cases/.zgroup"]["zarr_format"] == 2


@pytest.mark.faults
@pytest.mark.timeout(300)
def test_an_interrupt_in_the_certification_does_not_wait_for_the_linear_optimum(
    tmp_path: Path, undisturbed: Undisturbed, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The linear optimum is computed in a thread of the study's process while the workers certify; a Ctrl-C (or
    SIGTERM) in the certification waited for it to finish before the run stopped: design_vs_linear's takes 27 s
    (measured at load 6, 35 samples), this scene's 3.3 s (a SIGTERM in its certification with --jobs 2 ended the run
    9.5 s later, 2-3.5 s in the other stages). Here the linear optimum waits until the run has answered the Ctrl-C
    (30 s at most): the run must answer while it still waits. The search comes from the undisturbed run's store."""
    from vibroimpact import cli
    from vibroimpact.kinds.design import study

    computing, release, finished = threading.Event(), threading.Event(), threading.Event()

    def slow_linear(_outcome: object, _amplitude: float) -> None:
        computing.set()
        release.wait(timeout=30.0)
        finished.set()

    def interrupted_certification(_outcome: object, _runner: object, _say: object) -> None:
        assert computing.wait(timeout=60.0)
        raise KeyboardInterrupt  # Ctrl-C while the candidates are certified

    monkeypatch.setattr(study, "_linear", slow_linear)
    monkeypatch.setattr(study, "_certify", interrupted_certification)
    out = tmp_path / "out"
    shutil.copytree(undisturbed.out, out)
    try:
        assert cli.main([str(undisturbed.scene), "--out", str(out), "--jobs", "1", "--no-report"]) == cli.EXIT_INTERRUPTED
        assert not finished.is_set(), "the run stopped only once the linear optimum was done"
    finally:
        release.set()
    err = capsys.readouterr().err
    assert "Traceback" not in err and err.rstrip().splitlines()[-1].startswith("interrupted: "), err
