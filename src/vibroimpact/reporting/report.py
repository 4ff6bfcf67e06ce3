"""Comparison report of a study dataset: figures like the paper's 2-8, 16-28 and tables of reduction factors.

``write_report(dataset, out_dir)`` writes PNG figures and a self-contained ``report.html`` (figures embedded as
base64, a table of contents linking every figure and table) into ``out_dir``. Everything is derived from the dataset
and the scene stored in its attributes. The page depends on the scene:

* benchmark scenes: work-precision diagrams and tolerance guidance (:mod:`vibroimpact.accuracy_report`);
* swept-sine tests: running estimates against the steady states (:mod:`vibroimpact.sweep_report`);
* a swept bumper frequency: convergence of the compliant bumper to the rigid stop (:mod:`vibroimpact.bumper_report`);
* otherwise frequency responses, regimes, stability, simulations against the closed form, reduction factors and
  resonance peaks (:mod:`vibroimpact.report_responses`, :mod:`vibroimpact.report_tables`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Iterable, Iterator

import xarray as xr

from vibroimpact.reporting.page import DrawnFigure, Figure, Section, render_page, save_figure, write_page  # selects the Agg backend
from vibroimpact.reporting import accuracy_page as accuracy_report, bumper_page as bumper_report, sweep_page as sweep_report  # noqa: E402
from vibroimpact.reporting.responses import clearance_text, linear_figure, regime_figure, response_figure, simulation_figure, stability_figure  # noqa: E402
from vibroimpact.reporting.tables import agreement_table, modal_table, reduction_intro, reduction_tables  # noqa: E402
from vibroimpact.scene.core import ENGINE_SOLUTIONS, Scene, parse_scene, read_yaml  # noqa: E402

__all__ = ["write_report", "page_sections"]

#: Quantities drawn as frequency responses, in page order.
RESPONSE_QUANTITIES = ("x2_amplitude", "x1_amplitude", "force_amplitude", "suspension_force_amplitude", "impulse")
#: Quantities drawn as simulations against the closed form.
SIMULATION_QUANTITIES = ("x1_amplitude", "x2_amplitude", "force_amplitude", "impulse")
#: Grid dimensions of which a swept-sine page shows the first point.
_SWEEP_PAGE_POINT = ("restitution", "bumper_loss_factor", "clearance", "bumper_frequency")


def write_report(dataset: xr.Dataset, out_dir: str | Path) -> Path:
    """Write the PNG figures and ``report.html`` for ``dataset`` into ``out_dir``; return the HTML path."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    scene = parse_scene(read_yaml(dataset.attrs["scene"]), text=dataset.attrs["scene"])
    sections = page_sections(dataset, scene, out)
    # the scene's solutions: a swept-sine run is not along the dataset's ``solution`` dimension
    contents = f"methods: {', '.join(map(str, dataset['engine'].values))}" if scene.benchmark is not None else f"solutions: {', '.join(scene.solutions)}"
    paragraphs = [scene.description, f"vibroimpact {dataset.attrs.get('vibroimpact_version', '?')}; {contents}."]
    return write_page(out / "report.html", render_page(f"Study '{scene.name}'", paragraphs, sections, scene.text))


def _saved(drawn: Iterable[DrawnFigure | None], out: Path) -> list[Figure]:
    """Write each drawn figure (skipping None) as soon as it comes, so that few are open at once."""
    return [save_figure(figure, out) for figure in drawn if figure is not None]


def page_sections(dataset: xr.Dataset, scene: Scene, out: Path) -> list[Section]:
    """The sections of the page of ``dataset``, their figures written into ``out``."""
    if scene.benchmark is not None:
        return [Section("Work-precision", figures=_saved(accuracy_report.accuracy_figures(dataset), out), tables=accuracy_report.accuracy_tables(dataset))]
    sections = [Section("Linear system", figures=_saved([linear_figure(scene)], out), tables=[modal_table(scene)])]
    if scene.swept_sine is not None:
        first = {d: 0 for d in _SWEEP_PAGE_POINT if d in dataset.dims}
        part = dataset.isel(first)
        intro = f"<p>Figures and tables show the first point of the swept grids ({', '.join(first)}); the dataset holds every point.</p>" if first else ""
        sections.append(Section("Swept sine against the steady states", intro=intro, figures=_saved(sweep_report.sweep_figures(part, scene), out), tables=sweep_report.sweep_tables(part, scene)))
        return sections
    if "bumper_frequency" in dataset.dims:
        sections.append(Section("Compliant bumper against the rigid stop", figures=_saved([bumper_report.stiffness_figure(dataset, scene, "bumper_stiffness")], out), tables=bumper_report.stiffness_tables(dataset, scene)))
        return sections
    # the summary (resonance peaks against the swept parameter) first, then the detail per clearance, then the tables
    engines = [str(s) for s in dataset["solution"].values if s in ENGINE_SOLUTIONS]
    for parameter in ("restitution", "clearance"):
        if parameter in dataset.dims and engines and "x1_amplitude" in dataset:
            figure = bumper_report.peak_figure(dataset, scene, parameter, f"peaks_vs_{parameter}")
            sections.append(Section(f"Resonance peaks against the {parameter}", figures=_saved([figure], out), tables=bumper_report.peak_tables(dataset, scene, parameter)))
    sections += _response_sections(dataset, out)
    agreement = agreement_table(dataset, scene)
    if agreement is not None:
        sections.append(Section("Simulation against the closed form: agreement by band", tables=[agreement]))
    if any(s != "linear" for s in dataset["solution"].values):
        sections.append(Section("Reduction factors", intro=reduction_intro(), tables=reduction_tables(dataset, scene)))
    return sections


def _response_sections(dataset: xr.Dataset, out: Path) -> list[Section]:
    """Per clearance: the frequency responses, regimes, stability and peak contact values, then the simulations."""
    sections = []
    several = "clearance" in dataset.dims
    for index in range(dataset.sizes.get("clearance", 1)):
        part = dataset.isel(clearance=index) if several else dataset
        tag = f"_clearance{index}" if several else ""
        where = f", {clearance_text(part)}"
        sections.append(Section(f"Frequency responses{where}", figures=_saved(_response_figures(part, tag), out)))
        engines = [str(name) for name in part["solution"].values if name in ENGINE_SOLUTIONS]
        if engines:
            simulations = (simulation_figure(part, quantity, engines, f"simulation_{quantity}{tag}") for quantity in SIMULATION_QUANTITIES if quantity in part)
            sections.append(Section(f"Simulations against the closed form{where}", figures=_saved(simulations, out)))
    return sections


def _response_figures(part: xr.Dataset, tag: str) -> Iterator[DrawnFigure | None]:
    """Frequency responses, regime map, stability and peak contact values at one clearance, one at a time."""
    for quantity in RESPONSE_QUANTITIES:
        if quantity in part:
            yield response_figure(part, quantity, f"{quantity}{tag}")
    if "regime" in part:
        yield regime_figure(part, f"regime{tag}")
    if "floquet_modulus" in part and "pgf" in part["solution"].values:
        yield stability_figure(part, f"stability{tag}")
    if "compliant" in part["solution"].values:
        yield bumper_report.peak_acceleration_figure(part, f"peak_acceleration{tag}")
