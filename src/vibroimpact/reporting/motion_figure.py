"""What the simulated motion is where it is not periodic: the largest Lyapunov exponent of each engine's motion
against frequency, with the band the classification calls zero, one panel per restitution ratio."""

from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.lines import Line2D

from vibroimpact.analysis.regime import Regime
from vibroimpact.orbits.motion import MotionThresholds
from vibroimpact.reporting.page import DrawnFigure
from vibroimpact.reporting.responses import clearance_text, series_by_restitution
from vibroimpact.reporting.style import ENGINE_MARKERS, REGIME_COLOURS, Caption, axis_label, figure_legend, finish_axes, legend_rows, new_figure, solution_ref

__all__ = ["lyapunov_figure"]

#: How each kind of motion is drawn: the regime map's colour, filled markers.
_KINDS = (Regime.CHAOTIC, Regime.QUASI_PERIODIC, Regime.IRREGULAR)


def lyapunov_figure(part: xr.Dataset, engines: list[str], name: str) -> DrawnFigure | None:
    """The largest Lyapunov exponent of every non-periodic simulated point, coloured by the regime it decided;
    None where no engine has one."""
    if "lyapunov_exponent" not in part or "regime" not in part:
        return None
    drawn = [e for e in engines if np.isfinite(part["lyapunov_exponent"].sel(solution=e).values).any()]
    if not drawn:
        return None
    band = MotionThresholds()
    lines = series_by_restitution(part)
    f = part["frequency"].values
    fig, axes = new_figure(len(lines), panel_height=3.0, legend_rows=legend_rows(len(_KINDS) + len(drawn) + 1))
    for ax, (text, line) in zip(axes, lines):
        ax.axhspan(-band.zero_band, band.zero_band, color="#dddddd", zorder=0)
        ax.axhline(0.0, color="k", lw=0.8)
        for engine in drawn:
            marker, size = ENGINE_MARKERS.get(engine, ("s", 5.0))
            exponent = line["lyapunov_exponent"].sel(solution=engine).values
            error = line["lyapunov_error"].sel(solution=engine).values if "lyapunov_error" in line else np.zeros_like(exponent)
            regime = line["regime"].sel(solution=engine).values
            for kind in _KINDS:
                chosen = np.isfinite(exponent) & (regime == int(kind))
                if chosen.any():
                    ax.errorbar(f[chosen], exponent[chosen], yerr=error[chosen], fmt=marker, ms=size, color=REGIME_COLOURS[kind], mec="k", mew=0.5, ecolor="0.4", elinewidth=0.8, ls="none", gid=engine)
        finish_axes(ax, "frequency [Hz]", axis_label("lyapunov_exponent"), text)
        ax.set_xlim(f[0], f[-1])  # the study's band, as in the other figures
    keys = [_key("o", REGIME_COLOURS[kind], kind.name.lower()) for kind in _KINDS]
    keys += [_key(ENGINE_MARKERS.get(e, ("s", 5.0))[0], "white", solution_ref(e)) for e in drawn]
    figure_legend(fig, axes, keys)
    caption = Caption(
        f"Largest Lyapunov exponent of the stroboscopic map per excitation period where the simulated motion did not "
        f"become periodic, {clearance_text(part)}: one panel per restitution ratio, one marker shape per engine "
        f"({', '.join(solution_ref(e) for e in drawn)}), coloured by what it decided (the regime map's colours), bars: "
        "the standard error of block averages. 'exact' takes the exponent from its exact Jacobians (flow x saltation "
        "matrices, renormalised); an integrator from a copy of its own run perturbed by 1e-6 of the motion's scale, "
        f"renormalised every 32 periods. Chaotic: exponent above {band.chaotic_exponent:g} and {band.margin:g} errors; "
        f"quasi-periodic: within the grey band (|exponent| and error <= {band.zero_band:g}) with a line spectrum or a "
        "regular rotation of the strobe points; irregular: the evidence does not decide."
    )
    return DrawnFigure(fig, name, f"What the motion is where it is not periodic, {clearance_text(part)}", caption.text())


def _key(marker: str, colour: str, label: str) -> Line2D:
    return Line2D([], [], marker=marker, ls="none", color=colour, mec="k", mew=0.5, ms=6, label=label)
