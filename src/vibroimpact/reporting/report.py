"""Comparison report of a study dataset: figures like the paper's 2-8, 16-28 and tables of reduction factors.

``write_report(dataset, out_dir)`` writes PNG figures and a self-contained ``report.html`` (figures embedded as
base64, a table of contents linking every figure and table) into ``out_dir``. Everything is read from the dataset
itself (:mod:`vibroimpact.reporting.record`), never from a re-validated scene. :func:`page_for` chooses the page by
the kind of study, in this one place:

* absorber concepts side by side: the designer's table and figures (:class:`~vibroimpact.reporting.concepts_page.ConceptsPage`);
* validation against published closed forms: published against computed (:class:`~vibroimpact.reporting.validation_page.ValidationPage`);
* benchmark studies: work-precision diagrams and tolerance guidance (:class:`~vibroimpact.reporting.accuracy_page.AccuracyPage`);
* bifurcation studies: diagrams with brute force and continued branches, special points, multipliers and the chart
  (:class:`~vibroimpact.reporting.bifurcation_page.BifurcationPage`);
* swept-sine tests: running estimates against the steady states (:class:`~vibroimpact.reporting.sweep_page.SweptSinePage`;
  :class:`~vibroimpact.reporting.sweep_page.GeneralSweptPage` for a general scene: every coordinate and stop);
* stepped design maps (attribute ``report_page`` = ``design_map``: restitution x clearance x frequency): which R and
  clearance to choose, peak |X1| per band, realisable regimes, the recommended design
  (:class:`~vibroimpact.reporting.design_page.DesignMapPage`);
* stepped studies of the paper's layout (:func:`~vibroimpact.reporting.general_record.named_layout`) with a swept
  bumper frequency: convergence of the compliant bumper to the rigid stop
  (:class:`~vibroimpact.reporting.bumper_page.BumperStiffnessPage`);
* every other stepped study, any structure and stops: one page (:class:`~vibroimpact.reporting.stepped_page.FrequencyResponsePage`)
  whose sections follow what the dataset holds, never how its scene was written: the paper's extras (fit of H22,
  modal parameters, reduction factors, resonance peaks by band) where the structure has the named view, one curve per
  stop where there are several.
"""

from __future__ import annotations

from pathlib import Path

import xarray as xr

from vibroimpact.reporting.page import StudyPage, render_page, rendering, write_page  # selects the Agg backend
from vibroimpact.reporting.accuracy_page import AccuracyPage  # noqa: E402
from vibroimpact.reporting.bifurcation_page import BifurcationPage  # noqa: E402
from vibroimpact.reporting.concepts_page import ConceptsPage  # noqa: E402
from vibroimpact.reporting.design_page import DesignMapPage  # noqa: E402
from vibroimpact.reporting.validation_page import ValidationPage  # noqa: E402
from vibroimpact.reporting.bumper_page import BumperStiffnessPage  # noqa: E402
from vibroimpact.reporting.general_record import is_general, named_layout  # noqa: E402
from vibroimpact.reporting.record import study_kind, study_record, study_setting  # noqa: E402
from vibroimpact.reporting.stepped_page import FrequencyResponsePage  # noqa: E402
from vibroimpact.reporting.sweep_page import GeneralSweptPage, SweptSinePage  # noqa: E402

__all__ = ["write_report", "page_for"]


def write_report(dataset: xr.Dataset, out_dir: str | Path, jobs: int = 1) -> Path:
    """Write the PNG figures and ``report.html`` for ``dataset`` into ``out_dir``, rendering the figures in ``jobs``
    processes; return the HTML path."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    record = study_record(dataset)
    page = page_for(dataset)
    with rendering(jobs):
        sections = page.sections(out)
    paragraphs = [record.description, f"vibroimpact {record.version}; {page.summary()}."]
    return write_page(out / "report.html", render_page(f"Study '{record.name}'", paragraphs, sections, record.scene_text))


def page_for(dataset: xr.Dataset) -> StudyPage:
    """The page of ``dataset``, chosen by its kind of study (:func:`~vibroimpact.reporting.record.study_kind`)."""
    kind = study_kind(dataset)
    if kind == "benchmark":
        return AccuracyPage(dataset)
    if kind == "concepts":
        return ConceptsPage(dataset)
    if kind == "validation":
        return ValidationPage(dataset)
    if kind == "bifurcation":
        return BifurcationPage(dataset)
    if kind == "stepped" and dataset.attrs.get("report_page") == "design_map":
        return DesignMapPage(dataset)
    if kind == "swept" and is_general(dataset):
        return GeneralSweptPage(dataset)
    if kind == "swept":
        return SweptSinePage(dataset, study_setting(dataset))
    if "bumper_frequency" in dataset.dims and named_layout(dataset) is not None:
        return BumperStiffnessPage(dataset, study_setting(dataset))
    return FrequencyResponsePage(dataset)
