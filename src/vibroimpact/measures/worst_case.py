"""One entry point for a band's worst case: :func:`worst_case` (problem, band, measure, method), as
:func:`scipy.integrate.solve_ivp` dispatches on ``method``, returning one :class:`BandMaximum` whatever found it.

The methods (:data:`METHODS`), each the largest stable value of the measure over the band by its own means:

* ``closed_form``: the contact-free and period-1 impact orbits in closed form, scanned and refined
  (:func:`~vibroimpact.analysis.band_worst.closed_form_worst`; rigid stops, one or a symmetric pair);
* ``bumper_orbits``: the same motions for Kelvin-Voigt bumpers, each orbit shot from its rigid twin's
  (:func:`~vibroimpact.orbits.bumper_screen.bumper_worst`);
* ``continuation``: every branch continued from the closed-form orbits, maxima located on the branches
  (:func:`~vibroimpact.orbits.worst_case.worst_response`);
* ``brute_force``: stepped sweeps both ways and more starts per frequency, every attractor the flow settles on
  (:func:`~vibroimpact.simulation.band_attractors.band_attractors`);
* ``certified``: continuation and brute force, the brute force's periodic orbit continued where it is larger
  (:func:`~vibroimpact.simulation.certified_worst.certified_worst`).

``options`` go to the method (``scan``, ``frequencies``, ``starts`` ...); what each cannot see is said in its module.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from vibroimpact.analysis.band_worst import closed_form_worst
from vibroimpact.analysis.measures import Measure, measure as measure_row
from vibroimpact.model.keywords import checked_options, suggest_keywords
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.orbits.bumper_screen import bumper_worst
from vibroimpact.orbits.worst_case import worst_response
from vibroimpact.simulation.band_attractors import band_attractors
from vibroimpact.simulation.certified_worst import certified_worst

__all__ = ["BandMaximum", "METHODS", "worst_case"]


@suggest_keywords
@dataclass(frozen=True, eq=False)
class BandMaximum:
    """The largest stable value of a measure over a band, and what found it.

    Attributes
    ----------
    value : float
        The maximum [the measure's unit]; 0 where the method found no stable motion.
    frequency : float
        Where [Hz] (NaN where none).
    motion : str
        Which motion sets it, in the method's words.
    measure : Measure
        What was judged.
    method : str
        A key of :data:`METHODS`.
    found : object
        The method's own result (its scans, branches or runs): ``BandWorst``, ``WorstCase``, ``AttractorSweep`` or
        ``CertifiedWorst``.
    """

    value: float
    frequency: float
    motion: str
    measure: Measure
    method: str
    found: Any


def _closed_form(problem: ImpactProblem, band: tuple[float, float], row: Measure, **options: Any) -> BandMaximum:
    found = closed_form_worst(problem, band, row, **options)
    return BandMaximum(found.amplitude, found.frequency, found.motion, row, "closed_form", found)


def _bumper_orbits(problem: ImpactProblem, band: tuple[float, float], row: Measure, **options: Any) -> BandMaximum:
    found = bumper_worst(problem, band, row, **options)
    return BandMaximum(found.amplitude, found.frequency, found.motion, row, "bumper_orbits", found)


def _continuation(problem: ImpactProblem, band: tuple[float, float], row: Measure, **options: Any) -> BandMaximum:
    found = worst_response(problem, band, row, **options)
    return BandMaximum(found.amplitude, found.frequency, found.motion, row, "continuation", found)


def _brute_force(problem: ImpactProblem, band: tuple[float, float], row: Measure, **options: Any) -> BandMaximum:
    found = band_attractors(problem, band, measure=row, **options)
    top = found.maximum
    return BandMaximum(top.amplitude, top.frequency, top.motion, row, "brute_force", found)


def _certified(problem: ImpactProblem, band: tuple[float, float], row: Measure, **options: Any) -> BandMaximum:
    found = certified_worst(problem, band, measure=row, **options)
    return BandMaximum(found.amplitude, found.frequency, found.motion, row, "certified", found)


#: Method name -> how it finds a band maximum of a measure (module docstring).
METHODS: dict[str, Callable[..., BandMaximum]] = {
    "closed_form": _closed_form,
    "bumper_orbits": _bumper_orbits,
    "continuation": _continuation,
    "brute_force": _brute_force,
    "certified": _certified,
}

#: Method name -> the function its ``**options`` go to (each checked against its keywords before any work).
OPTION_TAKERS: dict[str, Callable[..., Any]] = {
    "closed_form": closed_form_worst,
    "bumper_orbits": bumper_worst,
    "continuation": worst_response,
    "brute_force": band_attractors,
    "certified": certified_worst,
}


@suggest_keywords
def worst_case(problem: ImpactProblem, band: tuple[float, float], measure: str | Measure = "x1_amplitude", method: str = "certified", **options: Any) -> BandMaximum:
    """The largest stable value of ``measure`` of ``problem`` over ``band`` [Hz], found by ``method``.

    Parameters
    ----------
    problem : ImpactProblem
        Structure, stops and harmonic load (its frequency is replaced along the band).
    band : (float, float)
        (low, high) [Hz].
    measure : str or Measure
        A row of the measure table (:func:`vibroimpact.analysis.measures.measure`), by name on the problem's coordinates.
    method : str
        A key of :data:`METHODS` (module docstring).
    **options
        Passed to the method.

    Raises
    ------
    ValueError
        An unknown method or measure (naming the allowed ones), or what the method refuses (a layout without closed
        forms for ``closed_form``, rigid stops for ``bumper_orbits`` ...).
    TypeError
        An option the method does not take (naming the ones it takes and the closest).
    """
    if method not in METHODS:
        raise ValueError(f"method = {method!r}: allowed {', '.join(METHODS)}")
    checked_options(f"worst_case(method={method!r})", options, OPTION_TAKERS[method])
    row = measure if isinstance(measure, Measure) else measure_row(measure, problem.structure.coordinates)
    reason = row.refusal(problem)
    if reason is not None:
        raise ValueError(reason)
    return METHODS[method](problem, band, row, **options)
