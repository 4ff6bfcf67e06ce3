"""The page of a stepped study of a general scene (any structure, load and stops): the structure and its stops in
words, the linear responses of every coordinate and stop, then per clearance and restitution the responses of every
coordinate, the force on the base and the impulse on each stop, the regime map, the closed form's stability, what
the simulated motion is where it is not periodic, and a table of the largest responses."""

from __future__ import annotations

import html
from pathlib import Path

import numpy as np
import xarray as xr

from vibroimpact.reporting.general_figures import layout_tables, peaks_table, response_panels_figure, structure_figure, where_text
from vibroimpact.reporting.general_record import GeneralSetting, general_setting
from vibroimpact.reporting.motion_figure import lyapunov_figure
from vibroimpact.reporting.page import DrawnFigure, Section, saved
from vibroimpact.reporting.responses import regime_figure, stability_figure
from vibroimpact.scene.schema import ENGINE_SOLUTIONS

__all__ = ["GeneralResponsePage"]


class GeneralResponsePage:
    """The page of a general stepped study (dimension ``solution``, swept parameters, ``frequency``, and ``stop``
    where the scene has several stops)."""

    def __init__(self, dataset: xr.Dataset) -> None:
        self.dataset = dataset
        self.setting: GeneralSetting = general_setting(dataset)

    def summary(self) -> str:
        """The solutions and the layout in words."""
        return f"solutions: {', '.join(self.setting.solutions)}; stops: {'; '.join(self.setting.stops)}"

    def sections(self, out: Path) -> list[Section]:
        """Structure and stops, then per clearance and restitution the responses, regimes, stability, motion."""
        dataset, setting = self.dataset, self.setting
        clearances = np.atleast_1d(dataset["clearance"].values) if "clearance" in dataset.coords else np.array([])
        intro = f"<p>Stops: {html.escape('; '.join(setting.stops))}. Load: {html.escape(setting.load_text())}.</p>"
        sections = [Section("Structure and stops", intro=intro, figures=saved([structure_figure(setting, dataset['frequency'].values, clearances)], out), tables=layout_tables(setting))]
        outer = [d for d in ("clearance", "bumper_frequency") if d in dataset.dims]
        for index in np.ndindex(*(dataset.sizes[d] for d in outer)):
            part = dataset.isel(dict(zip(outer, index)))
            tag = "".join(f"_{d}{i}" for d, i in zip(outer, index))
            figures: list[DrawnFigure | None] = []
            for r in range(part.sizes.get("restitution", 1)):
                line = part.isel(restitution=r) if "restitution" in part.dims else part
                figures.append(response_panels_figure(line, setting, f"responses{tag}_r{r}" if "restitution" in part.dims else f"responses{tag}"))
            if "regime" in part:
                figures.append(regime_figure(part, f"regime{tag}"))
            if "floquet_modulus" in part and "pgf" in part["solution"].values and np.isfinite(part["floquet_modulus"].sel(solution="pgf").values).any():
                figures.append(stability_figure(part, f"stability{tag}"))
            engines = [str(s) for s in part["solution"].values if s in ENGINE_SOLUTIONS]
            if engines:
                figures.append(lyapunov_figure(part, engines, f"lyapunov{tag}"))
            sections.append(Section(f"Responses, {where_text(part) if outer else 'every coordinate and stop'}", figures=saved(figures, out)))
        sections.append(Section("Largest responses", tables=[peaks_table(dataset, setting)]))
        return sections
