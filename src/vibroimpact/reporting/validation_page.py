"""The page of a validation study: the table of published against computed values, and the case's figure.

Everything is read from the dataset (:mod:`vibroimpact.study.validation_checks` describes it): the rows of the
``check`` dimension make the table (quantity, published, computed, relative error, tolerance, pass), the attributes
``validation_case``, ``validation_source`` and ``validation_notes`` the introduction, and the case's own variables
its figure (:mod:`vibroimpact.reporting.validation_figures`).
"""

from __future__ import annotations

import html
import math
from pathlib import Path

import numpy as np
import xarray as xr

from vibroimpact.reporting.page import Section, Table, render_page, saved, write_page
from vibroimpact.reporting.record import stored_description
from vibroimpact.reporting.validation_figures import validation_figure

__all__ = ["ValidationPage", "validation_table", "write_validation_report"]

#: What each flag of ``passed`` shows.
_VERDICT = {0: "<b style='color:#b00'>fail</b>", 1: "<span style='color:#070'>pass</span>", 2: "<span style='color:#777'>shown only</span>"}


def _number(value: float) -> str:
    """A table cell: 12 significant digits, empty for NaN."""
    return "" if not math.isfinite(value) else f"{value:.12g}"


def _error(value: float) -> str:
    return "" if not math.isfinite(value) else f"{value:.2e}"


def validation_table(dataset: xr.Dataset) -> Table:
    """The table of every compared quantity."""
    header = "".join(f"<th>{column}</th>" for column in ("quantity", "published", "computed", "unit", "relative error", "tolerance", "pass", "note"))
    rows = []
    for i in range(dataset.sizes["check"]):
        row = dataset.isel(check=i)
        cells = (
            html.escape(str(row["quantity"].values)),
            _number(float(row["published"])),
            _number(float(row["computed"])),
            html.escape(str(row["unit"].values)),
            _error(float(row["relative_error"])),
            _error(float(row["tolerance"])),
            _VERDICT.get(int(row["passed"]), "?"),
            html.escape(str(row["note"].values)),
        )
        wrap = "style='white-space:normal;text-align:left;min-width:{}em'"
        rows.append(f"<tr><td {wrap.format(16)}>{cells[0]}</td>" + "".join(f"<td>{cell}</td>" for cell in cells[1:-1]) + f"<td {wrap.format(18)}>{cells[-1]}</td></tr>")
    return Table("Published against computed", f"<table><tr>{header}</tr>{''.join(rows)}</table>")


class ValidationPage:
    """The page of a ``validation`` dataset."""

    def __init__(self, dataset: xr.Dataset) -> None:
        self.dataset = dataset
        self.case = str(dataset.attrs.get("validation_case", "?"))

    def counts(self) -> tuple[int, int]:
        """(checks passed, checks) without the informative rows."""
        flags = np.asarray(self.dataset["passed"].values, dtype=int)
        return int(np.sum(flags == 1)), int(np.sum(flags != 2))

    def summary(self) -> str:
        """``validation case <name>: k of n checks passed``."""
        passed, total = self.counts()
        return f"validation case {self.case}: {passed} of {total} checks passed"

    def sections(self, out: Path) -> list[Section]:
        """The table (with the source and notes) and the case's figure."""
        attrs = self.dataset.attrs
        passed, total = self.counts()
        verdict = "every check passed" if passed == total else f"{total - passed} of {total} checks FAILED"
        notes = [line for line in str(attrs.get("validation_notes", "")).split("\n") if line]
        intro = (
            f"<p>Source: {html.escape(str(attrs.get('validation_source', '')))}. <b>{html.escape(verdict)}</b>.</p>"
            + "".join(f"<p>{html.escape(note)}</p>" for note in notes)
        )
        figures = saved([validation_figure(self.dataset)], out)
        return [Section("Agreement with the published closed form", intro, [], [validation_table(self.dataset)]), Section("Figure", "", figures, [])]


def write_validation_report(dataset: xr.Dataset, out_dir: str | Path) -> Path:
    """``report.html`` of a validation dataset in ``out_dir`` (what :func:`vibroimpact.reporting.report.write_report`
    writes for it, in this process); return its path."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    page = ValidationPage(dataset)
    text = str(dataset.attrs.get("scene", ""))
    paragraphs = [stored_description(text), f"vibroimpact {dataset.attrs.get('vibroimpact_version', '?')}; {page.summary()}."]
    return write_page(out / "report.html", render_page(f"Study '{dataset.attrs.get('scene_name', '')}'", paragraphs, page.sections(out), text))
