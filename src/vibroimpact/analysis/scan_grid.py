"""The frequencies a band screen scans: an evenly spaced grid, made fine wherever the structure can resonate.

A screen (:func:`~vibroimpact.analysis.band_worst.closed_form_worst`, the bumper screen) takes the largest value on its
scan and refines each local maximum between the scan points either side. That finds a maximum wherever the scan has a
point on the stretch of the motion that holds it; a motion that exists and is stable only on a stretch narrower than
the scan's step (the paper's impact orbit: 20-27 Hz) is missed, and a band's worst case would depend on how finely
someone scanned it (the paper's design: 2.75 mm over 15-45 Hz, 1.83 mm over 15-4500 Hz with the same 241 points).

So the scan is the union of the evenly spaced grid and geometric grids of relative step :data:`RESONANCE_SPACING`
over where the structure can resonate, located from the structure, not from the scan:

* the undamped natural frequencies of the free structure (the contact-free motion's resonances);
* those of the structure with each stop's coordinate locked (n . x = 0; an infinitely stiff contact): an impact
  orbit's resonance stiffens from the free modes toward these;
* the contact region: where the contact-free steady state does not fit inside the clearances (linear closed form on
  a geometric grid of the same relative step over the band), between its onsets, the impacting motions live;
* for a Kelvin-Voigt bumper, the structure with the bumper's spring engaged (K + k_b n n^T): a cluster around each.

The span from the lowest to the highest of the first three (widened by :data:`RESONANCE_MARGIN`), and the cluster
around each engaged mode, get points where the evenly spaced grid is coarser than :data:`RESONANCE_SPACING` of the
frequency, and only there: a band scanned finely enough already (the shipped 241 points over 15-45 Hz: 0.125 Hz,
0.83 % of 15 Hz) is scanned as before.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg
from numpy.typing import NDArray

from vibroimpact.analysis.linear import linear_amplitudes
from vibroimpact.model.contact import KelvinVoigtBumper
from vibroimpact.model.problem import ImpactProblem

__all__ = ["RESONANCE_SPACING", "RESONANCE_MARGIN", "MOST_ADDED", "scan_frequencies", "resonances", "contact_region", "scan_widths"]

#: Largest step of the scan, relative to the frequency [-], where the structure can resonate. A screen refines a
#: maximum between its scan neighbours, so a peak need not be resolved, only each stretch where a motion exists and is
#: stable must hold a few points (the paper's impact orbit: 20-27 Hz, about 30 % of its frequency); 1 % leaves the
#: shipped scans (241 points over 15-45 Hz: 0.83 % at 15 Hz) as they were, and puts 1 % steps where a wider band's
#: evenly spaced grid steps over a resonance.
RESONANCE_SPACING = 0.01
#: The span of resonances is widened by this share on either side [-]: a damped peak, and the contact-free motion's
#: approach to a contact onset, reach a little beyond the frequencies that bound them.
RESONANCE_MARGIN = 0.1
#: At most this many points are added to a scan: beyond it the geometric grids' step grows so that they fit (a span of
#: resonances of 100:1 at 1 % needs 463).
MOST_ADDED = 480
#: At most this many frequencies of the linear closed form locate the contact region (its step grows beyond).
_MOST_ONSET_SAMPLES = 4000
#: A natural frequency below this share of the structure's highest is a rigid-body mode (a free mass, a coordinate
#: with no spring once another is locked) and resonates nowhere [-].
_RIGID = 1e-6


def _modes(mass: NDArray[np.float64], stiffness: NDArray[np.float64]) -> NDArray[np.float64]:
    """Undamped natural frequencies [Hz] of K v = w^2 M v, rigid-body modes (w^2 <= 0) dropped."""
    squared = scipy.linalg.eigh(stiffness, mass, eigvals_only=True)
    return np.sqrt(squared[squared > 0.0]) / (2.0 * np.pi)


def resonances(problem: ImpactProblem) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The frequencies [Hz] where ``problem``'s structure resonates with its stops open or locked (the free structure's
    natural frequencies and those with each stop's coordinate n . x held at 0), and those with each Kelvin-Voigt
    bumper's spring engaged (K + k_b n n^T); each sorted, rigid-body modes left out."""
    structure = problem.structure
    mass, stiffness = structure.mass_matrix, structure.stiffness_matrix
    locked = [_modes(mass, stiffness)]
    engaged = []
    for stop in problem.stops:
        n = stop.normal(problem.size)
        held = scipy.linalg.null_space(n[None, :])  # coordinates keeping n . x = 0, shape (N, N - 1)
        if held.shape[1]:
            locked.append(_modes(held.T @ mass @ held, held.T @ stiffness @ held))
        if isinstance(stop.law, KelvinVoigtBumper):
            spring = stop.law.stiffness(stop.effective_mass(mass))
            engaged.append(_modes(mass, stiffness + spring * np.outer(n, n)))
    both = [np.sort(np.concatenate(group)) if group else np.zeros(0) for group in (locked, engaged)]
    top = max((float(group.max()) for group in both if group.size), default=0.0)
    return both[0][both[0] > _RIGID * top], both[1][both[1] > _RIGID * top]


def contact_region(problem: ImpactProblem, band: tuple[float, float], spacing: float = RESONANCE_SPACING) -> tuple[float, float] | None:
    """The lowest and highest frequency [Hz] of ``band`` where the contact-free steady state does not fit inside the
    stops' clearances (the linear closed form, on a geometric grid of relative step ``spacing``, at most
    ``_MOST_ONSET_SAMPLES`` points; each end moved out to the grid point beyond, so that the onset lies inside), or
    None where it fits everywhere or the problem has no stop."""
    if not problem.stops:
        return None
    low, high = band
    count = min(_MOST_ONSET_SAMPLES, max(3, math.ceil(math.log(high / low) / math.log1p(spacing)) + 1))
    f = np.geomspace(low, high, count)
    touching = np.flatnonzero(~linear_amplitudes(problem, omega=2.0 * np.pi * f).fits(problem.clearances()))
    if touching.size == 0:
        return None
    return float(f[max(touching[0] - 1, 0)]), float(f[min(touching[-1] + 1, f.size - 1)])


def _spans(problem: ImpactProblem, band: tuple[float, float], spacing: float) -> list[tuple[float, float]]:
    """The stretches of ``band`` [Hz] the module docstring scans finely: the span of resonances and contact region,
    and a cluster around each engaged bumper mode, each widened by :data:`RESONANCE_MARGIN`."""
    open_or_locked, engaged = resonances(problem)
    region = contact_region(problem, band, spacing)
    bounds = [*open_or_locked, *(region or ())]
    stretches = [(min(bounds), max(bounds))] if bounds else []
    stretches += [(float(f), float(f)) for f in engaged]
    low, high = band
    widened = [(max(low, a * (1.0 - RESONANCE_MARGIN)), min(high, b * (1.0 + RESONANCE_MARGIN))) for a, b in stretches]
    return [(a, b) for a, b in widened if a < b]


def scan_frequencies(band: tuple[float, float], scan: int, problem: ImpactProblem | None = None, spacing: float = RESONANCE_SPACING, most: int = MOST_ADDED) -> NDArray[np.float64]:
    """The frequencies [Hz] a screen scans over ``band``: ``scan`` evenly spaced, its ends included, and with a
    ``problem`` the points that make the step at most ``spacing`` of the frequency where its structure can resonate
    (module docstring; at most ``most`` added, their step widened to fit), sorted, unique, inside the band.

    Raises
    ------
    ValueError
        Unless 0 < low < high and scan >= 3.
    """
    low, high = (float(b) for b in band)
    if not 0.0 < low < high or scan < 3:
        raise ValueError(f"band = {band!r} must be 0 < low < high [Hz] and scan = {scan} >= 3")
    even = np.linspace(low, high, scan)
    coarse_below = (high - low) / (scan - 1) / spacing  # the even grid's step is within ``spacing`` of f above this
    if problem is None or coarse_below <= low:  # fine enough everywhere: no modes nor onsets to look for
        return even
    spans = [(a, min(b, coarse_below)) for a, b in _spans(problem, (low, high), spacing) if a < coarse_below]
    logs = [math.log(b / a) for a, b in spans if b > a]
    if not logs:
        return even
    ratio = max(math.log1p(spacing), sum(logs) / max(most, 1))  # log of the geometric grids' step
    added = [np.geomspace(a, b, math.ceil(math.log(b / a) / ratio) + 1) for a, b in spans if b > a]
    f = np.unique(np.concatenate([even, *added]))
    distinct = np.concatenate([[True], np.diff(f) > 1e-12 * f[1:]])  # a point round-off away from another is one
    return np.clip(f[distinct], low, high)


def scan_widths(f: NDArray[np.float64]) -> NDArray[np.float64]:
    """The width [Hz] each scan frequency ``f`` (ascending, >= 2 points) stands for: half the steps to either
    neighbour, the ends a whole step (half of it beyond the band), so that an evenly spaced scan weights its points
    alike and a share of the widths is the share of the points it was before."""
    steps = np.diff(f)
    return np.concatenate([[steps[0]], steps[:-1] / 2.0 + steps[1:] / 2.0, [steps[-1]]])
