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
from vibroimpact.reporting.style import fmt
from vibroimpact.scene.schema import ENGINE_SOLUTIONS

__all__ = ["GeneralResponsePage", "unswept_restitution"]

#: The row, series or panel label the shared figures give a layout whose stops have their own R.
_OWN_R = "each stop's R"
#: Caption phrases of the shared figures that assume a swept R, and what they say where it is not swept.
_SWEPT_R_WORDS = {": one panel per restitution ratio, ": ": ", "), one colour per restitution ratio. ": "). "}


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
        intro = f"<p>Stops: {html.escape('; '.join(setting.stops))}. Load: {html.escape(setting.load_text())}.</p>"
        sections = [Section("Structure and stops", intro=intro, figures=saved([structure_figure(setting, dataset['frequency'].values)], out), tables=layout_tables(setting))]
        outer = [d for d in ("clearance", "bumper_frequency") if d in dataset.dims]
        for index in np.ndindex(*(dataset.sizes[d] for d in outer)):
            part = dataset.isel(dict(zip(outer, index)))
            tag = "".join(f"_{d}{i}" for d, i in zip(outer, index))
            figures: list[DrawnFigure | None] = []
            for r in range(part.sizes.get("restitution", 1)):
                line = part.isel(restitution=r) if "restitution" in part.dims else part
                figures.append(response_panels_figure(line, setting, f"responses{tag}_r{r}" if "restitution" in part.dims else f"responses{tag}"))
            if "regime" in part:
                figures.append(unswept_restitution(regime_figure(part, f"regime{tag}"), part))
            if "floquet_modulus" in part and "pgf" in part["solution"].values and np.isfinite(part["floquet_modulus"].sel(solution="pgf").values).any():
                figures.append(unswept_restitution(stability_figure(part, f"stability{tag}"), part))
            engines = [str(s) for s in part["solution"].values if s in ENGINE_SOLUTIONS]
            if engines:
                figures.append(unswept_restitution(lyapunov_figure(part, engines, f"lyapunov{tag}"), part))
            sections.append(Section(f"Responses, {where_text(part) if outer else 'every coordinate and stop'}", figures=saved(figures, out)))
        sections.append(Section("Largest responses", tables=[peaks_table(dataset, setting)]))
        return sections
