"""The table of hard cases (``cases.py``) run against every engine: each (case, engine) pair is one test.

The default tier runs the reference ``exact`` and the default integrator (``momentary_adams``) on every case; the
other engines' rows are the ``hard`` tier (``pytest -m hard``), and the longest runs the ``slow`` tier.

A pair whose engine does not apply is reported as skipped with the table's reason; nothing is left out silently
(``test_every_case_names_every_engine``). A failure lists every requirement that did not hold, with the measured
value and its bound, and all the measurements of the run.
"""

from __future__ import annotations

import math

import pytest

from .cases import CASES, ENGINE_NAMES, RIGID, Expect, HardCase, NotRun
from .runs import exact_run, measure, run_case


#: Engines whose rows run in the default tier; the rest of the table is the ``hard`` tier (``pytest -m hard``).
DEFAULT_TIER_ENGINES = ("exact", "momentary_adams")


def _params() -> list:
    params = []
    for case in CASES:
        for engine in ENGINE_NAMES:
            expect = case.expect[engine]
            marks = [pytest.mark.timeout(case.timeout)]
            if case.slow:
                marks.append(pytest.mark.slow)
            elif case.long or engine not in DEFAULT_TIER_ENGINES:
                marks.append(pytest.mark.hard)
            if isinstance(expect, NotRun):
                marks.append(pytest.mark.skip(reason=f"{engine} does not run {case.id}: {expect.reason}"))
            params.append(pytest.param(case, engine, id=f"{case.id}-{engine}", marks=marks))
    return params


def test_every_case_names_every_engine() -> None:
    """Every case says, for every engine, what holds or why it does not run; relaxed counts say why."""
    ids = [case.id for case in CASES]
    assert len(set(ids)) == len(ids)
    for case in CASES:
        assert set(case.expect) == set(ENGINE_NAMES), case.id
        for engine, expect in case.expect.items():
            if isinstance(expect, NotRun):
                assert engine != "exact" and expect.reason, (case.id, engine)
        if case.reference is not None:
            assert any(isinstance(e, Expect) and e.reference is not None for e in case.expect.values()), case.id


def judge(case: HardCase, engine: str, expect: Expect, m: dict[str, float]) -> list[str]:
    """Every requirement of ``expect`` (and the ones that always hold) that the measurements ``m`` break."""
    broken: list[str] = []

    def require(ok: bool, what: str) -> None:
        if not ok:
            broken.append(what)

    def at_most(key: str, bound: float | None, what: str) -> None:
        if bound is not None:
            value = m.get(key, math.inf)
            require(value <= bound, f"{what}: {value:.3g} > {bound:.3g}")

    # always
    if engine in RIGID:
        require(m["law_speed"] == 0.0, f"{m['law_speed']:g} impacts with a pre-impact speed <= 0")  # exact: a count
        at_most("law_position", 0.0, "absorber not at the stop just after an impact [m]")
        at_most("law_velocity", 1e-12, "X2'+ = -R X2'- (or 0 when it sticks), relative error")
        at_most("law_impulse", 1e-12, "impulse M2 (1 + R) X2'- (or M2 X2'- when it sticks), relative error")
        if expect.penetration is not None:
            at_most("penetration", expect.penetration, "X2 - Delta at strobes and segment starts / length scale")
            require(m["flow_exceedances"] == 0, f"{m['flow_exceedances']:g} free segments whose flow passes the stop by more than {expect.penetration:g} of the length scale (missed contacts)")
    else:
        require(m["contact_speed"] == 0, f"{m['contact_speed']:g} contacts begun at the surface at a negative speed")
        require(m["contact_impulse_sign"] == 0, f"{m['contact_impulse_sign']:g} contacts with an impulse <= 0")
        require(m["contact_unreleased"] in (0.0, 1.0), f"{m['contact_unreleased']:g} contacts never released")
        at_most("penetration", m["penetration_bound"], "penetration / length scale beyond entry speed / Omega_b + static load / K")
        at_most("contact_restitution", expect.restitution, "-X2'+ / X2'- against R(xi_b)")
        at_most("contact_impulse", expect.impulse, "impulse against M2 (X2'- - X2'+), relative")
    # the count of impacts (contacts)
    if expect.impacts == "none":
        require(m["impacts"] == 0, f"{m['impacts']:g} impacts where there must be none")
    elif "exact_impacts" in m and expect.impacts == "same":
        require(m["impacts"] == m["exact_impacts"], f"{m['impacts']:g} impacts, exact has {m['exact_impacts']:g}")
    elif "exact_impacts" in m and expect.impacts == "at_least":
        require(m["impacts"] >= m["exact_impacts"], f"{m['impacts']:g} impacts, fewer than exact's {m['exact_impacts']:g}")
    # agreement with exact
    if "exact_impacts" in m:
        if expect.times is not None and m["exact_impacts"] > 0:
            require("times" in m, "impact times not comparable (different counts)")
            at_most("times", expect.times, "impact times against exact's [s]")
        at_most("states", expect.states, "strobe states against exact's / scale")
        at_most("x1", expect.x1, "|X1| fundamental against exact's, relative")
        if expect.sticking and engine in RIGID:
            require(m["sticks"] == m["exact_sticks"] and m["releases"] == m["exact_releases"], f"sticks/releases {m['sticks']:g}/{m['releases']:g}, exact {m['exact_sticks']:g}/{m['exact_releases']:g}")
            require(abs(m["stuck_time"] - m["exact_stuck_time"]) <= 1e-6 * m["exact_stuck_time"], f"stuck time {m['stuck_time']!r} s, exact {m['exact_stuck_time']!r} s")
    if expect.sticking and engine == "exact":
        require(m["releases"] > 0, "exact is never released from sticking: the case lost its point")
    at_most("energy", expect.energy, "energy balance residual / work")
    at_most("reference", expect.reference, f"distance from the {case.reference} reference")
    return broken


@pytest.mark.parametrize(("case", "engine"), _params())
def test_hard_case(case: HardCase, engine: str) -> None:
    """One engine on one hard case: everything the table says must hold, holds."""
    expect = case.expect[engine]
    assert isinstance(expect, Expect)
    run = run_case(case, engine)
    measured = measure(run, expect, None if engine == "exact" else exact_run(case.id))
    broken = judge(case, engine, expect, measured)
    shown = ", ".join(f"{k}={v:.3g}" for k, v in measured.items())
    assert not broken, f"{case.id} on {engine} ({case.hard}):\n  " + "\n  ".join(broken) + f"\nmeasured: {shown}"
