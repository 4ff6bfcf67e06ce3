"""Dimensions labelled by strings (or by numbers out of order), as a netCDF file holds them (CF 1.8 section 6.1.1,
labels).

In memory a dataset labels some of its dimensions with strings (``solution`` = ``linear``, ``pgf``, ``exact``, ...;
``sweep`` = ``up``, ``down``; a benchmark's ``case``, ``engine``, ``reference``, ``model``; a concepts study's
``concept``; a validation's ``engine``), so that ``dataset.sel(solution="exact")`` reads as it says, and a bumper
bifurcation study labels its brute force's contact models by ``bumper_frequency`` = inf (the rigid stop), then each
bumper's frequency in the scene's order. CF 1.8 wants a coordinate variable (a variable named as its dimension)
numeric and strictly monotonic (section 5, 1.2); the IOOS compliance checker's monotonicity check raises on one of
strings (the command line then exits 2) and fails one out of order (exit 1). In the file such a dimension is
therefore an index dimension without a coordinate variable (positions 0, 1, ... along it), and its labels are the
auxiliary coordinate ``<dimension>_label`` (:data:`LABEL_SUFFIX`), with the coordinate's attributes, which every data
variable along the dimension names in its ``coordinates`` attribute. :func:`encode_labels` makes that form and
:func:`decode_labels` undoes it: ``decode_labels(encode_labels(dataset))`` is ``dataset``.

A file opened with xarray alone selects by label once the labels are its index:
``xr.open_dataset(path).set_xindex("solution_label").sel(solution_label="exact")``.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

__all__ = ["LABEL_SUFFIX", "encode_labels", "decode_labels", "labelled_dimensions"]

#: The suffix of the auxiliary coordinate that holds a dimension's labels in a file (``solution_label``).
LABEL_SUFFIX = "_label"


def _is_coordinate_variable(variable: xr.DataArray) -> bool:
    """Can ``variable`` (a dimension's coordinate) be a CF coordinate variable: numbers, strictly monotonic?"""
    if variable.dtype.kind not in "iufmM":
        return False
    steps = np.diff(variable.values)
    return bool(np.all(steps > 0) or np.all(steps < 0))


def labelled_dimensions(dataset: xr.Dataset) -> list[str]:
    """The dimensions of ``dataset`` whose coordinate (index) cannot be a CF coordinate variable: strings, or numbers
    that are not strictly monotonic (NaN among them included)."""
    return [str(dim) for dim in dataset.dims if dim in dataset.coords and not _is_coordinate_variable(dataset[dim])]


def encode_labels(dataset: xr.Dataset) -> xr.Dataset:
    """``dataset`` as a file holds it: each labelled dimension (:func:`labelled_dimensions`) without its coordinate,
    its labels (and their attributes) in the coordinate ``<dimension>_label`` along it.

    Raises
    ------
    ValueError
        If ``dataset`` already has a variable of that name (it would be read back as the labels).
    """
    labelled = labelled_dimensions(dataset)
    if not labelled:
        return dataset
    taken = [f"{dim}{LABEL_SUFFIX}" for dim in labelled if f"{dim}{LABEL_SUFFIX}" in dataset.variables]
    if taken:
        raise ValueError(f"the dataset already has {', '.join(taken)}: the labels of its dimensions {', '.join(labelled)} go there in a file")
    labels = {f"{dim}{LABEL_SUFFIX}": xr.Variable((dim,), dataset[dim].values, dict(dataset[dim].attrs)) for dim in labelled}
    return dataset.drop_vars(labelled).assign_coords(labels)


def decode_labels(dataset: xr.Dataset) -> xr.Dataset:
    """``dataset`` as :func:`encode_labels` had it: every coordinate ``<dimension>_label`` along a dimension without a
    coordinate becomes that dimension's coordinate again (a file written before the labels moved, with string
    coordinate variables, is returned as it is)."""
    found = {}
    for name, variable in dataset.coords.items():
        dim = str(name).removesuffix(LABEL_SUFFIX)
        if str(name).endswith(LABEL_SUFFIX) and variable.dims == (dim,) and dim not in dataset.coords:
            found[str(name)] = dim
    if not found:
        return dataset
    labels = {dim: xr.Variable((dim,), dataset[name].values, dict(dataset[name].attrs)) for name, dim in found.items()}
    return dataset.drop_vars(list(found)).assign_coords(labels)
