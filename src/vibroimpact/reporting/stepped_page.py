"""The page of a stepped study (paper figures 2-8, 21-26 and any layout's responses), chosen by what its dataset holds,
never by how its scene was written.

First the answer (the largest responses of every solution, against the linear system's), then the linear system
(every coordinate, each stop's coordinate against its gap, the force on the base; the structure, stops and load in
tables), then the detail per clearance, then the tables. Where the structure has the named view (the paper's two-mass
chain: ``system_m1`` ... ``system_b2``) the paper's extras join: the fit of H22 and the modal table, resonance peaks
against a swept parameter, the agreement by band and the reduction factors, both bands split at the anti-resonance.
With one stop on the named view the responses are the paper's figures (one figure per quantity, one panel per
solution, one colour per restitution ratio); with several stops, or another structure, one figure per restitution
ratio with a panel per coordinate, the force on the base and the impulse on each stop.
"""

from __future__ import annotations

import html
from pathlib import Path
from typing import Iterator

import numpy as np
import xarray as xr

from vibroimpact.reporting.bumper_page import peak_acceleration_figure, peak_figure, peak_tables
from vibroimpact.reporting.general_figures import layout_tables, peaks_table, response_panels_figure, structure_figure, where_text
from vibroimpact.reporting.general_record import GeneralSetting, general_setting, named_layout
from vibroimpact.reporting.motion_figure import lyapunov_figure
from vibroimpact.reporting.page import DrawnFigure, Section, saved
from vibroimpact.reporting.record import StudySetting, study_setting
from vibroimpact.reporting.responses import clearance_text, regime_figure, response_figure, simulation_figure, stability_figure
from vibroimpact.reporting.style import fmt
from vibroimpact.reporting.tables import agreement_table, modal_table, reduction_intro, reduction_tables
from vibroimpact.scene.schema import ENGINE_SOLUTIONS

__all__ = ["FrequencyResponsePage", "RESPONSE_QUANTITIES", "SIMULATION_QUANTITIES", "unswept_restitution", "answer_text"]

#: Quantities drawn as frequency responses, in page order.
RESPONSE_QUANTITIES = ("x2_amplitude", "x1_amplitude", "force_amplitude", "suspension_force_amplitude", "impulse")
#: Quantities drawn as simulations against the closed form.
SIMULATION_QUANTITIES = ("x1_amplitude", "x2_amplitude", "force_amplitude", "impulse")
#: Swept parameters whose resonance peaks get a figure of their own.
PEAK_PARAMETERS = ("restitution", "clearance")
#: The row, series or panel label the shared figures give a layout whose stops have their own R.
_OWN_R = "each stop's R"
#: Caption phrases of the shared figures that assume a swept R, and what they say where it is not swept.
_SWEPT_R_WORDS = {": one panel per restitution ratio, ": ": ", "), one colour per restitution ratio. ": "). "}


class FrequencyResponsePage:
    """The page of a stepped study of steady states along frequency (dimension ``solution``, swept parameters,
    ``frequency``, and ``stop`` where the layout has several stops)."""

    def __init__(self, dataset: xr.Dataset) -> None:
        self.dataset = dataset
        self.layout: GeneralSetting = general_setting(dataset)
        #: the paper's view of the study, where its structure has the named view (its extras need it)
        self.setting: StudySetting | None = study_setting(dataset) if self.layout.named is not None else None

    def summary(self) -> str:
        """The solutions and the stops in words."""
        return f"solutions: {', '.join(self.layout.solutions)}; stops: {'; '.join(self.layout.stops)}"

    def sections(self, out: Path) -> list[Section]:
        """The answer, the linear system, resonance peaks, per clearance the responses and simulations, agreement,
        reduction factors."""
        dataset, layout, setting = self.dataset, self.layout, self.setting
        sections = [Section("Largest responses", intro=f"<p>{html.escape(answer_text(dataset, layout))}</p>", tables=[peaks_table(dataset, layout)])]
        intro = f"<p>Stops: {html.escape('; '.join(layout.stops))}. Load: {html.escape(layout.load_text())}.</p>"
        tables = ([modal_table(layout.named)] if layout.named is not None else []) + layout_tables(layout)
        sections.append(Section("Linear system", intro=intro, figures=saved([structure_figure(layout, dataset["frequency"].values)], out), tables=tables))
        engines = [str(s) for s in dataset["solution"].values if s in ENGINE_SOLUTIONS]
        if setting is not None and "x1_amplitude" in dataset and engines:
            for parameter in PEAK_PARAMETERS:
                if parameter in dataset.dims:
                    figure = peak_figure(dataset, setting, parameter, f"peaks_vs_{parameter}")
                    sections.append(Section(f"Resonance peaks against the {parameter}", figures=saved([figure], out), tables=peak_tables(dataset, setting, parameter)))
        if setting is not None and "stop" not in dataset.dims:
            sections += _paper_response_sections(dataset, out)
        else:
            sections += _panel_sections(dataset, layout, out)
        if setting is not None:
            agreement = agreement_table(dataset, setting.split_frequency)
            if agreement is not None:
                sections.append(Section("Simulation against the closed form: agreement by band", tables=[agreement]))
            if any(s != "linear" for s in dataset["solution"].values):
                sections.append(Section("Reduction factors", intro=reduction_intro(), tables=reduction_tables(dataset, layout, named_layout(dataset) is not None)))
        return sections


def answer_text(dataset: xr.Dataset, layout: GeneralSetting) -> str:
    """The largest fundamental of the first coordinate of every solution over the frequencies it computed (the
    largest over the swept parameters, and where), against the linear system's: the page's answer in one sentence."""
    quantity = f"{layout.names[0]}_amplitude"
    if quantity not in dataset:
        return "The largest value of each response over the frequencies every solution computed, and where it occurs."
    f = dataset["frequency"].values
    parts = []
    for solution in (str(s) for s in dataset["solution"].values):
        data = dataset[quantity].sel(solution=solution)
        values = np.asarray(data.values, dtype=float)
        if not np.isfinite(values).any():
            continue
        index = np.unravel_index(int(np.nanargmax(values)), values.shape)
        at = {dim: data[dim].values[i] for dim, i in zip(data.dims, index)}
        where = [f"{fmt(float(f[index[data.dims.index('frequency')]]), '.4g')} Hz"]
        where += [f"{'R' if dim == 'restitution' else dim} = {fmt(float(at[dim]) * (1e3 if dim == 'clearance' else 1.0), 'g')}{' mm' if dim == 'clearance' else ''}" for dim in data.dims if dim not in ("frequency", "stop") and solution != "linear"]
        label = "linear system (no stop)" if solution == "linear" else solution
        parts.append(f"{label} {fmt(float(values[index]) * 1e3, '.4g')} mm at {', '.join(where)}")
    return f"Largest |{layout.names[0]}| over the frequencies each solution computed: " + "; ".join(parts) + ". The table gives every response per solution and swept value."


def _paper_response_sections(dataset: xr.Dataset, out: Path) -> list[Section]:
    """Per clearance: the frequency responses, regimes, stability and peak contact values, then the simulations (one
    stop on the named view: the paper's figures 5-8 and 21-24)."""
    sections = []
    several = "clearance" in dataset.dims
    for index in range(dataset.sizes.get("clearance", 1)):
        part = dataset.isel(clearance=index) if several else dataset
        tag = f"_clearance{index}" if several else ""
        where = f", {clearance_text(part)}"
        sections.append(Section(f"Frequency responses{where}", figures=saved(_response_figures(part, tag), out)))
        engines = [str(name) for name in part["solution"].values if name in ENGINE_SOLUTIONS]
        if engines:
            simulations = [simulation_figure(part, quantity, engines, f"simulation_{quantity}{tag}") for quantity in SIMULATION_QUANTITIES if quantity in part]
            sections.append(Section(f"Simulations against the closed form{where}", figures=saved(simulations + [lyapunov_figure(part, engines, f"lyapunov{tag}")], out)))
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
        yield peak_acceleration_figure(part, f"peak_acceleration{tag}")


def _panel_sections(dataset: xr.Dataset, layout: GeneralSetting, out: Path) -> list[Section]:
    """Per clearance and bumper: per restitution ratio one panel per coordinate, the force on the base and each
    stop's impulse; the regime map, the closed form's stability, what the simulated motion is."""
    sections = []
    outer = [d for d in ("clearance", "bumper_frequency") if d in dataset.dims]
    for index in np.ndindex(*(dataset.sizes[d] for d in outer)):
        part = dataset.isel(dict(zip(outer, index)))
        tag = "".join(f"_{d}{i}" for d, i in zip(outer, index))
        figures: list[DrawnFigure | None] = []
        for r in range(part.sizes.get("restitution", 1)):
            line = part.isel(restitution=r) if "restitution" in part.dims else part
            figures.append(response_panels_figure(line, layout, f"responses{tag}_r{r}" if "restitution" in part.dims else f"responses{tag}"))
        if "regime" in part:
            figures.append(unswept_restitution(regime_figure(part, f"regime{tag}"), part))
        if "floquet_modulus" in part and "pgf" in part["solution"].values and np.isfinite(part["floquet_modulus"].sel(solution="pgf").values).any():
            figures.append(unswept_restitution(stability_figure(part, f"stability{tag}"), part))
        engines = [str(s) for s in part["solution"].values if s in ENGINE_SOLUTIONS]
        if engines:
            figures.append(unswept_restitution(lyapunov_figure(part, engines, f"lyapunov{tag}"), part))
        sections.append(Section(f"Responses, {where_text(part) if outer else 'every coordinate and stop'}", figures=saved(figures, out)))
    return sections


def unswept_restitution(drawn: DrawnFigure | None, part: xr.Dataset) -> DrawnFigure | None:
    """Where ``part`` does not sweep R, the shared regime, stability and Lyapunov figures' wording of one series per
    restitution ratio becomes what was drawn: a single series, labelled by R only where one R is shared."""
    if drawn is None or "restitution" in part.dims:
        return drawn
    shared = f"R = {fmt(float(part['restitution']), 'g')}" if "restitution" in part.coords else None
    for ax in drawn.figure.axes:
        if ax.get_title() == _OWN_R:
            ax.set_title(shared or "every simulated point")
        ticks = [t.get_text() for t in ax.get_yticklabels()]
        if _OWN_R in ticks:
            ax.set_yticks(ax.get_yticks(), [(shared or "") if t == _OWN_R else t for t in ticks])
    for legend in drawn.figure.legends:
        for text in legend.get_texts():
            if text.get_text() == _OWN_R:
                text.set_text(shared or "largest modulus")
    caption = drawn.caption
    for swept, single in _SWEPT_R_WORDS.items():
        caption = caption.replace(swept, single)
    return DrawnFigure(drawn.figure, drawn.name, drawn.title, caption)
