"""Bifurcation studies of any layout: the paper's scene written with matrices gives the named form's study, relative
two-sided stops continue their symmetric two-impact orbit, and a layout without a closed form gets its orbits from the
brute force, with its variables named after its coordinates."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from tests.golden.golden import SCENES, page_text
from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.reporting.page import write_report
from vibroimpact.scene import parse_scene, read_yaml
from vibroimpact.kinds.bifurcation.study import diagram_problem
from vibroimpact.kinds.bifurcation.branches import ORIGINS, closed_form_orbits
from vibroimpact.runs.run import run_study

pytestmark = pytest.mark.slow  # a whole study per module: the slow tier (issue 49, measured)

#: The paper's system as matrices (k1 + k2 = 29300, b1 + b2 = 0.88), force on x1: the named form's structure.
MATRICES = {"mass": [[1.0, 0.0], [0.0, 0.1]], "stiffness": [[29300.0, -4300.0], [-4300.0, 4300.0]], "damping": [[0.88, -0.08], [-0.08, 0.08]], "coordinates": ["x1", "x2"]}
#: The golden bifurcation scene shrunk to the one-impact branch of R = 0.2 over 20-27 Hz, which holds a grazing point
#: at each end, a Neimark-Sacker point (21.21 Hz), a period doubling (26.58 Hz) and a fold (26.70 Hz).
SHRUNK = {
    "frequency": {"start": 20.0, "stop": 27.0},
    "restitution": [0.2],
    "brute_force": {"step": 1.0, "transient_periods": 20, "strobes": 16},
    "continuation": {"max_steps": 300, "max_step": 0.2, "brute_force": False, "period_doubling": False, "grazing": False, "linear": False},
}


def named_and_twin() -> tuple[dict, dict]:
    """The shrunk golden scene in the paper's named form, and the same written in the general form."""
    named = read_yaml((SCENES / "bifurcation.yaml").read_text(encoding="utf-8"))
    named["bifurcation"] = copy.deepcopy(SHRUNK)
    twin = copy.deepcopy(named)
    twin["system"] = copy.deepcopy(MATRICES)
    twin["excitation"] = {"amplitude": 10.0, "on": "x1"}
    del twin["stop"]
    twin["stops"] = [{"coordinate": "x2", "side": "upper", "clearance": 0.003, "restitution": 0.2}]
    del twin["bifurcation"]["restitution"]
    return named, twin


@pytest.fixture(scope="module")
def twins(tmp_path_factory: pytest.TempPathFactory) -> tuple[xr.Dataset, xr.Dataset, str, str]:
    named, twin = named_and_twin()
    out = []
    for doc, tag in ((named, "named"), (twin, "twin")):
        dataset = run_study(parse_scene(doc), progress=None)
        page = write_report(dataset, tmp_path_factory.mktemp(tag))
        out += [dataset, page_text(page.read_text(encoding="utf-8"))]
    return out[0], out[2], out[1], out[3]


def test_the_twin_parses_to_the_named_scenes_problem() -> None:
    named, twin = (parse_scene(doc) for doc in named_and_twin())
    assert twin.layout.paper_view() is not None and named.layout.paper_view() is not None  # the paper's layout, however written
    for r in (0.2, 0.8):
        a, b = diagram_problem(named, r), diagram_problem(twin, r)
        assert a.structure == b.structure and a.stops == b.stops
        assert np.array_equal(a.load()[0], b.load()[0]) and np.array_equal(a.load()[1], b.load()[1])


def test_the_matrix_twin_gives_the_same_special_points_names_and_page(twins) -> None:
    named, twin, named_page, twin_page = twins
    kinds = named["special_point_kind"].values
    assert set(kinds.tolist()) == {0, 1, 2, 3}  # fold, period doubling, Neimark-Sacker, grazing: all four are compared
    assert np.array_equal(kinds, twin["special_point_kind"].values)
    assert np.max(np.abs(named["special_point_frequency"].values - twin["special_point_frequency"].values)) < 1e-6  # [Hz]
    assert set(named.variables) == set(twin.variables)
    assert {"x1_amplitude", "x2_amplitude", "special_point_x1_amplitude", "brute_x1", "brute_x1_amplitude"} <= set(named.variables)
    assert named_page == twin_page
    assert "R = 0.2: up to |X1| =" in named_page and "stops: x2 <= 3 mm" in named_page


def test_the_one_impact_branch_is_the_closed_form_of_the_general_problem(twins) -> None:
    named = twins[0]
    one = named.where(named["branch_origin"] == ORIGINS.index("one_impact"), drop=True)
    f = one["branch_frequency"].values
    assert f.size > 50 and f.min() < 20.7 and f.max() > 26.6
    plus, minus = (orbit.impulse for orbit in closed_form_orbits(diagram_problem(parse_scene(named_and_twin()[1]), 0.2), f))
    impulse = one["impulse"].values
    closest = np.where(np.abs(plus - impulse) < np.abs(minus - impulse), plus, minus)
    assert np.nanmax(np.abs(impulse - closest) / np.nanmax(plus)) < 1e-8


RELATIVE = """
name: relative
system:
  mass: [[1.0, 0.0], [0.0, 0.1]]
  stiffness: [[29300.0, -4300.0], [-4300.0, 4300.0]]
  damping: [[0.88, -0.08], [-0.08, 0.08]]
  coordinates: [x1, x2]
excitation: {amplitude: 10.0, on: x1}
stops:
  - {between: [x2, x1], side: upper, clearance: 0.003}
  - {between: [x2, x1], side: lower, clearance: 0.003}
bifurcation:
  frequency: {start: 21.5, stop: 23.0}
  restitution: [0.2]
  brute_force: {step: 0.25, transient_periods: 150, strobes: 16, directions: [up]}
  continuation: {max_steps: 200, brute_force: false, period_doubling: false, grazing: false}
"""


def test_relative_two_sided_stops_continue_the_symmetric_two_impact_orbit() -> None:
    scene = parse_scene(read_yaml(RELATIVE))
    data = run_study(scene, progress=None)
    assert data.attrs["stop_layout"] == "x2 - x1 <= 3 mm; x2 - x1 >= -3 mm"
    two = data.where(data["branch_origin"] == ORIGINS.index("two_impacts"), drop=True)
    assert two.sizes["branch_point"] > 10 and np.all(two["impacts_per_period"].values == 2)
    f = two["branch_frequency"].values
    problem = diagram_problem(scene, 0.2)
    orbit = solve_impact_orbit(problem, omega=2.0 * np.pi * f)
    assert orbit.two_sided
    # two impacts of J each per period, one on each side, half a period apart
    assert np.nanmax(np.abs(two["impulse"].values - 2.0 * orbit.impulse)) < 1e-8 * np.nanmax(2.0 * orbit.impulse)
    # the linear orbit fits inside the stops up to 21.92 Hz, where it grazes (|x2 - x1| reaches 3 mm)
    linear = data.where(data["branch_origin"] == ORIGINS.index("linear"), drop=True)
    assert abs(float(linear["branch_frequency"].max()) - 21.923) < 2e-3
    # where the orbit is stable the brute force settles on it: two impacts per period, each at the closed form's
    # approach speed J / (m_eff (1 + R))
    stable = two["branch_frequency"].values[two["stable"].values == 1]
    checked = 0
    for k, frequency in enumerate(data["frequency"].values):
        point = data.isel(restitution=0, sweep=0, frequency=k)
        if not stable.size or not stable.min() < frequency < stable.max():
            continue
        assert int(point["brute_period"]) == 1 and float(point["brute_impacts_per_period"]) == pytest.approx(2.0)
        speeds = point["brute_impact_velocity"].values[np.isfinite(point["brute_impact_velocity"].values)]
        expected = float(solve_impact_orbit(problem, omega=2.0 * np.pi * frequency).pre_impact_velocity)
        assert np.max(np.abs(speeds - expected)) < 1e-4 * expected
        checked += 1
    assert checked >= 2


NO_CLOSED_FORM = """
name: no_closed_form
system:
  mass: [[1.0, 0.0], [0.0, 0.1]]
  stiffness: [[29300.0, -4300.0], [-4300.0, 4300.0]]
  damping: [[0.88, -0.08], [-0.08, 0.08]]
  coordinates: [primary, absorber]
excitation: {amplitude: 10.0, on: primary}
stops:
  - {coordinate: absorber, side: upper, clearance: 0.003, restitution: 0.8}
  - {coordinate: primary, side: upper, clearance: 0.003, restitution: 0.8}
bifurcation:
  frequency: {start: 23.5, stop: 24.5}
  brute_force: {step: 0.25, transient_periods: 150, strobes: 16}
  continuation: {max_steps: 100, period_doubling: false, grazing: false}
"""


def test_a_layout_without_closed_form_is_found_by_the_brute_force() -> None:
    """Two stops that are no symmetric pair: no closed form, the branches come from the brute force. Over this band
    the one-impact orbit on the absorber keeps the primary mass below 2.7 mm, so it never touches its stop: the
    seeded branch is the closed form of the absorber's stop alone."""
    scene = parse_scene(read_yaml(NO_CLOSED_FORM))
    data = run_study(scene, progress=None)
    assert "no closed-form orbit for this layout" in data.attrs["continuation_notes"]
    assert {"primary_amplitude", "absorber_amplitude", "special_point_primary_amplitude", "brute_primary", "brute_primary_amplitude"} <= set(data.variables)
    assert "x1_amplitude" not in data and "coordinate absorber" in data["absorber_amplitude"].attrs["long_name"]
    seeded = data.where(data["branch_origin"] == ORIGINS.index("brute_force"), drop=True)
    assert seeded.sizes["branch_point"] > 5 and np.all(seeded["impacts_per_period"].values == 1)
    problem = diagram_problem(scene, 0.8)
    alone = ImpactProblem(problem.system, problem.stops[:1], problem.excitation)
    orbit = solve_impact_orbit(alone, omega=2.0 * np.pi * seeded["branch_frequency"].values)
    assert np.nanmax(orbit.displacement(np.linspace(0.0, 1.0, 256)[None, :] * orbit.period[:, None])[..., 0]) < 2.9e-3
    assert np.max(np.abs(seeded["impulse"].values - orbit.impulse)) < 1e-8 * np.max(orbit.impulse)


def test_the_page_of_a_general_layout_names_its_coordinate_and_stops(tmp_path: Path) -> None:
    data = run_study(parse_scene(read_yaml(NO_CLOSED_FORM)), progress=None)
    text = page_text(write_report(data, tmp_path).read_text(encoding="utf-8"))
    assert "stops: absorber <= 3 mm; primary <= 3 mm" in text and "|primary| =" in text and "no branch from the closed form" in text
    assert "top: the primary fundamental" in text
