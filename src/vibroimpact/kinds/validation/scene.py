"""Validation scenes: one published closed form, reproduced by the project's engines and continuation.

Example (``studies/validation/budd_dux.yaml``)::

    name: budd_dux
    description: Budd & Dux's impact oscillator ...
    validation:
      case: budd_dux              # budd_dux, bouncing_ball, zeno, grazing or relative_stop
      forcing_frequency: 2.8      # every other key is optional (the case's defaults)
      restitution: 0.8
      clearance: {start: -0.5, stop: 0.14}

The keys of each case, their units and ranges are :data:`vibroimpact.kinds.validation.settings.CASE_PARAMETERS`, declared as
one form of the ``validation`` section per case (:data:`~vibroimpact.kinds.validation.settings.CASE_SECTIONS`).
Every unknown key, wrong type and out-of-range value is reported together, each naming its key.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass
from typing import Any


from vibroimpact.model.layout import Layout, LoadSpec, StopSpec
from vibroimpact.scene.header import open_scene
from vibroimpact.kinds.validation.settings import BouncingBallCase, BuddDuxCase, GrazingCase, RelativeStopCase, ValidationCase, ZenoCase
from vibroimpact.kinds.validation.settings import (
    VALIDATION_CASES,
    VALIDATION_TOP_KEYS,
    CASE_KEY,
    CASE_SECTIONS,
    SECTIONS,
    ValidationSettings,
)
from vibroimpact.model.contact import RigidStop, Stop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.structure import LinearStructure
from vibroimpact.model.system import NAMED_KEYS, named_system
from vibroimpact.scene.checker import Checker, SceneError
from vibroimpact.scene.schema import Scene

__all__ = ["BALL_TIME_SHIFT", "case_structure", "budd_dux_problem", "ball_problem", "ball_amplitude", "zeno_problem", "grazing_problem", "grazing_phase", "relative_stop_problem", "ValidationScene", "read_validation_scene", "parse_validation_scene", "validation_settings", "SECTIONS"]


# --------------------------------------------------------------------------------------------------------------------
# The impact problems of the validation cases: each published system written in the project's general model.
# --------------------------------------------------------------------------------------------------------------------

#: The ball problem's time t is the table's time t + T/2 ... as a phase: the table is A sin(w t + BALL_TIME_SHIFT).
BALL_TIME_SHIFT = math.pi


def case_structure(case: ValidationCase) -> LinearStructure:
    """The structure of a case."""
    if isinstance(case, BuddDuxCase):
        return LinearStructure([[1.0]], [[1.0]], [[0.0]], ("x",))
    if isinstance(case, (BouncingBallCase, ZenoCase)):
        return LinearStructure([[case.mass]], [[0.0]], [[0.0]], ("z",))
    if isinstance(case, GrazingCase):
        return LinearStructure([[case.mass]], [[case.stiffness]], [[case.damping]], ("x",))
    return named_system({key: getattr(case, key) for key in NAMED_KEYS}).structure  # the paper's masses (relative stop)


def case_layout(case: ValidationCase) -> Layout:
    """The layout of a case: its structure, where its load acts and where its stop acts (its problems below give
    the values)."""
    structure = case_structure(case)
    if isinstance(case, (BouncingBallCase, ZenoCase)):
        return Layout(structure, LoadSpec(weights=(1.0,), static=(-case.mass * case.gravity,)), (StopSpec(0, side="lower"),))
    if isinstance(case, (BuddDuxCase, GrazingCase)):
        return Layout(structure, LoadSpec(weights=(1.0,)), (StopSpec(0, side="upper"),))
    return Layout(structure, LoadSpec(weights=(1.0, 0.0)), (StopSpec(1, other=0, side="upper"),))


def budd_dux_problem(case: BuddDuxCase, clearance: float) -> ImpactProblem:
    """x'' + x = cos(w t), x <= ``clearance`` (sigma), x' -> -r x'."""
    w = case.forcing_frequency
    stop = Stop(RigidStop(clearance, case.restitution), coordinate=0, side="upper")
    return ImpactProblem(case_structure(case), (stop,), HarmonicForce(1.0, w / (2.0 * math.pi), 0.0, weights=(1.0,)))


def ball_amplitude(case: BouncingBallCase, gamma: float) -> float:
    """The harmonic force m A w^2 [N] of the table acceleration Gamma = A w^2 / g."""
    return case.mass * gamma * case.gravity


def ball_problem(case: BouncingBallCase, gamma: float) -> ImpactProblem:
    """The ball in table coordinates at Gamma = A w^2 / g (module docstring; force m A w^2 cos(w t + pi/2))."""
    stop = Stop(RigidStop(0.0, case.restitution), coordinate=0, side="lower")
    force = HarmonicForce(ball_amplitude(case, gamma), case.frequency, BALL_TIME_SHIFT - 0.5 * math.pi, weights=(1.0,), static=(-case.mass * case.gravity,))
    return ImpactProblem(case_structure(case), (stop,), force)


def zeno_problem(case: ZenoCase) -> ImpactProblem:
    """A free mass with gravity above a fixed table z >= 0 (no harmonic force)."""
    stop = Stop(RigidStop(0.0, case.restitution), coordinate=0, side="lower")
    return ImpactProblem(case_structure(case), (stop,), HarmonicForce(0.0, case.frequency, 0.0, weights=(1.0,), static=(-case.mass * case.gravity,)))


def grazing_phase(case: GrazingCase) -> float:
    """Force phase [rad] that puts the linear orbit's maximum at t = T/2: x = |H| A cos(w t + phase + arg H)."""
    w = 2.0 * math.pi * case.frequency
    h = 1.0 / complex(case.stiffness - case.mass * w * w, case.damping * w)
    return (-math.pi - cmath.phase(h)) % (2.0 * math.pi)


def grazing_problem(case: GrazingCase, amplitude: float) -> ImpactProblem:
    """m x'' + c x' + k x = A cos(w t + phase), x <= d."""
    stop = Stop(RigidStop(case.clearance, case.restitution), coordinate=0, side="upper")
    return ImpactProblem(case_structure(case), (stop,), HarmonicForce(amplitude, case.frequency, grazing_phase(case), weights=(1.0,)))


def relative_stop_problem(case: RelativeStopCase) -> ImpactProblem:
    """The paper's masses with a stop between absorber and primary mass, x2 - x1 <= Delta."""
    stop = Stop(RigidStop(case.clearance, case.restitution), coordinate=1, other=0, side="upper")
    return ImpactProblem(case_structure(case), (stop,), HarmonicForce(case.amplitude, case.frequency, 0.0, weights=(1.0, 0.0)))

@dataclass(frozen=True)
class ValidationScene:
    """A checked validation scene: what :class:`Scene` carries for the ``validation`` kind.

    Attributes
    ----------
    name : str
        Scene name (output ``<name>.nc``).
    description : str
        Free text.
    settings : ValidationSettings
        The case and its parameters.
    report : bool
        Whether ``run-study`` writes the report.
    text : str
        The YAML source.
    cluster_scheduler : str or None
        The scene's ``cluster: {scheduler: ADDRESS}`` (None: a local cluster).
    """

    name: str
    description: str
    settings: ValidationSettings
    report: bool = True
    text: str = ""
    cluster_scheduler: str | None = None


def validation_settings(c: Checker, value: Any) -> ValidationSettings | None:
    """The ``validation`` section as settings, or None with every problem recorded in ``c``."""
    if not isinstance(value, dict):
        c.fail("validation", f"expected a mapping with 'case' and the case's parameters, got {type(value).__name__}")
        return None
    case_name = value.get("case")
    if case_name not in VALIDATION_CASES:
        CASE_KEY.check(c, "validation.case", case_name) if "case" in value else c.fail("validation.case", f"required key is missing ({CASE_KEY.allowed()})")
        return None
    values = CASE_SECTIONS[case_name].read(c, value)
    if values is None:
        return None
    values.pop("case")
    cls = VALIDATION_CASES[case_name]
    kwargs = {key: item for key, item in values.items() if key in value}  # as given: the defaults are the case's own
    if not _consistent(c, case_name, values):
        return None
    return ValidationSettings(cls(**kwargs))


def _consistent(c: Checker, case: str, values: dict[str, Any]) -> bool:
    """Checks that involve several keys of a case (each failure names the key to change)."""
    problems = len(c.problems)
    if case == "budd_dux":
        w = values["forcing_frequency"]
        if abs(w - 1.0) < 1e-6 or abs(math.sin(2.0 * math.pi / w)) < 1e-6:
            c.fail("validation.forcing_frequency", f"{w!r}: the ellipse needs w != 1 (resonance) and sin(2 pi / w) != 0 (w != 1/k)")
        low, high = values["clearance"]
        if not low <= values["start_clearance"] <= high:
            c.fail("validation.start_clearance", f"{values['start_clearance']!r} is out of range: allowed [{low:g}, {high:g}] (validation.clearance)")
        if high >= abs(1.0 / (1.0 - w * w)):
            c.fail("validation.clearance.stop", f"{high!r} is out of range: allowed below |gamma| = {abs(1.0 / (1.0 - w * w)):.6g}, where the orbit grazes")
    if case == "bouncing_ball":
        low, high = values["acceleration"]
        if values["brute_step"] > high - low:
            c.fail("validation.brute_step", f"{values['brute_step']!r} is out of range: allowed (0, {high - low:g}] (the width of validation.acceleration)")
    return len(c.problems) == problems


def read_validation_scene(document: Any, text: str = "", source: str = "scene") -> ValidationScene:
    """Check a validation scene's document (a mapping with ``validation``); raise :class:`SceneError` listing all
    problems."""
    c, doc, name, description, report, scheduler = open_scene(document, VALIDATION_TOP_KEYS, {"name", "validation"}, "validation")
    settings = validation_settings(c, doc["validation"]) if "validation" in doc else None
    if settings is not None and not c.problems:
        case = settings.case
        try:
            if isinstance(case, RelativeStopCase):
                named_system({key: getattr(case, key) for key in NAMED_KEYS}).check_ratios()
            else:
                case_structure(case).check_dynamic_range()
        except ValueError as error:  # a ratio beyond double precision (model/structure.py, model/system.py)
            c.fail("validation", str(error).partition(": ")[2])
    if c.problems:
        raise SceneError(c.problems, source)
    assert isinstance(name, str) and settings is not None
    return ValidationScene(name, description, settings, report, text, scheduler)


def parse_validation_scene(document: Any, text: str = "", source: str = "scene") -> Scene:
    """The :class:`Scene` of a validation scene (kind ``validation``): its :class:`ValidationSettings` (the case) in
    :attr:`Scene.settings`."""
    checked = read_validation_scene(document, text, source)
    case = checked.settings.case
    return Scene(
        name=checked.name,
        description=checked.description,
        layout=case_layout(case),
        amplitude=1.0,
        kind="validation",
        settings=checked.settings,
        report=checked.report,
        text=text,
        cluster_scheduler=checked.cluster_scheduler,
    )
