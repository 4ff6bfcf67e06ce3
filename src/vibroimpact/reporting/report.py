"""Comparison report of a study dataset: figures like the paper's 2-8, 16-28 and tables of reduction factors.

``write_report(dataset, out_dir)`` writes PNG figures and a self-contained ``report.html`` (figures embedded as
base64, a table of contents linking every figure and table) into ``out_dir``. Everything is read from the dataset
itself (:mod:`vibroimpact.reporting.record`), never from a re-validated scene. :func:`page_for` asks the dataset's kind
(:data:`vibroimpact.scene.kinds.KINDS`) for its page; the kinds' pages:

* absorber concepts side by side: the designer's table and figures (:class:`~vibroimpact.kinds.concepts.page.ConceptsPage`);
* validation against published closed forms: published against computed (:class:`~vibroimpact.kinds.validation.page.ValidationPage`);
* benchmark studies: work-precision diagrams and tolerance guidance (:class:`~vibroimpact.kinds.benchmark.page.AccuracyPage`);
* bifurcation studies: diagrams with brute force and continued branches, special points, multipliers and the chart
  (:class:`~vibroimpact.kinds.bifurcation.page.BifurcationPage`);
* swept-sine tests: running estimates against the steady states (:class:`~vibroimpact.kinds.swept.page.SweptSinePage`;
  :class:`~vibroimpact.kinds.swept.page.GeneralSweptPage` for a general scene: every coordinate and stop);
* stepped design maps (attribute ``report_page`` = ``design_map``: restitution x clearance x frequency): which R and
  clearance to choose, peak |X1| per band, realisable regimes, the recommended design
  (:class:`~vibroimpact.kinds.stepped.design_page.DesignMapPage`);
* stepped studies of the paper's layout (:func:`~vibroimpact.reporting.record.named_layout`) with a swept
  bumper frequency: convergence of the compliant bumper to the rigid stop
  (:class:`~vibroimpact.kinds.stepped.page.BumperStiffnessPage`);
* every other stepped study, any structure and stops: one page (:class:`~vibroimpact.kinds.stepped.page.FrequencyResponsePage`)
  whose sections follow what the dataset holds, never how its scene was written: the paper's extras (fit of H22,
  modal parameters, reduction factors, resonance peaks by band) where the structure has the named view, one curve per
  stop where there are several.
"""

from __future__ import annotations

from pathlib import Path

import xarray as xr

from vibroimpact.reporting.page import StudyPage, render_page, rendering, write_page  # selects the Agg backend
from vibroimpact.reporting.record import study_kind, study_record  # noqa: E402
from vibroimpact.scene.kinds import kind_named  # noqa: E402

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
    """The page of ``dataset``: its kind's (:func:`~vibroimpact.reporting.record.study_kind`, the kind's ``page_for``
    in :data:`vibroimpact.scene.kinds.KINDS`)."""
    page: StudyPage = kind_named(study_kind(dataset)).page_for(dataset)
    return page
