"""The page of a design study: which absorber and stop to build, answered first, with what it was compared with and
what was not checked; then the figures (:mod:`vibroimpact.kinds.design.figures`). Everything is read from the
dataset."""

from __future__ import annotations

import html
from pathlib import Path

import xarray as xr

from vibroimpact.kinds.design.answer import answer_text, warnings
from vibroimpact.kinds.design.figures import design_figures
from vibroimpact.reporting.page import Section, saved

__all__ = ["DesignPage", "page_for"]


class DesignPage:
    """The page of a ``design`` dataset."""

    def __init__(self, dataset: xr.Dataset) -> None:
        self.dataset = dataset

    def summary(self) -> str:
        """What was computed, for the page's heading."""
        d = self.dataset
        return (f"{d.sizes['evaluation']} candidate designs ({d.attrs.get('search_method', '?')} over {d.attrs.get('variables', '?')}), each under "
                f"{d.sizes['sample']} mistuning samples (the nominal design included); {d.sizes['certificate']} problems certified by continuation")  # fmt: skip

    def sections(self, out: Path) -> list[Section]:
        """The answer, the warnings, the figures."""
        d = self.dataset
        items = "".join(f"<li>{html.escape(w)}</li>" for w in warnings(d))
        first = Section("Which design to build", f"<p><b>{html.escape(answer_text(d))}</b></p>" + (f"<p>Before you build it:</p><ul>{items}</ul>" if items else ""))
        return [first, Section("Figures", "", figures=saved(design_figures(d), out))]


def page_for(dataset: xr.Dataset) -> DesignPage:
    """The page of a design dataset."""
    return DesignPage(dataset)
