"""Which solutions a general scene's layout admits, each refusal with its reason (checked before any work)."""

from __future__ import annotations

import numpy as np

from vibroimpact.model.structure import LinearStructure
from vibroimpact.model.system import TwoDofSystem
from vibroimpact.scene.checker import Checker
from vibroimpact.scene.layout import LoadSpec, StopSpec, paper_layout

__all__ = ["check_general_solutions", "pgf_refusal", "static_drift"]


def pgf_refusal(system: TwoDofSystem | LinearStructure, specs: tuple[StopSpec, ...], load: LoadSpec | None) -> str | None:
    """Why the closed-form (PGF) solution does not apply to this layout; None where it does.

    It applies to one rigid stop on a structure without rigid-body modes, harmonically loaded without a static force.
    """
    stops = specs or (StopSpec(coordinate=1),)
    if system.rigid_body_modes():
        return f"the structure has {system.rigid_body_modes()} rigid-body mode(s) (a free mass): its periodic Green function does not exist"
    if load is not None and load.static is not None and any(load.static):
        return "a static force (excitation.static) shifts the orbit: the closed form has none"
    if len(stops) != 1:
        return f"it solves one stop; the layout has {len(stops)}"
    if paper_layout(system, specs, load):
        return None
    return "its general form (any coordinate, relative stops, any load) is not available in this version: the paper's layout only (two masses in a chain, an upper stop on x2, the force on x1)"


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


def check_general_solutions(c: Checker, solutions: tuple[str, ...], system: TwoDofSystem | LinearStructure, specs: tuple[StopSpec, ...], load: LoadSpec | None, swept_sine: bool) -> None:
    """Record the solutions (and swept-sine tests) a general scene asks for that its layout does not admit."""
    if "pgf_paper" in solutions:
        c.fail("solutions", "pgf_paper is the paper's own route for its named layout (system {m1 ... b2}, stop, force on x1): use pgf")
    if "pgf" in solutions and (reason := pgf_refusal(system, specs, load)) is not None:
        c.fail("solutions", f"pgf does not apply to this layout: {reason}")
    if "linear" in solutions and static_drift(system, load):
        c.fail("solutions", "linear does not apply: the static force pushes the structure along a rigid-body mode, so it has no steady state without its stops")
    if swept_sine:
        c.fail("swept_sine", "swept-sine tests run the paper's named layout only (system {m1 ... b2}, stop, force on x1)")
