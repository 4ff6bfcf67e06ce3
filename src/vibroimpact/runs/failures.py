"""What failed inside a run, said in words: one line per kind of failure for the page, one line for the console.

A study never stops for one failing point: the point is left blank (NaN) and flagged, and the run goes on. So that
no failure is silent, :func:`run_failures` gathers them from the dataset itself, by two rules that hold for every kind
of study:

* a kind that knows more records its own lines in the dataset attribute ``run_failures`` (a list of one-line
  strings, each "what failed: how many of how many; what it means for the results"), and the raw messages in
  ``run_failure_details``;
* every CF flag variable whose ``flag_meanings`` include ``failed`` (a stepped study's ``regime``, a swept-sine
  run's ``sweep_failed``, a validation's ``brute_failed``) is counted, per solution where it has that dimension.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # only named in signatures: the CLI's help and refusals must not load xarray
    import xarray as xr

__all__ = ["FAILED_FLAG", "run_failures", "failure_details", "console_line", "as_lines"]

#: The flag meaning that marks a point whose computation raised (its values are blank).
FAILED_FLAG = "failed"


def as_lines(value: object) -> list[str]:
    """An attribute read back from netCDF (a string, or an array/list of strings) as a list of lines."""
    if value is None:
        return []
    if isinstance(value, str):
        return [value] if value else []
    return [str(line) for line in np.atleast_1d(np.asarray(value)).tolist() if str(line)]


def _flag_value(variable: xr.DataArray, meaning: str) -> int | None:
    """The value of a CF flag variable's flag ``meaning`` (e.g. ``failed``), or None if it has no such flag."""
    meanings = str(variable.attrs.get("flag_meanings", "")).split()
    values = variable.attrs.get("flag_values")
    if meaning not in meanings or values is None:
        return None
    values = np.atleast_1d(np.asarray(values))
    return int(values[meanings.index(meaning)]) if values.size == len(meanings) else None


def run_failures(dataset: xr.Dataset) -> list[str]:
    """One line per kind of failure in ``dataset``: what failed, how many of how many, what it means for the results.

    Empty when nothing failed.
    """
    lines = as_lines(dataset.attrs.get("run_failures"))
    for name, variable in dataset.data_vars.items():
        flag = _flag_value(variable, FAILED_FLAG)
        if flag is None:
            continue
        failed = variable == flag
        if "solution" in variable.dims and variable.sizes["solution"] > 1:
            other = [dim for dim in variable.dims if dim != "solution"]
            counts = failed.sum(other).values
            # the points each solution was computed at: a simulated solution covers a subset of the grid
            not_computed = _flag_value(variable, "not_computed")
            computed = (variable != not_computed).sum(other).values if not_computed is not None else np.full(counts.shape, variable.size // variable.sizes["solution"])
            parts = [f"{solution}: {int(count)} of {int(total)} points" for solution, count, total in zip(variable["solution"].values, counts, computed) if count]
        else:
            count = int(failed.sum())
            parts = [f"{count} of {int(variable.size)} points"] if count else []
        if parts:
            lines.append(f"{', '.join(parts)} failed ({name} = {FAILED_FLAG}): no value could be computed there (the computation raised, or a closed form is ill-conditioned there); those points are blank (NaN) in the dataset and missing from the figures, the others are unaffected")
    return lines


def failure_details(dataset: xr.Dataset) -> list[str]:
    """The raw messages of the run's failures that its kind kept (``run_failure_details``), for a collapsed section."""
    return as_lines(dataset.attrs.get("run_failure_details"))


def console_line(failures: list[str], report: str | None = None) -> str:
    """The one console line that says a run had failures (empty string: none). ``report`` names where the details are."""
    if not failures:
        return ""
    where = f"; details in {report}" if report else ""
    head = failures[0] if len(failures) == 1 else f"{failures[0]} (and {len(failures) - 1} more kinds of failure)"
    return f"warning: the run finished with failures: {head}{where}"
