"""Figures of merit of a design map: which restitution ratio R and clearance Delta to choose for the absorber.

A design map is a stepped dataset over (``solution``, ``restitution``, ``clearance``, ``frequency``). Everything
here is read from it, for one *design solution* (:func:`design_solution`: ``exact`` where it was computed, else
``pgf``), over that solution's own frequency grid (the frequencies where it was computed for some design; a
time-domain solution is often run on a coarser grid than the closed forms).

Frequency bands (:class:`FrequencyBands`), from the dataset's ``natural_frequencies_Hz`` f1 < f2 and
``antiresonance_frequency_Hz`` fa (f1 < fa < f2):

* lower resonance band: f < (f1 + fa) / 2;
* upper resonance band: f > (fa + f2) / 2;
* working band: |f - fa| <= w fa (w = 3 % unless told), kept inside the two splits.

Frequencies between the working band and a split belong to no band; they count in the regime map.

Motion at each point (:class:`DesignRegime`, from the ``regime`` flag and, for the closed form, its Floquet
``stable`` flag), in the order used for the *worst regime* of a design: no impact < one impact per period <
periodic otherwise (several impacts, or several excitation periods) < irregular (irregular, quasi-periodic or
chaotic) < unresolved (the closed form has no stable orbit there: no one-impact orbit, an inadmissible or an
unstable one, so the steady motion is unknown, possibly irregular) < failed or not computed. A point's |X1| counts
as *realised* in the first four classes only: an unstable orbit's |X1| is never a peak, and a NaN is never 0.
Where the design solution is a simulation, the closed form ``pgf``'s stable state at the same point (the linear
motion where it fits, or a stable one-impact orbit) counts too: it may coexist with the attractor the simulation
settled on, so a band's peak is the largest |X1| of every stable steady state known there, and a frequency impacts
when any of them does.

The no-stop absorber's peaks (:func:`no_stop_peaks`) are the yardstick, and :func:`working_band_clearance` the
clearance above which its linear motion stays off the stop across the whole working band. Which design to choose
is :mod:`vibroimpact.kinds.stepped.design_ranking`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import IntEnum

import numpy as np
import xarray as xr
from scipy.optimize import minimize_scalar

from vibroimpact.analysis.linear import paper_linear_response
from vibroimpact.analysis.stability import Regime
from vibroimpact.reporting.record import named_view
from vibroimpact.scene.schema import ENGINE_SOLUTIONS

__all__ = [
    "BAND_NAMES", "RESONANCE_BANDS", "WORKING_FRACTION", "DesignRegime", "DESIGN_REGIME_LABELS", "FrequencyBands", "frequency_bands",
    "design_solution", "solution_frequencies", "design_regimes", "companion_solution", "worst_stable_x1", "point_impacts", "band_peaks", "NoStopPeak", "no_stop_amplitude", "no_stop_peaks",
    "working_band_clearance", "regime_map", "restitution_dependent_clearances",
]  # fmt: skip

#: The three bands, in frequency order.
BAND_NAMES = ("lower", "working", "upper")
#: The bands whose peak a design minimises.
RESONANCE_BANDS = ("lower", "upper")
#: Default half-width of the working band, relative to the anti-resonance frequency.
WORKING_FRACTION = 0.03
#: Samples of the analytic no-stop response per band.
_DENSE_POINTS = 20001
#: The system's attributes in a dataset.


class DesignRegime(IntEnum):
    """The motion at one point of a design, ordered from best to worst (see the module docstring)."""

    NO_IMPACT = 0
    ONE_IMPACT = 1
    PERIODIC_OTHER = 2
    IRREGULAR = 3
    UNRESOLVED = 4
    NOT_COMPUTED = 5


#: How the page names each class.
DESIGN_REGIME_LABELS: dict[DesignRegime, str] = {
    DesignRegime.NO_IMPACT: "no impact",
    DesignRegime.ONE_IMPACT: "one impact per period",
    DesignRegime.PERIODIC_OTHER: "periodic, several impacts or periods",
    DesignRegime.IRREGULAR: "irregular, quasi-periodic or chaotic",
    DesignRegime.UNRESOLVED: "unresolved (no stable closed-form orbit)",
    DesignRegime.NOT_COMPUTED: "failed or not computed",
}
#: The regime flags of each class; a one-impact flag whose orbit is unstable is unresolved instead.
_CLASSES: dict[DesignRegime, tuple[Regime, ...]] = {
    DesignRegime.NO_IMPACT: (Regime.LINEAR, Regime.LINEAR_WITH_INADMISSIBLE_ONE_IMPACT, Regime.LINEAR_WITH_UNSTABLE_ONE_IMPACT, Regime.HELD_ON_STOP),
    DesignRegime.ONE_IMPACT: (Regime.ONE_IMPACT, Regime.ONE_IMPACT_COEXISTING_LINEAR),
    DesignRegime.PERIODIC_OTHER: (Regime.PERIODIC_IMPACTS,),
    DesignRegime.IRREGULAR: (Regime.IRREGULAR, Regime.QUASI_PERIODIC, Regime.CHAOTIC),
    DesignRegime.UNRESOLVED: (Regime.NONE, Regime.NONE_INADMISSIBLE_ONE_IMPACT, Regime.LINEAR_EXCEEDS_CLEARANCE, Regime.SWEPT_CONTACT),
    DesignRegime.NOT_COMPUTED: (Regime.NOT_COMPUTED, Regime.FAILED),
}
#: Regime flags whose linear motion crosses the stop: the steady motion impacts, whatever it is.
_MUST_IMPACT = (Regime.ONE_IMPACT, Regime.NONE, Regime.NONE_INADMISSIBLE_ONE_IMPACT, Regime.LINEAR_EXCEEDS_CLEARANCE)
_UNSTABLE = 0
#: The closed form whose stable states count alongside a simulation's.
COMPANION = "pgf"
#: Relative margin [-] by which the companion's |X1| must exceed the simulated one to count as another, larger steady
#: state: within it the two are one orbit (a converged simulation repeats to a tolerance of ~1e-7 of the motion).
SAME_ORBIT = 1e-6


@dataclass(frozen=True)
class FrequencyBands:
    """The lower resonance, working and upper resonance bands (see the module docstring).

    Attributes
    ----------
    natural_Hz : tuple of float
        Natural frequencies f1 < f2 [Hz].
    antiresonance_Hz : float
        Anti-resonance frequency fa of the absorber [Hz].
    working_fraction : float
        Half-width of the working band relative to fa [-].
    """

    natural_Hz: tuple[float, float]
    antiresonance_Hz: float
    working_fraction: float = WORKING_FRACTION

    def __post_init__(self) -> None:
        f1, f2 = self.natural_Hz
        if not f1 < self.antiresonance_Hz < f2:
            raise ValueError(f"the anti-resonance must lie between the natural frequencies, got {self.antiresonance_Hz!r} and {self.natural_Hz!r} [Hz]")
        if not 0.0 < self.working_fraction < 1.0:
            raise ValueError(f"working_fraction must be in (0, 1), got {self.working_fraction!r}")

    @property
    def splits(self) -> tuple[float, float]:
        """(f1 + fa) / 2 and (fa + f2) / 2 [Hz]."""
        return 0.5 * (self.natural_Hz[0] + self.antiresonance_Hz), 0.5 * (self.antiresonance_Hz + self.natural_Hz[1])

    def limits(self, band: str) -> tuple[float, float]:
        """(lowest, highest) frequency of ``band`` [Hz]; the resonance bands are open-ended (infinite)."""
        low, high = self.splits
        if band == "lower":
            return -math.inf, low
        if band == "upper":
            return high, math.inf
        if band == "working":
            half = self.working_fraction * self.antiresonance_Hz
            return max(self.antiresonance_Hz - half, low), min(self.antiresonance_Hz + half, high)
        raise ValueError(f"band must be one of {BAND_NAMES}, got {band!r}")

    def mask(self, frequency: np.ndarray, band: str) -> np.ndarray:
        """Which of ``frequency`` [Hz] lie in ``band``."""
        low, high = self.limits(band)
        f = np.asarray(frequency, dtype=float)
        if band == "working":
            return (f >= low) & (f <= high)
        return (f > low) & (f < high)

    def describe(self, band: str, frequency: np.ndarray) -> str:
        """``band``'s limits within ``frequency`` (the grid), e.g. ``15.0-28.0 Hz``."""
        low, high = self.limits(band)
        f = np.asarray(frequency, dtype=float)
        return f"{max(low, float(f.min())):.1f}-{min(high, float(f.max())):.1f} Hz"


def frequency_bands(dataset: xr.Dataset, working_fraction: float = WORKING_FRACTION) -> FrequencyBands:
    """The bands of ``dataset``, from its attributes ``natural_frequencies_Hz`` and ``antiresonance_frequency_Hz``."""
    natural = np.sort(np.asarray(dataset.attrs["natural_frequencies_Hz"], dtype=float))
    return FrequencyBands((float(natural[0]), float(natural[-1])), float(dataset.attrs["antiresonance_frequency_Hz"]), working_fraction)


def design_solution(dataset: xr.Dataset, solution: str | None = None) -> str:
    """``solution`` if given (it must be in the dataset), else ``exact`` where it was computed somewhere, else ``pgf``."""
    names = [str(s) for s in dataset["solution"].values]
    if solution is not None:
        if solution not in names:
            raise ValueError(f"solution {solution!r} is not in the dataset (it has {names})")
        return solution
    if "exact" in names and bool(np.any(dataset["regime"].sel(solution="exact").values != Regime.NOT_COMPUTED)):
        return "exact"
    if "pgf" in names:
        return "pgf"
    raise ValueError(f"a design map needs solution 'exact' or 'pgf'; the dataset has {names}")


def _design_grid(dataset: xr.Dataset) -> xr.Dataset:
    """``dataset`` with ``restitution`` and ``clearance`` as dimensions (a scalar coordinate becomes one of length 1)."""
    for name in ("restitution", "clearance"):
        if name not in dataset.dims:
            if name not in dataset.coords:
                raise ValueError(f"a design map needs the coordinate {name!r}")
            dataset = dataset.expand_dims(name)
    return dataset


def _part(dataset: xr.Dataset, solution: str) -> xr.Dataset:
    return _design_grid(dataset).sel(solution=solution, drop=True).transpose("restitution", "clearance", "frequency", ...)


def solution_frequencies(dataset: xr.Dataset, solution: str) -> np.ndarray:
    """Which frequencies of the dataset ``solution`` was computed at, for some design (its own grid)."""
    regime = _part(dataset, solution)["regime"].values
    return np.any(regime != Regime.NOT_COMPUTED, axis=(0, 1))


def design_regimes(dataset: xr.Dataset, solution: str) -> xr.DataArray:
    """The :class:`DesignRegime` of every point (restitution, clearance, frequency) of ``solution``'s grid."""
    part = _part(dataset, solution).isel(frequency=solution_frequencies(dataset, solution))
    regime = part["regime"].values.astype(int)
    stable = part["stable"].values if "stable" in part else np.full(regime.shape, -1)
    classes = np.full(regime.shape, int(DesignRegime.NOT_COMPUTED), dtype=np.int8)
    for design, flags in _CLASSES.items():
        classes[np.isin(regime, [int(f) for f in flags])] = int(design)
    classes[(regime == Regime.ONE_IMPACT) & (stable == _UNSTABLE)] = int(DesignRegime.UNRESOLVED)
    return xr.DataArray(classes, coords={name: part[name] for name in ("restitution", "clearance", "frequency")}, dims=("restitution", "clearance", "frequency"))


def companion_solution(dataset: xr.Dataset, solution: str) -> str | None:
    """``pgf`` when ``solution`` is a simulation and the dataset has it, else None.

    A simulation settles on one attractor; the closed form's stable steady state at the same point (the linear motion
    where it fits the clearance, or a stable one-impact orbit) may coexist with it, and is just as realisable.
    """
    names = [str(s) for s in dataset["solution"].values]
    return COMPANION if solution in ENGINE_SOLUTIONS and COMPANION in names else None


def _companion_states(dataset: xr.Dataset, solution: str, classes: xr.DataArray) -> tuple[np.ndarray, np.ndarray] | None:
    """(|X1| [m] of the companion's stable state on ``solution``'s grid (NaN: none), where that state impacts)."""
    companion = companion_solution(dataset, solution)
    if companion is None:
        return None
    other = design_regimes(dataset, companion).sel(frequency=classes["frequency"]).values
    x1 = _part(dataset, companion)["x1_amplitude"].sel(frequency=classes["frequency"]).values
    stable = (other <= DesignRegime.ONE_IMPACT) & np.isfinite(x1)
    return np.where(stable, x1, np.nan), other == DesignRegime.ONE_IMPACT


def worst_stable_x1(dataset: xr.Dataset, solution: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The largest |X1| of the stable steady states known at each point of ``solution``'s grid.

    Returns
    -------
    (ndarray, ndarray, ndarray)
        Shape (restitution, clearance, frequency): |X1| [m] (NaN: none known); where ``solution`` itself realised a
        value (the others are counted as unknown); where the value is the companion closed form's
        (:func:`companion_solution`), larger than the simulated one by more than :data:`SAME_ORBIT` or the only one.
    """
    classes = design_regimes(dataset, solution)
    x1 = _part(dataset, solution)["x1_amplitude"].sel(frequency=classes["frequency"]).values
    realised = (classes.values <= DesignRegime.IRREGULAR) & np.isfinite(x1)
    own = np.where(realised, x1, np.nan)
    companion = _companion_states(dataset, solution, classes)
    if companion is None:
        return own, realised, np.zeros(own.shape, bool)
    other = companion[0]
    larger = np.isfinite(other) & ~(own >= other * (1.0 - SAME_ORBIT))
    return np.where(larger, other, own), realised, larger


def point_impacts(dataset: xr.Dataset, solution: str) -> xr.DataArray:
    """1 where a known steady motion impacts, 0 where none does, NaN where unknown, on ``solution``'s grid.

    Impacts where ``impacts_per_period`` > 0, where the linear motion crosses the stop (any steady motion there
    touches it), or where the companion closed form (:func:`companion_solution`) has a stable impacting orbit;
    unknown where the point failed or was not computed, or the count is missing.
    """
    classes = design_regimes(dataset, solution)
    part = _part(dataset, solution).isel(frequency=solution_frequencies(dataset, solution))
    count = part["impacts_per_period"].values if "impacts_per_period" in part else np.full(classes.shape, np.nan)
    impacts = np.where(np.isfinite(count), (count > 0).astype(float), np.nan)
    impacts[np.isin(part["regime"].values, [int(f) for f in _MUST_IMPACT])] = 1.0
    impacts[classes.values == DesignRegime.NOT_COMPUTED] = np.nan
    companion = _companion_states(dataset, solution, classes)
    if companion is not None:
        impacts[companion[1]] = 1.0
    return classes.copy(data=impacts)


def band_peaks(dataset: xr.Dataset, solution: str, bands: FrequencyBands) -> xr.Dataset:
    """Peak of the largest stable |X1| (:func:`worst_stable_x1`) in each band, per design.

    Returns
    -------
    xarray.Dataset
        Dimensions (``band``, ``restitution``, ``clearance``): ``peak_x1_amplitude`` [m] (NaN where the band has no
        value), ``peak_frequency`` [Hz], ``peak_from_companion`` (the peak is the companion closed form's state),
        ``band_points`` (points of the solution's grid in the band) and ``unknown_points`` (of those, points where
        ``solution`` realised no |X1|: unresolved, failed, not computed or NaN).
    """
    worst, realised, from_companion = worst_stable_x1(dataset, solution)
    f = np.asarray(dataset["frequency"].values[solution_frequencies(dataset, solution)], dtype=float)
    peaks, where, companion, points, unknown = [], [], [], [], []
    for band in BAND_NAMES:
        inside = bands.mask(f, band)
        values = np.where(np.isfinite(worst) & inside, worst, -np.inf)
        best = np.argmax(values, axis=-1) if f.size else np.zeros(values.shape[:2], int)
        top = np.take_along_axis(values, best[..., None], axis=-1)[..., 0] if f.size else np.full(best.shape, -np.inf)
        found = np.isfinite(top)
        peaks.append(np.where(found, top, np.nan))
        where.append(np.where(found, f[best] if f.size else np.nan, np.nan))
        companion.append(found & (np.take_along_axis(from_companion, best[..., None], axis=-1)[..., 0] if f.size else False))
        points.append(np.full(found.shape, int(inside.sum())))
        unknown.append(np.sum(inside & ~realised, axis=-1))
    dims = ("band", "restitution", "clearance")
    grid = _part(dataset, solution)
    coords = {"band": list(BAND_NAMES), "restitution": grid["restitution"], "clearance": grid["clearance"]}
    return xr.Dataset(
        {
            "peak_x1_amplitude": (dims, np.array(peaks), {"units": "m"}),
            "peak_frequency": (dims, np.array(where), {"units": "Hz"}),
            "peak_from_companion": (dims, np.array(companion, dtype=bool)),
            "band_points": (dims, np.array(points)),
            "unknown_points": (dims, np.array(unknown)),
        },
        coords=coords,
    )


@dataclass(frozen=True)
class NoStopPeak:
    """Largest |X1| of the absorber without a stop in one band.

    Attributes
    ----------
    value : float
        |X1| [m].
    frequency : float
        Where [Hz].
    source : str
        ``analytic`` (the linear response sampled densely from the dataset's system) or ``grid`` (the ``linear``
        solution on the dataset's grid).
    """

    value: float
    frequency: float
    source: str


def no_stop_amplitude(dataset: xr.Dataset, frequency: np.ndarray, quantity: str = "x1") -> np.ndarray | None:
    """|X1| or |X2| (``quantity`` 'x1' or 'x2') [m] of the absorber without a stop at ``frequency`` [Hz], from the
    system and excitation the dataset stores (None if it does not)."""
    system = named_view(dataset)
    if system is None or "excitation_amplitude_N" not in dataset.attrs:
        return None
    response = paper_linear_response(system, omega=2.0 * np.pi * np.asarray(frequency, dtype=float), amplitude=float(dataset.attrs["excitation_amplitude_N"]))
    return np.abs(getattr(response, quantity))


def _dense_linear(dataset: xr.Dataset, bands: FrequencyBands, band: str, quantity: str) -> tuple[np.ndarray, np.ndarray] | None:
    """(frequency [Hz], |quantity| [m]) of the no-stop response sampled densely over ``band`` within the grid."""
    f = dataset["frequency"].values
    low, high = bands.limits(band)
    dense = np.linspace(max(low, float(f.min())), min(high, float(f.max())), _DENSE_POINTS)
    values = no_stop_amplitude(dataset, dense, quantity)
    return None if values is None else (dense, values)


def _refined_peak(dataset: xr.Dataset, frequency: np.ndarray, values: np.ndarray) -> NoStopPeak:
    """The largest of the sampled no-stop |X1| ``values``, refined by a bounded search between its neighbours."""
    k = int(np.argmax(values))
    low, high = frequency[max(k - 1, 0)], frequency[min(k + 1, frequency.size - 1)]

    def negative(f: float) -> float:
        amplitude = no_stop_amplitude(dataset, np.array([f]), "x1")
        return -float(amplitude[0]) if amplitude is not None else 0.0

    best = minimize_scalar(negative, bounds=(low, high), method="bounded", options={"xatol": 1e-9 * high})
    if -best.fun < values[k]:
        return NoStopPeak(float(values[k]), float(frequency[k]), "analytic")
    return NoStopPeak(float(-best.fun), float(best.x), "analytic")


def no_stop_peaks(dataset: xr.Dataset, bands: FrequencyBands, solution: str) -> dict[str, NoStopPeak]:
    """The no-stop peak of |X1| in each band, the yardstick of a design's peaks.

    Resonance bands: analytic where the dataset stores its system (the resonances are about 0.1 Hz wide, narrower
    than most grids), else the ``linear`` solution's largest value on the grid. Working band: the ``linear``
    solution on ``solution``'s own grid, so that a design whose working band is free of impacts (its motion there
    is the linear one) compares equal.
    """
    part = _part(dataset, "linear")
    f = part["frequency"].values
    linear = part["x1_amplitude"].isel(restitution=0, clearance=0).values
    on_grid = solution_frequencies(dataset, solution)
    peaks = {}
    for band in BAND_NAMES:
        dense = _dense_linear(dataset, bands, band, "x1") if band != "working" else None
        if dense is not None:
            peaks[band] = _refined_peak(dataset, *dense)
            continue
        values = np.where(bands.mask(f, band) & np.isfinite(linear) & (on_grid if band == "working" else True), linear, -np.inf)
        k = int(np.argmax(values))
        found = bool(np.isfinite(values[k]))
        peaks[band] = NoStopPeak(float(values[k]) if found else math.nan, float(f[k]) if found else math.nan, "grid")
    return peaks


def working_band_clearance(dataset: xr.Dataset, bands: FrequencyBands) -> float:
    """The largest no-stop |X2| in the working band [m]: a larger clearance keeps the linear motion off the stop
    there (so whether the working band is free of impacts depends on Delta alone, unless an impacting orbit coexists
    with the linear one, which depends on R)."""
    dense = _dense_linear(dataset, bands, "working", "x2")
    if dense is not None:
        return float(np.max(dense[1]))
    f = dataset["frequency"].values
    x2 = _part(dataset, "linear")["x2_amplitude"].isel(restitution=0, clearance=0).values
    inside = bands.mask(f, "working") & np.isfinite(x2)
    return float(np.max(x2[inside])) if np.any(inside) else math.nan


def regime_map(dataset: xr.Dataset, solution: str, bands: FrequencyBands) -> xr.Dataset:
    """Per design (restitution, clearance): ``worst_regime`` (:class:`DesignRegime`), ``impact_fraction`` (of the
    frequencies whose impacts are known), ``unknown_impact_points``, ``count_<class>`` for every class, and
    ``working_impact_free`` (every point of the working band known to be free of impacts)."""
    classes = design_regimes(dataset, solution)
    impacts = point_impacts(dataset, solution).values
    known = np.isfinite(impacts)
    working = bands.mask(classes["frequency"].values, "working")
    dims = ("restitution", "clearance")
    out = {
        "worst_regime": (dims, classes.max("frequency").values.astype(np.int8) if classes.sizes["frequency"] else np.full(classes.shape[:2], int(DesignRegime.NOT_COMPUTED), np.int8)),
        "impact_fraction": (dims, np.where(known.sum(-1) > 0, np.nansum(impacts, axis=-1) / np.maximum(known.sum(-1), 1), np.nan)),
        "unknown_impact_points": (dims, np.sum(~known, axis=-1)),
        "working_impact_free": (dims, np.any(working) & np.all(~working | (impacts == 0.0), axis=-1)),
    }
    for design in DesignRegime:
        out[f"count_{design.name.lower()}"] = (dims, np.sum(classes.values == design, axis=-1))
    return xr.Dataset(out, coords={"restitution": classes["restitution"], "clearance": classes["clearance"]})


def restitution_dependent_clearances(regimes: xr.Dataset) -> np.ndarray:
    """The clearances [m] at which some restitution ratios keep the working band free of impacts and others do not.

    Physically the linear motion's reach of the stop depends on Delta alone; R matters only where an impacting orbit
    coexists with the fitting linear one (hysteresis), which a closed form reports and a simulation started on it
    finds.
    """
    free = regimes["working_impact_free"].values
    mixed = np.any(free, axis=0) & ~np.all(free, axis=0)
    return np.asarray(regimes["clearance"].values[mixed], dtype=float)
