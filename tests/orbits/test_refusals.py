"""The public orbit API refuses as the scene checker does (issue 50): each parameter named where it enters, with the
allowed values, before any work: a fractional count of periods, a parameter a map does not have, a non-finite or
mis-sized guess."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.orbits.continuation import continue_branch
from vibroimpact.orbits.maps import ImpactMap
from vibroimpact.orbits.shooting import ShootingError, shoot

PROBLEM = ImpactProblem(PAPER_SYSTEM, RigidStop(3e-3, 0.2), HarmonicForce(10.0, 25.0))


@pytest.mark.parametrize("periods", [1.7, 2.0, 0, -1, True, "2"])
def test_a_map_s_periods_are_a_whole_positive_count(periods: object) -> None:
    with pytest.raises(ValueError, match=r"periods = .* is out of range: allowed an integer in \[1, inf\)"):
        ImpactMap(PROBLEM, periods=periods)  # type: ignore[arg-type]
    assert ImpactMap(PROBLEM, periods=np.int16(2)).periods == 2  # a count read from an array is one


def test_a_continued_parameter_is_one_the_map_has() -> None:
    system = ImpactMap(PROBLEM)
    with pytest.raises(ValueError, match=r"parameter = 'mass\[5,5\]' is not one of the map's parameters: allowed frequency, restitution, clearance"):
        continue_branch(system, None, "mass[5,5]")  # type: ignore[arg-type]


@pytest.mark.parametrize(("guess", "parameters", "period", "error", "words"), [
    ([math.nan, 0.0, 0.0, 0.0], None, 1, ShootingError, "the guess is not finite"),  # a failed seed: counted as a failed shot
    ([0.0, 0.0, 0.0, 0.0], [math.inf, 0.2, 3e-3, 10.0, 0.0], 1, ShootingError, "the parameters is not finite"),
    ([0.0, 0.0, 0.0], None, 1, ValueError, r"guess: expected 4 values, got \[0.0, 0.0, 0.0\]"),
    ([0.0, 0.0, 0.0, 0.0], [25.0, 0.2], 1, ValueError, "parameters: expected 5 values"),
    ([0.0, 0.0, 0.0, 0.0], None, 1.5, ValueError, r"period = 1.5 is out of range"),
])  # fmt: skip
def test_shooting_names_the_input_it_cannot_start_from(guess: list[float], parameters: list[float] | None, period: object, error: type, words: str) -> None:
    system = ImpactMap(PROBLEM)
    with pytest.raises(error, match=words):
        shoot(system, guess, system.parameters if parameters is None else parameters, period)  # type: ignore[arg-type]
