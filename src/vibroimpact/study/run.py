"""Run a scene: its kind of study (:mod:`vibroimpact.study.kinds`) expands it into its grid, computes the solutions it
asks for and gathers one labelled ``xarray.Dataset``.

Output contract (read by other tools; keep these names): dimensions ``solution`` (strings), each swept parameter
(``restitution`` [1], ``clearance`` [m]) and ``frequency`` [Hz]; variables ``x1_amplitude`` [m],
``x2_amplitude`` [m], ``force_amplitude`` [N], ``suspension_force_amplitude`` [N], ``impulse`` [N s], ``phase``
[rad] and ``regime`` (CF flags). Unswept stop parameters are scalar coordinates. Swept-sine scenes add dimension
``sweep``: the swept runs' estimates are ``swept_<quantity>`` (sweep, frequency) and their running estimates
``running_<quantity>`` (sweep, elapsed_time); the steady-state solutions are not repeated along ``sweep``. Benchmark
scenes have dimensions (case, engine, rtol). Every dataset names its kind in the attribute ``study_kind``.
"""

from __future__ import annotations

import sys
import xarray as xr

from vibroimpact.scene.schema import Scene
from vibroimpact.study.grid import Progress
from vibroimpact.study.kinds import study_kind
from vibroimpact.study.runner import Runner
from vibroimpact.study.store import StudyStore

__all__ = ["run_study"]


def _stderr_progress(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def run_study(scene: Scene, progress: Progress | None = _stderr_progress, jobs: int = 1, store: StudyStore | None = None, scheduler: str | None = None, load: bool = True) -> xr.Dataset:
    """Compute every solution of ``scene`` over its grid.

    Parameters
    ----------
    scene : Scene
        A validated scene.
    progress : callable, optional
        Receives one line per finished step; ``None`` for silence (also silences the progress bar).
    jobs : int
        Worker processes of the local dask cluster; 1: this process alone.
    store : StudyStore, optional
        Where finished work is kept as it arrives (a rerun skips it); None: in memory.
    scheduler : str, optional
        Address of a running dask scheduler to run the work on instead of a local cluster.
    load : bool
        Load the dataset into memory; False: a stepped study's variables stay lazy arrays over ``store``.

    Returns
    -------
    xarray.Dataset
        Dimensions ``solution``, the swept parameters (``sweep`` for swept-sine tests) and ``frequency``; benchmark
        scenes: ``case``, ``engine``, ``rtol``.

    Raises
    ------
    KeyboardInterrupt
        On Ctrl-C, after the work in progress is cancelled (finished work stays in ``store``).
    vibroimpact.study.cluster.ClusterLost
        When the dask scheduler goes away.
    """
    kind = study_kind(scene)
    with Runner(jobs, scheduler, store, progress is not None) as runner:
        dataset = kind.run(scene, progress, runner)
    dataset.attrs["study_kind"] = kind.name
    if runner.worker_peak_memory:
        dataset.attrs["run_peak_memory_worker_bytes"] = runner.worker_peak_memory  # the largest dask worker
    return dataset.load() if load else dataset
