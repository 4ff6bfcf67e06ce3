"""Page sections of the frequency-grid study shared by the stepped and swept kinds: what a page of either knows of its
dataset (:class:`SolutionsPage`), and the section on the linear system a page opens with, of the paper's named system
(:func:`linear_section`: its responses, force on the base and the fit of H22, paper figures 2-4, and
:func:`modal_table`) or of any layout (:func:`structure_figure` and :func:`layout_tables`: every coordinate and stop,
the matrices, the stops and the load in words).
"""

from __future__ import annotations

import html
from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib.lines import Line2D

from vibroimpact.analysis.linear import base_force, paper_linear_response
from vibroimpact.model.modal import exact_modal_parameters, fit_modal_parameters, underdamped_mode_count
from vibroimpact.model.layout import Layout
from vibroimpact.model.problem import System
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.reporting.coincide import coincidence_phrase, reveal_coincident
from vibroimpact.reporting.page import DrawnFigure, Section, Table, saved
from vibroimpact.reporting.record import GeneralSetting, StudySetting, named_layout
from vibroimpact.reporting.style import DISPLACEMENT_SCALE, DISPLACEMENT_UNITS, figure_legend, finish_axes, fmt, legend_rows, new_figure, series_colour

__all__ = ["paper_study", "SolutionsPage", "linear_section", "linear_figure", "modal_table", "structure_figure", "layout_tables", "stop_constraint", "LINEAR_FIGURE_POINTS"]

#: Frequencies of the linear system's figures (0.0075 Hz over 15-45 Hz: the resonances are about 0.1 Hz wide).
LINEAR_FIGURE_POINTS = 4001
_FREQUENCY = "frequency [Hz]"


def paper_study(dataset: xr.Dataset) -> bool:
    """Is ``dataset``'s study the paper's own: its layout (:meth:`~vibroimpact.model.layout.Layout.paper_view`) on
    its system of eq. 24 (:data:`~vibroimpact.model.system.PAPER_SYSTEM`)? Only then do captions cite the paper's
    figures and equations; any other system gets neutral ones."""
    return named_layout(dataset) == PAPER_SYSTEM


def _titles(paper: bool) -> dict[str, str]:
    """The linear figures' panel titles and fit labels: citing the paper's figures and equations, or neutral."""
    if paper:
        return {"responses": "Linear responses (paper fig. 2)", "force": "Linear force on the base (paper fig. 3)", "fit": "Accuracy of the curve fit (paper fig. 4)",
                "exact": "|H22| exact (eq. 4)", "fitted": "|H22| of eq. 10, the paper's fitted modes", "against": "against the paper's curve fit (circles)",
                "no_fit": "(the paper's fit needs two underdamped modes)"}  # fmt: skip
    return {"responses": "Linear responses", "force": "Linear force on the base", "fit": "Accuracy of the two-mode curve fit", "exact": "|H22| exact",
            "fitted": "|H22| of the two-mode curve fit", "against": "against the two-mode curve fit with the undamped natural frequencies held (circles)",
            "no_fit": "(the two-mode curve fit needs two underdamped modes)"}  # fmt: skip


class SolutionsPage:
    """What the pages of stepped and swept studies share: the dataset, what it says of its study, and the summary
    naming the solutions; each page gives its own sections.

    Parameters
    ----------
    dataset : xarray.Dataset
        The study's dataset.
    setting : StudySetting
        What the dataset says of its system, excitation and grids.
    """

    def __init__(self, dataset: xr.Dataset, setting: StudySetting) -> None:
        self.dataset = dataset
        self.setting = setting

    def summary(self) -> str:
        """The solutions of the study."""
        return f"solutions: {', '.join(self.setting.solutions)}"


def linear_section(setting: StudySetting, out: Path, paper: bool = True) -> Section:
    """The section the swept-sine and bumper pages open with: the linear system and the modal parameters of H22
    (captions citing the paper where ``paper``, :func:`paper_study`)."""
    return Section("Linear system", figures=saved([linear_figure(setting, paper)], out), tables=[modal_table(setting.system)])


def linear_figure(setting: StudySetting, paper: bool = True) -> DrawnFigure:
    """Linear responses, force on the base and the curve fit of H22 (paper figures 2-4; their captions cite the
    paper only where ``paper``)."""
    titles = _titles(paper)
    system = setting.system
    # the closed form is cheap: a fine grid over the study's range (its own grid may be a handful of points)
    f = np.union1d(setting.frequency, np.linspace(setting.frequency.min(), setting.frequency.max(), LINEAR_FIGURE_POINTS))
    w = 2.0 * np.pi * f
    response = paper_linear_response(system, omega=w, amplitude=setting.amplitude)
    fit = fit_modal_parameters(system) if underdamped_mode_count(system) == 2 else None
    fig, axes = new_figure(3, panel_height=3.6, legend_rows=2)
    ax = axes[0]
    ax.semilogy(f, DISPLACEMENT_SCALE * np.abs(response.x1), label="|X1| primary", color="C0", lw=1.4, gid="linear")
    ax.semilogy(f, DISPLACEMENT_SCALE * np.abs(response.x2), label="|X2| absorber", color="C1", lw=1.4, gid="linear")
    for delta in setting.clearance:
        ax.axhline(DISPLACEMENT_SCALE * delta, color="k", lw=0.9, ls="--")
    finish_axes(ax, _FREQUENCY, f"amplitude [{DISPLACEMENT_UNITS}]", titles["responses"])
    ax = axes[1]
    ax.semilogy(f, np.abs(response.force), color="C2", lw=1.4, gid="linear")
    finish_axes(ax, _FREQUENCY, "|F| on the base [N]", titles["force"])
    ax = axes[2]
    ax.semilogy(f, np.abs(system.receptances(w).h22), label=titles["exact"], color="k", lw=1.4)
    if fit is not None:
        step = max(1, f.size // 120)
        ax.semilogy(f[::step], np.abs(fit.receptance(w[::step])), "o", color="C3", mfc="none", ms=4.5, label=titles["fitted"])
    finish_axes(ax, _FREQUENCY, "|H22| [m/N]", titles["fit"])
    figure_legend(fig, axes, [Line2D([], [], color="k", lw=0.9, ls="--", label="clearance Delta")])
    natural = ", ".join(fmt(x / (2 * np.pi), ".3f") for x in system.natural_angular_frequencies())
    caption = (
        f"Linear system (Delta -> infinity): |X1| and |X2| (dashed: the clearance), the force on the base, and |H22| exact "
        f"{titles['against'] if fit is not None else titles['no_fit']}. "
        f"Natural frequencies {natural} Hz, anti-resonance {fmt(system.antiresonance_angular_frequency() / (2 * np.pi), '.3f')} Hz."
    )
    return DrawnFigure(fig, "linear", "Linear responses, force on the base, fit of H22", caption)


def modal_table(structure: System) -> Table:
    """Exact and fitted modal parameters of H22 of ``structure``, the paper's two-mass chain (its named system, or
    matrices that have that view; ``ValueError`` otherwise)."""
    system = Layout(structure).named_view()
    if system is None:
        raise ValueError("modal_table: the modal parameters of H22 are the paper's two-mass chain's (x1 primary, x2 absorber)")
    exact = exact_modal_parameters(system)
    fit = fit_modal_parameters(system) if exact.omega.size == 2 else None
    rows = ["<tr><th>mode</th><th>Omega/2pi [Hz]</th><th>xi exact</th><th>xi fitted</th><th>A exact (complex) [1/kg]</th><th>A fitted [1/kg]</th></tr>"]
    for i in range(exact.omega.size):
        a = exact.form_factor[i]
        fitted = ("", "") if fit is None else (fmt(fit.loss_factor[i], ".5f"), fmt(np.real(fit.form_factor[i]), ".4f"))
        rows.append(
            f"<tr><td>{i + 1}</td><td>{fmt(exact.omega[i] / (2 * np.pi), '.4f')}</td><td>{fmt(exact.loss_factor[i], '.5f')}</td><td>{fitted[0]}</td>"
            f"<td>{fmt(a.real, '.4f')} {fmt(a.imag, '+.4f')}j</td><td>{fitted[1]}</td></tr>"
        )
    note = "The paper prints A = 2.75, 7.25 and xi = 0.0022, 0.0023 for its system (eq. 24)." if system == PAPER_SYSTEM else ""
    if fit is None:
        note += " The system has fewer than two underdamped modes: the two-mode curve fit does not apply."
    return Table("Modal parameters of H22", "<table>" + "".join(rows) + f"</table><p>{note}</p>")


def structure_figure(setting: GeneralSetting, frequency: np.ndarray, paper: bool = False) -> DrawnFigure:
    """The linear system: |X| of every coordinate, |n_k . X| of every stop's coordinate (dashed) against the gap the
    static deflection leaves it, Delta_k - n_k . x_static (dotted, the stop's colour), the force on the base, and,
    where the structure has the named view, |H22| exact against the two-mode curve fit (paper figures 2-4; their
    captions cite the paper only where ``paper``, :func:`paper_study`)."""
    titles = _titles(paper)
    f = np.union1d(frequency, np.linspace(frequency.min(), frequency.max(), LINEAR_FIGURE_POINTS))
    w = 2.0 * np.pi * f
    x = setting.linear(w)
    named = setting.named
    fit = fit_modal_parameters(named) if named is not None and underdamped_mode_count(named) == 2 else None
    fig, axes = new_figure(3 if named is None else 4, panel_height=3.6, legend_rows=legend_rows(setting.structure.size + 2 * len(setting.stops) + 2))
    coordinates = [(f"|{name}|", axes[0].semilogy(f, DISPLACEMENT_SCALE * np.abs(x[:, i]), color=series_colour(i), lw=1.4, label=f"|{name}|", gid=f"linear:{name}")) for i, name in enumerate(setting.names)]
    finish_axes(axes[0], _FREQUENCY, f"amplitude [{DISPLACEMENT_UNITS}]", "Every coordinate, linear system (no stop)")
    static = setting.static_deflection()
    gaps = setting.clearances - (setting.normals @ static if static is not None else 0.0)
    stops: list[tuple[str, list[Line2D]]] = []
    lines: list[tuple[str, list[Line2D]]] = []
    for k, (normal, words) in enumerate(zip(setting.normals, setting.stops)):
        stops.append((f"stop {k}", axes[1].semilogy(f, DISPLACEMENT_SCALE * np.abs(x @ normal), color=series_colour(k), lw=1.4, ls="--", label=f"stop {k}: {stop_constraint(words)}", gid=f"linear:stop{k}")))
        if np.isfinite(gaps[k]) and gaps[k] > 0.0:  # drawn on the frequencies, as the curves it is compared with
            lines.append((f"the gap of stop {k}", axes[1].plot(f, np.full(f.shape, DISPLACEMENT_SCALE * gaps[k]), color=series_colour(k), lw=1.1, ls=":", label=f"stop {k}: gap {fmt(gaps[k] * 1e3, '.4g')} mm", gid=f"gap:stop{k}")))
    finish_axes(axes[1], _FREQUENCY, f"amplitude [{DISPLACEMENT_UNITS}]", "Each stop's coordinate, linear system")
    coincide = coincidence_phrase([*reveal_coincident(axes[0], coordinates), *reveal_coincident(axes[1], stops), *reveal_coincident(axes[1], lines, share=False)])
    axes[2].semilogy(f, np.abs(base_force(setting.structure, w, x)), color="C2", lw=1.4, label="|F| on the base", gid="linear:force")
    finish_axes(axes[2], _FREQUENCY, "|F| on the base [N]", titles["force"])
    if named is not None:
        axes[3].semilogy(f, np.abs(named.receptances(w).h22), label=titles["exact"], color="k", lw=1.4)
        if fit is not None:
            step = max(1, f.size // 120)
            axes[3].semilogy(f[::step], np.abs(fit.receptance(w[::step])), "o", color="C3", mfc="none", ms=4.5, label=titles["fitted"])
        finish_axes(axes[3], _FREQUENCY, "|H22| [m/N]", titles["fit"])
    figure_legend(fig, axes)
    natural = ", ".join(fmt(v / (2 * np.pi), ".3f") for v in (named.natural_angular_frequencies() if named is not None else setting.structure.natural_angular_frequencies()))
    caption = (
        f"Linear steady state without stops under the {setting.load_text()}: the amplitude of every coordinate "
        f"({', '.join(setting.names)}); the amplitude of each stop's coordinate n . x (dashed) and, dotted in the "
        f"same colour, {_gap_words(setting, static, gaps)} The force on the base, 1^T (K + j w C) X."
    )
    if named is not None:
        fitted = titles["against"] if fit is not None else titles["no_fit"]
        caption += f" |H22| exact {fitted}. Natural frequencies {natural} Hz, anti-resonance {fmt(named.antiresonance_angular_frequency() / (2 * np.pi), '.3f')} Hz."
    else:
        caption += f" Natural frequencies {natural} Hz."
    caption += f" Stops: {'; '.join(setting.stops)}." + (f" {coincide}" if coincide else "")
    return DrawnFigure(fig, "structure", "Linear responses, force on the base" + (", fit of H22" if named is not None else ""), caption)


def _gap_words(setting: GeneralSetting, static: np.ndarray | None, gaps: np.ndarray) -> str:
    """What the dotted lines of the structure figure are, and which stops have none."""
    if static is None:
        words = (
            "its clearance Delta: where the dashed curve is above, the linear motion would cross that stop if the "
            "structure stood at rest on its mean; the constant force shifts the mean (K is singular: no static "
            "deflection is drawn)."
        )
    elif np.any(setting.static):
        words = (
            "the gap the static deflection leaves it, Delta - n . x_static (x_static = K^-1 F0): where the dashed "
            "curve is above, the linear motion would cross that stop."
        )
    else:
        words = "its clearance Delta: where the dashed curve is above, the linear motion would cross that stop."
    swept = [str(k) for k in range(gaps.size) if not np.isfinite(gaps[k])]
    closed = [str(k) for k in range(gaps.size) if np.isfinite(gaps[k]) and gaps[k] <= 0.0]
    if swept:
        words += f" No line for stop {', '.join(swept)}: its clearance is swept (one value per section below)."
    if closed:
        words += f" No line for stop {', '.join(closed)}: the static deflection already closes it (gap <= 0)."
    return words


def stop_constraint(words: str) -> str:
    """The constraint part of a stop's description (``x2 - x1 <= 3 mm``)."""
    return words.split(",")[0]


def layout_tables(setting: GeneralSetting) -> list[Table]:
    """The structure's matrices and natural frequencies, and the stops in words."""
    names = setting.names

    def matrix(title: str, values: np.ndarray, units: str) -> str:
        head = "".join(f"<th>{html.escape(n)}</th>" for n in names)
        rows = "".join(f"<tr><th>{html.escape(n)}</th>" + "".join(f"<td>{fmt(v, '.6g')}</td>" for v in row) + "</tr>" for n, row in zip(names, values))
        return f"<p><b>{title}</b> [{units}]</p><table><tr><th></th>{head}</tr>{rows}</table>"

    s = setting.structure
    natural = ", ".join(fmt(v / (2 * np.pi), ".4f") for v in s.natural_angular_frequencies())
    matrices = matrix("mass M", s.mass_matrix, "kg") + matrix("stiffness K", s.stiffness_matrix, "N/m") + matrix("damping C", s.damping_matrix, "N s/m")
    matrices += f"<p>Natural frequencies (undamped): {natural} Hz; rigid-body modes: {s.rigid_body_modes()}.</p>"
    stops = "".join(f"<tr><td>{k}</td><td>{html.escape(words)}</td></tr>" for k, words in enumerate(setting.stops))
    stop_table = f"<table><tr><th>stop</th><th>constraint (gap Delta - n . x >= 0)</th></tr>{stops}</table><p>Load: {html.escape(setting.load_text())}.</p>"
    return [Table("Structure", matrices), Table("Stops and load", stop_table)]
