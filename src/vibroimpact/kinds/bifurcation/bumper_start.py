"""One start of a bumper's one-contact branch: the rigid stop's orbit continued to the scene's bumper through the
bumper period. (The other, needing no rigid stop, is the contact-free orbit's onset:
:mod:`vibroimpact.orbits.onset_start`.)

A Kelvin-Voigt bumper has no closed-form orbit of its own; its one-contact orbit at a frequency f0 is the rigid
stop's (the limit T_b -> 0 of the bumper period T_b = 1 / (Omega_b / 2 pi)) continued in T_b. :func:`bumper_start`
shoots the rigid orbit on a bumper :data:`STIFF_START` times stiffer than the scene's (the orbits converge at first
order in T_b: the rigid orbit is 1 / :data:`STIFF_START` as far from that bumper's as from the scene's), then follows
it in T_b on :class:`~vibroimpact.orbits.bumper_map.BumperPeriodMap` up to the scene's bumper, in stages of a
factor :data:`STAGE` in T_b, each measuring arclength in its own first T_b (steps in log T_b: a bumper 64 times
softer than the start is 3 stages); a stage that neither arrives nor meets a fold or an onset is taken again to the
scene's bumper with one 1 ms unit (next to the rigid limit, a 256 kHz bumper's T_b of 4 us as the unit stalled on the
paper's 18.27 Hz orbit). Shooting the rigid
orbit on the scene's bumper directly fails where the two are far apart (the shipped ``bifurcation_bumper``: 8 of its
20 starts, the line search or 40 Newton iterations stalling on a residual of 1e-3 to 5e-2).

Where the continuation turns back in T_b (a fold: the orbit merges with another one-contact orbit and both vanish
as the bumper softens) or loses its contact (an onset at tangency) before the scene's bumper, the bumper has no
such orbit at f0: that is an answer, not a failure (:attr:`BumperStart.orbit` is None and :attr:`BumperStart.why`
says where). On the shipped study the rigid branch over 18.25-18.71 Hz has one only for bumpers stiffer than about
840 Hz: at 18.27 Hz the orbit turns back at 3.46 kHz, at 18.70 Hz at 15.1 kHz.
"""

from __future__ import annotations

from dataclasses import dataclass

from vibroimpact.model.contact import KelvinVoigtBumper
from vibroimpact.orbits.branch import Branch, PeriodicOrbit, SpecialPoint
from vibroimpact.orbits.bumper_map import BUMPER_PERIOD, BumperPeriodMap
from vibroimpact.orbits.continuation import ContinuationSettings, continue_branch
from vibroimpact.orbits.maps import ImpactMap
from vibroimpact.orbits.shooting import ShootingError, shoot

__all__ = ["STIFF_START", "STIFFER", "STIFF_TRIES", "START_STEPS", "STAGE", "BumperStart", "bumper_start"]

#: The rigid orbit is first shot on a bumper this many times stiffer (in Omega_b) than the scene's [-].
STIFF_START = 64.0
#: Where the rigid orbit does not converge on that bumper, it is shot on one this many times stiffer again [-] ...
STIFFER = 8.0
#: ... at most this many bumpers in all [-].
STIFF_TRIES = 4
#: Most continuation steps in T_b per stage (measured: 5-50 on the shipped study).
START_STEPS = 300
#: T_b grows by at most this factor per stage, each stage measuring arclength in its first T_b: steps in log T_b, as
#: many per octave of the bumper's stiffness wherever they are (one scale for all of them took 300 steps to soften a
#: 100 Hz bumper to 10 Hz and stalled there on NLvib's chain, whose bumper is 1.59 Hz) [-].
STAGE = 4.0
#: The continuation reached the scene's bumper when its largest T_b is within this of it, relative [-] (its last
#: point lies on the bound).
REACHED = 1e-9


@dataclass(frozen=True)
class BumperStart:
    """The outcome of :func:`bumper_start`.

    Attributes
    ----------
    orbit : PeriodicOrbit or None
        The bumper's one-contact orbit on the scene's map; None where it has none at this frequency.
    why : str
        Where it has none: "turns back at Omega_b / 2 pi = 3460 Hz (a fold in the bumper's stiffness)", or "loses its
        contact at ..."; empty with an orbit.
    softest : float
        The softest bumper the continuation reached, Omega_b / 2 pi [Hz] (the scene's where it got there).
    """

    orbit: PeriodicOrbit | None
    why: str
    softest: float

    def __post_init__(self) -> None:
        if (self.orbit is None) == (not self.why):
            raise ValueError(f"orbit = {self.orbit!r}, why = {self.why!r}: a start has an orbit, or says why it has none")
        if not self.softest > 0.0:
            raise ValueError(f"softest = {self.softest!r} Hz is out of range: allowed (0, inf)")


def bumper_start(mapping: ImpactMap, rigid: PeriodicOrbit) -> BumperStart:
    """The bumper's orbit on ``mapping`` continued from the rigid stop's orbit ``rigid`` (module docstring).

    Parameters
    ----------
    mapping : ImpactMap
        The stroboscopic map of the scene's bumper at the start frequency (every stop one Kelvin-Voigt bumper of one
        Omega_b, the section of ``rigid``).
    rigid : PeriodicOrbit
        The rigid stop's orbit there (the same section), converged.

    Raises
    ------
    ShootingError
        The rigid orbit does not converge on the stiff bumper.
    RuntimeError
        The continuation in T_b ends (its steps, or too small a step) before the scene's bumper without a fold or an
        onset on the way.
    ValueError
        ``mapping``'s stops are not all Kelvin-Voigt bumpers.
    """
    laws = {stop.law for stop in mapping.problem.stops}
    if not all(isinstance(law, KelvinVoigtBumper) for law in laws):
        raise ValueError("mapping: every stop must be a Kelvin-Voigt bumper")
    target = 1.0 / next(iter(laws)).frequency  # type: ignore[union-attr]
    orbit, reached = _stiff_orbit(mapping, rigid, target)
    while reached < target * (1.0 - REACHED):  # one stage per factor STAGE in T_b: steps in log T_b
        upper = min(STAGE * reached, target)
        branch = _soften(mapping, orbit, reached, upper, reached)  # a unit of arclength: this stage's T_b
        turned = _turns(branch)
        if branch.values.max() < upper * (1.0 - REACHED) and not turned:  # neither there nor an answer: one scale to the end
            upper = target
            branch = _soften(mapping, orbit, reached, target, None)
            turned = _turns(branch)
        periods = branch.values
        if periods.max() >= upper * (1.0 - REACHED):
            orbit, reached = branch.orbits[int(periods.argmax())], upper
            continue
        softest = 1.0 / float(periods.max())
        if turned and turned[0].kind == "fold":
            why = f"followed in the bumper's stiffness it turns back at Omega_b / 2 pi = {1.0 / turned[0].value:.4g} Hz (a fold in T_b: it exists only with stiffer bumpers)"
        elif turned:
            why = f"followed in the bumper's stiffness it loses its contact at Omega_b / 2 pi = {1.0 / turned[0].value:.4g} Hz (an onset at tangency)"
        else:  # neither an answer nor the orbit: the continuation gave up
            raise RuntimeError(f"the continuation in the bumper's stiffness reached only Omega_b / 2 pi = {softest:.4g} Hz of {1.0 / target:g} Hz (it ended: {branch.end})")
        return BumperStart(None, why, softest)
    return BumperStart(shoot(mapping, orbit.state, mapping.parameters), "", 1.0 / target)


def _soften(mapping: ImpactMap, orbit: PeriodicOrbit, start: float, upper: float, unit: float | None) -> Branch:
    """``orbit`` (T_b = ``start`` [s]) continued in T_b up to ``upper`` [s], a unit of arclength in T_b of ``unit``
    [s] (None: :meth:`BumperPeriodMap.natural_scale`'s 1 ms)."""
    scale = None if unit is None else (*BumperPeriodMap.natural_scale(mapping.problem)[:-1], unit)
    system = BumperPeriodMap(mapping.problem, bounds={**mapping.bounds, BUMPER_PERIOD: (0.5 * start, upper)}, parameter_scale=scale)
    settings = ContinuationSettings(lower=0.5 * start, upper=upper, max_steps=START_STEPS, stop_at_grazing=True)
    return continue_branch(system, orbit, BUMPER_PERIOD, settings, direction=1)


def _turns(branch: Branch) -> list[SpecialPoint]:
    """The folds and onsets (grazing) on ``branch``: where the softening orbit turns back or loses its contact."""
    return [point for point in branch.special_points if point.kind in ("fold", "grazing")]


def _stiff_orbit(mapping: ImpactMap, rigid: PeriodicOrbit, target: float) -> tuple[PeriodicOrbit, float]:
    """The rigid orbit shot on a bumper :data:`STIFF_START` times stiffer than the scene's (in Omega_b), or, where
    Newton does not converge there, :data:`STIFFER` times stiffer again, up to :data:`STIFF_TRIES` times: the orbit and
    its T_b [s]. (Next to a fold in T_b the bumper's orbit moves fast as the bumper softens: on the paper's layout the
    rigid branch at 18.27 and 18.70 Hz, whose bumper orbits turn back near 840 Hz, did not converge on a 6.4 kHz bumper.)
    Raises the last ShootingError where none converged."""
    failure: ShootingError | None = None
    for k in range(STIFF_TRIES):
        stiff = target / (STIFF_START * STIFFER**k)
        system = BumperPeriodMap(mapping.problem, bounds={**mapping.bounds, BUMPER_PERIOD: (0.5 * stiff, target)})
        parameters = system.parameters.copy()
        parameters[-1] = stiff
        try:
            return shoot(system, rigid.state, parameters), stiff
        except ShootingError as error:
            failure = error
    assert failure is not None
    raise failure
