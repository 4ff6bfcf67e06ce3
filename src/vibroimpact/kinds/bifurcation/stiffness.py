"""Special points of the compliant model followed in the bumper's stiffness: which bumper point continues which rigid
one, by continuation instead of by distance.

A :class:`StiffnessCase` finds the one-contact branches of the stiffest bumper of a study (``bifurcation.bumper``)
and continues each of their folds, period doublings and Neimark-Sacker points (period 1; not those a contact onset
induces, their ``induced_by``: the multipliers jump across the unit circle at the onset, which does not depend on
Omega_b, so such a point solves no smooth extended system and has no curve in the stiffness) in (frequency, T_b) on
:class:`~vibroimpact.orbits.bumper_map.BumperPeriodMap`, T_b = 1 / (Omega_b / 2 pi) [s] the bumper period, over
:data:`STIFFER` times the stiffest bumper's frequency down to the softest's divided by :data:`SOFTER`. A curve says
where its special point is at every bumper in between (and whether it still exists: a fold curve that turns back in
T_b ends a branch at a cusp), and its stiff end, extrapolated to T_b = 0 by Richardson's rule (the points converge at
first order in T_b), names the rigid stop's special point it continues.

Rows of the case's result (one per curve point): ``curve``, ``kind`` (index in
:data:`~vibroimpact.orbits.branch.SPECIAL_POINT_KINDS`), ``frequency`` [Hz], ``bumper_frequency`` [Hz] = 1 / T_b.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import asdict, dataclass

import numpy as np
from scipy.interpolate import CubicSpline

from vibroimpact.engines.registry import BUMPER, engine_for
from vibroimpact.kinds.bifurcation.branches import find_branches, map_bounds
from vibroimpact.kinds.bifurcation.logs import FAILURE_FIELDS, failure_arrays
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.orbits.branch import SPECIAL_POINT_KINDS, SpecialPoint
from vibroimpact.orbits.bumper_map import BUMPER_PERIOD, BumperPeriodMap
from vibroimpact.orbits.continuation import ContinuationSettings, continue_special_point
from vibroimpact.runs.runner import CaseResult, ProgressReport
from vibroimpact.runs.fingerprints import case_key

__all__ = ["StiffnessCase", "monotone_pieces", "curve_pieces", "on_piece", "FOLLOWED", "STIFFER", "SOFTER", "CURVE_SETTINGS", "STIFFNESS_FIELDS", "ON_CURVE"]

#: The kinds of special point followed in the bumper's stiffness (a grazing point, the contact onset at tangency,
#: does not depend on Omega_b).
FOLLOWED = ("fold", "period_doubling", "neimark_sacker")
#: The curves reach this many times the stiffest bumper's frequency (Richardson's extrapolation to the rigid stop
#: takes the curve at its stiffest T_b and twice it) ...
STIFFER = 16.0
#: ... and the softest bumper's frequency divided by this.
SOFTER = 1.25
#: Continuation of a curve: its test functions carry ~1e-10 of round-off with stiff bumpers (det(M - I) at 16-32 kHz
#: on the paper's system), above the default corrector tolerance of 1e-11.
CURVE_SETTINGS = ContinuationSettings(step=0.5, max_steps=400, tolerance=1e-9)
#: A special point within this of a curve's spline at its own T_b is on that curve [Hz] (the spline's error through a
#: curve's points: 2e-9 Hz measured for the fold at 26.7 Hz, 250 Hz - 16 kHz).
ON_CURVE = 1e-5
#: The arrays of a case's result.
STIFFNESS_FIELDS = ("curve", "kind", "frequency", "bumper_frequency", "notes", *FAILURE_FIELDS)


@dataclass(frozen=True, eq=False)
class StiffnessCase:
    """The curves of the special points of ``problem`` (bumpers of the stiffest frequency) in (frequency, T_b).

    Attributes
    ----------
    problem : ImpactProblem
        Stops that are Kelvin-Voigt bumpers (the study's stiffest), harmonic force.
    low, high : float
        The band [Hz] of the branches.
    bumper_range : tuple of float
        The lowest and highest bumper frequency Omega_b / 2 pi [Hz] the curves may reach.
    max_steps : int
        Most continuation steps per direction of a branch.
    max_step : float
        Largest arclength step of a branch [-].
    """

    problem: ImpactProblem
    low: float
    high: float
    bumper_range: tuple[float, float]
    max_steps: int = 2000
    max_step: float = 0.1
    engine: str = engine_for(BUMPER, "exact_jacobians")  # what computes it (the store names its result after it)
    fields: tuple[str, ...] = STIFFNESS_FIELDS
    progress_unit: str = "branch sets"

    @property
    def progress_total(self) -> float:
        """One unit."""
        return 1.0

    def key(self) -> str:
        """Hash of everything that determines the result."""
        return case_key({"kind": "bifurcation_stiffness", "problem": asdict(self.problem), "band": [self.low, self.high], "bumper_range": list(self.bumper_range),
                         "steps": [self.max_steps, self.max_step]})  # fmt: skip

    def run(self, report: ProgressReport | None = None) -> CaseResult:
        """The curves as flat arrays (one row per curve point), with notes and what failed."""
        # the stiffest bumper's branches, computed again: its branch case counts and says what failed of them
        found = find_branches(self.problem, self.low, self.high, period_doubling=False, grazing=False, linear=False, max_steps=self.max_steps, max_step=self.max_step)
        low_b, high_b = self.bumper_range
        periods = (1.0 / high_b, 1.0 / low_b)
        bounds = {BUMPER_PERIOD: periods, "frequency": map_bounds(self.low, self.high)["frequency"]}
        rows: list[tuple[int, int, float, float]] = []
        notes: list[str] = []
        attempts: dict[str, int] = {"stiffness_curve": 0}
        failures: list[tuple[str, str]] = []
        curve = 0
        for mapping, branch in found.maps:  # the closed-form branches only (no period doubling, grazing, seeds)
            if branch.orbits[0].period != 1:
                continue
            system = BumperPeriodMap(mapping.problem, bounds=bounds)
            for point in branch.special_points:
                kind = SPECIAL_POINT_KINDS.index(point.kind)
                if point.kind not in FOLLOWED or point.induced_by is not None or _on_a_curve(rows, kind, point.value, float(system.parameters[-1])):
                    continue  # not followed (or induced by a contact onset); or on a curve already followed (both roots' branches, a fold pair's cusp)
                attempts["stiffness_curve"] += 1
                try:
                    special = continue_special_point(system, _with_period(point, system), BUMPER_PERIOD, CURVE_SETTINGS, bounds=bounds)
                except Exception as error:  # noqa: BLE001 - a curve that cannot be followed is recorded, not fatal
                    failures.append(("stiffness_curve", f"{point.kind} at {point.value:.4f} Hz not followed in the bumper's stiffness: {type(error).__name__}: {str(error)[:160]}"))
                    notes.append(failures[-1][1])
                    continue
                f, fb = special.values("frequency"), 1.0 / special.values(BUMPER_PERIOD)
                notes.append(f"{point.kind} at {point.value:.4f} Hz followed in the bumper's stiffness: {f.size} points, {fb.min():.4g}-{fb.max():.4g} Hz, "
                             f"{f.min():.4f}-{f.max():.4f} Hz, ends: {special.end}")  # fmt: skip
                rows += [(curve, kind, fi, bi) for fi, bi in zip(f, fb)]
                curve += 1
        table = np.array(rows, dtype=float).reshape(-1, 4)
        return {"curve": table[:, 0].astype(int), "kind": table[:, 1].astype(int), "frequency": table[:, 2], "bumper_frequency": table[:, 3],
                "notes": np.array(notes, dtype=str), **failure_arrays(attempts, failures)}  # fmt: skip


def _with_period(point: SpecialPoint, system: BumperPeriodMap) -> SpecialPoint:
    """``point`` (found on the :class:`ImpactMap` of the same problem) with its orbit's parameters extended by the bumper
    period, :class:`BumperPeriodMap`'s last parameter."""
    orbit = point.orbit
    extended = dataclasses.replace(orbit, parameters=np.append(orbit.parameters, system.parameters[-1]), parameter_names=system.parameter_names)
    return dataclasses.replace(point, orbit=extended)


def monotone_pieces(periods: np.ndarray, frequencies: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """A curve's points (in their order along the curve) split where T_b turns back (the curve's own fold: two special
    points of the kind meet, e.g. a branch's two folds at a cusp), each piece by increasing T_b [s] with its
    frequencies [Hz]; pieces of fewer than 2 points are dropped."""
    turns = np.flatnonzero(np.diff(np.sign(np.diff(periods))) != 0) + 1
    out = []
    for start, stop in zip([0, *turns], [*turns, periods.size - 1]):
        t, f = periods[start : stop + 1], frequencies[start : stop + 1]
        order = np.argsort(t)
        t, f = t[order], f[order]
        keep = np.concatenate([[True], np.diff(t) > 0.0])
        if keep.sum() >= 2:
            out.append((t[keep], f[keep]))
    return out


def on_piece(piece: tuple[np.ndarray, np.ndarray], period: float) -> float:
    """The frequency [Hz] of a :func:`monotone_pieces` piece at ``period`` [s] (a cubic spline through its points,
    linear through 2-3), NaN outside it."""
    t, f = piece
    if not t[0] <= period <= t[-1]:
        return math.nan
    return float(CubicSpline(t, f)(period)) if t.size >= 4 else float(np.interp(period, t, f))


def curve_pieces(labels: np.ndarray, bumper_frequencies: np.ndarray, frequencies: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """The :func:`monotone_pieces` of every curve among points labelled by curve (``labels``; each curve's points in
    their order along it), from their bumper frequencies [Hz] and frequencies [Hz], by increasing label."""
    out = []
    for label in np.unique(labels):
        mine = labels == label
        out += monotone_pieces(1.0 / bumper_frequencies[mine], frequencies[mine])
    return out


def _on_a_curve(rows: list[tuple[int, int, float, float]], kind: int, frequency: float, period: float) -> bool:
    """Is a special point of ``kind`` at ``frequency`` [Hz] and bumper period ``period`` [s] on a curve of ``rows``?"""
    table = np.array([row for row in rows if row[1] == kind], dtype=float).reshape(-1, 4)
    return any(abs(on_piece(piece, period) - frequency) <= ON_CURVE for piece in curve_pieces(table[:, 0], table[:, 3], table[:, 2]))
