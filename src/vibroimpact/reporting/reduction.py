"""Reduction factors: how much a stop lowers the response at each linear resonance.

They need the structure's named view (the paper's two resonances and its anti-resonance); the linear response, its
peaks and where it fits are those of the study's own load and stops (:class:`~vibroimpact.reporting.general_record.GeneralSetting`).

Definition (stated in every report): for a quantity (|X1|, |X2| or the force on the base) and linear resonance i,

    factor_i = (peak of the linear response near natural frequency i, by analytic maximisation)
               / (largest realisable steady response on the grid within resonance i's band)

The bands split the frequency range at the anti-resonance sqrt(K2/M2). A steady response is *realisable* if it is a
one-impact value that is not known to be unstable, or the linear value wherever the linear motion stays clear of the
stops (it coexists with any impact regime there, and a frequency sweep can stay on it). Unstable one-impact
values and undefined points (NaN) are left out and counted; where there are any, the factor is an upper bound.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

from vibroimpact.analysis.linear import ResonancePeak, peaks_near
from vibroimpact.model.modal import exact_modal_parameters
from vibroimpact.model.system import PAPER_SYSTEM, TwoDofSystem
from vibroimpact.reporting.general_record import GeneralSetting

__all__ = ["DEFINITION", "ReductionRow", "reduction_factors", "paper_reduction_factors"]

DEFINITION = " ".join(__doc__.split("Definition (stated in every report): ")[1].split())

#: Quantities with reduction factors (coordinates of the named view, the force on the base).
QUANTITIES = ("x1_amplitude", "x2_amplitude", "force_amplitude", "suspension_force_amplitude")
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
    if quantity not in QUANTITIES:
        raise ValueError(f"quantity must be one of {sorted(QUANTITIES)}, got {quantity!r}")
    system = setting.named
    if system is None:
        raise ValueError("reduction factors need the paper's two-mass chain (its two resonances and anti-resonance)")
    peaks = linear_peaks(setting, quantity)
    split = system.antiresonance_frequency() / (2.0 * np.pi)
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
    return peaks_near(setting.named.natural_frequencies(), lambda w: setting.linear_value(quantity, np.asarray(w, dtype=float)), _SPAN)


def _values(data: xr.DataArray, name: str) -> np.ndarray:
    """The values of coordinate ``name`` (NaN where the stops give their own and the dataset has none)."""
    return np.atleast_1d(data[name].values) if name in data.coords else np.array([np.nan])


def _loss_factors(system: TwoDofSystem) -> list[float]:
    """Modal loss factors for the half-power widths (exact decomposition of H22; padded if fewer than 2 modes)."""
    zeta = list(exact_modal_parameters(system).loss_factor)
    return (zeta + [zeta[-1] if zeta else 1.0] * 2)[:2]
