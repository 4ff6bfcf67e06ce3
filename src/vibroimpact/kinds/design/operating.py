"""What a design page says of the absorber's operating point before it recommends a stop: a measure of the recommended
design there with its stop against the same absorber without it, and whether the absorber's free motion there fits
in the recommended clearance (a warning first where the stop makes it worse, or it does not fit).

The measure (:mod:`vibroimpact.kinds.design.quantity`) is the operating constraint's where the frequency is declared
(|X1| by default: the primary's notch), else the objective's (the responses' measure); |X1| on the paper's scenes.

The operating point is the scene's declared operating frequency (``design.constraints.operating.frequency``), else the
recommended absorber's anti-resonance sqrt(k2/m2) / 2 pi. With the stop: the worst coexisting measure there over the
samples where the frequency is declared (the search's own value), else the worst stable motion of the recommended
design's responses at the nearest frequency of their grid (within 1 %). Without: the linear closed form of the same
absorber (its k2 and b2, the scene's or the design's), nominal. Read from the dataset and its stored scene (its
``system`` as m1 ... b2); a structure given as matrices has no named absorber and nothing is said.
"""

from __future__ import annotations

import html
import math
from dataclasses import dataclass

import numpy as np
import xarray as xr
import yaml

from vibroimpact.analysis.linear_optimum import linear_measure
from vibroimpact.kinds.design.answer import operating_motion
from vibroimpact.kinds.design.quantity import Quantity, constraint_quantity, objective_quantity, quantity
from vibroimpact.measures.figures_of_merit import NEAREST, WORSE_RATIO
from vibroimpact.model.problem import System
from vibroimpact.model.system import named_system
from vibroimpact.reporting.style import fmt

__all__ = ["DesignOperating", "design_operating", "operating_sentence", "operating_warnings", "WORSE_RATIO", "NEAREST"]



@dataclass(frozen=True)
class DesignOperating:
    """The recommended design at the absorber's operating point.

    Attributes
    ----------
    frequency : float
        The operating frequency [Hz].
    declared : bool
        The scene declared it (else: the recommended absorber's anti-resonance).
    stopped : float
        The measure with the stop there [m or N] (NaN: not computed there).
    linear : float
        The measure of the same absorber without the stop there [m or N].
    free : float
        |X2| of the same absorber without the stop there [m], its free motion.
    clearance : float
        The recommended clearance [m] (NaN: no stop).
    measure : Quantity
        What ``stopped`` and ``linear`` measure (default |X1|).
    motion : str
        The motion that sets ``stopped`` and who reached it ("": not known).
    """

    frequency: float
    declared: bool
    stopped: float
    linear: float
    free: float
    clearance: float
    measure: Quantity = quantity("x1_amplitude")
    motion: str = ""

    def __post_init__(self) -> None:
        if not self.frequency > 0.0:
            raise ValueError(f"the operating frequency must be positive [Hz], got {self.frequency!r}")

    @property
    def ratio(self) -> float:
        """With the stop / without [-] (NaN without a value)."""
        return self.stopped / self.linear if self.linear > 0.0 else math.nan


def _system(dataset: xr.Dataset) -> System | None:
    """The recommended design's two-mass system: the stored scene's m1 ... b2 with the design's k2 and b2 where they
    are design variables; None where the scene gives no named system."""
    try:
        document = yaml.safe_load(str(dataset.attrs.get("scene", "")))
    except yaml.YAMLError:
        return None
    system = document.get("system") if isinstance(document, dict) else None
    keys = ("m1", "m2", "k1", "k2", "b1", "b2")
    if not isinstance(system, dict) or not all(isinstance(system.get(k), (int, float)) for k in keys):
        return None
    values = {k: float(system[k]) for k in keys}
    for k in ("k2", "b2"):
        if f"design_{k}" in dataset and math.isfinite(float(dataset[f"design_{k}"].values[0])):
            values[k] = float(dataset[f"design_{k}"].values[0])
    return named_system(values) if values["k2"] > 0.0 else None


def _responses(dataset: xr.Dataset, frequency: float) -> float:
    """The recommended design's worst stable motion (the objective's measure) at the response grid's frequency
    nearest ``frequency`` [m or N] (NaN
    where none lies within :data:`NEAREST` of it, or no motion is stable there)."""
    f = np.asarray(dataset["response_frequency"].values, dtype=float) if "response_frequency" in dataset else np.zeros(0)
    if not f.size:
        return math.nan
    k = int(np.argmin(np.abs(f - frequency)))
    if not abs(f[k] - frequency) <= NEAREST * frequency:
        return math.nan
    linear = float(dataset["response_linear"].values[0, k]) if float(dataset["response_linear_fits"].values[0, k]) == 1.0 else math.nan  # exact: a 0/1 flag
    impacts = [float(dataset[name].values[0, k]) for name in ("response_impact_plus_stable", "response_impact_minus_stable") if name in dataset]
    values = [v for v in [linear, *impacts] if math.isfinite(v)]
    return max(values) if values else math.nan


def design_operating(dataset: xr.Dataset) -> DesignOperating | None:
    """The recommended design at the operating point (module doc); None without a recommendation or a named absorber."""
    d = dataset
    if int(d.attrs.get("recommended_evaluation", -1)) < 0:
        return None
    system = _system(d)
    if system is None:
        return None
    declared = math.isfinite(float(d.attrs.get("operating_frequency_Hz", math.nan)))
    frequency = float(d.attrs["operating_frequency_Hz"]) if declared else system.antiresonance_frequency()
    stopped = float(d["design_operating_amplitude"].values[0]) if declared else _responses(d, frequency)
    measure = constraint_quantity(d) if declared else objective_quantity(d)
    amplitude = float(d.attrs.get("excitation_amplitude_N", math.nan))
    omega = 2.0 * math.pi * frequency
    linear = float(linear_measure(system, amplitude, omega, measure.name))  # the same absorber without its stop
    free = float(abs(amplitude * system.receptances(np.array([omega])).h12[0]))  # its absorber's motion there [m]
    clearance = float(d["design_clearance"].values[0]) if "design_clearance" in d else math.nan
    return DesignOperating(frequency, declared, stopped, linear, free, clearance, measure, operating_motion(d, 0) if declared else "")


def _mm(value: float) -> str:
    """The absorber's free motion and its clearance (displacements, whatever the measures): ``2.32 mm``."""
    return f"{fmt(1e3 * value, '.4g')} mm" if math.isfinite(value) else "not known"


def _where(point: DesignOperating) -> str:
    return f"{fmt(point.frequency, '.5g')} Hz, {'the declared operating frequency' if point.declared else 'the recommended absorber' + chr(39) + 's anti-resonance sqrt(k2/m2) / 2 pi'}"


def operating_warnings(point: DesignOperating | None) -> list[str]:
    """The page's first lines where the recommended stop makes the measure at the operating point worse than the same
    absorber without it, or the absorber's free motion there does not fit in the recommended clearance."""
    if point is None:
        return []
    lines, q = [], point.measure
    if point.ratio > WORSE_RATIO:
        lines.append(f"The recommended stop makes the absorber worse at its operating point ({_where(point)}): {q.symbol} is {q.text(point.linear)} without the stop against "
                     f"{q.text(point.stopped)} with it, ×{fmt(point.ratio, '.3g')}.")  # fmt: skip
    if point.free > point.clearance:
        lines.append(f"The absorber's free motion at its operating point does not fit in the recommended gap: without the stop, at {fmt(point.frequency, '.5g')} Hz, "
                     f"|X2| = {_mm(point.free)} against a clearance of {_mm(point.clearance)}: the stop is struck at the frequency the absorber works at.")  # fmt: skip
    return lines


def operating_sentence(point: DesignOperating | None, idle: bool = False) -> str:
    """The measure of the recommended design at the operating point with its stop and without, in one HTML paragraph;
    ``idle``: its stop is never struck (the answer is to build it without), said so rather than "with its stop"."""
    if point is None:
        return ""
    q = point.measure
    if not math.isfinite(point.stopped):
        return (f"<p>At the absorber's operating point ({html.escape(_where(point))}) {q.symbol} of the same absorber without the stop is {q.text(point.linear)}; "
                "with the stop it was not computed there (the band's responses do not reach it).</p>")  # fmt: skip
    worst = (f" (the largest over every motion found there under every sample: {html.escape(point.motion)})" if point.motion else " (the largest over every motion found there under every sample)") if point.declared else " (its worst stable motion on the responses' grid)"
    if idle:
        return (f"<p>At the absorber's operating point ({html.escape(_where(point))}) the recommended absorber's {q.symbol} is {q.text(point.stopped)}{worst}; its stop is never "
                f"struck, and without it the same absorber has {q.text(point.linear)} there.</p>")  # fmt: skip
    return (f"<p>At the absorber's operating point ({html.escape(_where(point))}) the recommended design's {q.symbol} is {q.text(point.stopped)} with its stop{worst} against "
            f"{q.text(point.linear)} for the same absorber without the stop: ×{fmt(point.ratio, '.3g')}.</p>")  # fmt: skip
