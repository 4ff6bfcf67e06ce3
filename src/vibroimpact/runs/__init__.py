"""The machinery every kind of study shares: the runner (this process or dask.distributed), the resumable store, the
cost estimate, progress, and atomic dataset writes (``run``: :func:`run_study`, :func:`write_dataset`). It knows the
kinds only through the table :data:`vibroimpact.scene.kinds.KINDS`."""
