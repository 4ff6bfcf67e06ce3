"""Where a study's work runs: this process, a local dask cluster of worker processes, or a running dask cluster.

Which scheduler, first found wins: ``run-study --scheduler ADDRESS``, the environment variable
``VIBROIMPACT_SCHEDULER``, the scene's ``cluster: {scheduler: ADDRESS}``; none: a local cluster of ``--jobs`` worker
processes (one thread each), or this process alone for ``--jobs 1``.
"""

from __future__ import annotations

import logging
import os
import signal
import sys
import threading
import time
import traceback
import warnings
from dataclasses import dataclass
from typing import Callable

import numpy as np

from vibroimpact.model.structure import require_count
from vibroimpact.runs.spawn_main import workers_without_main

__all__ = ["WORKERS_PER_CORE", "local_worker_limit", "check_jobs", "WORKER_LIBRARIES", "import_libraries", "DASHBOARD_VARIABLE", "DEFAULT_DASHBOARD", "dashboard_address", "SCHEDULER_VARIABLE", "ClusterLost", "SyncCancelRace", "Connection", "choose_scheduler", "connect", "Terminated", "unreachable", "dask_setup", "Progress", "ProgressReport", "Throttled", "ProgressBar", "REPORT_INTERVAL", "HEARTBEAT"]

#: The environment variable naming a running scheduler (``tcp://host:8786``).
SCHEDULER_VARIABLE = "VIBROIMPACT_SCHEDULER"
#: The environment variable giving the local cluster's dask dashboard address (``HOST:PORT``; port 0: any free one).
DASHBOARD_VARIABLE = "VIBROIMPACT_DASHBOARD"
#: Where the local cluster's dashboard listens unless :data:`DASHBOARD_VARIABLE` says otherwise: loopback only (it
#: shows worker addresses, local paths, memory and call stacks), on any free port. The scheduler and the workers listen
#: on loopback too (dask's default for a local cluster).
DEFAULT_DASHBOARD = "127.0.0.1:0"
#: Environment of a local cluster's worker processes, set before they start: dask's default but for its
#: MALLOC_TRIM_THRESHOLD_ (glibc returning freed memory above 64 KiB to the system at once, 4 % more time for the
#: exact engine's many small arrays, measured in one process), and one malloc arena (a worker computes in a thread).
#: ``VIBROIMPACT_WORKER`` makes a worker ignore Ctrl-C from its first import of the package (the parent's main module,
#: which ``multiprocessing`` imports first in a spawned child), should it not be born with SIGINT blocked
#: (:func:`_cluster_blocking_ctrl_c`): the study's process handles it.
WORKER_ENVIRONMENT = {"OMP_NUM_THREADS": 1, "MKL_NUM_THREADS": 1, "OPENBLAS_NUM_THREADS": 1, "MALLOC_ARENA_MAX": 1, "VIBROIMPACT_WORKER": 1}
#: dask settings of a local cluster's workers: no statistical profiler (it samples the computing thread every 10 ms
#: for a dashboard the study does not show; 36 blocks of the design map on 2 workers: 6.6 s with it, 6.1 s without,
#: the mean of 3 interleaved runs each).
WORKER_CONFIG = {"distributed.nanny.pre-spawn-environ": WORKER_ENVIRONMENT, "distributed.worker.profile.enabled": False}
#: Most local worker processes per core: each runs one thread, so more only wait for a core while each holds its
#: ~0.3 GB of libraries (``--jobs 1000`` on 2 cores once ran the machine out of memory after 341 s).
WORKERS_PER_CORE = 4


def local_worker_limit() -> int:
    """The most worker processes a local cluster of this machine may start: :data:`WORKERS_PER_CORE` per core."""
    return WORKERS_PER_CORE * (os.cpu_count() or 1)


def check_jobs(jobs: object, key: str = "jobs") -> int:
    """``jobs`` as a count of local worker processes, or ValueError naming ``key`` and the range this machine allows."""
    limit = local_worker_limit()
    return require_count(key, jobs, 1, limit, f" on this machine ({os.cpu_count() or 1} cores, at most {WORKERS_PER_CORE} worker processes a core)")


#: The libraries a study's code imports on a worker, imported as the workers start (:func:`import_libraries`), while
#: the study's process imports its own code; none holds a compiled kernel of the package's (those load only after the
#: study's process has compiled them: :class:`~vibroimpact.runs.kernel_loader.KernelLoader`). restitution.yaml: the
#: first task began ~2.6 s after the cluster was up, of which ~1.2 s imported these.
WORKER_LIBRARIES = ("numpy", "scipy.integrate", "scipy.optimize", "scipy.linalg", "xarray", "zarr", "numba", "dask.array")
#: How long connecting to a named scheduler may take before the study gives up [s].
CONNECT_TIMEOUT = 30.0
#: How long a named scheduler without workers is given for one to join before the study, not begun, gives up [s]
#: (:func:`unreachable`; without the check: ``TimeoutError: No valid workers found`` after 30-46 s, an empty store left).
WORKER_WAIT = 20.0


class ClusterLost(RuntimeError):
    """The dask scheduler went away (or could not be reached) while a study ran."""


def dashboard_address() -> str:
    """The local cluster's dashboard address: ``$VIBROIMPACT_DASHBOARD`` or :data:`DEFAULT_DASHBOARD`.

    Raises
    ------
    ValueError
        When the variable is not ``HOST:PORT`` with a port in [0, 65535] (an empty host: every interface, said so).
    """
    value = os.environ.get(DASHBOARD_VARIABLE, "").strip()
    if not value:
        return DEFAULT_DASHBOARD
    host, colon, port = value.rpartition(":")
    if not colon or not port.isdigit() or not 0 <= int(port) <= 65535 or len(value) > 300:
        raise ValueError(f"${DASHBOARD_VARIABLE} = {value[:80]!r}: allowed HOST:PORT with a port in [0, 65535] (e.g. 127.0.0.1:8787; ':8787' listens on every interface)")
    return value


def choose_scheduler(option: str | None, scene_scheduler: str | None) -> str | None:
    """The scheduler address to use: the command line's, the environment's, the scene's, or None (local)."""
    for candidate in (option, os.environ.get(SCHEDULER_VARIABLE), scene_scheduler):
        if candidate:
            return candidate
    return None


@dataclass
class Connection:
    """A dask client and, for a local cluster, the cluster it started (closed with it)."""

    client: object
    cluster: object | None
    address: str
    _counted: tuple[float, int] | None = None

    @property
    def workers(self) -> int:
        """Worker threads the scheduler knows of now (at least 1)."""
        return max(1, self.worker_count())

    def worker_count(self) -> int:
        """Worker threads the scheduler knows of (0 for a cluster without workers), asked at most once a second."""
        now = time.monotonic()
        if self._counted is None or now - self._counted[0] > 1.0:
            info = self.client.scheduler_info(n_workers=-1)  # type: ignore[attr-defined]
            self._counted = (now, sum(int(worker.get("nthreads", 1)) for worker in info.get("workers", {}).values()))
        return self._counted[1]

    def close(self) -> None:
        """Close the client, and the local cluster if this connection started one (its workers stop)."""
        try:
            self.client.close(timeout=10)  # type: ignore[attr-defined]
        finally:
            if self.cluster is not None:
                self.cluster.close(timeout=10)  # type: ignore[attr-defined]


def unreachable(scheduler: str, timeout: float = 10.0, worker_wait: float | None = None) -> str | None:
    """Why the dask scheduler at ``scheduler`` cannot run a study (not reached within ``timeout`` [s], or no worker
    within ``worker_wait`` [s], default :data:`WORKER_WAIT`), or None if it can.

    The handshake has a deadline of its own: a server that accepts the connection but is not a dask scheduler (its
    dashboard's port, a web server) would otherwise keep the client waiting for an answer that never comes. A
    scheduler that answers but has no worker is given ``worker_wait`` for one to join (workers of a batch system may
    start after it); then it is refused too, before the study makes its store.
    """
    from distributed import Client
    from distributed.comm.registry import backends

    scheme = scheduler.split("://", 1)[0] if "://" in scheduler else "tcp"
    if scheme not in backends:  # refused before a client exists (a client that never connected warns as it goes)
        return f"unknown address scheme {scheme!r}: dask knows {', '.join(sorted(backends))} (e.g. tcp://host:8786)"
    wait = WORKER_WAIT if worker_wait is None else worker_wait
    no_workers = f"it has no workers: none joined within {wait:g} s (start some with 'dask worker {scheduler}', or give --jobs N without a scheduler to run on this machine)"
    outcome: list[str | None] = []
    reached: list[bool] = []

    def handshake() -> None:
        logging.getLogger("distributed").setLevel(logging.CRITICAL)  # the one line below says what went wrong
        try:
            client = Client(scheduler, timeout=timeout, set_as_default=False)
        except Exception as error:  # noqa: BLE001 - any failure of the handshake is an answer: not reachable
            outcome.append(f"{type(error).__name__}: {error}" if str(error) else type(error).__name__)
            return
        reached.append(True)
        try:
            client.wait_for_workers(1, timeout=wait)
        except TimeoutError:
            outcome.append(no_workers)
        except Exception as error:  # noqa: BLE001 - the scheduler went away while asked: not usable
            outcome.append(f"{type(error).__name__}: {error}" if str(error) else type(error).__name__)
        else:
            outcome.append(None)
        finally:
            client.close()

    thread = threading.Thread(target=handshake, name="vibroimpact-scheduler-check", daemon=True)
    thread.start()
    thread.join(timeout + 2.0)  # the handshake's own deadline first: a server that never answers is not waited on for workers
    if not outcome and not reached:  # the thread is left behind: the study stops here (exit 2)
        return f"no dask scheduler answered within {timeout:.0f} s (a server that is not a dask scheduler, such as the dashboard's port?)"
    thread.join(wait + 2.0)
    return outcome[0] if outcome else no_workers


class SyncCancelRace(logging.Filter):
    """Drops tornado's traceback of a race in ``distributed.utils.sync`` (distributed 2026.8): on Ctrl-C, ``sync``
    schedules a callback that cancels the future of the coroutine it waits for, and when the interrupt comes before
    that coroutine has made its future, the callback raises ``NameError`` (``free variable 'future'``) in the event
    loop's thread, which tornado logs as an error with a traceback. The interrupt itself is the study's to handle (it
    says in one line what it kept); this filter drops that one record and nothing else."""

    def filter(self, record: logging.LogRecord) -> bool:
        error = record.exc_info[1] if record.exc_info else None
        if not isinstance(error, NameError) or "future" not in str(error) or error.__traceback__ is None:
            return True
        frames = [frame.f_code for frame, _line in traceback.walk_tb(error.__traceback__)]
        return not any(code.co_name == "cancel" and os.path.join("distributed", "utils.py") in code.co_filename for code in frames)


def _drop_sync_cancel_race() -> None:
    """Install :class:`SyncCancelRace` on tornado's application logger (once)."""
    logger = logging.getLogger("tornado.application")
    if not any(isinstance(existing, SyncCancelRace) for existing in logger.filters):
        logger.addFilter(SyncCancelRace())


def connect(jobs: int, scheduler: str | None) -> Connection:
    """Start a local cluster of ``jobs`` worker processes, or connect to ``scheduler``.

    Raises
    ------
    ClusterLost
        When the named scheduler cannot be reached within :data:`CONNECT_TIMEOUT`.
    """
    if scheduler is None:
        return _start_local_cluster(jobs)
    from distributed import Client

    _drop_sync_cancel_race()
    # a running cluster's comings and goings (a worker lost, a connection closed) are the scheduler's to log; the
    # study's process says what matters to it in one line
    logging.getLogger("distributed").setLevel(logging.WARNING)
    try:
        client = Client(scheduler, timeout=CONNECT_TIMEOUT, set_as_default=False)
    except (OSError, TimeoutError) as error:
        raise ClusterLost(f"cannot reach the dask scheduler at {scheduler}: {error}") from None
    return Connection(client, None, scheduler)


#: What dask's abandoned work says as a failing study closes its cluster: a call cut off by the interrupt leaves the
#: coroutine it had made for the event loop never awaited (it is collected whenever the loop's objects are, down to
#: the interpreter's exit, after the study's one line).
ABANDONED_COROUTINE = r"coroutine '.*' was never awaited"


def leave_quietly() -> None:
    """The study is ending on a failure it says in one line (Ctrl-C, SIGTERM, a lost scheduler): from now on, the
    warnings of the dask calls that failure cut off (:data:`ABANDONED_COROUTINE`) are not the user's, and are not
    shown. Left in place to the process's end: the coroutines are collected at no fixed moment."""
    warnings.filterwarnings("ignore", message=ABANDONED_COROUTINE, category=RuntimeWarning)


class Terminated(KeyboardInterrupt):
    """SIGTERM (a batch system's end of time, ``timeout``, ``kill``): handled like Ctrl-C, finished work kept."""


def _start_local_cluster(jobs: int) -> Connection:
    """A local cluster of ``jobs`` worker processes, Ctrl-C (and SIGTERM) honoured at every moment of its start.

    A terminal's Ctrl-C goes to every process of its group. The workers never receive it: they are born with SIGINT
    blocked (:func:`_cluster_blocking_ctrl_c`), and their preload then ignores it. This process handles it throughout:
    the start (the scheduler; the workers importing dask and numba, 5-16 s under load) records a Ctrl-C, says so at
    once, stops waiting, closes the cluster and raises it.
    """
    interrupted: list[int] = []

    def record(signum: int, _frame: object) -> None:
        leave_quietly()
        if not interrupted:  # SIGTERM (a batch system, `timeout`) is said as itself, not as a Ctrl-C
            what = "terminated (SIGTERM)" if signum == signal.SIGTERM else "interrupted"
            print(f"\n{what}: stopping the workers as they start", file=sys.stderr, flush=True)
        interrupted.append(signum)

    def stop_if_interrupted(cluster: object | None, client: object | None) -> None:
        if not interrupted:
            return
        for closing in (client, cluster):
            if closing is not None:
                closing.close(timeout=10)  # type: ignore[attr-defined]
        raise Terminated() if interrupted[0] == signal.SIGTERM else KeyboardInterrupt()

    main = threading.current_thread() is threading.main_thread()
    # recorded from here on, before the first import of dask and distributed: an exception raised by a handler inside
    # those imports (seconds under load) could be swallowed by a library, and a SIGTERM was (the faults tier, once)
    previous = {signum: signal.signal(signum, record) for signum in (signal.SIGINT, signal.SIGTERM)} if main else {}
    cluster = client = None
    try:
        import dask.config
        from distributed import Client

        _drop_sync_cancel_race()
        stop_if_interrupted(None, None)
        with dask.config.set(WORKER_CONFIG), workers_without_main():  # a user's script is not run again by each worker
            cluster = _cluster_blocking_ctrl_c()
            client = Client(cluster, set_as_default=False)
            stop_if_interrupted(cluster, client)
            cluster.scale(jobs)
            while len(client.scheduler_info(n_workers=-1).get("workers", {})) < jobs and not interrupted:
                if cluster.status.name in ("failed", "closed"):
                    raise RuntimeError(f"the local cluster's workers failed to start ({cluster.status.name})")
                time.sleep(0.1)
        stop_if_interrupted(cluster, client)
    except Exception:
        if interrupted:  # a worker hit by the interrupt before it could ignore it: the interrupt is what happened
            raise Terminated() if interrupted[0] == signal.SIGTERM else KeyboardInterrupt() from None
        raise
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
    return Connection(client, cluster, cluster.scheduler_address)


def _cluster_blocking_ctrl_c() -> object:
    """A local cluster (no workers yet) whose worker processes will be born with SIGINT blocked.

    The cluster's event loop thread is started while this thread blocks SIGINT, and a thread inherits its creator's
    signal mask: the loop's thread, the threads it starts (one per worker process, which spawns it) and the processes
    they spawn keep SIGINT blocked, across ``exec`` and through the workers' seconds of imports. This thread blocks it
    only while the cluster object is made (a Ctrl-C meanwhile is held, then handled). Multiprocessing's resource tracker
    is started here first: started later, from the loop's threads, it would *unblock* SIGINT in the thread that starts
    it (it blocks SIGINT and SIGTERM around its own spawn, then unblocks them), and the workers spawned from there
    would be born able to die of a Ctrl-C during their imports, with a traceback (CI's faults tier saw one). Were the
    tracker ever restarted, the package's ``__init__`` (``VIBROIMPACT_WORKER``) still ignores Ctrl-C from a worker's
    first import.
    """
    from multiprocessing import resource_tracker

    from distributed import LocalCluster

    dashboard = dashboard_address()  # checked before anything starts
    resource_tracker.ensure_running()
    blocked = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        return LocalCluster(n_workers=0, threads_per_worker=1, processes=True, dashboard_address=dashboard, silence_logs=logging.CRITICAL, preload=[__name__])
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, blocked)


async def import_libraries() -> None:
    """Import :data:`WORKER_LIBRARIES` (run on each worker as it starts: ``Client.run``, which runs only a coroutine
    without waiting for it)."""
    import importlib

    for name in WORKER_LIBRARIES:
        importlib.import_module(name)


def dask_setup(worker: object) -> None:
    """Preload of a local cluster's workers (dask calls it in each worker process): ignore Ctrl-C, which the study
    handles."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)


# --------------------------------------------------------------------------------------------------------------------
# Progress of a study's work: a one-line bar on stderr that advances while tasks run, fed from this process or,
# through the dask scheduler's event log, from the workers.
# --------------------------------------------------------------------------------------------------------------------

#: Called by running work with what it has done so far, in its progress unit (points, simulated seconds).
#: Where a study's one-line messages go (a finished step, a kept block): a callable taking the line.
Progress = Callable[[str], None]
ProgressReport = Callable[[float], None]
#: Shortest interval between two progress messages of one task [s].
REPORT_INTERVAL = 0.25
#: Longest a study's progress bar stays silent while nothing arrives (workers starting, a long first task) [s].
HEARTBEAT = 10.0


class Throttled:
    """Passes a progress value on at most every :data:`REPORT_INTERVAL` seconds."""

    def __init__(self, send: ProgressReport) -> None:
        self.send, self.last = send, -np.inf

    def __call__(self, done: float) -> None:
        now = time.monotonic()
        if now - self.last >= REPORT_INTERVAL:
            self.last = now
            self.send(done)


class ProgressBar:
    """A one-line progress bar on stderr (a line per 10 % when stderr is not a terminal).

    Thread-safe: the dask client delivers the workers' progress messages on its own thread.

    Parameters
    ----------
    totals : list of float
        The work of each task, in ``unit``.
    finished : list of int
        Tasks already done (taken from the store of an interrupted run).
    unit : str
        What the work is counted in (``points``, ``s``).
    enabled : bool
        False: print nothing.
    verb : str
        The bar's first word.
    done_before : float
        Work done before these tasks (cases an interrupted run finished), in ``unit``: counted as done.
    heartbeat : float
        Longest silence of the bar [s]: while no work arrives (workers starting, a long first task) the bar is shown
        again with its elapsed time and :attr:`status` at least this often (on a terminal every second).
    status : str
        What the run is doing before work arrives (see :meth:`set_status`).
    """

    def __init__(self, totals: list[float], finished: list[int], unit: str, enabled: bool, verb: str = "simulating", done_before: float = 0.0, heartbeat: float = HEARTBEAT, status: str = "") -> None:
        self.totals = totals
        self.total = max(sum(totals) + done_before, 1e-300)
        self.done = {index: totals[index] for index in finished}
        self.finished = set(finished)
        self.done_sum = float(sum(self.done.values())) + done_before
        self.unit = unit
        self.verb = verb
        self.enabled = enabled and sum(totals) + done_before > 0
        self.started = time.perf_counter()
        self.first_done = self.done_sum
        self.tty = sys.stderr.isatty()
        self.last_decile = -1
        self.lock = threading.Lock()
        #: What the run is doing while no work has arrived (e.g. "starting 2 worker processes"); shown in the bar.
        self.status = status
        self.heartbeat = heartbeat
        self.last_shown = -np.inf  # when a line was last printed [s, perf_counter]
        self._show()
        self._stop = threading.Event()
        self._ticker: threading.Thread | None = None
        if self.enabled:
            self._ticker = threading.Thread(target=self._tick, name="vibroimpact-progress", daemon=True)
            self._ticker.start()

    def _tick(self) -> None:
        """Show the bar again while nothing arrives: no line is silent for longer than :attr:`heartbeat`."""
        interval = min(1.0, self.heartbeat / 10.0)
        silence = interval if self.tty else self.heartbeat - interval  # a terminal's bar counts seconds in place
        while not self._stop.wait(interval):
            with self.lock:
                if time.perf_counter() - self.last_shown >= silence:
                    self._show(force=True)

    def partial(self, index: int, done: float) -> None:
        """Task ``index`` has done ``done`` of its work (a late message of a finished task changes nothing)."""
        with self.lock:
            if index in self.finished:
                return
            value = min(max(done, 0.0), self.totals[index])
            self.done_sum += value - self.done.get(index, 0.0)
            self.done[index] = value
            self.status = ""  # work arrives: the run is past its start
            self._show()

    def finish(self, index: int) -> None:
        """Task ``index`` is done."""
        self.partial(index, self.totals[index])
        self.finished.add(index)

    def set_status(self, status: str) -> None:
        """Say what the run is doing before work arrives (shown at once and with every heartbeat)."""
        with self.lock:
            self.status = status
            self._show(force=True)

    def _show(self, force: bool = False) -> None:
        if not self.enabled:
            return
        done = self.done_sum
        fraction = min(done / self.total, 1.0)
        now = time.perf_counter()
        elapsed = now - self.started
        rate = (done - self.first_done) / elapsed if elapsed > 0 and done > self.first_done else 0.0
        remaining = f"{(self.total - done) / rate:.0f} s left" if rate > 0 else (self.status or "...")
        filled = int(30 * fraction)
        line = f"{self.verb} [{'#' * filled}{'.' * (30 - filled)}] {done:.0f}/{self.total:.0f} {self.unit}, {elapsed:.0f} s, {remaining}"
        if self.tty:
            print("\r" + line + "  ", end="", file=sys.stderr, flush=True)
            self.last_shown = now
        elif int(10 * fraction) > self.last_decile or force:
            self.last_decile = max(self.last_decile, int(10 * fraction))
            print(line, file=sys.stderr, flush=True)
            self.last_shown = now

    def close(self) -> None:
        """Stop the heartbeat and end the bar's line."""
        self._stop.set()
        if self._ticker is not None:
            self._ticker.join()
        if self.enabled and self.tty:
            print(file=sys.stderr, flush=True)
