"""Report pages of the compliant-bumper studies (paper section 5 and figures 16-28).

* swept-sine tests: running fundamental and RMS of X1 and X2 against the instantaneous frequency, up and down,
  against the linear and PGF steady states (figures 16-24), and the runs' cost;
* resonance peaks of |X1| against the restitution ratio or the clearance (figures 25-26);
* peak contact acceleration and force against frequency, simulation against the PGF-based estimate (figure 28);
* convergence of the compliant model to the rigid-stop one as the bumper stiffens, and what it costs.
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import xarray as xr

from .report_common import Figure, save_figure
from .regime import Regime
from .scene import ENGINE_SOLUTIONS, Scene

__all__ = ["sweep_figures", "sweep_tables", "peak_figures", "peak_tables", "peak_acceleration_figure", "stiffness_figures", "stiffness_tables", "band_peaks"]

_SWEEP_COLOURS = {"up": "C3", "down": "C2"}


def _split(scene: Scene) -> float:
    """The anti-resonance frequency [Hz], which separates the two resonance bands."""
    return scene.system.antiresonance_frequency() / (2.0 * np.pi)


# --------------------------------------------------------------------------------------------- sweeps
def sweep_figures(dataset: xr.Dataset, scene: Scene, out: Path) -> list[Figure]:
    """Running estimates of each swept-sine run against the steady-state solutions."""
    figures = []
    f = dataset["frequency"].values
    sweeps = [str(s) for s in dataset["sweep"].values]
    panels = [("x1_amplitude", "x1_rms", "X1"), ("x2_amplitude", "x2_rms", "X2")]
    fig, axes = plt.subplots(1, 2, figsize=(15, 4.8), squeeze=False)
    for ax, (fundamental, rms, name) in zip(axes[0], panels):
        if fundamental not in dataset and rms not in dataset:
            ax.set_visible(False)
            continue
        _steady_lines(ax, dataset, fundamental, f)
        if rms in dataset and "pgf" in dataset["solution"].values:
            first = {"sweep": 0} if "sweep" in dataset.dims else {}
            ax.plot(f, np.sqrt(2.0) * dataset[rms].sel(solution="pgf").isel(first).values, color="C0", lw=0.8, ls="--", alpha=0.7, label="PGF: sqrt 2 x RMS")
        for direction in sweeps:
            line = dataset.sel(solution="compliant", sweep=direction)
            colour = _SWEEP_COLOURS.get(direction, "C4")
            if fundamental in line:
                ax.plot(f, line[fundamental].values, color=colour, lw=1.0, label=f"sweep {direction}: fundamental")
            if rms in line:
                ax.plot(f, np.sqrt(2.0) * line[rms].values, color=colour, lw=0.8, ls="--", alpha=0.7, label=f"sweep {direction}: sqrt 2 x RMS")
        ax.set(yscale="log", xlabel="instantaneous frequency [Hz]", ylabel=f"{name} [m]", title=f"{name}: swept sine against steady states")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    figures.append(
        Figure(
            save_figure(fig, out / "sweep_displacements.png"),
            f"Swept sine ({_sweep_text(scene)}): running fundamental (solid) and sqrt 2 x running RMS (dashed; equal to the "
            "fundamental for a pure sine) of X1 and X2 against the instantaneous frequency, like the paper's figures 16-20. "
            "Thin black: linear system (no stop); blue: PGF one-impact steady state (dashed where the orbit is unstable).",
        )
    )
    fig, axes = plt.subplots(1, 3, figsize=(18, 4.6), squeeze=False)
    for ax, quantity, label, units, log in zip(
        axes[0], ("force_amplitude", "impulse", "impacts_per_period"), ("|F| fundamental on the base", "impulse per period", "contacts per period"), ("N", "N s", "1"), (True, False, False)
    ):
        if quantity not in dataset:
            ax.set_visible(False)
            continue
        _steady_lines(ax, dataset, quantity, f, linear=quantity == "force_amplitude")
        for direction in sweeps:
            ax.plot(f, dataset[quantity].sel(solution="compliant", sweep=direction).values, color=_SWEEP_COLOURS.get(direction, "C4"), lw=0.9, label=f"sweep {direction}")
        ax.set(xlabel="instantaneous frequency [Hz]", ylabel=f"{label} [{units}]", title=label)
        if log:
            ax.set_yscale("log")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    figures.append(
        Figure(
            save_figure(fig, out / "sweep_force_impulse.png"),
            "Force on the base (suspension plus bumper, fundamental), impulse per excitation period and contacts per period "
            "over the estimator window, swept sine against the PGF steady state (paper figures 21-24).",
        )
    )
    if "running_x1_amplitude" in dataset:
        fig, ax = plt.subplots(figsize=(15, 4.2))
        for direction in sweeps:
            ax.plot(dataset["elapsed_time"].values, dataset["running_x1_amplitude"].sel(sweep=direction).values, color=_SWEEP_COLOURS.get(direction, "C4"), lw=0.9, label=f"sweep {direction}")
        ax.set(yscale="log", xlabel="time [s]", ylabel="|X1| running fundamental [m]", title="Running fundamental of X1 against time (the Simulink scope view)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        figures.append(Figure(save_figure(fig, out / "sweep_time.png"), "The running fundamental of X1 against time since the start of each sweep."))
    return figures


def _steady_lines(ax: plt.Axes, dataset: xr.Dataset, quantity: str, f: np.ndarray, linear: bool = True) -> None:
    """Linear and PGF steady states (first sweep: they do not depend on it)."""
    first = {"sweep": 0} if "sweep" in dataset.dims else {}
    solutions = dataset["solution"].values
    if linear and "linear" in solutions and quantity in dataset:
        ax.plot(f, dataset[quantity].sel(solution="linear").isel(first).values, color="k", lw=0.7, label="linear")
    if "pgf" in solutions and quantity in dataset:
        values = dataset[quantity].sel(solution="pgf").isel(first).values
        unstable = dataset["stable"].sel(solution="pgf").isel(first).values == 0 if "stable" in dataset else np.zeros(values.shape, bool)
        ax.plot(f, np.where(unstable, np.nan, values), color="C0", lw=1.4, label="PGF steady state")
        if unstable.any():
            ax.plot(f, np.where(unstable, values, np.nan), color="C0", lw=0.8, ls="--", alpha=0.5, label="PGF, unstable orbit")


def _sweep_text(scene: Scene) -> str:
    s = scene.swept_sine
    assert s is not None and scene.bumper_frequency is not None
    return f"{s.start_frequency:g} <-> {s.stop_frequency:g} Hz at {s.rate:g} Hz/s, bumper {scene.bumper_frequency[0]:g} Hz, xi_b = {scene.loss_factors()[0]:.4f}, window {s.window_cycles} cycles"


def sweep_tables(dataset: xr.Dataset, scene: Scene) -> list[tuple[str, str]]:
    """Cost of each run, and the sweep against the PGF steady state where that is stable."""
    rows = ["<tr><th>sweep</th><th>wall time [s]</th><th>steps</th><th>contacts</th><th>residual calls</th><th>simulated [s]</th></tr>"]
    s = scene.swept_sine
    assert s is not None
    duration = (s.stop_frequency - s.start_frequency) / s.rate
    for direction in dataset["sweep"].values:
        line = dataset.sel(sweep=direction)
        rows.append(
            f"<tr><td>{direction}</td><td>{float(line['sweep_wall_time']):.1f}</td><td>{float(line['sweep_steps']):.0f}</td>"
            f"<td>{float(line['sweep_contacts']):.0f}</td><td>{float(line['sweep_rhs_calls']):.0f}</td><td>{duration:g}</td></tr>"
        )
    tables = [("Cost of the swept-sine runs (one process each)", "<table>" + "".join(rows) + "</table>")]
    if "pgf" in dataset["solution"].values and "x1_amplitude" in dataset:
        rows = ["<tr><th>sweep</th><th>band</th><th>points (PGF stable, contact)</th><th>median rel. diff. |X1|</th><th>90th percentile</th></tr>"]
        f = dataset["frequency"].values
        split = _split(scene)
        for direction in dataset["sweep"].values:
            sim = dataset["x1_amplitude"].sel(solution="compliant", sweep=direction).values
            pgf = dataset["x1_amplitude"].sel(solution="pgf", sweep=direction).values
            stable = dataset["stable"].sel(solution="pgf", sweep=direction).values == 1 if "stable" in dataset else np.isfinite(pgf)
            with np.errstate(invalid="ignore", divide="ignore"):
                difference = np.abs(sim - pgf) / pgf
            for band, mask in (("1", f < split), ("2", f >= split)):
                good = mask & stable & np.isfinite(difference)
                median = f"{np.median(difference[good]):.3f}" if good.any() else ""
                p90 = f"{np.percentile(difference[good], 90):.3f}" if good.any() else ""
                rows.append(f"<tr><td>{direction}</td><td>{band}</td><td>{int(good.sum())}</td><td>{median}</td><td>{p90}</td></tr>")
        tables.append(("Swept sine against the stable PGF steady state (|X1| fundamental)", "<table>" + "".join(rows) + "</table>"))
    return tables


# ---------------------------------------------------------------------------------------------- peaks
def band_peaks(values: np.ndarray, f: np.ndarray, split: float) -> tuple[tuple[float, float], tuple[float, float]]:
    """Largest finite value below and above ``split`` [Hz] and where it is: ((peak 1, f 1), (peak 2, f 2))."""
    result = []
    for mask in (f < split, f >= split):
        v = np.where(mask & np.isfinite(values), values, -np.inf)
        i = int(np.argmax(v))
        result.append((float(v[i]), float(f[i])) if np.isfinite(v[i]) else (math.nan, math.nan))
    return result[0], result[1]


def _peak_rows(dataset: xr.Dataset, scene: Scene, parameter: str) -> list[tuple[str, float, tuple[float, float], tuple[float, float]]]:
    """(solution label, parameter value, band-1 peak, band-2 peak) of |X1|; PGF also on the simulation grid."""
    f = dataset["frequency"].values
    split = _split(scene)
    sim_f = scene.simulation.frequency if scene.simulation is not None else None
    rows = []
    for value in dataset[parameter].values:
        line = dataset["x1_amplitude"].sel({parameter: value})
        for solution in dataset["solution"].values:
            if solution == "linear":
                continue
            values = line.sel(solution=solution).values
            if solution in ENGINE_SOLUTIONS:
                on = np.isfinite(values)
                rows.append((str(solution), float(value), *band_peaks(values[on], f[on], split)))
            else:
                rows.append((str(solution), float(value), *band_peaks(values, f, split)))
                if solution == "pgf" and "stable" in dataset and "regime" in dataset:
                    point = dataset.sel({parameter: value, "solution": solution})
                    impact = np.isin(point["regime"].values, (Regime.ONE_IMPACT, Regime.ONE_IMPACT_COEXISTING_LINEAR)) & (point["stable"].values == 1)
                    rows.append(("pgf, stable one-impact orbits only", float(value), *band_peaks(np.where(impact, values, np.nan), f, split)))
                if sim_f is not None:
                    on = np.isin(f, sim_f)
                    rows.append((f"{solution} on the simulation grid", float(value), *band_peaks(values[on], f[on], split)))
    return rows


def peak_figures(dataset: xr.Dataset, scene: Scene, parameter: str, out: Path) -> list[Figure]:
    """Peak |X1| of each resonance band against ``parameter`` (``restitution`` or ``clearance``): figures 25-26."""
    rows = _peak_rows(dataset, scene, parameter)
    scale, unit = (1e3, "mm") if parameter == "clearance" else (1.0, "-")
    fig, axes = plt.subplots(1, 2, figsize=(14, 4.6), squeeze=False)
    labels = list(dict.fromkeys(r[0] for r in rows))
    styles = {"pgf": ("-", None), "pgf, stable one-impact orbits only": ("--", None), "pgf_paper": ("-.", None), "momentary": ("none", "o"), "exact": ("none", "x"), "compliant": ("none", "s")}
    for band, ax in enumerate(axes[0]):
        for k, label in enumerate(labels):
            x = np.array([r[1] for r in rows if r[0] == label]) * scale
            y = np.array([r[2 + band][0] for r in rows if r[0] == label])
            ls, marker = styles.get(label, (":", "."))
            ax.plot(x, y, ls=ls, marker=marker, color=f"C{k}", mfc="none", label=label)
        ax.set(xlabel=f"{parameter} [{unit}]", ylabel="peak |X1| fundamental [m]", title=f"resonance band {band + 1} ({'below' if band == 0 else 'above'} the anti-resonance)")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    caption = (
        f"Largest |X1| fundamental in each resonance band against the {parameter} (paper figures 25-26). PGF lines take "
        "the analytic grid and (dotted) only the simulated frequencies, so that the comparison with the markers is like "
        "for like; simulations include irregular motions' averages. 'pgf' is the largest realisable steady state (where "
        "the linear motion fits beside an unstable one-impact orbit, the linear one); the dashed line keeps only stable "
        "one-impact orbits, the curve the paper draws. Where motions coexist, a simulation settles on one of them "
        "depending on where it starts (here: near the one-impact orbit)."
    )
    return [Figure(save_figure(fig, out / f"peaks_vs_{parameter}.png"), caption)]


def peak_tables(dataset: xr.Dataset, scene: Scene, parameter: str) -> list[tuple[str, str]]:
    """The values of :func:`peak_figures`."""
    unit = "mm" if parameter == "clearance" else "-"
    scale = 1e3 if parameter == "clearance" else 1.0
    header = f"<tr><th>solution</th><th>{parameter} [{unit}]</th><th>peak 1 [mm]</th><th>at [Hz]</th><th>peak 2 [mm]</th><th>at [Hz]</th></tr>"
    body = [
        f"<tr><td>{label}</td><td>{value * scale:g}</td><td>{p1[0] * 1e3:.4g}</td><td>{p1[1]:.3f}</td><td>{p2[0] * 1e3:.4g}</td><td>{p2[1]:.3f}</td></tr>"
        for label, value, p1, p2 in _peak_rows(dataset, scene, parameter)
    ]
    return [(f"Resonance peaks of |X1| against the {parameter}", f"<table>{header}{''.join(body)}</table>")]


# -------------------------------------------------------------------------------------- peak acceleration
def peak_acceleration_figure(dataset: xr.Dataset, scene: Scene, path: Path) -> list[Figure]:
    """Peak contact deceleration and force against frequency at one clearance: simulation against the PGF-based
    estimate (figure 28)."""
    f = dataset["frequency"].values
    fig, axes = plt.subplots(1, 2, figsize=(15, 4.6), squeeze=False)
    lines = [(f"R = {float(r):g}", dataset.sel(restitution=r)) for r in dataset["restitution"].values] if "restitution" in dataset.dims else [(f"R = {float(dataset['restitution']):g}", dataset)]
    for ax, quantity, label, units in zip(axes[0], ("peak_acceleration", "peak_contact_force"), ("peak contact deceleration", "peak contact force"), ("m s-2", "N")):
        if quantity not in dataset:
            ax.set_visible(False)
            continue
        for k, (name, line) in enumerate(lines):
            if "pgf" in line["solution"].values:
                values = line[quantity].sel(solution="pgf").values
                unstable = line["stable"].sel(solution="pgf").values == 0 if "stable" in line else np.zeros(values.shape, bool)
                ax.plot(f, np.where(unstable, np.nan, values), color=f"C{k}", lw=1.0, label=f"PGF estimate, {name}")
                if unstable.any():
                    ax.plot(f, np.where(unstable, values, np.nan), color=f"C{k}", lw=0.8, ls="--", alpha=0.5, label=f"PGF estimate on an unstable orbit, {name}")
            if "compliant" in line["solution"].values:
                values = line[quantity].sel(solution="compliant").values
                converged = line["converged"].sel(solution="compliant").values == 1 if "converged" in line else np.isfinite(values)
                irregular = np.isfinite(values) & ~converged
                ax.plot(f[converged], values[converged], "o", color=f"C{k}", ms=4, label=f"compliant, periodic, {name}")
                if irregular.any():
                    ax.plot(f[irregular], values[irregular], "o", color=f"C{k}", mfc="none", ms=4, label=f"compliant, irregular (largest over the window), {name}")
        ax.set(xlabel="frequency [Hz]", ylabel=f"{label} [{units}]", title=label)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    caption = (
        "Largest deceleration of the absorber on the bumper (left) and largest bumper force (right) per steady state, "
        "against the PGF-based estimate Gamma(xi_b) Omega_b J / (M2 (1 + R)) (section 6.3 with the corrected factor Gamma): "
        "the rigid-stop impulse J gives the entry speed, the one-collision solution of the bumper gives the peak."
    )
    return [Figure(save_figure(fig, path), caption + f" Delta = {float(dataset['clearance']) * 1e3:g} mm.")]


# ------------------------------------------------------------------------------------------- stiffness
def _stiffness_reference(dataset: xr.Dataset) -> str | None:
    for name in ("exact", "momentary"):
        if name in dataset["solution"].values:
            return name
    return None


def stiffness_figures(dataset: xr.Dataset, scene: Scene, out: Path) -> list[Figure]:
    """Difference of the compliant |X1| from the rigid-stop one against Omega_b, and the wall time per point."""
    reference = _stiffness_reference(dataset)
    if reference is None or "compliant" not in dataset["solution"].values:
        return []
    bumper = dataset["bumper_frequency"].values
    f = scene.simulation.frequency if scene.simulation is not None else dataset["frequency"].values
    fig, axes = plt.subplots(1, 2, figsize=(15, 4.8), squeeze=False)
    ax = axes[0, 0]
    for k, frequency in enumerate(f):
        point = dataset.sel(frequency=frequency)
        sim = point["x1_amplitude"].sel(solution="compliant").values
        ref = point["x1_amplitude"].sel(solution=reference).values
        ax.loglog(bumper, np.abs(sim - ref) / ref, "o-", color=f"C{k % 10}", ms=4, label=f"{frequency:g} Hz")
    anchor = bumper[0]
    ax.loglog(bumper, 0.1 * anchor / bumper, "k--", lw=0.8, label="slope -1")
    ax.set(xlabel="bumper frequency Omega_b / 2 pi [Hz]", ylabel=f"| |X1| compliant - |X1| {reference} | / |X1| {reference}", title="Convergence to the rigid stop")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    ax = axes[0, 1]
    if "wall_time" in dataset:
        for k, frequency in enumerate(f):
            ax.loglog(bumper, dataset["wall_time"].sel(solution="compliant", frequency=frequency).values, "o-", color=f"C{k % 10}", ms=4, label=f"{frequency:g} Hz")
        rigid = np.nanmedian(dataset["wall_time"].sel(solution=reference).values)
        ax.axhline(rigid, color="k", ls=":", label=f"{reference} (median)")
    ax.set(xlabel="bumper frequency Omega_b / 2 pi [Hz]", ylabel="wall time per steady state [s]", title="Cost of the compliant model")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    caption = (
        f"Left: relative difference of the steady-state |X1| fundamental of the compliant model (restitution-matched loss "
        f"factor) from the rigid-stop model ({reference}) as the bumper stiffens; the dashed line has slope -1. Right: the "
        "wall time of each steady state (transient plus measurement, one process)."
    )
    return [Figure(save_figure(fig, out / "bumper_stiffness.png"), caption)]


def stiffness_tables(dataset: xr.Dataset, scene: Scene) -> list[tuple[str, str]]:
    """Per bumper frequency: median and largest difference from the rigid stop, fitted order, median wall time."""
    reference = _stiffness_reference(dataset)
    if reference is None or "compliant" not in dataset["solution"].values or scene.simulation is None:
        return []
    f = scene.simulation.frequency
    bumper = dataset["bumper_frequency"].values
    data = dataset.sel(frequency=f)
    sim = data["x1_amplitude"].sel(solution="compliant").transpose("bumper_frequency", "frequency").values
    ref = data["x1_amplitude"].sel(solution=reference).values
    difference = np.abs(sim - ref) / ref
    wall = data["wall_time"].sel(solution="compliant").transpose("bumper_frequency", "frequency").values if "wall_time" in data else np.full(sim.shape, np.nan)
    rows = ["<tr><th>Omega_b/2pi [Hz]</th><th>median rel. diff. |X1|</th><th>largest</th><th>observed order (median)</th><th>median wall time [s]</th></tr>"]
    for i, b in enumerate(bumper):
        order = ""
        if i > 0:
            with np.errstate(invalid="ignore", divide="ignore"):
                orders = np.log(difference[i - 1] / difference[i]) / np.log(b / bumper[i - 1])
            if np.isfinite(orders).any():
                order = f"{np.nanmedian(orders):.2f}"
        rows.append(f"<tr><td>{b:g}</td><td>{np.nanmedian(difference[i]):.2e}</td><td>{np.nanmax(difference[i]):.2e}</td><td>{order}</td><td>{np.nanmedian(wall[i]):.3f}</td></tr>")
    return [(f"Compliant against {reference}: convergence and cost", "<table>" + "".join(rows) + "</table>")]
