"""The stroboscopic map of a problem with Kelvin-Voigt bumpers, with the bumpers' stiffness as a parameter.

:class:`BumperPeriodMap` is :class:`~vibroimpact.orbits.maps.ImpactMap` with one more parameter, the bumper period
T_b = 2 pi / Omega_b [s]: the period of the absorber's own oscillation on the bumper, Omega_b^2 = K_b / M2. The rigid
stop is its limit T_b -> 0, and the compliant model's steady states, branches and special points approach the rigid
stop's at first order in T_b: a special point continued in (frequency, T_b) with
:func:`~vibroimpact.orbits.continuation.continue_special_point` is a nearly straight curve that says which bumper
point continues which rigid one, and where a branch the rigid stop has ends as the bumper softens (a fold curve
reaching a cusp), without matching points of separate branches by distance.

Changing T_b keeps the bumper's restitution R, hence its loss factor (R depends on the loss factor alone, corrected
eq. 26): K_b and B_b = 2 M2 xi_b Omega_b scale together.

:class:`CompiledPeriodMap` is the same :class:`~vibroimpact.orbits.maps.ImpactMap` of bumpers over one period with
each evaluation the engine's compiled period alone (its image and exact Jacobian bit for bit, its contacts, nothing
that continuation watches besides): the map :func:`~vibroimpact.orbits.shooting.shoot` is given where it shoots many
orbits (the bumper screen, :mod:`~vibroimpact.orbits.bumper_screen`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from vibroimpact.model.contact import BUMPER, KelvinVoigtBumper, RigidStop
from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.parameters import BUMPER_STIFFNESS
from vibroimpact.orbits.branch import HybridInfo, MapEvaluation
from vibroimpact.orbits.maps import PARAMETERS, ImpactMap

__all__ = ["BumperPeriodMap", "CompiledPeriodMap", "BUMPER_PERIOD"]

#: The added parameter's name; its units are seconds.
BUMPER_PERIOD = "bumper_period"


@suggest_keywords
class BumperPeriodMap(ImpactMap):
    """:class:`~vibroimpact.orbits.maps.ImpactMap` of a problem whose selected stops are Kelvin-Voigt bumpers, with
    their period T_b = 2 pi / Omega_b = 1 / (Omega_b / 2 pi) [s] as the last parameter.

    Parameters
    ----------
    problem : ImpactProblem
        Harmonic force; the stops the parameters set (``stop``) carry Kelvin-Voigt bumpers of one Omega_b.
    periods, engine, bounds, stop
        As :class:`~vibroimpact.orbits.maps.ImpactMap`; ``bounds`` may bound ``bumper_period`` [s] too.
    parameter_scale : array_like, shape (6,), optional
        A unit of arclength per parameter (default :meth:`natural_scale`).

    Raises
    ------
    ValueError
        A selected stop is a rigid stop, or the selected bumpers differ in Omega_b.
    """

    parameter_names = (*PARAMETERS, BUMPER_PERIOD)

    @staticmethod
    def natural_scale(problem: ImpactProblem) -> tuple[float, ...]:
        """:meth:`ImpactMap.natural_scale` and 1 ms for the bumper period."""
        return (*ImpactMap.natural_scale(problem), 1e-3)

    def __init__(self, problem: ImpactProblem, periods: int = 1, engine: Any = None, bounds: dict[str, tuple[float, float]] | None = None,
                 stop: int | str | None = None, parameter_scale: ArrayLike | None = None, layout: Sequence[str] = ()) -> None:  # fmt: skip
        if BUMPER_STIFFNESS in layout:
            raise ValueError(f"layout = {list(layout)!r}: {BUMPER_STIFFNESS} and {BUMPER_PERIOD} set the same Omega_b: continue in one of them")
        super().__init__(problem, periods, engine, bounds, stop, parameter_scale, layout)
        laws = [problem.stops[k].law for k in self.stops]
        if problem.contact_law != BUMPER or not all(isinstance(law, KelvinVoigtBumper) for law in laws):
            raise ValueError(f"stop = {stop!r}: a bumper period needs Kelvin-Voigt bumpers on every selected stop (stops {list(self.stops)})")
        frequencies = {law.frequency for law in laws}  # type: ignore[union-attr]
        if len(frequencies) > 1:
            raise ValueError(f"stop = {stop!r}: the selected bumpers differ in Omega_b / 2 pi ({sorted(frequencies)} Hz): select one stop, or give them one")

    def _more_parameters(self, law: RigidStop | KelvinVoigtBumper) -> tuple[float, ...]:
        """T_b = 1 / (Omega_b / 2 pi) [s] of the chosen stop's bumper (NaN for a rigid stop: refused after)."""
        return (1.0 / law.frequency,) if isinstance(law, KelvinVoigtBumper) else (math.nan,)

    def _problem_before_layout(self, p: NDArray[np.float64]) -> ImpactProblem:
        """The problem with parameters (frequency, restitution, clearance, amplitude, phase, T_b); a T_b <= 0 raises
        ``ValueError`` (the rigid stop is the limit, not a member). Layout scalars after them are set on it
        (:meth:`ImpactMap.problem_at`): T_b is the bumper's period on the base structure."""
        problem = super()._problem_before_layout(p)
        period = float(p[len(PARAMETERS)])
        if not period > 0.0:
            raise ValueError(f"{BUMPER_PERIOD} = {period!r} s is out of range: allowed (0, inf)")
        stops = tuple(
            dataclasses.replace(item, law=dataclasses.replace(item.law, frequency=1.0 / period)) if k in self.stops else item for k, item in enumerate(problem.stops)
        )
        return ImpactProblem(problem.system, stops, problem.excitation)


class CompiledPeriodMap(ImpactMap):
    """:class:`~vibroimpact.orbits.maps.ImpactMap` of a problem with Kelvin-Voigt bumpers over one period, each
    evaluation its engine's compiled period (:meth:`~vibroimpact.engines.compliant.exact.CompliantExactEngine.
    compiled_period`, made once per parameter vector): the same image and exact Jacobian, and of the hybrid
    information the contacts per period only (no closest approach nor onset speeds: NaN), for
    :func:`~vibroimpact.orbits.shooting.shoot`, not for continuation. Parameters as ImpactMap's (``periods`` 1).

    Raises
    ------
    ValueError
        ``periods`` other than 1, or an engine without a compiled period (``capabilities.compiled_period``).
    """

    def __init__(self, problem: ImpactProblem, periods: int = 1, engine: Any = None, bounds: dict[str, tuple[float, float]] | None = None,
                 stop: int | str | None = None, parameter_scale: ArrayLike | None = None, layout: Sequence[str] = ()) -> None:  # fmt: skip
        super().__init__(problem, periods, engine, bounds, stop, parameter_scale, layout)
        if self.periods != 1:
            raise ValueError(f"periods = {periods!r}: a compiled period map is over one period")
        if not self.engine.capabilities.compiled_period:
            raise ValueError(f"a compiled period map needs an engine that gives its compiled period; {self.engine.name!r} does not")
        self._period: tuple[ImpactProblem, Any] | None = None  # the last parameter vector's problem and its period

    def __getstate__(self) -> dict[str, Any]:
        """The map without its caches."""
        return super().__getstate__() | {"_period": None}

    def evaluate(self, y: NDArray[np.float64], p: NDArray[np.float64]) -> MapEvaluation:
        """The state one period after ``y`` at t = 0, its exact Jacobian and the contacts; no image (NaN) where
        :meth:`ImpactMap.evaluate` has none."""
        problem = self.image_problem(y, p)
        image = None
        if problem is not None:
            last = self._period  # read once: another thread may replace it
            if last is None or last[0] is not problem:
                last = self._period = (problem, self.engine.compiled_period(problem))
            image = last[1](y)
        n = self.dimension
        if image is None:
            return MapEvaluation(np.full(n, np.nan), np.full((n, n), np.nan), None, None)
        length = self.state_scale[0]
        return MapEvaluation(image.state, image.jacobian, None, HybridInfo(image.contacts, math.nan, math.nan, 0, length, problem.omega * length))  # type: ignore[union-attr]
