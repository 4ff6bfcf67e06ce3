"""The ``simulation`` section of a scene, whatever its kind: how the time-domain solutions are run.

One parser (:func:`parse_simulation`) and one rule for the absolute tolerance a scene does not give
(:func:`tolerances`: atol = rtol times the ratio of the defaults, the ratio the guidance was measured with); each kind
names the keys it reads.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, TypeVar

import numpy as np

from vibroimpact.engines.settings import STEPPED_TOLERANCES, SWEPT_TOLERANCES, EngineSettings
from vibroimpact.scene.checker import Checker
from vibroimpact.scene.declared import DERIVED, OPTIONAL, Grid, Key, Section, Table
from vibroimpact.scene.schema import SIMULATION_STARTS
from vibroimpact.scene.subset import Subset, parse_subset
from vibroimpact.simulation.settings import SteadySettings

__all__ = ["SimulationSettings", "SIMULATION", "SIMULATION_KEYS", "parse_simulation", "tolerances"]

_T = TypeVar("_T")
_ENGINE, _STEADY = EngineSettings(), SteadySettings()
#: ``simulation``, declared (:mod:`vibroimpact.scene.declared`): the defaults and ranges are the settings' own.
SIMULATION = Section("simulation", (
    Key("frequency", Grid, "the time-domain solutions' own frequencies, merged into the dataset's (derived: the scene's grid)", DERIVED, 0.0, math.inf, "Hz",
        open_low=True),
    Key("start", str, "where each steady state starts", "pgf", choices=SIMULATION_STARTS),
    Key("method", str, "the integrator of the momentary and compliant engines", _ENGINE.method, choices=("adams", "bdf")),
    Key("rtol", float, "relative tolerance of the integrators (derived: 1e-8 stepped, 1e-7 swept)", DERIVED, 1e-15, 1e-1),
    Key("atol", float, "absolute tolerance of the displacements (derived: rtol x 1e-4 m)", DERIVED, 1e-300, 1e-1, "m"),
    Key("max_step", float, "largest integrator step (0: none)", _ENGINE.max_step, 0.0, math.inf, "s"),
    Key("tolerance", float, "a steady state's strobes agree to this fraction of the state's scale", _STEADY.tolerance, 1e-14, 1e-1),
    Key("max_periods", int, "periods simulated before a steady state is given up", _STEADY.max_periods, 1, 100_000_000),
    Key("measure_periods", int, "periods measured on a periodic steady state", _STEADY.measure_periods, 1, 1_000_000),
    Key("irregular_measure_periods", int, "periods measured on a motion that does not repeat", _STEADY.irregular_measure_periods, 1, 1_000_000),
    Key("lyapunov_periods", int, "periods of the Lyapunov run (0: none)", _STEADY.lyapunov_periods, 0, 10_000_000),
    Key("subset", Table, "{solution: {axis: [values]}}: a solution on part of the grid only", OPTIONAL),
), "how the time-domain solutions are run")  # fmt: skip
#: Every key of a ``simulation`` section (a kind reads some of them).
SIMULATION_KEYS = frozenset(SIMULATION.names)


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
    subset : mapping
        Solutions run on part of the grid only (``simulation.subset``, :mod:`~vibroimpact.scene.subset`):
        solution -> axis (``frequency`` [Hz], a swept ``restitution``, ``clearance`` [m] or ``bumper_frequency``
        [Hz]) -> the values it keeps; an axis or solution not named is kept whole.
    """

    frequency: np.ndarray
    start: str = "pgf"
    engine: EngineSettings = field(default_factory=EngineSettings)
    steady: SteadySettings = field(default_factory=SteadySettings)
    subset: Subset = field(default_factory=dict)


def tolerances(spec: dict[str, Any], swept: bool = False) -> dict[str, Any]:
    """(rtol, atol) of a ``simulation`` section: as given; an rtol alone takes atol = rtol x (atol / rtol of the
    defaults), the ratio the guidance was measured with (1e-4 m); neither: the defaults (stepped steady states, or
    swept-sine tests with ``swept``)."""
    rtol, atol = SWEPT_TOLERANCES if swept else STEPPED_TOLERANCES
    out = {"rtol": spec.get("rtol", rtol), "atol": spec.get("atol", atol)}
    if "rtol" in spec and "atol" not in spec and isinstance(spec["rtol"], (int, float)) and not isinstance(spec["rtol"], bool):
        out["atol"] = spec["rtol"] * (atol / rtol)
    return out


def parse_simulation(
    c: Checker, value: Any, default_frequency: np.ndarray | None, *, swept: bool = False, engines: list[str] | None = None,
    axes: dict[str, np.ndarray | None] | None = None, allowed: frozenset[str] | set[str] = SIMULATION_KEYS,
) -> SimulationSettings | None:  # fmt: skip
    """The ``simulation`` section of any kind: tolerances (:func:`tolerances`), steady-state settings, the simulated
    frequencies [Hz] (``default_frequency`` where it gives none) and the solutions run on part of the grid
    (``subset``, checked against ``engines`` and the swept ``axes``). ``allowed``: the keys the kind reads (a subset
    of :data:`SIMULATION_KEYS`); ``swept``: the defaults of swept-sine tests. None where something is unusable (each
    problem recorded)."""
    given = c.mapping("simulation", value, set(allowed))
    spec = SIMULATION.read(c, {key: item for key, item in given.items() if key in allowed}, partial=True)
    if spec is None:
        return None
    rules = tolerances({key: spec[key] for key in ("rtol", "atol") if spec[key] is not None}, swept)
    rtol, atol = (spec[key] if spec[key] is not None else rules[key] for key in ("rtol", "atol"))
    frequency = spec["frequency"] if "frequency" in given else default_frequency
    start = spec["start"]
    engine = steady = None
    engine_values = {"method": spec["method"], "rtol": rtol, "atol": atol, "max_step": spec["max_step"]}
    steady_values = {key: spec[key] for key in ("tolerance", "max_periods", "measure_periods", "irregular_measure_periods", "lyapunov_periods")}
    if None not in engine_values.values():
        engine = _settings(c, EngineSettings, engine_values)
    if None not in steady_values.values():
        steady = _settings(c, SteadySettings, steady_values)
    subset: Subset = {}
    if spec["subset"] is not None and frequency is not None and start is not None:
        subset = parse_subset(c, spec["subset"], engines or [], {"frequency": frequency, **(axes or {})}, start)
    if frequency is None or start is None or engine is None or steady is None:
        return None
    return SimulationSettings(frequency=frequency, start=start, engine=engine, steady=steady, subset=subset)


def _settings(c: Checker, kind: type[_T], kwargs: dict[str, Any]) -> _T | None:
    """Build a settings dataclass from declared values, turning a check of its own across them into a scene problem
    under ``simulation.``."""
    try:
        return kind(**kwargs)
    except (ValueError, TypeError) as error:
        c.fail_settings("simulation", error)
        return None
