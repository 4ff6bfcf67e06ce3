"""The parameter table (issue 47): one row per scalar a study may vary, read by the scene sweeps, the datasets'
coordinates, the impact map and the design kind; a layout scalar's row follows its matrix."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vibroimpact.model.contact import MAX_LOSS_FACTOR, RigidStop, Stop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.parameters import MAX_BUMPER_FREQUENCY, MAX_RELATIVE_SPREAD, PARAMETERS, Parameter, layout_parameter, parameter, with_layout
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.structure import LinearStructure
from vibroimpact.model.system import PAPER_SYSTEM

PAPER = ImpactProblem(PAPER_SYSTEM, RigidStop(3e-3, 0.2), HarmonicForce(10.0, 25.0))
CHAIN = ImpactProblem(
    LinearStructure(mass=((2.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 0.2)), stiffness=((30000.0, -6000.0, 0.0), (-6000.0, 8000.0, -2000.0), (0.0, -2000.0, 2000.0))),
    (Stop(RigidStop(2e-3, 0.5), coordinate=2),),
    HarmonicForce(20.0, 14.0),
)


def test_every_consumer_reads_the_table() -> None:
    """The scene's sweepable ranges, the datasets' coordinate attributes and the impact map's units are the table's
    rows, not copies: each is the same object or the same values."""
    from vibroimpact.orbits.maps import PARAMETERS as MAP_PARAMETERS
    from vibroimpact.scene.schema import SWEEPABLE
    from vibroimpact.scene.variables import COORDINATE_ATTRIBUTES

    for name, row in SWEEPABLE.items():
        assert row is PARAMETERS[name]
        assert COORDINATE_ATTRIBUTES[name] == {"units": row.unit, "long_name": row.long_name}
    assert MAP_PARAMETERS == {name: PARAMETERS[name].unit for name in ("frequency", "restitution", "clearance", "amplitude", "phase")}
    assert PARAMETERS["bumper_frequency"].high == MAX_BUMPER_FREQUENCY and PARAMETERS["bumper_loss_factor"].high == MAX_LOSS_FACTOR


@pytest.mark.parametrize(
    ("name", "value", "allowed"),
    [("restitution", 0.0, True), ("restitution", 1.0, True), ("restitution", 1.0 + 1e-12, False), ("restitution", -1e-300, False),
     ("frequency", 0.0, False), ("frequency", 1e-300, True), ("frequency", math.inf, False), ("clearance", -1e-3, True),
     ("bumper_frequency", MAX_BUMPER_FREQUENCY, True), ("bumper_frequency", MAX_BUMPER_FREQUENCY * (1 + 1e-12), False),
     ("bumper_loss_factor", 0.0, True), ("bumper_stiffness", 0.0, False)],
)  # fmt: skip
def test_ranges(name: str, value: float, allowed: bool) -> None:
    assert PARAMETERS[name].allows(value) is allowed


def test_layout_scalars_follow_their_matrix() -> None:
    """A layout scalar's row: the unit of its matrix; a spring or mass positive, a dashpot non-negative, an off-diagonal
    matrix entry of any sign (a coupling spring is a negative K[a, b]); mistuned relatively, at most +-50 %."""
    rows = {name: parameter(name, PAPER) for name in ("k2", "b2", "m2", "spring[x1,x2]", "stiffness[x1,x2]", "damping[x1]", "mass[x2]")}
    assert [rows[n].unit for n in rows] == ["N m-1", "N s m-1", "kg", "N m-1", "N m-1", "N s m-1", "kg"]
    assert not rows["k2"].allows(0.0) and rows["b2"].allows(0.0) and rows["damping[x1]"].allows(0.0) and not rows["m2"].allows(0.0)
    assert rows["stiffness[x1,x2]"].allows(-PAPER_SYSTEM.k2) and not rows["spring[x1,x2]"].allows(-1.0)
    assert all(row.relative_spread and row.spread_limit == MAX_RELATIVE_SPREAD for row in rows.values())
    assert "spring[x1,x2]" in rows["k2"].long_name  # the named system's field says which element it is
    # the row's range holds what the layout accepts: the coupling entry's own (negative) value is its value
    own = layout_parameter("stiffness[x1,x2]", PAPER).value(PAPER, (0,))
    assert own < 0.0 and rows["stiffness[x1,x2]"].allows(own)


def test_stop_scalars_spread_absolutely() -> None:
    assert not PARAMETERS["clearance"].relative_spread and not PARAMETERS["restitution"].relative_spread
    assert PARAMETERS["restitution"].spread_limit == pytest.approx(1.0, rel=0, abs=0)
    assert math.isinf(PARAMETERS["clearance"].spread_limit)


def test_a_row_is_resolved_against_the_structure() -> None:
    """Without a problem only the name's form is checked; with one, a coordinate the structure lacks, or the paper's
    named fields on another structure, are refused naming the parameter."""
    assert parameter("mass[x3]").unit == "kg"
    assert parameter("mass[x3]", CHAIN).unit == "kg"
    with pytest.raises(ValueError, match="x3"):
        parameter("mass[x3]", PAPER)
    with pytest.raises(ValueError, match="'k2' names a field of the paper's two-mass system"):
        parameter("k2", CHAIN)
    with pytest.raises(ValueError, match="unknown parameter 'stiffnes\\[x1\\]': allowed frequency, amplitude"):
        parameter("stiffnes[x1]")


def test_a_row_is_validated() -> None:
    with pytest.raises(ValueError, match="low < high"):
        Parameter("bad", "1", "bad", 1.0, 1.0)


def test_clip_and_set_agree() -> None:
    """Setting a layout scalar to its clipped value keeps the problem valid; at its own value the problem is the base
    problem bit for bit."""
    k2 = layout_parameter("k2", PAPER)
    same = with_layout(PAPER, (k2,), (k2.value(PAPER, (0,)),), (0,))
    assert same is PAPER
    clipped = parameter("k2").clip(-5.0)
    assert clipped == pytest.approx(0.0, abs=0.0)  # clip returns the bound itself: exact
    moved = with_layout(PAPER, (k2,), (2.0 * PAPER_SYSTEM.k2,), (0,))
    assert np.isclose(layout_parameter("k2", moved).value(moved, (0,)), 2.0 * PAPER_SYSTEM.k2, rtol=1e-14, atol=0.0)
