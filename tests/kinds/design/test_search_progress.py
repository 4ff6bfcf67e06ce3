"""The design search's console names each batch (issue 51: "0/15 designs" stood three times with no generation
number): the first population, then each generation of at most the scene's; the runner's bar leads with it."""

from __future__ import annotations

import numpy as np
import pytest

from vibroimpact.kinds.design.search import differential_evolution
from vibroimpact.model.system import TwoDofSystem
from vibroimpact.runs.runner import Runner


class _Search:
    """What differential_evolution asks of the evaluations: bounds, scaling and a batch's scores (a bowl here)."""

    def __init__(self) -> None:
        self.bounds = np.array([[0.0, 1.0], [0.0, 1.0]])
        self.verbs: list[str] = []

    def scaled(self, unit: np.ndarray) -> np.ndarray:
        return unit

    def evaluate(self, designs: np.ndarray, stage: str, verb: str = "simulating") -> np.ndarray:
        assert stage == "global"
        self.verbs.append(verb)
        return np.sum((designs - 0.3) ** 2, axis=1)


def test_each_batch_of_the_search_is_named_by_its_generation() -> None:
    search = _Search()
    differential_evolution(search, population=4, generations=3, seed=1)  # type: ignore[arg-type]
    assert search.verbs[0] == "design: the first population"
    assert search.verbs[1:] == [f"design: generation {k} of at most 3" for k in range(1, len(search.verbs))]
    assert 2 <= len(search.verbs) <= 4


def test_the_runner_s_bar_leads_with_what_the_batch_is(system: TwoDofSystem, capsys: pytest.CaptureFixture[str]) -> None:
    from tests.kinds.stepped.test_cases import _case

    Runner(progress=True).map([_case(system, "linear", frequencies=(30.0,))], "design: generation 2 of at most 25")
    bars = [line for line in capsys.readouterr().err.replace("\r", "\n").splitlines() if "[" in line]
    assert bars and all(line.startswith("design: generation 2 of at most 25 [") for line in bars)
