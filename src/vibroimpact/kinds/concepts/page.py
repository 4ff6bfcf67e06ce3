"""The page of a concepts study: which absorber concept, with which stop.

First the answer (the table of :mod:`~vibroimpact.kinds.concepts.page` with a verdict per concept and how each number is defined),
then the figures side by side (:mod:`~vibroimpact.kinds.concepts.page`), then what the continuation and the closed forms said.
Everything is read from the dataset.
"""

from __future__ import annotations

import html
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.lines import Line2D

from vibroimpact.reporting.coincide import Coincidence, Shared, coincidence_phrase, reveal_coincident
from vibroimpact.reporting.page import DrawnFigure, Section, Table, render_page, rendering, saved, write_page
from vibroimpact.reporting.record import stored_description
from vibroimpact.reporting.style import LINEAR_STYLE, STABLE_STYLE, UNSTABLE_STYLE, Caption, figure_legend, fmt, new_figure, finish_axes, legend_rows, plain_log, scale_phrase

__all__ = ["page_for", "concept_colour", "response_figure", "overview_figure", "impact_figure", "Column", "COLUMNS", "best_rows", "verdict", "verdicts", "concepts_table", "ConceptsPage", "write_concepts_report", "DEFINITIONS"]


# --------------------------------------------------------------------------------------------------------------------
# Figures of a concepts study: |X1| of each concept with its stable and unstable orbits, every concept's worst stable
# response and base force side by side, and what the impacts cost (bumper acceleration and force, impulse).
# --------------------------------------------------------------------------------------------------------------------

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


def _short(label: str) -> str:
    """How a caption names a concept: its tag, ``(b)`` of ``(b) light damping, ...``; the whole label if it has none."""
    return label.split(" ", 1)[0] if label.startswith("(") and ")" in label.split(" ", 1)[0] else label


def _isolated(y: np.ndarray) -> np.ndarray:
    """Finite values whose neighbours are both missing: a line does not show them, a marker must."""
    finite = np.isfinite(y)
    before = np.concatenate([[False], finite[:-1]])
    after = np.concatenate([finite[1:], [False]])
    return finite & ~before & ~after


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
    caption = Caption("|X1| (fundamental amplitude of the primary mass) against frequency, one panel per concept, in mm on a {scale}.")
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
        plain_log(ax)
    caption.add("band", f"The shaded stretch is the anti-resonance band ({fmt(dataset.attrs['band_low_Hz'], '.2f')}-{fmt(dataset.attrs['band_high_Hz'], '.2f')} Hz), where the lightly damped absorber without a stop keeps |X1| below the static deflection q/k1 = {fmt(1e3 * dataset.attrs['static_deflection_m'], '.2g')} mm (dotted grey line).")
    caption.add("worst", "The wide pale band is the worst stable motion found at each frequency, from which the table's peak and notch are taken.")
    figure_legend(fig, axes, columns=4)
    caption.lead = caption.lead.format(scale=scale_phrase(axes))
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
    curves: list[list[tuple[str, list[Line2D]]]] = [[], []]
    for i in range(dataset.sizes["concept"]):
        label = str(dataset["label"].values[i])
        for panel, ax, values in ((0, axes[0], dataset["worst_x1_amplitude"].values[i] * 1e3), (1, axes[1], dataset["worst_base_force_amplitude"].values[i])):
            curves[panel].append((_short(label), ax.plot(f, values, color=concept_colour(i), lw=1.5, label=label, gid=f"concept:{i}")))
            alone = _isolated(values)
            ax.plot(f[alone], values[alone], "o", ms=3.0, color=concept_colour(i))
    _band(axes[0], dataset)
    _band(axes[1], dataset, static=False)
    finish_axes(axes[0], FREQUENCY, "worst stable |X1| [mm]", "primary mass", log=True)
    finish_axes(axes[1], FREQUENCY, "worst stable base force, fundamental [N]", "force on the base", log=True)
    for ax in axes:
        ax.set_xlim(float(f[0]), float(f[-1]))
        plain_log(ax)
    coincide = coincidence_phrase(found for ax, drawn in zip(axes, curves) for found in reveal_coincident(ax, drawn))
    figure_legend(fig, axes, columns=2)
    caption = (
        f"Left: the worst stable |X1| found at each frequency, every concept in its colour ({scale_phrase(axes[:1])}; where no stable periodic orbit is "
        f"known only the simulated steady states are drawn, as dots). Right: the fundamental of the force on the base of that motion, through the suspension "
        "(k1 x1 + b1 x1') and the absolute stops (a relative stop's force stays between the masses). Shaded: the anti-resonance band; "
        "dotted grey: q/k1." + (f" {coincide}" if coincide else "")
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
    found: list[Coincidence | Shared] = []
    for ax, (variable, ylabel, title, log) in zip(axes, panels):
        _band(ax, dataset, static=False)
        curves: list[tuple[str, list[Line2D]]] = []
        for i in rows:
            values = dataset[variable].values[i]
            label = str(dataset["label"].values[i])
            curves.append((_short(label), ax.plot(fs, np.where(values > 0, values, np.nan) if log else values, "o-", ms=3.0, lw=1.0, color=concept_colour(i), label=label, gid=f"concept:{i}")))
        finish_axes(ax, FREQUENCY, ylabel, title, log=log)
        ax.set_xlim(float(fs[0]), float(fs[-1]))
        if log:
            plain_log(ax)
        found += reveal_coincident(ax, curves, zero="no impacts" if variable.startswith("simulated_") else "")
    figure_legend(fig, axes, columns=2)
    bumper = fmt(dataset.attrs.get("bumper_frequency_Hz"), ".4g")
    caption = (
        f"First three panels: steady states of each rigid stop's Kelvin-Voigt twin (Omega_b/2pi = {bumper} Hz, loss factor giving the stop's R) "
        "through the compliant engine: the largest deceleration in contact, the largest bumper force, and the largest force on the base "
        f"(k1 x1 + b1 x1' plus the absolute stops' force, from a dense replay of the steady state), against frequency ({scale_phrase(axes[:3])}; the first two "
        "have no point where nothing touches). Last two: the exact engine's rigid stops, total impulse and impacts per excitation period (chattering shows "
        "as many impacts). Shaded: the anti-resonance band."
    )
    coincide = coincidence_phrase(found)
    caption += f" {coincide}" if coincide else ""
    return DrawnFigure(fig, "concepts_impacts", "What the impacts cost: bumper acceleration and force, impulse", caption)


# --------------------------------------------------------------------------------------------------------------------
# The table a designer reads in a minute: one row per absorber concept, one column per figure of merit, the best
# value of each column marked, and a one-line verdict per concept written from the numbers.
# --------------------------------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Column:
    """One figure of merit of the table.

    Attributes
    ----------
    variable : str
        Dataset variable (per concept).
    title : str
        Column heading with units.
    scale : float
        Factor from the dataset's units to the table's (1e3: m -> mm).
    spec : str
        Number format.
    short : str
        How a verdict names it.
    where : str or None
        Variable with the frequency of the value [Hz], shown after it.
    stops_only : bool
        Only concepts with a stop have it (others show "no stop" and take no part in the ranking).
    """

    variable: str
    title: str
    scale: float
    spec: str
    short: str
    where: str | None = None
    stops_only: bool = False


COLUMNS = (
    Column("peak_x1_amplitude", "peak |X1| [mm]", 1e3, ".3g", "peak |X1|", "peak_x1_frequency"),
    Column("peak_base_force_amplitude", "peak base force, fundamental [N]", 1.0, ".3g", "base force", "peak_base_force_frequency"),
    Column("peak_base_force_bumper", "peak base force with bumpers, time domain [N]", 1.0, ".3g", "time-domain base force"),
    Column("peak_impact_acceleration", "peak impact acceleration, bumper [m/s²]", 1.0, ".0f", "impact acceleration", stops_only=True),
    Column("band_impact_fraction", "impacts in the anti-resonance band [% of band]", 100.0, ".0f", "impacts in the band", stops_only=True),
    Column("notch_depth", "notch depth, min |X1| / (q/k1) [dB]", 1.0, ".1f", "notch depth", "notch_frequency"),
)


def _values(dataset: xr.Dataset, column: Column) -> np.ndarray:
    values = np.asarray(dataset[column.variable].values, dtype=float) * column.scale
    if column.stops_only:
        values = np.where(_has_stops(dataset), values, np.nan)
    return values


def _has_stops(dataset: xr.Dataset) -> np.ndarray:
    return np.array([str(s) != "no stop" for s in dataset["stops"].values])


def best_rows(values: np.ndarray, tolerance: float = 1e-9) -> np.ndarray:
    """Rows holding the column's smallest finite value (within a relative ``tolerance``: ties all count)."""
    finite = np.isfinite(values)
    if not np.any(finite):
        return np.zeros(values.shape, dtype=bool)
    low = float(np.min(values[finite]))
    return finite & (values <= low + tolerance * max(abs(low), 1e-300))


def verdict(dataset: xr.Dataset, row: int) -> str:
    """One line on concept ``row``: where it is best and worst, and its key numbers, from the dataset."""
    best, worst = [], []
    for column in COLUMNS:
        values = _values(dataset, column)
        if not np.isfinite(values[row]) or np.sum(np.isfinite(values)) < 2:
            continue
        if best_rows(values)[row]:
            best.append(column.short)
        elif best_rows(-values)[row]:
            worst.append(column.short)
    peak = float(dataset["peak_x1_amplitude"].values[row])
    peaks = np.asarray(dataset["peak_x1_amplitude"].values, dtype=float)
    lowest = float(np.nanmin(peaks)) if np.any(np.isfinite(peaks)) else math.nan
    depth = float(dataset["notch_depth"].values[row])
    fraction = float(dataset["band_impact_fraction"].values[row])
    facts = [f"peak |X1| {fmt(peak * 1e3, '.3g')} mm" + (f" ({fmt(peak / lowest, '.2g')}x the lowest)" if math.isfinite(lowest) and peak > lowest * (1 + 1e-9) else "")]
    if math.isfinite(depth):
        facts.append(f"notch {fmt(depth, '+.0f')} dB" if depth < 0.0 else f"no notch (|X1| stays {fmt(depth, '.1f')} dB above q/k1 in the band)")
    if math.isfinite(fraction) and _has_stops(dataset)[row]:
        facts.append("no impacts in the band" if fraction == 0.0 else f"impacts on {fmt(100.0 * fraction, '.0f')} % of the band")
    unstable = str(dataset["unstable_stretches"].values[row])
    nonperiodic = str(dataset["nonperiodic_stretches"].values[row])
    if nonperiodic not in ("none", ""):
        facts.append(f"not periodic at {nonperiodic} Hz")
    elif unstable not in ("none", ""):
        facts.append(f"unstable orbits at {unstable} Hz")
    head = []
    if best:
        head.append("best " + ", ".join(best))
    if worst:
        head.append("worst " + ", ".join(worst))
    return ("; ".join(head) + ": " if head else "") + "; ".join(facts) + "."


def verdicts(dataset: xr.Dataset) -> list[str]:
    """:func:`verdict` of every concept, in the dataset's order."""
    return [verdict(dataset, row) for row in range(dataset.sizes["concept"])]


def concepts_table(dataset: xr.Dataset) -> str:
    """The HTML table: concept, absorber k2 and b2, the figures of merit (best marked ★ and bold), the unstable
    stretches and the verdict."""
    rows = dataset.sizes["concept"]
    has_stops = _has_stops(dataset)
    wrap = "style='white-space:normal'"
    head = "".join(f"<th {wrap}>{html.escape(c.title)}</th>" for c in COLUMNS)
    lines = [f"<table style='font-size:93%'><tr><th {wrap}>concept</th><th {wrap}>k2 [N/m], b2 [N s/m]</th>{head}<th {wrap}>unstable orbits [Hz]</th><th style='text-align:left'>verdict</th></tr>"]
    marks = {c.variable: best_rows(_values(dataset, c)) for c in COLUMNS}
    texts = verdicts(dataset)
    for row in range(rows):
        cells = []
        for column in COLUMNS:
            value = _values(dataset, column)[row]
            if column.stops_only and not has_stops[row]:
                text = "no stop"
            else:
                text = fmt(value, column.spec) or "n/a"
                if column.where is not None and math.isfinite(value):
                    text += f"<br><small>at {fmt(dataset[column.where].values[row], '.2f')} Hz</small>"
                if column.variable == "band_impact_fraction" and has_stops[row] and value > 0:
                    text += f"<br><small>{html.escape(str(dataset['band_impacts'].values[row]))} Hz</small>"
            if marks[column.variable][row]:
                text = f"<b>★ {text}</b>"
            cells.append(f"<td>{text}</td>")
        label = html.escape(str(dataset["label"].values[row]))
        absorber = str(dataset["absorber"].values[row])
        k2, b2 = (fmt(dataset[name].values[row], ".4g") for name in ("absorber_stiffness", "absorber_damping"))
        k2 += " <small>(DH)</small>" if "Den Hartog" in absorber.split(", b2")[0] else ""
        b2 += " <small>(DH)</small>" if "Den Hartog" in absorber.split(", b2")[-1] else ""
        unstable = html.escape(str(dataset["unstable_stretches"].values[row]))
        lines.append(f"<tr><td style='white-space:normal;min-width:10em'>{label}</td><td title='{html.escape(absorber)}'>{k2}<br>{b2}</td>{''.join(cells)}"
                     f"<td style='white-space:normal;min-width:6em'><small>{unstable}</small></td><td style='white-space:normal;min-width:17em;text-align:left'>{html.escape(texts[row])}</td></tr>")  # fmt: skip
    lines.append("</table>")
    return "".join(lines)

#: How the table's numbers are defined (HTML).
DEFINITIONS = (
    "<p>Definitions. <b>|X1|</b>: fundamental-harmonic amplitude of the primary mass. <b>Worst stable motion</b>: at each "
    "frequency the largest |X1| over every stable steady state found there: the linear motion where it clears the stops, the "
    "closed-form impact orbit where its Floquet multipliers are inside the unit circle, the stable stretches of the continued "
    "branches, and the exact engine's simulated steady state (an attractor, periodic or not). <b>Peak</b>: its largest value "
    "over the band. <b>Base force</b>: fundamental of k1 x1 + b1 x1' plus the force of the absolute stops (a stop between the "
    "masses pushes no force into the base). <b>With bumpers</b>: every rigid stop replaced by a Kelvin-Voigt bumper of the "
    "same clearance whose one collision restitutes the same R; the time-domain peak of the base force over the simulated "
    "steady states (from a dense replay of each, whose state after the replayed periods agrees with the compliant engine's "
    "to {mismatch} of the motion's scale; without a stop, the amplitude of the linear force), and the largest deceleration "
    "in contact. <b>Anti-resonance band</b>: {band}. <b>Impacts in the "
    "band</b>: share of the band where the motion impacts (wherever the linear motion hits a stop every steady motion "
    "impacts). <b>Notch depth</b>: 20 log10 of the smallest worst-stable |X1| in the band over q/k1 = {static} mm. "
    "★ bold: the best value of the column (smallest; deepest notch). (DH): Den Hartog's optimum. <b>Unstable orbits</b>: "
    "frequencies of the continued branches' and the closed form's unstable stretches.</p>"
)
#: Den Hartog's optimum as the page states it (HTML).
DEN_HARTOG = (
    "<p>Den Hartog's damped absorber (J. P. Den Hartog, <i>Mechanical Vibrations</i>, 4th ed., McGraw-Hill 1956, sec. 3.3; "
    "J. E. Brock, J. Appl. Mech. 13 (1946) A-284): with mu = m2/m1 and Omega_p = sqrt(k1/m1), the optimal tuning "
    "omega_a/Omega_p = 1/(1 + mu) makes the two fixed points P and Q of |X1| equally high, and the damping "
    "zeta = c2/(2 m2 Omega_p) = sqrt(3 mu / (8 (1 + mu)^3)) (Den Hartog's c_c = 2 m2 Omega_p, with the primary's natural "
    "frequency) makes the curve flat there; the table marks such values (DH). That optimum minimises the resonant peak; "
    "the scene's own k2 puts the anti-resonance (the smallest |X1| without a stop) at {anti} Hz instead, where the lightly damped "
    "absorber cuts |X1| far below q/k1. A stop between the masses (on x2 - x1) is the kind Ormondroyd and Den Hartog "
    "proposed (Trans. ASME APM-50-7, 1928), one against the base (on x2) the paper's.</p>"
)


class ConceptsPage:
    """The page of a ``concepts`` dataset."""

    def __init__(self, dataset: xr.Dataset) -> None:
        self.dataset = dataset

    def summary(self) -> str:
        """What was computed, for the page's heading."""
        d = self.dataset
        return (f"{d.sizes['concept']} absorber concepts; closed forms on {d.sizes['frequency']} frequencies, "
                f"steady states on {d.sizes['simulation_frequency']}, branches continued in frequency")  # fmt: skip

    def sections(self, out: Path) -> list[Section]:
        """The answer, the figures, the notes."""
        d = self.dataset
        low, high = float(d.attrs.get("band_low_Hz", math.nan)), float(d.attrs.get("band_high_Hz", math.nan))
        band = (f"{fmt(low, '.2f')}-{fmt(high, '.2f')} Hz around the anti-resonance at {fmt(d.attrs.get('anti_resonance_Hz'), '.2f')} Hz, where "
                "the scene's lightly damped absorber without a stop keeps |X1| below q/k1") if math.isfinite(low) else "none (|X1| never drops below q/k1)"  # fmt: skip
        mismatch = d["bumper_replay_mismatch"].values if "bumper_replay_mismatch" in d else np.zeros(0)
        worst = f"{np.nanmax(mismatch):.1e}" if np.any(np.isfinite(mismatch)) else "(no replay)"
        definitions = DEFINITIONS.format(band=html.escape(band), static=fmt(1e3 * float(d.attrs["static_deflection_m"]), ".2g"), mismatch=worst)
        intro = DEN_HARTOG.format(anti=fmt(d.attrs.get("anti_resonance_Hz"), ".2f"))
        answer = Section("Which absorber concept, with which stop", intro, tables=[Table("Concepts side by side", concepts_table(d) + definitions)])
        figures = Section("Figures", "", figures=saved((overview_figure(d), response_figure(d), impact_figure(d)), out))
        notes = "".join(f"<li><b>{html.escape(str(d['label'].values[i]))}</b>: {html.escape(str(d['notes'].values[i]) or 'closed forms only')}</li>" for i in range(d.sizes["concept"]))
        return [answer, figures, Section("How each concept was computed", f"<ul>{notes}</ul>")]


def write_concepts_report(dataset: xr.Dataset, out_dir: str | Path, jobs: int = 1) -> Path:
    """Write the figures and ``report.html`` of a concepts dataset into ``out_dir``; return the HTML path."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    page = ConceptsPage(dataset)
    with rendering(jobs):
        sections = page.sections(out)
    text = str(dataset.attrs.get("scene", ""))
    paragraphs = [stored_description(text), f"vibroimpact {dataset.attrs.get('vibroimpact_version', '?')}; {page.summary()}."]
    return write_page(out / "report.html", render_page(f"Study '{dataset.attrs.get('scene_name', '')}'", paragraphs, sections, text))


def page_for(dataset: xr.Dataset) -> ConceptsPage:
    """The page of a concepts dataset."""
    return ConceptsPage(dataset)
