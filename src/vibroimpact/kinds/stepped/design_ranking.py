"""Which restitution ratio R and clearance Delta to choose: every design's numbers, their ranking and the
recommendation, from the figures of merit of :mod:`vibroimpact.kinds.stepped.design_metrics`.

A design is *eligible* when its working band is free of impacts: no point of it impacts on the design solution's
grid, none is unknown, and Delta is at least the no-stop absorber's largest |X2| over the whole working band (so
that the linear motion clears the stop between grid points too). Eligible designs fall in tiers
(:attr:`Candidate.tier`): regular motion everywhere (worst regime periodic at most), else irregular somewhere but
every point known, else unresolved or missing points somewhere (resonance peaks then lower bounds). Within the first
non-empty tier the recommendation minimises the larger of the two resonance-band peaks of |X1|; designs within a
relative ``tie_tolerance`` (2 %) of the smallest count as tied, and among them the largest clearance wins (fewer and
softer impacts, a looser manufacturing tolerance), then the lowest R (a lossier stop, easier to make).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import xarray as xr

from vibroimpact.kinds.stepped.design_metrics import (
    BAND_NAMES,
    RESONANCE_BANDS,
    WORKING_FRACTION,
    DesignRegime,
    FrequencyBands,
    NoStopPeak,
    band_peaks,
    design_regimes,
    design_solution,
    frequency_bands,
    no_stop_peaks,
    regime_map,
    restitution_dependent_clearances,
    solution_frequencies,
    working_band_clearance,
)

__all__ = ["TIE_TOLERANCE", "TIER_TEXT", "Candidate", "Recommendation", "DesignMap", "candidates", "rank", "recommend", "design_map"]

#: Default relative tolerance within which two designs' objectives tie.
TIE_TOLERANCE = 0.02
#: What each tier of :attr:`Candidate.tier` means, for the page.
TIER_TEXT = ("regular motion at every frequency", "irregular motion at some frequencies, every point known", "some frequencies unresolved or not computed")


@dataclass(frozen=True)
class Candidate:
    """One design (R, Delta) and its numbers.

    Attributes
    ----------
    restitution : float
        R [-].
    clearance : float
        Delta [m].
    peaks : dict of str to float
        Peak realised |X1| per band [m] (NaN: none realised).
    peak_frequencies : dict of str to float
        Where [Hz].
    unknown_points : dict of str to int
        Points of each band whose |X1| is not realised (the peak is then a lower bound).
    no_stop : dict of str to float
        No-stop peak per band [m].
    worst_regime : DesignRegime
        Worst motion over the solution's frequency grid.
    impact_fraction : float
        Share of the frequencies (impacts known) where the motion impacts [-].
    irregular_frequencies : tuple of float
        Frequencies of irregular motion [Hz].
    unresolved_points, missing_points : int
        Frequencies of unresolved, and of failed or not computed, motion.
    working_impact_free : bool
        No point of the working band impacts on the grid, none unknown.
    clears_working_band : bool
        Delta is at least the no-stop |X2| anywhere in the working band (True when that is unknown).
    peak_from_closed_form : dict of str to bool
        Per band: the peak is the closed form's stable state, coexisting with the simulated motion (or alone).
    """

    restitution: float
    clearance: float
    peaks: dict[str, float]
    peak_frequencies: dict[str, float]
    unknown_points: dict[str, int]
    no_stop: dict[str, float]
    worst_regime: DesignRegime
    impact_fraction: float
    irregular_frequencies: tuple[float, ...]
    unresolved_points: int
    missing_points: int
    working_impact_free: bool
    clears_working_band: bool
    peak_from_closed_form: dict[str, bool] = field(default_factory=dict)

    @property
    def eligible(self) -> bool:
        """The working band is free of impacts, on the grid and between its points."""
        return self.working_impact_free and self.clears_working_band

    @property
    def objective(self) -> float:
        """The larger resonance-band peak of |X1| [m] (NaN when a resonance band has no realised value)."""
        values = [self.peaks[band] for band in RESONANCE_BANDS]
        return max(values) if all(math.isfinite(v) for v in values) else math.nan

    @property
    def reduction_dB(self) -> dict[str, float]:
        """20 log10(no-stop peak / peak) per band [dB]: positive where the stop lowers the peak."""
        return {band: 20.0 * math.log10(self.no_stop[band] / self.peaks[band]) if self.peaks[band] > 0.0 and self.no_stop[band] > 0.0 else math.nan for band in BAND_NAMES}

    @property
    def tier(self) -> int:
        """0: regular motion everywhere; 1: irregular somewhere, every point known; 2: unresolved or missing points."""
        if self.unresolved_points or self.missing_points or any(self.unknown_points.values()):
            return 2
        return 1 if self.irregular_frequencies else 0

    @property
    def bounds_only(self) -> bool:
        """A resonance band has points whose |X1| is not realised: its peak is a lower bound."""
        return any(self.unknown_points[band] for band in RESONANCE_BANDS)


@dataclass(frozen=True)
class Recommendation:
    """The recommended design and why.

    Attributes
    ----------
    design : Candidate
        The chosen (R, Delta).
    tier : int
        Its :attr:`Candidate.tier`: the best tier any eligible design reached.
    tied : int
        Designs of that tier within the tie tolerance of its smallest objective (the chosen one included).
    tie_tolerance : float
        That tolerance, relative [-].
    eligible : int
        Eligible designs.
    """

    design: Candidate
    tier: int
    tied: int
    tie_tolerance: float
    eligible: int


def candidates(peaks: xr.Dataset, regimes: xr.Dataset, classes: xr.DataArray, no_stop: dict[str, NoStopPeak], working_clearance: float) -> list[Candidate]:
    """Every design of the grid as a :class:`Candidate`, in the grid's order (restitution outer, clearance inner).

    Parameters
    ----------
    peaks, regimes : xarray.Dataset
        :func:`~vibroimpact.kinds.stepped.design_metrics.band_peaks` and :func:`~vibroimpact.kinds.stepped.design_metrics.regime_map`.
    classes : xarray.DataArray
        :func:`~vibroimpact.kinds.stepped.design_metrics.design_regimes`.
    no_stop : dict of str to NoStopPeak
        :func:`~vibroimpact.kinds.stepped.design_metrics.no_stop_peaks`.
    working_clearance : float
        :func:`~vibroimpact.kinds.stepped.design_metrics.working_band_clearance` [m] (NaN: unknown).
    """
    out = []
    f = classes["frequency"].values
    for i, r in enumerate(peaks["restitution"].values):
        for j, c in enumerate(peaks["clearance"].values):
            at = {band: peaks.sel(band=band).isel(restitution=i, clearance=j) for band in BAND_NAMES}
            row = regimes.isel(restitution=i, clearance=j)
            irregular = f[classes.values[i, j] == DesignRegime.IRREGULAR]
            out.append(Candidate(
                restitution=float(r), clearance=float(c),
                peaks={b: float(at[b]["peak_x1_amplitude"]) for b in BAND_NAMES},
                peak_frequencies={b: float(at[b]["peak_frequency"]) for b in BAND_NAMES},
                unknown_points={b: int(at[b]["unknown_points"]) for b in BAND_NAMES},
                no_stop={b: no_stop[b].value for b in BAND_NAMES},
                worst_regime=DesignRegime(int(row["worst_regime"])),
                impact_fraction=float(row["impact_fraction"]),
                irregular_frequencies=tuple(float(x) for x in irregular),
                unresolved_points=int(row["count_unresolved"]),
                missing_points=int(row["count_not_computed"]),
                working_impact_free=bool(row["working_impact_free"]),
                clears_working_band=not float(c) < working_clearance,
                peak_from_closed_form={b: bool(at[b]["peak_from_companion"]) for b in BAND_NAMES},
            ))  # fmt: skip
    return out


def _tied(designs: list[Candidate], tie_tolerance: float) -> tuple[list[Candidate], list[Candidate]]:
    """(the eligible designs tied with the best, the other eligible designs), sorted by tier then objective (a NaN
    objective last in its tier)."""
    ordered = sorted((d for d in designs if d.eligible), key=lambda d: (d.tier, math.isnan(d.objective), d.objective if math.isfinite(d.objective) else 0.0))
    if not ordered or not math.isfinite(ordered[0].objective):
        return ordered[:1], ordered[1:]
    best = ordered[0]
    tied = [d for d in ordered if d.tier == best.tier and d.objective <= best.objective * (1.0 + tie_tolerance)]
    return tied, [d for d in ordered if d not in tied]


def _tie_order(design: Candidate) -> tuple[float, float]:
    """Larger clearance first, then lower R."""
    return -design.clearance, design.restitution


def rank(designs: list[Candidate], tie_tolerance: float = TIE_TOLERANCE) -> list[Candidate]:
    """The eligible designs, best first: the designs tied with the best (largest clearance, then lowest R), then the
    others by tier and objective."""
    tied, others = _tied(designs, tie_tolerance)
    return sorted(tied, key=_tie_order) + others


def recommend(designs: list[Candidate], tie_tolerance: float = TIE_TOLERANCE) -> Recommendation | None:
    """The first design of :func:`rank`; None when no design is eligible."""
    tied, others = _tied(designs, tie_tolerance)
    if not tied:
        return None
    first = min(tied, key=_tie_order)
    return Recommendation(first, first.tier, len(tied), tie_tolerance, len(tied) + len(others))


@dataclass(frozen=True)
class DesignMap:
    """Everything the design-map page shows.

    Attributes
    ----------
    solution : str
        The design solution.
    bands : FrequencyBands
        The bands.
    frequency : ndarray
        The solution's own frequency grid [Hz].
    peaks, regimes : xarray.Dataset
        :func:`~vibroimpact.kinds.stepped.design_metrics.band_peaks`, :func:`~vibroimpact.kinds.stepped.design_metrics.regime_map`.
    no_stop : dict of str to NoStopPeak
        :func:`~vibroimpact.kinds.stepped.design_metrics.no_stop_peaks`.
    working_clearance : float
        :func:`~vibroimpact.kinds.stepped.design_metrics.working_band_clearance` [m].
    restitution_dependent : ndarray
        Clearances [m] where R decides whether the working band impacts.
    designs : list of Candidate
        Every design, in the grid's order.
    ranked : list of Candidate
        :func:`rank`.
    recommendation : Recommendation or None
        :func:`recommend`.
    """

    solution: str
    bands: FrequencyBands
    frequency: np.ndarray
    peaks: xr.Dataset
    regimes: xr.Dataset
    no_stop: dict[str, NoStopPeak]
    working_clearance: float
    restitution_dependent: np.ndarray
    designs: list[Candidate]
    ranked: list[Candidate]
    recommendation: Recommendation | None


def design_map(dataset: xr.Dataset, solution: str | None = None, working_fraction: float = WORKING_FRACTION, tie_tolerance: float = TIE_TOLERANCE) -> DesignMap:
    """The design map of ``dataset`` for ``solution`` (default :func:`~vibroimpact.kinds.stepped.design_metrics.design_solution`)."""
    name = design_solution(dataset, solution)
    bands = frequency_bands(dataset, working_fraction)
    peaks = band_peaks(dataset, name, bands)
    regimes = regime_map(dataset, name, bands)
    classes = design_regimes(dataset, name)
    no_stop = no_stop_peaks(dataset, bands, name)
    reach = working_band_clearance(dataset, bands)
    designs = candidates(peaks, regimes, classes, no_stop, reach)
    frequency = np.asarray(dataset["frequency"].values[solution_frequencies(dataset, name)], dtype=float)
    return DesignMap(
        name, bands, frequency, peaks, regimes, no_stop, reach, restitution_dependent_clearances(regimes), designs, rank(designs, tie_tolerance), recommend(designs, tie_tolerance)
    )
