"""Report page of swept-sine tests (paper section 5, figures 16-24): running estimates against the steady states.

Dataset layout read here: the steady-state solutions (``linear``, ``pgf``, ...) as ``<quantity>(solution, frequency)``
without a ``sweep`` dimension; the swept runs' running estimates on the frequency grid as
``swept_<quantity>(sweep, frequency)``; ``running_<quantity>(sweep, elapsed_time)`` against time; ``sweep_<stat>(sweep)``
per run. The page shows the first point of any other swept dimension. The sweep's settings are the dataset's
``swept_sine_*`` attributes.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib.axes import Axes

from vibroimpact.analysis.regime import Regime
from vibroimpact.reporting.page import DrawnFigure, Section, Table, saved
from vibroimpact.reporting.record import SWEPT_SOLUTION, StudySetting
from vibroimpact.reporting.responses import SolutionsPage, linear_section, regime_map
from vibroimpact.reporting.series import draw_curve, draw_linear, stability_keys, unstable_points
from vibroimpact.reporting.style import QUANTITIES, SOLUTION_COLOURS, SOLUTION_DESCRIPTIONS, Caption, axis_label, figure_legend, finish_axes, fmt, legend_rows, new_figure, solution_ref

__all__ = ["SweptSinePage", "SweptSineRun", "swept_sine_run", "sweep_figures", "sweep_tables"]

#: Colour of each sweep direction.
SWEEP_COLOURS = {"up": "C3", "down": "C2"}
#: Running fundamental of a sweep: thinner than the steady states' curves, which show beneath.
SWEPT_STYLE = {"ls": "-", "lw": 0.9}
#: sqrt 2 x running RMS: thinner, dash-dot (dashed means an unstable orbit).
RMS_STYLE = {"ls": "-.", "lw": 0.9}
_FREQUENCY = "instantaneous frequency [Hz]"
#: Grid dimensions of which the page shows the first point.
PAGE_POINT_DIMS = ("restitution", "bumper_loss_factor", "clearance", "bumper_frequency")


@dataclass(frozen=True)
class SweptSineRun:
    """How the swept-sine runs of a dataset were made, as its ``swept_sine_*`` attributes say.

    Attributes
    ----------
    start_frequency, stop_frequency : float
        Frequency range of the sweep [Hz].
    rate : float
        Sweep rate [Hz/s].
    window_cycles : int
        Excitation cycles in the running estimators' window.
    bumper_frequency : float
        Omega_b / 2 pi of the (first) bumper [Hz].
    bumper_loss_factor : float
        xi_b of the (first) bumper [-].
    """

    start_frequency: float
    stop_frequency: float
    rate: float
    window_cycles: int
    bumper_frequency: float
    bumper_loss_factor: float

    def __post_init__(self) -> None:
        if not (0.0 < self.start_frequency and 0.0 < self.stop_frequency and 0.0 < self.rate):
            raise ValueError(f"a sweep has positive frequencies [Hz] and rate [Hz/s], got {self}")

    @property
    def duration(self) -> float:
        """Simulated time of one sweep [s]."""
        return (self.stop_frequency - self.start_frequency) / self.rate

    def text(self) -> str:
        """The sweep's range [Hz], rate [Hz/s], bumper [Hz], loss factor [-] and window [cycles], for captions."""
        return (
            f"{fmt(self.start_frequency, 'g')} <-> {fmt(self.stop_frequency, 'g')} Hz at {fmt(self.rate, 'g')} Hz/s, bumper {fmt(self.bumper_frequency, 'g')} Hz, "
            f"xi_b = {fmt(self.bumper_loss_factor, '.4f')}, estimator window {self.window_cycles} cycles"
        )


def swept_sine_run(dataset: xr.Dataset, setting: StudySetting) -> SweptSineRun:
    """The :class:`SweptSineRun` of a swept-sine study's ``dataset``."""
    attrs = dataset.attrs
    return SweptSineRun(
        start_frequency=float(attrs["swept_sine_start_frequency"]),
        stop_frequency=float(attrs["swept_sine_stop_frequency"]),
        rate=float(attrs["swept_sine_rate"]),
        window_cycles=int(attrs["swept_sine_window_cycles"]),
        bumper_frequency=float(setting.bumper_frequency[0]),
        bumper_loss_factor=float(setting.bumper_loss_factor[0]),
    )


class SweptSinePage(SolutionsPage):
    """The page of a swept-sine study (dimensions ``solution``, ``sweep``, ``frequency``, ``elapsed_time``): the linear
    system, then the sweeps against the steady states; the swept solution is the last of the summary's."""

    def sections(self, out: Path) -> list[Section]:
        """Linear system, then the sweeps at the first point of the other swept grids."""
        run = swept_sine_run(self.dataset, self.setting)
        first = {d: 0 for d in PAGE_POINT_DIMS if d in self.dataset.dims}
        part = self.dataset.isel(first)
        intro = f"<p>Figures and tables show the first point of the swept grids ({', '.join(first)}); the dataset holds every point.</p>" if first else ""
        sweeps = Section("Swept sine against the steady states", intro=intro, figures=saved(sweep_figures(part, run), out), tables=sweep_tables(part, run, self.setting))
        return [linear_section(self.setting, out), sweeps]


def _steady_solutions(dataset: xr.Dataset) -> list[str]:
    """The steady-state solutions of a swept-sine dataset (none if it has no ``solution`` dimension)."""
    return [str(s) for s in dataset["solution"].values] if "solution" in dataset.coords else []


def _directions(dataset: xr.Dataset) -> list[str]:
    """The sweep directions of the dataset, in its order."""
    return [str(s) for s in dataset["sweep"].values]


def _draw_steady(ax: Axes, dataset: xr.Dataset, quantity: str, caption: Caption, with_linear: bool = True) -> bool:
    """Linear system and pgf steady state of ``quantity``; returns whether an unstable stretch was drawn."""
    f = dataset["frequency"].values
    steady = _steady_solutions(dataset)
    if quantity not in dataset:
        return False
    if with_linear and "linear" in steady:
        draw_linear(ax, f, dataset[quantity].sel(solution="linear").values)
        caption.add("linear", "LIN (dotted black): the linear system (no stop).")
    unstable = False
    if "pgf" in steady:
        drawn, unstable = draw_curve(ax, f, dataset[quantity].sel(solution="pgf").values, colour=SOLUTION_COLOURS["pgf"], label=f"{solution_ref('pgf')} steady state", gid="pgf", unstable=unstable_points(dataset, "pgf"))
        if drawn:
            caption.add("pgf", f"{solution_ref('pgf')}: the {SOLUTION_DESCRIPTIONS['pgf']} (solid where the orbit is stable{', dashed where unstable' if unstable else ''}).")
    return unstable


def _draw_swept(ax: Axes, dataset: xr.Dataset, quantity: str, solution: str, scale: float = 1.0, style: dict[str, object] | None = None, suffix: str = "") -> bool:
    """The running estimate of ``quantity`` of each sweep direction; returns whether anything was drawn."""
    name = f"swept_{quantity}"
    if name not in dataset:
        return False
    f = dataset["frequency"].values
    drawn = False
    for direction in _directions(dataset):
        values = scale * dataset[name].sel(sweep=direction).values
        drawn |= draw_curve(ax, f, values, colour=SWEEP_COLOURS.get(direction, "C4"), label=f"{solution_ref(solution)} sweep {direction}{suffix}", gid=solution, style=style or SWEPT_STYLE)[0]
    return drawn


def sweep_figures(dataset: xr.Dataset, run: SweptSineRun) -> list[DrawnFigure]:
    """Running estimates of each swept-sine run against the steady states, the regimes, and X1 against time."""
    solution = SWEPT_SOLUTION
    figures = [_displacement_figure(dataset, run, solution)]
    force = _force_figure(dataset, solution)
    if force is not None:
        figures.append(force)
    if "swept_regime" in dataset:
        panels = [(f"{solution_ref(s)}: regime of the steady state", ["steady state"], dataset["regime"].sel(solution=s).values[None, :].astype(int)) for s in _steady_solutions(dataset) if "regime" in dataset]
        panels.append((f"{solution_ref(solution)}: swept sine, regime within the estimator window", [f"sweep {d}" for d in _directions(dataset)], dataset["swept_regime"].values.astype(int)))
        figures.append(regime_map(panels, dataset["frequency"].values, "sweep_regime", "Regime map", "Regime of the steady states and of the sweeps at each frequency"))
    if "running_x1_amplitude" in dataset:
        fig, axes = new_figure(1, panel_height=3.6, legend_rows=1)
        for direction in _directions(dataset):
            values = dataset["running_x1_amplitude"].sel(sweep=direction).values
            draw_curve(axes[0], dataset["elapsed_time"].values, values, colour=SWEEP_COLOURS.get(direction, "C4"), label=f"{solution_ref(solution)} sweep {direction}", gid=solution)
        finish_axes(axes[0], "time since the start of the sweep [s]", f"running {axis_label('x1_amplitude')}", "Running fundamental of X1 against time (the Simulink scope view)", log=True)
        figure_legend(fig, axes)
        caption = f"The running {QUANTITIES['x1_amplitude'].label} of each {solution_ref(solution)} sweep against the time since its start ({run.text()})."
        figures.append(DrawnFigure(fig, "sweep_time", "Running |X1| against time", caption))
    return figures


def _displacement_figure(dataset: xr.Dataset, run: SweptSineRun, solution: str) -> DrawnFigure:
    """Running fundamental and sqrt 2 x RMS of X1 and X2 of each sweep against the steady states (figures 16-20)."""
    caption = Caption(f"Swept sine ({run.text()}): running estimates of {solution_ref(solution)} against the instantaneous frequency, like the paper's figures 16-20, against the steady states.")
    fig, axes = new_figure(2, panel_height=4.0, legend_rows=legend_rows(8))
    any_unstable = False
    for ax, (quantity, rms, name) in zip(axes, (("x1_amplitude", "x1_rms", "X1"), ("x2_amplitude", "x2_rms", "X2"))):
        any_unstable |= _draw_steady(ax, dataset, quantity, caption)
        if rms in dataset and "pgf" in _steady_solutions(dataset):
            ax.plot(dataset["frequency"].values, np.sqrt(2.0) * dataset[rms].sel(solution="pgf").values, color=SOLUTION_COLOURS["pgf"], label=f"{solution_ref('pgf')}: sqrt 2 x RMS", gid="pgf", **RMS_STYLE)
            caption.add("pgf rms", f"Dash-dot: sqrt 2 x RMS (equal to the fundamental for a pure sine) of the orbit reconstructed by {solution_ref('pgf')} and of the sweeps.")
        if _draw_swept(ax, dataset, quantity, solution):
            caption.add("swept", "Red: sweep up, green: sweep down, running fundamental over the estimator window (solid).")
        _draw_swept(ax, dataset, rms, solution, scale=np.sqrt(2.0), style=RMS_STYLE, suffix=": sqrt 2 x RMS")
        finish_axes(ax, _FREQUENCY, f"{name} amplitude [m]", f"{name}: swept sine against steady states", log=True)
    if any_unstable:
        caption.add("unstable", "Dashed: one-impact orbits that exist but are unstable.")
    figure_legend(fig, axes, stability_keys() if any_unstable else [], columns=3)
    return DrawnFigure(fig, "sweep_displacements", "Swept sine: X1 and X2", caption.text())


def _force_figure(dataset: xr.Dataset, solution: str) -> DrawnFigure | None:
    """Force on the base, impulse and contacts per period of each sweep against the steady states (figures 21-24)."""
    quantities = [q for q in ("force_amplitude", "impulse", "impacts_per_period") if f"swept_{q}" in dataset]
    if not quantities:
        return None
    caption = Caption(f"{', '.join(QUANTITIES[q].label for q in quantities)} over the estimator window of each {solution_ref(solution)} sweep (red: up, green: down) against the instantaneous frequency (paper figures 21-24).")
    fig, axes = new_figure(len(quantities), panel_height=3.8, legend_rows=legend_rows(6))
    any_unstable = False
    for ax, quantity in zip(axes, quantities):
        any_unstable |= _draw_steady(ax, dataset, quantity, caption, with_linear=quantity == "force_amplitude")
        _draw_swept(ax, dataset, quantity, solution)
        finish_axes(ax, _FREQUENCY, axis_label(quantity), QUANTITIES[quantity].label, log=QUANTITIES[quantity].log)
    if any_unstable:
        caption.add("unstable", "Dashed: one-impact orbits that exist but are unstable.")
    figure_legend(fig, axes, stability_keys() if any_unstable else [], columns=3)
    return DrawnFigure(fig, "sweep_force_impulse", "Swept sine: force, impulse and contacts", caption.text())


def sweep_tables(dataset: xr.Dataset, run: SweptSineRun, setting: StudySetting) -> list[Table]:
    """Cost of each run, and the sweep against the pgf steady state where that is stable."""
    rows = ["<tr><th>sweep</th><th>wall time [s]</th><th>steps</th><th>contacts</th><th>residual calls</th><th>simulated [s]</th><th>failed</th></tr>"]
    for direction in _directions(dataset):
        line = dataset.sel(sweep=direction)
        cells = [fmt(float(line[f"sweep_{stat}"]), spec) if f"sweep_{stat}" in line else "" for stat, spec in (("wall_time", ".1f"), ("steps", ".0f"), ("contacts", ".0f"), ("rhs_calls", ".0f"))]
        failed = "yes" if "sweep_failed" in line and float(line["sweep_failed"]) == 1.0 else "no"
        rows.append(f"<tr><td>{direction}</td>{''.join(f'<td>{c}</td>' for c in cells)}<td>{fmt(run.duration, 'g')}</td><td>{failed}</td></tr>")
    tables = [Table("Cost of the swept-sine runs (one process each)", "<table>" + "".join(rows) + "</table>")]
    if "pgf" in _steady_solutions(dataset) and "swept_x1_amplitude" in dataset:
        rows = ["<tr><th>sweep</th><th>band</th><th>points (pgf stable, sweep in contact)</th><th>median rel. diff. |X1|</th><th>90th percentile</th></tr>"]
        f = dataset["frequency"].values
        split = setting.split_frequency
        pgf = dataset["x1_amplitude"].sel(solution="pgf").values
        stable = dataset["stable"].sel(solution="pgf").values == 1 if "stable" in dataset else np.isfinite(pgf)
        for direction in _directions(dataset):
            sim = dataset["swept_x1_amplitude"].sel(sweep=direction).values
            contact = dataset["swept_regime"].sel(sweep=direction).values == Regime.SWEPT_CONTACT if "swept_regime" in dataset else np.isfinite(sim)
            with np.errstate(invalid="ignore", divide="ignore"):
                difference = np.abs(sim - pgf) / pgf
            for band, mask in (("1", f < split), ("2", f >= split)):
                good = mask & stable & contact & np.isfinite(difference)
                median = fmt(np.median(difference[good]), ".3f") if good.any() else ""
                p90 = fmt(np.percentile(difference[good], 90), ".3f") if good.any() else ""
                rows.append(f"<tr><td>{direction}</td><td>{band}</td><td>{int(good.sum())}</td><td>{median}</td><td>{p90}</td></tr>")
        tables.append(Table("Swept sine against the stable pgf steady state (|X1| fundamental)", "<table>" + "".join(rows) + "</table>"))
    return tables
