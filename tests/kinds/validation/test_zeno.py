"""The Zeno time of a ball dropped on a fixed table, reached by the chattering-to-sticking logic of every rigid-stop
engine (studies/validation/zeno.yaml)."""

from __future__ import annotations

import math

import pytest

from vibroimpact.engines.registry import RIGID, engine_names
from vibroimpact.kinds.validation.settings import ZenoCase
from vibroimpact.kinds.validation.formulas import zeno_sticking_bounds, zeno_time
from vibroimpact.kinds.validation.study import run_zeno

#: Every registered rigid-stop engine the case knows (``momentary`` is ``momentary_adams``).
ENGINES = tuple(name for name in engine_names(RIGID) if name != "momentary")


def test_every_engine_reaches_the_zeno_time() -> None:
    """Zeno time sqrt(2h/g)(1+e)/(1-e) (the geometric series of the bounces; e.g. Budd & Dux, Phil. Trans. R. Soc. A
    347 (1994) 365, on chatter). Each engine sticks the ball at the first impact no faster than v_s = 1e-6 g / w, so
    it stops 2 e v_n / (g (1 - e)) early with v_n in (e v_s, v_s]: 2.35e-7 of t_Z at most here. Every engine lands
    inside that bound (plus its own precision: round-off for the exact engines, ~atol / v_s for integrators), and on
    the bounce sum up to the impact that sticks."""
    case = ZenoCase(engines=ENGINES)
    outcome = run_zeno(case)
    failed = [(c.quantity, c.relative_error, c.tolerance) for c in outcome.checks if not c.passed]
    assert not failed
    t_zeno = zeno_time(case.height, case.gravity, case.restitution)
    low, high = zeno_sticking_bounds(case.restitution, case.gravity, outcome.data.attrs["sticking_velocity_m_s"])
    for name, t_stick in zip(outcome.data["engine"].values, outcome.data["sticking_time"].values):
        assert low - 1e-7 * t_zeno < t_zeno - t_stick <= high + 1e-7 * t_zeno, name
    assert high / t_zeno == pytest.approx(2.35e-7, rel=0.01)


def test_a_smaller_sticking_velocity_tightens_the_exact_engines() -> None:
    """With v_s = 1e-10 of the velocity scale the exact engines stop within 1e-8 relative of the Zeno time (the bound
    is 2.4e-11)."""
    engines = tuple(name for name in ("exact", "exact_python") if name in ENGINES)
    if not engines:
        pytest.skip("no exact engine registered")
    outcome = run_zeno(ZenoCase(engines=engines, sticking_velocity=1e-10))
    for c in outcome.checks:
        assert c.passed, c
        if c.quantity.startswith("Zeno time"):
            assert c.relative_error < 1e-8
    assert all(math.isfinite(t) for t in outcome.data["sticking_time"].values)
