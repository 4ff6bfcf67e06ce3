"""Any layout scalar as a parameter of the impact map (issue 31, item 6): masses, matrix entries, springs and
dashpots, the named system's m1 ... b2 and the bumpers' stiffness, continued and used as the second parameter of a
special point's curve, against the closed form and against the maps that had these parameters before.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from vibroimpact.engines.exact import ExactEngine
from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop, Stop, loss_factor_from_restitution
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.structure import LinearStructure
from vibroimpact.model.system import PAPER_SYSTEM, TwoDofSystem
from vibroimpact.orbits.bumper_map import BumperPeriodMap
from vibroimpact.orbits.continuation import ContinuationSettings, continue_branch, continue_special_point
from vibroimpact.model.parameters import layout_parameter
from vibroimpact.orbits.maps import ImpactMap, closed_form_state
from vibroimpact.orbits.shooting import shoot

pytestmark = pytest.mark.skipif(not hasattr(ExactEngine, "strobe_map"), reason="needs the compiled exact core (ExactEngine.strobe_map)")

PAPER = ImpactProblem(PAPER_SYSTEM, RigidStop(3e-3, 0.2), HarmonicForce(10.0, 25.0))
#: Three masses in a chain (ground - x1 - x2 - x3), the stop on x3: no named view, every scalar by the grammar.
CHAIN = LinearStructure(
    mass=((2.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 0.2)),
    stiffness=((30000.0, -6000.0, 0.0), (-6000.0, 8000.0, -2000.0), (0.0, -2000.0, 2000.0)),
    damping=((3.0, -0.5, 0.0), (-0.5, 0.7, -0.2), (0.0, -0.2, 0.2)),
)


def _chain(frequency: float = 14.0) -> ImpactProblem:
    return ImpactProblem(CHAIN, (Stop(RigidStop(2e-3, 0.5), coordinate=2),), HarmonicForce(20.0, frequency))


def _bumper(frequency: float = 25.0) -> ImpactProblem:
    return ImpactProblem(PAPER_SYSTEM, KelvinVoigtBumper(3e-3, 400.0, loss_factor_from_restitution(0.2)), HarmonicForce(10.0, frequency))


@pytest.mark.parametrize(
    ("problem", "layout"),
    [(PAPER, ("k2", "m2", "b1")), (PAPER, ("spring[x1,x2]", "mass[x1]", "damping[1]")), (_chain(), ("mass[x3]", "spring[x2,x3]", "dashpot[x1]")), (_bumper(), ("bumper_stiffness", "m2"))],
)
def test_a_layout_scalar_at_its_own_value_changes_nothing(problem: ImpactProblem, layout: tuple[str, ...]) -> None:
    plain, extended = ImpactMap(problem), ImpactMap(problem, layout=layout)
    assert extended.parameter_names == (*plain.parameter_names, *layout)
    assert extended.parameter_names[: len(plain.parameters)] == plain.parameter_names
    y = closed_form_state(problem) if problem.contact_law == "rigid" else np.zeros(2 * problem.size)
    a, b = plain.evaluate(y, plain.parameters), extended.evaluate(y, extended.parameters)
    assert np.array_equal(a.image, b.image) and np.array_equal(a.jacobian, b.jacobian)  # bit for bit


def test_values_and_units_follow_the_grammar() -> None:
    system = ImpactMap(PAPER, layout=("k1", "mass[x2]", "damping[x1,x2]"))
    assert system.parameters[-3:].tolist() == [25000.0, 0.1, -0.08]
    chain = _chain()
    assert layout_parameter("spring[x1]", chain).value(chain, (0,)) == pytest.approx(24000.0, rel=1e-15)  # row sum: the ground spring
    assert layout_parameter("spring[x2,x3]", chain).value(chain, (0,)) == pytest.approx(2000.0, rel=1e-15)
    assert layout_parameter("stiffness[0,1]", chain).value(chain, (0,)) == pytest.approx(-6000.0, rel=1e-15)
    assert [layout_parameter(n, chain).unit for n in ("mass[0]", "spring[x1]", "dashpot[x1,x2]")] == ["kg", "N m-1", "N s m-1"]


def test_a_spring_moves_only_its_own_entries() -> None:
    """k1 set through the element grammar on the paper's system is the named system with k1 replaced, to round-off;
    an element between x2 and x3 of the chain leaves the ground spring of x1 and the x1-x2 spring alone."""
    system = ImpactMap(PAPER, layout=("spring[x1]",))
    p = system.parameters.copy()
    p[-1] = 20000.0
    assert TwoDofSystem.of(system.problem_at(p).structure) == dataclasses.replace(PAPER_SYSTEM, k1=20000.0)
    chain = ImpactMap(_chain(), layout=("spring[x2,x3]",))
    q = chain.parameters.copy()
    q[-1] = 2500.0
    k = chain.problem_at(q).structure.stiffness_matrix
    np.testing.assert_allclose(k, [[30000.0, -6000.0, 0.0], [-6000.0, 8500.0, -2500.0], [0.0, -2500.0, 2500.0]], rtol=1e-15)


def test_a_branch_in_k2_is_the_closed_form_at_every_point() -> None:
    """The paper's one-impact orbit at 25 Hz continued in the absorber stiffness K2 [N/m] over 3000-6000 N/m: each
    point is the closed-form orbit (eqs. 15-18) of the system with that K2, to 1e-10 of the state scale."""
    system = ImpactMap(PAPER, layout=("k2",))
    orbit = shoot(system, closed_form_state(PAPER), system.parameters)
    branch = continue_branch(system, orbit, "k2", ContinuationSettings(lower=3000.0, upper=6000.0))
    assert branch.end == "bound, bound"
    assert branch.values.min() == pytest.approx(3000.0, rel=1e-12) and branch.values.max() == pytest.approx(6000.0, rel=1e-12)
    for point in branch.orbits:
        problem = system.problem_at(point.parameters)
        assert TwoDofSystem.of(problem.structure).k2 == pytest.approx(point.parameters[-1], rel=1e-15)
        np.testing.assert_allclose(point.state / system.state_scale, closed_form_state(problem) / system.state_scale, rtol=0.0, atol=1e-10)


def test_a_mass_of_a_chain_continued_against_the_closed_form() -> None:
    """The chain's stopped mass M[x3] from 0.2 kg down to 0.15 kg and up to 0.3 kg: the closed form of each structure
    (below 0.1257 kg a free flight grazes the stop)."""
    problem = _chain()
    system = ImpactMap(problem, layout=("mass[x3]",))
    orbit = shoot(system, closed_form_state(problem), system.parameters)
    branch = continue_branch(system, orbit, "mass[x3]", ContinuationSettings(lower=0.15, upper=0.3))
    assert branch.end == "bound, bound"
    for point in branch.orbits[:: max(1, len(branch.orbits) // 8)]:
        at = system.problem_at(point.parameters)
        assert at.structure.mass_matrix[2, 2] == point.parameters[-1]  # exact: the entry is set
        np.testing.assert_allclose(point.state / system.state_scale, closed_form_state(at) / system.state_scale, rtol=0.0, atol=1e-10)


@pytest.mark.slow
def test_a_fold_followed_in_frequency_and_k2_is_the_fold_of_each_branch() -> None:
    """The first band's fold (26.7027 Hz at K2 = 4300 N/m) followed in (frequency, K2) over 4000-4600 N/m: at a
    K2 on the curve, the frequency branch of that system has its fold at the curve's frequency (1e-9 Hz)."""
    system = ImpactMap(PAPER, layout=("k2",))
    orbit = shoot(system, closed_form_state(PAPER), system.parameters)
    branch = continue_branch(system, orbit, "frequency", ContinuationSettings(lower=20.0, upper=30.0, stop_at_grazing=True))
    fold = next(point for point in branch.special_points if point.kind == "fold")
    curve = continue_special_point(system, fold, "k2", bounds={"k2": (4000.0, 4600.0)})
    frequencies, stiffnesses = curve.values("frequency"), curve.values("k2")
    assert stiffnesses.min() == pytest.approx(4000.0, rel=1e-9) and stiffnesses.max() == pytest.approx(4600.0, rel=1e-9)
    i = len(stiffnesses) // 3
    other = ImpactProblem(dataclasses.replace(PAPER_SYSTEM, k2=float(stiffnesses[i])), RigidStop(3e-3, 0.2), HarmonicForce(10.0, 25.0))
    twin = ImpactMap(other)
    again = continue_branch(twin, shoot(twin, closed_form_state(other), twin.parameters), "frequency", ContinuationSettings(lower=20.0, upper=30.0, stop_at_grazing=True))
    folds = [point.value for point in again.special_points if point.kind == "fold"]
    assert len(folds) == 1 and folds[0] == pytest.approx(frequencies[i], abs=1e-9)


def test_a_bumper_keeps_its_stiffness_and_damping_when_the_mass_changes() -> None:
    """K_b = m Omega_b^2 and B_b = 2 m xi Omega_b [SI] are the part's; doubling M2 moves Omega_b and xi_b, not them."""
    problem = _bumper()
    system = ImpactMap(problem, layout=("m2",))
    p = system.parameters.copy()
    p[-1] = 0.2
    before, after = problem.stops[0], system.problem_at(p).stops[0]
    m_before, m_after = before.effective_mass(problem.structure.mass_matrix), after.effective_mass(np.diag([1.0, 0.2]))
    assert after.law.stiffness(m_after) == pytest.approx(before.law.stiffness(m_before), rel=1e-14)
    assert after.law.damping(m_after) == pytest.approx(before.law.damping(m_before), rel=1e-14)
    assert after.law.frequency == pytest.approx(400.0 / np.sqrt(2.0), rel=1e-14)


def test_the_bumper_stiffness_is_the_bumper_period_in_other_units() -> None:
    """The map in K_b [N/m] and the map in T_b [s] (:class:`BumperPeriodMap`) at K_b = M2 (2 pi / T_b)^2: the same
    image and Jacobian to round-off, at a stiffer and a softer bumper."""
    problem = _bumper()
    stiffness, period = ImpactMap(problem, layout=("bumper_stiffness",)), BumperPeriodMap(problem)
    y = np.array([1e-4, 2.9e-3, 0.05, 0.2])
    for frequency in (250.0, 1000.0):
        p, q = stiffness.parameters.copy(), period.parameters.copy()
        p[-1], q[-1] = 0.1 * (2.0 * np.pi * frequency) ** 2, 1.0 / frequency
        a, b = stiffness.evaluate(y, p), period.evaluate(y, q)
        np.testing.assert_allclose(a.image, b.image, rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(a.jacobian, b.jacobian, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize(
    ("problem", "layout", "message"),
    [
        (PAPER, ("k2", "spring[x1,x2]"), "set the same stiffness entries"),
        (PAPER, ("k2", "stiffness[x1,x2]"), "set the same stiffness entries"),
        (PAPER, ("stiffness[x9]",), "'x9' is not a coordinate of the structure: allowed x1, x2"),
        (PAPER, ("spring[x1,x1]",), "an element joins two different coordinates"),
        (PAPER, ("volume[x1]",), "is not a layout scalar: allowed mass[a]"),
        (PAPER, ("bumper_stiffness",), "are not Kelvin-Voigt bumpers"),
        (_chain(), ("k2",), "names a field of the paper's two-mass system"),
        (PAPER, ("k2", "k2"), "named twice"),
    ],
)
def test_bad_layout_scalars_are_refused_with_the_allowed_forms(problem: ImpactProblem, layout: tuple[str, ...], message: str) -> None:
    with pytest.raises(ValueError, match=message.replace("[", r"\[").replace("(", r"\(")):
        ImpactMap(problem, layout=layout)


def test_a_bumper_period_map_refuses_the_bumper_stiffness_too() -> None:
    with pytest.raises(ValueError, match="set the same Omega_b"):
        BumperPeriodMap(_bumper(), layout=("bumper_stiffness",))
