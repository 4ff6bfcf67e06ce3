"""The one rigid-mode rule (model/structure.py, :func:`stiffness_modes`): an eigenvalue of K at most RIGID_MODE_RATIO
(1e-12) of the largest is a rigid-body mode, for every judgement that asks. Before, the structure's rigid-body modes,
the closed forms' refusal and a scene's static drift judged at 1e-10 of K's largest entry while the exact flows, the
bumper limit and the contact-free stability judged at 1e-12: a spring 1e-11 of the stiffest was a free mass to the
first and a spring to the others."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vibroimpact.analysis.layout import layout_refusal
from vibroimpact.analysis.linear import contact_free_is_stable
from vibroimpact.engines.exact_flows import mechanical_null_basis
from vibroimpact.model import structure as structure_module
from vibroimpact.model.bumper_limit import STIFFNESS_SPREAD, bumper_refusal
from vibroimpact.model.contact import KelvinVoigtBumper, Stop, loss_factor_from_restitution
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.layout import Layout, LoadSpec, StopSpec
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.structure import _ROUND_OFF, RIGID_MODE_RATIO, SOFTEST_SPRING, STIFFNESS_RATIO, LinearStructure, stiffness_modes
from vibroimpact.model.system import PAPER_SYSTEM, TwoDofSystem
from vibroimpact.reporting.record import GeneralSetting
from vibroimpact.scene.layout_parse import static_drift

from tests.conftest import PAPER_AMPLITUDE, PAPER_CLEARANCE

#: A bumper on x1 of K_b = 1000 N/m (unit masses): its normal is orthogonal to the soft mode x2, which it cannot stop.
BUMPER_FREQUENCY = math.sqrt(1000.0) / (2.0 * math.pi)


def soft_structure(ratio: float) -> LinearStructure:
    """x1 on a spring of 1 N/m with a dashpot, x2 on a spring of ``ratio`` N/m without one (unit masses): K's
    eigenvalues are exactly ``ratio`` and 1, the soft mode is x2 and no dashpot resists it."""
    return LinearStructure([[1.0, 0.0], [0.0, 1.0]], [[1.0, 0.0], [0.0, ratio]], [[0.1, 0.0], [0.0, 0.0]])


def verdicts(structure: LinearStructure) -> dict[str, bool]:
    """Whether each judgement that asks the rule takes x2's mode for a rigid-body one, read from what it does."""
    mass, stiffness, damping = structure.mass_matrix, structure.stiffness_matrix, structure.damping_matrix
    stop = StopSpec(0, clearance=1e-3, restitution=0.5)
    setting = GeneralSetting(structure, 1.0, False, np.array([1.0, 0.0]), np.array([0.0, 1.0]), ("x1 <= 1 mm",), np.array([[1.0, 0.0]]), ("exact",), np.array([1e-3]))
    bumped = ImpactProblem(structure, (Stop(KelvinVoigtBumper(1e-3, BUMPER_FREQUENCY, 0.3), coordinate=0),), HarmonicForce(1.0, 0.5))
    return {
        "LinearStructure.rigid_body_modes": structure.rigid_body_modes() == 1,
        "closed forms (analysis.layout)": "rigid-body mode" in (layout_refusal(Layout(structure, LoadSpec(), (stop,))) or ""),
        "exact flows (mechanical_null_basis)": mechanical_null_basis(mass, stiffness, damping).shape[1] > 0,
        "contact-free stability (analysis.linear)": not contact_free_is_stable(structure),  # rigid and undamped: unstable
        "static drift (scene)": static_drift(Layout(structure, LoadSpec(static=(0.0, 1.0)), (stop,))),
        "static deflection (report)": setting.static_deflection() is None,
        # a rigid mode the bumper cannot stop stays rigid in contact and is not judged; a flexible one of 1e-9 or less
        # next to the contact's 1001 N/m is under STIFFNESS_SPREAD and refused
        "bumper limit (model.bumper_limit)": bumper_refusal(bumped) is None,
    }


def test_the_refusal_edges_lie_strictly_inside_the_rule() -> None:
    """What lies near the rule is refused before any work: a contact mode softer than STIFFNESS_SPREAD (10x above),
    a scene's eigenvalue between _ROUND_OFF (10x below) and SOFTEST_SPRING (100x above); the named system's springs
    within STIFFNESS_RATIO keep K's eigenvalue ratio above SOFTEST_SPRING."""
    assert _ROUND_OFF < RIGID_MODE_RATIO < STIFFNESS_SPREAD < SOFTEST_SPRING
    for k2 in (1.0 / STIFFNESS_RATIO, STIFFNESS_RATIO):
        system = TwoDofSystem(m1=1.0, m2=0.1, k1=1.0, k2=k2, b1=0.01, b2=0.001)
        system.check_ratios()
        system.structure.check_dynamic_range()
        values = np.linalg.eigvalsh(system.structure.stiffness_matrix)
        assert values[0] > SOFTEST_SPRING * values[-1]
        assert system.rigid_body_modes() == 0 and system.structure.rigid_body_modes() == 0


@pytest.mark.parametrize("ratio", [0.0, 5e-13, 1e-12, 2e-12, 1e-11, 5e-11, 1e-10, 1.01e-10, 1e-9])
def test_every_judgement_agrees_on_each_side_of_the_rule(ratio: float) -> None:
    """A free mass (0), a round-off-sized spring (5e-13) and one exactly at the rule (1e-12) are rigid-body modes to
    every judgement; 2e-12 ... 1e-9 are springs to every one (before, those up to 1e-10 were free masses to the
    structure's count, the closed forms and the static drift, and springs to the exact flows)."""
    rigid = ratio <= RIGID_MODE_RATIO
    assert verdicts(soft_structure(ratio)) == dict.fromkeys(verdicts(soft_structure(0.0)), rigid)
    assert stiffness_modes(soft_structure(ratio).stiffness_matrix).count == int(rigid)
    if ratio > 0.0 and not math.isclose(ratio, RIGID_MODE_RATIO, rel_tol=0.01):  # the named system's K: round-off ~1e-16
        named = TwoDofSystem(m1=1.0, m2=1.0, k1=1.0, k2=ratio, b1=0.1, b2=0.0)
        assert named.rigid_body_modes() == named.structure.rigid_body_modes() == int(rigid)


def test_every_judgement_reads_the_one_threshold(monkeypatch: pytest.MonkeyPatch) -> None:
    """A spring 1e-11 of the stiffest is a spring to every judgement; with the rule moved to 1e-10 it is a free mass
    to every one: none keeps a threshold of its own."""
    structure = soft_structure(1e-11)
    assert not any(verdicts(structure).values())
    monkeypatch.setattr(structure_module, "RIGID_MODE_RATIO", 1e-10)
    assert all(verdicts(structure).values()), verdicts(structure)


def test_a_floating_pair_has_one_rigid_mode_zero_to_round_off() -> None:
    """Two masses joined by one spring and nothing else: eigh's zero is round-off (~1e-16 of the largest), far under
    _ROUND_OFF, so a scene accepts it and every judgement sees one rigid-body mode."""
    pair = LinearStructure([[1.0, 0.0], [0.0, 0.1]], [[4300.0, -4300.0], [-4300.0, 4300.0]], [[0.08, -0.08], [-0.08, 0.08]])
    modes = stiffness_modes(pair.stiffness_matrix)
    assert modes.count == pair.rigid_body_modes() == 1
    assert abs(modes.values[0]) <= 1e-15 * modes.scale
    np.testing.assert_allclose(np.abs(modes.rigid[:, 0]), [math.sqrt(0.5)] * 2, rtol=1e-12)
    pair.check_dynamic_range()
    basis = mechanical_null_basis(pair.mass_matrix, pair.stiffness_matrix, np.zeros((2, 2)))
    assert basis.shape == (4, 2)  # the rigid translation and, undamped, its drift


def test_the_softest_spring_a_scene_accepts_is_a_spring_and_a_softer_one_is_refused() -> None:
    """1.01e-10 of the stiffest passes the scene's check and is a spring everywhere (above); 0.99e-10 is refused,
    naming the ratio, and so is every eigenvalue down to _ROUND_OFF (1e-13): none near the rule reaches a run."""
    soft_structure(1.01 * SOFTEST_SPRING).check_dynamic_range()
    for ratio in (0.99 * SOFTEST_SPRING, RIGID_MODE_RATIO, 2.0 * _ROUND_OFF):
        with pytest.raises(ValueError, match=r"system.stiffness: largest / smallest nonzero eigenvalue = .* is out of range: allowed \[1, 1e10\]"):
            soft_structure(ratio).check_dynamic_range()
    soft_structure(0.5 * _ROUND_OFF).check_dynamic_range()  # zero to round-off: a free mass


@pytest.mark.parametrize(("frequency", "accepted", "rigid"), [(2.7e7, True, 0), (5e7, False, 0), (8e7, False, 0), (9e7, False, 1)])
def test_the_bumper_limit_refuses_before_the_rule_takes_a_flexible_mode_for_rigid(frequency: float, accepted: bool, rigid: int) -> None:
    """The paper's system against ever stiffer bumpers: the stiffest accepted (2.7e7 Hz, contact spread 1.0e-11) and
    the refused ones up to 8e7 Hz (1.2e-12) keep the primary's mode flexible in contact; from 9e7 Hz (9.2e-13) the rule
    takes it for rigid, the wrong answer (|X1| 27 % low) the refusal stands for."""
    law = KelvinVoigtBumper(PAPER_CLEARANCE, frequency, loss_factor_from_restitution(0.2))
    problem = ImpactProblem(PAPER_SYSTEM, law, HarmonicForce(PAPER_AMPLITUDE, 24.0))
    assert (bumper_refusal(problem) is None) == accepted
    normal = problem.normals()[0]
    structure = problem.structure
    k_mode = structure.stiffness_matrix + law.stiffness(problem.stops[0].effective_mass(structure.mass_matrix)) * np.outer(normal, normal)
    assert stiffness_modes(k_mode).count == rigid
    assert mechanical_null_basis(structure.mass_matrix, k_mode, structure.damping_matrix).shape[1] == rigid
