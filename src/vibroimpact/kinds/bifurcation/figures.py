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
from matplotlib import patheffects
from matplotlib.axes import Axes
from matplotlib.colors import BoundaryNorm, ListedColormap
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from vibroimpact.reporting.page import DrawnFigure
from vibroimpact.analysis.stability import Regime
from vibroimpact.model.units import length_unit
from vibroimpact.reporting.style import OKABE_ITO, REGIME_COLOURS, STABLE_STYLE, UNSTABLE_STYLE, figure_legend, finish_axes, fmt, legend_rows, new_figure, SWEEP_COLOURS
from vibroimpact.kinds.bifurcation.scene import coordinate_label

__all__ = ["KIND_NAMES", "bifurcation_figures", "diagram_figure", "multiplier_figure", "chart_figure", "orbit_class", "branch_class", "orbit_looks", "orbit_label", "first_coordinate", "flags", "length_of"]

#: How the page names each kind of special point.
KIND_NAMES = {"fold": "fold", "period_doubling": "period doubling", "neimark_sacker": "Neimark-Sacker", "grazing": "grazing"}
#: Marker of each kind of special point.
SPECIAL_MARKERS = {"fold": "o", "period_doubling": "s", "neimark_sacker": "D", "grazing": "^"}
#: Line colours of the orbit classes: Okabe-Ito's, told apart with any colour vision; not the sweeps' vermillion and
#: sky blue (:data:`SWEEP_COLOURS`, the brute-force dots), not black (the linear orbit), not yellow (too faint as a line).
ORBIT_PALETTE = OKABE_ITO[:4]
#: Markers on the lines of the classes beyond the palette: class k (in order of period and impacts) takes colour
#: k mod 4 and marker k // 4; filled and small, unlike the special points' open black markers.
ORBIT_MARKERS = ("", "o", "s", "v", "P", "X", "*", "h")
#: How the linear orbit (no impact) is drawn.
LINEAR_LOOK = {"color": "k"}
#: What the motion at a brute-force point is, as the project's regimes (:data:`REGIME_COLOURS`: one palette on every
#: page), keyed by the flags of ``brute_regime`` and ``chart_regime``.
MOTION_REGIMES = {
    "failed": Regime.FAILED, "linear": Regime.LINEAR, "one_impact": Regime.ONE_IMPACT, "other_periodic": Regime.PERIODIC_IMPACTS,
    "quasi_periodic": Regime.QUASI_PERIODIC, "chaotic": Regime.CHAOTIC, "irregular": Regime.IRREGULAR,
}  # fmt: skip
#: Colour of the chart's curves of each kind of special point (Okabe-Ito and black, grazing dashed; drawn with a white
#: edge, to show over any regime).
CURVE_COLOURS = {"fold": "k", "period_doubling": OKABE_ITO[1], "neimark_sacker": OKABE_ITO[3], "grazing": "k"}
_FREQUENCY = "excitation frequency [Hz]"
#: Top of the multiplier figure's axis [-].
MODULUS_TOP = 20.0


def length_of(dataset: xr.Dataset) -> tuple[str, float]:
    """The page's unit of lengths and its factor from metres, chosen from the clearance (:func:`length_unit`: "mm"
    for 3 mm, "m" for 1 m)."""
    return length_unit(float(dataset["clearance"])) if "clearance" in dataset.variables else length_unit(0.0)


def first_coordinate(dataset: xr.Dataset) -> str:
    """The coordinate whose amplitude the page draws: the first of ``system_coordinates`` (``x1`` when absent)."""
    return str(dataset.attrs.get("system_coordinates", "x1")).split()[0]


def orbit_class(impacts_per_period: float, period: int) -> tuple[int, int]:
    """(impacts per orbit period, period multiplicity) of an orbit."""
    return int(round(impacts_per_period * period)), int(period)


def branch_class(impacts_per_period: np.ndarray, period: np.ndarray) -> tuple[int, int]:
    """The class of a branch: its points' most common (:func:`orbit_class`; an end at a grazing point may count
    another number of impacts)."""
    keys = [orbit_class(float(i), int(p)) for i, p in zip(impacts_per_period, period)]
    return max(sorted(set(keys)), key=keys.count)


def orbit_looks(dataset: xr.Dataset, restitution: float) -> dict[tuple[int, int], dict[str, object]]:
    """How each class of orbit of one restitution's branches is drawn (the same in its diagram and its multipliers):
    the linear orbit black, the others in order of period and impacts a colour of :data:`ORBIT_PALETTE` and, beyond
    the first four, a marker of :data:`ORBIT_MARKERS` every few millimetres of line."""
    classes = sorted(_classes(dataset, restitution), key=lambda k: (k[1], k[0]))
    looks: dict[tuple[int, int], dict[str, object]] = {}
    for n, key in enumerate(k for k in classes if k[0]):
        marker = ORBIT_MARKERS[min(n // len(ORBIT_PALETTE), len(ORBIT_MARKERS) - 1)]
        looks[key] = {"color": ORBIT_PALETTE[n % len(ORBIT_PALETTE)]} | ({"marker": marker, "markersize": 4.5, "markevery": 0.06} if marker else {})
    return looks | {k: LINEAR_LOOK for k in classes if not k[0]}


def _class_legend(looks: dict[tuple[int, int], dict[str, object]], classes: set[tuple[int, int]]) -> list[Line2D]:
    """A solid line (with its marker) per class drawn, in order of period and impacts (stability is told by the line
    style)."""
    return [Line2D([], [], lw=1.6, label=orbit_label(k), **{key: v for key, v in looks[k].items() if key != "markevery"}) for k in sorted(classes, key=lambda k: (k[1], k[0]))]


def orbit_label(key: tuple[int, int]) -> str:
    """What an orbit of a class is, in words: "3 impacts per 7 periods" (its period, in excitation periods, and its
    impacts in that time), "linear orbit (no impact)"."""
    impacts, period = key
    if impacts == 0:
        return "linear orbit (no impact)"
    return f"{impacts} impact{'s' if impacts > 1 else ''} per {'period' if period == 1 else f'{period} periods'}"


def flags(variable: xr.DataArray) -> list[str]:
    """The meanings of a CF flag variable, in the order of its values."""
    return str(variable.attrs.get("flag_meanings", "")).split()


def _branches(dataset: xr.Dataset, restitution: float) -> Iterator[tuple[int, xr.Dataset]]:
    """Each branch of one restitution, its points in arclength order."""
    mask = np.isclose(dataset["branch_restitution"].values, restitution)
    part = dataset[[f"{first_coordinate(dataset)}_amplitude", "floquet_modulus", "stable", "impacts_per_period", "period_multiplicity", "impact_velocity"]].isel(branch_point=np.flatnonzero(mask))
    for label in np.unique(part["branch"].values):
        yield int(label), part.isel(branch_point=np.flatnonzero(part["branch"].values == label))


def _classes(dataset: xr.Dataset, restitution: float) -> list[tuple[int, int]]:
    """The classes of orbit of one restitution's branches (:func:`branch_class`)."""
    return sorted({branch_class(b["impacts_per_period"].values, b["period_multiplicity"].values) for _, b in _branches(dataset, restitution)})


def _draw_branch(ax: Axes, frequency: np.ndarray, values: np.ndarray, stable: np.ndarray, look: dict[str, object]) -> None:
    """A branch line in its class's ``look`` (:func:`orbit_looks`), solid where stable, dashed where unstable; each
    change of stability drawn on both sides."""
    change = np.flatnonzero(np.diff(stable.astype(int))) + 1
    for piece in np.split(np.arange(frequency.size), change):
        if piece.size == 0:
            continue
        run = np.append(piece, piece[-1] + 1) if piece[-1] + 1 < frequency.size else piece
        style = STABLE_STYLE if stable[piece[0]] else UNSTABLE_STYLE
        ax.plot(frequency[run], values[run], label="_", **style, **look)


def diagram_figure(dataset: xr.Dataset, restitution: float, index: int) -> DrawnFigure:
    """The bifurcation diagram of one restitution: the first coordinate's amplitude and impact velocities against
    frequency."""
    keys = _classes(dataset, restitution)
    name = first_coordinate(dataset)
    label = coordinate_label(name)
    unit, scale = length_of(dataset)
    fig, (top, bottom) = new_figure(2, panel_height=4.2, columns=1, sharex=True, legend_rows=legend_rows(len(keys) + 8, 4))
    classes: set[tuple[int, int]] = set()
    r_index = int(np.argmin(np.abs(dataset["restitution"].values - restitution)))
    for direction in dataset["sweep"].values:
        brute = dataset.isel(restitution=r_index).sel(sweep=direction)
        f = brute["frequency"].values
        amp = brute[f"brute_{name}_amplitude"].values
        top.scatter(np.repeat(f, amp.shape[1]), amp.ravel() * scale, s=1.5, color=SWEEP_COLOURS.get(str(direction), "C7"), alpha=0.6, lw=0, zorder=1)
        vel = brute["brute_impact_velocity"].values
        bottom.scatter(np.repeat(f, vel.shape[1]), vel.ravel(), s=1.5, color=SWEEP_COLOURS.get(str(direction), "C7"), alpha=0.6, lw=0, zorder=1)
    looks = orbit_looks(dataset, restitution)
    for _label, branch in _branches(dataset, restitution):
        f = branch["branch_frequency"].values
        key = branch_class(branch["impacts_per_period"].values, branch["period_multiplicity"].values)
        classes.add(key)
        stable = branch["stable"].values == 1
        _draw_branch(top, f, branch[f"{name}_amplitude"].values * scale, stable, looks[key])
        velocities = branch["impact_velocity"].values
        for k in range(velocities.shape[1]):
            if np.isfinite(velocities[:, k]).any():
                _draw_branch(bottom, f, velocities[:, k], stable, looks[key])
    specials = _specials(dataset, restitution)
    kinds = flags(dataset["special_point_kind"])
    for code, kind in enumerate(kinds):
        chosen = specials.isel(special_point=np.flatnonzero(specials["special_point_kind"].values == code))
        if chosen.sizes["special_point"]:
            top.scatter(chosen["special_point_frequency"], chosen[f"special_point_{name}_amplitude"] * scale, marker=SPECIAL_MARKERS.get(kind, "x"), s=42,
                        facecolor="none", edgecolor="k", lw=1.2, zorder=5, label=KIND_NAMES.get(kind, kind))  # fmt: skip
    where = f"R = {fmt(restitution, 'g')}{_model(dataset)}"
    finish_axes(top, "", f"|{label}| fundamental [{unit}]", f"{where}: {label} amplitude")
    finish_axes(bottom, _FREQUENCY, "impact velocity [m/s]", f"{where}: impact velocities")
    dots = [Line2D([], [], ls="", marker="o", ms=5, color=SWEEP_COLOURS.get(str(d), "C7"), label=f"brute force, sweep {d}") for d in dataset["sweep"].values]
    extra = [*dots, Line2D([], [], color="k", **STABLE_STYLE, label="stable periodic orbit of the continuation (solid)"), Line2D([], [], color="k", **UNSTABLE_STYLE, label="unstable periodic orbit of the continuation (dashed)")]
    figure_legend(fig, [top, bottom], [*_class_legend(looks, classes), *extra], columns=4)
    caption = (
        f"Bifurcation diagram at R = {fmt(restitution, 'g')}{_model(dataset)}, Delta = {fmt(float(dataset['clearance']) * scale, 'g')} {unit}. Dots: brute-force "
        f"time simulation ({dataset.attrs.get('brute_force_engine', 'compiled exact engine')}) sweeping up (vermillion) and down (sky blue), the end state carried to the next frequency; "
        f"top: the {label} fundamental over each of the {dataset.sizes['strobe']} kept periods; bottom: the velocity of every impact in them. "
        "Lines: every continued branch (solid stable, dashed unstable; colour, and beyond four classes a small filled marker: the "
        "orbit's period and impacts, legend), the linear orbit where it fits inside the clearance in black; open black markers: the "
        "located special points (table below)."
    )
    return DrawnFigure(fig, f"bifurcation_R{index}{dataset.attrs.get('diagram_tag', '')}", f"Bifurcation diagram, R = {fmt(restitution, 'g')}{_model(dataset)}", caption)


def _model(dataset: xr.Dataset) -> str:
    """The diagram's contact model after its R (", bumper 250 Hz", ", rigid stop"), from a bumper dataset's view
    (:func:`~vibroimpact.kinds.bifurcation.bumper.model_view`); empty for a scene of rigid stops."""
    label = str(dataset.attrs.get("diagram_label", ""))
    return f", {label}" if label else ""


def _specials(dataset: xr.Dataset, restitution: float) -> xr.Dataset:
    mask = np.isclose(dataset["special_point_restitution"].values, restitution)
    return dataset[[f"special_point_{first_coordinate(dataset)}_amplitude", "special_point_floquet_modulus"]].isel(special_point=np.flatnonzero(mask))


def multiplier_figure(dataset: xr.Dataset, restitution: float, index: int) -> DrawnFigure:
    """The largest Floquet multiplier modulus along every branch of one restitution (log scale)."""
    keys = [k for k in _classes(dataset, restitution) if k[0]]
    fig, (ax,) = new_figure(1, panel_height=4.0, columns=1, legend_rows=legend_rows(len(keys) + 1, 4))
    seen: set[tuple[int, int]] = set()
    looks = orbit_looks(dataset, restitution)
    for _label, branch in _branches(dataset, restitution):
        key = branch_class(branch["impacts_per_period"].values, branch["period_multiplicity"].values)
        if key[0] == 0:
            continue
        seen.add(key)
        _draw_branch(ax, branch["branch_frequency"].values, branch["floquet_modulus"].values, branch["stable"].values == 1, looks[key])
    ax.axhline(1.0, color="k", lw=0.8)
    specials = _specials(dataset, restitution)
    ax.scatter(specials["special_point_frequency"], specials["special_point_floquet_modulus"], s=30, facecolor="none", edgecolor="k", zorder=5, label="special points")
    finish_axes(ax, _FREQUENCY, "largest |Floquet multiplier|", f"R = {fmt(restitution, 'g')}{_model(dataset)}: stability along the branches", log=True)
    ax.set_ylim(0.2, MODULUS_TOP)
    figure_legend(fig, [ax], _class_legend(looks, seen), columns=4)
    caption = (f"Largest modulus of the Floquet multipliers along every impacting branch at R = {fmt(restitution, 'g')}{_model(dataset)} (log scale, "
               f"clipped at {fmt(MODULUS_TOP, 'g')}: next to a grazing point the multipliers grow without bound): an orbit is stable below 1 (the horizontal line); solid stable, dashed unstable; colour and marker: the orbit's period and impacts, as in the diagram; open circles: the special points.")  # fmt: skip
    return DrawnFigure(fig, f"multipliers_R{index}{dataset.attrs.get('diagram_tag', '')}", f"Floquet multipliers, R = {fmt(restitution, 'g')}{_model(dataset)}", caption)


def chart_figure(dataset: xr.Dataset) -> DrawnFigure:
    """The regime map of each sweep direction with the curves of special points in (frequency, clearance)."""
    directions = [str(d) for d in dataset["sweep"].values]
    fig, axes = new_figure(len(directions), panel_height=4.6, columns=len(directions), sharey=True, legend_rows=3)
    meanings = flags(dataset["chart_regime"])
    colours = [REGIME_COLOURS[MOTION_REGIMES[meaning]] for meaning in meanings]
    cmap = ListedColormap(colours)
    norm = BoundaryNorm(np.arange(-1.5, len(meanings) - 1), cmap.N)
    kinds = flags(dataset["chart_kind"])
    edge = [patheffects.withStroke(linewidth=3.4, foreground="white")]
    unit, scale = length_of(dataset)
    for ax, direction in zip(axes, directions):
        regime = dataset["chart_regime"].sel(sweep=direction)
        ax.pcolormesh(dataset["map_frequency"], dataset["map_clearance"] * scale, regime.values, cmap=cmap, norm=norm, shading="nearest", rasterized=True)
        for label in np.unique(dataset["chart_curve"].values):
            points = np.flatnonzero(dataset["chart_curve"].values == label)
            kind = kinds[int(dataset["chart_kind"].values[points[0]])]
            ax.plot(dataset["chart_frequency"].values[points], dataset["chart_clearance"].values[points] * scale, color=CURVE_COLOURS.get(kind, "0.3"),
                    lw=1.8, ls="--" if kind == "grazing" else "-", path_effects=edge, label=f"{KIND_NAMES.get(kind, kind)} curve")  # fmt: skip
        ax.axhline(float(dataset["clearance"]) * scale, color="k", lw=0.9, ls=":", path_effects=edge)
        ax.set_ylim(float(dataset["map_clearance"].min()) * scale, float(dataset["map_clearance"].max()) * scale)
        ax.set_xlim(float(dataset["map_frequency"].min()), float(dataset["map_frequency"].max()))
        finish_axes(ax, _FREQUENCY, f"clearance Delta [{unit}]" if ax is axes[0] else "", f"brute force sweeping {direction}")
    drawn = set(np.unique(dataset["chart_regime"].values).tolist())
    # a legend entry for each class some cell shows, no other (flag k - 1 is the k-th meaning)
    patches = [Patch(facecolor=colours[k], edgecolor="0.5", label=meaning.replace("_", " ")) for k, meaning in enumerate(meanings) if k - 1 in drawn]
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
