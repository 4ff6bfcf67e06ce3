"""Tables of the stepped frequency-response pages: reduction factors, simulation against the closed form (the modal
parameters' table, shared with the swept page, is :func:`vibroimpact.grids.sections.modal_table`).

A solution is judged only on the points it was asked to compute: time-domain solutions run on their own, coarser
grid and are flagged ``not_computed`` elsewhere; those points are neither failures nor undefined values.

Reduction factors need the structure's named view (the paper's two resonances and its anti-resonance); the linear
response, its peaks and where it fits are those of the study's own load and stops
(:class:`~vibroimpact.reporting.record.GeneralSetting`).

Definition (stated in every report): for a quantity (|X1|, |X2| or the force on the base) and linear resonance i,

    factor_i = (peak of the linear response near natural frequency i, by analytic maximisation)
               / (largest realisable steady response on the grid within resonance i's band)

The bands split the frequency range at the anti-resonance sqrt(K2/M2). A steady response is *realisable* if it is a
one-impact value that is not known to be unstable, or the linear value wherever the linear motion stays clear of the
stops (it coexists with any impact regime there, and a frequency sweep can stay on it). Unstable one-impact
values and undefined points (NaN) are left out and counted; where there are any, the factor is an upper bound.
"""

from __future__ import annotations

import html
from dataclasses import dataclass

import numpy as np
import xarray as xr

from vibroimpact.kinds.stepped.crosscheck import subset_solutions
from vibroimpact.analysis.linear import ResonancePeak, peaks_near
from vibroimpact.analysis.stability import Regime
from vibroimpact.model.modal import exact_modal_parameters
from vibroimpact.model.system import PAPER_SYSTEM, TwoDofSystem
from vibroimpact.reporting.page import Table
from vibroimpact.reporting.record import GeneralSetting
from vibroimpact.reporting.style import QUANTITIES, fmt
from vibroimpact.scene.schema import ENGINE_SOLUTIONS

__all__ = ["DEFINITION", "ReductionRow", "reduction_factors", "paper_reduction_factors", "reduction_tables", "reduction_intro", "agreement_table", "computed_part"]


# --------------------------------------------------------------------------------------------------------------------
# Reduction factors: how much a stop lowers the response at each linear resonance.
# --------------------------------------------------------------------------------------------------------------------

DEFINITION = " ".join(__doc__.split("Definition (stated in every report): ")[1].split())

#: Quantities with reduction factors (coordinates of the named view, the force on the base).
#: The quantities a reduction factor is computed for.
REDUCED_QUANTITIES = ("x1_amplitude", "x2_amplitude", "force_amplitude", "suspension_force_amplitude")
#: Relative half-width of the search for each linear peak around its undamped natural frequency [-].
_SPAN = 0.05
#: Reduction factors quoted in the paper (section 4) for its example at R = 0.2, Delta = 3 mm.
_PAPER = {"x1_amplitude": (28.0, 23.0), "force_amplitude": (25.0, 30.0)}


@dataclass(frozen=True)
class ReductionRow:
    """Reduction factors of one quantity for one (clearance, R), one entry per linear resonance (mode 1, 2).

    Attributes
    ----------
    clearance : float
        Delta [m].
    restitution : float
        R [-].
    linear_peak : tuple of float
        Analytic linear peak near each natural frequency (units of the quantity).
    largest : tuple of float
        Largest realisable value on the grid in each band.
    factor : tuple of float
        linear_peak / largest [-].
    undefined : tuple of int
        Grid points of the band where the solution is NaN.
    unstable : tuple of int or None
        Grid points of the band with an unstable one-impact value (None: stability not computed).
    coarse : tuple of bool
        The grid step in the band exceeds a quarter of the linear peak's half-power width: a narrow maximum of the
        vibro-impact response may fall between grid points.
    """

    clearance: float
    restitution: float
    linear_peak: tuple[float, ...]
    largest: tuple[float, ...]
    factor: tuple[float, ...]
    undefined: tuple[int, ...]
    unstable: tuple[int, ...] | None
    coarse: tuple[bool, ...]


def reduction_factors(dataset: xr.Dataset, setting: GeneralSetting, quantity: str, solution: str) -> list[ReductionRow]:
    """Reduction factors of ``quantity`` for ``solution`` at each (clearance, R) of ``dataset`` (see module doc).

    Parameters
    ----------
    dataset : xarray.Dataset
        A stepped study's dataset (or part of it) holding ``quantity`` along ``solution`` and ``frequency``.
    setting : GeneralSetting
        The study's structure (with its named view), load and stops.
    quantity : str
        ``x1_amplitude``, ``x2_amplitude``, ``force_amplitude`` or ``suspension_force_amplitude``.
    solution : str
        The solution whose factors are wanted.

    Raises
    ------
    ValueError
        For another quantity, or a structure without the named view.
    """
    if quantity not in REDUCED_QUANTITIES:
        raise ValueError(f"quantity must be one of {sorted(REDUCED_QUANTITIES)}, got {quantity!r}")
    system = setting.named
    if system is None:
        raise ValueError("reduction factors need the paper's two-mass chain (its two resonances and anti-resonance)")
    peaks = linear_peaks(setting, quantity)
    split = system.antiresonance_angular_frequency() / (2.0 * np.pi)
    data = dataset[quantity].sel(solution=solution)
    stable = dataset["stable"].sel(solution=solution) if "stable" in dataset and solution == "pgf" else None
    f = data["frequency"].values
    w = 2.0 * np.pi * f
    bands = [f < split, f >= split]
    linear_value = setting.linear_value(quantity, w)
    widths = [2.0 * zeta * peak.frequency for zeta, peak in zip(_loss_factors(system), peaks)]
    coarse = tuple(bool(np.sum(band) < 2 or np.max(np.diff(f[band]), initial=0.0) > width / 4.0) for band, width in zip(bands, widths))
    rows = []
    for delta in _values(data, "clearance"):
        fits = setting.linear_fits(w, float(delta))
        for r in _values(data, "restitution"):
            sel = {k: v for k, v in (("clearance", delta), ("restitution", r)) if k in data.dims}
            values = np.asarray(data.sel(sel).values, dtype=float)
            unstable = np.asarray(stable.sel(sel).values == 0) if stable is not None else np.zeros(f.shape, bool)
            realisable = np.where(unstable | np.isnan(values), -np.inf, values)
            realisable = np.maximum(realisable, np.where(fits, linear_value, -np.inf))
            largest = tuple(float(np.max(realisable[b], initial=-np.inf)) for b in bands)
            rows.append(
                ReductionRow(
                    clearance=float(delta),
                    restitution=float(r),
                    linear_peak=tuple(p.value for p in peaks),
                    largest=tuple(v if np.isfinite(v) else np.nan for v in largest),
                    factor=tuple(p.value / v if np.isfinite(v) and v > 0 else np.nan for p, v in zip(peaks, largest)),
                    undefined=tuple(int(np.sum(np.isnan(values) & b)) for b in bands),
                    unstable=tuple(int(np.sum(unstable & b)) for b in bands) if stable is not None else None,
                    coarse=coarse,
                )
            )
    return rows


def paper_reduction_factors(system: TwoDofSystem, amplitude: float, quantity: str, restitution: float, clearance: float) -> tuple[float, float] | None:
    """The factors the paper quotes, for its own example only (system of eq. 24, q = 10 N, Delta = 3 mm, R = 0.2)."""
    if system == PAPER_SYSTEM and amplitude == 10.0 and abs(clearance - 3e-3) < 1e-12 and abs(restitution - 0.2) < 1e-12:
        return _PAPER.get(quantity)
    return None


def linear_peaks(setting: GeneralSetting, quantity: str) -> list[ResonancePeak]:
    """Maxima of the linear |quantity| near each natural frequency of the named view, by analytic maximisation."""
    assert setting.named is not None
    return peaks_near(setting.named.natural_angular_frequencies(), lambda w: setting.linear_value(quantity, np.asarray(w, dtype=float)), _SPAN)


def _values(data: xr.DataArray, name: str) -> np.ndarray:
    """The values of coordinate ``name`` (NaN where the stops give their own and the dataset has none)."""
    return np.atleast_1d(data[name].values) if name in data.coords else np.array([np.nan])


def _loss_factors(system: TwoDofSystem) -> list[float]:
    """Modal loss factors for the half-power widths (exact decomposition of H22; padded if fewer than 2 modes)."""
    zeta = list(exact_modal_parameters(system).loss_factor)
    return (zeta + [zeta[-1] if zeta else 1.0] * 2)[:2]

_REDUCTION_QUANTITIES = ("x1_amplitude", "force_amplitude", "suspension_force_amplitude", "x2_amplitude")


def computed_part(dataset: xr.Dataset, solution: str) -> xr.Dataset:
    """``dataset`` on the frequencies where ``solution`` was computed (its regime is not ``not_computed`` at some
    point of the other dimensions); all of it if there is no regime."""
    if "regime" not in dataset:
        return dataset
    regime = dataset["regime"].sel(solution=solution)
    computed = regime != Regime.NOT_COMPUTED
    others = [d for d in regime.dims if d != "frequency"]
    if others:
        computed = computed.any(others)
    return dataset.isel(frequency=np.flatnonzero(computed.values))


def reduction_intro() -> str:
    """The definition of the reduction factors and the notes on the tables' columns (HTML)."""
    return (
        f"<p>{html.escape(DEFINITION[:1].upper() + DEFINITION[1:])}</p><p>Each solution is counted on the points it was asked to compute only "
        "(simulations: their own frequency grid): <i>computed</i> is their number per band, <i>undefined</i> those "
        "without a value (no steady state known, or the simulation failed). &dagger;: the grid step in that band exceeds "
        "a quarter of the linear peak's half-power width; a narrow maximum may be missed.</p>"
    )


def reduction_tables(dataset: xr.Dataset, setting: GeneralSetting, paper_layout: bool) -> list[Table]:
    """One table per quantity: reduction factors of every solution but ``linear`` at each (clearance, R) of a study
    whose structure has the named view; the paper's own values beside them, in a column of their own, where the study
    is the paper's (``paper_layout``, :func:`~vibroimpact.grids.sections.paper_study`) and has its example's numbers."""
    assert setting.named is not None
    on_subset = subset_solutions(dataset)  # a few points make no resonance peak: their own section compares them
    solutions = [str(s) for s in dataset["solution"].values if s != "linear" and s not in on_subset]
    split = setting.named.antiresonance_angular_frequency() / (2.0 * np.pi)
    tables = []
    for quantity in _REDUCTION_QUANTITIES:
        if quantity not in dataset or not solutions:
            continue
        units, scale = QUANTITIES[quantity].page_units, QUANTITIES[quantity].scale
        cells: list[tuple[str, tuple[float, float] | None]] = []
        for solution in solutions:
            part = computed_part(dataset, solution)
            f = part["frequency"].values
            computed = f"{int(np.sum(f < split))} / {int(np.sum(f >= split))}"
            for row in reduction_factors(part, setting, quantity, solution):
                paper = paper_reduction_factors(setting.named, setting.amplitude, quantity, row.restitution, row.clearance) if paper_layout else None
                factors = "".join(f"<td>{fmt(factor, '.1f')}{' &dagger;' if coarse else ''}</td>" for factor, coarse in zip(row.factor, row.coarse))
                unstable = "n/a" if row.unstable is None else f"{row.unstable[0]} / {row.unstable[1]}"
                cells.append((
                    f"<tr><td>{solution}</td><td>{fmt(row.clearance * 1e3, 'g')}</td><td>{fmt(row.restitution, 'g')}</td>"
                    f"<td>{fmt(scale * row.linear_peak[0], '#.4g')} / {fmt(scale * row.linear_peak[1], '#.4g')}</td><td>{fmt(scale * row.largest[0], '#.4g')} / {fmt(scale * row.largest[1], '#.4g')}</td>"
                    f"{factors}<td>{computed}</td><td>{row.undefined[0]} / {row.undefined[1]}</td><td>{unstable}</td>", paper))  # fmt: skip
        quoted = any(paper is not None for _, paper in cells)  # the paper's column only where it quotes a value
        header = _header(
            f"linear peak 1 / 2 [{units}]", f"largest realisable in band 1 / 2 [{units}]", "reduction factor 1", "reduction factor 2", "computed points 1 / 2",
            "undefined points 1 / 2", "unstable points 1 / 2", *(["paper"] if quoted else []),
        )
        body = [row + (f"<td>{'' if paper is None else fmt(paper[0], 'g') + ' / ' + fmt(paper[1], 'g')}</td>" if quoted else "") + "</tr>" for row, paper in cells]
        tables.append(Table(f"Reduction factors: {QUANTITIES[quantity].label}", f"<table>{header}{''.join(body)}</table>"))
    return tables


def agreement_table(dataset: xr.Dataset, split: float) -> Table | None:
    """Simulation against pgf by band (split at ``split`` [Hz], the anti-resonance): relative differences of |X1|
    where the pgf orbit is stable and where not."""
    engines = [str(name) for name in dataset["solution"].values if name in ENGINE_SOLUTIONS]
    if not engines or "pgf" not in dataset["solution"].values or "x1_amplitude" not in dataset:
        return None
    header = _header(
        "band", "computed points", "max rel. diff. |X1|, pgf stable or linear", "median", "pgf unstable: points", "max rel. diff. there",
        "simulation quasi-periodic", "chaotic", "not periodic, undecided", "simulation with other than 1 or 0 impacts per period",
    )
    body = []
    for engine in engines:
        data = computed_part(dataset, engine)
        sim_f = data["frequency"].values
        for delta in _grid_values(data, "clearance"):
            for r in _grid_values(data, "restitution"):
                line = data.sel({k: v for k, v in (("clearance", delta), ("restitution", r)) if k in data.dims})
                sim = line["x1_amplitude"].sel(solution=engine).values
                pgf = line["x1_amplitude"].sel(solution="pgf").values
                # the one-impact orbit is unstable where flagged so, and where pgf reports the linear motion instead (regime 7)
                unstable = line["regime"].sel(solution="pgf").values == Regime.LINEAR_WITH_UNSTABLE_ONE_IMPACT
                if "stable" in line:
                    unstable = unstable | (line["stable"].sel(solution="pgf").values == 0)
                regime = line["regime"].sel(solution=engine).values
                kinds = [regime == int(kind) for kind in (Regime.QUASI_PERIODIC, Regime.CHAOTIC, Regime.IRREGULAR)]
                other = ~np.isin(line["impacts_per_period"].sel(solution=engine).values, (0.0, 1.0)) if "impacts_per_period" in line else np.zeros(sim.shape, bool)
                with np.errstate(invalid="ignore", divide="ignore"):
                    difference = np.abs(sim - pgf) / np.abs(pgf)
                for band, mask in (("1", sim_f < split), ("2", sim_f >= split)):
                    good = mask & ~unstable & np.isfinite(difference)
                    bad = mask & unstable & np.isfinite(difference)
                    body.append(
                        f"<tr><td>{engine}</td><td>{fmt(float(delta) * 1e3, 'g')}</td><td>{fmt(r, 'g')}</td><td>{band}</td><td>{int(mask.sum())}</td>"
                        f"<td>{fmt(_largest(difference[good]), '.1e')}</td><td>{fmt(np.median(difference[good]) if good.any() else np.nan, '.1e')}</td>"
                        f"<td>{int(bad.sum())}</td><td>{fmt(_largest(difference[bad]), '.1e')}</td>"
                        + "".join(f"<td>{int((kind & mask).sum())}</td>" for kind in kinds)
                        + f"<td>{int((other & mask).sum())}</td></tr>"
                    )
    return Table("Simulation against PGF by band (|X1| fundamental)", f"<table>{header}{''.join(body)}</table>")


def _header(*columns: str) -> str:
    """Header row of a table over the (clearance, R) grid: solution, Delta [mm], R, then ``columns`` (HTML)."""
    return "<tr>" + "".join(f"<th>{column}</th>" for column in ("solution", "Delta [mm]", "R", *columns)) + "</tr>"


def _grid_values(data: xr.Dataset, name: str) -> np.ndarray:
    """The values of coordinate ``name`` (NaN where the stops give their own and the dataset has none)."""
    return np.atleast_1d(data[name].values) if name in data.coords else np.array([np.nan])


def _largest(values: np.ndarray) -> float:
    """Largest of ``values``; NaN if there are none."""
    return float(np.max(values)) if values.size else float("nan")
