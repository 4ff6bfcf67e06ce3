"""Page of stepped studies (paper figures 2-8, 21-26): frequency responses, regimes, stability, simulations against
the closed form, resonance peaks against a swept parameter, agreement by band and reduction factors.

The summary (resonance peaks against the swept parameter) comes first, then the detail per clearance, then the
tables.
"""

from __future__ import annotations

from pathlib import Path
from typing import Iterator

import xarray as xr

from vibroimpact.reporting.bumper_page import peak_acceleration_figure, peak_figure, peak_tables
from vibroimpact.reporting.motion_figure import lyapunov_figure
from vibroimpact.reporting.page import DrawnFigure, Section, saved
from vibroimpact.reporting.responses import SolutionsPage, clearance_text, linear_section, regime_figure, response_figure, simulation_figure, stability_figure
from vibroimpact.reporting.tables import agreement_table, reduction_intro, reduction_tables
from vibroimpact.scene.schema import ENGINE_SOLUTIONS

__all__ = ["FrequencyResponsePage", "RESPONSE_QUANTITIES", "SIMULATION_QUANTITIES"]

#: Quantities drawn as frequency responses, in page order.
RESPONSE_QUANTITIES = ("x2_amplitude", "x1_amplitude", "force_amplitude", "suspension_force_amplitude", "impulse")
#: Quantities drawn as simulations against the closed form.
SIMULATION_QUANTITIES = ("x1_amplitude", "x2_amplitude", "force_amplitude", "impulse")
#: Swept parameters whose resonance peaks get a figure of their own.
PEAK_PARAMETERS = ("restitution", "clearance")


class FrequencyResponsePage(SolutionsPage):
    """The page of a stepped study of steady states along frequency (dimension ``solution``, swept parameters,
    ``frequency``)."""

    def sections(self, out: Path) -> list[Section]:
        """Linear system, resonance peaks, per clearance the responses and simulations, agreement, reduction factors."""
        dataset, setting = self.dataset, self.setting
        sections = [linear_section(setting, out)]
        engines = [str(s) for s in dataset["solution"].values if s in ENGINE_SOLUTIONS]
        for parameter in PEAK_PARAMETERS:
            if parameter in dataset.dims and engines and "x1_amplitude" in dataset:
                figure = peak_figure(dataset, setting, parameter, f"peaks_vs_{parameter}")
                sections.append(Section(f"Resonance peaks against the {parameter}", figures=saved([figure], out), tables=peak_tables(dataset, setting, parameter)))
        sections += _response_sections(dataset, out)
        agreement = agreement_table(dataset, setting)
        if agreement is not None:
            sections.append(Section("Simulation against the closed form: agreement by band", tables=[agreement]))
        if any(s != "linear" for s in dataset["solution"].values):
            sections.append(Section("Reduction factors", intro=reduction_intro(), tables=reduction_tables(dataset, setting)))
        return sections


def _response_sections(dataset: xr.Dataset, out: Path) -> list[Section]:
    """Per clearance: the frequency responses, regimes, stability and peak contact values, then the simulations."""
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
