"""What a scene says: the frozen :class:`Scene` and its parts, and the vocabulary and limits of the scene format.

Nothing here reads YAML or checks a document (see :mod:`vibroimpact.scene.grid` and
:mod:`vibroimpact.kinds.benchmark.scene`); a :class:`Scene` is built only from checked values. Engine names come from
:mod:`vibroimpact.engines.registry`, which names every engine without importing one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Generic, Sequence, TypeVar


from vibroimpact.engines.registry import RIGID, engine_for, engine_names, engine_spec, stepped_solutions
from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.model.layout import Layout
from vibroimpact.model.parameters import PARAMETERS
from vibroimpact.scene.kinds import KIND_NAMES
from vibroimpact.scene.variables import MOTION_QUANTITIES, QUANTITIES, STOP_QUANTITIES, quantities_for
from vibroimpact.simulation.settings import START_MODES, SWEEP_STARTS

__all__ = [
    "Scene",
    "SOLUTIONS",
    "ENGINE_SOLUTIONS",
    "ENGINE_CONTACT",
    "contact_solutions",
    "BENCHMARK_REFERENCE",
    "BENCHMARK_METHODS",
    "QUANTITIES",
    "MOTION_QUANTITIES",
    "SWEEPABLE",
    "GRID_DIMS",
    "STOP_QUANTITIES",
    "quantities_for",
]

#: The type of a scene's kind settings.
SettingsT = TypeVar("SettingsT")

#: Solutions computed by time integration (they need the ``simulation`` section's settings): the registered engines
#: offered as stepped solutions.
ENGINE_SOLUTIONS = stepped_solutions()
#: Solutions a scene can ask for: the closed forms, then the engines.
SOLUTIONS = ("linear", "pgf", "pgf_paper", *ENGINE_SOLUTIONS)
#: The contact law of each engine solution (from the engine registry, which must name every one of them).
ENGINE_CONTACT = {name: engine_spec(name).contact for name in ENGINE_SOLUTIONS}


def contact_solutions(solutions: Sequence[str], contact: str) -> list[str]:
    """The time-domain solutions among ``solutions`` that solve ``contact`` (``rigid`` or ``bumper``), the contact
    law's reference (its first registered engine with an exact flow,
    :func:`~vibroimpact.engines.registry.engine_for`) first, then in their order."""
    chosen = [name for name in solutions if ENGINE_CONTACT.get(name) == contact]
    reference = engine_for(contact, "exact_flow")
    return sorted(chosen, key=lambda name: name != reference)


#: The engine every rigid-stop benchmark method is measured against (the rigid stop's first registered engine with an
#: exact flow); a benchmark always runs it.
BENCHMARK_REFERENCE = engine_for(RIGID, "exact_flow")
#: Engines a benchmark scene may compare: every registered engine but the reference.
BENCHMARK_METHODS = tuple(name for name in engine_names() if name != BENCHMARK_REFERENCE)
#: Directions of a swept-sine test.
SWEEP_DIRECTIONS = ("up", "down")
#: How a simulation starts at each frequency.
SIMULATION_STARTS = START_MODES + SWEEP_STARTS
#: Parameters a stepped or swept scene can sweep: rows of the parameter table (units and allowed ranges).
SWEEPABLE = {name: PARAMETERS[name] for name in ("frequency", "restitution", "clearance", "bumper_frequency", "bumper_loss_factor")}
#: Dimension order of a study's grid (unswept ones are squeezed out of the dataset).
GRID_DIMS = ("restitution", "clearance", "bumper_frequency", "sweep", "frequency")
#: Most points of one grid.
MAX_GRID_POINTS = 1_000_000
#: Largest study: restitution x clearance x frequency points (each solution holds a few arrays of this size).
MAX_STUDY_POINTS = 10_000_000
#: Most output samples of one swept-sine run (7 floats each, plus the estimators' temporaries: ~1 GB).
MAX_SWEEP_SAMPLES = 10_000_000
#: Most periods of one benchmark run.
MAX_BENCHMARK_PERIODS = 1_000_000


@suggest_keywords
@dataclass(frozen=True, eq=False)
class Scene(Generic[SettingsT]):
    """A validated scene: a header shared by every kind, and its kind's own settings.

    Attributes
    ----------
    name : str
        Scene name; output goes to ``<out>/<name>.nc``.
    description : str
        Free text.
    layout : Layout
        The structure, its load and where its stops act (:class:`~vibroimpact.model.layout.Layout`), the paper's
        named form or any other, read by one grammar (:func:`vibroimpact.scene.layout_parse.parse_layout`).
    amplitude : float
        Excitation amplitude: force q [N] (for a base motion, the base displacement [m]).
    kind : str
        The kind of study (a name of :data:`vibroimpact.scene.kinds.KINDS`), set by the kind's scene parser: the row
        of the table whose section the document has.
    settings : object
        The kind's own frozen settings, built by its parser (``GridSettings`` for stepped and swept scenes,
        ``BenchmarkScene``, ``BifurcationSettings``, ``ValidationSettings``, ``ConceptsSettings``).
    report : bool
        Whether ``run-study`` writes the comparison report.
    text : str
        The YAML source, stored in the output's attributes.
    cluster_scheduler : str or None
        The scene's ``cluster: {scheduler: ADDRESS}``: a running dask scheduler to run on; None: a local cluster.
    """

    name: str
    description: str
    layout: Layout
    amplitude: float
    kind: str
    settings: SettingsT
    report: bool = True
    text: str = ""
    cluster_scheduler: str | None = None

    def __post_init__(self) -> None:
        if self.kind not in KIND_NAMES:
            raise ValueError(f"kind must be one of {', '.join(KIND_NAMES)}, got {self.kind!r}")
        if self.settings is None:
            raise ValueError(f"settings: a {self.kind} scene needs the settings of its kind")

    @property
    def coordinates(self) -> tuple[str, ...]:
        """Names of the structure's coordinates (``x1, x2`` for the paper's system)."""
        return self.layout.coordinates
