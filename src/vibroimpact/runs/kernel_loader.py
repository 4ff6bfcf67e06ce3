"""The dask worker plugin that loads the study's compiled engine kernels as a worker starts (imported when a study
starts its workers: it imports dask's distributed)."""

from __future__ import annotations

from collections.abc import Sequence

from distributed.diagnostics.plugin import WorkerPlugin

from vibroimpact.engines.registry import engine_spec

__all__ = ["KernelLoader"]


class KernelLoader(WorkerPlugin):  # type: ignore[misc]
    """As a worker starts (or the plugin is registered), load the compiled kernels of the study's ``engines`` from
    numba's on-disk cache (:meth:`~vibroimpact.engines.registry.EngineSpec.prepare_kernels`; the study's process
    compiled them first, :func:`vibroimpact.runs.run.prepare_engines`), so that no task's own wall time includes them.

    Parameters
    ----------
    engines : sequence of str
        Registered engine names; those without compiled kernels are skipped.
    batched : sequence of str
        Those whose batch entry the study runs too.
    """

    idempotent = True

    def __init__(self, engines: Sequence[str], batched: Sequence[str] = ()) -> None:
        self.engines = tuple(engines)
        self.batched = tuple(batched)

    def setup(self, worker: object) -> None:
        for name in self.engines:
            engine_spec(name).prepare_kernels(name in self.batched)
