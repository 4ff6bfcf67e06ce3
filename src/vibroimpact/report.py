"""Comparison report of a study dataset: figures like the paper's 2-8 and a table of reduction factors.

``write_report(dataset, out_dir)`` writes PNG figures and a self-contained ``report.html`` (figures embedded as
base64) into ``out_dir``. Everything is derived from the dataset and the scene stored in its attributes.
"""

from __future__ import annotations

import base64
import html
import math
from pathlib import Path

from .report_common import Figure, save_figure  # sets the Agg backend before pyplot is imported

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import xarray as xr  # noqa: E402

from . import accuracy_report, bumper_report  # noqa: E402
from .atomic import atomic_path  # noqa: E402
from .linear import linear_response  # noqa: E402
from .modal import exact_modal_parameters, fit_modal_parameters, underdamped_mode_count  # noqa: E402
from .reduction import DEFINITION, paper_reduction_factors, reduction_factors  # noqa: E402
from .regime import Regime  # noqa: E402
from .scene import ENGINE_SOLUTIONS, Scene, parse_scene, read_yaml  # noqa: E402
from .system import PAPER_SYSTEM  # noqa: E402

__all__ = ["write_report"]

_LABELS = {
    "x1_amplitude": ("|X1| fundamental", "m"),
    "x2_amplitude": ("|X2| fundamental", "m"),
    "force_amplitude": ("|F| fundamental, suspension + impacts (eq. 23)", "N"),
    "suspension_force_amplitude": ("|F| fundamental, suspension only (eq. 21)", "N"),
    "impulse": ("impact impulse J", "N s"),
}


def write_report(dataset: xr.Dataset, out_dir: str | Path) -> Path:
    """Write the PNG figures and ``report.html`` for ``dataset`` into ``out_dir``; return the HTML path."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    scene = parse_scene(read_yaml(dataset.attrs["scene"]), text=dataset.attrs["scene"])
    if scene.benchmark is not None:
        return _write_text_atomic(out / "report.html", _html(dataset, scene, accuracy_report.accuracy_figures(dataset, out), accuracy_report.accuracy_tables(dataset)))
    figures = [_linear_figure(scene, out)]
    if scene.swept_sine is not None:
        # the pages show one (restitution, clearance, bumper) point: the first of each swept grid (the dataset has all)
        first = {d: 0 for d in ("restitution", "bumper_loss_factor", "clearance", "bumper_frequency") if d in dataset.dims}
        part = dataset.isel(first)
        figures += bumper_report.sweep_figures(part, scene, out)
        tables = [("Modal parameters of H22", _modal_table(scene)), *bumper_report.sweep_tables(part, scene)]
        if first:
            tables.append(("Grid", f"<p>Figures and tables show the first point of the swept grids ({', '.join(first)}); the dataset holds every point.</p>"))
        return _write_text_atomic(out / "report.html", _html(dataset, scene, figures, tables))
    if "bumper_frequency" in dataset.dims:
        figures += bumper_report.stiffness_figures(dataset, scene, out)
        tables = [("Modal parameters of H22", _modal_table(scene)), *bumper_report.stiffness_tables(dataset, scene)]
        return _write_text_atomic(out / "report.html", _html(dataset, scene, figures, tables))
    for clearance_index in range(dataset.sizes.get("clearance", 1)):
        part = dataset.isel(clearance=clearance_index) if "clearance" in dataset.dims else dataset
        tag = f"_clearance{clearance_index}" if "clearance" in dataset.dims else ""
        for quantity in ("x2_amplitude", "x1_amplitude", "force_amplitude", "suspension_force_amplitude", "impulse"):
            if quantity in part:
                figures.append(_response_figure(part, quantity, out / f"{quantity}{tag}.png"))
        if "regime" in part:
            figures.append(_regime_figure(part, out / f"regime{tag}.png"))
        if "floquet_modulus" in part and "pgf" in part["solution"].values:
            figures.append(_stability_figure(part, out / f"stability{tag}.png"))
        if "peak_acceleration" in part and "compliant" in part["solution"].values:
            figures += bumper_report.peak_acceleration_figure(part, scene, out / f"peak_acceleration{tag}.png")
        engines = [name for name in part["solution"].values if name in ENGINE_SOLUTIONS]
        if engines:
            for quantity in ("x1_amplitude", "x2_amplitude", "force_amplitude", "impulse"):
                if quantity in part:
                    figures.append(_simulation_figure(part, quantity, engines, out / f"simulation_{quantity}{tag}.png"))
    tables = _tables(dataset, scene)
    engines_present = any(name in ENGINE_SOLUTIONS for name in dataset["solution"].values)
    for parameter in ("restitution", "clearance"):
        if parameter in dataset.dims and engines_present and "x1_amplitude" in dataset:
            figures += bumper_report.peak_figures(dataset, scene, parameter, out)
            tables += bumper_report.peak_tables(dataset, scene, parameter)
    page = _html(dataset, scene, figures, tables)
    return _write_text_atomic(out / "report.html", page)


# ------------------------------------------------------------------------------------------- figures
def _clearance_text(part: xr.Dataset) -> str:
    return f"{float(part['clearance']) * 1e3:.6g} mm"


def _style(f: np.ndarray) -> dict[str, object]:
    """Markers where a grid is too coarse for lines to mean anything."""
    return {"marker": "o", "ms": 3} if f.size < 30 else {}


def _linear_figure(scene: Scene, out: Path) -> Figure:
    system = scene.system
    f = scene.frequency
    w = 2.0 * np.pi * f
    response = linear_response(system, w, scene.amplitude)
    exact = system.receptances(w).h22
    fit = fit_modal_parameters(system) if underdamped_mode_count(system) == 2 else None
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.2))
    ax = axes[0]
    ax.semilogy(f, np.abs(response.x1), label="|X1| primary")
    ax.semilogy(f, np.abs(response.x2), label="|X2| absorber")
    for delta in scene.clearance:
        ax.axhline(delta, color="k", lw=0.8, ls="--")
    ax.set(xlabel="frequency [Hz]", ylabel="amplitude [m]", title="Linear responses (paper fig. 2); dashed: clearance")
    ax.legend()
    ax = axes[1]
    ax.semilogy(f, np.abs(response.force), color="C2")
    ax.set(xlabel="frequency [Hz]", ylabel="force [N]", title="Linear force on the base (paper fig. 3)")
    ax = axes[2]
    ax.semilogy(f, np.abs(exact), label="|H22| exact (eq. 4)")
    step = max(1, f.size // 150)
    if fit is not None:
        ax.semilogy(f[::step], np.abs(fit.receptance(w[::step])), "o", mfc="none", ms=4, label="eq. 10, fitted modes")
    ax.set(xlabel="frequency [Hz]", ylabel="|H22| [m/N]", title="Accuracy of the curve fit (paper fig. 4)")
    ax.legend()
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
    caption = (
        f"Linear system (Delta -> infinity). Natural frequencies {', '.join(f'{x / (2 * np.pi):.3f}' for x in system.natural_frequencies())} Hz, "
        f"anti-resonance {system.antiresonance_frequency() / (2 * np.pi):.3f} Hz."
    )
    return Figure(save_figure(fig, out / "linear.png"), caption)


def _lines(part: xr.Dataset) -> list[tuple[str, xr.Dataset]]:
    if "restitution" in part.dims:
        return [(f"R = {float(r):g}", part.sel(restitution=r)) for r in part["restitution"].values]
    return [(f"R = {float(part['restitution']):g}", part)]


def _response_figure(part: xr.Dataset, quantity: str, path: Path) -> Figure:
    impact_solutions = [s for s in part["solution"].values if s != "linear"]
    label, units = _LABELS[quantity]
    clearance_text = _clearance_text(part)
    panels = impact_solutions or ["linear"]
    fig, axes = plt.subplots(1, len(panels), figsize=(7.5 * len(panels), 4.6), sharey=True, squeeze=False)
    f = part["frequency"].values
    style = _style(f)
    raw_name = f"one_impact_{quantity}" if quantity != "suspension_force_amplitude" else ""
    has_linear = "linear" in part["solution"].values and quantity != "impulse"
    top = 0.0
    for ax, solution in zip(axes[0], panels):
        if has_linear:
            linear = part[quantity].sel(solution="linear").isel(_first(part)).values
            ax.plot(f, linear, ":", color="k", lw=1.2, label="LIN", **style)
            top = max(top, float(np.nanmax(linear, initial=0.0)))
        if solution == "linear":
            continue
        for i, (name, line) in enumerate(_lines(part)):
            values = line[quantity].sel(solution=solution).values
            top = max(top, float(np.nanmax(values, initial=0.0)))
            unstable = line["stable"].sel(solution=solution).values == 0 if "stable" in line else np.zeros(values.shape, bool)
            ax.plot(f, np.where(unstable, np.nan, values), color=f"C{i}", lw=1.0, label=name, **style)
            if unstable.any():
                ax.plot(f, np.where(unstable, values, np.nan), color=f"C{i}", lw=0.8, ls="--", alpha=0.45)
            if raw_name in line:
                ax.plot(f, line[raw_name].sel(solution=solution).values, color=f"C{i}", lw=0.6, alpha=0.25)
        ax.set(title=f"{solution}: {label} (Delta = {clearance_text})", xlabel="frequency [Hz]", ylabel=f"{label} [{units}]")
        if quantity != "impulse":
            ax.set_yscale("log")
        ax.grid(True, which="both", alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=8)
    if top > 0.0:
        axes[0, 0].set_ylim(top=3.0 * top if quantity != "impulse" else 1.3 * top)
    parts = [f"{label} against frequency, Delta = {clearance_text}; one curve per restitution ratio."]
    if has_linear:
        parts.append("LIN (dotted): linear system.")
    parts.append("Gaps: no admissible one-impact regime while the linear motion would cross the stop.")
    if "stable" in part:
        parts.append("Faint dashed (pgf): one-impact orbits that exist but are unstable (Floquet); the real motion there is another one.")
    if raw_name in part:
        parts.append("Faint thin: the raw one-impact solution wherever eqs. 15-16 have a root, unchecked; this is what the paper plots, spikes included.")
    if len(panels) == 2:
        parts.append("Left: exact poles/residues and exact chi22'(0-); right: the paper's fitted modes and constant chi22'(0-).")
    return Figure(save_figure(fig, path), " ".join(parts))


def _first(part: xr.Dataset) -> dict[str, int]:
    """Index the first restitution value (the linear response does not depend on it)."""
    return {"restitution": 0} if "restitution" in part.dims else {}


def _regime_figure(part: xr.Dataset, path: Path) -> Figure:
    solutions = list(part["solution"].values)
    clearance_text = _clearance_text(part)
    lines = _lines(part)
    fig, axes = plt.subplots(len(solutions), 1, figsize=(15, 0.5 + 0.45 * len(lines) * len(solutions) + 0.6 * len(solutions)), sharex=True, squeeze=False)
    flags = [r for r in Regime if r is not Regime.NOT_COMPUTED]
    cmap = plt.get_cmap("tab10", len(flags))
    f = part["frequency"].values
    for ax, solution in zip(axes[:, 0], solutions):
        grid = np.array([line["regime"].sel(solution=solution).values for _, line in lines], dtype=float)
        computed = np.any(grid != Regime.NOT_COMPUTED, axis=0)
        columns = f[computed]
        # each column spans halfway to its neighbours, so coarse simulation grids show as blocks, not hairlines
        edges = np.concatenate([[f[0]], (columns[1:] + columns[:-1]) / 2.0, [f[-1]]]) if columns.size else np.array([f[0], f[-1]])
        values = np.ma.masked_equal(grid[:, computed], Regime.NOT_COMPUTED) if columns.size else np.ma.masked_all((len(lines), 1))
        ax.pcolormesh(edges, np.arange(len(lines) + 1) - 0.5, values, cmap=cmap, vmin=-0.5, vmax=len(flags) - 0.5, shading="flat")
        ax.set_ylim(len(lines) - 0.5, -0.5)
        ax.set_yticks(range(len(lines)), [name for name, _ in lines])
        ax.set_title(f"{solution}: regime (Delta = {clearance_text})", fontsize=10)
    axes[-1, 0].set_xlabel("frequency [Hz]")
    handles = [plt.Rectangle((0, 0), 1, 1, color=cmap(int(r))) for r in flags]
    fig.legend(handles, [r.name.lower() for r in flags], loc="lower center", ncol=4, fontsize=8, bbox_to_anchor=(0.5, -0.02 - 0.12 / len(solutions)))
    caption = (
        "Regime of each point (the dataset's 'regime' flag): where each value comes from, where the one-impact solution "
        "is missing, inadmissible or unstable, and what the simulations found (periodic or irregular impacting motion)."
    )
    return Figure(save_figure(fig, path), caption)


def _stability_figure(part: xr.Dataset, path: Path) -> Figure:
    clearance_text = _clearance_text(part)
    fig, ax = plt.subplots(figsize=(12, 4.2))
    f = part["frequency"].values
    for i, (name, line) in enumerate(_lines(part)):
        ax.semilogy(f, line["floquet_modulus"].sel(solution="pgf").values, color=f"C{i}", lw=1.0, label=name, **_style(f))
    ax.axhline(1.0, color="k", lw=1.0)
    ax.set(xlabel="frequency [Hz]", ylabel="max |Floquet multiplier|", title=f"pgf: stability of the one-impact orbit (Delta = {clearance_text})")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    caption = (
        "Largest Floquet multiplier modulus of the exact one-impact orbit (monodromy = impact saltation matrix x exact flow "
        "over the period). Above 1 the orbit exists but is unstable: a simulation started on it leaves it."
    )
    return Figure(save_figure(fig, path), caption)


def _simulation_figure(part: xr.Dataset, quantity: str, engines: list[str], path: Path) -> Figure:
    """Simulation against PGF, one panel per restitution ratio (like the paper's figures 21-24)."""
    label, units = _LABELS[quantity]
    lines = _lines(part)
    columns = min(3, len(lines))
    rows = math.ceil(len(lines) / columns)
    fig, axes = plt.subplots(rows, columns, figsize=(6.2 * columns, 3.8 * rows), squeeze=False, sharex=True)
    f = part["frequency"].values
    simulated = np.isin(f, np.asarray(part.attrs.get("simulation_frequency_Hz", f)))
    markers = {"momentary": ("o", 4.5), "exact": ("x", 4.0), "compliant": ("s", 4.0)}
    for ax, (name, line) in zip(axes.flat, lines):
        if "linear" in part["solution"].values and quantity != "impulse":
            ax.plot(f, line[quantity].sel(solution="linear").values, ":", color="k", lw=1.0, label="LIN")
        if "pgf" in part["solution"].values:
            values = line[quantity].sel(solution="pgf").values
            unstable = line["stable"].sel(solution="pgf").values == 0 if "stable" in line else np.zeros(values.shape, bool)
            ax.plot(f, np.where(unstable, np.nan, values), color="C0", lw=1.1, label="pgf")
            if unstable.any():
                ax.plot(f, np.where(unstable, values, np.nan), color="C0", lw=0.8, ls="--", alpha=0.5, label="pgf, unstable orbit")
        for k, engine in enumerate(engines):
            values = line[quantity].sel(solution=engine).values[simulated]
            converged = line["converged"].sel(solution=engine).values[simulated] == 1 if "converged" in line else np.ones(values.shape, bool)
            marker, size = markers.get(engine, ("s", 4.0))
            color = f"C{k + 1}"
            ax.plot(f[simulated][converged], values[converged], marker, color=color, ms=size, mfc=color if marker == "o" else "none", ls="none", label=f"{engine}, periodic")
            if (~converged).any():
                ax.plot(f[simulated][~converged], values[~converged], marker, color=color, ms=size, mfc="none", ls="none", alpha=0.8, label=f"{engine}, irregular")
        if quantity != "impulse":
            ax.set_yscale("log")
        ax.set(title=f"{name}", xlabel="frequency [Hz]", ylabel=f"{label} [{units}]")
        ax.grid(True, which="both", alpha=0.3)
    for ax in list(axes.flat)[len(lines) :]:
        ax.set_visible(False)
    handles, names = axes.flat[0].get_legend_handles_labels()
    fig.legend(handles, names, loc="upper center", ncol=6, fontsize=8, bbox_to_anchor=(0.5, 0.0))
    fig.suptitle(f"Simulation against PGF: {label} (Delta = {_clearance_text(part)})", y=1.0 + 0.06 / rows)
    caption = (
        f"{label}: steady states simulated at each marked frequency (filled: the stroboscopic state repeated; hollow: "
        "irregular motion, averaged over the measured periods) against the PGF closed form (solid where its orbit is "
        "stable, dashed where unstable). Impulse of a simulation: mean impulse per impact."
    )
    return Figure(save_figure(fig, path), caption)


def _agreement_table(dataset: xr.Dataset, scene: Scene) -> str:
    """Simulation against PGF by band: relative differences of |X1| where the PGF orbit is stable and where not."""
    engines = [name for name in dataset["solution"].values if name in ENGINE_SOLUTIONS]
    if not engines or "pgf" not in dataset["solution"].values or "x1_amplitude" not in dataset or scene.simulation is None:
        return ""
    split = scene.system.antiresonance_frequency() / (2.0 * np.pi)
    sim_f = scene.simulation.frequency
    data = dataset.sel(frequency=sim_f)
    header = (
        "<tr><th>engine</th><th>Delta [mm]</th><th>R</th><th>band</th><th>points</th><th>max rel. diff. |X1|, PGF stable or linear</th>"
        "<th>median</th><th>PGF unstable: points</th><th>max rel. diff. there</th><th>simulation irregular</th><th>simulation with other than 1 or 0 impacts per period</th></tr>"
    )
    body = []
    for engine in engines:
        for delta in np.atleast_1d(data["clearance"].values):
            for r in np.atleast_1d(data["restitution"].values):
                sel = {k: v for k, v in (("clearance", delta), ("restitution", r)) if k in data.dims}
                line = data.sel(sel)
                sim = line["x1_amplitude"].sel(solution=engine).values
                pgf = line["x1_amplitude"].sel(solution="pgf").values
                # the one-impact orbit is unstable where flagged so, and where pgf reports the linear motion instead (regime 7)
                unstable = line["regime"].sel(solution="pgf").values == Regime.LINEAR_WITH_UNSTABLE_ONE_IMPACT
                if "stable" in line:
                    unstable = unstable | (line["stable"].sel(solution="pgf").values == 0)
                irregular = line["converged"].sel(solution=engine).values == 0 if "converged" in line else np.zeros(sim.shape, bool)
                other = ~np.isin(line["impacts_per_period"].sel(solution=engine).values, (0.0, 1.0)) if "impacts_per_period" in line else np.zeros(sim.shape, bool)
                with np.errstate(invalid="ignore", divide="ignore"):
                    difference = np.abs(sim - pgf) / np.abs(pgf)
                for band, mask in (("1", sim_f < split), ("2", sim_f >= split)):
                    good = mask & ~unstable & np.isfinite(difference)
                    bad = mask & unstable & np.isfinite(difference)
                    body.append(
                        f"<tr><td>{engine}</td><td>{float(delta) * 1e3:g}</td><td>{float(r):g}</td><td>{band}</td><td>{int(mask.sum())}</td>"
                        f"<td>{_fmt(_largest(difference[good]))}</td><td>{_fmt(np.median(difference[good]) if good.any() else np.nan)}</td>"
                        f"<td>{int(bad.sum())}</td><td>{_fmt(_largest(difference[bad]))}</td><td>{int((irregular & mask).sum())}</td><td>{int((other & mask).sum())}</td></tr>"
                    )
    return f"<table>{header}{''.join(body)}</table>"


def _largest(values: np.ndarray) -> float:
    return float(np.max(values)) if values.size else math.nan


def _fmt(value: float) -> str:
    return "" if not np.isfinite(value) else f"{value:.1e}"


# -------------------------------------------------------------------------------------------- tables
def _tables(dataset: xr.Dataset, scene: Scene) -> list[tuple[str, str]]:
    tables = [("Modal parameters of H22", _modal_table(scene))]
    solutions = [s for s in dataset["solution"].values if s != "linear"]
    for quantity in ("x1_amplitude", "force_amplitude", "suspension_force_amplitude", "x2_amplitude"):
        if quantity not in dataset or not solutions:
            continue
        label, units = _LABELS[quantity]
        header = (
            f"<tr><th>solution</th><th>Delta [mm]</th><th>R</th><th>linear peak 1 / 2 [{units}]</th><th>largest realisable in band 1 / 2</th>"
            "<th>reduction factor 1</th><th>reduction factor 2</th><th>undefined points 1 / 2</th><th>unstable points 1 / 2</th><th>paper</th></tr>"
        )
        body = []
        for solution in solutions:
            for row in reduction_factors(dataset, scene, quantity, solution):
                paper = paper_reduction_factors(scene, quantity, row.restitution, row.clearance)
                factors = "".join(f"<td>{factor:.1f}{' &dagger;' if coarse else ''}</td>" for factor, coarse in zip(row.factor, row.coarse))
                unstable = "n/a" if row.unstable is None else f"{row.unstable[0]} / {row.unstable[1]}"
                body.append(
                    f"<tr><td>{solution}</td><td>{row.clearance * 1e3:g}</td><td>{row.restitution:g}</td>"
                    f"<td>{row.linear_peak[0]:.4g} / {row.linear_peak[1]:.4g}</td><td>{row.largest[0]:.4g} / {row.largest[1]:.4g}</td>"
                    f"{factors}<td>{row.undefined[0]} / {row.undefined[1]}</td><td>{unstable}</td>"
                    f"<td>{'' if paper is None else f'{paper[0]:g} / {paper[1]:g}'}</td></tr>"
                )
        tables.append((f"Reduction factors: {label}", f"<table>{header}{''.join(body)}</table>"))
    agreement = _agreement_table(dataset, scene)
    if agreement:
        tables.append(("Simulation against PGF by band (|X1| fundamental)", agreement))
    return tables


def _modal_table(scene: Scene) -> str:
    exact = exact_modal_parameters(scene.system)
    fit = fit_modal_parameters(scene.system) if exact.omega.size == 2 else None
    rows = ["<tr><th>mode</th><th>Omega/2pi [Hz]</th><th>xi exact</th><th>xi fitted</th><th>A exact (complex) [1/kg]</th><th>A fitted [1/kg]</th></tr>"]
    for i in range(exact.omega.size):
        a = exact.form_factor[i]
        fitted = ("", "") if fit is None else (f"{fit.loss_factor[i]:.5f}", f"{np.real(fit.form_factor[i]):.4f}")
        rows.append(
            f"<tr><td>{i + 1}</td><td>{exact.omega[i] / (2 * np.pi):.4f}</td><td>{exact.loss_factor[i]:.5f}</td><td>{fitted[0]}</td>"
            f"<td>{a.real:.4f} {a.imag:+.4f}j</td><td>{fitted[1]}</td></tr>"
        )
    note = "The paper prints A = 2.75, 7.25 and xi = 0.0022, 0.0023 for its system (eq. 24)." if scene.system == PAPER_SYSTEM else ""
    if fit is None:
        note += " The system has fewer than two underdamped modes: the paper's fit does not apply."
    return "<table>" + "".join(rows) + f"</table><p>{note}</p>"


def _html(dataset: xr.Dataset, scene: Scene, figures: list[Figure], tables: list[tuple[str, str]]) -> str:
    parts = [
        "<!DOCTYPE html><html><head><meta charset='utf-8'>",
        f"<title>vibroimpact report: {html.escape(scene.name)}</title>",
        "<style>body{font-family:sans-serif;max-width:1500px;margin:2em auto;padding:0 1em;color:#222}"
        "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #bbb;padding:3px 8px;text-align:right}"
        "img{max-width:100%}pre{background:#f4f4f4;padding:1em;overflow:auto}figcaption{font-size:90%;color:#444}</style>",
        "</head><body>",
        f"<h1>Study '{html.escape(scene.name)}'</h1>",
        f"<p>{html.escape(scene.description)}</p>",
        f"<p>vibroimpact {html.escape(str(dataset.attrs.get('vibroimpact_version', '?')))}; "
        f"{'solutions: ' + ', '.join(map(str, dataset['solution'].values)) if 'solution' in dataset.coords else 'methods: ' + ', '.join(map(str, dataset['engine'].values))}.</p>",
        "<h2>Figures</h2>",
    ]
    for figure in figures:
        encoded = base64.b64encode(figure.path.read_bytes()).decode("ascii")
        parts.append(f"<figure><img alt='{figure.path.name}' src='data:image/png;base64,{encoded}'><figcaption>{html.escape(figure.caption)} ({figure.path.name})</figcaption></figure>")
    parts.append("<h2>Tables</h2>")
    if scene.benchmark is None:
        parts.append(f"<p>{html.escape(DEFINITION)}</p>")
        parts.append("<p>&dagger;: the grid step in that band exceeds a quarter of the linear peak's half-power width; a narrow maximum may be missed.</p>")
    for title, table in tables:
        parts.append(f"<h3>{html.escape(title)}</h3>{table}")
    parts.append(f"<h2>Scene</h2><pre>{html.escape(scene.text)}</pre></body></html>")
    return "\n".join(parts)


def _write_text_atomic(path: Path, text: str) -> Path:
    with atomic_path(path) as temporary:
        temporary.write_text(text, encoding="utf-8")
    return path
