"""Which solutions a general scene's layout admits, each refusal with its reason (checked before any work)."""

from __future__ import annotations

import numpy as np

from vibroimpact.analysis.layout import closed_form_refusal
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.structure import LinearStructure
from vibroimpact.model.system import TwoDofSystem
from vibroimpact.scene.checker import Checker
from vibroimpact.scene.layout import LoadSpec, StopSpec, build_stops

__all__ = ["check_general_solutions", "pgf_refusal", "paper_layout_applies", "static_drift"]


def pgf_refusal(system: TwoDofSystem | LinearStructure, specs: tuple[StopSpec, ...], load: LoadSpec | None, restitution: np.ndarray | None = None, clearance: np.ndarray | None = None) -> str | None:
    """Why the closed-form (PGF) solution does not apply to this layout at some grid point; None where it applies
    everywhere (:func:`vibroimpact.analysis.layout.closed_form_refusal`: one rigid stop, or a symmetric two-sided
    stop, on a structure without rigid-body modes, with a harmonic load)."""
    stops = specs or (StopSpec(coordinate=1),)
    r_grid = np.array([np.nan]) if restitution is None else restitution
    d_grid = np.array([np.nan]) if clearance is None else clearance
    corners = {(float(r), float(d)) for r in (r_grid[0], r_grid[-1]) for d in (d_grid[0], d_grid[-1])}
    force = (load or LoadSpec()).force(1.0, 1.0)
    for r, d in sorted(corners):
        try:
            problem = ImpactProblem(system, build_stops(stops, False, 0.5 if np.isnan(r) else r, 1e-3 if np.isnan(d) else d), force)
        except (ValueError, TypeError) as error:  # an unusable stop: reported where it is parsed
            return str(error)
        reason = closed_form_refusal(problem)
        if reason is not None:
            return reason
    return None


def paper_layout_applies(system: TwoDofSystem | LinearStructure, specs: tuple[StopSpec, ...], load: LoadSpec | None) -> bool:
    """Is the layout the paper's on its named system, however written (:attr:`vibroimpact.model.problem.ImpactProblem.named_system`):
    where its own route (``pgf_paper``) and its design map apply?"""
    try:
        problem = ImpactProblem(system, build_stops(specs or (StopSpec(coordinate=1),), False, 0.5, 1e-3), (load or LoadSpec()).force(1.0, 1.0))
    except (ValueError, TypeError):  # an unusable stop: reported where it is parsed
        return False
    return problem.named_system is not None


def static_drift(system: TwoDofSystem | LinearStructure, load: LoadSpec | None) -> bool:
    """Does the static force push the structure along a rigid-body mode (no static equilibrium without stops)?"""
    if load is None or load.static is None or not any(load.static) or not system.rigid_body_modes():
        return False
    stiffness = system.structure.stiffness_matrix
    values, vectors = np.linalg.eigh(stiffness)
    scale = float(np.max(np.abs(stiffness))) if np.any(stiffness) else 0.0
    free = vectors[:, values <= 1e-10 * scale] if scale > 0.0 else vectors
    static = np.asarray(load.static)
    return bool(np.max(np.abs(free.T @ static)) > 1e-12 * float(np.max(np.abs(static))))


def check_general_solutions(
    c: Checker, solutions: tuple[str, ...], system: TwoDofSystem | LinearStructure, specs: tuple[StopSpec, ...], load: LoadSpec | None, swept_sine: bool,
    restitution: np.ndarray | None = None, clearance: np.ndarray | None = None,
) -> None:  # fmt: skip
    """Record the solutions (and swept-sine tests: any layout, but a force, not a base motion) a general scene asks for
    that its layout does not admit, and stops that leave a coordinate no room (two opposite stops whose clearances sum to <= 0 at a corner of the grid)."""
    for d in sorted({float(clearance[0]), float(clearance[-1])} if clearance is not None and clearance.size else {float("nan")}):
        try:
            ImpactProblem(system, build_stops(specs or (StopSpec(coordinate=1),), False, 0.5, 1e-3 if np.isnan(d) else d), (load or LoadSpec()).force(1.0, 1.0))
        except ValueError as error:
            if "leave no room" in str(error):
                c.fail("stops", str(error).removeprefix("stops: ") + (f" (at clearance {d:g} m of the grid)" if not np.isnan(d) else ""))
                break
    if "pgf_paper" in solutions and not paper_layout_applies(system, specs, load):
        c.fail("solutions", "pgf_paper is the paper's own route for its layout (a two-mass chain x1, x2 as {m1 ... b2}; one upper stop on x2; force on x1): use pgf")
    if "pgf" in solutions and (reason := pgf_refusal(system, specs, load, restitution, clearance)) is not None:
        c.fail("solutions", f"pgf does not apply to this layout: {reason}")
    if "linear" in solutions and static_drift(system, load):
        c.fail("solutions", "linear does not apply: the static force pushes the structure along a rigid-body mode, so it has no steady state without its stops")
    if swept_sine and load is not None and load.base_motion:
        c.fail("excitation.base_motion", "a swept-sine test drives a force q sin(theta(t)) on the coordinates ('on'): a swept base motion is not supported; use base_motion: false")
