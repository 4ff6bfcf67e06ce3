"""The concepts study end to end on a coarse grid: its dataset, and its numbers against independent computations
(the linear receptance, the paper's closed-form one-impact orbit, the continued branch's own stability)."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
import xarray as xr

from vibroimpact.analysis.pgf import solve_one_impact
from vibroimpact.model.system import TwoDofSystem
from vibroimpact.kinds.concepts.scene import parse_concepts
from vibroimpact.kinds.concepts.study import ConceptsStudy, run_concepts

from tests.engine_cases import orbit_force

pytestmark = pytest.mark.slow  # a whole study per module: the slow tier (issue 49, measured)

DOCUMENT = {
    "name": "tiny_concepts",
    "system": {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0, "b1": 0.8, "b2": 0.08},
    "excitation": {"amplitude": 10.0},
    "frequency": {"start": 20.0, "stop": 36.0, "step": 0.05},
    "simulation": {"frequency": [22.0, 25.0, 34.5], "rtol": 1.0e-8, "irregular_measure_periods": 16},
    "bumper": {"frequency": 250.0},
    "continuation": {"max_steps": 60},
    "concepts": [
        {"name": "den_hartog", "label": "(a)", "absorber": {"stiffness": "den_hartog", "damping": "den_hartog"}},
        {"name": "absolute", "label": "(b)", "stops": [{"coordinate": "x2", "side": "upper", "clearance": 0.003, "restitution": 0.2}]},
        {"name": "relative", "label": "(c)", "stops": [{"between": ["x2", "x1"], "side": "upper", "clearance": 0.003, "restitution": 0.2}]},
    ],
}
SYSTEM = TwoDofSystem(1.0, 0.1, 25000.0, 4300.0, 0.8, 0.08)


@pytest.fixture(scope="module")
def dataset() -> xr.Dataset:
    _name, _description, _report, settings, _scheduler = parse_concepts(copy.deepcopy(DOCUMENT))
    return run_concepts(settings, progress=None)


def test_the_dataset_is_labelled(dataset: xr.Dataset) -> None:
    assert dict(dataset.sizes) == {"concept": 3, "frequency": 321, "simulation_frequency": 3, "point": dataset.sizes["point"]}
    assert list(dataset["concept"].values) == ["den_hartog", "absolute", "relative"]
    assert "study_kind" not in dataset.attrs and (dataset.attrs["band_low_Hz"], dataset.attrs["band_high_Hz"]) == (29.35, 34.6)  # run_study writes the header
    for name in ("peak_x1_amplitude", "worst_x1_amplitude", "simulated_x1", "bumper_peak_acceleration", "branch_floquet_modulus"):
        assert "long_name" in dataset[name].attrs
    assert dataset["peak_x1_amplitude"].attrs["units"] == "m"
    # decibels are not a UDUNITS unit: the depth keeps its dB values, units "1", and says so
    assert dataset["notch_depth"].attrs["units"] == "1" and "in dB" in dataset["notch_depth"].attrs["long_name"]
    assert dataset["point"].dtype == np.int32 and "long_name" in dataset["point"].attrs  # CF 2.2: no int64


def test_a_concept_without_a_stop_is_its_linear_receptance(dataset: xr.Dataset) -> None:
    concept = dataset.sel(concept="den_hartog")
    k2, c2 = float(concept["absorber_stiffness"]), float(concept["absorber_damping"])
    system = TwoDofSystem(1.0, 0.1, 25000.0, k2, 0.8, c2)
    f = dataset["frequency"].values
    x1 = 10.0 * np.abs(system.structure.receptance_matrix(2.0 * np.pi * f)[:, 0, 0])
    np.testing.assert_allclose(concept["worst_x1_amplitude"].values, x1, rtol=1e-12)
    assert math.isclose(float(concept["peak_x1_amplitude"]), float(x1.max()), rel_tol=1e-12)
    band = (f >= dataset.attrs["band_low_Hz"]) & (f <= dataset.attrs["band_high_Hz"])
    assert math.isclose(float(concept["notch_depth"]), 20.0 * math.log10(x1[band].min() / 4e-4), rel_tol=1e-12)
    assert float(concept["peak_impact_acceleration"]) == 0.0 and str(concept["unstable_stretches"].values) == "none"  # exact: no contact, no acceleration


def test_the_simulated_orbit_is_the_closed_form_one(dataset: xr.Dataset) -> None:
    """At 25 Hz the paper's stop has a stable one-impact orbit: the exact engine's steady state equals the closed form
    (|X1| and the base force's fundamental, eq. 23) to 1e-6, and so does the worst stable response there."""
    concept = dataset.sel(concept="absolute")
    solution = solve_one_impact(SYSTEM, omega=2.0 * np.pi * 25.0, clearance=0.003, restitution=0.2, amplitude=10.0)
    x1, force = float(np.abs(solution.harmonics()[0])), float(np.abs(orbit_force(SYSTEM, solution)))
    simulated = concept.sel(simulation_frequency=25.0)
    assert abs(float(simulated["simulated_x1"]) / x1 - 1.0) <= 1e-6
    assert abs(float(simulated["simulated_base_force"]) / force - 1.0) <= 1e-6
    assert abs(float(concept["worst_x1_amplitude"].sel(frequency=25.0)) / x1 - 1.0) <= 1e-6
    assert int(concept["closed_stable"].sel(frequency=25.0)) == 1
    assert float(concept["peak_x1_amplitude"]) >= x1


def test_the_bumpers_and_the_branches(dataset: xr.Dataset) -> None:
    for name in ("absolute", "relative"):
        concept = dataset.sel(concept=name)
        impacting = concept["simulated_impacts_per_period"].values > 0.0
        assert np.any(impacting)
        assert np.all(concept["bumper_peak_acceleration"].values[impacting] > 0.0)
        assert np.nanmax(concept["bumper_replay_mismatch"].values) <= 1e-4
        modulus = concept["branch_floquet_modulus"].values
        assert np.any(modulus < 1.0)
    absolute = dataset.sel(concept="absolute")
    # the branch continued from the stable orbit at 25 Hz passes through it with the same |X1|
    f, x1 = absolute["branch_frequency"].values, absolute["branch_x1_amplitude"].values
    near = np.isfinite(f) & (np.abs(f - 25.0) < 0.2)
    closed = float(absolute["closed_x1_amplitude"].sel(frequency=25.0))
    assert np.any(np.abs(x1[near] / closed - 1.0) < 0.02)
    assert "20.6" in str(absolute["unstable_stretches"].values)  # the one-impact orbit is unstable from its grazing at 20.62 Hz


def test_the_estimate_is_a_few_minutes_at_most() -> None:
    class Scene:
        settings = parse_concepts(copy.deepcopy(DOCUMENT))[3]

    estimate = ConceptsStudy().estimate(Scene(), 2, costs=None)  # type: ignore[arg-type]
    assert 0.0 < estimate.wall_time < 60.0


def test_the_chain_written_as_matrices_is_the_same_scene() -> None:
    """The shared ``system`` grammar: the two-mass chain as matrices (coordinates x1, x2) gives the concepts the same
    named system as m1 ... b2; a structure that is not that chain is refused, naming the key."""
    from vibroimpact.scene import SceneError

    matrices = copy.deepcopy(DOCUMENT)
    matrices["system"] = {"mass": [[1.0, 0.0], [0.0, 0.1]], "stiffness": [[29300.0, -4300.0], [-4300.0, 4300.0]], "damping": [[0.88, -0.08], [-0.08, 0.08]], "coordinates": ["x1", "x2"]}
    named = parse_concepts(copy.deepcopy(DOCUMENT))[3]
    written = parse_concepts(matrices)[3]
    for key in ("m1", "m2", "k1", "k2", "b1", "b2"):
        assert getattr(written.system, key) == pytest.approx(getattr(named.system, key), rel=1e-15, abs=1e-15)
    assert [c.name for c in written.concepts] == [c.name for c in named.concepts]
    three = copy.deepcopy(DOCUMENT)
    three["system"] = {"mass": [[1.0, 0.0], [0.0, 0.1]], "stiffness": [[29300.0, 0.0], [0.0, 4300.0]], "coordinates": ["x1", "x2"]}
    with pytest.raises(SceneError, match="system: a concepts scene needs the paper.s layout: the two-mass chain"):
        parse_concepts(three)


def test_a_concepts_stops_are_the_shared_stops_grammar() -> None:
    """A concept's ``stops`` read like any scene's (side defaults to upper, the same checks and messages, keyed by
    where they stand); what a concepts scene cannot take (a swept or missing value, a stop's own bumper) is refused."""
    from vibroimpact.scene import SceneError

    document = copy.deepcopy(DOCUMENT)
    document["concepts"][1]["stops"] = [{"coordinate": "x2", "clearance": 0.003, "restitution": 0.2}]  # no side: upper
    settings = parse_concepts(document)[3]
    stop = settings.concepts[1].stops[0]
    assert stop.side == "upper" and stop.coordinate == 1 and stop.law.clearance == pytest.approx(0.003)
    document["concepts"][1]["stops"] = [{"coordinate": "x3", "clearance": 0.003, "restitution": 0.2}, {"coordinate": "x2", "restitution": 0.2, "bumper": {"frequency": 500.0}}]
    with pytest.raises(SceneError) as caught:
        parse_concepts(document)
    problems = "\n".join(caught.value.problems)
    assert "concepts[1].stops[0].coordinate: 'x3' is not a coordinate of the system" in problems
    document["concepts"][1]["stops"] = [{"coordinate": "x2", "restitution": 0.2, "bumper": {"frequency": 500.0}}]
    with pytest.raises(SceneError) as caught:
        parse_concepts(document)
    problems = "\n".join(caught.value.problems)
    assert "concepts[1].stops[0].clearance: a concept's stop gives its clearance" in problems
    assert "concepts[1].stops[0].bumper: a concept's bumper twins are the scene's 'bumper' section" in problems
