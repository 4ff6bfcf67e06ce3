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
from vibroimpact.scene.schema import SIMULATION_STARTS
from vibroimpact.scene.subset import Subset, parse_subset
from vibroimpact.simulation.settings import SteadySettings

__all__ = ["SimulationSettings", "SIMULATION_KEYS", "parse_simulation", "tolerances"]

#: Every key of a ``simulation`` section (a kind reads some of them).
SIMULATION_KEYS = frozenset({"frequency", "start", "method", "rtol", "atol", "max_step", "tolerance", "max_periods", "measure_periods", "irregular_measure_periods", "lyapunov_periods", "subset"})
_T = TypeVar("_T")


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
    spec = dict(c.mapping("simulation", value, set(allowed)))
    spec.update(tolerances(spec, swept))
    frequency: np.ndarray | None = c.grid("simulation.frequency", spec["frequency"], 0.0, math.inf, False) if "frequency" in spec else default_frequency
    start = spec.get("start", "pgf")
    if start not in SIMULATION_STARTS:
        c.fail("simulation.start", f"{start!r} is not allowed: use one of {', '.join(SIMULATION_STARTS)}")
    engine_kwargs = {k: spec[k] for k in ("method", "rtol", "atol", "max_step") if k in spec}
    steady_kwargs = {k: spec[k] for k in ("tolerance", "max_periods", "measure_periods", "irregular_measure_periods", "lyapunov_periods") if k in spec}
    engine = _settings(c, EngineSettings, engine_kwargs)
    steady = _settings(c, SteadySettings, steady_kwargs)
    subset: Subset = {}
    if "subset" in spec and frequency is not None and start in SIMULATION_STARTS:
        subset = parse_subset(c, spec["subset"], engines or [], {"frequency": frequency, **(axes or {})}, start)
    if frequency is None or start not in SIMULATION_STARTS or engine is None or steady is None:
        return None
    return SimulationSettings(frequency=frequency, start=start, engine=engine, steady=steady, subset=subset)


def _settings(c: Checker, kind: type[_T], kwargs: dict[str, Any]) -> _T | None:
    """Build a settings dataclass, turning its validation errors into scene problems under ``simulation.``."""
    for key, item in kwargs.items():
        if isinstance(item, bool) or not isinstance(item, (int, float, str)):
            c.fail(f"simulation.{key}", f"expected a number or name, got {item!r}")
            return None
    try:
        return kind(**kwargs)
    except (ValueError, TypeError) as error:
        c.fail_settings("simulation", error)
        return None
