"""The ``concepts`` kind of study: absorber concepts side by side (which absorber, with which stop) over one band.

For every concept of the scene (:mod:`vibroimpact.scene.concepts`):

1. closed forms on the fine grid (:mod:`.concepts_closed`): the linear steady state, and the impact orbit with its
   Floquet stability where a closed form applies;
2. time-domain steady states on the simulation grid (:mod:`.concepts_cases`): the rigid stops through ``exact``, and
   each stop's Kelvin-Voigt twin through ``compliant`` for the peak impact acceleration and contact force;
3. branches continued in frequency from the simulated periodic motions and the closed-form orbit
   (:mod:`.concepts_branches`): stable and unstable stretches;
4. the worst stable response and the figures of merit (:mod:`.concepts_metrics`).

Steps 2 and 3 run in ``jobs`` processes through :func:`vibroimpact.study.runner.run_cases` (resumable cache).
Output contract: dimensions ``concept`` (names), ``frequency`` [Hz] (fine grid), ``simulation_frequency`` [Hz] and
``point`` (continued orbits); see :func:`.concepts_dataset.concepts_dataset` for the variables.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import xarray as xr

from vibroimpact.scene.concepts import ConceptsSettings
from vibroimpact.study.concepts_branches import BranchCase, branch_seeds
from vibroimpact.study.concepts_cases import CASE_FIELDS, ConceptCase
from vibroimpact.study.concepts_closed import closed_forms
from vibroimpact.study.concepts_dataset import concepts_dataset
from vibroimpact.study.cost_model import Costs, Estimate
from vibroimpact.study.grid import Progress
from vibroimpact.study.runner import Runner

__all__ = ["ConceptsStudy", "run_concepts", "CHUNK"]

#: Frequencies per simulation case (load balancing between processes).
CHUNK = 8
#: Costs of :meth:`ConceptsStudy.estimate` on the calibration machine: seconds per simulated frequency point of one
#: concept (exact march, bumper twin and replay where it impacts), per continued concept, and for the report. Measured
#: on the shipped scene: 100 s with --jobs 2 on 2 cores shared at load ~3 (warm caches; 171 s compiling from a fresh
#: tree), the speed probe reading 1.2-2.7 over that hour.
SECONDS_PER_POINT = 0.12
SECONDS_PER_BRANCH_CASE = 8.0
SECONDS_REPORT = 10.0


def run_concepts(settings: ConceptsSettings, progress: Progress | None = None, runner: Runner | None = None) -> xr.Dataset:
    """Every concept's closed forms, simulations and branches, and the figures of merit (module docstring)."""
    say = progress if progress is not None else (lambda message: None)
    runner = runner if runner is not None else Runner(progress=progress is not None)
    closed = {c.name: closed_forms(c, settings.amplitude, settings.frequency) for c in settings.concepts}
    say(f"closed forms of {len(closed)} concepts on {settings.frequency.size} frequencies")
    stopped = [c for c in settings.concepts if c.stops]
    cases, owners = [], []
    for concept in stopped:
        for first in range(0, settings.simulation_frequency.size, CHUNK):
            chunk = tuple(float(f) for f in settings.simulation_frequency[first : first + CHUNK])
            cases.append(ConceptCase(concept, settings.amplitude, chunk, settings.engine, settings.steady, settings.bumper_frequency))
            owners.append(concept.name)
    results = runner.map(cases)
    simulated: dict[str, dict[str, np.ndarray]] = {}
    for concept in stopped:
        parts = [r for r, owner in zip(results, owners) if owner == concept.name]
        simulated[concept.name] = {name: np.concatenate([p[name] for p in parts]) for name in CASE_FIELDS}
    say(f"simulated {len(stopped)} concepts on {settings.simulation_frequency.size} frequencies")
    branches: dict[str, dict[str, Any]] = {}
    if settings.continuation_steps > 0 and stopped:
        low, high = float(settings.frequency[0]), float(settings.frequency[-1])
        branch_cases = []
        for concept in stopped:
            s = simulated[concept.name]
            seeds = branch_seeds(settings.simulation_frequency, s["converged"], s["multiplicity"], s["impacts_per_period"], s["end_state"], s["end_time"])
            branch_cases.append(BranchCase(concept, settings.amplitude, low, high, seeds, settings.continuation_steps))
        for concept, result in zip(stopped, runner.map(branch_cases)):
            branches[concept.name] = result
            say(f"{concept.name}: {str(result['note'][0])}")
    return concepts_dataset(settings, closed, simulated, branches)


class ConceptsStudy:
    """The ``concepts`` kind: :func:`run_concepts` on the scene's :class:`ConceptsSettings`."""

    name = "concepts"

    def run(self, scene: Any, progress: Progress | None, runner: Runner) -> xr.Dataset:
        """The scene's dataset, with its name, text and provenance."""
        from vibroimpact.study.io import provenance

        dataset = run_concepts(scene.concepts, progress, runner)
        dataset.attrs.update({"title": f"vibroimpact absorber concepts '{scene.name}'", "scene_name": scene.name, "scene": scene.text} | provenance())
        return dataset

    def estimate(self, scene: Any, jobs: int, costs: Costs) -> Estimate:
        """Predicted wall time and memory on the calibration machine, from this kind's own measured costs per point
        (:data:`SECONDS_PER_POINT`, :data:`SECONDS_PER_BRANCH_CASE`; ``costs`` has none for it)."""
        settings: ConceptsSettings = scene.concepts
        stopped = sum(1 for c in settings.concepts if c.stops)
        points = stopped * settings.simulation_frequency.size
        simulations = points * SECONDS_PER_POINT * (1.0 if math.isfinite(settings.bumper_frequency) else 0.1)
        branches = SECONDS_PER_BRANCH_CASE * stopped if settings.continuation_steps else 0.0
        wall = simulations / max(jobs, 1) + branches / max(min(jobs, max(stopped, 1)), 1) + SECONDS_REPORT
        parts = {"simulations": simulations, "continuation": branches, "report": SECONDS_REPORT}
        return Estimate(wall_time=wall, memory=300e6, parts=parts, points={"simulations": f"{points} points of {stopped} concepts"})
