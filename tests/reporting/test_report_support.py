"""Tiny datasets and figure inspectors shared by the report tests, and tests of the inspectors themselves.

The datasets are cheap: the closed forms (linear, pgf, pgf_paper) are computed by ``run_study`` on a 0.05 Hz grid;
the simulations are made up on their own 0.5 Hz grid (NaN elsewhere, regime ``not_computed``), as the real engines
leave them: 90 % of a simulated solution's points are NaN, which is what hid simulated curves before.
"""

from __future__ import annotations

import functools
import io
import itertools
import struct
from typing import Any, Callable

import numpy as np
import xarray as xr
import yaml
from matplotlib.axes import Axes
from matplotlib.figure import Figure as MatplotlibFigure
from matplotlib.lines import Line2D
from matplotlib.text import Text

from vibroimpact.analysis.stability import Regime, regime_attributes
from vibroimpact.reporting.record import StudySetting, study_setting
from vibroimpact.reporting.style import DPI, FIGURE_WIDTH
from vibroimpact.scene import parse_scene
from vibroimpact.runs.run import run_study
from vibroimpact.simulation.swept import sweep_quantities
from vibroimpact.engines.registry import BUMPER
from vibroimpact.scene.schema import ENGINE_CONTACT, ENGINE_SOLUTIONS

from tests.scene.test_scene import PAPER_SYSTEM_SPEC

#: Simulated frequencies of the made-up simulations [Hz].
SIMULATION_GRID = {"start": 15.0, "stop": 45.0, "step": 0.5}
#: Page width a figure must fit unscaled [px].
PAGE_CONTENT_WIDTH = 1360


def steady_document(engines: tuple[str, ...] = ENGINE_SOLUTIONS, restitution: tuple[float, ...] = (0.2, 0.6), step: float = 0.05) -> dict[str, Any]:
    """A restitution-like scene: closed forms on a fine grid, simulations on a coarse one."""
    document: dict[str, Any] = {
        "name": "tiny",
        "description": "report test",
        "system": dict(PAPER_SYSTEM_SPEC),
        "excitation": {"amplitude": 10.0},
        "stop": {"clearance": 0.003},
        "bumper": {"frequency": 250.0},
        "sweep": {"restitution": list(restitution), "frequency": {"start": 15.0, "stop": 45.0, "step": step}},
        "solutions": ["linear", "pgf", "pgf_paper", *engines],
    }
    if engines:
        document["simulation"] = {"frequency": dict(SIMULATION_GRID)}
    if len(restitution) == 1:
        document["stop"]["restitution"] = restitution[0]
        del document["sweep"]["restitution"]
    return document


def _closed_forms(document: dict[str, Any]) -> xr.Dataset:
    closed = {k: v for k, v in document.items() if k not in ("simulation", "swept_sine")}
    closed["solutions"] = [s for s in document["solutions"] if s in ("linear", "pgf", "pgf_paper")]
    return run_study(parse_scene(closed, text=yaml.safe_dump(closed)), progress=None)


def _fake_simulation(closed: xr.Dataset, engine: str, offset: float) -> xr.Dataset:
    """A simulation on the coarse grid: the pgf values (else linear) shifted by ``offset``, irregular over 34-38 Hz,
    failed at 30 Hz, NaN and ``not_computed`` off its grid."""
    f = closed["frequency"].values
    grid = np.arange(SIMULATION_GRID["start"], SIMULATION_GRID["stop"] + 1e-9, SIMULATION_GRID["step"])
    pgf, linear = closed.sel(solution="pgf"), closed.sel(solution="linear")
    on_grid = np.any(np.isclose(f[:, None], grid[None, :], rtol=0.0, atol=1e-9), axis=1)

    def mask(values: np.ndarray) -> xr.DataArray:
        return xr.DataArray(values, dims="frequency", coords={"frequency": f}).broadcast_like(pgf["x1_amplitude"])

    on = mask(on_grid)
    irregular = mask(on_grid & (f > 34.0) & (f < 38.0))
    failed = mask(on_grid & np.isclose(f, 30.0, rtol=0.0, atol=1e-9))
    part = pgf.copy(deep=True)
    for name in ("x1_amplitude", "x2_amplitude", "force_amplitude", "suspension_force_amplitude", "impulse", "x1_rms", "x2_rms", "peak_acceleration", "peak_contact_force"):
        if name not in part:
            continue
        values = xr.where(np.isfinite(pgf[name]), pgf[name], linear[name]) * (1.0 + offset)
        if ENGINE_CONTACT[engine] != BUMPER and name.startswith("peak_"):
            values = values * np.nan  # rigid engines have no contact peaks
        part[name] = values.where(on & ~failed)
    impact = part["impulse"] > 0.0
    regime = xr.where(impact, int(Regime.ONE_IMPACT), int(Regime.LINEAR))
    chaotic = irregular & mask(f < 36.0)  # 34-36 Hz chaotic, 36-38 Hz quasi-periodic (their evidence below)
    regime = xr.where(irregular, int(Regime.QUASI_PERIODIC), regime)
    regime = xr.where(chaotic, int(Regime.CHAOTIC), regime)
    regime = xr.where(failed, int(Regime.FAILED), regime)
    part["lyapunov_exponent"] = xr.where(irregular, xr.where(chaotic, 0.08, 0.001), np.nan)
    part["lyapunov_error"] = xr.where(irregular, xr.where(chaotic, 0.005, 0.002), np.nan)
    part["regime"] = xr.where(on, regime, int(Regime.NOT_COMPUTED)).astype(np.int8).assign_attrs(regime_attributes())
    part["converged"] = xr.where(on, xr.where(irregular, 0, 1), -1).astype(np.int8)
    part["impacts_per_period"] = xr.where(on & ~failed, xr.where(impact, 1.0, 0.0), np.nan)
    for name in ("stable",):
        part[name] = xr.full_like(part[name], -1)
    for name in ("floquet_modulus", "phase", "one_impact_x1_amplitude", "one_impact_x2_amplitude", "one_impact_force_amplitude", "one_impact_impulse"):
        part[name] = part[name] * np.nan
    part["wall_time"] = xr.where(on, 0.01, np.nan)
    return part.assign_coords(solution=engine)


@functools.cache
def steady_dataset(engines: tuple[str, ...] = ENGINE_SOLUTIONS, restitution: tuple[float, ...] = (0.2, 0.6), step: float = 0.05) -> xr.Dataset:
    """The dataset of :func:`steady_document` (closed forms computed, simulations made up); cached: do not modify."""
    document = steady_document(engines, restitution, step)
    closed = _closed_forms(document)
    engines = [s for s in document["solutions"] if s not in ("linear", "pgf", "pgf_paper")]
    parts = [closed.sel(solution=[s]) for s in closed["solution"].values]
    parts += [_fake_simulation(closed, e, 0.01 * (k + 1)).expand_dims("solution") for k, e in enumerate(engines)]
    dataset = xr.concat(parts, dim="solution", data_vars="all", coords="minimal", compat="override", join="outer")
    dataset["regime"].attrs.update(regime_attributes())
    dataset.attrs = dict(closed.attrs, scene=yaml.safe_dump(document))
    return dataset


@functools.cache
def swept_dataset() -> xr.Dataset:
    """A swept-sine dataset in the current layout: steady states along ``solution``, ``swept_<quantity>(sweep,
    frequency)`` (made up from pgf inside the swept band), ``running_x1_amplitude(sweep, elapsed_time)``, ``sweep_*``;
    cached: do not modify."""
    document: dict[str, Any] = {
        "name": "tiny_sweep",
        "description": "report test",
        "system": dict(PAPER_SYSTEM_SPEC),
        "excitation": {"amplitude": 10.0},
        "stop": {"clearance": 0.003, "restitution": 0.2},
        "bumper": {"frequency": 250.0},
        "sweep": {"frequency": {"start": 20.0, "stop": 30.0, "step": 0.05}},
        "swept_sine": {"start": 21.0, "stop": 29.0, "rate": 1.0, "sample_rate": 1000.0},
        "solutions": ["linear", "pgf", "compliant"],
        "simulation": {"rtol": 1e-6, "atol": 1e-10},
    }
    closed = _closed_forms(document)
    f = closed["frequency"].values
    inside = (f > 21.5) & (f < 28.5)
    pgf = closed.sel(solution="pgf", drop=True)
    dataset = closed.assign_coords(sweep=["up", "down"])
    for name in sweep_quantities(("x1", "x2")):
        base = pgf[name] if name in pgf else xr.zeros_like(pgf["x1_amplitude"])
        dataset[f"swept_{name}"] = xr.concat([base.where(inside) * 1.01, base.where(inside) * 0.99], dim="sweep").assign_attrs(pgf[name].attrs if name in pgf else {})
    contact = dataset["swept_impacts_per_period"] > 0.0
    regime = xr.where(np.isfinite(dataset["swept_x1_amplitude"]), xr.where(contact, int(Regime.SWEPT_CONTACT), int(Regime.LINEAR)), int(Regime.NOT_COMPUTED))
    dataset["swept_regime"] = regime.astype(np.int8).assign_attrs(regime_attributes())
    time = np.linspace(0.0, 8.0, 81)
    dataset = dataset.assign_coords(elapsed_time=("elapsed_time", time, {"units": "s"}))
    dataset["running_x1_amplitude"] = (("sweep", "elapsed_time"), np.vstack([np.full(time.size, 2e-3), np.full(time.size, 1.5e-3)]))
    for stat, value in (("wall_time", 3.0), ("steps", 1e4), ("contacts", 200.0), ("rhs_calls", 2e4), ("linear_start", 1.0), ("failed", 0.0)):
        dataset[f"sweep_{stat}"] = ("sweep", [value, value])
    sweep = document["swept_sine"]
    # what a swept-sine study stores of its sweep (the closed forms alone were run without it)
    stored = {"start_frequency": sweep["start"], "stop_frequency": sweep["stop"], "rate": sweep["rate"], "directions": np.array(["up", "down"]), "sample_rate": sweep["sample_rate"], "window_cycles": 8, "initial_state": "linear"}
    dataset.attrs = dict(closed.attrs, scene=yaml.safe_dump(document), study_kind="swept", **{f"swept_sine_{key}": value for key, value in stored.items()})
    return dataset


@functools.cache
def benchmark_dataset() -> xr.Dataset:
    """What the benchmark page reads (made up): two cases, three methods, four tolerances."""
    cases, engines, rtol = ["one_impact", "irregular"], ["momentary_adams", "compliant_ida", "solve_ivp_DOP853"], [1e-4, 1e-6, 1e-8, 1e-10]
    shape = (len(cases), len(engines), len(rtol))
    wall = np.broadcast_to(np.array([0.1, 0.2, 0.4, 0.8]), shape) * np.array([1.0, 2.0, 3.0])[None, :, None]
    error = np.broadcast_to(np.array([1e-3, 1e-5, 1e-7, 1e-9]), shape).copy()
    missed = np.zeros(shape)
    missed[0, 2, 0] = 1.0
    dims = ("case", "engine", "rtol")
    return xr.Dataset(
        {
            "wall_time": (dims, wall),
            "x1_error": (dims, error),
            "impact_time_error": (dims, error * 1e-3),
            "missed_impacts": (dims, missed),
            "extra_impacts": (dims, np.zeros(shape)),
            "impacts": (dims, np.full(shape, 40.0)),
            "steps": (dims, np.full(shape, 1000.0)),
            "rhs_calls": (dims, np.full(shape, 3000.0)),
            "impulse_error": (dims, error * 10.0),
            "reference_wall_time": (("case", "reference"), np.array([[0.05, np.nan], [0.05, 1.0]])),
            "reference_impacts": (("case", "reference"), np.array([[40.0, np.nan], [40.0, 40.0]])),
        },
        coords={"case": cases, "engine": engines, "rtol": rtol, "reference": ["exact", "compliant_cvode_adams"]},
        attrs={"scene_name": "tiny_benchmark", "scene": "name: tiny_benchmark\ndescription: made up\n", "vibroimpact_version": "0.1.0"},
    )


@functools.cache
def stiffness_dataset() -> xr.Dataset:
    """A bumper-stiffness study's shape: pgf, exact and compliant at two frequencies and three bumpers (made up)."""
    document: dict[str, Any] = {
        "name": "tiny_stiffness",
        "system": dict(PAPER_SYSTEM_SPEC),
        "excitation": {"amplitude": 10.0},
        "stop": {"clearance": 0.003, "restitution": 0.2},
        "sweep": {"bumper_frequency": [250.0, 1000.0, 4000.0], "frequency": [24.0, 25.0]},
        "solutions": ["pgf", "exact", "compliant"],
        "quantities": ["x1_amplitude", "regime", "wall_time"],
        "simulation": {"start": "pgf"},
    }
    bumper = np.array(document["sweep"]["bumper_frequency"])
    rigid = np.array([2.0e-3, 2.5e-3])
    x1 = np.empty((3, 3, 2))
    x1[0], x1[1] = rigid, rigid * (1.0 + 1e-9)
    x1[2] = rigid * (1.0 + 10.0 / bumper[:, None])
    wall = np.broadcast_to(np.array([np.nan, 0.05, 0.0])[:, None, None], (3, 3, 2)).copy()
    wall[2] = 0.001 * bumper[:, None] * np.ones(2)
    dims = ("solution", "bumper_frequency", "frequency")
    return xr.Dataset(
        {"x1_amplitude": (dims, x1), "wall_time": (dims, wall), "regime": (dims, np.full((3, 3, 2), int(Regime.ONE_IMPACT), dtype=np.int8))},
        coords={"solution": ["pgf", "exact", "compliant"], "bumper_frequency": bumper, "frequency": [24.0, 25.0], "restitution": 0.2, "clearance": 0.003},
        attrs={"scene_name": document["name"], "scene": yaml.safe_dump(document), "excitation_amplitude_N": 10.0, **{f"system_{key}": value for key, value in PAPER_SYSTEM_SPEC.items()}},
    )


def setting_of(dataset: xr.Dataset) -> StudySetting:
    """What ``dataset`` says of its system, excitation and grids."""
    return study_setting(dataset)


def _one_regime_panel() -> xr.Dataset:
    ds = steady_dataset(engines=(), restitution=(0.2,), step=0.5)
    return ds.sel(solution=["pgf"])


def _builders() -> dict[str, Callable[[], list[Any]]]:
    """Every kind of report figure, each built from a tiny dataset: name -> () -> list of DrawnFigure."""
    from vibroimpact.kinds.benchmark.page import accuracy_figures
    from vibroimpact.kinds.stepped.page import peak_acceleration_figure, peak_figure, stiffness_figure
    from vibroimpact.kinds.stepped.page import lyapunov_figure
    from vibroimpact.grids.sections import linear_figure
    from vibroimpact.kinds.stepped.responses import regime_figure, response_figure, simulation_figure, stability_figure
    from vibroimpact.scene.schema import ENGINE_SOLUTIONS
    from vibroimpact.kinds.swept.page import sweep_figures, swept_sine_run

    def steady() -> xr.Dataset:
        return steady_dataset()

    return {
        "linear": lambda: [linear_figure(setting_of(steady()))],
        "response_x1": lambda: [response_figure(steady(), "x1_amplitude", "x1")],
        "response_force": lambda: [response_figure(steady(), "force_amplitude", "force")],
        "response_impulse": lambda: [response_figure(steady(), "impulse", "impulse")],
        "response_pgf_compliant": lambda: [response_figure(steady().sel(solution=["linear", "pgf", "compliant"]), "x1_amplitude", "x1")],
        "regime": lambda: [regime_figure(steady(), "regime")],
        "regime_one_row": lambda: [regime_figure(_one_regime_panel(), "regime")],
        "stability": lambda: [stability_figure(steady(), "stability")],
        "simulation_x1": lambda: [simulation_figure(steady(), "x1_amplitude", list(ENGINE_SOLUTIONS), "sim")],
        "simulation_impulse": lambda: [simulation_figure(steady(), "impulse", list(ENGINE_SOLUTIONS), "sim")],
        "peak_acceleration": lambda: [peak_acceleration_figure(steady(), "peak")],
        "peaks_vs_restitution": lambda: [peak_figure(steady(), setting_of(steady()), "restitution", "peaks")],
        "sweep": lambda: sweep_figures(swept_dataset(), swept_sine_run(swept_dataset())),
        "stiffness": lambda: [stiffness_figure(stiffness_dataset(), setting_of(stiffness_dataset()), "stiffness")],
        "work_precision": lambda: accuracy_figures(benchmark_dataset()),
        "lyapunov": lambda: [lyapunov_figure(steady(), ["momentary", "exact"], "lyapunov")],
    }


#: Names of :func:`build` figure kinds, for parametrised tests.
FIGURE_KINDS = ("linear", "response_x1", "response_force", "response_impulse", "response_pgf_compliant", "regime", "regime_one_row", "stability", "simulation_x1", "simulation_impulse", "peak_acceleration", "peaks_vs_restitution", "sweep", "stiffness", "work_precision", "lyapunov")


def build(kind: str) -> list[Any]:
    """The drawn figures of ``kind`` (one of :data:`FIGURE_KINDS`); close them after use."""
    figures = _builders()[kind]()
    assert figures and all(f is not None for f in figures), kind
    return figures


# ------------------------------------------------------------------------------------------- inspectors
def visible(line: Line2D) -> np.ndarray:
    """Which data points of ``line`` show: a marker at every finite point, or a line segment to a finite neighbour
    (a point between two NaN draws nothing); on a log axis only positive values show."""
    x = np.asarray(line.get_xdata(), dtype=float)
    y = np.asarray(line.get_ydata(), dtype=float)
    finite = np.isfinite(x) & np.isfinite(y)
    ax = line.axes
    if ax is not None and ax.get_yscale() == "log":
        finite &= y > 0.0
    if line.get_marker() not in (None, "None", "none", "", " ") and line.get_markersize() > 0:
        return finite
    if line.get_linestyle() in ("None", "none", "", " "):
        return np.zeros(finite.shape, bool)
    return finite & (np.r_[False, finite[:-1]] | np.r_[finite[1:], False])


def shown_points(ax: Axes, gid: str) -> set[tuple[float, float]]:
    """(x, y) of every visible data point drawn in ``ax`` by artists with ``gid``, or by the line of a constant it
    shares with other curves, drawn once for them all (gid ``shared:<gid>+<gid>...``)."""
    points: set[tuple[float, float]] = set()
    for line in ax.get_lines():
        name = str(line.get_gid())
        if name == gid or (name.startswith("shared:") and gid in name[len("shared:") :].split("+")):
            mask = visible(line)
            x = np.asarray(line.get_xdata(), dtype=float)[mask]
            y = np.asarray(line.get_ydata(), dtype=float)[mask]
            points.update(zip(np.round(x, 9).tolist(), np.round(y, 12).tolist()))
    return points


def drawn_gids(fig: MatplotlibFigure) -> set[str]:
    """gids of the artists of ``fig`` that show at least one data point (lines) or cell (meshes)."""
    gids = set()
    for ax in fig.axes:
        for line in ax.get_lines():
            if line.get_gid() and visible(line).any():
                gids.add(line.get_gid())
        for collection in ax.collections:
            if collection.get_gid():
                gids.add(collection.get_gid())
    return gids


def _in_view(label: Text, ax: Axes, axis: str) -> bool:
    low, high = sorted((ax.get_xlim() if axis == "x" else ax.get_ylim()))
    position = label.get_position()[0 if axis == "x" else 1]
    return bool(low - 1e-12 * abs(low) <= position <= high + 1e-12 * abs(high))


def texts(fig: MatplotlibFigure) -> list[Text]:
    """Every text of ``fig`` that is drawn: titles, axis labels, tick labels in view, legend entries."""
    fig.canvas.draw()
    found: list[Text] = []
    for ax in fig.axes:
        found += [ax.title, ax._left_title, ax._right_title, ax.xaxis.label, ax.yaxis.label]  # noqa: SLF001
        for axis, getter in (("x", ax.xaxis), ("y", ax.yaxis)):
            found += [t for t in getter.get_ticklabels(which="both") if _in_view(t, ax, axis)]
        if ax.get_legend() is not None:
            found += ax.get_legend().get_texts()
    for legend in fig.legends:
        found += legend.get_texts()
    if fig._suptitle is not None:  # noqa: SLF001
        found.append(fig._suptitle)  # noqa: SLF001
    return [t for t in found if t.get_visible() and t.get_text().strip()]


def layout_problems(fig: MatplotlibFigure, min_font: float, max_width_px: float = PAGE_CONTENT_WIDTH) -> list[str]:
    """What a reader would stumble on: a figure wider than the page, small or clipped or overlapping text, a legend
    on a panel."""
    problems = []
    width = fig.get_size_inches()[0] * DPI
    if width > max_width_px:
        problems.append(f"figure {width:.0f} px wide")
    renderer = fig.canvas.get_renderer()
    found = texts(fig)
    frame = fig.bbox
    boxes = []
    for text in found:
        box = text.get_window_extent(renderer)
        if text.get_fontsize() < min_font:
            problems.append(f"{text.get_text()!r}: {text.get_fontsize()} pt")
        if box.x0 < frame.x0 - 1 or box.y0 < frame.y0 - 1 or box.x1 > frame.x1 + 1 or box.y1 > frame.y1 + 1:
            problems.append(f"{text.get_text()!r} clipped at the figure's edge")
        boxes.append(box.expanded(0.98, 0.9))
    for (a, box_a), (b, box_b) in itertools.combinations(zip(found, boxes), 2):
        if box_a.overlaps(box_b):
            problems.append(f"{a.get_text()!r} overlaps {b.get_text()!r}")
    legends = list(fig.legends) + [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None]
    for legend in legends:
        box = legend.get_window_extent(renderer)
        for ax in fig.axes:
            if box.overlaps(ax.get_window_extent(renderer)):
                problems.append(f"a legend lies on the panel {ax.get_title()!r}")
    return problems


def png_width(fig: MatplotlibFigure) -> int:
    """Width of ``fig`` written as the report writes it [px]."""
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=DPI, bbox_inches="tight", pad_inches=0.08)
    return int(struct.unpack(">I", buffer.getvalue()[16:20])[0])


# ------------------------------------------------------------------------------------ tests of the inspectors
def test_a_value_between_gaps_is_not_visible_on_a_line_but_is_as_a_marker() -> None:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    y = np.array([1.0, np.nan, 2.0, np.nan, 3.0, 4.0])
    line = ax.plot(np.arange(6.0), y)[0]
    dots = ax.plot(np.arange(6.0), y, "o", ls="none")[0]
    np.testing.assert_array_equal(visible(line), [False, False, False, False, True, True])
    np.testing.assert_array_equal(visible(dots), [True, False, True, False, True, True])
    plt.close(fig)


def test_overlapping_titles_and_legends_on_panels_are_found() -> None:
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 1, figsize=(FIGURE_WIDTH, 1.2))
    axes[0].set_xlabel("a long x label that the next title runs into")
    axes[1].set_title("a long title that runs into the label above")
    axes[1].plot([0, 1], [0, 1], label="data")
    axes[1].legend(fontsize=6)
    problems = layout_problems(fig, min_font=9.0)
    assert any("overlaps" in p for p in problems), problems
    assert any("lies on the panel" in p for p in problems), problems
    assert any("6.0 pt" in p for p in problems), problems
    plt.close(fig)


def test_every_figure_kind_is_listed() -> None:
    assert set(FIGURE_KINDS) == set(_builders())
