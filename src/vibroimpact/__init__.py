"""vibroimpact: vibration protection by a tuned dynamic absorber whose motion is limited by a stop on the base.

Linear models (the paper's two masses, or any N-dof structure with stops on any coordinate, absolute or relative,
one- or two-sided), closed-form periodic-Green-function (PGF) solution of the one-impact regime,
time-domain engines, and studies that put them side by side (seed paper: the absorber with a stop mounted on the
base). The names users import are available here and load their layer on first use, so ``import vibroimpact``
stays light::

    from vibroimpact import design_answer, load_scene, run_study

    if __name__ == "__main__":  # a script that starts worker processes (jobs > 1) runs its study once, here
        dataset = run_study(load_scene("design_rigid_stop"), jobs=2)
        print(design_answer(dataset).headline)
"""

from __future__ import annotations

import os

if os.environ.get("VIBROIMPACT_WORKER") == "1":  # a local cluster's worker, spawned by run-study (runs.cluster)
    import multiprocessing as _multiprocessing
    import signal as _signal
    import threading as _threading

    # first thing in a spawned worker (multiprocessing imports the parent's main module, hence this package, while
    # the child is still inheriting): ignore Ctrl-C before its seconds of imports, the study's process handles it.
    # A process that merely inherited the variable (not a spawned child) keeps its Ctrl-C.
    _spawned = getattr(_multiprocessing.current_process(), "_inheriting", False) or _multiprocessing.parent_process() is not None
    if _spawned and _threading.current_thread() is _threading.main_thread():
        _signal.signal(_signal.SIGINT, _signal.SIG_IGN)

import importlib

#: Public name -> the module that defines it (README, "Architecture").
_PUBLIC = {
    "TwoDofSystem": "vibroimpact.model.system",
    "PAPER_SYSTEM": "vibroimpact.model.system",
    "RigidStop": "vibroimpact.model.contact",
    "KelvinVoigtBumper": "vibroimpact.model.contact",
    "HarmonicForce": "vibroimpact.model.excitation",
    "SweptSine": "vibroimpact.model.excitation",
    "ImpactProblem": "vibroimpact.model.problem",
    "LinearStructure": "vibroimpact.model.structure",
    "Stop": "vibroimpact.model.contact",
    "loss_factor_from_restitution": "vibroimpact.model.contact",
    "restitution_from_loss_factor": "vibroimpact.model.contact",
    "Layout": "vibroimpact.model.layout",
    "solve_one_impact": "vibroimpact.analysis.pgf",
    "solve_impact_orbit": "vibroimpact.analysis.impact_orbit",
    "solve_two_impacts": "vibroimpact.analysis.two_sided",
    "ImpactOrbit": "vibroimpact.analysis.impact_orbit",
    "closed_form_refusal": "vibroimpact.analysis.layout",
    "floquet_multipliers": "vibroimpact.analysis.stability",
    "linear_response": "vibroimpact.analysis.linear",
    "linear_amplitudes": "vibroimpact.analysis.linear",
    "LinearAmplitudes": "vibroimpact.analysis.linear",
    "Trajectory": "vibroimpact.engines.base",
    "Engine": "vibroimpact.engines.base",
    "Capabilities": "vibroimpact.engines.registry",
    "EngineSettings": "vibroimpact.engines.settings",
    "ENGINES": "vibroimpact.engines.registry",
    "make_engine": "vibroimpact.engines.registry",
    "ImpactMap": "vibroimpact.orbits.maps",
    "worst_case": "vibroimpact.measures.worst_case",
    "BandMaximum": "vibroimpact.measures.worst_case",
    "Parameter": "vibroimpact.model.parameters",
    "parameter": "vibroimpact.model.parameters",
    "orbit_measures": "vibroimpact.orbits.orbit_measures",
    "branch_measures": "vibroimpact.orbits.orbit_measures",
    "OrbitMeasures": "vibroimpact.orbits.orbit_measures",
    "BranchMeasures": "vibroimpact.orbits.orbit_measures",
    "BumperPeriodMap": "vibroimpact.orbits.bumper_map",
    "shoot": "vibroimpact.orbits.shooting",
    "closed_form_state": "vibroimpact.orbits.shooting",
    "switch_period_doubling": "vibroimpact.orbits.bifurcations",
    "continue_special_point": "vibroimpact.orbits.special_curves",
    "continue_branch": "vibroimpact.orbits.continuation",
    "ContinuationSettings": "vibroimpact.orbits.continuation",
    "classify_motion": "vibroimpact.orbits.motion",
    "steady_state": "vibroimpact.simulation.steady",
    "SteadySettings": "vibroimpact.simulation.settings",
    "TimeHistory": "vibroimpact.simulation.history",
    "time_history": "vibroimpact.simulation.history",
    "Scene": "vibroimpact.scene",
    "SceneError": "vibroimpact.scene",
    "load_scene": "vibroimpact.scene",
    "parse_scene": "vibroimpact.scene",
    "find_scene": "vibroimpact.scene",
    "run_study": "vibroimpact.runs.run",
    "write_dataset": "vibroimpact.runs.run",
    "read_dataset": "vibroimpact.runs.run",
    "split_groups": "vibroimpact.runs.run",
    "join_groups": "vibroimpact.runs.run",
    "write_report": "vibroimpact.reporting.page",
    "design_answer": "vibroimpact.kinds.design.result",
    "DesignAnswer": "vibroimpact.kinds.design.result",
}

__all__ = ["__version__", *_PUBLIC]


def __getattr__(name: str) -> object:
    """Load a public name's module on first use (PEP 562); the version too (``import vibroimpact``, run-study's first
    step, stays instant)."""
    if name == "__version__":
        from importlib.metadata import PackageNotFoundError, version

        try:
            found = version("vibroimpact")
        except PackageNotFoundError:  # running from a source tree without installation
            found = "0+unknown"
        globals()["__version__"] = found
        return found
    if name not in _PUBLIC:
        raise AttributeError(f"module 'vibroimpact' has no attribute {name!r}")
    value = getattr(importlib.import_module(_PUBLIC[name]), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(__all__)
