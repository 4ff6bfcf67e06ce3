"""Writing datasets: atomic files (a reader never sees half a file, a failed write leaves the previous one intact),
netCDF with compression and CF-clean coordinates, and the provenance every dataset carries."""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from datetime import datetime, timezone
from pathlib import Path

import xarray as xr

from vibroimpact import __version__
from vibroimpact.study.fingerprint import source_hash

__all__ = ["atomic_path", "write_dataset", "provenance"]


@contextmanager
def atomic_path(path: Path, suffix: str = ".tmp") -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on success it replaces ``path`` (mode 0644), on failure it is removed.

    ``suffix`` is the temporary file's ending (``.npz`` for ``numpy.savez``, which would otherwise add one).
    """
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix, dir=path.parent)
    os.close(handle)
    temporary = Path(name)
    try:
        yield temporary
        os.chmod(temporary, 0o644)
        os.replace(temporary, path)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise


def provenance() -> dict[str, str]:
    """What every dataset says about how it was made: the package version, its source and the conventions followed."""
    return {"vibroimpact_version": __version__, "vibroimpact_source_sha256": source_hash(), "Conventions": "CF-1.8"}


def write_dataset(dataset: xr.Dataset, path: str | Path) -> Path:
    """Write ``dataset`` to netCDF atomically: a temporary file in the same folder, then a rename.

    A reader never sees a half-written file, and an interrupted run leaves the previous file intact.
    """
    path = Path(path)
    encoding: dict[str, dict[str, object]] = {name: {"zlib": True, "complevel": 4} for name in dataset.data_vars}
    # CF 2.5.1: coordinate variables carry no _FillValue (xarray adds one to every float variable unless told not to)
    encoding |= {name: {"_FillValue": None} for name in dataset.coords if dataset[name].dtype.kind == "f"}
    if not dataset.attrs.get("history"):
        stamp = datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
        dataset = dataset.assign_attrs(history=f"{stamp} vibroimpact {__version__}: {dataset.attrs.get('title', 'dataset')} written")
    with atomic_path(path) as temporary:
        dataset.to_netcdf(temporary, engine="netcdf4", format="NETCDF4", encoding=encoding)
    return path
