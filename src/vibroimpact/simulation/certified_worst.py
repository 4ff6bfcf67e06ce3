"""A design's worst case certified two ways: continuation and brute force, and the larger of the two located exactly.

:func:`certified_worst` runs :func:`~vibroimpact.orbits.worst_case.worst_response` (every branch continued from the
closed-form orbits, maxima to the continuation's tolerance) and
:func:`~vibroimpact.simulation.band_attractors.band_attractors` (sweeps both ways and several starts per frequency:
every attractor the flow settles on, non-periodic ones included). Where brute force finds a larger stable motion and
it is periodic (a multi-impact orbit no closed form starts, a period-doubled one), its orbit is shot from the sweep's
end state, continued over the band and its maximum located (:func:`~vibroimpact.orbits.worst_case.branch_maximum`):
the worst case to the continuation's tolerance again, not to the grid's. A non-periodic attractor keeps the largest
|X1| the brute force measured.

Each method's wall time is kept, with the grid a stepped sweep would need to reach the same maximum to a stated
accuracy (:func:`sweep_points_for`): the cost comparison the design page shows.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from vibroimpact.analysis.layout import closed_form_refusal
from vibroimpact.analysis.measures import Measure
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.orbits.branch import Branch
from vibroimpact.orbits.bumper_screen import bumper_screen_refusal
from vibroimpact.orbits.continuation import ContinuationSettings, continue_branch
from vibroimpact.orbits.maps import ImpactMap
from vibroimpact.orbits.shooting import ShootingError, shoot
from vibroimpact.orbits.worst_case import WorstCase, branch_maximum, worst_response
from vibroimpact.simulation.attractors import at_frequency
from vibroimpact.simulation.band_attractors import AttractorSweep, band_attractors

__all__ = ["CertifiedWorst", "certified_worst", "sweep_points_for", "SOURCES"]

#: Where a certified worst case comes from.
SOURCES = ("continuation", "brute force", "brute force, continued")


@dataclass(frozen=True, eq=False)
class CertifiedWorst:
    """The worst stable |X1| of a problem over a band, certified by continuation and brute force.

    Attributes
    ----------
    amplitude : float
        |X1| [m].
    frequency : float
        Where [Hz].
    motion : str
        Which motion sets it, and where on its branch.
    source : str
        One of :data:`SOURCES`.
    continuation : WorstCase
        The continuation's answer.
    attractors : AttractorSweep
        The brute force's.
    extra : tuple of Branch
        Branches continued from brute-force orbits (empty unless ``source`` says so).
    continuation_time, brute_force_time : float
        Wall times [s] (the brute force's including any continuation from its orbits).
    attractor_time : float
        Wall time of the brute-force runs alone [s] (every frequency, every run).
    """

    amplitude: float
    frequency: float
    motion: str
    source: str
    continuation: WorstCase
    attractors: AttractorSweep
    extra: tuple[Branch, ...]
    continuation_time: float
    brute_force_time: float
    attractor_time: float = math.nan

    @property
    def seconds_per_point(self) -> float:
        """The brute force's wall time per frequency and run [s]: what one more point of a stepped sweep costs."""
        return self.attractor_time / self.attractors.amplitude.size if self.attractors.amplitude.size else math.nan

    def __post_init__(self) -> None:
        if self.source not in SOURCES:
            raise ValueError(f"source = {self.source!r} is not one of {SOURCES}")


def certified_worst(problem: ImpactProblem, band: tuple[float, float], frequencies: int = 121, starts: int = 2, transient: int = 200, strobes: int = 64,
                    measure: int | Measure = 0) -> CertifiedWorst:  # fmt: skip
    """The worst stable ``measure`` (a coordinate index: its |X|; 0: x1) of ``problem`` over ``band`` [Hz] (module
    docstring): continuation, brute force and the brute force's orbit continued all judge that measure; ``frequencies``, ``starts``,
    ``transient`` and ``strobes`` are the brute force's (:func:`~vibroimpact.simulation.band_attractors.band_attractors`).

    Bumpers continue from their rigid twin's closed-form orbits. A problem the closed forms do not apply to (a free
    mass, stops that are not one or a symmetric pair) has no closed-form start to continue from: its worst case is the
    brute force's, continued where periodic.
    """
    low, high = (float(b) for b in band)
    start = time.perf_counter()
    # continuation starts from the closed forms (bumpers: their rigid twin's); a layout without them (a free mass ...)
    # is brute force's alone
    closed = closed_form_refusal(problem) is None or bumper_screen_refusal(problem) is None
    continued = worst_response(problem, (low, high), measure) if closed else WorstCase(0.0, math.nan, "", ())
    middle = time.perf_counter()
    sweep = band_attractors(problem, (low, high), frequencies=frequencies, starts=starts, transient=transient, strobes=strobes, measure=measure)
    swept = time.perf_counter()
    top = sweep.maximum
    best = (continued.amplitude, continued.frequency, continued.motion, SOURCES[0])
    extra: tuple[Branch, ...] = ()
    if math.isfinite(top.amplitude) and top.amplitude > continued.amplitude * (1.0 + 1e-6):
        best = (top.amplitude, top.frequency, f"{top.motion} (brute force, {top.run} run)", SOURCES[1])
        if top.period >= 1 and top.impacts > 0.0 and top.regime in ("one_impact", "other_periodic"):
            refined = _continued(problem, (low, high), top.frequency, np.array(top.state), top.period, measure)
            if refined is not None and refined[0] >= top.amplitude * (1.0 - 1e-3):  # the same orbit, located exactly
                best = (refined[0], refined[1], f"{top.motion} ({refined[2]} of its branch, continued from the brute force)", SOURCES[2])
                extra = (refined[3],)
    end = time.perf_counter()
    return CertifiedWorst(best[0], best[1], best[2], best[3], continued, sweep, extra, middle - start, end - middle, swept - middle)


def _continued(problem: ImpactProblem, band: tuple[float, float], frequency: float, state: np.ndarray, period: int, measure: int | Measure = 0) -> tuple[float, float, str, Branch] | None:
    """(``measure``, where [Hz], which place, branch) of the stable maximum of the branch through the
    period-``period`` orbit near ``state`` at ``frequency``; None where shooting or continuation fails."""
    system = ImpactMap(at_frequency(problem, frequency), periods=period)
    try:
        orbit = shoot(system, state, system.parameters)
        branch = continue_branch(system, orbit, "frequency", ContinuationSettings(lower=band[0], upper=band[1]))
    except (ShootingError, ValueError, RuntimeError):
        return None
    top = branch_maximum(system, branch, measure)
    return (top.amplitude, top.value, top.where, branch) if top is not None else None


def sweep_points_for(amplitude: np.ndarray, frequency: np.ndarray, accuracy: float, band: tuple[float, float]) -> float:
    """Frequencies a stepped sweep over ``band`` needs so that its largest sample is within ``accuracy`` (relative)
    of the maximum of the curve (``frequency`` [Hz], ``amplitude`` [m]) near its largest point: h = sqrt(8 accuracy
    X / |X''|), X'' the curve's second difference there; NaN where the curve has no interior maximum with three
    distinct points about it."""
    f, x = np.asarray(frequency, dtype=float), np.asarray(amplitude, dtype=float)
    ok = np.isfinite(f) & np.isfinite(x)
    f, x = f[ok], x[ok]
    order = np.argsort(f)
    f, x = f[order], x[order]
    if f.size < 3:
        return math.nan
    i = int(np.argmax(x))
    if i == 0 or i == f.size - 1 or not (f[i - 1] < f[i] < f[i + 1]):
        return math.nan
    h1, h2 = f[i] - f[i - 1], f[i + 1] - f[i]
    second = 2.0 * ((x[i + 1] - x[i]) / h2 - (x[i] - x[i - 1]) / h1) / (h1 + h2)
    if not second < 0.0:
        return math.nan
    step = math.sqrt(8.0 * accuracy * x[i] / abs(second))
    return (band[1] - band[0]) / step + 1.0
