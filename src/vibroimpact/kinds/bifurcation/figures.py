"""Figures of the bifurcation page: the bifurcation diagram and the Floquet multipliers of each restitution, and the
two-parameter chart with its regime map (:mod:`vibroimpact.kinds.bifurcation.page` lays them out).

Dataset layout read here: see :mod:`vibroimpact.kinds.bifurcation.study`. The amplitude drawn is the first
coordinate's (``system_coordinates``: X1, the primary mass, on the paper's layout); the stops are named as the
dataset's ``stop_layout`` says.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.colors import BoundaryNorm, ListedColormap
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from vibroimpact.reporting.page import DrawnFigure
from vibroimpact.reporting.style import STABLE_STYLE, UNSTABLE_STYLE, figure_legend, finish_axes, fmt, legend_rows, new_figure, SWEEP_COLOURS
from vibroimpact.kinds.bifurcation.scene import coordinate_label

__all__ = ["bifurcation_figures", "diagram_figure", "multiplier_figure", "chart_figure", "orbit_class", "orbit_colours", "orbit_label", "first_coordinate", "flags"]

#: Marker of each kind of special point.
SPECIAL_MARKERS = {"fold": "o", "period_doubling": "s", "neimark_sacker": "D", "grazing": "^"}
#: Colour of an orbit by (impacts per orbit period, period multiplicity); other classes take :data:`EXTRA_COLOURS`.
ORBIT_COLOURS = {(0, 1): "k", (1, 1): "C0", (2, 2): "C1", (1, 2): "C4", (2, 1): "C5", (3, 3): "C6", (4, 4): "C8"}
#: Colours of the other classes of orbits (seeded from the brute force: periods up to 32), in order of period; none is
#: a colour of :data:`ORBIT_COLOURS` or of the brute-force dots.
EXTRA_COLOURS = ("#17becf", "#bcbd22", "#393b79", "#637939", "#8c6d31", "#843c39", "#7b4173", "#636363", "#e7ba52", "#5254a3",
                 "#a55194", "#b5cf6b", "#6b6ecf", "#bd9e39", "#de9ed6", "#9c9ede")  # fmt: skip
#: Colours of the regime map's classes (failed, linear, one_impact, other_periodic, quasi_periodic, chaotic, irregular).
REGIME_COLOURS = ("#ffffff", "#d9d9d9", "#9ecae1", "#a1d99b", "#fdae6b", "#e6550d", "#bcbddc")
_FREQUENCY = "excitation frequency [Hz]"
#: Top of the multiplier figure's axis [-].
MODULUS_TOP = 20.0


def first_coordinate(dataset: xr.Dataset) -> str:
    """The coordinate whose amplitude the page draws: the first of ``system_coordinates`` (``x1`` when absent)."""
    return str(dataset.attrs.get("system_coordinates", "x1")).split()[0]


def orbit_class(impacts_per_period: float, period: int) -> tuple[int, int]:
    """(impacts per orbit period, period multiplicity) of an orbit."""
    return int(round(impacts_per_period * period)), int(period)


def orbit_colours(dataset: xr.Dataset) -> dict[tuple[int, int], str]:
    """A colour for every class of orbit in ``dataset`` (the same in every figure): :data:`ORBIT_COLOURS`, then the
    other classes in order of period and impacts from :data:`EXTRA_COLOURS` (cycling)."""
    classes = sorted({orbit_class(float(i), int(p)) for i, p in zip(dataset["impacts_per_period"].values, dataset["period_multiplicity"].values)}, key=lambda k: (k[1], k[0]))
    colours = dict(ORBIT_COLOURS)
    extra = [k for k in classes if k not in colours]
    for n, key in enumerate(extra):
        colours[key] = EXTRA_COLOURS[n % len(EXTRA_COLOURS)]
    return colours


def _class_legend(colours: dict[tuple[int, int], str], classes: set[tuple[int, int]]) -> list[Line2D]:
    """A solid line per class drawn, in order of period and impacts (stability is told by the line style)."""
    return [Line2D([], [], color=colours[k], lw=1.6, label=orbit_label(k)) for k in sorted(classes, key=lambda k: (k[1], k[0]))]


def orbit_label(key: tuple[int, int]) -> str:
    impacts, period = key
    if impacts == 0:
        return "linear orbit (no impact)"
    return f"{impacts} impact{'s' if impacts > 1 else ''} per {'period' if period == 1 else f'{period} periods'}"


def flags(variable: xr.DataArray) -> list[str]:
    return str(variable.attrs.get("flag_meanings", "")).split()


def _branches(dataset: xr.Dataset, restitution: float) -> Iterator[tuple[int, xr.Dataset]]:
    """Each branch of one restitution, its points in arclength order."""
    mask = np.isclose(dataset["branch_restitution"].values, restitution)
    part = dataset[[f"{first_coordinate(dataset)}_amplitude", "floquet_modulus", "stable", "impacts_per_period", "period_multiplicity", "impact_velocity"]].isel(branch_point=np.flatnonzero(mask))
    for label in np.unique(part["branch"].values):
        yield int(label), part.isel(branch_point=np.flatnonzero(part["branch"].values == label))


def _classes(dataset: xr.Dataset, restitution: float) -> list[tuple[int, int]]:
    """The classes of orbit of one restitution's branches."""
    mask = np.isclose(dataset["branch_restitution"].values, restitution)
    pairs = zip(dataset["impacts_per_period"].values[mask], dataset["period_multiplicity"].values[mask])
    return sorted({orbit_class(float(i), int(p)) for i, p in pairs})


def _draw_branch(ax: Axes, frequency: np.ndarray, values: np.ndarray, stable: np.ndarray, colour: str, label: str) -> None:
    """A branch line, solid where stable, dashed where unstable; each change of stability drawn on both sides."""
    change = np.flatnonzero(np.diff(stable.astype(int))) + 1
    for piece in np.split(np.arange(frequency.size), change):
        if piece.size == 0:
            continue
        run = np.append(piece, piece[-1] + 1) if piece[-1] + 1 < frequency.size else piece
        style = STABLE_STYLE if stable[piece[0]] else UNSTABLE_STYLE
        ax.plot(frequency[run], values[run], color=colour, label=label, **style)
        label = "_"


def diagram_figure(dataset: xr.Dataset, restitution: float, index: int) -> DrawnFigure:
    """The bifurcation diagram of one restitution: the first coordinate's amplitude and impact velocities against
    frequency."""
    keys = _classes(dataset, restitution)
    name = first_coordinate(dataset)
    label = coordinate_label(name)
    fig, (top, bottom) = new_figure(2, panel_height=4.2, columns=1, sharex=True, legend_rows=legend_rows(len(keys) + 8, 5))
    classes: set[tuple[int, int]] = set()
    r_index = int(np.argmin(np.abs(dataset["restitution"].values - restitution)))
    for direction in dataset["sweep"].values:
        brute = dataset.isel(restitution=r_index).sel(sweep=direction)
        f = brute["frequency"].values
        amp = brute[f"brute_{name}_amplitude"].values
        top.scatter(np.repeat(f, amp.shape[1]), amp.ravel() * 1e3, s=1.5, color=SWEEP_COLOURS.get(str(direction), "C7"), alpha=0.6, lw=0, zorder=1)
        vel = brute["brute_impact_velocity"].values
        bottom.scatter(np.repeat(f, vel.shape[1]), vel.ravel(), s=1.5, color=SWEEP_COLOURS.get(str(direction), "C7"), alpha=0.6, lw=0, zorder=1)
    colours = orbit_colours(dataset)
    for _label, branch in _branches(dataset, restitution):
        f = branch["branch_frequency"].values
        key = orbit_class(float(branch["impacts_per_period"].values[0]), int(branch["period_multiplicity"].values[0]))
        colour = colours.get(key, "0.5")
        classes.add(key)
        stable = branch["stable"].values == 1
        _draw_branch(top, f, branch[f"{name}_amplitude"].values * 1e3, stable, colour, "_")
        velocities = branch["impact_velocity"].values
        for k in range(velocities.shape[1]):
            if np.isfinite(velocities[:, k]).any():
                _draw_branch(bottom, f, velocities[:, k], stable, colour, "_")
    specials = _specials(dataset, restitution)
    kinds = flags(dataset["special_point_kind"])
    for code, kind in enumerate(kinds):
        chosen = specials.isel(special_point=np.flatnonzero(specials["special_point_kind"].values == code))
        if chosen.sizes["special_point"]:
            top.scatter(chosen["special_point_frequency"], chosen[f"special_point_{name}_amplitude"] * 1e3, marker=SPECIAL_MARKERS.get(kind, "x"), s=42,
                        facecolor="none", edgecolor="k", lw=1.2, zorder=5, label=kind.replace("_", "-"))  # fmt: skip
    finish_axes(top, "", f"|{label}| fundamental [mm]", f"R = {fmt(restitution, 'g')}: {label} amplitude")
    finish_axes(bottom, _FREQUENCY, "impact velocity [m/s]", f"R = {fmt(restitution, 'g')}: impact velocities")
    dots = [Line2D([], [], ls="", marker="o", ms=5, color=SWEEP_COLOURS.get(str(d), "C7"), label=f"brute force, sweep {d}") for d in dataset["sweep"].values]
    extra = [*dots, Line2D([], [], color="k", **STABLE_STYLE, label="stable"), Line2D([], [], color="k", **UNSTABLE_STYLE, label="unstable")]
    figure_legend(fig, [top, bottom], [*_class_legend(colours, classes), *extra], columns=5)
    caption = (
        f"Bifurcation diagram at R = {fmt(restitution, 'g')}, Delta = {fmt(float(dataset['clearance']) * 1e3, 'g')} mm. Dots: brute-force "
        f"time simulation (compiled exact engine) sweeping up (vermillion) and down (sky blue), the end state carried to the next frequency; "
        f"top: the {label} fundamental over each of the {dataset.sizes['strobe']} kept periods; bottom: the velocity of every impact in them. "
        "Lines: every continued branch (solid stable, dashed unstable; colour: impacts per orbit period and period), the linear orbit "
        "where it fits inside the clearance in black; markers: the located special points (table below)."
    )
    return DrawnFigure(fig, f"bifurcation_R{index}", f"Bifurcation diagram, R = {fmt(restitution, 'g')}", caption)


def _specials(dataset: xr.Dataset, restitution: float) -> xr.Dataset:
    mask = np.isclose(dataset["special_point_restitution"].values, restitution)
    return dataset[[f"special_point_{first_coordinate(dataset)}_amplitude", "special_point_floquet_modulus"]].isel(special_point=np.flatnonzero(mask))


def multiplier_figure(dataset: xr.Dataset, restitution: float, index: int) -> DrawnFigure:
    """The largest Floquet multiplier modulus along every branch of one restitution (log scale)."""
    keys = [k for k in _classes(dataset, restitution) if k[0]]
    fig, (ax,) = new_figure(1, panel_height=4.0, columns=1, legend_rows=legend_rows(len(keys) + 1, 5))
    seen: set[tuple[int, int]] = set()
    colours = orbit_colours(dataset)
    for _label, branch in _branches(dataset, restitution):
        key = orbit_class(float(branch["impacts_per_period"].values[0]), int(branch["period_multiplicity"].values[0]))
        if key[0] == 0:
            continue
        seen.add(key)
        _draw_branch(ax, branch["branch_frequency"].values, branch["floquet_modulus"].values, branch["stable"].values == 1, colours.get(key, "0.5"), "_")
    ax.axhline(1.0, color="k", lw=0.8)
    specials = _specials(dataset, restitution)
    ax.scatter(specials["special_point_frequency"], specials["special_point_floquet_modulus"], s=30, facecolor="none", edgecolor="k", zorder=5, label="special points")
    finish_axes(ax, _FREQUENCY, "largest |Floquet multiplier|", f"R = {fmt(restitution, 'g')}: stability along the branches", log=True)
    ax.set_ylim(0.2, MODULUS_TOP)
    figure_legend(fig, [ax], _class_legend(colours, seen), columns=5)
    caption = (f"Largest modulus of the Floquet multipliers along every impacting branch at R = {fmt(restitution, 'g')} (log scale, "
               f"clipped at {fmt(MODULUS_TOP, 'g')}: next to a grazing point the multipliers grow without bound): an orbit is stable below 1 (the horizontal line); solid stable, dashed unstable; circles: the special points.")  # fmt: skip
    return DrawnFigure(fig, f"multipliers_R{index}", f"Floquet multipliers, R = {fmt(restitution, 'g')}", caption)


def chart_figure(dataset: xr.Dataset) -> DrawnFigure:
    """The regime map of each sweep direction with the curves of special points in (frequency, clearance)."""
    directions = [str(d) for d in dataset["sweep"].values]
    fig, axes = new_figure(len(directions), panel_height=4.6, columns=len(directions), sharey=True, legend_rows=3)
    meanings = flags(dataset["chart_regime"])
    cmap = ListedColormap(REGIME_COLOURS[: len(meanings)])
    norm = BoundaryNorm(np.arange(-1.5, len(meanings) - 1), cmap.N)
    kinds = flags(dataset["chart_kind"])
    curve_colours = {"fold": "C0", "period_doubling": "C1", "neimark_sacker": "C3", "grazing": "k"}
    for ax, direction in zip(axes, directions):
        regime = dataset["chart_regime"].sel(sweep=direction)
        ax.pcolormesh(dataset["map_frequency"], dataset["map_clearance"] * 1e3, regime.values, cmap=cmap, norm=norm, shading="nearest", rasterized=True)
        for label in np.unique(dataset["chart_curve"].values):
            points = np.flatnonzero(dataset["chart_curve"].values == label)
            kind = kinds[int(dataset["chart_kind"].values[points[0]])]
            ax.plot(dataset["chart_frequency"].values[points], dataset["chart_clearance"].values[points] * 1e3, color=curve_colours.get(kind, "0.3"),
                    lw=1.6, ls="--" if kind == "grazing" else "-", label=f"{kind.replace('_', '-')} curve")  # fmt: skip
        ax.axhline(float(dataset["clearance"]) * 1e3, color="0.3", lw=0.8, ls=":")
        ax.set_ylim(float(dataset["map_clearance"].min()) * 1e3, float(dataset["map_clearance"].max()) * 1e3)
        ax.set_xlim(float(dataset["map_frequency"].min()), float(dataset["map_frequency"].max()))
        finish_axes(ax, _FREQUENCY, "clearance Delta [mm]" if ax is axes[0] else "", f"brute force sweeping {direction}")
    patches = [Patch(facecolor=REGIME_COLOURS[k], edgecolor="0.5", label=meaning.replace("_", " ")) for k, meaning in enumerate(meanings) if meaning != "failed"]
    figure_legend(fig, axes, patches, columns=5)
    r = dataset.attrs.get("chart_restitution", float("nan"))
    caption = (
        f"Chart of frequency x clearance at R = {fmt(r, 'g')}. Colours: what the brute-force simulation settles on at each point of a "
        f"{dataset.sizes['map_frequency']} x {dataset.sizes['map_clearance']} grid (sweeping in frequency at each clearance, the end state "
        "carried over): linear motion, one impact per period, another periodic motion, or non-periodic motion (quasi-periodic, chaotic, or "
        "undecided: irregular) from the exact Lyapunov exponent. Lines: the fold, period-doubling and Neimark-Sacker points of the "
        f"branches started from the closed form, continued in (frequency, clearance); dashed, the grazing curves: the clearance the linear "
        f"motion of {_stopped(dataset)} just reaches (q |H12| = Delta on the paper's layout), where the closed-form orbit's impact "
        "velocity vanishes and the linear motion touches the stop, and the points where a free flight of an impacting orbit touches "
        "the stop (located again at each clearance); dotted: the clearance of the diagrams."
        + (" The symmetric orbit of the two-sided stop has two impacts per period: it counts as another periodic motion." if _has_origin(dataset, "two_impacts") else "")
    )
    return DrawnFigure(fig, "chart", f"Two-parameter chart, R = {fmt(r, 'g')}", caption)


def _has_origin(dataset: xr.Dataset, origin: str) -> bool:
    """Does a branch of ``dataset`` come from ``origin`` (a flag of ``branch_origin``)?"""
    meanings = flags(dataset["branch_origin"])
    return origin in meanings and bool(np.any(dataset["branch_origin"].values == meanings.index(origin)))


def _stopped(dataset: xr.Dataset) -> str:
    """The stopped coordinates in words (``x2``, ``x2 - x1``), from ``stop_layout`` (``x2`` when absent)."""
    layout = str(dataset.attrs.get("stop_layout", "x2 <= Delta"))
    targets = [part.split(" <=")[0].split(" >=")[0].strip() for part in layout.split("; ")]
    return " and ".join(dict.fromkeys(targets))


def bifurcation_figures(dataset: xr.Dataset) -> Iterator[DrawnFigure]:
    """Every figure of the page, in order."""
    for index, r in enumerate(dataset["restitution"].values):
        yield diagram_figure(dataset, float(r), index)
        yield multiplier_figure(dataset, float(r), index)
    if "chart_regime" in dataset:
        yield chart_figure(dataset)
