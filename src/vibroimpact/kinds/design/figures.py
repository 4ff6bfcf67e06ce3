"""Figures of a design study: the compared designs' frequency responses with every closed-form motion and the
certified branches, the distribution of their worst cases over the mistuning samples, and the objective over the
evaluated candidates with the search's path."""

from __future__ import annotations

import numpy as np
import xarray as xr

from vibroimpact.kinds.design.answer import variable_text
from vibroimpact.kinds.design.scene import safe_name
from vibroimpact.reporting.page import DrawnFigure
from vibroimpact.reporting.style import STABLE_STYLE, UNSTABLE_STYLE, Caption, figure_legend, finish_axes, fmt, legend_rows, new_figure

__all__ = ["design_figures", "response_figure", "robustness_figure", "search_figure", "DESIGN_COLOURS"]

#: The compared designs' colours (recommended, the scene's, the linear optimum), colour-blind safe (Okabe-Ito).
DESIGN_COLOURS = ("#0072B2", "#E69F00", "#009E73")
_TITLES = ("recommended design", "the scene's design", "best linear absorber")


def design_figures(dataset: xr.Dataset) -> list[DrawnFigure]:
    """Every figure of the page, in order."""
    return [response_figure(dataset), robustness_figure(dataset), search_figure(dataset)]


def response_figure(dataset: xr.Dataset) -> DrawnFigure:
    """|X1| of each compared design (nominal) against frequency: the contact-free motion (solid where it fits), each
    root's impact orbit (solid stable, dashed unstable) and the continued branches (grey points: stable)."""
    d = dataset
    f = d["response_frequency"].values
    present = [k for k in range(d.sizes["design"]) if np.any(np.isfinite(d["response_linear"].values[k]))]
    caption = Caption("|X1| (fundamental amplitude of the primary mass) of each compared design without mistuning, in mm on a log scale.")
    fig, axes = new_figure(len(present), panel_height=3.3, legend_rows=legend_rows(5))
    for ax, k in zip(axes, present):
        colour = DESIGN_COLOURS[k]
        linear = d["response_linear"].values[k] * 1e3
        fits = d["response_linear_fits"].values[k] == 1
        ax.plot(f, np.where(fits, linear, np.nan), color=colour, **STABLE_STYLE, label="contact-free motion (clears the stop)")
        ax.plot(f, np.where(~fits, linear, np.nan), color="0.6", lw=0.8, ls=":", label="contact-free motion that would cross the stop")
        for name in ("impact_plus", "impact_minus"):
            x = d[f"response_{name}"].values[k] * 1e3
            state = d[f"response_{name}_stable"].values[k]
            ax.plot(f, np.where(state == 1, x, np.nan), color=colour, lw=2.2, label="impact orbit, stable")
            ax.plot(f, np.where(state == 0, x, np.nan), color=colour, **UNSTABLE_STYLE, label="impact orbit, unstable")
        rows = np.flatnonzero((d["certificate_evaluation"].values == _evaluation(d, k)) & (d["certificate_sample"].values == 0)) if k < 2 else []
        for r in rows:
            bf, ba, bs = (d[f"branch_{n}"].values[r] for n in ("frequency", "amplitude", "stable"))
            ax.plot(bf[bs == 1], ba[bs == 1] * 1e3, ".", color="0.25", ms=2.0, label="continued branch, stable")
            worst, where = float(d["certificate_worst"].values[r]), float(d["certificate_frequency"].values[r])
            ax.plot([where], [worst * 1e3], marker="*", ms=12, color="#D55E00", ls="none", label="certified worst case")
        ax.set_xlim(float(f[0]), float(f[-1]))
        finish_axes(ax, "excitation frequency [Hz]", "|X1| [mm]", f"{_TITLES[k]}: {variable_text(d, k) or 'no stop'}", log=True)
    caption.add("lines", "Solid coloured lines are stable motions, dashed unstable ones; the dotted grey line is the contact-free motion where it would cross the stop (not a motion).")
    caption.add("branches", "Grey dots: stable orbits of the branches continued from the closed-form ones; the red star is the certified worst case.")
    figure_legend(fig, axes, columns=3)
    return DrawnFigure(fig, "design_response", "The compared designs' responses", caption.text())


def _evaluation(d: xr.Dataset, k: int) -> int:
    return int(d.attrs.get("recommended_evaluation", -1)) if k == 0 else 0


def robustness_figure(dataset: xr.Dataset) -> DrawnFigure:
    """The worst case of each compared design under every mistuning sample, sorted (an empirical distribution)."""
    d = dataset
    caption = Caption("Largest stable |X1| over the band of each compared design under each mistuning sample, sorted from least to largest (the nominal design is one of them).")
    fig, axes = new_figure(1, panel_height=3.6, legend_rows=legend_rows(3))
    ax = axes[0]
    values = d["design_sample_value"].values * 1e3
    for k in range(values.shape[0]):
        row = np.sort(values[k][np.isfinite(values[k])])
        if row.size:
            share = (np.arange(row.size) + 1) / row.size
            ax.step(row, share, where="post", color=DESIGN_COLOURS[k], lw=2.0, label=f"{_TITLES[k]} (worst {fmt(row[-1], '.3g')} mm)")
    finish_axes(ax, "worst case |X1| over the band [mm]", "share of samples at or below", "Robustness: worst case over the mistuning samples")
    figure_legend(fig, axes, columns=3)
    return DrawnFigure(fig, "design_robustness", "Worst case under mistuning", caption.text())


def search_figure(dataset: xr.Dataset) -> DrawnFigure:
    """The objective of every evaluated candidate over the first two variables (colour: objective; ring: the
    recommended design), or over the one variable."""
    d = dataset
    names = [n for n in str(d.attrs.get("variables", "")).split(", ") if n]
    score = d["objective"].values * 1e3
    recommended = int(d.attrs.get("recommended_evaluation", -1))
    caption = Caption("Every candidate the search evaluated: its worst case over the band and the samples (colour, mm).")
    fig, axes = new_figure(1, panel_height=4.2, legend_rows=legend_rows(2))
    ax = axes[0]
    x = d[f"variable_{safe_name(names[0])}"].values
    if len(names) > 1:
        y = d[f"variable_{safe_name(names[1])}"].values
        finite = np.isfinite(score)
        scatter = ax.scatter(x[finite], y[finite], c=score[finite], s=12, cmap="viridis", vmax=float(np.nanpercentile(score, 90)), label="candidate")
        fig.colorbar(scatter, ax=ax, label="worst case |X1| [mm]")
        if recommended >= 0:
            ax.plot([x[recommended]], [y[recommended]], "o", mfc="none", mec="#D55E00", ms=14, mew=2.0, label="recommended")
        finish_axes(ax, f"{names[0]} [{d[f'variable_{safe_name(names[0])}'].attrs.get('units')}]", f"{names[1]} [{d[f'variable_{safe_name(names[1])}'].attrs.get('units')}]", "The search: candidates over the first two variables")
        caption.add("colour", "The colour scale stops at the 90th percentile, so that the good region is resolved; worse candidates share its top colour.")
    else:
        ax.plot(x, score, ".", color=DESIGN_COLOURS[0], label="candidate")
        if recommended >= 0:
            ax.plot([x[recommended]], [score[recommended]], "o", mfc="none", mec="#D55E00", ms=14, mew=2.0, label="recommended")
        finish_axes(ax, names[0], "worst case |X1| [mm]", "The search", log=True)
    figure_legend(fig, axes, columns=2)
    return DrawnFigure(fig, "design_search", "The search", caption.text())
