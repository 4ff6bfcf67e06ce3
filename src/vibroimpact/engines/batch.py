"""Many runs of one layout in one compiled call, from Python: the cases' leading arguments stacked, the runs handed
to an engine's batch loop (:mod:`~vibroimpact.engines.batch_kernels`), and what it kept by name (:class:`BatchRuns`).

An engine that can (capability ``batched``) offers ``run_many(problems, case_of, starts, transient, strobes, scales,
max_period)``; it checks every problem and start as its single runs do, then calls :func:`run_batch` with its loop.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from vibroimpact.engines.interruptible import call_interruptibly

__all__ = ["BatchRuns", "run_batch"]


class BatchRuns(NamedTuple):
    """What a batch kept per run (index i of every field; :mod:`~vibroimpact.engines.batch_kernels`)."""

    status: NDArray[np.int64]  # 0: measured; else the loop's status where the run stopped
    stopped: NDArray[np.float64]  # where a failed run stopped [s] (NaN: measured)
    strobes: NDArray[np.float64]  # the measured run's strobes, (runs, strobes + 1, n) [m, m s-1]
    jacobians: NDArray[np.float64]  # each measured period's exact Jacobian, (runs, strobes, n, n)
    moments: NDArray[np.complex128]  # per measured period, (runs, strobes, 2 N + K)
    impacts: NDArray[np.int64]  # impacts in the measured run
    velocities: NDArray[np.float64]  # the last impact speeds, NaN-padded, (runs, 64) [m s-1]
    after: NDArray[np.int64]  # impacts at or after each strobe, (runs, strobes + 1)
    mismatch: NDArray[np.float64]  # the strobes' repeat test for p = 1 ... max_period, (runs, max_period) [-]


def _signature(arguments: Any) -> tuple:
    """The shapes and types of a case's leading arguments: cases of one signature stack into one call."""
    return tuple((np.shape(value), np.asarray(value).dtype.str) for value in arguments)


def _stacked(cases: Sequence[Any]) -> tuple:
    """Each leading argument stacked over ``cases`` (arrays: a new first axis; numbers: an array of them)."""
    return tuple(np.ascontiguousarray(np.stack([np.asarray(case[f]) for case in cases])) for f in range(len(cases[0])))


def run_batch(
    kernel: Callable[..., tuple], arguments: Sequence[Any], case_of: NDArray[np.int64], starts: NDArray[np.float64], transient: int, strobes: int,
    scales: NDArray[np.float64], max_period: int, chain_from: NDArray[np.int64] | None = None,
) -> BatchRuns:  # fmt: skip
    """Run every start through ``kernel`` (a batch loop), the cases grouped by the shapes of their leading arguments.

    Parameters
    ----------
    kernel : callable
        :func:`~vibroimpact.engines.batch_kernels.run_rigid_batch` or the bumper's.
    arguments : sequence of named tuples
        Per case, its loop's leading arguments.
    case_of : ndarray of int, shape (runs,)
        The case of each run.
    starts : ndarray, shape (runs, n)
        Each run's start at t = 0 [m, m s-1], checked.
    transient, strobes : int
        Periods dropped, then measured.
    scales : ndarray, shape (cases, n)
        The repeat test's scales per case [m, m s-1].
    max_period : int
        Longest period of the repeat test [periods].
    chain_from : ndarray of int, shape (runs,), optional
        Run i starts from run ``chain_from[i]``'s end state (an earlier run; ``starts[i]`` where that one failed),
        or from ``starts[i]`` where it is -1 (default: every run from its start). Chained runs share one group.
    """
    case_of = np.asarray(case_of, dtype=np.int64)
    starts = np.ascontiguousarray(starts, dtype=float)
    scales = np.ascontiguousarray(scales, dtype=float)
    chain_from = np.full(case_of.size, -1, dtype=np.int64) if chain_from is None else np.asarray(chain_from, dtype=np.int64)
    if np.any(chain_from >= np.arange(case_of.size)):
        raise ValueError("chain_from: a run starts from an earlier run's end (chain_from[i] < i) or from its start (-1)")
    groups: dict[tuple, list[int]] = {}
    for c, case in enumerate(arguments):
        groups.setdefault(_signature(case), []).append(c)
    if len(groups) > 1 and np.any(chain_from >= 0):
        raise ValueError("chained runs need cases whose leading arguments have one shape (one compiled call)")
    parts = []
    for members in groups.values():
        local = np.full(len(arguments), -1, dtype=np.int64)
        local[members] = np.arange(len(members))
        rows = np.flatnonzero(local[case_of] >= 0)
        stacked = _stacked([arguments[c] for c in members])
        total = rows.size * (transient + strobes)
        out = call_interruptibly(
            lambda cancel: kernel(*stacked, local[case_of[rows]], starts[rows], chain_from[rows], int(transient), int(strobes), scales[members], int(max_period), cancel), total
        )  # fmt: skip
        parts.append((rows, out))
    if len(parts) == 1 and parts[0][0].size == case_of.size:
        return BatchRuns._make(parts[0][1])
    fields = []
    for f in range(len(BatchRuns._fields)):
        first = np.asarray(parts[0][1][f])
        whole = np.empty((case_of.size, *first.shape[1:]), dtype=first.dtype)
        for rows, out in parts:
            whole[rows] = out[f]
        fields.append(whole)
    return BatchRuns._make(fields)
