"""The layout value: one structure, load and stop geometry that builds problems, writes and reads a dataset's layout
attributes, and alone says whether it is the paper's layout."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from vibroimpact.model.contact import RigidStop
from vibroimpact.model.layout import PAPER_STOP, Layout, LoadSpec, StopSpec
from vibroimpact.model.structure import LinearStructure
from vibroimpact.model.system import PAPER_SYSTEM, TwoDofSystem

from tests.golden.golden import DATA

#: A chain whose K1 does not survive (K1 + K2) - K2 in double precision: 0.1 + 0.2 - 0.2 = 0.10000000000000003.
ROUNDING = TwoDofSystem(m1=1.0, m2=0.1, k1=0.1, k2=0.2, b1=0.01, b2=0.002)


def test_the_named_form_keeps_its_parameters_unrounded() -> None:
    assert TwoDofSystem.of(ROUNDING.structure).k1 != 0.1  # exact: the matrices alone lose the last bit of K1 (0.10000000000000003)
    view = Layout(ROUNDING).paper_view()
    assert view is not None and view.k1 == 0.1 and view.b1 == 0.01  # exact: the parameters as written
    assert Layout(ROUNDING).with_stops((PAPER_STOP,)).paper_view() is view


@pytest.mark.parametrize(
    ("load", "stops", "size"),
    [
        (LoadSpec(), (StopSpec(1, side="lower"),), 2),
        (LoadSpec(), (StopSpec(1, other=0),), 2),
        (LoadSpec(), (StopSpec(0),), 2),
        (LoadSpec(), (PAPER_STOP, StopSpec(1, side="lower")), 2),
        (LoadSpec(weights=(0.0, 1.0)), (PAPER_STOP,), 2),
        (LoadSpec(static=(0.0, -1.0)), (PAPER_STOP,), 2),
        (LoadSpec(base_motion=True), (PAPER_STOP,), 2),
        (LoadSpec(), (PAPER_STOP,), 3),
    ],
    ids=["lower", "relative", "on-x1", "two-stops", "force-on-x2", "static", "base-motion", "three-masses"],
)
def test_only_the_papers_layout_has_the_paper_view(load: LoadSpec, stops: tuple[StopSpec, ...], size: int) -> None:
    structure = PAPER_SYSTEM.structure if size == 2 else LinearStructure(np.eye(3), [[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]])
    assert Layout(structure, load, stops).paper_view() is None
    assert Layout(PAPER_SYSTEM.structure, LoadSpec(weights=(1.0, 0.0)), (StopSpec(1, clearance=0.003),)).paper_view() is not None  # however written


def test_a_problem_is_the_layout_at_one_grid_point() -> None:
    layout = Layout(PAPER_SYSTEM.structure, LoadSpec(weights=(1.0, 0.0)), (StopSpec(1, other=0, clearance=0.002), StopSpec(1, other=0, side="lower")))
    problem = layout.problem(10.0, 25.0, 0.3, 0.004)
    assert [stop.clearance for stop in problem.stops] == [0.002, 0.004]  # exact: the stop's own, then the grid's
    assert [stop.law.restitution for stop in problem.stops] == [0.3, 0.3]  # exact: the grid's
    assert all(isinstance(stop.law, RigidStop) for stop in problem.stops)
    assert problem.frequency == 25.0 and problem.amplitude == 10.0  # exact: given
    bumpers = layout.problem(10.0, 25.0, 0.3, 0.004, bumper=True, bumper_frequency=500.0)
    assert [stop.law.frequency for stop in bumpers.stops] == [500.0, 500.0]  # exact: given
    assert isinstance(problem.system, LinearStructure) and Layout.of_problem(problem).stops == tuple(StopSpec(1, 0, s) for s in ("upper", "lower"))


def test_the_attributes_read_back_as_the_same_layout() -> None:
    structure = LinearStructure(np.diag([1.0, 0.5, 0.05]), [[2e4, -1e4, 0.0], [-1e4, 1.02e4, -200.0], [0.0, -200.0, 200.0]], np.eye(3) * 0.1, ("floor1", "floor2", "absorber"))
    layout = Layout(structure, LoadSpec(static=(0.0, 0.0, -0.49), base_motion=True), (StopSpec(2, other=1, clearance=0.003), StopSpec(2, other=1, side="lower")))
    attrs = layout.attributes(np.array([0.2]), np.array([0.004, 0.005]))
    back = Layout.from_attributes(attrs)
    assert back.structure == structure and back.load == layout.load
    assert back.stops == (StopSpec(2, 1, "upper", 0.003), StopSpec(2, 1, "lower", None))  # the swept clearance stays the grid's
    assert attrs["stop_layout"] == "absorber - floor2 <= 3 mm, R = 0.2; absorber - floor2 >= -Delta, R = 0.2"
    named = Layout(ROUNDING).attributes(np.array([0.2]), np.array([0.003]))
    view = Layout.from_attributes(named).paper_view()
    assert view is not None and view.k1 == 0.1  # exact: the recorded parameter, not K[0, 0] - K2


@pytest.mark.parametrize(("name", "paper"), [("bifurcation", True), ("bifurcation_relative_stop", False), ("restitution", True), ("relative_stop", False), ("design_paper", True), ("validation_relative_stop", False)])
def test_every_golden_dataset_records_its_layout(name: str, paper: bool) -> None:
    """The bifurcation, design and validation kinds write their layout with the one writer too: a page reads any
    kind's layout back (a concepts dataset records the concepts' shared structure and load, and no stop)."""
    with xr.open_dataset(DATA / f"{name}.nc") as dataset:
        layout = Layout.from_attributes(dataset.attrs)
    assert (layout.paper_view() is not None) is paper
    assert layout.coordinates == ("x1", "x2")


def test_a_stop_on_a_missing_coordinate_is_refused() -> None:
    with pytest.raises(ValueError, match=r"stops\[0\]: acts on a coordinate the structure does not have"):
        Layout(PAPER_SYSTEM, LoadSpec(), (StopSpec(2),))
    with pytest.raises(TypeError, match="stops"):
        Layout(PAPER_SYSTEM, LoadSpec(), ())


# ---------------------------------------------------------------------------------------------------------------------
# Questions a layout answers from its geometry (and the grid's values where a rule needs one), without a problem.
# ---------------------------------------------------------------------------------------------------------------------

#: A three-mass chain with named coordinates (no rigid-body mode).
CHAIN = LinearStructure(np.diag([1.0, 0.5, 0.05]), [[2e4, -1e4, 0.0], [-1e4, 1.02e4, -200.0], [0.0, -200.0, 200.0]], [[2.0, -1.0, 0.0], [-1.0, 1.02, -0.02], [0.0, -0.02, 0.02]], ("a", "b", "c"))
#: Two free masses joined by a spring: one rigid-body mode.
FREE_FREE = LinearStructure(np.diag([1.0, 0.1]), [[4300.0, -4300.0], [-4300.0, 4300.0]], [[0.08, -0.08], [-0.08, 0.08]])

#: (id, layout): the paper's; a symmetric relative pair (grid values, then its own); a base-motion frame with a pair;
#: a static load on a lower stop; stops on two coordinates; a free-free structure under a static load.
REACH_LAYOUTS = [
    ("paper", Layout(PAPER_SYSTEM)),
    ("relative-pair", Layout(PAPER_SYSTEM.structure, LoadSpec(weights=(1.0, 0.0)), (StopSpec(1, 0), StopSpec(1, 0, "lower")))),
    ("own-values", Layout(PAPER_SYSTEM.structure, LoadSpec(), (StopSpec(1, 0, clearance=0.002, restitution=0.4), StopSpec(1, 0, "lower", clearance=0.002, restitution=0.4)))),
    ("frame-base-motion", Layout(CHAIN, LoadSpec(base_motion=True), (StopSpec(2, 1), StopSpec(2, 1, "lower")))),
    ("static-lower", Layout(CHAIN, LoadSpec(weights=(0.0, 1.0, 0.5), static=(0.0, 0.0, -0.49)), (StopSpec(2, side="lower"),))),
    ("two-coordinates", Layout(CHAIN, LoadSpec(static=(3.0, 0.0, 0.0)), (StopSpec(0), StopSpec(2, side="lower")))),
    ("free-free-static", Layout(FREE_FREE, LoadSpec(static=(0.0, -0.981)), (StopSpec(1, 0),))),
    ("read-back", Layout.from_attributes(Layout(ROUNDING).attributes(np.array([0.2]), np.array([0.003])))),
]


@pytest.mark.parametrize("layout", [case[1] for case in REACH_LAYOUTS], ids=[case[0] for case in REACH_LAYOUTS])
def test_the_linear_reach_is_a_problem_s_linear_amplitudes_bit_for_bit(layout: Layout) -> None:
    """|n_k . X| + n_k . x0 of the layout equals that of a problem built from it, whatever the stops' values (the
    linear steady state does not see them): same arithmetic, same bits (NaN where K is singular under a static load)."""
    from vibroimpact.analysis.linear import linear_amplitudes, linear_reach

    for amplitude, frequency in ((10.0, 25.0), (0.001, 8.5), (3.0, 140.0)):
        reach = linear_reach(layout, amplitude, frequency)
        assert reach.shape == (len(layout.stops),)
        for restitution, clearance in ((0.5, 1.0), (0.05, 2e-4)):
            linear = linear_amplitudes(layout.problem(amplitude, frequency, restitution, clearance))
            np.testing.assert_array_equal(reach, np.abs(linear.stop_amplitudes) + linear.stop_static)  # exact: the one arithmetic, on the same structure and load


def test_the_linear_reach_of_the_paper_s_stop_is_q_h12() -> None:
    """On the paper's layout the reach is the absorber's linear amplitude q |H12| (no static load); on a relative pair
    both sides see the same |X2 - X1|; a static load adds n . K^-1 F0, signed by the stop's side."""
    from vibroimpact.analysis.linear import linear_reach, paper_linear_response

    frequencies = (12.0, 25.0, 33.0)
    for f in frequencies:
        reach = linear_reach(Layout(PAPER_SYSTEM), 10.0, f)
        response = paper_linear_response(PAPER_SYSTEM, f, 10.0)
        np.testing.assert_allclose(reach, [abs(response.x2)], rtol=1e-12)
        pair = linear_reach(REACH_LAYOUTS[1][1], 10.0, f)
        np.testing.assert_allclose(pair, [abs(response.x2 - response.x1)] * 2, rtol=1e-12)
    loaded = Layout(CHAIN, LoadSpec(static=(0.0, 0.0, -0.49)), (StopSpec(2), StopSpec(2, side="lower")))
    free = Layout(CHAIN, LoadSpec(), loaded.stops)
    offset = float(np.linalg.solve(CHAIN.stiffness_matrix, [0.0, 0.0, -0.49])[2])  # x3 of the static deflection [m]
    np.testing.assert_allclose(linear_reach(loaded, 1.0, 5.0) - linear_reach(free, 1.0, 5.0), [offset, -offset], rtol=1e-12)
    assert offset < 0.0


#: (id, layout, grid clearances [m], how many of them leave no room): opposite stops absolute and relative, the
#: relative coordinate written both ways, stops on different coordinates (never without room), one stop.
ROOM_LAYOUTS = [
    ("absolute-pair", Layout(CHAIN, LoadSpec(), (StopSpec(0, clearance=-0.002), StopSpec(0, side="lower"))), (0.001, 0.002, 0.003), 2),
    ("relative-pair", Layout(CHAIN, LoadSpec(), (StopSpec(2, 1), StopSpec(2, 1, "lower", clearance=-0.002))), (0.001, 0.002, 0.0025), 2),
    ("written-both-ways", Layout(CHAIN, LoadSpec(), (StopSpec(2, 1, clearance=0.0), StopSpec(1, 2))), (-0.001, 0.0, 0.001), 2),
    ("same-sides-apart", Layout(CHAIN, LoadSpec(), (StopSpec(0, clearance=-0.005), StopSpec(1, side="lower"), StopSpec(2, 1))), (-0.004, 0.0), 0),
    ("one-stop", Layout(PAPER_SYSTEM), (-0.003, 0.0, 0.003), 0),
]


@pytest.mark.parametrize(("layout", "clearances", "refusals"), [case[1:] for case in ROOM_LAYOUTS], ids=[case[0] for case in ROOM_LAYOUTS])
def test_the_room_check_refuses_what_a_problem_refuses(layout: Layout, clearances: tuple[float, ...], refusals: int) -> None:
    """Two opposite stops whose clearances sum to <= 0 leave no room: the layout says so from its geometry and
    clearances, with the message a problem with those stops raises, and accepts every layout a problem accepts."""
    refused = 0
    for clearance in clearances:
        try:
            layout.problem(10.0, 25.0, 0.5, clearance)
            expected = None
        except ValueError as error:
            expected = str(error)
        try:
            layout.check_room(clearance)
            got = None
        except ValueError as error:
            got = str(error)
        assert got == expected, (clearance, got, expected)
        refused += expected is not None and "leave no room between them" in expected
    assert refused == refusals


def test_a_clearance_the_grid_does_not_give_is_not_judged() -> None:
    """Without the grid's value (NaN) a stop that takes it leaves no pair refused; its own values still are."""
    layout = Layout(CHAIN, LoadSpec(), (StopSpec(0), StopSpec(0, side="lower", clearance=-1.0)))
    layout.check_room()
    with pytest.raises(ValueError, match=r"stops: stop 0 \(a <= 1 mm\) and stop 1 \(a >= 1 m\) leave no room between them"):
        layout.check_room(0.001)
    own = Layout(CHAIN, LoadSpec(), (StopSpec(0, clearance=0.001), StopSpec(0, side="lower", clearance=-0.001)))
    with pytest.raises(ValueError, match="leave no room"):
        own.check_room()


#: (id, layout, R, Delta, a fragment of the refusal or None): every rule of the closed forms that a layout can break.
REFUSALS = [
    ("paper", Layout(PAPER_SYSTEM), 0.2, 0.003, None),
    ("symmetric-pair", REACH_LAYOUTS[1][1], 0.2, 0.003, None),
    ("own-symmetric-pair", REACH_LAYOUTS[2][1], 0.7, 0.01, None),
    ("frame-base-motion", REACH_LAYOUTS[3][1], 0.5, 0.002, None),
    ("static-one-stop", REACH_LAYOUTS[4][1], 0.5, 0.002, None),
    ("two-coordinates", REACH_LAYOUTS[5][1], 0.5, 0.002, "not on the same coordinate with opposite sides"),
    ("same-side-twice", Layout(CHAIN, LoadSpec(), (StopSpec(2, 1), StopSpec(1, 2, "lower"))), 0.5, 0.002, "not on the same coordinate with opposite sides"),
    ("free-free", Layout(FREE_FREE, LoadSpec(), (StopSpec(1, 0),)), 0.5, 0.002, "1 rigid-body mode(s)"),
    ("free-free-pair", Layout(FREE_FREE, LoadSpec(base_motion=True), (StopSpec(1, 0), StopSpec(1, 0, "lower"))), 0.5, 0.002, "rigid-body"),
    ("unequal-clearances", Layout(CHAIN, LoadSpec(), (StopSpec(2, 1), StopSpec(2, 1, "lower", clearance=0.003))), 0.5, 0.002, "their clearances or restitutions differ"),
    ("unequal-restitutions", Layout(CHAIN, LoadSpec(), (StopSpec(2, 1, restitution=0.4), StopSpec(2, 1, "lower"))), 0.5, 0.002, "their clearances or restitutions differ"),
    ("static-on-the-pair", Layout(CHAIN, LoadSpec(static=(0.0, 0.0, -0.49)), (StopSpec(2, 1), StopSpec(2, 1, "lower"))), 0.5, 0.002, "the static load moves the two-sided stop's coordinate by"),
    ("three-stops", Layout(CHAIN, LoadSpec(), (StopSpec(0), StopSpec(2, 1), StopSpec(2, 1, "lower"))), 0.5, 0.002, "the problem has 3 stops"),
]


@pytest.mark.parametrize(("layout", "restitution", "clearance", "fragment"), [case[1:] for case in REFUSALS], ids=[case[0] for case in REFUSALS])
def test_the_layout_s_closed_form_refusal_is_the_problem_s(layout: Layout, restitution: float, clearance: float, fragment: str | None) -> None:
    """The layout's question (geometry, and the grid's R and Delta for a pair's equality) gives the same answer and
    message as the problem's at any load amplitude and frequency: the rules live in one function."""
    from vibroimpact.analysis.layout import closed_form_refusal, layout_refusal

    reason = layout_refusal(layout, restitution, clearance)
    assert (reason is None) if fragment is None else (reason is not None and fragment in reason), reason
    for amplitude, frequency in ((10.0, 25.0), (0.001, 8.5)):
        assert closed_form_refusal(layout.problem(amplitude, frequency, restitution, clearance)) == reason


def test_a_pair_s_values_the_grid_does_not_give_are_not_judged() -> None:
    """A symmetric pair taking R and Delta from a grid that gives none (NaN) is not refused for them; a pair whose own
    values differ is."""
    from vibroimpact.analysis.layout import layout_refusal

    pair = REACH_LAYOUTS[1][1]
    assert layout_refusal(pair) is None and layout_refusal(pair, 0.3) is None
    unequal = Layout(CHAIN, LoadSpec(), (StopSpec(2, 1, clearance=0.002), StopSpec(2, 1, "lower", clearance=0.003)))
    assert "differ" in str(layout_refusal(unequal))


def test_a_bumper_given_in_physical_units_is_described_and_recorded_in_them() -> None:
    """The stops' words and attributes say K_b and B_b as given (with the Omega_b / 2 pi they mean), and read back."""
    structure = LinearStructure([[1.0, 0.0], [0.0, 0.25]], [[2e4, -5e3], [-5e3, 5e3]], coordinates=("x1", "x2"))
    own = StopSpec(1, 0, "lower", 0.002, 0.5, bumper_frequency=50.0, bumper_loss_factor=0.1, bumper_stiffness=2e4, bumper_damping=8.0)
    shared = StopSpec(1, None, "upper", 0.003, bumper_stiffness=1e5)  # Omega_b / 2 pi the grid's
    layout = Layout(structure, LoadSpec(), (own, shared))
    np.testing.assert_allclose([own.effective_mass(structure), shared.effective_mass(structure)], [0.2, 0.25], rtol=1e-15)
    attrs = layout.attributes(np.array([0.5]), np.array([0.003]), np.array([100.0]))
    assert attrs["stop_layout"] == (
        "x2 - x1 >= -2 mm, R = 0.5, bumper K_b = 20000 N/m, B_b = 8 N s/m (Omega_b / 2 pi = 50 Hz); x2 <= 3 mm, R = 0.5, bumper K_b = 100000 N/m (Omega_b / 2 pi = 100 Hz)"
    )
    np.testing.assert_array_equal(attrs["stop_bumper_stiffness_N_per_m"], [2e4, 1e5])
    np.testing.assert_array_equal(attrs["stop_bumper_damping_N_s_per_m"], [8.0, np.nan])
    back = Layout.from_attributes(attrs).stops
    assert [(s.bumper_stiffness, s.bumper_damping) for s in back] == [(2e4, 8.0), (1e5, None)]  # exact: the attributes as written
    assert "stop_bumper_stiffness_N_per_m" not in Layout(structure).attributes(np.array([0.5]), np.array([0.003]))  # frequency form: unchanged
