"""Dimensions labelled by strings (or by numbers out of order) are index dimensions in a file, their labels an
auxiliary coordinate (CF 1.8 section 6.1.1): the file form and back is the dataset, a file of the old form still reads,
and xarray alone selects by label in the file."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from vibroimpact.runs.labels import decode_labels, encode_labels, labelled_dimensions
from vibroimpact.runs.run import read_dataset, write_dataset


def benchmark_like() -> xr.Dataset:
    """Three labelled dimensions (one only a coordinate's), one numeric, a string variable that is not a label."""
    return xr.Dataset(
        {
            "wall_time": (("case", "engine", "rtol"), np.arange(8.0).reshape(2, 2, 2), {"units": "s", "long_name": "wall time"}),
            "reference_wall_time": (("case", "reference"), [[0.5], [1.5]], {"units": "s", "long_name": "reference wall time"}),
            "case_note": ("case", np.array(["a", "b"], dtype=str), {"long_name": "note"}),
        },
        coords={
            "case": ("case", ["one_impact_25Hz", "swept"]),
            "engine": ("engine", np.array(["momentary_adams", "exact"], dtype=object), {"long_name": "engine"}),
            "rtol": ("rtol", [1e-6, 1e-8], {"units": "1", "long_name": "relative tolerance"}),
            "reference": ("reference", ["exact"], {"long_name": "reference method"}),
            "model": ("model", ["rigid", "bumper"]),
        },
        attrs={"Conventions": "CF-1.8", "title": "labels"},
    )


def test_the_file_form_has_index_dimensions_and_label_coordinates() -> None:
    dataset = benchmark_like()
    assert labelled_dimensions(dataset) == ["case", "engine", "reference", "model"]
    stored = encode_labels(dataset)
    assert not {"case", "engine", "reference", "model"} & set(stored.variables)  # no coordinate variable of strings
    assert dict(stored.sizes) == dict(dataset.sizes)
    for dim in ("case", "engine", "reference", "model"):
        label = stored[f"{dim}_label"]
        assert label.dims == (dim,) and list(label.values) == list(dataset[dim].values) and label.attrs == dataset[dim].attrs
    assert "rtol" in stored.indexes and "case_note" in stored.data_vars  # numbers and non-label text stay as they are
    back = decode_labels(stored)
    xr.testing.assert_identical(back, dataset)
    assert {name: back[name].dtype for name in dataset.variables} == {name: dataset[name].dtype for name in dataset.variables}
    assert decode_labels(dataset) is dataset and encode_labels(stored) is stored  # each form is its own fixed point


def test_numbers_out_of_order_are_labels_and_monotonic_ones_coordinates(tmp_path: Path) -> None:
    """A bumper bifurcation's contact models: inf (the rigid stop) before the bumpers' frequencies is not a CF
    coordinate variable (not monotonic); in increasing or decreasing order, or one value, it is."""
    from tests.study.test_cf import checked

    models = {"units": "Hz", "long_name": "bumper frequency (inf: the rigid stop)"}
    for values, labelled in (([np.inf, 250.0, 1000.0], True), ([250.0, np.nan], True), ([250.0, 1000.0, np.inf], False), ([1000.0, 250.0], False), ([250.0], False)):
        dataset = xr.Dataset({"x": ("bumper_frequency", np.ones(len(values)), {"units": "m", "long_name": "x"})}, coords={"bumper_frequency": ("bumper_frequency", values, models)}, attrs={"Conventions": "CF-1.8", "title": "t"})
        assert labelled_dimensions(dataset) == (["bumper_frequency"] if labelled else []), values
        path = write_dataset(dataset, tmp_path / "models.nc")
        back = read_dataset(path)
        assert back.attrs.pop("history")
        xr.testing.assert_identical(back, dataset)
        assert checked(path, tmp_path / "cf.json") == [], values


def test_a_dataset_that_already_has_the_label_name_is_refused() -> None:
    dataset = benchmark_like().assign(engine_label=("engine", ["x", "y"]))
    with pytest.raises(ValueError, match="engine_label"):
        encode_labels(dataset)


def test_the_written_file_reads_back_and_plain_xarray_selects_by_label(tmp_path: Path) -> None:
    dataset = benchmark_like()
    path = write_dataset(dataset, tmp_path / "labels.nc")
    back = read_dataset(path)
    assert back.attrs.pop("history")
    xr.testing.assert_identical(back, dataset)
    with xr.open_dataset(path) as opened:
        assert "engine" not in opened.variables and opened["wall_time"].encoding["coordinates"].split() == ["case_label", "engine_label"]
        by_label = opened.set_xindex("engine_label").set_xindex("case_label")
        assert float(by_label["wall_time"].sel(engine_label="exact", case_label="swept", rtol=1e-8)) == 7.0  # exact: stored as written


def test_a_file_with_string_coordinate_variables_still_reads(tmp_path: Path) -> None:
    """Files written before the labels moved (``solution`` a coordinate variable of strings) read as they did."""
    dataset = benchmark_like()
    dataset.to_netcdf(tmp_path / "old.nc")
    xr.testing.assert_identical(read_dataset(tmp_path / "old.nc"), dataset)
