"""What a scene says: the frozen :class:`Scene` and its parts, and the vocabulary and limits of the scene format.

Nothing here reads YAML or checks a document (see :mod:`vibroimpact.kinds.stepped.scene` and
:mod:`vibroimpact.kinds.benchmark.scene`); a :class:`Scene` is built only from checked values. Engine names come from
:mod:`vibroimpact.engines.registry`, which names every engine without importing one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from vibroimpact.analysis.pgf import AdmissibilitySettings
from vibroimpact.engines.registry import engine_names, engine_spec, stepped_solutions
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.model.contact import loss_factor_from_restitution
from vibroimpact.model.excitation import SweptSine
from vibroimpact.model.problem import Structure
from vibroimpact.scene.kinds import KIND_NAMES
from vibroimpact.scene.layout import LoadSpec, StopSpec
from vibroimpact.scene.variables import MOTION_QUANTITIES, QUANTITIES, STOP_QUANTITIES, quantities_for
from vibroimpact.simulation.settings import START_MODES, SWEEP_STARTS, SteadySettings

__all__ = [
    "Scene",
    "SimulationSettings",
    "SweptSineSettings",
    "SOLUTIONS",
    "ENGINE_SOLUTIONS",
    "ENGINE_CONTACT",
    "BENCHMARK_REFERENCE",
    "BENCHMARK_METHODS",
    "QUANTITIES",
    "MOTION_QUANTITIES",
    "SWEEPABLE",
    "GRID_DIMS",
    "STOP_QUANTITIES",
    "quantities_for",
]

#: Solutions computed by time integration (they need the ``simulation`` section's settings): the registered engines
#: offered as stepped solutions.
ENGINE_SOLUTIONS = stepped_solutions()
#: Solutions a scene can ask for: the closed forms, then the engines.
SOLUTIONS = ("linear", "pgf", "pgf_paper", *ENGINE_SOLUTIONS)
#: The contact law of each engine solution (from the engine registry, which must name every one of them).
ENGINE_CONTACT = {name: engine_spec(name).contact for name in ENGINE_SOLUTIONS}
#: The engine every rigid-stop benchmark method is measured against; a benchmark always runs it.
BENCHMARK_REFERENCE = "exact"
#: Engines a benchmark scene may compare: every registered engine but the reference.
BENCHMARK_METHODS = tuple(name for name in engine_names() if name != BENCHMARK_REFERENCE)
#: Directions of a swept-sine test.
SWEEP_DIRECTIONS = ("up", "down")
#: How a simulation starts at each frequency.
SIMULATION_STARTS = START_MODES + SWEEP_STARTS
#: Parameters that can be swept, with their units and allowed ranges (low, high, low inclusive).
SWEEPABLE = {
    "frequency": ("Hz", 0.0, math.inf, False),
    "restitution": ("1", 0.0, 1.0, True),
    "clearance": ("m", -math.inf, math.inf, False),
    "bumper_frequency": ("Hz", 0.0, 1e6, False),
    "bumper_loss_factor": ("1", 0.0, 1e3, True),
}
#: Dimension order of a study's grid (unswept ones are squeezed out of the dataset).
GRID_DIMS = ("restitution", "clearance", "bumper_frequency", "sweep", "frequency")
#: Most points of one grid.
MAX_GRID_POINTS = 1_000_000
#: Largest study: restitution x clearance x frequency points (each solution holds a few arrays of this size).
MAX_STUDY_POINTS = 10_000_000
#: Most output samples of one swept-sine run (7 floats each, plus the estimators' temporaries: ~1 GB).
MAX_SWEEP_SAMPLES = 10_000_000
#: Stiffest bumper accepted [Hz] (tested to 100 kHz; contact then lasts microseconds).
MAX_BUMPER_FREQUENCY = 1e6
#: Most periods of one benchmark run.
MAX_BENCHMARK_PERIODS = 1_000_000


@dataclass(frozen=True, eq=False)
class SimulationSettings:
    """How the time-domain solutions (``momentary``, ``exact``) are run.

    Attributes
    ----------
    frequency : ndarray
        Frequencies simulated [Hz] (a coarser grid than the analytic one, merged into the dataset's axis).
    start : str
        One of :data:`SIMULATION_STARTS`.
    engine : EngineSettings
        Integrator tolerances and method.
    steady : SteadySettings
        Convergence and measurement of the steady state.
    """

    frequency: np.ndarray
    start: str = "pgf"
    engine: EngineSettings = field(default_factory=EngineSettings)
    steady: SteadySettings = field(default_factory=SteadySettings)


@dataclass(frozen=True)
class SweptSineSettings:
    """A swept-sine test (the paper's Simulink run, section 5) instead of stepped steady states.

    Attributes
    ----------
    start_frequency, stop_frequency : float
        Ends of the sweep [Hz] (a sweep down runs from ``stop_frequency`` to ``start_frequency``).
    rate : float
        |alpha| [Hz s-1].
    directions : tuple of str
        Some of ``up``, ``down``.
    sample_rate : float
        Output samples per second of the simulated signals [Hz].
    window_cycles : int
        Cycles of the excitation in the running estimators' window.
    initial_state : str
        ``linear``: each run starts on the linear steady state at its first frequency (where it fits inside the
        clearance; else at rest), so no start-up transient shows; ``rest``: at rest, like a bench test.
    """

    start_frequency: float
    stop_frequency: float
    rate: float
    directions: tuple[str, ...] = SWEEP_DIRECTIONS
    sample_rate: float = 1000.0
    window_cycles: int = 8
    initial_state: str = "linear"

    def sweep(self, amplitude: float, direction: str) -> SweptSine:
        """The excitation of one direction."""
        low, high = self.start_frequency, self.stop_frequency
        return SweptSine(amplitude, low, high, self.rate) if direction == "up" else SweptSine(amplitude, high, low, self.rate)


@dataclass(frozen=True, eq=False)
class Scene:
    """A validated scene.

    Attributes
    ----------
    name : str
        Scene name; output goes to ``<out>/<name>.nc``.
    description : str
        Free text.
    system : TwoDofSystem or LinearStructure
        The linear system: the paper's named one, or any structure given by matrices.
    amplitude : float
        Excitation amplitude: force q [N] (for a base motion, the base displacement [m]).
    frequency : ndarray
        Excitation frequencies [Hz], increasing.
    restitution : ndarray
        Restitution ratios R [-]; one value unless swept.
    clearance : ndarray
        Clearances Delta [m]; one value unless swept.
    swept : tuple of str
        Parameters that are dimensions of the output, in dimension order (``frequency`` last).
    solutions : tuple of str
        Solutions to compute.
    quantities : tuple of str
        Quantities to write.
    admissibility : AdmissibilitySettings
        Settings of the X2(t) <= Delta check.
    simulation : SimulationSettings or None
        Settings of the time-domain solutions, when the scene asks for any.
    bumper_frequency : ndarray or None
        Omega_b / 2 pi of the compliant bumper [Hz] (one value unless swept); None without a bumper.
    bumper_loss_factor : ndarray or None
        xi_b [-]: one value, or one per ``restitution`` when ``bumper_loss_factor`` is swept (``restitution`` then
        holds R(xi_b), eq. 26 corrected); None: each restitution's own loss factor (the exact inverse of R(xi_b)).
    swept_sine : SweptSineSettings or None
        When given, the time-domain solutions are swept-sine tests, not stepped steady states.
    report : bool or str
        Whether ``run-study`` writes the comparison report; a string names the page (``design_map``).
    text : str
        The YAML source, stored in the output's attributes.
    load : LoadSpec or None
        A general scene's load (weights, static force, base motion); None: the paper's force on the primary mass.
    stops : tuple of StopSpec
        A general scene's stops; ``()``: the paper's stop (see :attr:`stop_specs`).
    sweep_stops : tuple of int or None
        The stops that swept restitution, clearance and bumper values apply to; None: every stop.
    cluster_scheduler : str or None
        The scene's ``cluster: {scheduler: ADDRESS}``: a running dask scheduler to run on; None: a local cluster.
    general : bool
        The scene uses the general format (matrices, a load beyond a force on the primary mass, or ``stops``): its
        outputs are named after its coordinates and stops. False: the paper's named form and outputs.
    kind : str
        The kind of study (a name of :data:`vibroimpact.scene.kinds.KINDS`), set by the kind's scene parser: the row
        of the table whose section the document has.
    settings : object or None
        The kind's own frozen settings, built by its parser (``BenchmarkScene``, ``BifurcationSettings``,
        ``ValidationSettings``, ``ConceptsSettings``); None for stepped and swept scenes, whose settings are the
        grid fields above.
    """

    name: str
    description: str
    system: Structure
    amplitude: float
    frequency: np.ndarray
    restitution: np.ndarray
    clearance: np.ndarray
    swept: tuple[str, ...]
    solutions: tuple[str, ...]
    quantities: tuple[str, ...]
    admissibility: AdmissibilitySettings = field(default_factory=AdmissibilitySettings)
    simulation: SimulationSettings | None = None
    bumper_frequency: np.ndarray | None = None
    bumper_loss_factor: np.ndarray | None = None
    swept_sine: SweptSineSettings | None = None
    report: bool | str = True
    text: str = ""
    load: LoadSpec | None = None
    stops: tuple[StopSpec, ...] = ()
    sweep_stops: tuple[int, ...] | None = None
    general: bool = False
    cluster_scheduler: str | None = None
    kind: str = "stepped"
    settings: Any = None

    def __post_init__(self) -> None:
        if self.kind not in KIND_NAMES:
            raise ValueError(f"kind must be one of {', '.join(KIND_NAMES)}, got {self.kind!r}")
        if (self.settings is None) != (self.kind in ("stepped", "swept")):
            raise ValueError(f"settings: a {self.kind} scene {'has' if self.settings is None else 'takes'} no settings of its kind")

    @property
    def coordinates(self) -> tuple[str, ...]:
        """Names of the structure's coordinates (``x1, x2`` for the paper's system)."""
        return tuple(self.system.coordinates)

    @property
    def stop_specs(self) -> tuple[StopSpec, ...]:
        """Every stop: the scene's ``stops``, or the paper's upper stop on the absorber taking the grid's values."""
        return self.stops or (StopSpec(coordinate=1),)

    @property
    def load_spec(self) -> LoadSpec:
        """The load: the scene's, or the paper's force on the primary mass."""
        return self.load if self.load is not None else LoadSpec()

    def loss_factors(self) -> np.ndarray:
        """The bumper's xi_b for each restitution of the grid [-] (NaN where none gives it, R = 0)."""
        if self.bumper_loss_factor is not None:
            return np.broadcast_to(self.bumper_loss_factor, self.restitution.shape).astype(float)
        return np.array([loss_factor_from_restitution(r) if r > 0.0 else np.nan for r in self.restitution])

    @property
    def sweep_directions(self) -> tuple[str, ...]:
        """Directions of the swept-sine test; ``()`` for stepped steady states."""
        return () if self.swept_sine is None else self.swept_sine.directions

    @property
    def all_frequencies(self) -> np.ndarray:
        """The dataset's frequency axis: the analytic grid merged with the simulation grid [Hz]."""
        if self.simulation is None:
            return self.frequency
        return np.union1d(self.frequency, self.simulation.frequency)
