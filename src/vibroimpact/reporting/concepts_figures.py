"""Figures of a concepts study: |X1| of each concept with its stable and unstable orbits, every concept's worst stable
response and base force side by side, and what the impacts cost (bumper acceleration and force, impulse).

One colour per concept in every figure (:func:`concept_colour`); the anti-resonance band is shaded and the static
deflection q / k1 drawn in every |X1| panel. Captions say what was drawn, from the dataset.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.ticker import FormatStrFormatter, LogFormatter

from vibroimpact.reporting.page import DrawnFigure
from vibroimpact.reporting.style import LINEAR_STYLE, STABLE_STYLE, UNSTABLE_STYLE, Caption, figure_legend, fmt, new_figure
from vibroimpact.reporting.style import finish_axes, legend_rows

__all__ = ["concept_colour", "response_figure", "overview_figure", "impact_figure"]

_BAND = {"color": "#fff2b3", "zorder": 0}
_STATIC = {"color": "0.45", "ls": (0, (1, 2)), "lw": 1.0}
_BRANCH = {"color": "0.2", "lw": 0.9}
FREQUENCY = "excitation frequency [Hz]"


def concept_colour(index: int) -> str:
    """The colour of concept ``index`` (ten distinct colours; concepts beyond reuse them)."""
    return ("#1b9e77", "#7570b3", "#d95f02", "#e7298a", "#1f78b4", "#66a61e", "#e6ab02", "#a6761d", "#666666", "#17becf")[index % 10]


def _band(ax: Axes, dataset: xr.Dataset, static: bool = True) -> None:
    low, high = float(dataset.attrs.get("band_low_Hz", math.nan)), float(dataset.attrs.get("band_high_Hz", math.nan))
    if math.isfinite(low) and math.isfinite(high):
        ax.axvspan(low, high, **_BAND)
    if static:
        ax.axhline(1e3 * float(dataset.attrs["static_deflection_m"]), **_STATIC)


def _isolated(y: np.ndarray) -> np.ndarray:
    """Finite values whose neighbours are both missing: a line does not show them, a marker must."""
    finite = np.isfinite(y)
    before = np.concatenate([[False], finite[:-1]])
    after = np.concatenate([finite[1:], [False]])
    return finite & ~before & ~after


class PlainLogFormatter(LogFormatter):
    """matplotlib's log-axis labels (its choice of which minor ticks to label) written as plain numbers: 0.2, 3."""

    def _num_to_string(self, x: float, vmin: float, vmax: float) -> str:
        return f"{x:g}"


def _plain_ticks(ax: Axes) -> None:
    """Plain numbers on a log axis (0.5, 1, 2 rather than 5 x 10^-1); a few minor ticks labelled when the axis spans
    about a decade or less (matplotlib's thinning)."""
    ax.yaxis.set_major_formatter(FormatStrFormatter("%g"))
    ax.yaxis.set_minor_formatter(PlainLogFormatter(labelOnlyBase=False, minor_thresholds=(1.0, 0.5)))


def _split(x: np.ndarray, y: np.ndarray, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """x, y with NaN where ``mask`` is False (a broken line)."""
    return x, np.where(mask, y, np.nan)


def response_figure(dataset: xr.Dataset) -> DrawnFigure:
    """|X1| against frequency, one panel per concept: the worst stable response (wide band), the closed-form impact
    orbit (stable solid, unstable dashed), the continued branches, the simulated steady states and the linear motion
    without the stop."""
    names = [str(n) for n in dataset["concept"].values]
    f = dataset["frequency"].values
    fs = dataset["simulation_frequency"].values
    caption = Caption("|X1| (fundamental amplitude of the primary mass) against frequency, one panel per concept, in mm on a log scale.")
    fig, axes = new_figure(len(names), panel_height=3.3, legend_rows=legend_rows(7))
    for i, (ax, name) in enumerate(zip(axes, names)):
        colour = concept_colour(i)
        _band(ax, dataset)
        worst = dataset["worst_x1_amplitude"].values[i] * 1e3
        ax.plot(f, worst, color=colour, lw=5.0, alpha=0.25, solid_capstyle="butt", label="worst stable motion (the table's)")
        has_stop = str(dataset["stops"].values[i]) != "no stop"
        linear = dataset["linear_x1_amplitude"].values[i] * 1e3
        if has_stop:
            ax.plot(f, linear, **LINEAR_STYLE, label="linear, without the stop")
            caption.add("linear", "The dotted black curve is the same absorber without its stop.")
        else:
            ax.plot(f, linear, color=colour, **STABLE_STYLE, label="closed form: linear (stable)")
        closed = dataset["closed_x1_amplitude"].values[i] * 1e3
        flag = dataset["closed_stable"].values[i]
        if np.any(np.isfinite(closed)):
            ax.plot(*_split(f, closed, flag == 1), color=colour, **STABLE_STYLE, label="closed-form impact orbit, stable")
            ax.plot(*_split(f, closed, flag == 0), color=colour, **UNSTABLE_STYLE, label="closed-form impact orbit, unstable")
            caption.add("closed", "In the concept's colour: the closed-form impact orbit (one impact per period; two for the two-sided stop), solid where its Floquet multipliers are inside the unit circle, dashed where not.")
        _branches(ax, dataset, i, caption)
        _simulated(ax, dataset, i, fs, colour, caption)
        ax.set_xlim(float(f[0]), float(f[-1]))
        finish_axes(ax, FREQUENCY, "|X1| [mm]", str(dataset["label"].values[i]), log=True)
        _plain_ticks(ax)
    caption.add("band", f"The shaded stretch is the anti-resonance band ({fmt(dataset.attrs['band_low_Hz'], '.2f')}-{fmt(dataset.attrs['band_high_Hz'], '.2f')} Hz), where the lightly damped absorber without a stop keeps |X1| below the static deflection q/k1 = {fmt(1e3 * dataset.attrs['static_deflection_m'], '.2g')} mm (dotted grey line).")
    caption.add("worst", "The wide pale band is the worst stable motion found at each frequency, from which the table's peak and notch are taken.")
    figure_legend(fig, axes, columns=4)
    return DrawnFigure(fig, "concepts_x1", "|X1| of each concept: stable and unstable orbits", caption.text())


def _branches(ax: Axes, dataset: xr.Dataset, i: int, caption: Caption) -> None:
    bf = dataset["branch_frequency"].values[i]
    if not np.any(np.isfinite(bf)):
        return
    x1 = dataset["branch_x1_amplitude"].values[i] * 1e3
    modulus = dataset["branch_floquet_modulus"].values[i]
    label = dataset["branch_branch"].values[i]
    for k in np.unique(label[np.isfinite(label)]):
        on = label == k
        ax.plot(*_split(bf[on], x1[on], modulus[on] < 1.0), **_BRANCH, ls="-", label="continued orbit, stable")
        unstable = (modulus[on] >= 1.0) | np.concatenate([[False], modulus[on][:-1] >= 1.0])  # join the stable ends
        ax.plot(*_split(bf[on], x1[on], unstable), **_BRANCH, ls=(0, (3, 2)), label="continued orbit, unstable")
    caption.add("branches", "Thin dark lines: branches of periodic orbits continued in frequency on the exact stroboscopic map (solid stable, dashed unstable).")


def _simulated(ax: Axes, dataset: xr.Dataset, i: int, fs: np.ndarray, colour: str, caption: Caption) -> None:
    x1 = dataset["simulated_x1"].values[i] * 1e3
    if not np.any(np.isfinite(x1)):
        return
    periodic = dataset["simulated_converged"].values[i] == 1.0
    ax.plot(fs[periodic], x1[periodic], "D", ms=4.0, color=colour, mec="k", mew=0.5, ls="none", label="simulated steady state, periodic")
    ax.plot(fs[~periodic], x1[~periodic], "D", ms=4.0, mfc="none", mec=colour, mew=1.0, ls="none", label="simulated steady state, not periodic")
    caption.add("simulated", "Diamonds: steady states of the exact engine (rigid stops), filled where periodic, hollow where not (fundamental over the measured periods).")


def overview_figure(dataset: xr.Dataset) -> DrawnFigure:
    """Every concept's worst stable |X1| and base-force fundamental against frequency, side by side."""
    f = dataset["frequency"].values
    fig, axes = new_figure(2, panel_height=4.2, legend_rows=legend_rows(dataset.sizes["concept"], 2))
    for i in range(dataset.sizes["concept"]):
        label = str(dataset["label"].values[i])
        for ax, values in ((axes[0], dataset["worst_x1_amplitude"].values[i] * 1e3), (axes[1], dataset["worst_base_force_amplitude"].values[i])):
            ax.plot(f, values, color=concept_colour(i), lw=1.5, label=label)
            alone = _isolated(values)
            ax.plot(f[alone], values[alone], "o", ms=3.0, color=concept_colour(i))
    _band(axes[0], dataset)
    _band(axes[1], dataset, static=False)
    finish_axes(axes[0], FREQUENCY, "worst stable |X1| [mm]", "primary mass", log=True)
    finish_axes(axes[1], FREQUENCY, "worst stable base force, fundamental [N]", "force on the base", log=True)
    for ax in axes:
        ax.set_xlim(float(f[0]), float(f[-1]))
        _plain_ticks(ax)
    figure_legend(fig, axes, columns=2)
    caption = (
        "Left: the worst stable |X1| found at each frequency, every concept in its colour (log scale; where no stable periodic orbit is "
        "known only the simulated steady states are drawn, as dots). Right: the fundamental of the force on the base of that motion, through the suspension "
        "(k1 x1 + b1 x1') and the absolute stops (a relative stop's force stays between the masses). Shaded: the anti-resonance band; "
        "dotted grey: q/k1."
    )
    return DrawnFigure(fig, "concepts_overview", "Every concept side by side: |X1| and the force on the base", caption)


def impact_figure(dataset: xr.Dataset) -> DrawnFigure | None:
    """What the impacts cost, for the concepts with stops: the bumper twins' peak acceleration and peak force, and
    the rigid stops' impulse and impacts per period."""
    fs = dataset["simulation_frequency"].values
    rows = [i for i in range(dataset.sizes["concept"]) if str(dataset["stops"].values[i]) != "no stop"]
    if not rows:
        return None
    panels = (("bumper_peak_acceleration", "peak impact acceleration [m/s²]", "bumper twins: acceleration", True),
              ("bumper_peak_contact_force", "peak bumper force [N]", "bumper twins: contact force (time domain)", True),
              ("bumper_peak_base_force", "peak base force [N]", "bumper twins: force on the base (time domain)", True),
              ("simulated_impulse_per_period", "impulse per period [N s]", "rigid stops: impulse", False),
              ("simulated_impacts_per_period", "impacts per period", "rigid stops: impacts", False))  # fmt: skip
    fig, axes = new_figure(len(panels), panel_height=3.2, legend_rows=legend_rows(len(rows), 2))
    for ax, (variable, ylabel, title, log) in zip(axes, panels):
        _band(ax, dataset, static=False)
        for i in rows:
            values = dataset[variable].values[i]
            ax.plot(fs, np.where(values > 0, values, np.nan) if log else values, "o-", ms=3.0, lw=1.0, color=concept_colour(i), label=str(dataset["label"].values[i]))
        finish_axes(ax, FREQUENCY, ylabel, title, log=log)
        ax.set_xlim(float(fs[0]), float(fs[-1]))
        if log:
            _plain_ticks(ax)
    figure_legend(fig, axes, columns=2)
    bumper = fmt(dataset.attrs.get("bumper_frequency_Hz"), ".4g")
    caption = (
        f"First three panels: steady states of each rigid stop's Kelvin-Voigt twin (Omega_b/2pi = {bumper} Hz, loss factor giving the stop's R) "
        "through the compliant engine: the largest deceleration in contact, the largest bumper force, and the largest force on the base "
        "(k1 x1 + b1 x1' plus the absolute stops' force, from a dense replay of the steady state), against frequency (log scales; the first two "
        "have no point where nothing touches). Last two: the exact engine's rigid stops, total impulse and impacts per excitation period (chattering shows "
        "as many impacts). Shaded: the anti-resonance band."
    )
    return DrawnFigure(fig, "concepts_impacts", "What the impacts cost: bumper acceleration and force, impulse", caption)

