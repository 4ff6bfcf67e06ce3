"""A stepped study's grid in blocks: each block a sub-scene solved on a worker, written into the store as it arrives
(a region aligned with the store's chunks), skipped by a rerun once written.

The grid is (restitution, clearance, bumper_frequency, sweep, frequency). Every point of a stepped study is
independent of the others, except along ``frequency`` for the stepped sweeps (``sweep_up``, ``sweep_down``: a
chain), so a block is a box of the grid: whole frequency rows for a chain, else any range. A block of the
restitution, clearance and frequency ranges is the same scene with those values, so the same code that solves a
whole scene solves a block, with the same numbers.

Block sizes: closed forms only, :data:`CLOSED_FORM_POINTS` points (bounded memory: a 10^7-point study holds a few
blocks at a time); with time-domain engines, enough simulated points that a task's work dwarfs the scheduler's
~2 ms and the store's write per block, and enough blocks that every worker stays busy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Callable

import numpy as np
import xarray as xr

from vibroimpact.scene.subset import subset_axes, subset_share
from vibroimpact.scene.schema import ENGINE_SOLUTIONS, GRID_DIMS, Scene
from vibroimpact.simulation.settings import SWEEP_STARTS
from vibroimpact.runs.cluster import ProgressReport
from vibroimpact.runs.runner import Runner

__all__ = ["BlockPlan", "plan_blocks", "run_grid", "CLOSED_FORM_POINTS", "SIMULATED_POINTS"]

#: Grid points of a block of closed forms only (~50 MB of intermediate arrays per block).
CLOSED_FORM_POINTS = 50_000
#: Simulated points of a block with time-domain engines: at least ``SIMULATED_POINTS[0]`` (the compiled exact
#: engine's ~1-3 ms per point then outweigh the ~2 ms a task costs the scheduler 15-50 times), at most
#: ``SIMULATED_POINTS[1]``, aiming at :data:`BLOCKS_PER_WORKER` blocks per worker.
SIMULATED_POINTS = (32, 1024)
BLOCKS_PER_WORKER = 16

#: Solves one block: (the block's scene, a runner in this process) -> its variables over the block's unsqueezed grid.
BlockSolver = Callable[[Scene, Runner], xr.Dataset]


@dataclass(frozen=True)
class BlockPlan:
    """The grid's shape and the shape of its blocks (the last block along an axis may be shorter).

    Attributes
    ----------
    full : tuple of int
        The grid's shape along :data:`GRID_DIMS`.
    block : tuple of int
        A block's shape along :data:`GRID_DIMS`.
    """

    full: tuple[int, ...]
    block: tuple[int, ...]

    @property
    def counts(self) -> tuple[int, ...]:
        """Blocks along each axis."""
        return tuple(math.ceil(n / b) for n, b in zip(self.full, self.block))

    @property
    def count(self) -> int:
        """Blocks in all."""
        return math.prod(self.counts)

    def region(self, index: int) -> dict[str, slice]:
        """The grid's slices of block ``index`` (C order over the block counts)."""
        position = np.unravel_index(index, self.counts)
        return {dim: slice(int(p) * b, min((int(p) + 1) * b, n)) for dim, p, b, n in zip(GRID_DIMS, position, self.block, self.full)}

    def points(self, index: int) -> int:
        """Grid points in block ``index``."""
        return math.prod(s.stop - s.start for s in self.region(index).values())


def _simulates(scene: Scene) -> bool:
    """Whether the scene asks for a time-domain solution (and so has simulation settings)."""
    return scene.settings.simulation is not None and any(name in ENGINE_SOLUTIONS for name in scene.settings.solutions)


def plan_blocks(scene: Scene, workers: int) -> BlockPlan:
    """Blocks of ``scene``'s grid for ``workers`` workers (module docstring)."""
    frequency = scene.settings.all_frequencies
    bumpers = scene.settings.bumper_frequency.size if scene.settings.bumper_frequency is not None else 1
    directions = max(len(scene.settings.sweep_directions), 1)
    full = (scene.settings.restitution.size, scene.settings.clearance.size, bumpers, directions, frequency.size)
    if _simulates(scene):
        assert scene.settings.simulation is not None
        rows = full[0] * full[1] * full[2] * full[3]
        per_row = scene.settings.simulation.frequency.size
        target = int(np.clip(rows * per_row / (BLOCKS_PER_WORKER * max(workers, 1)), *SIMULATED_POINTS))
        if scene.settings.simulation.start in SWEEP_STARTS:
            row = frequency.size  # a chain: whole rows
        else:
            row = max(1, min(frequency.size, math.ceil(target * frequency.size / max(per_row, 1))))
        points = max(row, target * frequency.size // max(per_row, 1))
    else:
        row = min(frequency.size, CLOSED_FORM_POINTS)
        points = CLOSED_FORM_POINTS
    block = [1, 1, 1, 1, row]
    for axis in (1, 0):  # clearance, then restitution, while the block stays within its points
        block[axis] = max(1, min(full[axis], points // math.prod(block)))
    return BlockPlan(full, tuple(block))


def block_scene(scene: Scene, region: dict[str, slice]) -> Scene:
    """The scene restricted to a block: the same scene with the block's restitution, clearance, bumper and frequency
    values (the analytic and the simulation grids each keep their frequencies inside the block's range)."""
    grid = scene.settings
    frequencies = grid.all_frequencies[region["frequency"]]
    restitution = region["restitution"]
    changes: dict[str, object] = {
        "restitution": grid.restitution[restitution],
        "clearance": grid.clearance[region["clearance"]],
        "frequency": np.intersect1d(grid.frequency, frequencies),
    }
    if grid.bumper_frequency is not None:
        changes["bumper_frequency"] = grid.bumper_frequency[region["bumper_frequency"]]
    if grid.bumper_loss_factor is not None and np.size(grid.bumper_loss_factor) == grid.restitution.size and grid.restitution.size > 1:
        changes["bumper_loss_factor"] = np.asarray(grid.bumper_loss_factor)[restitution]
    if grid.simulation is not None:
        changes["simulation"] = replace(grid.simulation, frequency=np.intersect1d(grid.simulation.frequency, frequencies))
    return replace(scene, settings=replace(grid, **changes))  # type: ignore[arg-type]


def _solve_block(shared: tuple[Scene, BlockPlan, BlockSolver], index: int, report: ProgressReport) -> dict[str, tuple[tuple[str, ...], np.ndarray, dict[str, object]]]:
    """Run on a worker (or here): block ``index``'s variables as (dimensions, values, attributes)."""
    scene, plan, solve = shared
    with Runner(jobs=1, report=report) as runner:
        dataset = solve(block_scene(scene, plan.region(index)), runner)
    return {name: (tuple(map(str, variable.dims)), np.asarray(variable.values), dict(variable.attrs)) for name, variable in dataset.data_vars.items()}


def block_work(scene: Scene, plan: BlockPlan, index: int) -> float:
    """A block's work for the progress bar: simulated points times engine runs, or grid points of closed forms."""
    region = plan.region(index)
    if not _simulates(scene):
        return float(plan.points(index))
    assert scene.settings.simulation is not None
    frequencies = scene.settings.all_frequencies[region["frequency"]]
    simulated = scene.settings.simulation.frequency[(scene.settings.simulation.frequency >= frequencies[0]) & (scene.settings.simulation.frequency <= frequencies[-1])]
    rows = math.prod(s.stop - s.start for dim, s in region.items() if dim != "frequency")
    axes = subset_axes(block_scene(scene, region), simulated)
    share = sum(subset_share(scene.settings.simulation.subset, name, axes) for name in scene.settings.solutions if name in ENGINE_SOLUTIONS)
    return float(simulated.size * rows * share)


def run_grid(scene: Scene, runner: Runner, solve: BlockSolver, extra_sizes: dict[str, int] | None = None) -> xr.Dataset:
    """Every block of ``scene`` solved by ``solve`` (in ``runner``'s workers) and written into its store; the grid's
    variables, lazily from the store (dimensions ``solution`` and :data:`GRID_DIMS` unsqueezed, no coordinates).

    ``extra_sizes``: sizes of dimensions other than the grid's (``solution``, ``stop``), which every block has whole.
    """
    from vibroimpact.runs.fingerprints import store_fingerprint
    from vibroimpact.runs.store import StoreUnusable, StudyStore

    store = runner.store if runner.store is not None else StudyStore(None, store_fingerprint(scene.text))
    plan = plan_blocks(scene, runner.workers if runner.distributed else 1)
    dropped = store.check_grid()  # the metadata as it was written (rebuilt where it differs), before anything reads it
    if dropped:
        store.say(f"the grid's record of its metadata is lost or damaged: {dropped} finished blocks are computed again")
    if store.grid_ready:
        kept = store.grid_plan()
        if kept is not None and kept[0] == plan.full:
            plan = BlockPlan(plan.full, kept[1])  # a resumed study keeps the blocks it began with, whatever its workers
    sizes = dict(zip(GRID_DIMS, plan.full)) | (extra_sizes or {})
    chunks = dict(zip(GRID_DIMS, plan.block))

    def finished(index: int, variables: dict[str, tuple[tuple[str, ...], np.ndarray, dict[str, object]]]) -> None:
        if not store.grid_ready:
            store.begin_grid(_template(variables, sizes, chunks), plan.count, (plan.full, plan.block))
        store.write_block(index, plan.region(index), {name: (dims, values) for name, (dims, values, _attrs) in variables.items()})

    totals = [block_work(scene, plan, index) for index in range(plan.count)]
    for attempt in (1, 2):
        # every finished block proves its values against its checksum: on resume, and again before they are exported
        for check in ("resumed", "exported"):
            finished_before = store.block_count()
            damaged = store.verify_blocks(plan.region)
            if damaged:
                store.say(f"{damaged} damaged blocks of {max(finished_before, damaged)} finished ({check}) are computed again")
            skip = np.flatnonzero(store.finished_blocks()).tolist() if store.grid_ready else []
            if check == "resumed" and attempt == 1:
                runner.note_reused("blocks", len(skip), plan.count)
            if check == "exported" and len(skip) == plan.count:
                break
            runner.run_tasks(_solve_block, (scene, plan, solve), list(range(plan.count)), totals, "points", finished, skip=skip, verb="simulating" if _simulates(scene) else "solving")
        if store.block_count() != plan.count:  # cannot happen: a block that failed twice in one run raises on the way
            raise RuntimeError(f"the store holds {store.block_count()} of the grid's {plan.count} blocks after the run")
        try:
            return store.grid_dataset()
        except StoreUnusable as error:
            if attempt == 2:
                raise RuntimeError(f"{store.path}: a store begun afresh cannot be read: {error}") from error
            store.start_afresh(str(error))  # an unreadable array beside the grid's: nothing can be trusted
    raise AssertionError("unreachable")


def _template(variables: dict[str, tuple[tuple[str, ...], np.ndarray, dict[str, object]]], sizes: dict[str, int], chunks: dict[str, int]) -> xr.Dataset:
    """Lazy arrays (nothing computed) of the grid's variables, shaped and chunked like the grid, typed like a block's."""
    import dask.array

    data = {}
    for name, (dims, values, attrs) in variables.items():
        shape = tuple(sizes.get(dim, values.shape[axis]) for axis, dim in enumerate(dims))
        chunk = tuple(chunks.get(dim, shape[axis]) for axis, dim in enumerate(dims))
        data[name] = xr.Variable(dims, dask.array.empty(shape, chunks=chunk, dtype=values.dtype), attrs)
    return xr.Dataset(data)
