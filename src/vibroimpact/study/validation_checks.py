"""The record of a validation: one row per compared quantity, and the dataset a validation scene writes.

A :class:`Check` says what was compared (published against computed), the relative error, the tolerance and whether
it passed; an informative row (tolerance NaN) shows a value beside the checks without being one (e.g. what an
approximate formula would have said). A :class:`CaseOutcome` is a case's rows with the arrays of its figure.

Dataset (``<name>.nc``): dimension ``check`` with ``quantity``, ``unit`` and ``note`` (strings), ``published``,
``computed``, ``relative_error``, ``tolerance`` and ``passed`` (CF flags ``failed passed informative``); every
other variable is the case's own (its figure's data, with its units). Attributes: the case's own (its thresholds),
``validation_case``,
``validation_source``, ``validation_passed`` (1 when every check passed), the scene and provenance.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import xarray as xr

__all__ = ["Check", "CaseOutcome", "PASSED_MEANINGS", "check", "outcome_dataset"]

#: Meanings of the ``passed`` flag, in order of its values 0, 1, 2.
PASSED_MEANINGS = ("failed", "passed", "informative")


@dataclass(frozen=True)
class Check:
    """One compared quantity.

    Attributes
    ----------
    quantity : str
        What is compared (a short phrase; the page's first column).
    published : float
        The closed form's value (in ``unit``).
    computed : float
        The project's value.
    relative_error : float
        |computed - published| / |published| unless the row defines its own measure (e.g. a residual) [-].
    tolerance : float
        Largest relative error that passes [-]; NaN: an informative row, not a check.
    unit : str
        Unit of ``published`` and ``computed`` (CF string; ``1`` for dimensionless).
    note : str
        Where the tolerance comes from, or what the row means.
    """

    quantity: str
    published: float
    computed: float
    relative_error: float
    tolerance: float
    unit: str = "1"
    note: str = ""

    @property
    def informative(self) -> bool:
        """Is the row shown beside the checks without being one?"""
        return math.isnan(self.tolerance)

    @property
    def passed(self) -> bool:
        """The relative error is finite and within the tolerance (False for an informative row)."""
        return not self.informative and math.isfinite(self.relative_error) and self.relative_error <= self.tolerance

    @property
    def flag(self) -> int:
        """0 failed, 1 passed, 2 informative (:data:`PASSED_MEANINGS`)."""
        return 2 if self.informative else int(self.passed)


def check(quantity: str, published: float, computed: float, tolerance: float, unit: str = "1", note: str = "", error: float | None = None) -> Check:
    """A :class:`Check` whose relative error is |computed - published| / |published| unless ``error`` is given."""
    if error is None:
        error = abs(computed - published) / abs(published) if published != 0.0 else abs(computed)
    return Check(quantity, float(published), float(computed), float(error), float(tolerance), unit, note)


@dataclass(frozen=True, eq=False)
class CaseOutcome:
    """What a validation case found: its rows and the variables of its figure.

    Attributes
    ----------
    case : str
        The case's name.
    checks : tuple of Check
        The rows of the table.
    data : xarray.Dataset
        The case's own variables (the figure's data), with units and long names.
    notes : tuple of str
        Sentences for the page (conventions, approximations, what was run).
    """

    case: str
    checks: tuple[Check, ...]
    data: xr.Dataset = field(default_factory=xr.Dataset)
    notes: tuple[str, ...] = ()

    @property
    def passed(self) -> bool:
        """Every check (not the informative rows) passed."""
        return all(c.passed for c in self.checks if not c.informative)


def outcome_dataset(outcome: CaseOutcome, attrs: dict[str, object]) -> xr.Dataset:
    """The dataset of a validation (module docstring), with ``attrs`` added."""
    rows = outcome.checks
    index = np.arange(len(rows), dtype=np.int32)
    table = xr.Dataset(
        {
            "quantity": ("check", np.array([c.quantity for c in rows], dtype=str), {"long_name": "compared quantity"}),
            "unit": ("check", np.array([c.unit for c in rows], dtype=str), {"long_name": "unit of published and computed (CF)"}),
            "note": ("check", np.array([c.note for c in rows], dtype=str), {"long_name": "where the tolerance comes from, or what the row means"}),
            "published": ("check", np.array([c.published for c in rows], dtype=float), {"long_name": "value of the published closed form (unit: variable 'unit')", "units": "1"}),
            "computed": ("check", np.array([c.computed for c in rows], dtype=float), {"long_name": "value computed by the project's engines and continuation (unit: variable 'unit')", "units": "1"}),
            "relative_error": ("check", np.array([c.relative_error for c in rows], dtype=float), {"long_name": "relative error of computed against published", "units": "1"}),
            "tolerance": ("check", np.array([c.tolerance for c in rows], dtype=float), {"long_name": "largest relative error that passes (NaN: informative row)", "units": "1"}),
            "passed": ("check", np.array([c.flag for c in rows], dtype=np.int8), {
                "long_name": "whether the check passed", "units": "1",
                "flag_values": np.arange(len(PASSED_MEANINGS), dtype=np.int8), "flag_meanings": " ".join(PASSED_MEANINGS)}),
        },  # fmt: skip
        coords={"check": ("check", index, {"long_name": "index of the compared quantity", "units": "1"})},
    )
    merged = xr.merge([table, outcome.data], combine_attrs="override")  # each variable keeps its own attributes
    merged.attrs = dict(outcome.data.attrs)
    merged.attrs.update(attrs)
    merged.attrs["validation_case"] = outcome.case
    merged.attrs["validation_passed"] = np.int8(outcome.passed)
    merged.attrs["validation_notes"] = "\n".join(outcome.notes)
    return merged
