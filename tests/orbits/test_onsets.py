"""Continuation through contact onsets, scale-free (issue 31): a system that is not the paper's.

A chain of two unit masses between walls (springs k, k, k: natural frequencies 0.09 and 0.156 Hz), damping 3 % of
critical in the first mode (C = 2 zeta / w1 K), a lossless Kelvin-Voigt bumper of 100 N/m at 1 m clearance on the
first mass, 0.1 N on the second, and the same system with every frequency times 300 (stiffnesses and force times
300^2: the same motion in metres, in a 300 times shorter time). From the contact-free orbit at either end of the
band 0.08-0.13 Hz, one call of ``continue_branch`` with default settings must trace the whole branch: through the
lower onset (where a complex pair of multipliers leaves the unit circle), the Neimark-Sacker point, the fold at
0.1129 Hz, the fold next to the upper onset and the upper onset itself, on to the contact-free orbit at both ends;
the special points the same in non-dimensional frequency f / 0.09 Hz on both systems (1e-9); the onsets where the
linear orbit's |X1| reaches the clearance, from the receptance matrix directly (1e-14).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from vibroimpact.engines.compliant.exact import CompliantExactEngine
from vibroimpact.model.contact import KelvinVoigtBumper, Stop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.structure import LinearStructure
from vibroimpact.orbits.continuation import continue_branch
from vibroimpact.orbits.maps import ImpactMap
from vibroimpact.orbits.shooting import shoot

pytestmark = [pytest.mark.slow, pytest.mark.skipif(not hasattr(CompliantExactEngine, "strobe_map"), reason="needs the compiled compliant core")]

CLEARANCE, BUMPER, FORCE = 1.0, 100.0, 0.1  # [m], [N/m], [N]
BAND = (0.08, 0.13)  # [Hz] on the 0.1 Hz system


def chain(scale: float, frequency: float) -> ImpactProblem:
    """The chain with every frequency times ``scale``, forced at ``frequency`` [Hz] (of the scaled system)."""
    k = (2.0 * math.pi * 0.09 * scale) ** 2
    stiffness = np.array([[2.0 * k, -k], [-k, 2.0 * k]])
    damping = 0.03 * 2.0 / (2.0 * math.pi * 0.09 * scale) * stiffness
    structure = LinearStructure(np.eye(2).tolist(), stiffness.tolist(), damping.tolist())
    bumper = KelvinVoigtBumper(CLEARANCE, math.sqrt(BUMPER * scale**2) / (2.0 * math.pi), 0.0)
    return ImpactProblem(structure, (Stop(bumper, 0),), HarmonicForce(FORCE * scale**2, frequency, weights=(0.0, 1.0)))


def traced(scale: float, start: float):
    """The branch from the contact-free orbit at ``start`` (a fraction of the band's ends) with default settings."""
    problem = chain(scale, start * scale)
    system = ImpactMap(problem)
    closed = system.linear_orbit(system.parameters)
    assert closed is not None and closed[1] > 0.0  # contact-free where it starts
    return system, continue_branch(system, shoot(system, closed[0], system.parameters), "frequency")


@pytest.fixture(scope="module")
def branches():
    return {"top, 0.1 Hz": traced(1.0, BAND[1]), "bottom, x300": traced(300.0, BAND[0])}


def _onset(scale: float, low: float, high: float) -> float:
    """Where |X1| of the linear orbit, H(w) F from the receptance matrix, reaches the clearance [Hz]."""

    def excess(f: float) -> float:
        problem = chain(scale, f)
        h = problem.structure.receptance_matrix(2.0 * math.pi * f)
        return abs((h @ np.array([0.0, FORCE * scale**2]))[0]) - CLEARANCE

    return brentq(excess, low * scale, high * scale, xtol=1e-300, rtol=4.0 * np.finfo(float).eps)


def test_one_call_traces_the_whole_branch_from_either_end(branches) -> None:
    for name, (system, branch) in branches.items():
        scale = 300.0 if "x300" in name else 1.0
        assert branch.end == "clear, clear", name
        f = branch.values / scale
        assert f.min() < BAND[0] and f.max() > 0.1128, name
        assert set(branch.impacts) == {0, 1}
        assert max(o.residual for o in branch.orbits) < 1e-9
        kinds = [p.kind for p in sorted(branch.special_points, key=lambda p: p.value)]
        assert kinds == ["grazing", "neimark_sacker", "neimark_sacker", "fold", "grazing", "fold"] or kinds == [
            "grazing", "neimark_sacker", "neimark_sacker", "fold", "fold", "grazing"], (name, kinds)


def test_special_points_are_scale_free(branches) -> None:
    (_s, first), (_t, second) = branches.values()
    a = sorted((p.kind, p.value / 0.09) for p in first.special_points)
    b = sorted((p.kind, p.value / (0.09 * 300.0)) for p in second.special_points)
    assert [k for k, _ in a] == [k for k, _ in b]
    for (kind, x), (_, y) in zip(a, b):
        assert x == pytest.approx(y, rel=1e-9), kind


def test_onsets_are_the_linear_orbits_touch_and_name_what_happens(branches) -> None:
    for name, (system, branch) in branches.items():
        scale = 300.0 if "x300" in name else 1.0
        lower, upper = sorted(branch.special("grazing"), key=lambda p: p.value)
        assert lower.value == pytest.approx(_onset(scale, 0.08, 0.09), rel=1e-14)
        assert upper.value == pytest.approx(_onset(scale, 0.09, 0.11), rel=1e-14)
        # the lower onset: a complex pair of multipliers leaves the unit circle (within 1e-5 of the onset)
        assert "discontinuity-induced Neimark-Sacker" in lower.note and lower.continues
        assert "discontinuity-induced fold" in upper.note and upper.continues
        near = [p for p in branch.special("neimark_sacker") if "induced by it" in p.note]
        assert len(near) == 1 and 0.0 < near[0].value - lower.value < 1e-5 * lower.value
        assert near[0].induced_by == lower.value  # exact: the onset's own value, carried
        assert all((p.induced_by is not None) == ("induced by it" in p.note) for p in branch.special_points)
        # the grazing orbit is the linear one touching the bumper
        closed = system.linear_orbit(lower.orbit.parameters)
        assert abs(closed[1]) < 1e-9 and np.max(np.abs(lower.orbit.state - closed[0]) / system.state_scale) < 1e-9


def test_branch_measures_are_public_and_read_the_linear_orbit(branches) -> None:
    """``vibroimpact.branch_measures``: |X1| of every contact-free point is |H(w) F| of the first mass (1e-9), and
    the orbits at the onsets touch the bumper (|X1| = 1 m)."""
    from vibroimpact import branch_measures

    system, branch = branches["top, 0.1 Hz"]
    measures = branch_measures(system, branch)
    assert measures.parameter == "frequency" and measures.amplitudes.shape == (len(branch.orbits), 2)
    for f, x1, impacts in zip(measures.values, measures.amplitude(0), measures.impacts):
        h = chain(1.0, f).structure.receptance_matrix(2.0 * math.pi * f)
        linear = abs((h @ np.array([0.0, FORCE]))[0])
        if impacts == 0:
            assert x1 == pytest.approx(linear, rel=1e-9)
            assert linear <= CLEARANCE * (1.0 + 1e-9)
    assert np.min(np.abs(measures.amplitude(0) - CLEARANCE)) < 1e-9  # the onset orbits touch the bumper
    assert np.all(measures.peak_impulse[measures.impacts == 0] == 0.0)  # exact: no contact, no impulse
    assert np.all(measures.peak_impulse >= 0.0)
