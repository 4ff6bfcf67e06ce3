"""One worst-case entry point (issue 47): every method judges the measure it is handed, and on a design whose worst
motion is the one-impact orbit they agree with each other and with the closed form's own maximum of that measure,
found here by an independent bounded search over the frequency."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.engines.exact import ExactEngine
from vibroimpact.measures.table import Measure, measure, measure_names
from vibroimpact.measures.worst_case import METHODS, BandMaximum, worst_case
from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop, loss_factor_from_restitution
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM

pytestmark = pytest.mark.skipif(not hasattr(ExactEngine, "strobe_map"), reason="needs the compiled exact core (ExactEngine.strobe_map)")

PROBLEM = ImpactProblem(PAPER_SYSTEM, RigidStop(0.003, 0.2), HarmonicForce(10.0, 25.0))
BAND = (24.5, 26.0)
#: Each method's options, small enough for the default tier.
OPTIONS = {"closed_form": {}, "continuation": {}, "brute_force": {"frequencies": 7, "starts": 1, "transient": 100}, "certified": {"frequencies": 7, "starts": 1, "transient": 100}}


def closed_form_maximum(coordinate: int) -> tuple[float, float]:
    """(largest |X| of ``coordinate`` [m], where [Hz]) of the stable one-impact orbit over the band, by a bounded
    search on the closed form alone (the whole band is that orbit's: tests/simulation/test_attractors.py)."""
    found = minimize_scalar(lambda f: -float(np.abs(solve_impact_orbit(PROBLEM, frequency=np.array([f]), root="+").harmonics())[0, coordinate]),
                            bounds=BAND, method="bounded", options={"xatol": 1e-10})  # fmt: skip
    return -float(found.fun), float(found.x)


def test_the_table_names_each_coordinate() -> None:
    assert measure_names(("x1", "x2", "x3")) == ("x1_amplitude", "x2_amplitude", "x3_amplitude")
    row = measure("x3_amplitude", ("x1", "x2", "x3"))
    assert (row.coordinate, row.unit) == (2, "m")
    with pytest.raises(ValueError, match="unknown measure 'x3_amplitude': allowed x1_amplitude, x2_amplitude"):
        measure("x3_amplitude")
    with pytest.raises(ValueError, match="coordinate"):
        Measure("bad", "m", "bad", -1)


@pytest.mark.parametrize("name", ["x1_amplitude", "x2_amplitude"])
@pytest.mark.parametrize("method", list(OPTIONS))
def test_every_method_judges_the_measure_it_is_handed(method: str, name: str) -> None:
    """Located methods (closed form, continuation, certified) reach the closed form's maximum to 1e-6; brute force,
    on a 0.25 Hz grid, is below it by at most the grid's h^2 |X''| / 8 (here < 2 %) and never above it."""
    found = worst_case(PROBLEM, BAND, name, method, **OPTIONS[method])
    assert isinstance(found, BandMaximum) and found.method == method and found.measure.name == name
    exact, where = closed_form_maximum(found.measure.coordinate)
    if method == "brute_force":
        assert exact * (1.0 - 0.02) <= found.value <= exact * (1.0 + 1e-7)
    else:
        assert found.value == pytest.approx(exact, rel=1e-6)
        assert found.frequency == pytest.approx(where, abs=1e-3)


def test_bumper_orbits_judge_the_measure_too() -> None:
    """A stiff bumper (20 kHz, the rigid stop's restitution): its worst |X| of each coordinate is the rigid stop's to
    its stiffness (the README's 26.4 Hz / f relative: 1.3e-3), and brute force of the bumper's own engine, on a 0.25 Hz
    grid, is at most that and within 2 % of it."""
    bumper = ImpactProblem(PAPER_SYSTEM, KelvinVoigtBumper(0.003, 20_000.0, loss_factor_from_restitution(0.2)), HarmonicForce(10.0, 25.0))
    for name in ("x1_amplitude", "x2_amplitude"):
        located = worst_case(bumper, BAND, name, "bumper_orbits")
        assert located.value == pytest.approx(closed_form_maximum(located.measure.coordinate)[0], rel=3e-3)
        brute = worst_case(bumper, BAND, name, "brute_force", **OPTIONS["brute_force"])
        assert located.value * (1.0 - 0.02) <= brute.value <= located.value * (1.0 + 1e-6)


def test_refusals_name_what_is_allowed() -> None:
    with pytest.raises(ValueError, match="method = 'newton': allowed closed_form, bumper_orbits, continuation, brute_force, certified"):
        worst_case(PROBLEM, BAND, "x1_amplitude", "newton")
    with pytest.raises(ValueError, match="unknown measure 'force_amplitude'"):
        worst_case(PROBLEM, BAND, "force_amplitude", "closed_form")
    assert set(METHODS) == {"closed_form", "bumper_orbits", "continuation", "brute_force", "certified"}
