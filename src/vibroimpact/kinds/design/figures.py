"""Figures of a design study, everything read from the dataset.

* :func:`search_figure` (:mod:`vibroimpact.kinds.design.search_map`): the objective over the design variables.
* :func:`response_figure`: the compared designs' worst stable motion side by side, then each design with every
  coexisting motion (contact-free, both roots of the period-1 impact orbit, the continued branches), its worst case
  and the operating constraint.
* :func:`robustness_figure`: each compared design's worst case under every mistuning sample, as an empirical
  distribution.

Every value is the objective's measure (|X1|, |X2|, |F|: :mod:`vibroimpact.kinds.design.quantity`), in its page
unit, except the operating constraint's, which is its own measure.

Colours: one per compared design (:data:`DESIGN_COLOURS`, Okabe-Ito, safe for colour-blind readers); line styles
tell the motions apart, markers the special designs and points.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.lines import Line2D
from numpy.typing import NDArray

from vibroimpact.kinds.design.answer import design_evaluation, design_titles, design_text, mistuning_spreads, present_designs, sample_counts, screen_words
from vibroimpact.kinds.design.quantity import constraint_quantity, objective_quantity, operating_limit
from vibroimpact.kinds.design.palette import CERTIFIED_COLOUR, DESIGN_COLOURS, DESIGN_MARKERS, LIMIT_COLOUR, OBJECTIVE_PERCENTILE, PATH_COLOUR
from vibroimpact.kinds.design.search_map import search_figure
from vibroimpact.reporting.page import DrawnFigure
from vibroimpact.reporting.style import STABLE_STYLE, UNSTABLE_STYLE, Caption, figure_legend, finish_axes, fmt, legend_rows, new_figure, plain_log, readable_scale

__all__ = ["design_figures", "search_figure", "response_figure", "robustness_figure", "worst_stable",
           "DESIGN_COLOURS", "DESIGN_MARKERS", "PATH_COLOUR", "CERTIFIED_COLOUR", "LIMIT_COLOUR", "OBJECTIVE_PERCENTILE"]  # fmt: skip

_FREQUENCY = "excitation frequency [Hz]"
_OPERATING = {"color": "0.3", "lw": 1.0, "ls": (0, (6, 2, 1, 2))}


def design_figures(dataset: xr.Dataset) -> list[DrawnFigure]:
    """Every figure of the page, in order."""
    return [search_figure(dataset), response_figure(dataset), robustness_figure(dataset)]


def worst_stable(dataset: xr.Dataset, design: int) -> NDArray[np.float64]:
    """The largest objective's measure [m or N] of the stable closed-form motions of a compared design at each response frequency (NaN
    where none is stable)."""
    d = dataset
    curves = [np.where(d["response_linear_fits"].values[design] == 1, d["response_linear"].values[design], np.nan)]
    curves += [np.where(d[f"response_{n}_stable"].values[design] == 1, d[f"response_{n}"].values[design], np.nan) for n in ("impact_plus", "impact_minus")]
    return np.fmax.reduce(curves)


def _worst_point(d: xr.Dataset, k: int) -> tuple[float, float]:
    """(frequency [Hz], the objective's measure [m or N]) of a compared design's nominal worst case: the screen's, or the linear peak's."""
    value = float(d["design_sample_value"].values[k, 0])
    evaluation = design_evaluation(d, k)
    if evaluation >= 0:
        return float(d["sample_frequency"].values[evaluation, 0]), value
    curve = d["response_linear"].values[k]
    return (float(d["response_frequency"].values[int(np.nanargmax(curve))]), value) if np.any(np.isfinite(curve)) else (math.nan, math.nan)


def _operating_drawn(d: xr.Dataset) -> bool:
    """Whether the scene sets an operating limit at a frequency inside the responses' band (the panels' x range): the
    line and bar of :func:`_operating` are drawn, and the legend and caption name them, only then."""
    at, f = float(d.attrs.get("operating_frequency_Hz", math.nan)), d["response_frequency"].values
    return math.isfinite(at) and math.isfinite(operating_limit(d)) and float(f[0]) <= at <= float(f[-1])


def _operating(ax: Axes, d: xr.Dataset) -> None:
    """The operating frequency (vertical line) and the allowed value there (a bar, where the constraint limits the
    objective's measure: the axes' own), when the scene sets a limit at a frequency the panels show."""
    at, limit, c = float(d.attrs.get("operating_frequency_Hz", math.nan)), operating_limit(d), constraint_quantity(d)
    if _operating_drawn(d):
        ax.axvline(at, **_OPERATING, zorder=1)
        if c.name == objective_quantity(d).name:
            ax.plot([at], [c.value(limit)], marker="_", ms=22, mew=2.5, color="k", ls="none", zorder=6)


def _design_panel(ax: Axes, d: xr.Dataset, k: int) -> tuple[list[float], set[str]]:
    """Every motion of compared design ``k`` (nominal): the values drawn [the page's unit] (for the axis limits) and which
    kinds of :data:`_LOOKS` were drawn (for the legend)."""
    f, colour, q = d["response_frequency"].values, DESIGN_COLOURS[k], objective_quantity(d)
    linear, fits = q.value(d["response_linear"].values[k]), d["response_linear_fits"].values[k] == 1
    ax.plot(f, np.where(fits, linear, np.nan), color=colour, **STABLE_STYLE)
    ax.plot(f, np.where(~fits, linear, np.nan), color="0.6", lw=0.8, ls=":")
    drawn, kinds = [linear[fits]], {"contact_free"} | ({"crossing"} if np.any(~fits & np.isfinite(linear)) else set())
    for name in ("impact_plus", "impact_minus"):
        x, state = q.value(d[f"response_{name}"].values[k]), d[f"response_{name}_stable"].values[k]
        ax.plot(f, np.where(state == 1, x, np.nan), color=colour, lw=2.4)
        ax.plot(f, np.where(state == 0, x, np.nan), color=colour, **UNSTABLE_STYLE)
        drawn.append(x[state >= 0])
        kinds |= {kind for kind, flag in (("impact_stable", 1), ("impact_unstable", 0)) if np.any(state == flag)}
    evaluation = design_evaluation(d, k)
    rows = np.flatnonzero((d["certificate_evaluation"].values == evaluation) & (d["certificate_sample"].values == 0)) if evaluation >= 0 else []
    for r in rows:
        bf, ba, bs = (d[f"branch_{n}"].values[r] for n in ("frequency", "amplitude", "stable"))
        for flag, kind, look in ((0, "branch_unstable", {"color": "0.65", "ms": 1.6, "zorder": 2}), (1, "branch_stable", {"color": "0.15", "ms": 2.2, "zorder": 3})):
            on = (bs == flag) & np.isfinite(ba)
            ax.plot(bf[on], q.value(ba[on]), ".", ls="none", **look)
            kinds |= {kind} if np.any(on) else set()
        drawn.append(q.value(ba[np.isfinite(ba)]))
        worst, where = float(d["certificate_worst"].values[r]), float(d["certificate_frequency"].values[r])
        if math.isfinite(worst):
            ax.plot([where], [q.value(worst)], marker="*", ms=14, color=CERTIFIED_COLOUR, mec="k", mew=0.6, ls="none", zorder=7, clip_on=False)  # whole at a band edge
            kinds.add("certified")
    where, value = _worst_point(d, k)
    ax.plot([where], [q.value(value)], marker="o", ms=12, mfc="none", mec="k", mew=1.4, ls="none", zorder=6, clip_on=False)  # whole at a band edge
    return [float(v) for part in drawn for v in np.asarray(part).ravel() if np.isfinite(v) and v > 0.0], kinds


#: The legend's entries for the motions and points, by the kind :func:`_design_panel` says it drew.
_LOOKS = {
    "contact_free": ({"color": "k", **STABLE_STYLE}, "contact-free motion, clears the stop"),
    "crossing": ({"color": "0.6", "lw": 0.8, "ls": ":"}, "contact-free motion crossing the stop (not a motion)"),
    "impact_stable": ({"color": "k", "lw": 2.4}, "period-1 impact orbit, stable (either root)"),
    "impact_unstable": ({"color": "k", **UNSTABLE_STYLE}, "period-1 impact orbit, unstable"),
    "branch_stable": ({"color": "0.15", "marker": ".", "ls": "none"}, "continued branch, stable"),
    "branch_unstable": ({"color": "0.65", "marker": ".", "ls": "none"}, "continued branch, unstable"),
    "worst": ({"marker": "o", "ms": 10, "mfc": "none", "mec": "k", "mew": 1.4, "ls": "none"}, "worst case over the band (screen)"),
    "certified": ({"marker": "*", "ms": 12, "color": CERTIFIED_COLOUR, "mec": "k", "mew": 0.6, "ls": "none"}, "certified worst case (continuation)"),
}


def response_figure(dataset: xr.Dataset) -> DrawnFigure:
    """The compared designs' worst stable motion (the objective's measure) side by side, then each one's every motion (module docstring)."""
    d = dataset
    f = d["response_frequency"].values
    present = present_designs(d)
    compare = len(present) > 1
    q, c, limit = objective_quantity(d), constraint_quantity(d), operating_limit(d)
    fig, axes = new_figure(len(present) + compare, panel_height=3.3, legend_rows=legend_rows(len(present) + len(_LOOKS) + 1, 3))
    first_scale = ""
    if compare:
        ax = axes[0]
        worst = [q.value(worst_stable(d, k)) for k in present]
        finite = np.concatenate([w[np.isfinite(w) & (w > 0.0)] for w in worst])
        first_scale = readable_scale(float(np.min(finite)), float(np.max(finite))) if finite.size else "log"
        for k in sorted(present, reverse=True):  # the recommended design on top, drawn narrower than the others
            ax.plot(f, worst[present.index(k)], color=DESIGN_COLOURS[k], lw=1.8 if k == 0 else 3.2, zorder=3 - k)
            ax.plot(*(np.array(_worst_point(d, k)) * (1.0, q.scale)), marker="o", ms=12, mfc="none", mec="k", mew=1.4, ls="none", zorder=6, clip_on=False)
        _operating(ax, d)
        ax.set_xlim(float(f[0]), float(f[-1]))
        finish_axes(ax, _FREQUENCY, q.label, "Worst stable motion of each design (no mistuning)", log=first_scale == "log")
        if first_scale == "log":
            plain_log(ax)
    kinds = {"worst"}
    shown: list[float] = []
    design_axes = list(zip(axes[int(compare) :], present))
    for ax, k in design_axes:
        values, drawn = _design_panel(ax, d, k)
        kinds |= drawn
        shown += list(values)
        _operating(ax, d)
        ax.set_xlim(float(f[0]), float(f[-1]))
    # one y range for the designs' own panels, so that they compare by eye; log only over a decade or more
    low, high = (0.7 * min(shown), 1.6 * max(shown)) if shown else (math.nan, math.nan)
    scale = readable_scale(low, high) if shown else "log"
    for ax, k in design_axes:
        if shown:
            ax.set_ylim(low, high)
        finish_axes(ax, _FREQUENCY, q.label, f"{design_titles(d)[k][:1].upper()}{design_titles(d)[k][1:]}: {design_text(d, k)}", log=scale == "log")
        if scale == "log":
            plain_log(ax)
    entries = [Line2D([], [], color=DESIGN_COLOURS[k], lw=2.4, label=f"{design_titles(d)[k]}: {design_text(d, k)}") for k in present]
    entries += [Line2D([], [], **look, label=label) for kind, (look, label) in _LOOKS.items() if kind in kinds]
    scaled = f"{scale} scale" if first_scale in ("", scale) else f"the first panel on a {first_scale} scale, the others on a {scale} scale"
    caption = Caption(f"{q.symbol} ({q.description}, {q.unit}, {scaled}) of the compared designs without mistuning, the designs' own panels on one y range; colour: whose design.")
    if compare:
        caption.add("compare", f"The first panel overlays each design's worst stable motion at each frequency (gaps: no {screen_words(d)} period-1 motion is stable there); the others show every motion of one design.")
    roots = "the bumper orbits grown from both roots of the rigid twin's impulse equation, where its shots converged" if screen_words(d) == "bumper" else "both roots of the impulse equation, where admissible"
    caption.add("lines", f"Thin solid: the contact-free motion where it clears the stop; thick solid and dashed: the stable and unstable period-1 impact orbits ({roots}); dotted grey: the contact-free motion where it would cross the stop, not a motion.")
    if kinds & {"branch_stable", "branch_unstable"}:
        caption.add("branches", f"Dots: orbits of the branches continued from the {'bumper orbits shot from the rigid twin' + chr(39) + 's closed forms' if screen_words(d) == 'bumper' else 'closed-form ones'} (dark stable, light unstable).")
    if "certified" in kinds:
        caption.add("certified", "The vermillion star is the certified worst case over the band (continuation, no mistuning).")
    caption.add("worst", "The black ring is the worst case over the band without mistuning (the screen's value; the linear absorber's band peak).")
    if math.isfinite(limit):
        at = fmt(d.attrs["operating_frequency_Hz"], ".4g")
        allowed = f"{fmt(c.value(limit), '.3g')} {c.unit}"
        if not _operating_drawn(d):  # outside the band the panels show: not drawn, and said so
            caption.add("operating", f"The operating frequency, {at} Hz, lies outside the band drawn ({fmt(f[0], 'g')}-{fmt(f[-1], 'g')} Hz): its allowed {c.symbol} ({allowed}) is not drawn.")
        elif c.name == q.name:
            entries.append(Line2D([], [], **_OPERATING, marker="_", ms=14, mew=2.5, mec="k", label=f"operating frequency {at} Hz and the allowed {c.symbol} there"))
            caption.add("operating", f"The dash-dotted line is the operating frequency, {at} Hz, and the black bar on it the allowed {c.symbol} there ({allowed}).")
        else:  # the constraint limits another measure than these axes show: its limit is not drawn on them
            entries.append(Line2D([], [], **_OPERATING, label=f"operating frequency {at} Hz (its constraint limits {c.symbol}, not drawn)"))
            caption.add("operating", f"The dash-dotted line is the operating frequency, {at} Hz, where the operating constraint limits {c.symbol} (allowed {allowed}), a measure these axes do not show.")
    figure_legend(fig, axes, extra=entries, columns=3)
    return DrawnFigure(fig, "design_response", "The compared designs' frequency responses: every coexisting motion", caption.text())


# ----------------------------------------------------------------------------------------- robustness
def _certified_above(d: xr.Dataset, k: int, screened: NDArray[np.float64]) -> list[tuple[int, float]]:
    """(sample, certified worst case [the page's unit]) of compared design ``k``'s certificates whose value is above
    the screen's (``screened`` [the page's unit] per sample)."""
    evaluation = design_evaluation(d, k)
    out = []
    for r in np.flatnonzero(d["certificate_evaluation"].values == evaluation) if evaluation >= 0 else ():
        sample, certified = int(d["certificate_sample"].values[r]), objective_quantity(d).value(float(d["certificate_worst"].values[r]))
        if sample >= 0 and math.isfinite(certified) and math.isfinite(float(screened[sample])) and certified > float(screened[sample]) * (1.0 + 1e-6):  # the box's worst point is no sample
            out.append((sample, certified))
    return out


def robustness_figure(dataset: xr.Dataset) -> DrawnFigure:
    """The worst case of each compared design under every mistuning sample, as an empirical distribution, the
    nominal sample marked."""
    d = dataset
    q = objective_quantity(d)
    values = q.value(d["design_sample_value"].values)
    samples = d.sizes["sample"]
    fig, axes = new_figure(1, panel_height=3.6, legend_rows=legend_rows(4, 2))
    ax = axes[0]
    constant, raised = [], []
    for k in range(values.shape[0]):
        row = np.sort(values[k][np.isfinite(values[k])])
        if not row.size:
            continue
        share = np.arange(row.size + 1) / row.size
        above = _certified_above(d, k, values[k])
        note = f" (screened; certified up to {fmt(max(c for _, c in above), '.3g')} {q.unit})" if above else ""
        ax.step(np.r_[row[0], row], share, where="post", color=DESIGN_COLOURS[k], lw=2.0,
                label=f"{design_titles(d)[k]}: worst {fmt(row[-1], '.3g')} {q.unit}, median {fmt(float(np.median(row)), '.3g')} {q.unit}{note}")  # fmt: skip
        nominal = float(values[k, 0])
        if math.isfinite(nominal):
            ax.plot([nominal], [np.searchsorted(row, nominal, side="right") / row.size], "o", ms=8, color=DESIGN_COLOURS[k], mec="k", mew=1.0, zorder=5)
        for sample, certified in above:  # the screen missed this sample's worst motion: the certified one, joined to it
            y = np.searchsorted(row, float(values[k, sample]), side="right") / row.size
            ax.plot([float(values[k, sample]), certified], [y, y], color=CERTIFIED_COLOUR, lw=1.0, ls=":", zorder=4)
            ax.plot([certified], [y], "*", ms=13, color=CERTIFIED_COLOUR, mec="k", mew=0.6, zorder=6)
            raised.append((design_titles(d)[k], sample, certified))
        if row[-1] - row[0] <= 1e-9 * row[-1] and row.size > 1:
            constant.append(design_titles(d)[k])
    ax.set_ylim(-0.03, 1.05)
    finite = np.r_[values[np.isfinite(values) & (values > 0.0)], [c for _, _, c in raised]]
    if finite.size and np.max(finite) > 4.0 * np.min(finite):  # a design far worse than the others: a log axis keeps both legible
        ax.set_xscale("log")
        plain_log(ax, "x")
    finish_axes(ax, f"worst case {q.symbol} over the band [{q.unit}]", "share of samples at or below", "Worst case under mistuning: empirical distribution over the samples")
    nominal = Line2D([], [], marker="o", ms=8, color="0.7", mec="k", mew=1.0, ls="none", label="the nominal design (sample 0)")
    extra = [nominal] + ([Line2D([], [], marker="*", ms=13, color=CERTIFIED_COLOUR, mec="k", mew=0.6, ls=":", lw=1.0, label="certified worst case of a sample, where above the screen's")] if raised else [])
    figure_legend(fig, axes, extra=extra, columns=2)
    spreads = mistuning_spreads(d)
    if samples > 1 and spreads:
        corners, random = sample_counts(d)
        box = f", the {corners} corners of the tolerance box" if corners else ""
        drawn = f"{samples} samples: the nominal design{box} and {random} of a Latin hypercube (seed {d.attrs.get('mistuning_seed', '?')}) over {' and '.join(s.text() for s in spreads)}"
    else:
        drawn = "one sample: no mistuning, the nominal design only"
    caption = Caption(f"Each compared design's largest stable {q.symbol} over the band under each mistuning sample, as the share of samples at or below a value (a step per sample); {drawn}.")
    caption.add("nominal", "Dots mark the nominal design's value on each curve.")
    if raised:
        which = "; ".join(f"{title}, sample {sample}: {fmt(value, '.4g')} {q.unit}" for title, sample, value in raised)
        screen = ("a coarse brute force: few frequencies and starts" if np.any(d["sample_motion"].values == 3) else
                  "period-1 bumper orbits" if d.attrs.get("screen") == "bumper_orbits" else "the closed forms: period-1 motions")  # fmt: skip
        caption.add("certified", f"The curves are the screen's values ({screen}). Vermillion stars mark where the certification (continuation and brute force) found a larger motion under a certified sample, joined to the screen's value ({which}): the distribution above the screen's values is not known for the other samples.")
    if constant:
        caption.add("constant", f"The same value under every sample for {' and '.join(t if t.startswith('the ') else 'the ' + t for t in constant)}: the mistuned scalars do not change it (a stop that is never reached, or none).")
    return DrawnFigure(fig, "design_robustness", "Worst case under mistuning", caption.text())
