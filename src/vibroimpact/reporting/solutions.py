"""What every solution is, one row each: how pages present it and what datasets record of how it is computed.

A solution's words come from two places only: its row of :data:`SOLUTION_LOOKS` (colour, title, the captions' words on
the paper's layout and on a general one, the dataset's ``method_<name>`` attribute) and, for an engine whose row has
no method of its own, the engine registry's one-line description (:mod:`vibroimpact.engines.registry`).

No plotting library here: the studies write the methods into their datasets without loading matplotlib;
:mod:`vibroimpact.reporting.style` re-exports the table and its views for the pages.
"""

from __future__ import annotations

from dataclasses import dataclass

from vibroimpact.engines.registry import engine_spec

__all__ = ["SolutionLook", "SOLUTION_LOOKS", "ENGINE_MARKERS", "SOLUTION_COLOURS", "SOLUTION_TITLES", "SOLUTION_DESCRIPTIONS", "GENERAL_SOLUTION_DESCRIPTIONS", "solution_method", "FORCE_METHOD", "closed_form_methods"]


@dataclass(frozen=True)
class SolutionLook:
    """How every page presents one solution, and what a dataset records of its method.

    Attributes
    ----------
    colour : str
        Its colour where a figure distinguishes solutions (not restitution ratios).
    title : str
        Its short name for panel titles (half a figure wide).
    description : str
        What it is, for captions.
    marker : (str, float) or None
        Time-domain solutions: the marker (a fillable shape: filled means periodic) and its size [pt].
    general : str
        What it is on a general layout (any structure, several stops), where the captions say it otherwise; empty:
        :attr:`description`.
    method : str
        How it is computed, as a dataset's ``method_<name>`` attribute records it; empty for an engine: the registry's
        description (:func:`solution_method`).
    """

    colour: str
    title: str
    description: str
    marker: tuple[str, float] | None = None
    general: str = ""
    method: str = ""


#: Every solution's presentation, one row each: a new engine offered as a stepped solution adds its row here. The
#: simulations' markers: exact's larger diamonds show under momentary's circles where both agree.
SOLUTION_LOOKS: dict[str, SolutionLook] = {
    "linear": SolutionLook("k", "linear system", "linear system, no stop"),
    "pgf": SolutionLook(
        "C0", "closed form, exact modes", "one-impact closed form, exact poles/residues and exact chi22'(0-)",
        general="closed-form impact orbit (periodic Green function of the stopped coordinate: one impact per period on one stop, two on a symmetric two-sided stop)",
        method="closed-form impact orbit (periodic Green function of the stopped coordinate n^T H n; one impact per period on one stop, two on a symmetric two-sided stop); stable (+) root",
    ),
    "pgf_paper": SolutionLook(
        "C4", "closed form, paper's fitted modes", "one-impact closed form, the paper's fitted modes and constant chi22'(0-)",
        method="the paper's route: curve-fitted modal parameters of H22 (eq. 10, Omega fixed from eq. 11); chi22'(0-) = -1/(2 M2); stable (+) root of corrected eq. 16",
    ),
    "momentary": SolutionLook(
        "C1", "CVODE, rigid stop", "CVODE simulation, rigid stop", ("o", 3.5), general="CVODE simulation, rigid stops",
        method="scikit-sundae CVODE with contact/release events and an apex event guarding grazing contacts",
    ),
    "exact": SolutionLook(
        "C2", "exact engine, rigid stop", "piecewise-exact simulation, rigid stop", ("D", 5.0), general="piecewise-exact simulation, rigid stops",
        method="piecewise-exact propagation (eigenvectors + harmonic particular solution), contacts by guaranteed Taylor-bound root bracketing",
    ),
    "compliant": SolutionLook(
        "C3", "IDA, compliant bumper", "IDA simulation, Kelvin-Voigt bumper (eq. 25)", ("s", 4.0), general="IDA simulation, Kelvin-Voigt bumpers",
        method="Kelvin-Voigt bumper (eq. 25) through scikit-sundae IDA: one solver per contact mode, onset/release events, recorded force and deceleration peaks; atol of the displacements [m], other states scaled",
    ),
    "compliant_exact": SolutionLook(
        "C6", "closed form, compliant bumper", "closed-form Kelvin-Voigt bumper (eq. 25), exact per contact mode", ("^", 5.0),
        general="closed-form Kelvin-Voigt bumpers, exact per contact mode",
    ),
}  # fmt: skip
#: Views of :data:`SOLUTION_LOOKS`: simulation markers and sizes, colours, panel titles, caption descriptions (on the
#: paper's layout, and on a general one).
ENGINE_MARKERS: dict[str, tuple[str, float]] = {name: look.marker for name, look in SOLUTION_LOOKS.items() if look.marker is not None}
SOLUTION_COLOURS: dict[str, str] = {name: look.colour for name, look in SOLUTION_LOOKS.items()}
SOLUTION_TITLES: dict[str, str] = {name: look.title for name, look in SOLUTION_LOOKS.items()}
SOLUTION_DESCRIPTIONS: dict[str, str] = {name: look.description for name, look in SOLUTION_LOOKS.items()}
GENERAL_SOLUTION_DESCRIPTIONS: dict[str, str] = {name: look.general or look.description for name, look in SOLUTION_LOOKS.items()}


def solution_method(name: str) -> str:
    """What a dataset records of how solution ``name`` is computed (its ``method_<name>`` attribute): its look's
    ``method``, else the engine registry's description; ``ValueError`` for a name that is neither."""
    look = SOLUTION_LOOKS.get(name)
    if look is not None and look.method:
        return look.method
    return engine_spec(name).description


#: How the force on the base is computed (not a solution: every solution's force is this one formula).
FORCE_METHOD = "force on the base: 1^T (K x + C x') through springs and dashpots plus (1^T n_k) lambda_k of each absolute stop"


def closed_form_methods() -> dict[str, str]:
    """The ``method_pgf`` and ``method_force`` attributes recorded beside every layout a grid study writes (and a
    benchmark of a layout other than the paper's)."""
    return {"method_pgf": solution_method("pgf"), "method_force": FORCE_METHOD}
