"""Run a study's work on dask.distributed (or in this process), with a progress bar, a resumable store and a clean
interrupt.

Two kinds of work go through a :class:`Runner`:

* *cases* (:class:`Case`): picklable pieces of work with a stable key, e.g. one engine at one stop over 16
  frequencies (:meth:`Runner.map`). Consecutive cases are batched into one dask task, so that the scheduler's cost
  per task (~2 ms) stays a small share of the task's work; each finished case is kept in the store;
* *tasks* over shared data (:meth:`Runner.run_tasks`): e.g. the blocks of a stepped study's grid, each written by
  the caller into the store as it arrives.

``jobs = 1`` without a scheduler runs everything here, in order; otherwise a local cluster of ``jobs`` worker
processes starts on first use (:mod:`vibroimpact.runs.cluster`), or the named scheduler's workers run it. A task on
a worker that dies is run again by the scheduler on another one; a task that raises ends the study. Workers send
their progress through the scheduler's event log, so the bar advances inside long tasks.
"""

from __future__ import annotations

import logging
import sys
import threading
import time
import uuid
from concurrent.futures import CancelledError
from pathlib import Path
from typing import Any, Callable, Protocol, Sequence

import numpy as np
from numpy.typing import NDArray

from vibroimpact import __version__
from vibroimpact.engines.registry import engine_spec
from vibroimpact.runs.cluster import ClusterLost, Connection, check_jobs, connect, import_libraries, leave_quietly, ProgressBar, ProgressReport, Throttled
from vibroimpact.runs.fingerprints import source_hash
from vibroimpact.runs.store import StudyStore

__all__ = ["Case", "CaseResult", "ProgressReport", "Runner", "TaskFunction", "OtherCode", "WorkerDied", "MAX_CASES_PER_TASK"]

CaseResult = dict[str, NDArray[np.generic]]
#: What a task runs on a worker: ``function(shared, item, report)`` -> its result.
TaskFunction = Callable[[Any, Any, ProgressReport], Any]
#: Most cases batched into one task (batching keeps the scheduler's cost per task small; more tasks share the work
#: between workers more evenly).
MAX_CASES_PER_TASK = 8
#: Tasks per worker a batch count aims at (load balance: the last tasks do not leave workers idle for long).
TASKS_PER_WORKER = 4
#: Tasks in flight per worker: enough to keep every worker busy, few enough that the scheduler holds little.
IN_FLIGHT_PER_WORKER = 3
#: How often the main process looks at finished tasks and at the scheduler [s].
POLL_INTERVAL = 0.2


class Case(Protocol):
    """What :meth:`Runner.map` runs."""

    engine: str
    fields: tuple[str, ...]

    @property
    def progress_total(self) -> float:
        """The case's work in ``progress_unit`` (frequency points, simulated seconds)."""
        ...

    @property
    def progress_unit(self) -> str: ...

    def key(self) -> str: ...

    def run(self, report: ProgressReport | None = None) -> CaseResult: ...


class Runner:
    """Where a study's cases and tasks run, and where finished work is kept.

    Parameters
    ----------
    jobs : int
        Worker processes of the local cluster; 1: this process alone (unless ``scheduler`` is given).
    scheduler : str or None
        Address of a running dask scheduler (``tcp://host:8786``); None: local.
    store : StudyStore or None
        Where finished cases are kept (and read back by a rerun); None: nowhere.
    progress : bool
        Show the progress bar on stderr.
    report : callable or None
        Receives the work done so far by this runner, summed over its cases (a runner inside a worker task passes its
        progress on to the task's own report).

    The registered engines the work runs are named by :meth:`use_engines`, once their kernels are compiled: each dask
    worker loads them (:class:`~vibroimpact.runs.kernel_loader.KernelLoader`) before its first task, so no task's own
    timing includes loading (or compiling) them.
    """

    def __init__(self, jobs: int = 1, scheduler: str | None = None, store: StudyStore | None = None, progress: bool = True, report: ProgressReport | None = None) -> None:
        self.engines: tuple[str, ...] = ()
        self.batched: tuple[str, ...] = ()
        self.jobs = check_jobs(jobs) if scheduler is None else jobs  # refused before anything starts
        self.scheduler = scheduler
        self.store = store
        self.progress = progress and report is None
        self.report = report
        self._offset = 0.0
        self._connection: Connection | None = None
        #: The largest resident memory of one worker process [bytes], read when the connection closes (0: none ran).
        self.worker_peak_memory = 0
        #: What the store gave back instead of computing it: unit (cases, blocks) -> [reused, of all asked].
        self.reuse: dict[str, list[int]] = {}
        self._saved: set[str] = set()  # the cases this runner stored itself

    @property
    def distributed(self) -> bool:
        """Whether work goes to dask workers (not run here)."""
        return self.scheduler is not None or self.jobs > 1

    @property
    def connection(self) -> Connection:
        """The dask connection, started on first use (or by :meth:`start`)."""
        if self._connection is None:
            self._connection = connect(self.jobs, self.scheduler)
            self._load_kernels()
        return self._connection

    def start(self) -> None:
        """Start the dask connection now, if work goes to dask workers: the workers start and import their libraries
        (:data:`~vibroimpact.runs.cluster.WORKER_LIBRARIES`) while this process goes on (importing the study's code);
        the engines' kernels load on the workers once :meth:`use_engines` names them."""
        if self.distributed and self._connection is None:
            if self.progress:  # the start takes ~1 s, 5-16 s under load: said before it begins
                print(self._starting(), file=sys.stderr, flush=True)
            self.connection.client.run(import_libraries, wait=False)  # type: ignore[attr-defined]

    def _starting(self) -> str:
        """What the start of the dask connection does, in words (said before it begins, and by the bar meanwhile)."""
        return f"starting {self.jobs} worker processes" if self.scheduler is None else f"connecting to the dask scheduler at {self.scheduler}"

    def use_engines(self, engines: Sequence[str], batched: Sequence[str] = ()) -> None:
        """The registered engines the work runs (those in ``batched`` with their batch entry), their kernels compiled
        in this process by now (:func:`vibroimpact.runs.run.prepare_engines`): each worker loads them before its next
        task."""
        self.engines = tuple(engines)
        self.batched = tuple(batched)
        if self._connection is not None:
            self._load_kernels()

    def _load_kernels(self) -> None:
        if self._connection is not None and any(engine_spec(name).capabilities.compiled for name in self.engines):
            from vibroimpact.runs.kernel_loader import KernelLoader

            # every worker, and any that joins later, loads the kernels before it takes a task
            self._connection.client.register_plugin(KernelLoader(self.engines, self.batched), name="vibroimpact-kernels")  # type: ignore[attr-defined]

    @property
    def workers(self) -> int:
        """Workers the work is shared between (``jobs`` for a local cluster, the scheduler's worker threads now)."""
        if self.scheduler is None:
            return self.jobs
        return self.connection.workers

    def note_reused(self, unit: str, reused: int, total: int) -> None:
        """Count ``reused`` of ``total`` pieces of work (``unit``: cases, blocks) that the store gave back."""
        counts = self.reuse.setdefault(unit, [0, 0])
        counts[0] += reused
        counts[1] += total

    def reuse_line(self) -> str:
        """One line saying what the store gave back (``resumed: 270 of 271 cases reused from ...``); "" where nothing."""
        parts = [f"{reused} of {total} {unit}" for unit, (reused, total) in self.reuse.items() if reused]
        where = f" from {self.store.path}" if self.store is not None and self.store.path is not None else ""
        return f"resumed: {' and '.join(parts)} reused{where}" if parts else ""

    def close(self, failed: bool = False) -> None:
        """Close the dask connection (a local cluster's workers stop); after a success, first read the workers' peak
        memory. ``failed``: leaving on an error, an interrupt or a lost scheduler: close at once, quietly."""
        if self._connection is None:
            return
        connection, self._connection = self._connection, None
        if not failed:
            try:
                peaks = connection.client.run(_peak_memory, wait=True)  # type: ignore[attr-defined]
                self.worker_peak_memory = max(peaks.values(), default=0)
            except (OSError, TimeoutError, ValueError, CancelledError):
                pass  # the scheduler went away at the very end: nothing to read
            connection.close()
            return
        # the client's reconnect task logs its cancellation with a traceback: the study says what happened in one line
        leave_quietly()
        loggers = [logging.getLogger(name) for name in ("distributed", *logging.root.manager.loggerDict) if name.startswith("distributed")]
        levels = [logger.level for logger in loggers]
        for logger in loggers:
            logger.setLevel(logging.CRITICAL)
        try:
            connection.close()
        except (OSError, TimeoutError, CancelledError):
            pass  # the scheduler is gone: nothing left to close
        finally:
            for logger, level in zip(loggers, levels):
                logger.setLevel(level)

    def __enter__(self) -> "Runner":
        return self

    def __exit__(self, kind: type[BaseException] | None, *rest: object) -> None:
        self.close(failed=kind is not None)

    # -- cases -------------------------------------------------------------------------------------------------

    def map(self, cases: Sequence[Case], verb: str = "simulating") -> list[CaseResult]:
        """The results of ``cases`` in their order: taken from the store where finished before, else run (and stored);
        ``verb`` leads the progress bar (``design: generation 2 of at most 25``).

        Raises
        ------
        KeyboardInterrupt
            On Ctrl-C, after the running tasks are cancelled; finished cases stay in the store.
        ClusterLost
            When the dask scheduler goes away.
        """
        names = [f"{case.engine}-{case.key()}" for case in cases] if self.store is not None else []
        results: list[CaseResult | None] = [None] * len(cases)
        if self.store is not None:
            before = (self.store.damaged_cases, self.store.unsealed_cases, self.store.lost_cases)
            results = [self.store.load_case(name, case.fields) for name, case in zip(names, cases)]
            damaged, unsealed, lost = (now - then for now, then in zip((self.store.damaged_cases, self.store.unsealed_cases, self.store.lost_cases), before))
            if damaged:
                self.store.say(f"{damaged} damaged case{'s' if damaged > 1 else ''} of {len(cases)} (values failing their checksum, or unreadable metadata) "
                               f"{'are' if damaged > 1 else 'is'} computed again")
            if unsealed:
                self.store.say(f"{unsealed} case{'s' if unsealed > 1 else ''} of {len(cases)} stored without {'their' if unsealed > 1 else 'its'} checksum "
                               f"(cut off before it was written, or it was lost) {'are' if unsealed > 1 else 'is'} computed again")
            if lost:
                self.store.say(f"{lost} case{'s' if lost > 1 else ''} of {len(cases)} that the store had finished {'are' if lost > 1 else 'is'} gone from it (removed): computed again")
        pending = [index for index, result in enumerate(results) if result is None]
        # reused: given back by the store, not saved earlier in this run (a case asked twice in one run is no resume)
        self.note_reused("cases", sum(1 for i, result in enumerate(results) if result is not None and names[i] not in self._saved), len(cases))

        def keep(index: int, result: CaseResult) -> None:
            results[index] = result
            if self.store is not None:
                self.store.save_case(names[index], result)
                self._saved.add(names[index])

        units = list(dict.fromkeys(case.progress_unit for case in cases))  # each unit once, in order
        unit = " + ".join(units) if units else "points"  # mixed cases (sweeps beside a chart) count each in its own unit
        if not self.distributed or (len(pending) <= 1 and self.scheduler is None):
            self._run_here(cases, pending, [i for i in range(len(cases)) if results[i] is not None], unit, keep, verb)
        else:
            per_task = max(1, min(MAX_CASES_PER_TASK, len(pending) // (TASKS_PER_WORKER * self.workers)))
            batches = [pending[first : first + per_task] for first in range(0, len(pending), per_task)]
            totals = [sum(cases[i].progress_total for i in batch) for batch in batches]

            def finished(task: int, outputs: list[CaseResult]) -> None:
                for index, result in zip(batches[task], outputs):
                    keep(index, result)

            items = [[cases[i] for i in batch] for batch in batches]
            done_before = sum(cases[i].progress_total for i in range(len(cases)) if results[i] is not None)
            self.run_tasks(_run_cases, None, items, totals, unit, finished, verb=verb, done_before=done_before)
        finished_results = [result for result in results if result is not None]
        if len(finished_results) != len(cases):  # cannot happen: every case either came from the store or was run
            raise RuntimeError(f"{len(cases) - len(finished_results)} simulation cases have no result")
        return finished_results

    def _run_here(self, cases: Sequence[Case], pending: list[int], finished: list[int], unit: str, keep: Callable[[int, CaseResult], None], verb: str = "simulating") -> None:
        bar = ProgressBar([case.progress_total for case in cases], finished, unit, self.progress, verb)
        try:
            for index in pending:
                offset = self._offset

                def report(done: float, index: int = index, offset: float = offset) -> None:
                    bar.partial(index, done)
                    if self.report is not None:
                        self.report(offset + done)

                keep(index, cases[index].run(Throttled(report)))
                bar.finish(index)
                self._offset += cases[index].progress_total
        finally:
            bar.close()

    # -- tasks -------------------------------------------------------------------------------------------------

    def run_tasks(self, function: TaskFunction, shared: Any, items: Sequence[Any], totals: Sequence[float], unit: str, finished: Callable[[int, Any], None], skip: Sequence[int] = (), verb: str = "simulating", done_before: float = 0.0) -> None:
        """Run ``function(shared, item, report)`` for every item not in ``skip`` and pass each result to
        ``finished(index, result)`` in this process, as it arrives.

        ``totals`` are the items' work in ``unit`` (the progress bar's); ``shared`` goes to the workers once.
        ``done_before``: work already done elsewhere (shown as done by the bar).
        """
        skipped = set(skip)
        order = [index for index in range(len(items)) if index not in skipped]
        starting = ""  # the bar's heartbeat says why nothing moves while the cluster starts (5-16 s)
        if self.distributed and self._connection is None:
            starting = self._starting()
        bar = ProgressBar(list(totals), list(skipped), unit, self.progress, verb, done_before, status=starting)
        try:
            if not self.distributed:
                for index in order:
                    finished(index, function(shared, items[index], Throttled(lambda done, index=index: bar.partial(index, done))))
                    bar.finish(index)
            else:
                self._run_distributed(function, shared, items, order, bar, finished)
        finally:
            bar.close()

    def _run_distributed(self, function: TaskFunction, shared: Any, items: Sequence[Any], order: list[int], bar: ProgressBar, finished: Callable[[int, Any], None]) -> None:
        connection = self.connection
        if connection.worker_count() == 0:  # a named scheduler without workers: a broadcast would wait dask's own timeout
            _await_a_worker(connection, bar)
        bar.set_status("waiting for the workers' first results")
        client: Any = connection.client
        token = uuid.uuid4().hex[:12]
        topic = f"vibroimpact-progress-{token}"
        client.subscribe_topic(topic, lambda event: bar.partial(*event[1]))
        shared_data = _broadcast(connection, shared, bar) if shared is not None else None
        source = source_hash()  # a worker running other code refuses the task rather than mixing its results in
        queue = iter(order)
        running: dict[Any, int] = {}
        arrived = threading.Event()

        def submit() -> bool:
            index = next(queue, None)
            if index is None:
                return False
            future = client.submit(_task, function, shared_data, items[index], topic, index, source, key=f"vibroimpact-{token}-{index}", pure=False)
            running[future] = index
            future.add_done_callback(lambda _future: arrived.set())
            return True

        alone_since: list[float] = []  # when the cluster was last seen with no worker

        def top_up() -> None:
            # workers that join a running cluster get work at once
            while len(running) < IN_FLIGHT_PER_WORKER * max(connection.worker_count(), 1) and submit():
                pass

        try:
            top_up()
            while running:
                if not arrived.wait(POLL_INTERVAL):
                    _check(client, connection.address)
                    _check_workers(connection, alone_since)
                    top_up()
                    continue
                arrived.clear()
                done = [future for future in running if future.done()]
                for future in done:
                    index = running.pop(future)
                    try:
                        result = future.result()
                    except Exception as error:
                        if future.status == "error":
                            if type(error).__name__ == "KilledWorker":  # its worker died on every try (out of memory?)
                                raise WorkerDied(f"task {index} of {len(items)} killed its worker {ALLOWED_FAILURES} times: {error}") from None
                            raise  # the task's own error
                        # cancelled with "scheduler-connection-lost", or its result lost on the way (CommClosedError)
                        raise ClusterLost(f"lost the dask scheduler at {connection.address} ({type(error).__name__})") from None
                    finished(index, result)
                    bar.finish(index)
                top_up()
        except BaseException:
            # Ctrl-C, a failed task or a lost scheduler: nothing more runs for this study
            leave_quietly()
            if client.status == "running":
                client.cancel(list(running), force=True)
            raise
        finally:
            if client.status == "running":
                client.unsubscribe_topic(topic)


def _peak_memory() -> int:
    """Run on a worker: its process's largest resident memory so far [bytes]."""
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


class WorkerDied(RuntimeError):
    """A task's worker died every time it ran it (the scheduler gives up after ``distributed.scheduler.allowed-failures``)."""


#: How often the scheduler reruns a task whose worker died before giving up (dask's default).
ALLOWED_FAILURES = 3
#: How long a cluster may have no worker at all before the study gives up [s].
NO_WORKER_TIMEOUT = 120.0
#: How long one broadcast of the shared data waits for a worker to send it to [s] (dask's own wait otherwise: the
#: client's timeout, 30 s); none there by then: :func:`_wait_for_a_worker`, then the broadcast again.
BROADCAST_TIMEOUT = 5.0
#: How many broadcasts of the shared data are tried before the study gives up (each lost to workers that left).
BROADCAST_TRIES = 3


def _wait_for_a_worker(connection: Connection) -> None:
    """Return once the cluster has a worker; raise :class:`ClusterLost` when none joins within
    :data:`NO_WORKER_TIMEOUT` (before: ``TimeoutError: No valid workers found`` from the broadcast of the shared data,
    after dask's own timeout, 30-46 s)."""
    try:
        connection.client.wait_for_workers(1, timeout=NO_WORKER_TIMEOUT)  # type: ignore[attr-defined]
    except TimeoutError:
        raise ClusterLost(f"the dask scheduler at {connection.address} has no workers: none joined within {NO_WORKER_TIMEOUT:g} s") from None


def _await_a_worker(connection: Connection, bar: ProgressBar) -> None:
    """:func:`_wait_for_a_worker`, said meanwhile on the bar's status line."""
    bar.set_status(f"waiting for a worker to join the dask scheduler (at most {NO_WORKER_TIMEOUT:.0f} s)")
    _wait_for_a_worker(connection)


def _broadcast(connection: Connection, shared: Any, bar: ProgressBar) -> Any:
    """``shared`` on every worker (the future of ``client.scatter(broadcast=True)``), sent again when the workers left
    while it was sent: the count of workers before it is no promise that one is still there. A broadcast that finds
    no worker within :data:`BROADCAST_TIMEOUT` (``TimeoutError``), or whose worker leaves as the data goes to it
    (``OSError``: the connection closed; ``ValueError``: no worker left to copy it to), waits for a worker to join
    (:func:`_wait_for_a_worker`) and is tried again, :data:`BROADCAST_TRIES` times in all (before: exit 1 with dask's
    ``TimeoutError: No valid workers found`` in one line).

    Raises
    ------
    ClusterLost
        When the scheduler is lost, no worker joins within :data:`NO_WORKER_TIMEOUT`, or every try lost its workers.
    """
    client: Any = connection.client
    failure = ""
    for _ in range(BROADCAST_TRIES):
        try:
            return client.scatter(shared, broadcast=True, hash=False, timeout=BROADCAST_TIMEOUT)
        except (TimeoutError, OSError, ValueError) as error:
            _check(client, connection.address)  # the scheduler itself gone: said as such, at once
            failure = f"{type(error).__name__}: {error}" if str(error) else type(error).__name__
        _await_a_worker(connection, bar)
        bar.set_status("waiting for the workers' first results")
    raise ClusterLost(f"the dask scheduler at {connection.address} has no workers: they left during each of {BROADCAST_TRIES} broadcasts of the study's shared data ({failure})")


def _check_workers(connection: Connection, alone_since: list[float]) -> None:
    """Raise :class:`ClusterLost` when the cluster has had no worker for :data:`NO_WORKER_TIMEOUT`."""
    if connection.worker_count() > 0:
        alone_since.clear()
        return
    if not alone_since:
        alone_since.append(time.monotonic())
    elif time.monotonic() - alone_since[0] > NO_WORKER_TIMEOUT:
        raise ClusterLost(f"the dask scheduler at {connection.address} has had no worker for {NO_WORKER_TIMEOUT:.0f} s")


def _check(client: Any, address: str) -> None:
    """Raise :class:`ClusterLost` when the client has lost its scheduler."""
    if client.status not in ("running", "connecting", "newly-created"):
        raise ClusterLost(f"lost the dask scheduler at {address} (client {client.status})")
    if client.status == "connecting":
        raise ClusterLost(f"lost the dask scheduler at {address} (reconnecting)")


class OtherCode(RuntimeError):
    """A dask worker runs another version of the package than the study's process."""


def _task(function: TaskFunction, shared: Any, item: Any, topic: str, index: int, source: str) -> Any:
    """Run on a worker: ``function`` with a report that sends the task's progress to the scheduler's event log."""
    from distributed import get_worker

    worker = get_worker()
    if source_hash() != source:
        raise OtherCode(f"the dask worker {worker.address} runs vibroimpact {__version__} from {Path(__file__).parents[1]} whose source differs from the study's: install the same version on every worker")
    return function(shared, item, Throttled(lambda done: worker.log_event(topic, (index, done))))


def _run_cases(_shared: Any, cases: list[Case], report: ProgressReport) -> list[CaseResult]:
    """A batch of cases, one after the other, reporting their summed progress."""
    results = []
    offset = 0.0
    for case in cases:
        results.append(case.run(lambda done, offset=offset: report(offset + done)))
        offset += case.progress_total
    return results
