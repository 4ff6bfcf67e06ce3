"""A failed netCDF write (a full disk: the netCDF library says only "NetCDF: HDF error") is said in words, with the
free space, and leaves neither a partial file nor a temporary one (issue 22, item 7)."""

from __future__ import annotations

from pathlib import Path

import pytest
import xarray as xr

from vibroimpact.runs.run import write_dataset

GOLDEN = Path(__file__).parents[1] / "golden" / "data"


def test_a_failed_write_says_what_happened_and_leaves_nothing(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    dataset = xr.load_dataset(GOLDEN / "restitution.nc")

    def full_disk(self: xr.Dataset, *_arguments: object, **_options: object) -> None:
        Path(_arguments[0]).write_bytes(b"\x89HDF half")  # type: ignore[arg-type]
        raise RuntimeError("NetCDF: HDF error")

    monkeypatch.setattr(xr.Dataset, "to_netcdf", full_disk)
    with pytest.raises(OSError, match=r"writing .*out\.nc failed \(NetCDF: HDF error\); \d+ MB free on its disk: free space there or choose another --out"):
        write_dataset(dataset, tmp_path / "out.nc")
    assert list(tmp_path.iterdir()) == []
