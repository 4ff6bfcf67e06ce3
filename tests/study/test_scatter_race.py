"""A worker that leaves between the runner's count of workers and the broadcast of the shared data (or while the data
goes to it) does not end the study: the broadcast waits for a worker to join and is sent again (before: exit 1 with
dask's ``TimeoutError: No valid workers found``, or ``OSError`` of the lost connection, in one line). The race is
provoked, not waited for: an in-process dask cluster (threads, loopback tcp), the count made to say 1 worker where
there is none, or the worker closed as the scheduler sends it the data; the replacement worker is started when the
runner begins to wait for one, so a runner that does not wait never gets it."""

from __future__ import annotations

import logging
from collections.abc import Iterator
from typing import Any

import dask.config
import numpy as np
import pytest

from vibroimpact.runs import cluster, runner
from vibroimpact.runs.cluster import ClusterLost, Connection
from vibroimpact.runs.runner import Runner

pytestmark = pytest.mark.timeout(60)

#: The shared data and the items: task i returns SHARED * ITEMS[i].
SHARED = np.arange(4.0)
ITEMS = [1.0, 2.0, 3.0]


def _scaled(shared: np.ndarray, item: float, _report: object) -> np.ndarray:
    return shared * item


@pytest.fixture
def local_cluster(monkeypatch: pytest.MonkeyPatch) -> Iterator[Any]:
    """An in-process dask cluster without workers (threads, loopback tcp); the study's connection gives up on a
    connection after 2 s (dask's 30 s otherwise: the old broadcast's own wait for a worker, and a lost worker's)."""
    from distributed import LocalCluster

    monkeypatch.setattr(cluster, "CONNECT_TIMEOUT", 2.0)
    monkeypatch.setattr(runner, "BROADCAST_TIMEOUT", 0.3, raising=False)
    with dask.config.set({"distributed.comm.timeouts.connect": "2s"}):
        with LocalCluster(n_workers=0, processes=False, protocol="tcp", dashboard_address="127.0.0.1:0", silence_logs=logging.CRITICAL) as started:
            yield started


def _count_says_one_worker(monkeypatch: pytest.MonkeyPatch) -> None:
    """The runner's first count of workers says 1 (the worker left right after): it goes straight to the broadcast."""
    counted = Connection.worker_count
    calls: list[int] = []

    def first_one(self: Connection) -> int:
        calls.append(1)
        return 1 if len(calls) == 1 else counted(self)

    monkeypatch.setattr(Connection, "worker_count", first_one)


def _worker_joins_when_waited_for(monkeypatch: pytest.MonkeyPatch, local: Any, workers: int) -> list[int]:
    """A worker joins once the runner waits for one (the cluster scaled to ``workers``); the waits, counted."""
    wait = runner._wait_for_a_worker
    waits: list[int] = []

    def joining(connection: Connection) -> None:
        waits.append(1)
        local.scale(workers)
        wait(connection)

    monkeypatch.setattr(runner, "_wait_for_a_worker", joining)
    return waits


def _run(address: str) -> dict[int, np.ndarray]:
    results: dict[int, np.ndarray] = {}
    with Runner(scheduler=address, progress=False) as work:
        work.run_tasks(_scaled, SHARED, ITEMS, [1.0] * len(ITEMS), "points", results.__setitem__)
    return results


def _assert_all_results(results: dict[int, np.ndarray]) -> None:
    assert sorted(results) == list(range(len(ITEMS)))
    for index, item in enumerate(ITEMS):
        np.testing.assert_allclose(results[index], SHARED * item, rtol=0.0, atol=0.0)


def test_a_broadcast_that_finds_no_worker_waits_for_one_and_is_sent_again(local_cluster: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    """The count says 1, there is none: the broadcast times out, the runner waits for a worker, which joins, and the
    broadcast sent again reaches it (before: TimeoutError: No valid workers found)."""
    _count_says_one_worker(monkeypatch)
    waits = _worker_joins_when_waited_for(monkeypatch, local_cluster, 1)
    _assert_all_results(_run(local_cluster.scheduler_address))
    assert len(waits) == 1


def test_a_worker_leaving_as_the_data_goes_to_it_is_replaced(local_cluster: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    """The only worker leaves as the scheduler sends it the shared data: the broadcast fails (OSError after the
    connection's 2 s), the runner waits for a worker, which joins, and the broadcast sent again reaches it."""
    import distributed.scheduler

    local_cluster.scale(1)
    local_cluster.wait_for_workers(1, timeout=30)
    send = distributed.scheduler.scatter_to_workers
    sent: list[list[str]] = []

    async def leaving(workers: list[str], data: dict[str, Any], rpc: Any) -> Any:
        sent.append(list(workers))
        if len(sent) == 1:
            for worker in list(local_cluster.workers.values()):
                await worker.close()
        return await send(workers, data, rpc=rpc)

    monkeypatch.setattr(distributed.scheduler, "scatter_to_workers", leaving)
    waits = _worker_joins_when_waited_for(monkeypatch, local_cluster, 2)  # the closed worker still counts in its spec
    _assert_all_results(_run(local_cluster.scheduler_address))
    assert len(sent) == 2 and sent[0] != sent[1] and len(waits) == 1


def test_no_worker_ever_after_the_count_is_the_one_line_refusal(local_cluster: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    """The count says 1, there is none and none joins: the refusal of a scheduler without workers, naming it."""
    _count_says_one_worker(monkeypatch)
    monkeypatch.setattr(runner, "NO_WORKER_TIMEOUT", 1.0)
    address = local_cluster.scheduler_address
    with pytest.raises(ClusterLost, match=rf"^the dask scheduler at {address} has no workers: none joined within 1 s$"):
        _run(address)


class _Leaving:
    """A client whose workers leave during every broadcast (a worker always joins again at once)."""

    status = "running"

    def __init__(self) -> None:
        self.broadcasts = 0

    def scatter(self, *_args: object, **_options: object) -> object:
        self.broadcasts += 1
        raise OSError("Timed out trying to connect to tcp://127.0.0.1:1 after 2 s")

    def wait_for_workers(self, *_args: object, **_options: object) -> None:
        return None


class _Bar:
    def set_status(self, _status: str) -> None:
        return None


def test_workers_leaving_during_every_broadcast_end_the_study_in_one_line() -> None:
    client = _Leaving()
    connection = Connection(client, None, "tcp://127.0.0.1:8786")
    with pytest.raises(ClusterLost, match=r"^the dask scheduler at tcp://127\.0\.0\.1:8786 has no workers: they left during each of 3 broadcasts of the study's shared data \(OSError: Timed out "):
        runner._broadcast(connection, SHARED, _Bar())  # type: ignore[arg-type]
    assert client.broadcasts == runner.BROADCAST_TRIES == 3
