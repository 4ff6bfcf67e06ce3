"""Report pages of swept-sine tests (paper section 5, figures 16-24): running estimates against the steady states.

Dataset layout read here: the steady-state solutions (``linear``, ``pgf``, ...) as ``<quantity>(solution, frequency)``
without a ``sweep`` dimension; the swept runs' running estimates on the frequency grid as
``swept_<quantity>(sweep, frequency)``; ``running_<quantity>(sweep, elapsed_time)`` against time; ``sweep_<stat>(sweep)``
per run. The page shows the first point of any other swept dimension. The sweep's settings are the dataset's
``swept_sine_*`` attributes. The figures draw one panel per coordinate (``<name>_amplitude``: X1 and X2 for the
paper's system, each coordinate of a general scene by its name) and the impulse of each stop (a dimension ``stop``
where a general scene has several); the paper's named system opens with its linear system
(:class:`SweptSinePage`), a general scene with its structure and stops (:class:`GeneralSweptPage`).
"""

from __future__ import annotations

import html
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.lines import Line2D

from vibroimpact.analysis.stability import Regime
from vibroimpact.grids.regime_map import regime_map
from vibroimpact.grids.sections import paper_study, SolutionsPage, layout_tables, linear_section, structure_figure
from vibroimpact.reporting.record import GeneralSetting, bumper_text, general_setting, is_general, study_setting, SWEPT_SOLUTION
from vibroimpact.reporting.coincide import Coincidence, coincidence_phrase, reveal_coincident
from vibroimpact.reporting.page import DrawnFigure, Section, Table, saved
from vibroimpact.reporting.series import draw_curve, draw_linear, stability_keys, unstable_points
from vibroimpact.reporting.style import DISPLACEMENT_SCALE, DISPLACEMENT_UNITS, QUANTITIES, GENERAL_SOLUTION_DESCRIPTIONS, SOLUTION_COLOURS, SOLUTION_DESCRIPTIONS, Caption, axis_label, figure_legend, finish_axes, fmt, legend_rows, new_figure, solution_ref, SWEEP_COLOURS

__all__ = ["page_for", "SweptSinePage", "GeneralSweptPage", "SweptSineRun", "SweepLayout", "sweep_layout", "swept_sine_run", "sweep_figures", "sweep_tables", "sweep_answer", "contact_stretches"]

#: Colour of each sweep direction.
#: Running fundamental of a sweep: thinner than the steady states' curves, which show beneath.
SWEPT_STYLE = {"ls": "-", "lw": 0.9}
#: sqrt 2 x running RMS: thinner, dash-dot (dashed means an unstable orbit).
RMS_STYLE = {"ls": "-.", "lw": 0.9}
_FREQUENCY = "instantaneous frequency [Hz]"
#: Grid dimensions of which the page shows the first point.
PAGE_POINT_DIMS = ("restitution", "bumper_loss_factor", "clearance", "bumper_frequency")


@dataclass(frozen=True)
class SweepLayout:
    """What the sweep figures name: the coordinates as the dataset names them, their labels, and the stops.

    Attributes
    ----------
    coordinates : tuple of str
        Names of the coordinates (``<name>_amplitude`` ...): ``x1, x2`` for the paper's system.
    labels : tuple of str
        How figures write them: X1, X2 for names x1, x2 ...; a general scene's own names otherwise.
    stops : tuple of str
        Each stop in words where the dataset has a ``stop`` dimension (several stops); ``()`` for one stop.
    closed_form : str
        What the ``pgf`` steady state is on this layout (the paper's one-impact closed form, or the general one).
    orbits : str
        What its orbits are called in captions.
    """

    coordinates: tuple[str, ...] = ("x1", "x2")
    labels: tuple[str, ...] = ("X1", "X2")
    stops: tuple[str, ...] = ()
    closed_form: str = SOLUTION_DESCRIPTIONS["pgf"]
    orbits: str = "one-impact orbits"

    def __post_init__(self) -> None:
        if not self.coordinates or len(self.labels) != len(self.coordinates):
            raise ValueError(f"a sweep layout has one label per coordinate, got {self.coordinates} and {self.labels}")

    def both(self) -> str:
        """The coordinates' labels in words: ``X1 and X2``, ``a, b and c``."""
        return self.labels[0] if len(self.labels) == 1 else f"{', '.join(self.labels[:-1])} and {self.labels[-1]}"


def _label(name: str) -> str:
    """How a figure writes coordinate ``name``: ``x1`` -> ``X1`` (the paper's displacements), others as named."""
    return name.upper() if re.fullmatch(r"x[0-9]+", name) else name


def sweep_layout(dataset: xr.Dataset) -> SweepLayout:
    """The :class:`SweepLayout` of a swept-sine dataset: a general scene's coordinates (attribute
    ``system_coordinates``) and stops, else the paper's x1, x2."""
    stops = tuple(str(s) for s in dataset["stop_description"].values) if "stop" in dataset.dims and "stop_description" in dataset.coords else ()
    if not is_general(dataset):
        return SweepLayout(stops=stops)
    coordinates = tuple(str(dataset.attrs["system_coordinates"]).split())
    return SweepLayout(coordinates, tuple(_label(c) for c in coordinates), stops, GENERAL_SOLUTION_DESCRIPTIONS["pgf"], "closed-form impact orbits")


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
        Omega_b / 2 pi of the (first) bumper [Hz]; NaN where each stop has its own (the stops' descriptions say it).
    bumper_loss_factor : float
        xi_b of the (first) bumper [-]; NaN where each stop has its own.
    bumper_words : str
        The bumper in its scene's units (:func:`~vibroimpact.reporting.record.bumper_text`); empty: ``bumper_frequency``.
    """

    start_frequency: float
    stop_frequency: float
    rate: float
    window_cycles: int
    bumper_frequency: float
    bumper_loss_factor: float
    bumper_words: str = ""

    def __post_init__(self) -> None:
        if not (0.0 < self.start_frequency and 0.0 < self.stop_frequency and 0.0 < self.rate):
            raise ValueError(f"a sweep has positive frequencies [Hz] and rate [Hz/s], got {self}")

    @property
    def duration(self) -> float:
        """Simulated time of one sweep [s]."""
        return (self.stop_frequency - self.start_frequency) / self.rate

    def text(self) -> str:
        """The sweep's range [Hz], rate [Hz/s], bumper [Hz], loss factor [-] and window [cycles], for captions."""
        bumper = (self.bumper_words or f"bumper {fmt(self.bumper_frequency, 'g')} Hz") if np.isfinite(self.bumper_frequency) else "each stop's own bumper"
        loss = f", xi_b = {fmt(self.bumper_loss_factor, '.4f')}" if np.isfinite(self.bumper_loss_factor) else ""
        return f"{fmt(self.start_frequency, 'g')} <-> {fmt(self.stop_frequency, 'g')} Hz at {fmt(self.rate, 'g')} Hz/s, {bumper}{loss}, estimator window {self.window_cycles} cycles"


def swept_sine_run(dataset: xr.Dataset) -> SweptSineRun:
    """The :class:`SweptSineRun` of a swept-sine study's ``dataset`` (its first bumper frequency and loss factor, NaN
    where the dataset has none: each stop has its own)."""
    attrs = dataset.attrs

    def first(name: str) -> float:
        return float(np.atleast_1d(dataset[name].values)[0]) if name in dataset.coords else float("nan")

    return SweptSineRun(
        start_frequency=float(attrs["swept_sine_start_frequency"]),
        stop_frequency=float(attrs["swept_sine_stop_frequency"]),
        rate=float(attrs["swept_sine_rate"]),
        window_cycles=int(attrs["swept_sine_window_cycles"]),
        bumper_frequency=first("bumper_frequency"),
        bumper_loss_factor=first("bumper_loss_factor"),
        bumper_words=bumper_text(attrs, first("bumper_frequency")) if np.isfinite(first("bumper_frequency")) else "",
    )


def _first_point(dataset: xr.Dataset) -> tuple[xr.Dataset, str]:
    """The dataset at the first point of the other swept grids, and the paragraph that says so."""
    first = {d: 0 for d in PAGE_POINT_DIMS if d in dataset.dims}
    intro = f"<p>Figures and tables show the first point of the swept grids ({', '.join(first)}); the dataset holds every point.</p>" if first else ""
    return dataset.isel(first), intro


def _descending(dataset: xr.Dataset, direction: str) -> bool:
    """Whether sweep ``direction`` runs down in frequency (its instantaneous frequency falls)."""
    if "instantaneous_frequency" in dataset.coords:
        f = np.asarray(dataset["instantaneous_frequency"].sel(sweep=direction).values, dtype=float)
        f = f[np.isfinite(f)]
        return f.size > 1 and f[-1] < f[0]
    return direction == "down"


def contact_stretches(f: np.ndarray, contact: np.ndarray, gap: float) -> list[tuple[float, float, tuple[float, float] | None]]:
    """Stretches of frequency [Hz] where ``contact``, those less than ``gap`` [Hz] apart joined: (start, end, and the
    span over which a joined stretch had contact-free points, or None)."""
    edges = np.flatnonzero(np.diff(np.concatenate(([0], contact.astype(int), [0]))))
    runs = [(int(a), int(b) - 1) for a, b in zip(edges[::2], edges[1::2])]
    joined: list[tuple[int, int, int, int]] = []  # first, last, first gap start, last gap end (-1: none)
    for a, b in runs:
        if joined and f[a] - f[joined[-1][1]] <= gap:
            first, last, g0, _ = joined[-1]
            joined[-1] = (first, b, g0 if g0 >= 0 else last + 1, a - 1)
        else:
            joined.append((a, b, -1, -1))
    return [(float(f[a]), float(f[b]), (float(f[g0]), float(f[g1])) if g0 >= 0 else None) for a, b, g0, g1 in joined]


def sweep_answer(dataset: xr.Dataset, run: SweptSineRun, split: float | None, layout: SweepLayout | None = None) -> str:
    """What the sweeps show, in numbers (HTML): where each sweep touches the stops, in its own direction (gaps shorter
    than an estimator window joined, and said), and how far its running fundamental of the first coordinate lies from
    the pgf orbit where that is stable and the sweep in contact (signed median per band)."""
    layout = layout or sweep_layout(dataset)
    f = dataset["frequency"].values
    paragraphs = []
    if "swept_regime" in dataset:
        middle = 0.5 * (run.start_frequency + run.stop_frequency)
        gap = run.rate * run.window_cycles / middle + float(np.min(np.diff(f), initial=0.0))
        words = []
        for direction in _directions(dataset):
            stretches = contact_stretches(f, dataset["swept_regime"].sel(sweep=direction).values == Regime.SWEPT_CONTACT, gap)
            down = _descending(dataset, direction)
            texts = []
            for start, end, free in reversed(stretches) if down else stretches:
                a, b = (end, start) if down else (start, end)
                text = f"{fmt(a, '.1f')}-{fmt(b, '.1f')} Hz"
                if free is not None:
                    c, d = (free[1], free[0]) if down else free
                    text += f" (with contact-free windows over {fmt(c, '.2f')}-{fmt(d, '.2f')} Hz)"
                texts.append(text)
            words.append(f"sweeping {direction} over {_and(texts)}" if texts else f"sweeping {direction} none")
        paragraphs.append(f"Contacts of the {solution_ref(SWEPT_SOLUTION)} sweeps ({run.text()}): {'; '.join(words)}.")
    quantity, label = f"{layout.coordinates[0]}_amplitude", layout.labels[0]
    if "pgf" in _steady_solutions(dataset) and f"swept_{quantity}" in dataset and "swept_regime" in dataset:
        pgf = dataset[quantity].sel(solution="pgf").values
        stable = dataset["stable"].sel(solution="pgf").values == 1 if "stable" in dataset else np.isfinite(pgf)
        bands = ((f"band 1 (below {fmt(split, '.4g')} Hz)", f < split), ("band 2", f >= split)) if split is not None else (("", np.ones(f.shape, bool)),)
        parts = []
        for band, mask in bands:
            per = []
            for direction in _directions(dataset):
                sim = dataset[f"swept_{quantity}"].sel(sweep=direction).values
                good = mask & stable & (dataset["swept_regime"].sel(sweep=direction).values == Regime.SWEPT_CONTACT) & np.isfinite(sim) & np.isfinite(pgf) & (pgf > 0)
                if good.any():
                    median = float(np.median((sim[good] - pgf[good]) / pgf[good]))
                    per.append(f"{fmt(100.0 * abs(median), '.1f')} % {'above' if median >= 0 else 'below'} sweeping {direction} ({int(good.sum())} points)")
            if per:
                parts.append(f"{_and(per)}{' in ' + band if band else ''}")
        if parts:
            paragraphs.append(f"Where a sweep is in contact and the {solution_ref('pgf')} orbit is stable, its running |{label}| fundamental lies (median) {'; '.join(parts)}.")
    return "".join(f"<p>{html.escape(p)}</p>" for p in paragraphs)


def _and(items: list[str]) -> str:
    return items[0] if len(items) == 1 else f"{', '.join(items[:-1])} and {items[-1]}"


class SweptSinePage(SolutionsPage):
    """The page of a swept-sine study of the paper's named system (dimensions ``solution``, ``sweep``, ``frequency``,
    ``elapsed_time``): the linear system, then the sweeps against the steady states; the swept solution is the last
    of the summary's."""

    def sections(self, out: Path) -> list[Section]:
        """What the sweeps show in numbers, the linear system, then the sweeps at the first point of the other swept
        grids."""
        run = swept_sine_run(self.dataset)
        part, intro = _first_point(self.dataset)
        sweeps = Section("Swept sine against the steady states", intro=intro, figures=saved(sweep_figures(part, run), out), tables=sweep_tables(part, run, self.setting.split_frequency))
        return [Section("Contacts and the steady states", intro=sweep_answer(part, run, self.setting.split_frequency) + intro), linear_section(self.setting, out, paper_study(self.dataset)), sweeps]


class GeneralSweptPage:
    """The page of a swept-sine study of a general scene (any structure, load and stops): the structure and its stops
    in words with their linear responses, then the sweeps of every coordinate and stop against the steady states."""

    def __init__(self, dataset: xr.Dataset) -> None:
        self.dataset = dataset
        self.setting: GeneralSetting = general_setting(dataset)

    def summary(self) -> str:
        """The solutions (the swept one last) and the layout in words."""
        swept = (SWEPT_SOLUTION,) if any(str(name).startswith("swept_") for name in self.dataset.data_vars) else ()
        return f"solutions: {', '.join(self.setting.solutions + swept)}; stops: {'; '.join(self.setting.stops)}"

    def sections(self, out: Path) -> list[Section]:
        """What the sweeps show in numbers, the structure and stops, then the sweeps at the first point of the other
        swept grids."""
        setting = self.setting
        run = swept_sine_run(self.dataset)
        part, intro = _first_point(self.dataset)
        layout = f"<p>Stops: {html.escape('; '.join(setting.stops))}. Load: {html.escape(setting.load_text())}, swept in frequency.</p>"
        structure = Section("Structure and stops", intro=layout, figures=saved([structure_figure(setting, self.dataset['frequency'].values)], out), tables=layout_tables(setting))
        sweeps = Section("Swept sine against the steady states", intro=intro, figures=saved(sweep_figures(part, run), out), tables=sweep_tables(part, run, None))
        return [Section("Contacts and the steady states", intro=sweep_answer(part, run, None) + intro), structure, sweeps]


def _steady_solutions(dataset: xr.Dataset) -> list[str]:
    """The steady-state solutions of a swept-sine dataset (none if it has no ``solution`` dimension)."""
    return [str(s) for s in dataset["solution"].values] if "solution" in dataset.coords else []


def _directions(dataset: xr.Dataset) -> list[str]:
    """The sweep directions of the dataset, in its order."""
    return [str(s) for s in dataset["sweep"].values]


def _at(variable: xr.DataArray, stop: int | None, **where: str) -> np.ndarray:
    """The values of ``variable`` at ``where`` (and at stop ``stop`` where it has a ``stop`` dimension)."""
    if stop is not None and "stop" in variable.dims:
        variable = variable.isel(stop=stop)
    return variable.sel(where).values


#: Curves of a panel in drawing order, each with its lines (for :func:`~vibroimpact.reporting.coincide.reveal_coincident`).
Curves = list[tuple[str, list[Line2D]]]


def _draw_steady(ax: Axes, dataset: xr.Dataset, quantity: str, caption: Caption, layout: SweepLayout, with_linear: bool = True, stop: int | None = None, scale: float = 1.0, curves: Curves | None = None) -> bool:
    """Linear system and pgf steady state of ``quantity`` (of stop ``stop``), times ``scale`` (to the page's units),
    the pgf curve added to ``curves``; returns whether an unstable stretch was drawn."""
    f = dataset["frequency"].values
    steady = _steady_solutions(dataset)
    if quantity not in dataset:
        return False
    if with_linear and "linear" in steady:
        draw_linear(ax, f, scale * _at(dataset[quantity], stop, solution="linear"))
        caption.add("linear", "LIN (dotted black): the linear system (no stop).")
    unstable = False
    if "pgf" in steady:
        before = len(ax.lines)
        drawn, unstable = draw_curve(ax, f, scale * _at(dataset[quantity], stop, solution="pgf"), colour=SOLUTION_COLOURS["pgf"], label=f"{solution_ref('pgf')} steady state", gid="pgf", unstable=unstable_points(dataset, "pgf"))
        if curves is not None:
            curves.append((solution_ref("pgf"), list(ax.lines[before:])))
        if drawn:
            caption.add("pgf", f"{solution_ref('pgf')}: the {layout.closed_form} (solid where the orbit is stable{', dashed where unstable' if unstable else ''}).")
    return unstable


def _draw_swept(ax: Axes, dataset: xr.Dataset, quantity: str, solution: str, scale: float = 1.0, style: dict[str, object] | None = None, suffix: str = "", stop: int | None = None, curves: Curves | None = None) -> bool:
    """The running estimate of ``quantity`` (of stop ``stop``) of each sweep direction, each added to ``curves``;
    returns whether anything was drawn."""
    name = f"swept_{quantity}"
    if name not in dataset:
        return False
    f = dataset["frequency"].values
    drawn = False
    for direction in _directions(dataset):
        values = scale * _at(dataset[name], stop, sweep=direction)
        before = len(ax.lines)
        drawn |= draw_curve(ax, f, values, colour=SWEEP_COLOURS.get(direction, "C4"), label=f"{solution_ref(solution)} sweep {direction}{suffix}", gid=solution, style=style or SWEPT_STYLE)[0]
        if curves is not None:
            curves.append((f"sweep {direction}{' RMS' if suffix else ''}", list(ax.lines[before:])))
    return drawn


def sweep_figures(dataset: xr.Dataset, run: SweptSineRun, layout: SweepLayout | None = None) -> list[DrawnFigure]:
    """Running estimates of each swept-sine run against the steady states, the regimes, and the first coordinate
    against time; ``layout``: the coordinates and stops to draw (by default :func:`sweep_layout` of the dataset)."""
    layout = layout or sweep_layout(dataset)
    solution = SWEPT_SOLUTION
    figures = [_displacement_figure(dataset, run, solution, layout)]
    force = _force_figure(dataset, solution, layout)
    if force is not None:
        figures.append(force)
    if "swept_regime" in dataset:
        panels = [(f"{solution_ref(s)}: regime of the steady state", ["steady state"], dataset["regime"].sel(solution=s).values[None, :].astype(int)) for s in _steady_solutions(dataset) if "regime" in dataset]
        panels.append((f"{solution_ref(solution)}: swept sine, regime within the estimator window", [f"sweep {d}" for d in _directions(dataset)], dataset["swept_regime"].values.astype(int)))
        figures.append(regime_map(panels, dataset["frequency"].values, "sweep_regime", "Regime map", "Regime of the steady states and of the sweeps at each frequency"))
    first, label = layout.coordinates[0], layout.labels[0]
    if f"running_{first}_amplitude" in dataset:
        fig, axes = new_figure(1, panel_height=3.6, legend_rows=1)
        for direction in _directions(dataset):
            values = dataset[f"running_{first}_amplitude"].sel(sweep=direction).values
            draw_curve(axes[0], dataset["elapsed_time"].values, DISPLACEMENT_SCALE * values, colour=SWEEP_COLOURS.get(direction, "C4"), label=f"{solution_ref(solution)} sweep {direction}", gid=solution)
        finish_axes(axes[0], "time since the start of the sweep [s]", f"running |{label}| fundamental [{DISPLACEMENT_UNITS}]", f"Running fundamental of {label} against time (the Simulink scope view)", log=True)
        figure_legend(fig, axes)
        caption = f"The running |{label}| fundamental of each {solution_ref(solution)} sweep against the time since its start ({run.text()})."
        figures.append(DrawnFigure(fig, "sweep_time", f"Running |{label}| against time", caption))
    return figures


def _displacement_figure(dataset: xr.Dataset, run: SweptSineRun, solution: str, layout: SweepLayout) -> DrawnFigure:
    """Running fundamental and sqrt 2 x RMS of every coordinate of each sweep against the steady states (figures
    16-20: X1 and X2 for the paper's system)."""
    caption = Caption(f"Swept sine ({run.text()}): running estimates of {solution_ref(solution)} against the instantaneous frequency, like the paper's figures 16-20, against the steady states.")
    fig, axes = new_figure(len(layout.coordinates), panel_height=4.0, legend_rows=legend_rows(8))
    any_unstable = False
    found: list[Coincidence] = []
    for ax, coordinate, name in zip(axes, layout.coordinates, layout.labels):
        quantity, rms = f"{coordinate}_amplitude", f"{coordinate}_rms"
        fundamentals: Curves = []
        spreads: Curves = []
        any_unstable |= _draw_steady(ax, dataset, quantity, caption, layout, scale=DISPLACEMENT_SCALE, curves=fundamentals)
        if rms in dataset and "pgf" in _steady_solutions(dataset):
            spreads.append((f"{solution_ref('pgf')} RMS", ax.plot(dataset["frequency"].values, DISPLACEMENT_SCALE * np.sqrt(2.0) * dataset[rms].sel(solution="pgf").values, color=SOLUTION_COLOURS["pgf"], label=f"{solution_ref('pgf')}: sqrt 2 x RMS", gid="pgf", **RMS_STYLE)))
            caption.add("pgf rms", f"Dash-dot: sqrt 2 x RMS (equal to the fundamental for a pure sine) of the orbit reconstructed by {solution_ref('pgf')} and of the sweeps.")
        if _draw_swept(ax, dataset, quantity, solution, scale=DISPLACEMENT_SCALE, curves=fundamentals):
            caption.add("swept", "Vermillion: sweep up, sky blue: sweep down, running fundamental over the estimator window (solid).")
        _draw_swept(ax, dataset, rms, solution, scale=DISPLACEMENT_SCALE * np.sqrt(2.0), style=RMS_STYLE, suffix=": sqrt 2 x RMS", curves=spreads)
        finish_axes(ax, _FREQUENCY, f"{name} amplitude [{DISPLACEMENT_UNITS}]", f"{name}: swept sine against steady states", log=True)
        found += reveal_coincident(ax, fundamentals) + reveal_coincident(ax, spreads)
    if any_unstable:
        caption.add("unstable", f"Dashed: {layout.orbits} that exist but are unstable.")
    caption.add("coincide", coincidence_phrase(found, spec=".3g"))
    figure_legend(fig, axes, stability_keys() if any_unstable else [], columns=3)
    return DrawnFigure(fig, "sweep_displacements", f"Swept sine: {layout.both()}", caption.text())


def _force_figure(dataset: xr.Dataset, solution: str, layout: SweepLayout) -> DrawnFigure | None:
    """Force on the base, impulse (of each stop) and contacts per period of each sweep against the steady states
    (figures 21-24)."""
    quantities = [q for q in ("force_amplitude", "impulse", "impacts_per_period") if f"swept_{q}" in dataset]
    if not quantities:
        return None
    # one panel per quantity; the impulse one per stop where the dataset has several
    panels: list[tuple[str, int | None]] = []
    for quantity in quantities:
        several = quantity == "impulse" and layout.stops and "stop" in dataset[f"swept_{quantity}"].dims
        panels += [(quantity, k) for k in range(len(layout.stops))] if several else [(quantity, None)]
    caption = Caption(f"{', '.join(QUANTITIES[q].label for q in quantities)} over the estimator window of each {solution_ref(solution)} sweep (vermillion: up, sky blue: down) against the instantaneous frequency (paper figures 21-24).")
    if any(stop is not None for _, stop in panels):
        caption.add("stops", "The impulse per period on each stop in its own panel (its constraint in the title).")
    fig, axes = new_figure(len(panels), panel_height=3.8, legend_rows=legend_rows(6))
    any_unstable = False
    found: list[Coincidence] = []
    for ax, (quantity, stop) in zip(axes, panels):
        scale = QUANTITIES[quantity].scale
        curves: Curves = []
        any_unstable |= _draw_steady(ax, dataset, quantity, caption, layout, with_linear=quantity == "force_amplitude", stop=stop, scale=scale, curves=curves)
        _draw_swept(ax, dataset, quantity, solution, scale=scale, stop=stop, curves=curves)
        title = QUANTITIES[quantity].label if stop is None else f"{QUANTITIES[quantity].label}, stop {stop}: {layout.stops[stop].split(',')[0]}"
        finish_axes(ax, _FREQUENCY, axis_label(quantity), title, log=QUANTITIES[quantity].log)
        found += reveal_coincident(ax, curves)
    if any_unstable:
        caption.add("unstable", f"Dashed: {layout.orbits} that exist but are unstable.")
    caption.add("coincide", coincidence_phrase(found, spec=".3g"))
    figure_legend(fig, axes, stability_keys() if any_unstable else [], columns=3)
    return DrawnFigure(fig, "sweep_force_impulse", "Swept sine: force, impulse and contacts", caption.text())


def sweep_tables(dataset: xr.Dataset, run: SweptSineRun, split: float | None, layout: SweepLayout | None = None) -> list[Table]:
    """Cost of each run, and the sweep against the pgf steady state where that is stable (the first coordinate's
    fundamental), in the two resonance bands either side of ``split`` [Hz] (the paper's anti-resonance), or over
    the whole grid where it is None."""
    layout = layout or sweep_layout(dataset)
    rows = ["<tr><th>sweep</th><th>wall time [s]</th><th>steps</th><th>contacts</th><th>residual calls</th><th>simulated [s]</th><th>failed</th></tr>"]
    for direction in _directions(dataset):
        line = dataset.sel(sweep=direction)
        cells = [fmt(float(line[f"sweep_{stat}"]), spec) if f"sweep_{stat}" in line else "" for stat, spec in (("wall_time", ".1f"), ("steps", ".0f"), ("contacts", ".0f"), ("rhs_calls", ".0f"))]
        failed = "yes" if "sweep_failed" in line and float(line["sweep_failed"]) == 1.0 else "no"
        rows.append(f"<tr><td>{direction}</td>{''.join(f'<td>{c}</td>' for c in cells)}<td>{fmt(run.duration, 'g')}</td><td>{failed}</td></tr>")
    tables = [Table("Cost of the swept-sine runs (one process each)", "<table>" + "".join(rows) + "</table>")]
    quantity, label = f"{layout.coordinates[0]}_amplitude", layout.labels[0]
    if "pgf" in _steady_solutions(dataset) and f"swept_{quantity}" in dataset:
        rows = [f"<tr><th>sweep</th><th>band</th><th>points (pgf stable, sweep in contact)</th><th>median rel. diff. |{label}|</th><th>90th percentile</th></tr>"]
        f = dataset["frequency"].values
        pgf = dataset[quantity].sel(solution="pgf").values
        stable = dataset["stable"].sel(solution="pgf").values == 1 if "stable" in dataset else np.isfinite(pgf)
        bands = (("1", f < split), ("2", f >= split)) if split is not None else (("all", np.ones(f.shape, dtype=bool)),)
        for direction in _directions(dataset):
            sim = dataset[f"swept_{quantity}"].sel(sweep=direction).values
            contact = dataset["swept_regime"].sel(sweep=direction).values == Regime.SWEPT_CONTACT if "swept_regime" in dataset else np.isfinite(sim)
            with np.errstate(invalid="ignore", divide="ignore"):
                difference = np.abs(sim - pgf) / pgf
            for band, mask in bands:
                good = mask & stable & contact & np.isfinite(difference)
                median = fmt(np.median(difference[good]), ".3f") if good.any() else ""
                p90 = fmt(np.percentile(difference[good], 90), ".3f") if good.any() else ""
                rows.append(f"<tr><td>{direction}</td><td>{band}</td><td>{int(good.sum())}</td><td>{median}</td><td>{p90}</td></tr>")
        tables.append(Table(f"Swept sine against the stable pgf steady state (|{label}| fundamental)", "<table>" + "".join(rows) + "</table>"))
    return tables


def page_for(dataset: xr.Dataset) -> SweptSinePage | GeneralSweptPage:
    """The page of a swept-sine dataset: every coordinate and stop where the recorded layout is not the paper's
    (:func:`~vibroimpact.reporting.record.is_general`), the paper's figures 16-24 where it is."""
    if is_general(dataset):
        return GeneralSweptPage(dataset)
    return SweptSinePage(dataset, study_setting(dataset))
