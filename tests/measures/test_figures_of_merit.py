"""The figures of merit of the concepts study on tiny grids, against values computed by hand or directly; the
concepts scene's checks; the force on the base and the engine's layout check."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vibroimpact.engines.base import Trajectory
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.contact import Stop
from vibroimpact.model.system import TwoDofSystem
from vibroimpact.scene.checker import SceneError
from vibroimpact.kinds.concepts.scene import parse_concepts
from vibroimpact.model.absorber import den_hartog_absorber
from vibroimpact.measures.figures_of_merit import anti_resonance_band, band_metrics, envelope, stretches
from vibroimpact.analysis.linear import base_force
from vibroimpact.simulation.harmonics import base_weights
from vibroimpact.kinds.concepts.branches import check_stops

SYSTEM = TwoDofSystem(1.0, 0.1, 25000.0, 4300.0, 0.8, 0.08)


def test_the_envelope_is_the_largest_stable_value_at_each_frequency() -> None:
    f = np.array([1.0, 2.0, 3.0, 4.0, 5.0])
    linear = (np.array([1.0, 1.0, 5.0, 5.0, 1.0]), np.array([10.0, 10.0, 50.0, 50.0, 10.0]), np.array([True, True, False, False, True]))
    closed = (np.array([np.nan, np.nan, 2.0, 9.0, np.nan]), np.array([np.nan, np.nan, 20.0, 90.0, np.nan]), np.array([-1, -1, 1, 0, -1]), 1)
    simulated = (np.array([4.1]), np.array([3.0]), np.array([31.0]), np.array([2.0]))
    # one branch, stable from 2.5 to 4.5 Hz (|X1| 1.5 -> 3.5): 2.0 at 3 Hz, 3.0 at 4 Hz; then unstable
    branches = (np.array([2.5, 4.5, 4.9]), np.array([1.5, 3.5, 7.0]), np.array([15.0, 35.0, 70.0]), np.array([0.5, 0.9, 1.2]), np.array([1.0, 1.0, 1.0]), np.zeros(3))
    worst = envelope(f, linear, closed, simulated, branches)
    np.testing.assert_allclose(worst.x1, [1.0, 1.0, 2.0, 3.0, 1.0], rtol=1e-14)
    np.testing.assert_allclose(worst.base_force, [10.0, 10.0, 20.0, 31.0, 10.0], rtol=1e-14)  # 4 Hz: the simulation's 31 beats the branch's 30
    np.testing.assert_array_equal(worst.impacts, [0, 0, 1, 1, 0])
    m = band_metrics(f, worst, (2.0, 4.0), static=2.0)
    assert (m.peak_x1, m.peak_x1_frequency, m.peak_force, m.peak_force_frequency) == (3.0, 4.0, 31.0, 4.0)
    assert math.isclose(m.notch_depth, 20.0 * math.log10(1.0 / 2.0), rel_tol=1e-14) and m.notch_frequency == 2.0  # exact: a grid value
    assert math.isclose(m.band_impact_fraction, 2.0 / 3.0, rel_tol=1e-14) and m.band_impacts == [(3.0, 4.0)]
    assert m.band_coverage == 1.0  # exact: a ratio of counts


def test_no_stable_motion_leaves_a_gap() -> None:
    f = np.array([1.0, 2.0])
    nan = np.full(2, np.nan)
    worst = envelope(f, (nan, nan, np.array([False, False])), (nan, nan, np.array([0, 0]), 1), (np.zeros(0),) * 4, (np.zeros(0),) * 6)
    assert np.all(np.isnan(worst.x1)) and np.all(worst.impacts == 1)  # the linear motion hits the stop: every motion impacts
    m = band_metrics(f, worst, (1.0, 2.0), static=1.0)
    assert math.isnan(m.peak_x1) and math.isnan(m.notch_depth) and m.band_coverage == 0.0 and m.band_impact_fraction == 1.0  # exact: ratios of counts


def test_stretches_join_neighbours() -> None:
    f = np.array([1.0, 1.1, 1.2, 1.3, 2.0, 2.1])
    assert stretches(f, np.array([True, True, False, True, True, True]), 0.15) == [(1.0, 1.1), (1.3, 1.3), (2.0, 2.1)]
    assert stretches(f, np.array([True, True, False, True, True, True]), 0.25) == [(1.0, 1.3), (2.0, 2.1)]  # 1.1 -> 1.3 is 0.2 apart
    assert stretches(f, np.zeros(6, dtype=bool), 1.0) == []


def test_the_anti_resonance_band_of_the_paper() -> None:
    """The band is the stretch around sqrt(k2/m2)/2pi = 33.0 Hz where |X1| < q/k1, its ends the grid's last points below."""
    f = np.arange(15.0, 45.0 + 1e-9, 0.01)
    x1 = 10.0 * np.abs(SYSTEM.structure.receptance_matrix(2.0 * np.pi * f)[:, 0, 0])
    low, high, anti = anti_resonance_band(f, x1, 10.0 / 25000.0)
    assert abs(anti - math.sqrt(43000.0) / (2.0 * math.pi)) <= 0.01
    step = 0.01
    for edge, outside in ((low, low - step), (high, high + step)):
        inside_value = 10.0 * abs(SYSTEM.structure.receptance_matrix(2.0 * np.pi * edge)[0, 0])
        outside_value = 10.0 * abs(SYSTEM.structure.receptance_matrix(2.0 * np.pi * outside)[0, 0])
        assert inside_value < 4e-4 <= outside_value
    assert (round(low, 2), round(high, 2)) == (29.32, 34.61)
    assert math.isnan(anti_resonance_band(f, np.ones(f.size), 0.5)[0])


@pytest.mark.parametrize("stops, through", [((Stop(RigidStop(0.003, 0.2), 1, None, "upper"),), 1.0), ((Stop(RigidStop(0.003, 0.2), 1, 0, "upper"),), 0.0),
                                            ((Stop(RigidStop(0.003, 0.2), 1, None, "lower"),), -1.0)])  # fmt: skip
def test_the_force_on_the_base(stops: tuple[Stop, ...], through: float) -> None:
    """k1 x1 + b1 x1' plus the stop's force on the base: +lambda upper, -lambda lower, none for a stop between masses."""
    problem = ImpactProblem(SYSTEM, stops, HarmonicForce(10.0, 30.0))
    x = np.array([1e-3 + 2e-4j, 3e-3 - 1e-3j])
    contact = np.array([0.7 - 0.2j])
    expected = (25000.0 + 1j * problem.omega * 0.8) * x[0] + through * contact[0]
    assert abs(base_force(problem.structure, problem.omega, x, base_weights(problem), contact) - expected) <= 1e-12 * abs(expected)


def _trajectory(problem: ImpactProblem, after_impact: np.ndarray) -> Trajectory:
    return Trajectory(problem, np.array([0.0, problem.period]), np.zeros((2, 4)), np.array([0.01]), np.array([0.1]), np.array([0.01]),
                      np.array([[0.0, 0.01, 0.0], [0.01, problem.period, 0.0]]), np.array([np.zeros(4), after_impact]), np.zeros((1, 5), dtype=complex))  # fmt: skip


def test_an_engine_that_takes_a_relative_stop_for_the_papers_is_refused() -> None:
    problem = ImpactProblem(SYSTEM, (Stop(RigidStop(0.003, 0.2), 1, 0, "upper"),), HarmonicForce(10.0, 30.0))
    check_stops(_trajectory(problem, np.array([0.001, 0.004, 0.0, 0.0])))  # x2 - x1 = 3 mm: on the stop
    with pytest.raises(RuntimeError, match="does not honour this layout"):
        check_stops(_trajectory(problem, np.array([0.001, 0.003, 0.0, 0.0])))  # x2 = 3 mm: the paper's stop
    with pytest.raises(RuntimeError, match="inside a stop"):
        check_stops(_trajectory(problem, np.array([0.0, 0.0045, 0.0, 0.0])))


DOCUMENT = {
    "name": "tiny",
    "system": {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0, "b1": 0.8, "b2": 0.08},
    "excitation": {"amplitude": 10.0},
    "frequency": {"start": 20.0, "stop": 40.0, "step": 0.5},
    "simulation": {"frequency": [25.0, 34.0]},
    "concepts": [
        {"name": "dh", "absorber": {"stiffness": "den_hartog", "damping": "den_hartog"}},
        {"name": "paper_k2", "absorber": {"damping": "den_hartog"}},
        {"name": "stop", "stops": [{"coordinate": "x2", "side": "upper", "clearance": 0.003, "restitution": 0.2}]},
        {"name": "rel", "stops": [{"between": ["x2", "x1"], "side": "upper", "clearance": 0.003, "restitution": 0.2}]},
    ],
}


def test_a_concepts_scene() -> None:
    name, _description, report, settings, _scheduler = parse_concepts(DOCUMENT)
    optimum = den_hartog_absorber(1.0, 25000.0, 0.1)
    dh, paper_k2, stop, rel = settings.concepts
    assert name == "tiny" and report and settings.simulation_frequency.tolist() == [25.0, 34.0] and math.isnan(settings.bumper_frequency)
    assert (dh.system.k2, dh.system.b2) == (optimum.stiffness, optimum.damping) and not dh.stops
    assert (paper_k2.system.k2, paper_k2.system.b2) == (4300.0, optimum.damping)
    assert [(s.coordinate, s.other, s.side) for s in stop.stops] == [(1, None, "upper")] and stop.system == SYSTEM and stop.describe_stops() == "x2 <= 3 mm, R = 0.2"
    assert rel.stops[0].other == 0 and rel.stops[0].normal(2).tolist() == [-1.0, 1.0]
    assert rel.problem(10.0, 30.0).stops[0].other == 0 and stop.problem(10.0, 30.0, bumper_frequency=250.0).bumper.frequency == 250.0  # exact: a parsed input


@pytest.mark.parametrize(
    "change, key",
    [
        (lambda d: d["concepts"][0].update(colour="red"), "concepts[0].colour"),
        (lambda d: d["concepts"][2]["stops"][0].update(coordinate="x3"), "concepts[2].stops[0].coordinate"),
        (lambda d: d["concepts"][3]["stops"][0].update(between=["x2", "x2"]), "concepts[3].stops[0].between"),
        (lambda d: d["concepts"][0]["absorber"].update(damping="optimal"), "concepts[0].absorber.damping"),
        (lambda d: d["concepts"][1].update(name="dh"), "concepts[1].name"),
        (lambda d: d["concepts"][2]["stops"][0].update(side="above"), "concepts[2].stops[0].side"),
        (lambda d: d.update(continuation={"max_steps": -1}), "continuation.max_steps"),
        (lambda d: d.update(concepts=[]), "concepts"),
        (lambda d: d["simulation"].update(lyapunov_periods=256), "simulation.lyapunov_periods: not used by the concepts kind"),
    ],
)
def test_every_problem_names_its_key(change, key: str) -> None:
    import copy

    document = copy.deepcopy(DOCUMENT)
    change(document)
    with pytest.raises(SceneError) as error:
        parse_concepts(document)
    assert any(problem.startswith(key) for problem in error.value.problems), error.value.problems


def test_the_shipped_scene() -> None:
    """studies/absorber_concepts.yaml: the six concepts of issue 12 item 4, Den Hartog's optimum where it says so."""
    from vibroimpact.scene.reader import shipped_studies_dir
    from vibroimpact.scene.reader import read_yaml

    document = read_yaml((shipped_studies_dir() / "absorber_concepts.yaml").read_text(encoding="utf-8"))
    name, _description, _report, settings, _scheduler = parse_concepts(document)
    optimum = den_hartog_absorber(1.0, 25000.0, 0.1)
    concepts = {c.name: c for c in settings.concepts}
    assert name == "absorber_concepts" and settings.bumper_frequency == 250.0 and settings.amplitude == 10.0  # exact: parsed inputs
    assert (concepts["den_hartog"].system.k2, concepts["den_hartog"].system.b2) == (optimum.stiffness, optimum.damping)
    assert (concepts["den_hartog_damping"].system.k2, concepts["den_hartog_damping"].system.b2) == (4300.0, optimum.damping)
    assert [(s.coordinate, s.other, s.side) for s in concepts["absolute_stop"].stops] == [(1, None, "upper")] and [s.side for s in concepts["two_sided_stop"].stops] == ["upper", "lower"]
    assert [(s.coordinate, s.other, s.side) for s in concepts["relative_two_sided"].stops] == [(1, 0, "upper"), (1, 0, "lower")]
