"""Validation studies (kind ``validation``): one published closed form per scene, reproduced by the project.

``run-study studies/validation/<case>.yaml`` runs the case (:mod:`.validation_orbits`: continuation of periodic
orbits; :mod:`.validation_runs`: simulated runs) and writes ``<name>.nc``: a table of compared quantities
(dimension ``check``: ``quantity``, ``published``, ``computed``, ``relative_error``, ``tolerance``, ``passed``; see
:mod:`.validation_checks`) and the data of the case's figure, with the case's name and source in the attributes.
"""

from __future__ import annotations

from collections.abc import Callable
from types import MappingProxyType

import xarray as xr

from vibroimpact.scene.validation_settings import ValidationSettings
from vibroimpact.study.cost_model import Costs, Estimate
from vibroimpact.study.io import provenance
from vibroimpact.study.runner import Runner
from vibroimpact.study.validation_checks import CaseOutcome, outcome_dataset
from vibroimpact.study.validation_orbits import run_bouncing_ball, run_budd_dux, run_grazing
from vibroimpact.study.validation_runs import run_relative_stop, run_zeno

__all__ = ["ValidationStudy", "run_validation", "RUNNERS", "CASE_SECONDS"]

#: Each case's run: (case settings, progress) -> outcome.
RUNNERS: MappingProxyType[str, Callable[..., CaseOutcome]] = MappingProxyType(
    {"budd_dux": run_budd_dux, "bouncing_ball": run_bouncing_ball, "zeno": run_zeno, "grazing": run_grazing, "relative_stop": run_relative_stop}
)
#: Wall time of each shipped case [s] (measured at load ~7 on the 2-core machine: 1.1, 3.8, 0.6, 2.5, 0.8-3.3 s; the
#: numba cache warm).
CASE_SECONDS = MappingProxyType({"budd_dux": 1.5, "bouncing_ball": 4.0, "zeno": 1.0, "grazing": 2.5, "relative_stop": 2.0})
#: Figures of a validation page.
REPORT_FIGURES = 1


def run_validation(settings: ValidationSettings, name: str, text: str = "", progress: Callable[[str], None] | None = None) -> xr.Dataset:
    """Run a validation case and gather its dataset (module docstring)."""
    say = progress if progress is not None else (lambda message: None)
    outcome = RUNNERS[settings.name](settings.case, say)
    attrs = {
        "title": f"vibroimpact validation '{name}': {settings.name}",
        "scene_name": name,
        "scene": text,
        "validation_source": settings.source,
        "study_kind": "validation",
    } | provenance()
    passed = sum(c.passed for c in outcome.checks)
    checks = sum(not c.informative for c in outcome.checks)
    say(f"{settings.name}: {passed} of {checks} checks passed")
    return outcome_dataset(outcome, attrs)


class ValidationStudy:
    """The ``validation`` kind of study."""

    name = "validation"

    def run(self, scene, progress: Callable[[str], None] | None, runner: Runner) -> xr.Dataset:
        """The scene's dataset (module docstring); one process (each case takes seconds)."""
        return run_validation(scene.validation, scene.name, scene.text, progress)

    def estimate(self, scene, jobs: int, costs: Costs) -> Estimate:
        """The case's measured time plus the report, on the calibration machine."""
        work = CASE_SECONDS[scene.validation.name]
        report = costs.report_base + REPORT_FIGURES * costs.report_per_figure
        return Estimate(wall_time=costs.startup + work + report, memory=costs.main_process_memory, parts={scene.validation.name: work, "report": report})
