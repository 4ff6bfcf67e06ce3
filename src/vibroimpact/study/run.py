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
from pathlib import Path

import xarray as xr

from vibroimpact.scene.schema import Scene
from vibroimpact.study.grid import Progress
from vibroimpact.study.kinds import study_kind

__all__ = ["run_study"]


def _stderr_progress(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def run_study(scene: Scene, progress: Progress | None = _stderr_progress, jobs: int = 1, cache_dir: Path | None = None) -> xr.Dataset:
    """Compute every solution of ``scene`` over its grid.

    Parameters
    ----------
    scene : Scene
        A validated scene.
    progress : callable, optional
        Receives one line per finished step; ``None`` for silence (also silences the simulation progress bar).
    jobs : int
        Processes for the time-domain solutions.
    cache_dir : Path, optional
        Folder where finished simulation cases are kept, so that an interrupted study resumes.

    Returns
    -------
    xarray.Dataset
        Dimensions ``solution``, the swept parameters (``sweep`` for swept-sine tests) and ``frequency``; benchmark
        scenes: ``case``, ``engine``, ``rtol``.
    """
    kind = study_kind(scene)
    dataset = kind.run(scene, progress, jobs, cache_dir)
    dataset.attrs["study_kind"] = kind.name
    return dataset
