"""The page of a validation study: the table of published against computed values, and the case's figure.

Everything is read from the dataset (:mod:`vibroimpact.kinds.validation.formulas` describes it): the rows of the
``check`` dimension make the table (quantity, published, computed, relative error, tolerance, pass), the attributes
``validation_case``, ``validation_source`` and ``validation_notes`` the introduction, and the case's own variables
its figure (:mod:`vibroimpact.kinds.validation.page`).
"""

from __future__ import annotations

import html
import math
from pathlib import Path

import numpy as np
import xarray as xr

from vibroimpact.reporting.page import DrawnFigure, Section, Table, render_page, saved, write_page
from vibroimpact.reporting.record import stored_description
from vibroimpact.reporting.style import figure_legend, finish_axes, legend_rows, new_figure

__all__ = ["page_for", "validation_figure", "ValidationPage", "validation_table", "write_validation_report"]


# --------------------------------------------------------------------------------------------------------------------
# The figure of each validation case, drawn from its dataset: the published curve or thresholds beside the
# project's continued orbits, runs or impacts.
# --------------------------------------------------------------------------------------------------------------------

_STABLE = {"marker": "o", "ms": 4.5, "ls": "none", "color": "C0"}
_UNSTABLE = {"marker": "o", "ms": 4.5, "ls": "none", "mfc": "white", "color": "C0"}
_PUBLISHED = {"color": "k", "lw": 1.2}
_THRESHOLD = {"color": "C3", "lw": 1.2, "ls": "--"}


def validation_figure(dataset: xr.Dataset) -> DrawnFigure | None:
    """The case's figure (None for a case without one)."""
    case = str(dataset.attrs.get("validation_case", ""))
    draw = {"budd_dux": _budd_dux, "bouncing_ball": _bouncing_ball, "zeno": _zeno, "grazing": _grazing, "relative_stop": _relative_stop}.get(case)
    return draw(dataset) if draw is not None else None


def _stability(ax, x: np.ndarray, y: np.ndarray, stable: np.ndarray, label: str) -> None:
    """Continued points: filled where stable, hollow where unstable."""
    ax.plot(x[stable], y[stable], label=f"{label}, stable", **_STABLE)
    ax.plot(x[~stable], y[~stable], label=f"{label}, unstable", **_UNSTABLE)


def _computed(dataset: xr.Dataset, word: str) -> float:
    """The computed value of the first check whose quantity starts with ``word`` (NaN: none)."""
    for i, quantity in enumerate(dataset["quantity"].values):
        if str(quantity).startswith(word):
            return float(dataset["computed"].values[i])
    return float("nan")


def _budd_dux(ds: xr.Dataset) -> DrawnFigure:
    fig, (ax, zoom) = new_figure(2, panel_height=4.6, legend_rows=legend_rows(5))
    sigma, velocity = ds["clearance"].values, ds["impact_velocity"].values
    stable = ds["stable"].values == 1
    pd_sigma, pd_velocity = float(ds.attrs["period_doubling_clearance"]), float(ds.attrs["period_doubling_velocity"])
    for panel in (ax, zoom):
        panel.plot(ds["ellipse_clearance"].values, ds["ellipse_velocity"].values, label="Budd & Dux's ellipse", **_PUBLISHED)
        _stability(panel, sigma, velocity, stable, "continued orbit")
        panel.plot([pd_sigma], [pd_velocity], marker="*", ms=14, ls="none", color="C3", label="period doubling, closed form")
        panel.plot([_computed(ds, "sigma at the period doubling")], [_computed(ds, "V at the period doubling")], marker="x", ms=10, mew=2, ls="none", color="k", label="period doubling, located by continuation")
    ax.axhline(0.0, color="0.6", lw=0.8)
    finish_axes(ax, "sigma (stop position)", "impact velocity V", "Period-one orbits: the ellipse and the continued branch")
    span = max(float(np.ptp(sigma)), 1e-3)
    zoom.set_xlim(sigma.min() - 0.05 * span, sigma.max() + 0.05 * span)
    zoom.set_ylim(0.0, 1.1 * float(np.nanmax(velocity)))
    finish_axes(zoom, "sigma (stop position)", "impact velocity V", "The continued range")
    figure_legend(fig, [ax])
    worst = float(np.nanmax(np.abs(velocity - ds["published_velocity"].values) / np.abs(ds["published_velocity"].values)))
    caption = (f"Impact velocity V of the period-one orbit of x'' + x = cos(w t) (w = {ds.attrs['forcing_frequency']:g}, r = {ds.attrs['restitution']:g}) "
               f"against the stop position sigma: {sigma.size} points continued by the project (filled: stable), on Budd & Dux's ellipse "
               f"to {worst:.1e} relative; the star is the period doubling's closed form, the cross where the continuation located it.")  # fmt: skip
    return DrawnFigure(fig, "validation_budd_dux", "Budd & Dux's ellipse and the continued period-one orbits", caption)


def _bouncing_ball(ds: xr.Dataset) -> DrawnFigure:
    fig, (ax,) = new_figure(1, panel_height=5.0, columns=1, legend_rows=legend_rows(6))
    _stability(ax, ds["acceleration"].values, ds["impact_phase"].values, ds["stable"].values == 1, "continued period-one orbit")
    if "brute_acceleration" in ds.coords:
        gamma = np.repeat(ds["brute_acceleration"].values[:, None], ds.sizes["brute_impact"], axis=1)
        ax.plot(gamma.ravel(), ds["brute_impact_phase"].values.ravel(), ".", ms=2.0, color="k", zorder=3, label="brute force: impacts of the last periods")
    ax.axvline(float(ds.attrs["existence_acceleration"]), label="existence pi (1-e)/(1+e)", **_THRESHOLD)
    ax.axvline(float(ds.attrs["period_doubling_acceleration"]), color="C3", lw=1.2, ls="-.", label="period doubling, exact table (issue 12)")
    ax.axvline(float(ds.attrs["high_bounce_period_doubling_acceleration"]), color="0.5", lw=1.0, ls=":", label="period doubling, Holmes' high-bounce map")
    ax.set_ylim(-np.pi, np.pi)
    finish_axes(ax, "Gamma = A w^2 / g", "table phase at the impact theta [rad]", "The bouncing ball: bifurcation diagram")
    figure_legend(fig, [ax], columns=3)
    caption = (f"The table's phase at each impact of the ball (e = {ds.attrs['restitution']:g}; table at A sin theta) against the table's acceleration Gamma: "
               "black dots are the brute-force sweep's impacts over its last periods, circles the continued period-one orbit (filled: stable; the "
               "branch turns at the fold where the orbit is born, its unstable half below). The red lines are the published existence threshold and the "
               "exact table's period doubling, where one phase per period becomes two; the dotted grey line is where Holmes' high-bounce map would double.")  # fmt: skip
    return DrawnFigure(fig, "validation_bouncing_ball", "The bouncing ball's period-one orbit: existence and period doubling", caption)


def _zeno(ds: xr.Dataset) -> DrawnFigure:
    fig, (ax, err) = new_figure(2, panel_height=4.2, legend_rows=legend_rows(3))
    t_zeno = float(ds.attrs["zeno_time_s"])
    if "trace_time" in ds.coords:
        ax.plot(ds["trace_time"].values, ds["trace_height"].values, color="C0", lw=1.0, label="height, exact engine")
    ax.axvline(t_zeno, label="Zeno time sqrt(2h/g)(1+e)/(1-e)", **_THRESHOLD)
    finish_axes(ax, "time [s]", "height above the table [m]", "The dropped ball")
    engines = [str(e) for e in ds["engine"].values]
    errors = np.abs(ds["sticking_time"].values - t_zeno) / t_zeno
    tolerances = [float(ds["tolerance"].values[i]) for i, q in enumerate(ds["quantity"].values) if str(q).startswith("Zeno time")]
    positions = np.arange(len(engines))
    err.bar(positions, np.maximum(errors, 1e-18), color="C0", label="|sticking time - Zeno time| / Zeno time")
    err.plot(positions, tolerances, "_", ms=30, mew=2, color="C3", label="tolerance")
    err.axhline(float(ds.attrs["deficit_high_s"]) / t_zeno, color="0.4", lw=1.0, ls=":")
    err.set_xticks(positions, engines, rotation=35, ha="right")
    finish_axes(err, "", "relative error", "Each engine's sticking time", log=True)
    figure_legend(fig, [ax, err], columns=3)
    caption = (f"A ball dropped from rest on a fixed table comes to rest at the Zeno time {t_zeno:.6g} s. Right: how far each rigid-stop engine's sticking "
               f"time is from it, against its tolerance; the dotted line is the bound the sticking velocity sets (2 e v_s / (g (1 - e)) = "
               f"{float(ds.attrs['deficit_high_s']):.2e} s, drawn as {float(ds.attrs['deficit_high_s']) / t_zeno:.2e} of the Zeno time).")  # fmt: skip
    return DrawnFigure(fig, "validation_zeno", "The Zeno time, engine by engine", caption)


def _grazing(ds: xr.Dataset) -> DrawnFigure:
    fig, (ax, speed) = new_figure(2, panel_height=4.2, legend_rows=legend_rows(4))
    amplitude = ds["amplitude"].values
    stable = ds["stable"].values == 1
    graze = float(ds.attrs["grazing_amplitude_N"])
    ax.plot(amplitude, amplitude * float(ds.attrs["receptance_modulus_m_per_N"]), label="linear amplitude A |H|", **_PUBLISHED)
    _stability(ax, amplitude, ds["largest_displacement"].values, stable, "continued orbit")
    ax.axhline(float(ds.attrs["clearance_m"]), color="0.5", lw=1.0, label="stop d")
    for panel in (ax, speed):
        panel.axvline(graze, label="grazing d |k - m w^2 + j c w|", **_THRESHOLD)
    ax.set_ylim(0.0, 1.3 * float(ds.attrs["clearance_m"]))
    finish_axes(ax, "force amplitude A [N]", "largest x over the orbit [m]", "Largest displacement")
    _stability(speed, amplitude, ds["impact_velocity"].values, stable, "continued orbit")
    finish_axes(speed, "force amplitude A [N]", "impact speed [m/s]", "Impact speed")
    figure_legend(fig, [ax, speed])
    caption = ("The forced oscillator's orbit continued in the force amplitude: below the grazing amplitude it is the linear steady state (its largest "
               f"displacement A |H|); at A = {graze:.8g} N it touches the stop and impacts begin.")  # fmt: skip
    return DrawnFigure(fig, "validation_grazing", "Where the forced oscillator starts to impact", caption)


def _relative_stop(ds: xr.Dataset) -> DrawnFigure:
    fig, (ax, err) = new_figure(2, panel_height=4.2, legend_rows=legend_rows(4))
    ax.plot(ds["trace_time"].values, ds["trace_relative_displacement"].values * 1e3, color="C0", lw=1.0, label="x2 - x1")
    if "clearance_m" in ds.attrs:
        ax.axhline(float(ds.attrs["clearance_m"]) * 1e3, color="0.5", lw=1.0, label="stop Delta")
    finish_axes(ax, "time [s]", "x2 - x1 [mm]", "The last periods")
    times = ds["impact_time"].values
    for name, colour, label in (("momentum_error", "C0", "momentum"), ("restitution_error", "C1", "relative velocity"), ("impulse_error", "C2", "impulse")):
        err.plot(times, np.maximum(ds[name].values, 1e-18), ".", ms=3, color=colour, label=f"{label} error per impact")
    tolerance = float(np.nanmax(np.where(ds["passed"].values != 2, ds["tolerance"].values, np.nan)))
    err.axhline(tolerance, label="tolerance", **_THRESHOLD)
    finish_axes(err, "time of the impact [s]", "relative error", f"Each of {times.size} impacts", log=True)
    figure_legend(fig, [ax, err])
    caption = ("A stop between absorber and primary mass: the relative displacement over the last periods, and at every impact of the run the change "
               "of total momentum and the restituted relative velocity against Newton's law, from an independent propagation of the flight before it.")
    return DrawnFigure(fig, "validation_relative_stop", "The relative stop, impact by impact", caption)

#: What each flag of ``passed`` shows.
_VERDICT = {0: "<b style='color:#b00'>fail</b>", 1: "<span style='color:#070'>pass</span>", 2: "<span style='color:#777'>shown only</span>"}


def _number(value: float) -> str:
    """A table cell: 12 significant digits, empty for NaN."""
    return "" if not math.isfinite(value) else f"{value:.12g}"


def _error(value: float) -> str:
    return "" if not math.isfinite(value) else f"{value:.2e}"


def validation_table(dataset: xr.Dataset) -> Table:
    """The table of every compared quantity."""
    header = "".join(f"<th>{column}</th>" for column in ("quantity", "published", "computed", "unit", "relative error", "tolerance", "pass", "note"))
    rows = []
    for i in range(dataset.sizes["check"]):
        row = dataset.isel(check=i)
        cells = (
            html.escape(str(row["quantity"].values)),
            _number(float(row["published"])),
            _number(float(row["computed"])),
            html.escape(str(row["unit"].values)),
            _error(float(row["relative_error"])),
            _error(float(row["tolerance"])),
            _VERDICT.get(int(row["passed"]), "?"),
            html.escape(str(row["note"].values)),
        )
        wrap = "style='white-space:normal;text-align:left;min-width:{}em'"
        rows.append(f"<tr><td {wrap.format(16)}>{cells[0]}</td>" + "".join(f"<td>{cell}</td>" for cell in cells[1:-1]) + f"<td {wrap.format(18)}>{cells[-1]}</td></tr>")
    return Table("Published against computed", f"<table><tr>{header}</tr>{''.join(rows)}</table>")


class ValidationPage:
    """The page of a ``validation`` dataset."""

    def __init__(self, dataset: xr.Dataset) -> None:
        self.dataset = dataset
        self.case = str(dataset.attrs.get("validation_case", "?"))

    def counts(self) -> tuple[int, int]:
        """(checks passed, checks) without the informative rows."""
        flags = np.asarray(self.dataset["passed"].values, dtype=int)
        return int(np.sum(flags == 1)), int(np.sum(flags != 2))

    def summary(self) -> str:
        """``validation case <name>: k of n checks passed``."""
        passed, total = self.counts()
        return f"validation case {self.case}: {passed} of {total} checks passed"

    def sections(self, out: Path) -> list[Section]:
        """The table (with the source and notes) and the case's figure."""
        attrs = self.dataset.attrs
        passed, total = self.counts()
        verdict = "Every check passed" if passed == total else f"{total - passed} of {total} checks FAILED"
        notes = [line for line in str(attrs.get("validation_notes", "")).split("\n") if line]
        intro = (
            f"<p><b>{html.escape(verdict)}</b>. Source: {html.escape(str(attrs.get('validation_source', '')))}.</p>"  # the answer first
            + "".join(f"<p>{html.escape(note)}</p>" for note in notes)
        )
        figures = saved([validation_figure(self.dataset)], out)
        return [Section("Agreement with the published closed form", intro, [], [validation_table(self.dataset)]), Section("Figure", "", figures, [])]


def write_validation_report(dataset: xr.Dataset, out_dir: str | Path) -> Path:
    """``report.html`` of a validation dataset in ``out_dir`` (what :func:`vibroimpact.reporting.page.write_report`
    writes for it, in this process); return its path."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    page = ValidationPage(dataset)
    text = str(dataset.attrs.get("scene", ""))
    paragraphs = [stored_description(text), f"vibroimpact {dataset.attrs.get('vibroimpact_version', '?')}; {page.summary()}."]
    return write_page(out / "report.html", render_page(f"Study '{dataset.attrs.get('scene_name', '')}'", paragraphs, page.sections(out), text))


def page_for(dataset: xr.Dataset) -> ValidationPage:
    """The page of a validation dataset."""
    return ValidationPage(dataset)
