"""The largest stable response of a rigid-stop design over a band, in closed form: the design search's fast objective
(issue 32).

Two motions have closed forms on any layout with one stop or a symmetric two-sided pair: the contact-free steady
state (stable where it clears every stop, unless a free mass has no dashpot) and the period-1 impact orbit with one impact per
period (two for the pair; eqs. 15-18, both roots of the impulse equation, each where it exists, stays off the stops
between impacts and has every Floquet multiplier inside the unit circle). :func:`closed_form_worst` scans both on
``scan`` evenly spaced frequencies, with more where the structure can resonate (its free and locked modes, the
contact region: :func:`~vibroimpact.analysis.scan_grid.scan_frequencies`, so that the answer does not depend on the
band's width), takes the largest stable |X| of each motion (and every local maximum within 10 % of it) and
refines each by zoomed scans between the scan
points either side (each trial frequency solved in closed form and kept only where the motion is still stable and
admissible): the maximum's frequency to ``tolerance`` of the frequency, not to a scan step.

What a closed form cannot see: period-k orbits (k > 1), orbits with more impacts per period, and non-periodic
attractors. The band's share where neither motion is stable is returned as :attr:`BandWorst.uncovered`: there the
motion is one of those, and only continuation and brute force (:mod:`vibroimpact.orbits.worst_case`, the design
kind's certification) know its size; :attr:`BandWorst.estimate` guesses it from the unstable orbits there, so that a
search does not mistake a band it cannot see for a quiet one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.analysis.linear import contact_free_is_stable, linear_amplitudes
from vibroimpact.analysis.measures import Measure, as_measure
from vibroimpact.analysis.scan_grid import scan_frequencies, scan_widths
from vibroimpact.analysis.stability import MARGINAL_MODULUS, floquet_multipliers
from vibroimpact.model.problem import ImpactProblem

__all__ = ["BandWorst", "closed_form_worst", "closed_form_at", "contact_free_curve", "existing_impact_curve", "scan_frequencies", "uncovered_share", "MOTIONS", "SCAN", "refine_maximum"]

#: Frequencies of the scan whose maxima are refined.
SCAN = 241
#: Samples a period of the scan's admissibility check (a refined maximum is checked with the closed form's 512): the
#: same worst cases on 60 random designs of the paper's layout, a third cheaper.
SCAN_SAMPLES = 128
#: Local maxima of a scan within this share of its largest are refined too [-].
NEAR_TOP = 0.1
#: Frequencies of each zoomed scan of a maximum.
ZOOM = 17
#: The motions with a closed form, as :attr:`BandWorst.motion` names them (index: the CF flag value).
MOTIONS = ("none", "contact-free", "impacting, period 1")


@dataclass(frozen=True)
class BandWorst:
    """The largest stable value of a measure (|X| of one coordinate, or the force to the base) over a band (or at one
    frequency), over the closed-form motions; ``amplitude`` holds it, in the measure's unit.

    Attributes
    ----------
    amplitude : float
        |X| [m] (fundamental harmonic); 0 where no closed-form motion is stable anywhere.
    frequency : float
        Where [Hz] (NaN where none).
    motion : str
        One of :data:`MOTIONS`: which motion sets it.
    impacts : int
        Impacts per period of that motion (0 contact-free).
    uncovered : float
        Share of the band's width [-] where no closed-form motion is stable (there the motion is one the closed forms
        do not know): each scan frequency weighted by the width it stands for (:func:`uncovered_share`), since the
        scan is finer where the structure can resonate.
    estimate : float
        Where uncovered, a guess at the size of the motion there [m]: the largest |X| of the closed-form impact orbits
        that exist there, stable or not (a non-periodic attractor winds around its unstable orbits), else of the
        contact-free motion that does not fit; 0 where the band is covered.
    estimate_frequency : float
        Where the guess is largest [Hz] (NaN where covered).
    impulse : float
        The largest impulse of one impact [N s] among the stable, admissible closed-form impact orbits on the scan's
        frequencies (not refined between them); 0 where no impacting motion is stable (the impact force's measure
        for a rigid stop, whose force is a Dirac pulse).
    """

    amplitude: float
    frequency: float
    motion: str
    impacts: int
    uncovered: float
    estimate: float = 0.0
    estimate_frequency: float = math.nan
    impulse: float = 0.0

    def __post_init__(self) -> None:
        if self.motion not in MOTIONS:
            raise ValueError(f"motion = {self.motion!r} is not one of {MOTIONS}")
        if not 0.0 <= self.uncovered <= 1.0:
            raise ValueError(f"uncovered = {self.uncovered!r} must be a share in [0, 1]")


def contact_free_curve(problem: ImpactProblem, f: NDArray[np.float64], measure: int | Measure) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The ``measure`` (a coordinate index: its |X| [m]) of the contact-free steady state at frequencies ``f`` [Hz]
    where it clears every stop and is stable (NaN elsewhere), and everywhere (in closed form; any contact law: it
    never touches one)."""
    omega = 2.0 * np.pi * f
    linear = linear_amplitudes(problem, omega=omega)
    x = as_measure(measure, problem).of_harmonics(problem, omega, linear.amplitudes)
    return np.where(linear.fits(problem.clearances()) & contact_free_is_stable(problem.structure), x, np.nan), x


def _impacting(problem: ImpactProblem, f: NDArray[np.float64], measure: int | Measure, root: str, largest_only: bool = False) -> tuple[NDArray[np.float64], int, NDArray[np.float64], NDArray[np.float64]]:
    """|X| of the closed-form impact orbit (``root``) where it exists, is stable and admissible, NaN elsewhere; its
    impacts per period; |X| wherever it exists (any stability, admissible or not); and its impulse per impact [N s]
    where stable and admissible (NaN elsewhere). Stability first (cheap), admissibility (sampled over the period) only
    where stable; ``largest_only``: only until the largest admissible one is known (the others NaN)."""
    orbit = solve_impact_orbit(problem, frequency=f, root=root)
    measure = as_measure(measure, problem)
    x = np.full(f.shape, np.nan)
    impulse = np.full(f.shape, np.nan)
    exists = np.flatnonzero(np.asarray(orbit.exists, dtype=bool).reshape(-1))
    if exists.size == 0:
        return x, orbit.impacts_per_period, x.copy(), impulse
    existing = np.full(f.shape, np.nan)
    existing[exists] = measure.of_orbit(orbit.take(exists)).reshape(-1)
    modulus = np.max(np.abs(floquet_multipliers(orbit.take(exists))), axis=-1)
    stable = exists[modulus < 1.0 - MARGINAL_MODULUS]
    if stable.size == 0:
        return x, orbit.impacts_per_period, existing, impulse
    chosen = orbit.take(stable)
    amplitude = measure.of_orbit(chosen).reshape(-1)
    if largest_only:
        for k in np.argsort(amplitude)[::-1]:
            if bool(np.asarray(chosen.take([k]).admissible()).reshape(-1)[0]):
                x[stable[k]] = amplitude[k]
                break
        return x, orbit.impacts_per_period, existing, impulse
    ok = np.asarray(chosen.admissible(samples=SCAN_SAMPLES), dtype=bool).reshape(-1)
    x[stable[ok]] = amplitude[ok]
    impulse[stable[ok]] = np.asarray(chosen.impulse, dtype=float).reshape(-1)[ok]
    return x, orbit.impacts_per_period, existing, impulse


def existing_impact_curve(problem: ImpactProblem, f: NDArray[np.float64], measure: int | Measure, root: str) -> NDArray[np.float64]:
    """The ``measure`` (a coordinate index: its |X| [m]) of the closed-form impact orbit of ``root`` at frequencies ``f`` [Hz] wherever it exists (any
    stability, admissible or not; NaN elsewhere): what :attr:`BandWorst.estimate` guesses from."""
    orbit = solve_impact_orbit(problem, frequency=f, root=root)
    existing = np.full(f.shape, np.nan)
    exists = np.flatnonzero(np.asarray(orbit.exists, dtype=bool).reshape(-1))
    if exists.size:
        existing[exists] = as_measure(measure, problem).of_orbit(orbit.take(exists)).reshape(-1)
    return existing


#: The closed-form motions: the contact-free one, and the impact orbit of each root of the impulse equation.
_ROOTS = (None, "+", "-")


def _curve(problem: ImpactProblem, f: NDArray[np.float64], measure: int | Measure, root: str | None, largest_only: bool = False) -> tuple[str, int, NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """(motion, impacts, |X| where stable or NaN, |X| where it exists or NaN, impulse per impact [N s] where stable
    or NaN) of one closed-form motion (``root`` None: contact-free, which exists everywhere and has no impulse) at
    ``f`` [Hz] (``largest_only``: see :func:`_impacting`)."""
    if root is None:
        x, everywhere = contact_free_curve(problem, f, measure)
        return MOTIONS[1], 0, x, everywhere, np.where(np.isfinite(x), 0.0, np.nan)
    x, impacts, existing, impulse = _impacting(problem, f, measure, root, largest_only)
    return MOTIONS[2], impacts, x, existing, impulse


def _curves(problem: ImpactProblem, f: NDArray[np.float64], measure: int | Measure) -> list[tuple[str | None, tuple[str, int, NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]]]:
    """(root, :func:`_curve`) of every closed-form motion at frequencies ``f`` [Hz]."""
    return [(root, _curve(problem, f, measure, root)) for root in _ROOTS if root is None or problem.stops]


def closed_form_worst(problem: ImpactProblem, band: tuple[float, float], measure: int | Measure = 0, scan: int = SCAN, tolerance: float = 1e-8) -> BandWorst:
    """The largest stable ``measure`` over ``band`` [Hz] among the closed-form motions (module docstring).

    Parameters
    ----------
    problem : ImpactProblem
        Rigid stops: one, or a symmetric two-sided pair (else the closed form's ``ValueError``).
    band : (float, float)
        [Hz], low < high.
    measure : int or Measure
        A row of :mod:`vibroimpact.analysis.measures`, or a coordinate index for its |X| (0: the paper's primary mass x1).
    scan : int
        Evenly spaced frequencies of the scan (>= 3); more are added where they are coarser than
        :data:`~vibroimpact.analysis.scan_grid.RESONANCE_SPACING` of the frequency around the structure's resonances.
    tolerance : float
        Of the refined frequency, relative [-].
    """
    f = scan_frequencies(band, scan, problem)
    measure = as_measure(measure, problem)
    curves = _curves(problem, f, measure)
    covered = np.zeros(f.size, dtype=bool)
    best = (0.0, math.nan, MOTIONS[0], 0)
    impulse = 0.0
    for root, (motion, impacts, x, _, impulses) in curves:
        covered |= np.isfinite(x)
        if np.any(np.isfinite(impulses)):
            impulse = max(impulse, float(np.nanmax(impulses)))
        if not np.any(np.isfinite(x)):
            continue
        for i in _maxima(x):
            value, where = refine_maximum(problem, f, i, float(x[i]), measure, root, tolerance)
            if value > best[0]:
                best = (value, where, motion, impacts)
    estimate, estimate_frequency = 0.0, math.nan
    if not covered.all():
        impacting = [existing for root, (_, _, _, existing, _) in curves if root is not None]
        linear = curves[0][1][3]
        guess = np.fmax.reduce(impacting) if impacting else np.full(f.size, np.nan)
        guess = np.where(np.isfinite(guess), guess, linear)[~covered]
        k = int(np.argmax(guess))
        estimate, estimate_frequency = float(guess[k]), float(f[~covered][k])
    return BandWorst(best[0], best[1], best[2], best[3], uncovered_share(f, covered), estimate, estimate_frequency, impulse)


def uncovered_share(f: NDArray[np.float64], covered: NDArray[np.bool_]) -> float:
    """The share [-] of the band's width where no motion is ``covered`` on the scan ``f`` [Hz]: each point weighted by
    the width it stands for (:func:`~vibroimpact.analysis.scan_grid.scan_widths`; an evenly spaced scan: the share of
    its points)."""
    widths = scan_widths(f)
    return min(1.0, float(np.sum(widths[~covered]) / np.sum(widths)))


def _maxima(x: NDArray[np.float64]) -> list[int]:
    """Indices of the local maxima of ``x`` (NaN: no motion) within :data:`NEAR_TOP` of its largest, largest first:
    between scan points a lower sampled peak may be the higher one (two equal peaks, as on an optimum's ridge)."""
    y = np.nan_to_num(x, nan=-np.inf)
    top = float(np.max(y))
    found = [i for i in range(y.size) if np.isfinite(y[i]) and y[i] >= (1.0 - NEAR_TOP) * top and y[i] >= y[max(i - 1, 0)] and y[i] >= y[min(i + 1, y.size - 1)]]
    return sorted(found, key=lambda i: -y[i])


def refine_maximum(problem: ImpactProblem, f: NDArray[np.float64], i: int, value: float, measure: int | Measure, root: str | None, tolerance: float) -> tuple[float, float]:
    """The maximum of the motion ``root`` (:func:`_curve`) between the scan points either side of ``i``, where it
    stays stable and admissible, never below the scanned ``value``: zoomed scans of :data:`ZOOM` points, each over
    the two steps around the previous one's maximum, until a step is below ``tolerance`` of the frequency (one
    vectorised closed form per zoom, where a bounded search would solve one frequency at a time)."""
    best, where = value, float(f[i])
    a, b = float(f[max(i - 1, 0)]), float(f[min(i + 1, f.size - 1)])
    while (b - a) / (ZOOM - 1) > tolerance * b:
        x = np.linspace(a, b, ZOOM)
        y = _curve(problem, x, measure, root, largest_only=True)[2]
        if not np.any(np.isfinite(y)):
            break
        k = int(np.nanargmax(y))
        if y[k] > best:
            best, where = float(y[k]), float(x[k])
        a, b = float(x[max(k - 1, 0)]), float(x[min(k + 1, x.size - 1)])
    return best, where


def closed_form_at(problem: ImpactProblem, frequency: float, measure: int | Measure = 0) -> BandWorst:
    """The largest stable ``measure`` at one ``frequency`` [Hz] among the closed-form motions that coexist
    there (e.g. an absorber's operating point: the contact-free notch, or an impact orbit that destroys it)."""
    f = np.array([float(frequency)])
    best = (0.0, math.nan, MOTIONS[0], 0)
    covered = False
    for _, (motion, impacts, x, _, _) in _curves(problem, f, measure):
        if math.isfinite(x[0]):
            covered = True
            if x[0] > best[0]:
                best = (float(x[0]), float(frequency), motion, impacts)
    return BandWorst(best[0], best[1], best[2], best[3], 0.0 if covered else 1.0)
