"""Comparison report of a study dataset: figures like the paper's 2-8 and a table of reduction factors.

``write_report(dataset, out_dir)`` writes PNG figures and a self-contained ``report.html`` (figures embedded as
base64) into ``out_dir``. Everything is derived from the dataset and the scene stored in its attributes.
"""

from __future__ import annotations

import base64
import html
import io
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import xarray as xr  # noqa: E402

from .linear import linear_response, resonance_peaks  # noqa: E402
from .modal import exact_modal_parameters, fit_modal_parameters  # noqa: E402
from .regime import Regime  # noqa: E402
from .scene import Scene, parse_scene, read_yaml  # noqa: E402

__all__ = ["REDUCTION_FACTOR_DEFINITION", "ReductionRow", "reduction_factors", "write_report"]

REDUCTION_FACTOR_DEFINITION = (
    "Reduction factor of a quantity at linear resonance i = (peak of the linear response near natural frequency i, "
    "found by analytic maximisation, not from the grid) / (largest value of the vibro-impact solution on the grid "
    "within that resonance's band). The bands split the frequency range at the anti-resonance sqrt(K2/M2): band 1 "
    "below it, band 2 above it. Points where the solution is undefined (NaN: no admissible one-impact regime and "
    "the linear motion would cross the stop) are left out and counted in the 'undefined' column; where there are "
    "any, the factor is an upper bound. The 'unstable' column counts grid points of the band whose one-impact orbit "
    "is unstable (pgf only): the factor is computed from those values too, as in the paper, but the real motion "
    "there is another one (possibly larger), so treat such factors with care."
)
_PAPER_VALUES: dict[str, dict[float, tuple[float, float]]] = {"x1_amplitude": {0.2: (28.0, 23.0)}, "force_amplitude": {0.2: (25.0, 30.0)}}
_PEAK_QUANTITY = {"x1_amplitude": "x1", "x2_amplitude": "x2", "force_amplitude": "force", "suspension_force_amplitude": "force"}
_LABELS = {
    "x1_amplitude": ("|X1| fundamental", "m"),
    "x2_amplitude": ("|X2| fundamental", "m"),
    "force_amplitude": ("|F| fundamental, suspension + impacts", "N"),
    "suspension_force_amplitude": ("|F| fundamental, suspension only", "N"),
    "impulse": ("impact impulse J", "N s"),
}


@dataclass(frozen=True)
class Figure:
    """A figure written to disk and its caption."""

    path: Path
    caption: str


def write_report(dataset: xr.Dataset, out_dir: str | Path) -> Path:
    """Write the PNG figures and ``report.html`` for ``dataset`` into ``out_dir``; return the HTML path."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    scene = parse_scene(read_yaml(dataset.attrs["scene"]), text=dataset.attrs["scene"])
    figures = [_linear_figure(scene, out)]
    for clearance_index in range(dataset.sizes.get("clearance", 1)):
        part = dataset.isel(clearance=clearance_index) if "clearance" in dataset.dims else dataset
        for quantity in ("x2_amplitude", "x1_amplitude", "force_amplitude", "impulse"):
            if quantity in part:
                figures.append(_response_figure(part, quantity, out))
        if "regime" in part:
            figures.append(_regime_figure(part, out))
        if "floquet_modulus" in part and "pgf" in part["solution"].values:
            figures.append(_stability_figure(part, out))
    tables = _tables(dataset, scene)
    page = _html(dataset, scene, figures, tables)
    return _write_text_atomic(out / "report.html", page)


# ------------------------------------------------------------------------------------------- figures
def _save(fig: plt.Figure, path: Path) -> Path:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=110, bbox_inches="tight")
    plt.close(fig)
    path.write_bytes(buffer.getvalue())
    return path


def _clearance_tag(part: xr.Dataset) -> tuple[str, str]:
    value = float(part["clearance"])
    return f"{value * 1e3:g} mm", f"_clearance_{value * 1e3:g}mm" if "clearance" in part.coords and part["clearance"].size == 1 else ""


def _linear_figure(scene: Scene, out: Path) -> Figure:
    system = scene.system
    f = scene.frequency
    w = 2.0 * np.pi * f
    response = linear_response(system, w, scene.amplitude)
    exact = system.receptances(w).h22
    fit = fit_modal_parameters(system)
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
    ax.semilogy(f[::step], np.abs(fit.receptance(w[::step])), "o", mfc="none", ms=4, label="eq. 10, fitted modes")
    ax.set(xlabel="frequency [Hz]", ylabel="|H22| [m/N]", title="Accuracy of the curve fit (paper fig. 4)")
    ax.legend()
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
    caption = (
        f"Linear system (Delta -> infinity). Natural frequencies {', '.join(f'{x / (2 * np.pi):.3f}' for x in system.natural_frequencies())} Hz, "
        f"anti-resonance {system.antiresonance_frequency() / (2 * np.pi):.3f} Hz."
    )
    return Figure(_save(fig, out / "linear.png"), caption)


def _lines(part: xr.Dataset) -> list[tuple[str, xr.Dataset]]:
    if "restitution" in part.dims:
        return [(f"R = {float(r):g}", part.sel(restitution=r)) for r in part["restitution"].values]
    return [(f"R = {float(part['restitution']):g}", part)]


def _response_figure(part: xr.Dataset, quantity: str, out: Path) -> Figure:
    impact_solutions = [s for s in part["solution"].values if s != "linear"]
    label, units = _LABELS[quantity]
    clearance_text, tag = _clearance_tag(part)
    panels = impact_solutions or ["linear"]
    fig, axes = plt.subplots(1, len(panels), figsize=(7.5 * len(panels), 4.6), sharey=True, squeeze=False)
    f = part["frequency"].values
    for ax, solution in zip(axes[0], panels):
        if "linear" in part["solution"].values and quantity != "impulse":
            ax.plot(f, part[quantity].sel(solution="linear").isel(_first(part)).values, ":", color="k", lw=1.2, label="LIN")
        if solution != "linear":
            for i, (name, line) in enumerate(_lines(part)):
                values = line[quantity].sel(solution=solution).values
                unstable = line["stable"].sel(solution=solution).values == 0 if "stable" in line else np.zeros(values.shape, bool)
                ax.plot(f, np.where(unstable, np.nan, values), color=f"C{i}", lw=1.0, label=name)
                if unstable.any():
                    ax.plot(f, np.where(unstable, values, np.nan), color=f"C{i}", lw=0.8, ls="--", alpha=0.45)
        ax.set(title=f"{solution}: {label} (Delta = {clearance_text})", xlabel="frequency [Hz]", ylabel=f"{label} [{units}]")
        if quantity != "impulse":
            ax.set_yscale("log")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    caption = (
        f"{label} against frequency, Delta = {clearance_text}; one curve per restitution ratio, LIN = linear system. "
        "Gaps: no admissible one-impact regime while the linear motion would cross the stop. "
        "Faint dashed: one-impact orbits that exist but are unstable (Floquet multiplier outside the unit circle; pgf only): "
        "the real motion there is not this orbit. "
        "Left: exact poles/residues and exact chi22'(0-); right: the paper's fitted modes and constant chi22'(0-)."
    )
    return Figure(_save(fig, out / f"{quantity}{tag}.png"), caption)


def _first(part: xr.Dataset) -> dict[str, int]:
    """Index the first restitution value (the linear response does not depend on it)."""
    return {"restitution": 0} if "restitution" in part.dims else {}


def _regime_figure(part: xr.Dataset, out: Path) -> Figure:
    solutions = list(part["solution"].values)
    clearance_text, tag = _clearance_tag(part)
    lines = _lines(part)
    fig, axes = plt.subplots(len(solutions), 1, figsize=(15, 0.5 + 0.45 * len(lines) * len(solutions) + 0.6 * len(solutions)), sharex=True, squeeze=False)
    cmap = plt.get_cmap("tab10", len(Regime))
    f = part["frequency"].values
    for ax, solution in zip(axes[:, 0], solutions):
        grid = np.array([line["regime"].sel(solution=solution).values for _, line in lines], dtype=float)
        extent = (f[0], f[-1], len(lines) - 0.5, -0.5)
        ax.imshow(grid, aspect="auto", interpolation="nearest", cmap=cmap, vmin=-0.5, vmax=len(Regime) - 0.5, extent=extent)
        ax.set_yticks(range(len(lines)), [name for name, _ in lines])
        ax.set_title(f"{solution}: regime (Delta = {clearance_text})", fontsize=10)
    axes[-1, 0].set_xlabel("frequency [Hz]")
    handles = [plt.Rectangle((0, 0), 1, 1, color=cmap(int(r))) for r in Regime]
    fig.legend(handles, [r.name.lower() for r in Regime], loc="lower center", ncol=4, fontsize=8, bbox_to_anchor=(0.5, -0.08))
    caption = "Regime of each point (the dataset's 'regime' flag): where each value comes from and where the one-impact solution is missing or inadmissible."
    return Figure(_save(fig, out / f"regime{tag}.png"), caption)


def _stability_figure(part: xr.Dataset, out: Path) -> Figure:
    clearance_text, tag = _clearance_tag(part)
    fig, ax = plt.subplots(figsize=(12, 4.2))
    f = part["frequency"].values
    for i, (name, line) in enumerate(_lines(part)):
        ax.semilogy(f, line["floquet_modulus"].sel(solution="pgf").values, color=f"C{i}", lw=1.0, label=name)
    ax.axhline(1.0, color="k", lw=1.0)
    ax.set(xlabel="frequency [Hz]", ylabel="max |Floquet multiplier|", title=f"pgf: stability of the one-impact orbit (Delta = {clearance_text})")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    caption = (
        "Largest Floquet multiplier modulus of the exact one-impact orbit (monodromy = impact saltation matrix x exact flow "
        "over the period). Above 1 the orbit exists but is unstable: a simulation started on it leaves it."
    )
    return Figure(_save(fig, out / f"stability{tag}.png"), caption)


# -------------------------------------------------------------------------------------------- tables
@dataclass(frozen=True)
class ReductionRow:
    """Reduction factors of one quantity for one (clearance, R): one entry per linear resonance (mode 1, 2).

    Attributes
    ----------
    clearance : float
        Delta [m].
    restitution : float
        R [-].
    linear_peak : tuple of float
        Analytic linear peak near each natural frequency (units of the quantity).
    largest : tuple of float
        Largest vibro-impact value on the grid in each band.
    factor : tuple of float
        linear_peak / largest [-].
    undefined : tuple of int
        Grid points of the band with NaN (no admissible regime).
    unstable : tuple of int
        Grid points of the band whose one-impact orbit is unstable.
    """

    clearance: float
    restitution: float
    linear_peak: tuple[float, ...]
    largest: tuple[float, ...]
    factor: tuple[float, ...]
    undefined: tuple[int, ...]
    unstable: tuple[int, ...]


def reduction_factors(dataset: xr.Dataset, scene: Scene, quantity: str, solution: str) -> list[ReductionRow]:
    """Reduction factor of ``quantity`` at each linear resonance for each (clearance, R) of ``dataset``.

    See :data:`REDUCTION_FACTOR_DEFINITION`.
    """
    peaks = resonance_peaks(scene.system, scene.amplitude, _PEAK_QUANTITY[quantity])
    split = scene.system.antiresonance_frequency() / (2.0 * np.pi)
    data = dataset[quantity].sel(solution=solution)
    stable = dataset["stable"].sel(solution=solution) if "stable" in dataset else None
    f = data["frequency"]
    bands = [f < split, f >= split]
    rows = []
    for delta in np.atleast_1d(data["clearance"].values):
        for r in np.atleast_1d(data["restitution"].values):
            sel = {k: v for k, v in (("clearance", delta), ("restitution", r)) if k in data.dims}
            line = data.sel(sel)
            largest = tuple(float(line.where(b).max()) if bool(b.any()) else np.nan for b in bands)
            unstable_line = stable.sel(sel) == 0 if stable is not None else xr.zeros_like(line, dtype=bool)
            rows.append(
                ReductionRow(
                    clearance=float(delta),
                    restitution=float(r),
                    linear_peak=tuple(p.value for p in peaks),
                    largest=largest,
                    factor=tuple(p.value / v if v > 0 else np.nan for p, v in zip(peaks, largest)),
                    undefined=tuple(int((line.isnull() & b).sum()) for b in bands),
                    unstable=tuple(int((unstable_line & b).sum()) for b in bands),
                )
            )
    return rows


def _tables(dataset: xr.Dataset, scene: Scene) -> list[tuple[str, str]]:
    tables = [("Modal parameters of H22", _modal_table(scene))]
    solutions = [s for s in dataset["solution"].values if s != "linear"]
    for quantity in ("x1_amplitude", "force_amplitude", "x2_amplitude"):
        if quantity not in dataset or not solutions:
            continue
        label, units = _LABELS[quantity]
        header = "<tr><th>solution</th><th>Delta [mm]</th><th>R</th><th>linear peak 1 / 2 [" + units + "]</th><th>largest in band 1 / 2</th><th>reduction factor 1</th><th>reduction factor 2</th><th>undefined points 1 / 2</th><th>unstable points 1 / 2</th><th>paper (R = 0.2)</th></tr>"
        body = []
        for solution in solutions:
            for row in reduction_factors(dataset, scene, quantity, solution):
                paper = _PAPER_VALUES.get(quantity, {}).get(row.restitution) if abs(row.clearance - 0.003) < 1e-12 else None
                body.append(
                    f"<tr><td>{solution}</td><td>{row.clearance * 1e3:g}</td><td>{row.restitution:g}</td>"
                    f"<td>{row.linear_peak[0]:.4g} / {row.linear_peak[1]:.4g}</td>"
                    f"<td>{row.largest[0]:.4g} / {row.largest[1]:.4g}</td>"
                    f"<td>{row.factor[0]:.1f}</td><td>{row.factor[1]:.1f}</td>"
                    f"<td>{row.undefined[0]} / {row.undefined[1]}</td>"
                    f"<td>{row.unstable[0]} / {row.unstable[1]}</td>"
                    f"<td>{'' if paper is None else f'{paper[0]:g} / {paper[1]:g}'}</td></tr>"
                )
        tables.append((f"Reduction factors: {label}", f"<table>{header}{''.join(body)}</table>"))
    return tables


def _modal_table(scene: Scene) -> str:
    exact = exact_modal_parameters(scene.system)
    fit = fit_modal_parameters(scene.system)
    rows = ["<tr><th>mode</th><th>Omega/2pi [Hz]</th><th>xi exact</th><th>xi fitted</th><th>A exact (complex) [1/kg]</th><th>A fitted [1/kg]</th></tr>"]
    for i in range(exact.omega.size):
        a = exact.form_factor[i]
        rows.append(
            f"<tr><td>{i + 1}</td><td>{exact.omega[i] / (2 * np.pi):.4f}</td><td>{exact.loss_factor[i]:.5f}</td><td>{fit.loss_factor[i]:.5f}</td>"
            f"<td>{a.real:.4f} {a.imag:+.4f}j</td><td>{np.real(fit.form_factor[i]):.4f}</td></tr>"
        )
    return "<table>" + "".join(rows) + "</table><p>The paper prints A = 2.75, 7.25 and xi = 0.0022, 0.0023 for its system (eq. 24).</p>"


# ---------------------------------------------------------------------------------------------- page
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
        f"<p>vibroimpact {html.escape(str(dataset.attrs.get('vibroimpact_version', '?')))}; solutions: {', '.join(map(str, dataset['solution'].values))}.</p>",
        "<h2>Figures</h2>",
    ]
    for figure in figures:
        encoded = base64.b64encode(figure.path.read_bytes()).decode("ascii")
        parts.append(f"<figure><img alt='{figure.path.name}' src='data:image/png;base64,{encoded}'><figcaption>{html.escape(figure.caption)} ({figure.path.name})</figcaption></figure>")
    parts.append("<h2>Tables</h2>")
    parts.append(f"<p>{html.escape(REDUCTION_FACTOR_DEFINITION)}</p>")
    for title, table in tables:
        parts.append(f"<h3>{html.escape(title)}</h3>{table}")
    parts.append(f"<h2>Scene</h2><pre>{html.escape(scene.text)}</pre></body></html>")
    return "\n".join(parts)


def _write_text_atomic(path: Path, text: str) -> Path:
    handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    with os.fdopen(handle, "w", encoding="utf-8") as stream:
        stream.write(text)
    os.chmod(temporary, 0o644)
    os.replace(temporary, path)
    return path
