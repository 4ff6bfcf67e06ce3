"""Branches born at grazing points: where a continued branch meets a contact onset and an orbit with another,
non-zero impact count continues on the other side (a free flight that touches the stop gains an impact; an impact
whose speed vanishes is lost), that orbit is shot next to the grazing point and continued as a branch of its own.

:func:`grow_at_grazing` visits the grazing points of any list of branches, those continued from the closed form
(:func:`~vibroimpact.kinds.bifurcation.branches.find_branches`) and those seeded from the brute force
(:mod:`~vibroimpact.kinds.bifurcation.cases`) alike, and the born branches' own.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from vibroimpact.orbits.branch import Iterated, PeriodicOrbit, SpecialPoint
from vibroimpact.orbits.continuation import ContinuationSettings, continue_branch
from vibroimpact.orbits.maps import ImpactMap
from vibroimpact.orbits.orbit_measures import orbit_measures
from vibroimpact.orbits.shooting import shoot

if TYPE_CHECKING:  # annotations only: branches imports this module
    from vibroimpact.kinds.bifurcation.branches import OrbitSet

__all__ = ["MAX_GRAZING_BRANCHES", "grow_at_grazing"]

#: Most branches born at grazing points per call (per restitution; each may have its own grazing points).
MAX_GRAZING_BRANCHES = 8


def grow_at_grazing(found: "OrbitSet", maps: list, settings: ContinuationSettings, first: int = 0, say: Callable[[str], None] | None = None) -> None:
    """Start a branch at every grazing point of the branches ``maps[first:]`` (``(ImpactMap, Branch)`` pairs) where an
    orbit with another, non-zero impact count continues (shot next to it: :func:`_orbit_beyond`), unless a known
    branch passes through it; each born branch is appended to ``maps`` and its own grazing points are visited too,
    at most :data:`MAX_GRAZING_BRANCHES` in all. A failure is recorded in ``found`` (kind ``grazing``), never raised."""
    born, k = 0, first
    while k < len(maps):  # grows while it runs
        mapping, branch = maps[k]
        k += 1
        for point in branch.special("grazing"):
            if not point.continues or not point.impacts_after or point.impacts_after in set(branch.impacts.tolist()) or born >= MAX_GRAZING_BRANCHES:
                continue
            born += 1
            found.attempted("grazing")
            try:
                orbit = _orbit_beyond(mapping, point)
                if orbit is None:
                    found.notes.append(f"no orbit with {point.impacts_after} impacts found next to the grazing point at {point.value:.4f} Hz")
                    continue
                measures = orbit_measures(mapping, orbit)
                periods = orbit.period * int(getattr(mapping, "periods", 1))  # excitation periods (a seeded map's are several)
                if found.known(orbit.parameter("frequency"), periods, int(measures.impulses.size), float(measures.impulses.sum()) / periods):
                    continue
                child = continue_branch(Iterated(mapping, orbit.period) if orbit.period > 1 else mapping, orbit, "frequency", settings)
            except Exception as error:  # noqa: BLE001 - a failed branch is recorded, the others go on
                found.failed("grazing", f"branch born at {point.value:.4f} Hz failed: {type(error).__name__}: {str(error)[:200]}")
                continue
            label = found.add_branch(mapping, child, "grazing")
            maps.append((mapping, child))
            if say is not None:
                say(f"branch {label} born at the grazing point at {point.value:.3f} Hz: {len(child.orbits)} points")


def _orbit_beyond(mapping: ImpactMap, point: SpecialPoint) -> PeriodicOrbit | None:
    """The orbit with ``point.impacts_after`` impacts next to a grazing point: shooting from the grazing orbit on
    either side of it, ever farther."""
    orbit = point.orbit
    index = orbit.parameter_names.index("frequency")
    for offset in (1e-4, 1e-3, 1e-2, 5e-2):
        for sign in (1.0, -1.0):
            p = orbit.parameters.copy()
            p[index] = point.value + sign * offset
            try:
                found = shoot(mapping, orbit.state, p, orbit.period)
            except Exception:  # noqa: BLE001 - no orbit there: try the next guess
                continue
            if found.impacts == point.impacts_after:
                return found
    return None
