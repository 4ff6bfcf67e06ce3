"""The trade-off between the worst |X1| and the impulse of one impact (issue 32): the front is exactly the feasible
candidates no other feasible candidate dominates, and the page draws it with the designs marked."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from vibroimpact.kinds.design.search import pareto_front

VALUES = st.lists(st.tuples(st.sampled_from([0.5, 1.0, 1.5, 2.0, np.nan]), st.sampled_from([0.0, 0.1, 0.2, 0.3, np.nan]), st.booleans()), min_size=1, max_size=30)


@given(VALUES)
@settings(max_examples=200, deadline=None)
def test_the_front_is_what_no_feasible_candidate_dominates(points) -> None:
    x, y, ok = (np.array(column) for column in zip(*points))
    front = pareto_front(x, y, ok)
    valid = ok.astype(bool) & np.isfinite(x) & np.isfinite(y)
    for i in range(x.size):
        dominated = any(valid[j] and x[j] <= x[i] and y[j] <= y[i] and (x[j] < x[i] or y[j] < y[i]) for j in range(x.size))
        assert front[i] == (valid[i] and not dominated)
    if valid.any():  # the least objective and the least impulse among the valid are each on it (at one of their ties)
        assert front[valid & (x == np.min(x[valid]))].any() and front[valid & (y == np.min(y[valid]))].any()  # exact: picked values


def test_equal_candidates_are_all_on_the_front_and_an_infeasible_one_never() -> None:
    front = pareto_front([1.0, 1.0, 0.5, 2.0], [0.2, 0.2, 0.4, 0.1], [True, True, True, False])
    assert front.tolist() == [True, True, True, False]
