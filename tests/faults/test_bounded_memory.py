"""Memory that does not grow with the run's length (issue 34, item 5): the march keeps a ring of the strobes it reads,
not every strobe (~190 MB per 10^6 periods before), and a history's size is checked as the product it allocates."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

from vibroimpact.engines.registry import make_engine
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.simulation.settings import SteadySettings
from vibroimpact.simulation.steady import MAX_HISTORY_SAMPLES, march, steady_state


def _peak_march(periods: int) -> tuple[int, int]:
    """Peak traced memory [bytes] and periods integrated of a march that never repeats (a chaotic motion)."""
    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(0.003, 0.8), HarmonicForce(10.0, 35.5))
    engine = make_engine("exact")
    settings = SteadySettings(max_periods=periods, chunk_periods=500)
    march(engine, problem, 0.0, np.zeros(4), settings, max_periods=50)  # compiled and warmed outside the measurement
    tracemalloc.start()
    try:
        _t, _y, multiplicity, used = march(engine, problem, 0.0, np.zeros(4), settings)
        return tracemalloc.get_traced_memory()[1], used if multiplicity == 0 else -1
    finally:
        tracemalloc.stop()


@pytest.mark.faults
@pytest.mark.timeout(600)
def test_a_march_holds_the_same_memory_for_ten_times_the_periods() -> None:
    short, short_used = _peak_march(2_000)
    long, long_used = _peak_march(20_000)
    assert (short_used, long_used) == (2_000, 20_000)  # chaotic: neither repeats, both march to the end
    # 18 000 strobes more held ~2.7 MB before; a chunk's own arrays are the same in both
    assert long - short < 300_000, (short, long)


@pytest.mark.faults
def test_a_history_s_size_is_checked_as_a_product_before_it_is_allocated() -> None:
    result = steady_state("exact", ImpactProblem(PAPER_SYSTEM, RigidStop(0.003, 0.5), HarmonicForce(10.0, 25.0)))
    with pytest.raises(ValueError, match=r"^periods x samples_per_period = 1000000 x 10000000 = 1e\+13 samples is out of range"):
        result.history(periods=1_000_000, samples_per_period=10_000_000)  # each alone is allowed
    assert result.history(periods=2, samples_per_period=100).time.size == 201
    assert MAX_HISTORY_SAMPLES >= 1_000_000
