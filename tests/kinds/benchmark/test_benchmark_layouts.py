"""Benchmark scenes on general layouts (matrices, a load on named coordinates or a base motion, a list of stops): the
paper's layout written so gives the named form's dataset, and the two-storey frame on a shaking base (a layout the
named form cannot express) is benchmarked against its references and its closed form."""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pytest
import xarray as xr

from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.scene import SceneError, parse_scene
from vibroimpact.runs.run import run_study

from tests.golden.golden import is_timing
from tests.scene.test_scene import PAPER_SYSTEM_SPEC

pytestmark = pytest.mark.slow  # a whole study per module: the slow tier (issue 49, measured)

PAPER_MATRICES = {"mass": [[1.0, 0.0], [0.0, 0.1]], "stiffness": [[29300.0, -4300.0], [-4300.0, 4300.0]], "damping": [[0.88, -0.08], [-0.08, 0.08]], "coordinates": ["x1", "x2"]}
#: studies/base_motion_frame.yaml's structure, base motion and two-sided stop on the absorber.
FRAME = {
    "system": {
        "mass": [[1.0, 0.0, 0.0], [0.0, 0.5, 0.0], [0.0, 0.0, 0.05]],
        "stiffness": [[20000.0, -10000.0, 0.0], [-10000.0, 10200.0, -200.0], [0.0, -200.0, 200.0]],
        "damping": [[2.0, -1.0, 0.0], [-1.0, 1.02, -0.02], [0.0, -0.02, 0.02]],
        "coordinates": ["floor1", "floor2", "absorber"],
    },
    "excitation": {"amplitude": 0.001, "base_motion": True},
    "stops": [
        {"between": ["absorber", "floor2"], "side": "upper", "clearance": 0.002, "restitution": 0.5},
        {"between": ["absorber", "floor2"], "side": "lower", "clearance": 0.002, "restitution": 0.5},
    ],
}


def named_benchmark() -> dict[str, Any]:
    """Three cases of the paper's layout (stable orbit from pgf with a bumper, a clearance 0.1 mm inside the linear
    reach from the linear start, a 1 s sweep of the compliant model) and the ladder, every method kind."""
    return {
        "name": "tiny_bench",
        "system": dict(PAPER_SYSTEM_SPEC),
        "excitation": {"amplitude": 10.0},
        "benchmark": {
            "duration": 0.2,
            "methods": ["momentary_adams", "compliant_ida", "solve_ivp_DOP853"],
            "tolerances": [1e-6],
            "repeats": 1,
            "cases": [
                {"name": "orbit", "frequency": 25.0, "restitution": 0.2, "clearance": 0.003, "start": "pgf", "bumper_frequency": 1000.0},
                {"name": "inside", "frequency": 30.0, "restitution": 0.6, "clearance_below_linear": 1e-4, "start": "linear"},
                {"name": "swept", "restitution": 0.2, "clearance": 0.003, "bumper_frequency": 250.0, "swept_sine": {"start": 24.0, "stop": 24.5, "rate": 0.5, "sample_rate": 1000.0}},
            ],
            "ladder": {"frequency": 25.0, "restitution": 0.2, "clearance": 0.003, "bumper_frequencies": [1000.0], "rtol": 1e-6, "repeats": 1},
        },
        "report": False,
    }


def as_matrices(document: dict[str, Any]) -> dict[str, Any]:
    """The same scene written generally: matrices, the force on x1, the stop on x2 taking each case's values."""
    general = copy.deepcopy(document)
    general["system"] = copy.deepcopy(PAPER_MATRICES)
    general["excitation"] = {"amplitude": 10.0, "on": "x1"}
    general["stops"] = [{"coordinate": "x2", "side": "upper"}]
    return general


#: What the matrix form may differ by from the named form, per variable: counts equal; the references (the exact engine,
#: the closed-form start) still take the named system's own route for the named form (its paper flows and receptances),
#: so the measured errors, differences of nearly equal values, move by round-off of what they difference: impact times
#: [s] by 1e-12 (measured 2.1e-14), relative errors by 1e-9 (measured 2.4e-11), fundamentals [m] by 1e-12 of themselves
#: (measured 6e-15).
ROUND_OFF = {"impact_time_error": (0.0, 1e-12), "impulse_error": (0.0, 1e-9), "final_state_error": (0.0, 1e-9), "x1_error": (0.0, 1e-9), "ladder_x1_difference": (0.0, 1e-9), "reference_x1": (1e-12, 0.0), "ladder_x1_amplitude": (1e-12, 0.0)}


@pytest.mark.timeout(120)
def test_the_paper_layout_as_matrices_gives_the_named_forms_benchmark() -> None:
    """Every measured variable of the matrix form (errors, impacts, steps, the ladder) equals the named form's to
    round-off (:data:`ROUND_OFF`), counts exactly, timings aside; the same names (x1_error, reference_x1,
    ladder_x1_amplitude ...); the layout is the paper's however written, so neither records it (a benchmark records
    a layout other than the paper's, for its page's names: test_the_frame_benchmark_page_names_its_coordinate_and_layout)."""
    named = run_study(parse_scene(named_benchmark()), progress=None)
    general = run_study(parse_scene(as_matrices(named_benchmark())), progress=None)
    assert set(general.data_vars) == set(named.data_vars) and {"x1_error", "reference_x1", "ladder_x1_amplitude"} <= set(named.data_vars)
    assert "system_size" not in general.attrs and "system_size" not in named.attrs  # one layout, however written
    assert general.attrs["ladder_description"] == named.attrs["ladder_description"]
    assert int(named["reference_impacts"].sel(case="inside", reference="exact")) > 0  # the stop is reached
    for name, variable in named.data_vars.items():
        if is_timing(str(name), variable):
            continue
        rtol, atol = ROUND_OFF.get(str(name), (0.0, 0.0))
        np.testing.assert_allclose(general[name].values, variable.values, rtol=rtol, atol=atol, err_msg=str(name))


def frame_benchmark(**changes: Any) -> dict[str, Any]:
    """The frame at 8.5 Hz, started on its stable symmetric two-impact orbit (largest |Floquet multiplier| 0.88), the
    stops' own R and Delta, a 1 kHz bumper from the case; CVODE Adams at rtol 1e-6 and 1e-13 against the bumpers' closed
    form."""
    benchmark: dict[str, Any] = {
        "duration": 1.0,
        "methods": ["momentary_adams", "compliant_cvode_adams"],
        "tolerances": [1e-6, 1e-13],
        "repeats": 1,
        "cases": [{"name": "two_impact", "frequency": 8.5, "start": "pgf", "bumper_frequency": 1000.0}],
        "ladder": {"frequency": 8.5, "bumper_frequencies": [1000.0, 5000.0], "rtol": 1e-8, "repeats": 1},
    }
    document = {"name": "frame_bench", **copy.deepcopy(FRAME), "benchmark": benchmark, "report": False}
    document.update(changes)
    return document


@pytest.fixture(scope="module")
def frame_run() -> xr.Dataset:
    return run_study(parse_scene(frame_benchmark()), progress=None)


@pytest.mark.timeout(120)
def test_the_frame_benchmark_measures_floor1_against_its_references(frame_run: xr.Dataset) -> None:
    """Variables named after the first coordinate (floor1); the compliant methods are measured against the two bumpers'
    closed form (compliant_exact): CVODE Adams at rtol 1e-13 finds its contacts and agrees with it to 1e-11 in the
    floor1 fundamental and the contact times [s] and to 1e-9 in impulses (measured 8.8e-14, 1.3e-13 s, 8.9e-12); the exact
    reference's |floor1| fundamental over the run is the closed form's (started on it: 1e-7, measured 3e-8); momentary
    at rtol 1e-6 within 1e-5, no impact missed."""
    ds = frame_run
    assert {"floor1_error", "reference_floor1", "ladder_floor1_amplitude", "ladder_floor1_difference"} <= set(ds.data_vars)
    assert "x1_error" not in ds and "floor1 fundamental" in ds["floor1_error"].attrs["long_name"]
    tight = ds.sel(case="two_impact", engine="compliant_cvode_adams", rtol=1e-13)
    assert float(tight["floor1_error"]) < 1e-11 and float(tight["impact_time_error"]) < 1e-11 and float(tight["impulse_error"]) < 1e-9
    assert int(tight["missed_impacts"]) == int(tight["extra_impacts"]) == 0
    assert int(tight["impacts"]) == int(ds["reference_impacts"].sel(case="two_impact", reference="compliant_exact")) >= 14  # two per period
    scene = parse_scene(frame_benchmark())
    assert scene.settings is not None
    problem = scene.settings.cases[0].problem
    closed = float(np.abs(solve_impact_orbit(problem).harmonics()[0]))
    assert float(ds["reference_floor1"].sel(case="two_impact", reference="exact")) == pytest.approx(closed, rel=1e-7)
    momentary = ds.sel(case="two_impact", engine="momentary_adams", rtol=1e-6)
    assert float(momentary["floor1_error"]) < 1e-5 and int(momentary["missed_impacts"]) == 0


@pytest.mark.timeout(120)
def test_the_frame_ladder_converges_to_the_rigid_stop(frame_run: xr.Dataset) -> None:
    """The closed form (pgf) within 1e-7 of exact (measured 5e-10); the bumpers' difference is their physics and
    falls like 1 / Omega_b: 5 kHz about a fifth of 1 kHz's (measured 1.3e-4 against 6.5e-4, ratio 4.98)."""
    difference = frame_run["ladder_floor1_difference"]
    assert list(frame_run["model"].values) == ["pgf", "exact", "momentary", "compliant_1000Hz", "compliant_5000Hz"]
    assert float(difference.sel(model="pgf")) < 1e-7 and float(difference.sel(model="momentary")) < 1e-6
    soft, stiff = float(difference.sel(model="compliant_1000Hz")), float(difference.sel(model="compliant_5000Hz"))
    assert 1e-5 < stiff < soft < 1e-2 and 4.0 < soft / stiff < 6.0
    assert frame_run.attrs["ladder_description"].startswith("8.5 Hz, stops absorber - floor2 <= 2 mm, R = 0.5; absorber - floor2 >= -2 mm, R = 0.5; steady states from the slightly perturbed closed-form orbit")


@pytest.mark.timeout(120)
def test_the_frame_benchmark_page_names_its_coordinate_and_layout(frame_run: xr.Dataset, tmp_path: Path) -> None:
    import matplotlib.pyplot as plt

    from vibroimpact.reporting.page import page_for

    page = page_for(frame_run)
    (section,) = page.sections(tmp_path)
    assert "Errors are of the floor1 fundamental" in section.intro and "absorber - floor2 &lt;= 2 mm" in section.intro and "base motion" in section.intro
    titles = [t.title for t in section.tables]
    assert titles[0].startswith("Cost per period") and "Cheapest way to the floor1 fundamental within a target" in titles
    assert "<th>|floor1| [mm]</th>" in next(t.html for t in section.tables if t.title.startswith("Model cost ladder"))
    assert "<th>floor1 error</th>" in section.tables[-1].html
    plt.close("all")


# (case id, change of the frame's scene, fragments of one reported problem)
MISTAKES: list[tuple[str, Callable[[dict[str, Any]], Any], list[str]]] = [
    ("own-restitution", lambda d: d["benchmark"]["cases"][0].update(restitution=0.3), ["benchmark.cases[0]:", "every stop of 'stops' gives its own restitution", "remove"]),
    ("own-clearance", lambda d: d["benchmark"]["cases"][0].update(clearance=0.003), ["benchmark.cases[0]:", "own clearance"]),
    ("ladder-own-clearance", lambda d: d["benchmark"]["ladder"].update(clearance=0.003), ["benchmark.ladder.clearance:", "own clearance"]),
    ("swept-base-motion", lambda d: d["benchmark"]["cases"].append({"name": "s", "bumper_frequency": 250.0, "swept_sine": {"start": 8.0, "stop": 9.0, "rate": 0.1}}), ["benchmark.cases[1].swept_sine:", "swept base motion"]),
    ("needs-restitution", lambda d: [s.pop("restitution") for s in d["stops"]], ["benchmark.cases[0].restitution: required key is missing"]),
    ("below-too-far", lambda d: [s.pop("clearance") for s in d["stops"]] and d["benchmark"]["cases"][0].update(clearance_below_linear=0.5), ["benchmark.cases[0].clearance_below_linear: 0.5 m exceeds the linear amplitude of stop 0"]),
    ("unknown-on", lambda d: d.update(excitation={"amplitude": 1.0, "on": "roof"}), ["excitation.on: 'roof' is not a coordinate", "allowed floor1, floor2, absorber"]),
    ("no-room", lambda d: d["stops"][1].update(clearance=-0.002), ["benchmark.cases[0]:", "leave no room"]),
]


@pytest.mark.parametrize(("change", "fragments"), [m[1:] for m in MISTAKES], ids=[m[0] for m in MISTAKES])
def test_general_benchmark_mistakes_name_their_key(change: Callable[[dict[str, Any]], Any], fragments: list[str]) -> None:
    document = frame_benchmark()
    change(document)
    with pytest.raises(SceneError) as caught:
        parse_scene(document)
    assert any(all(f in p for f in fragments) for p in caught.value.problems), caught.value.problems


def test_a_case_on_a_layout_without_closed_form_starts_linear() -> None:
    """A third stop on the frame, far out (floor1 <= 5 cm, never reached): no closed form any more (not one stop nor a
    symmetric pair), so the case's ``pgf`` start is its ``linear`` one (here at rest: the linear motion would cross the
    absorber's stops), where the two stops alone start on the closed-form orbit, away from t = 0."""
    from vibroimpact.analysis.layout import closed_form_refusal
    from vibroimpact.simulation.steady import start_state

    two = parse_scene(frame_benchmark())
    document = frame_benchmark()
    document["stops"].append({"coordinate": "floor1", "side": "upper", "clearance": 0.05, "restitution": 0.5})
    three = parse_scene(document)
    assert two.settings is not None and three.settings is not None
    orbit, fallback = two.settings.cases[0].problem, three.settings.cases[0].problem
    assert closed_form_refusal(orbit) is None and closed_form_refusal(fallback) is not None
    assert start_state(orbit, "pgf")[0] > 0.0
    t0, state = start_state(fallback, "pgf")
    t1, linear = start_state(fallback, "linear")
    assert t0 == t1 and np.array_equal(state, linear)


def test_a_clearance_below_the_linear_reach_is_a_problem_s_linear_amplitude_minus_it() -> None:
    """The frame's two-sided stop without its own clearance, a case 0.1 mm inside the linear reach at 8.5 Hz: each
    stop's Delta is |n . X| + n . x0 of the case's own problem (its linear steady state, which does not see the stops)
    less 0.1 mm, bit for bit, the same on both sides (no static load); the reach is the stops' relative amplitude
    |X_absorber - X_floor2| under the base motion."""
    from vibroimpact.analysis.linear import linear_amplitudes

    document = frame_benchmark()
    for stop in document["stops"]:
        stop.pop("clearance")
    document["benchmark"]["cases"][0].update(clearance_below_linear=1e-4, start="linear")
    document["benchmark"].pop("ladder")
    scene = parse_scene(document)
    assert scene.settings is not None
    problem = scene.settings.cases[0].problem
    linear = linear_amplitudes(problem)
    reach = np.abs(linear.stop_amplitudes) + linear.stop_static
    np.testing.assert_array_equal([stop.clearance for stop in problem.stops], reach - 1e-4)  # exact: the same arithmetic, at the case's own frequency
    assert problem.stops[0].clearance == problem.stops[1].clearance  # exact: n_lower = -n_upper, |.| and a zero static load
    relative = np.abs(linear.relative("absorber", "floor2"))
    np.testing.assert_allclose(reach, [relative, relative], rtol=1e-14)
    assert 0.0 < problem.stops[0].clearance < relative
