"""The contact orbit born where the contact-free orbit touches a compliant stop: the start of a bumper's contact
branch with no rigid stop involved.

A Kelvin-Voigt bumper's force grows from zero with the penetration, so the flow is continuous across the contact
surface and the contact orbit is born smoothly at grazing: at the contact-free orbit's onset f_g (where its least
clearance to a stop is zero, :func:`~vibroimpact.orbits.onsets.contact_free_onset`) the branch of periodic orbits
passes from the contact-free side to a side where the orbit spends a short time in contact, its penetration growing
from zero. Just beyond the onset that orbit is the contact-free one pressed a little into the bumper, so the
contact-free orbit there, known in closed form (:meth:`~vibroimpact.orbits.maps.ImpactMap.linear_orbit`), is a
guess inside Newton's region: :func:`contact_orbit_at_onset` shoots from it at frequencies ever farther beyond the
onset (:data:`OFFSETS`, relative), first on the side where the contact-free orbit would cross the stop, then on the
other (a branch that folds back right at grazing), until an orbit with a contact converges.

This start needs no closed form and no rigid twin: it holds for any structure, any number of bumpers and any bumper
stiffness. The branch continued from it through the onset and on (its folds, the other onset) is the bumper's
contact branch; the continuation of the rigid stop's orbit in the bumper's stiffness
(:mod:`vibroimpact.kinds.bifurcation.bumper_start`) remains one more start where a rigid orbit has no onset in the
band.
"""

from __future__ import annotations

import math

import numpy as np

from vibroimpact.orbits.branch import PeriodicOrbit
from vibroimpact.orbits.maps import ImpactMap
from vibroimpact.orbits.shooting import shoot

__all__ = ["OFFSETS", "contact_orbit_at_onset"]

#: Distances beyond the onset at which the contact orbit is shot, relative to the onset frequency [-]: the penetration
#: grows linearly with the distance, so the nearest is tried first (the guess is best there), then farther ones where
#: Newton does not converge (a penetration below round-off of the state: no contact yet).
OFFSETS = (1e-6, 1e-5, 1e-4, 1e-3, 1e-2)


def contact_orbit_at_onset(mapping: ImpactMap, onset: float, outside: float, offsets: tuple[float, ...] = OFFSETS) -> PeriodicOrbit | None:
    """The orbit with a contact next to the contact-free orbit's onset at ``onset`` [Hz] (module docstring).

    Parameters
    ----------
    mapping : ImpactMap
        The stroboscopic map of the problem (period 1); its frequency parameter is set here.
    onset : float
        Where the contact-free orbit touches a stop [Hz], > 0.
    outside : float
        +1 where the contact-free orbit crosses the stop above ``onset``, -1 below: that side is tried first.
    offsets : tuple of float
        Relative distances from ``onset`` tried, nearest first [-].

    Returns
    -------
    PeriodicOrbit or None
        A converged period-1 orbit with at least one contact; None where none converged at any offset on either side.
    """
    if not (math.isfinite(onset) and onset > 0.0) or outside not in (1.0, -1.0):
        raise ValueError(f"onset = {onset!r} Hz, outside = {outside!r}: expected a positive onset and outside = +1 or -1")
    index = list(mapping.parameter_names).index("frequency")
    for sign in (outside, -outside):
        for offset in offsets:
            p = np.array(mapping.parameters, dtype=float)
            p[index] = onset * (1.0 + sign * offset)
            linear = mapping.linear_orbit(p)
            if linear is None:
                continue
            try:
                orbit = shoot(mapping, linear[0], p)
            except (RuntimeError, ValueError):  # ShootingError among them: no orbit from this guess
                continue
            if orbit.impacts > 0:
                return orbit
    return None
