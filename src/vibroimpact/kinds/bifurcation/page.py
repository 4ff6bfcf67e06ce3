"""Report page of bifurcation studies: bifurcation diagrams with brute force and continued branches, the special
points, the Floquet multipliers along the branches, and the two-parameter chart with its regime map.

Dataset layout read here: see :mod:`vibroimpact.kinds.bifurcation.study` (``branch_point``, ``special_point``, the
``brute_*`` variables over (restitution, sweep, frequency, ...), ``chart_point`` and ``chart_regime``). The amplitude
drawn is the first coordinate's (``system_coordinates``: X1, the primary mass, on the paper's layout); the stops are
named as the dataset's ``stop_layout`` says.
"""

from __future__ import annotations

import html
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.colors import BoundaryNorm, ListedColormap
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from vibroimpact.reporting.page import DrawnFigure, Section, Table, saved
from vibroimpact.reporting.style import STABLE_STYLE, UNSTABLE_STYLE, figure_legend, finish_axes, fmt, legend_rows, new_figure, SWEEP_COLOURS
from vibroimpact.kinds.bifurcation.scene import coordinate_label

__all__ = ["page_for", "BifurcationPage", "bifurcation_figures", "special_point_table", "orbit_class", "orbit_colours", "first_coordinate", "headline", "answer_text", "failure_text", "failure_details"]

#: Brute-force dots of each sweep direction.
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
    return [Line2D([], [], color=colours[k], lw=1.6, label=_orbit_label(k)) for k in sorted(classes, key=lambda k: (k[1], k[0]))]


def _orbit_label(key: tuple[int, int]) -> str:
    impacts, period = key
    if impacts == 0:
        return "linear orbit (no impact)"
    return f"{impacts} impact{'s' if impacts > 1 else ''} per {'period' if period == 1 else f'{period} periods'}"


def _flags(variable: xr.DataArray) -> list[str]:
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
    kinds = _flags(dataset["special_point_kind"])
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
    meanings = _flags(dataset["chart_regime"])
    cmap = ListedColormap(REGIME_COLOURS[: len(meanings)])
    norm = BoundaryNorm(np.arange(-1.5, len(meanings) - 1), cmap.N)
    kinds = _flags(dataset["chart_kind"])
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
    flags = _flags(dataset["branch_origin"])
    return origin in flags and bool(np.any(dataset["branch_origin"].values == flags.index(origin)))


def _stopped(dataset: xr.Dataset) -> str:
    """The stopped coordinates in words (``x2``, ``x2 - x1``), from ``stop_layout`` (``x2`` when absent)."""
    layout = str(dataset.attrs.get("stop_layout", "x2 <= Delta"))
    targets = [part.split(" <=")[0].split(" >=")[0].strip() for part in layout.split("; ")]
    return " and ".join(dict.fromkeys(targets))


#: The brute-force classes that are no periodic motion.
_NON_PERIODIC = ("quasi_periodic", "chaotic", "irregular")


def _ranges(values: np.ndarray, step: float) -> str:
    """Sorted frequencies [Hz] as ranges ``a-b`` (a gap wider than 1.5 ``step`` starts a new one), at most four."""
    if values.size == 0:
        return ""
    values = np.sort(values)
    breaks = np.flatnonzero(np.diff(values) > 1.5 * step)
    starts, ends = np.r_[values[0], values[breaks + 1]], np.r_[values[breaks], values[-1]]
    parts = [f"{fmt(a, '.2f')}-{fmt(b, '.2f')}" if b > a else fmt(a, ".2f") for a, b in zip(starts, ends)]
    return ", ".join(parts[:4]) + (f" and {len(parts) - 4} more" if len(parts) > 4 else "") + " Hz"


def _brute_facts(dataset: xr.Dataset, index: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Of the brute force at restitution ``index``: the largest amplitude of the first coordinate per (sweep,
    frequency) [m], the regime flags per (sweep, frequency), and where either sweep settles on no periodic motion."""
    brute = dataset.isel(restitution=index)
    amplitude = np.nanmax(brute[f"brute_{first_coordinate(dataset)}_amplitude"].values, axis=-1)
    regime = brute["brute_regime"].values
    meanings = _flags(dataset["brute_regime"])
    codes = [meanings.index(m) - 1 for m in _NON_PERIODIC if m in meanings]
    return amplitude, regime, np.isin(regime, codes).any(axis=0)


def headline(dataset: xr.Dataset) -> str:
    """The answer in one line per restitution: the largest amplitude the brute force settles on, and at how many
    frequencies it settles on no periodic motion."""
    label = coordinate_label(first_coordinate(dataset))
    frequency = dataset["frequency"].values
    lines = []
    for i, r in enumerate(dataset["restitution"].values):
        amplitude, _regime, wild = _brute_facts(dataset, i)
        top = ""
        if np.isfinite(amplitude).any():
            _j, k = np.unravel_index(int(np.nanargmax(amplitude)), amplitude.shape)
            top = f"up to |{label}| = {fmt(amplitude[_j, k] * 1e3, '.3g')} mm (at {fmt(frequency[k], '.2f')} Hz), "
        lines.append(f"R = {fmt(r, 'g')}: {top}no periodic motion at {int(wild.sum())} of {frequency.size} frequencies")
    return "; ".join(lines)


def answer_text(dataset: xr.Dataset) -> str:
    """What the motion is, per restitution, in a few sentences: the largest amplitude the brute force settles on, where
    it settles on no periodic motion, where the two sweeps disagree (coexisting attractors), where the closed-form
    orbit is stable, and how many special points were located."""
    label = coordinate_label(first_coordinate(dataset))
    meanings = _flags(dataset["brute_regime"])
    frequency = dataset["frequency"].values
    step = float(np.median(np.diff(frequency))) if frequency.size > 1 else 1.0
    origins = _flags(dataset["branch_origin"])
    closed = [origins.index(k) for k in ("one_impact", "two_impacts") if k in origins]
    kinds = _flags(dataset["special_point_kind"])
    paragraphs = []
    for i, r in enumerate(dataset["restitution"].values):
        amplitude, regime, wild = _brute_facts(dataset, i)
        words = [f"<b>R = {fmt(r, 'g')}</b>:"]
        if np.isfinite(amplitude).any():
            j, k = np.unravel_index(int(np.nanargmax(amplitude)), amplitude.shape)
            kind = meanings[int(regime[j, k]) + 1].replace("_", " ")
            words.append(f"the brute force settles at most on |{label}| = {fmt(amplitude[j, k] * 1e3, '.3g')} mm ({fmt(frequency[k], '.2f')} Hz, "
                         f"sweeping {dataset['sweep'].values[j]}: {kind});")  # fmt: skip
        words.append(f"no periodic motion at {int(wild.sum())} of {frequency.size} frequencies{' (' + _ranges(frequency[wild], step) + ')' if wild.any() else ''};")
        if regime.shape[0] > 1:
            scale = np.nanmax(amplitude) if np.isfinite(amplitude).any() else 1.0
            differ = (regime != regime[:1]).any(axis=0) | (np.abs(np.nan_to_num(amplitude - amplitude[:1])) > 0.05 * scale).any(axis=0)
            words.append(f"the sweeps settle on different motions (coexisting attractors) at {int(differ.sum())} frequencies"
                         f"{' (' + _ranges(frequency[differ], step) + ')' if differ.any() else ''};")  # fmt: skip
        on_branch = np.isclose(dataset["branch_restitution"].values, r) & np.isin(dataset["branch_origin"].values, closed) & (dataset["stable"].values == 1)
        if on_branch.any():
            words.append(f"the closed-form orbit is stable over {_stable_bands(dataset, on_branch)};")
        elif not np.isin(dataset["branch_origin"].values[np.isclose(dataset["branch_restitution"].values, r)], closed).any():
            words.append("no branch from the closed form;")
        else:
            words.append("the closed-form orbit is nowhere stable;")
        mask = np.isclose(dataset["special_point_restitution"].values, r)
        counts = [f"{int(np.count_nonzero(dataset['special_point_kind'].values[mask] == code))} {kind.replace('_', '-')}" for code, kind in enumerate(kinds)]
        words.append(f"special points: {', '.join(counts)}.")
        paragraphs.append("<p>" + " ".join(words) + "</p>")
    return "".join(paragraphs)


def _stable_bands(dataset: xr.Dataset, chosen: np.ndarray) -> str:
    """The frequency bands [Hz] over which the chosen branch points are stable: each branch's runs of consecutive
    stable points, merged where they overlap."""
    bands: list[list[float]] = []
    branch, f = dataset["branch"].values, dataset["branch_frequency"].values
    for label in np.unique(branch[chosen]):
        index = np.flatnonzero(branch == label)
        runs = np.split(index, np.flatnonzero(~chosen[index][1:] | ~chosen[index][:-1]) + 1)
        bands += [[float(f[run].min()), float(f[run].max())] for run in runs if run.size and chosen[run].all()]
    merged: list[list[float]] = []
    for low, high in sorted(bands):
        if merged and low <= merged[-1][1]:
            merged[-1][1] = max(merged[-1][1], high)
        else:
            merged.append([low, high])
    parts = [f"{fmt(a, '.2f')}-{fmt(b, '.2f')}" for a, b in merged]
    return ", ".join(parts[:4]) + (f" and {len(parts) - 4} more" if len(parts) > 4 else "") + " Hz"


def _lines(dataset: xr.Dataset, key: str) -> list[str]:
    """A list-of-strings attribute as a list (netCDF gives one string back as a string), empty when absent."""
    value = dataset.attrs.get(key)
    if value is None:
        return []
    return [value] if isinstance(value, str) else [str(v) for v in np.atleast_1d(value)]


def failure_text(dataset: xr.Dataset) -> str:
    """What failed in the run (``run_failures``: what, how many, what it means for the results), as HTML; empty when
    nothing did."""
    lines = _lines(dataset, "run_failures")
    if not lines:
        return ""
    items = "".join(f"<li>{html.escape(line)}</li>" for line in lines)
    return f"<p><b>What failed in this run</b> (each line says what it means for the results; the raw messages are at the end of the page):</p><ul>{items}</ul>"


def failure_details(dataset: xr.Dataset) -> str:
    """The raw messages of what failed (``run_failure_details``), collapsed; empty when nothing failed."""
    details = _lines(dataset, "run_failure_details")
    if not details:
        return ""
    return f"<details><summary>The raw messages of what failed ({len(details)})</summary><pre>{html.escape(chr(10).join(details))}</pre></details>"


def bifurcation_figures(dataset: xr.Dataset) -> Iterator[DrawnFigure]:
    """Every figure of the page, in order."""
    for index, r in enumerate(dataset["restitution"].values):
        yield diagram_figure(dataset, float(r), index)
        yield multiplier_figure(dataset, float(r), index)
    if "chart_regime" in dataset:
        yield chart_figure(dataset)


def _found_on(point: xr.Dataset) -> str:
    """The branches a special point was found on, ``3, 7`` (its own branch where the dataset lists no others)."""
    if "special_point_branches" in point:
        return ", ".join(str(point["special_point_branches"].values).split())
    return str(int(point["special_point_branch"]))


def special_point_table(dataset: xr.Dataset) -> Table:
    """Every located special point: kind, frequency, R, the orbit, its multipliers and what happens there."""
    kinds = _flags(dataset["special_point_kind"])
    rows = []
    order = np.lexsort((dataset["special_point_frequency"].values, dataset["special_point_restitution"].values))
    for k in order:
        point = dataset.isel(special_point=int(k))
        mu = point["special_point_multiplier_real"].values + 1j * point["special_point_multiplier_imag"].values
        multipliers = ", ".join(f"{m.real:.4f}{m.imag:+.4f}j" if abs(m.imag) > 1e-9 else f"{m.real:.4f}" for m in mu)
        key = orbit_class(float(point["special_point_impacts_per_period"]), int(point["special_point_period_multiplicity"]))
        cells = [
            kinds[int(point["special_point_kind"])].replace("_", "-"), fmt(float(point["special_point_frequency"]), ".5f"),
            fmt(float(point["special_point_restitution"]), "g"), _found_on(point), _orbit_label(key),
            html.escape(multipliers), fmt(float(point["special_point_floquet_modulus"]), ".4f"), html.escape(str(point["special_point_note"].values)),
        ]  # fmt: skip
        rows.append("<tr>" + "".join(f"<td>{c}</td>" for c in cells) + "</tr>")
    header = "".join(f"<th>{h}</th>" for h in ("kind", "frequency [Hz]", "R", "branch", "orbit", "Floquet multipliers", "max |mu|", "what happens there"))
    return Table("Special points", f"<table><tr>{header}</tr>{''.join(rows)}</table>")


class BifurcationPage:
    """The page of a bifurcation study's dataset."""

    def __init__(self, dataset: xr.Dataset) -> None:
        self.dataset = dataset

    def summary(self) -> str:
        """The answer (:func:`headline`), then what was computed."""
        d = self.dataset
        stops = f"; stops: {d.attrs['stop_layout']}" if "stop_layout" in d.attrs else ""
        return (f"{headline(d)}; {int(np.unique(d['branch'].values).size)} branches, {d.sizes['special_point']} special points, brute force at "
                f"{d.sizes['frequency']} frequencies x {d.sizes['sweep']} directions for R = {', '.join(fmt(r, 'g') for r in d['restitution'].values)}{stops}")  # fmt: skip

    def sections(self, out: Path) -> list[Section]:
        """The answer (and what failed, if anything did) with the diagrams, multipliers and special points per
        restitution, then the chart, then the continuation's logs and the raw messages of what failed, collapsed
        (what a reader checks, not what they read first)."""
        figures = saved(bifurcation_figures(self.dataset), out)
        chart = [f for f in figures if f.path.stem == "chart"]
        answer = answer_text(self.dataset) + failure_text(self.dataset)
        sections = [Section("Bifurcation diagrams", answer, [f for f in figures if f not in chart], [special_point_table(self.dataset)])]
        if chart:
            sections.append(Section("Two-parameter chart", "", chart))
        logs = [
            (title, str(self.dataset.attrs.get(key, "")))
            for key, title in (("continuation_notes", "Every branch found by continuation: how it was started and where it ends"), ("chart_notes", "The chart's curves: how each was traced"))
        ]
        shown = "".join(
            f"<details><summary>{html.escape(title)} ({len(text.splitlines())} lines)</summary><pre>{html.escape(text)}</pre></details>" for title, text in logs if text
        )
        if shown:
            sections.append(Section("Continuation logs", shown))
        if failure_details(self.dataset):
            sections.append(Section("What failed, in detail", failure_details(self.dataset)))
        return sections


def page_for(dataset: xr.Dataset) -> BifurcationPage:
    """The page of a bifurcation dataset."""
    return BifurcationPage(dataset)
