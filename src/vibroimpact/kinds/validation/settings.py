"""What a validation scene says: one published case and its parameters, checked values only.

Each case is a frozen dataclass whose fields are the scene's keys (``validation: {case: <name>, <field>: ...}``);
:data:`CASE_PARAMETERS` gives every field's unit, allowed range and default, which the parser
(:mod:`vibroimpact.kinds.validation.scene`) checks and the report shows. A range is written ``{start, stop}`` and stored as
a (low, high) pair. Nothing here reads YAML or imports another scene module, so :mod:`vibroimpact.scene.schema` can
name these types.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any, Union

from vibroimpact.scene.declared import REQUIRED, Band, Key, Names, Section

__all__ = [
    "CASE_KEY",
    "CASE_SECTIONS",
    "SECTIONS",
    "VALIDATION_CASES",
    "VALIDATION_TOP_KEYS",
    "CASE_SOURCES",
    "Parameter",
    "CASE_PARAMETERS",
    "ZENO_ENGINES",
    "BuddDuxCase",
    "BouncingBallCase",
    "ZenoCase",
    "GrazingCase",
    "RelativeStopCase",
    "ValidationCase",
    "ValidationSettings",
]

#: Top-level keys of a validation scene.
VALIDATION_TOP_KEYS = {"name", "description", "validation", "report"}
#: Default pass threshold: relative agreement with the closed form.
DEFAULT_TOLERANCE = 1e-8
#: The rigid-stop engines whose chattering-to-sticking logic the Zeno case checks (every one by default).
ZENO_ENGINES = ("exact", "exact_python", "momentary_adams", "momentary_bdf", "solve_ivp_RK45", "solve_ivp_DOP853", "solve_ivp_LSODA", "solve_ivp_Radau", "solve_ivp_BDF")


@dataclass(frozen=True)
class Parameter:
    """One key of a case: its unit and allowed interval (its default is the case dataclass's).

    ``kind`` is ``number``, ``integer``, ``range`` (a ``{start, stop}`` mapping inside the interval) or ``engines``
    (a list of names from :data:`ZENO_ENGINES`).
    """

    units: str
    low: float = -math.inf
    high: float = math.inf
    low_inclusive: bool = True
    high_inclusive: bool = True
    kind: str = "number"
    help: str = ""


def _key(name: str, parameter: Parameter, default: Any) -> Key:
    """A case's parameter as a declared scene key (:mod:`vibroimpact.scene.declared`), its default the case's."""
    kinds = {"number": float, "integer": int, "range": Band, "engines": Names}
    unit = "" if parameter.units == "1" else parameter.units
    if parameter.kind == "engines":
        return Key(name, Names, parameter.help, default, choices=ZENO_ENGINES)
    if parameter.kind == "integer":
        return Key(name, int, parameter.help, default, parameter.low, parameter.high, unit)
    return Key(name, kinds[parameter.kind], parameter.help, default, parameter.low, parameter.high, unit,
               open_low=not parameter.low_inclusive and math.isfinite(parameter.low), open_high=not parameter.high_inclusive and math.isfinite(parameter.high))


def _tolerance() -> Parameter:
    return Parameter("1", 0.0, 1.0, False, False, help="relative agreement required to pass")


@dataclass(frozen=True)
class BuddDuxCase:
    """x'' + x = cos(w t), x <= sigma, x' -> -r x' (Budd & Dux 1994): period-one orbits continued in sigma.

    Attributes
    ----------
    forcing_frequency : float
        w [-]: forcing over natural angular frequency (time in units of 1 / natural angular frequency).
    restitution : float
        r [-].
    clearance : tuple of float
        (low, high) of sigma along the continuation [-] (lengths in units of the static deflection under the force).
    start_clearance : float
        sigma of the orbit the continuation starts from (on the stable side, below the period doubling) [-].
    max_steps : int
        Continuation steps per direction.
    tolerance : float
        Relative agreement required [-].
    """

    forcing_frequency: float = 2.8
    restitution: float = 0.8
    clearance: tuple[float, float] = (-0.5, 0.14)
    start_clearance: float = -0.2
    max_steps: int = 400
    tolerance: float = DEFAULT_TOLERANCE
    name = "budd_dux"


@dataclass(frozen=True)
class BouncingBallCase:
    """A ball on a table moving as A sin(w t) (Holmes 1982): period-one orbit continued in A, and a brute force.

    Attributes
    ----------
    restitution : float
        e [-].
    frequency : float
        Table frequency w / 2 pi [Hz].
    gravity : float
        g [m s-2].
    mass : float
        Ball mass [kg] (the results do not depend on it).
    acceleration : tuple of float
        (low, high) of Gamma = A w^2 / g along the continuation and the brute force [-].
    brute_step : float
        Step of Gamma of the brute-force diagram [-].
    transient_periods, strobes : int
        Periods simulated before recording, and strobes recorded, at each brute-force point.
    tolerance : float
        Relative agreement required [-].
    """

    restitution: float = 0.5
    frequency: float = 10.0
    gravity: float = 9.81
    mass: float = 1.0
    acceleration: tuple[float, float] = (0.9, 2.0)
    brute_step: float = 0.01
    transient_periods: int = 200
    strobes: int = 16
    tolerance: float = DEFAULT_TOLERANCE
    name = "bouncing_ball"


@dataclass(frozen=True)
class ZenoCase:
    """A ball dropped from rest at height h on a fixed table: time to come to rest, engine by engine.

    Attributes
    ----------
    height : float
        h [m].
    restitution : float
        e [-].
    gravity : float
        g [m s-2].
    mass : float
        Ball mass [kg].
    frequency : float
        The engines' period 1 / frequency [s] (nothing is forced: it sets the strobes and the velocity scale g / w
        the sticking velocity is a fraction of) [Hz].
    sticking_velocity : float
        The engines' sticking velocity as a fraction of the velocity scale [-].
    rtol : float
        Relative tolerance of the integrators (atol = rtol x 1e-4 m) [-].
    engines : tuple of str
        Rigid-stop engines to run.
    tolerance : float
        Relative agreement required of the exact engines, on top of the sticking bound [-].
    """

    height: float = 1.0
    restitution: float = 0.5
    gravity: float = 9.81
    mass: float = 1.0
    frequency: float = 1.0
    sticking_velocity: float = 1e-6
    rtol: float = 1e-10
    engines: tuple[str, ...] = ZENO_ENGINES
    tolerance: float = DEFAULT_TOLERANCE
    name = "zeno"


@dataclass(frozen=True)
class GrazingCase:
    """m x'' + c x' + k x = A cos(w t) with a stop at x = d: where impacts begin as A grows.

    Attributes
    ----------
    mass, stiffness, damping : float
        m [kg], k [N m-1], c [N s m-1].
    frequency : float
        w / 2 pi [Hz].
    clearance : float
        d [m], > 0.
    restitution : float
        R of the stop [-].
    amplitude : tuple of float
        (low, high) of the force amplitude A along the continuation [N].
    tolerance : float
        Relative agreement required [-].
    """

    mass: float = 1.0
    stiffness: float = 1.0
    damping: float = 0.1
    frequency: float = 0.12
    clearance: float = 1.0
    restitution: float = 0.8
    amplitude: tuple[float, float] = (0.1, 1.0)
    tolerance: float = DEFAULT_TOLERANCE
    name = "grazing"


@dataclass(frozen=True)
class RelativeStopCase:
    """Ormondroyd & Den Hartog's layout: a primary mass on the base, an absorber on it, a rigid stop between the two
    (x2 - x1 <= Delta); impacts checked one by one against momentum and restitution.

    Attributes
    ----------
    m1, m2, k1, k2, b1, b2 : float
        Masses [kg], stiffnesses [N m-1], dampings [N s m-1] (the paper's named form).
    amplitude : float
        Force on the primary mass [N].
    frequency : float
        [Hz].
    clearance : float
        Delta [m].
    restitution : float
        R [-].
    periods : int
        Periods of the run.
    tolerance : float
        Relative agreement required [-].
    """

    m1: float = 1.0
    m2: float = 0.1
    k1: float = 25000.0
    k2: float = 4300.0
    b1: float = 0.8
    b2: float = 0.08
    amplitude: float = 10.0
    frequency: float = 24.0
    clearance: float = 0.003
    restitution: float = 0.6
    periods: int = 2000
    tolerance: float = DEFAULT_TOLERANCE
    name = "relative_stop"


#: Every case a validation scene may be.
ValidationCase = Union[BuddDuxCase, BouncingBallCase, ZenoCase, GrazingCase, RelativeStopCase]
_CLASSES = (BuddDuxCase, BouncingBallCase, ZenoCase, GrazingCase, RelativeStopCase)
#: Case name -> class.
VALIDATION_CASES = {cls.name: cls for cls in _CLASSES}
#: Where each case's closed form is published (what its tests and report cite).
CASE_SOURCES = {
    "budd_dux": "C. J. Budd and F. Dux, Chattering and related behaviour in impact oscillators, Phil. Trans. R. Soc. A 347 (1994) 365-389",
    "bouncing_ball": "P. J. Holmes, The dynamics of repeated impacts with a sinusoidally vibrating table, J. Sound Vib. 84 (1982) 173-189",
    "zeno": "the geometric series of the bounces of a ball dropped on a fixed table (e.g. Budd & Dux 1994, section 3, on chatter)",
    "grazing": "the linear steady state of a forced oscillator reaching the stop (e.g. Nordmark, J. Sound Vib. 145 (1991) 279)",
    "relative_stop": "Newton's impact law on a stop between two bodies: conservation of momentum and restitution of the relative velocity",
}

_POSITIVE = (0.0, math.inf, False, True)
#: Parameters of each case: key -> Parameter (every key is optional: the dataclass gives the default).
CASE_PARAMETERS: dict[str, dict[str, Parameter]] = {
    "budd_dux": {
        "forcing_frequency": Parameter("1", 0.0, math.inf, False, True, help="w, forcing over natural angular frequency (w != 1, sin(2 pi / w) != 0)"),
        "restitution": Parameter("1", 0.0, 1.0, False, False, help="r"),
        "clearance": Parameter("1", -10.0, 10.0, kind="range", help="range of sigma continued"),
        "start_clearance": Parameter("1", -10.0, 10.0, help="sigma of the first orbit"),
        "max_steps": Parameter("1", 1, 100_000, kind="integer", help="continuation steps per direction"),
        "tolerance": _tolerance(),
    },
    "bouncing_ball": {
        "restitution": Parameter("1", 0.0, 1.0, False, False, help="e"),
        "frequency": Parameter("Hz", *_POSITIVE, help="table frequency"),
        "gravity": Parameter("m s-2", *_POSITIVE, help="g"),
        "mass": Parameter("kg", *_POSITIVE, help="ball mass"),
        "acceleration": Parameter("1", 0.0, 100.0, False, True, kind="range", help="range of Gamma = A w^2 / g"),
        "brute_step": Parameter("1", 0.0, 10.0, False, True, help="Gamma step of the brute force"),
        "transient_periods": Parameter("1", 0, 100_000, kind="integer", help="periods before recording"),
        "strobes": Parameter("1", 1, 1000, kind="integer", help="strobes recorded per point"),
        "tolerance": _tolerance(),
    },
    "zeno": {
        "height": Parameter("m", *_POSITIVE, help="drop height h"),
        "restitution": Parameter("1", 0.0, 1.0, True, False, help="e"),
        "gravity": Parameter("m s-2", *_POSITIVE, help="g"),
        "mass": Parameter("kg", *_POSITIVE, help="ball mass"),
        "frequency": Parameter("Hz", *_POSITIVE, help="engines' period = 1 / frequency"),
        "sticking_velocity": Parameter("1", 0.0, 1e-2, False, True, help="sticking velocity / velocity scale"),
        "rtol": Parameter("1", 1e-14, 1e-3, help="integrators' relative tolerance"),
        "engines": Parameter("1", kind="engines", help="rigid-stop engines"),
        "tolerance": _tolerance(),
    },
    "grazing": {
        "mass": Parameter("kg", *_POSITIVE, help="m"),
        "stiffness": Parameter("N m-1", *_POSITIVE, help="k"),
        "damping": Parameter("N s m-1", 0.0, math.inf, True, False, help="c"),
        "frequency": Parameter("Hz", *_POSITIVE, help="w / 2 pi"),
        "clearance": Parameter("m", *_POSITIVE, help="d"),
        "restitution": Parameter("1", 0.0, 1.0, True, True, help="R"),
        "amplitude": Parameter("N", 0.0, math.inf, False, False, kind="range", help="range of A continued"),
        "tolerance": _tolerance(),
    },
    "relative_stop": {
        **{key: Parameter(unit, *_POSITIVE, help=key) for key, unit in (("m1", "kg"), ("m2", "kg"), ("k1", "N m-1"), ("k2", "N m-1"))},
        **{key: Parameter("N s m-1", 0.0, math.inf, True, False, help=key) for key in ("b1", "b2")},
        "amplitude": Parameter("N", *_POSITIVE, help="force on the primary mass"),
        "frequency": Parameter("Hz", *_POSITIVE, help="forcing frequency"),
        "clearance": Parameter("m", *_POSITIVE, help="Delta of x2 - x1 <= Delta"),
        "restitution": Parameter("1", 0.0, 1.0, True, True, help="R"),
        "periods": Parameter("1", 1, 1_000_000, kind="integer", help="periods of the run"),
        "tolerance": _tolerance(),
    },
}


@dataclass(frozen=True)
class ValidationSettings:
    """A validation scene's case (one of :data:`VALIDATION_CASES`) and its source."""

    case: ValidationCase = field(default_factory=BuddDuxCase)

    @property
    def name(self) -> str:
        """The case's name."""
        return self.case.name

    @property
    def source(self) -> str:
        """The publication whose closed form the case reproduces."""
        return CASE_SOURCES[self.case.name]


#: ``validation.case``, declared: which published closed form.
CASE_KEY = Key("case", str, "the published closed form reproduced", REQUIRED, choices=tuple(VALIDATION_CASES))
#: ``validation`` of each case, declared (one form per case): the case's parameters, their defaults the case's own.
def _case_section(name: str) -> Section:
    """The ``validation`` section of the case ``name``: its parameters, each default the case dataclass's own."""
    defaults = {field.name: field.default for field in dataclasses.fields(VALIDATION_CASES[name])}
    keys = (_key(key, parameter, defaults[key]) for key, parameter in CASE_PARAMETERS[name].items())
    return Section("validation", (CASE_KEY, *keys), f"the {name} case: {CASE_SOURCES[name]}", form=f"case: {name}")


CASE_SECTIONS = {name: _case_section(name) for name in CASE_PARAMETERS}
#: The sections of a validation scene that are declared (``run-study --keys`` lists them).
SECTIONS = tuple(CASE_SECTIONS.values())
