"""The one-impact closed form on any structure (analysis.impact_orbit) against the paper's named form and against an
independent integration (tests/analysis/impact_flow.py: scipy DOP853 with exact gap events and Newton's restitution).

Sources: the seed paper's eqs. 8, 15-16 (corrected, README errata) for the named form; the general form replaces
q H12 by n^T H F, H22 by n^T H n and M2 by m_eff = 1 / (n^T M^-1 n) (module docstring of analysis.impact_orbit).
"""

from __future__ import annotations

import numpy as np
import pytest

from vibroimpact.analysis.greens import periodic_green
from vibroimpact.analysis.impact_orbit import ImpactOrbit, impulse_roots, solve_impact_orbit
from vibroimpact.analysis.layout import closed_form_refusal
from vibroimpact.analysis.linear import linear_amplitudes, paper_linear_response
from vibroimpact.analysis.pgf import solve_one_impact
from vibroimpact.analysis.stability import floquet_multipliers, monodromy
from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop
from vibroimpact.model.excitation import HarmonicForce, SweptSine
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.contact import Stop
from vibroimpact.model.modal import exact_pole_residue
from vibroimpact.model.structure import LinearStructure
from vibroimpact.model.system import PAPER_SYSTEM

from tests.analysis.impact_flow import ImpactFlow

FREQUENCIES = np.linspace(15.0, 45.0, 3001)


def paper_problem(restitution: float = 0.2, clearance: float = 3e-3, frequency: float = 25.0, phase: float = 0.0) -> ImpactProblem:
    """The paper's layout written as a general problem: matrices, a tuple with one upper stop on x2."""
    return ImpactProblem(PAPER_SYSTEM.structure, (Stop(RigidStop(clearance, restitution), 1),), HarmonicForce(10.0, frequency, phase))


def relative_problem(frequency: float, restitution: float = 0.6, phase: float = 0.3) -> ImpactProblem:
    """Ormondroyd & Den Hartog's 1928 layout: the stop limits x2 - x1 <= 3 mm."""
    return ImpactProblem(PAPER_SYSTEM.structure, (Stop(RigidStop(3e-3, restitution), 1, other=0),), HarmonicForce(10.0, frequency, phase))


THREE_DOF = LinearStructure(
    mass=[[2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.2]],
    stiffness=[[60000.0, -20000.0, 0.0], [-20000.0, 30000.0, -10000.0], [0.0, -10000.0, 10000.0]],
    damping=[[2.0, -0.5, 0.0], [-0.5, 0.8, -0.3], [0.0, -0.3, 0.3]],
    coordinates=("base_mass", "middle", "tip"),
)


def scales(problem: ImpactProblem, orbit: ImpactOrbit) -> np.ndarray:
    """Length L = |Delta| + a + |u_s| and velocity w L for each state component."""
    length = float(abs(orbit.clearance) + orbit.linear_amplitude + abs(orbit.static_offset))
    n = problem.size
    return np.concatenate([np.full(n, length), np.full(n, problem.omega * length)])


class NamedForm:
    """The paper's eqs. 8, 15-18 on its named system, written out from the exact poles and residues of H12 and H22
    (:func:`exact_pole_residue`: roots of D(s), residues N(p) / D'(p)), and the monodromy of its 4-state orbit: the
    reference the general form on the paper's layout is held to."""

    def __init__(self, omega: np.ndarray, clearance: float, restitution: float, amplitude: float) -> None:
        system = PAPER_SYSTEM
        self.omega, self.clearance, self.restitution, self.amplitude = omega, clearance, restitution, amplitude
        self.green12, self.green22 = exact_pole_residue(system, 1, 2), exact_pole_residue(system, 2, 2)
        self.h = system.receptances(omega)
        self.period = 2.0 * np.pi / omega
        chi0 = periodic_green(self.green22, omega, 0.0)
        c = (1.0 / (system.m2 * (1.0 + restitution)) + periodic_green(self.green22, omega, self.period, 1)) / omega
        a = amplitude * np.abs(self.h.h12)
        quad = c**2 + chi0**2
        self.impulse = impulse_roots(quad, clearance * chi0, quad * a**2 - (c * clearance) ** 2, clearance**2 - a**2)
        self.exists = np.isfinite(self.impulse) & (self.impulse >= 0.0)
        with np.errstate(invalid="ignore"):
            self.phase = np.arctan2(-self.impulse * c / a, (clearance + self.impulse * chi0) / a)

    def harmonics(self) -> np.ndarray:
        """Eqs. 17-18: (X1, X2) [m], time from the impact."""
        h, rate = self.h, 2.0 * self.impulse / self.period
        x1 = self.amplitude * h.h11 * np.exp(1j * self.phase) * np.conj(h.h12) / np.abs(h.h12) - rate * h.h12
        x2 = self.amplitude * np.abs(h.h12) * np.exp(1j * self.phase) - rate * h.h22
        return np.stack([x1, x2], axis=-1)

    def motion(self, t: np.ndarray, derivative: int = 0) -> np.ndarray:
        """Eq. 8: (x1, x2)(t) or a derivative, t of shape S + (m,) [m s-derivative]."""
        w, phi, impulse = self.omega[..., None], self.phase[..., None], self.impulse[..., None]
        h11, h12 = self.h.h11[..., None], self.h.h12[..., None]
        turn = derivative * np.pi / 2.0
        x1 = self.amplitude * np.abs(h11) * w**derivative * np.cos(w * t + phi + np.angle(h11) - np.angle(h12) + turn)
        x2 = self.amplitude * np.abs(h12) * w**derivative * np.cos(w * t + phi + turn)
        x1 = x1 - impulse * periodic_green(self.green12, w, t, derivative)
        x2 = x2 - impulse * periodic_green(self.green22, w, t, derivative)
        return np.stack([x1, x2], axis=-1)

    def multipliers(self) -> np.ndarray:
        """Eigenvalues of S exp(A T) of the 4-state orbit: the reset D = diag(1, 1, 1, -R) on the surface x2 = Delta
        (normal e2) and the saltation S = D + (f(y+) - D f(y-)) e2^T / (e2 . f(y-)) [-], shape S + (4,); NaN where no
        orbit exists."""
        system = PAPER_SYSTEM
        ends = np.stack([np.zeros_like(self.period), self.period], axis=-1)  # t = 0+ and T- (= 0-)
        x, v = self.motion(ends), self.motion(ends, 1)
        force = np.stack([self.amplitude * np.cos(self.phase - np.angle(self.h.h12)), np.zeros_like(self.phase)], axis=-1)
        minv = np.linalg.inv(system.mass_matrix)

        def field(position: np.ndarray, velocity: np.ndarray) -> np.ndarray:
            acceleration = (force - position @ system.stiffness_matrix.T - velocity @ system.damping_matrix.T) @ minv.T
            return np.concatenate([velocity, acceleration], axis=-1)

        before, after = field(x[..., 1, :], v[..., 1, :]), field(x[..., 0, :], v[..., 0, :])
        reset = np.diag([1.0, 1.0, 1.0, -self.restitution])
        saltation = reset + (after - before @ reset.T)[..., :, None] * np.array([0.0, 1.0, 0.0, 0.0]) / before[..., 1, None, None]
        values, vectors = np.linalg.eig(system.state_matrix)
        flow = np.real(np.einsum("ij,...j,jk->...ik", vectors, np.exp(values * self.period[..., None]), np.linalg.inv(vectors)))
        monodromy = saltation @ flow
        out = np.full(self.omega.shape + (4,), np.nan, dtype=complex)
        ok = np.all(np.isfinite(monodromy), axis=(-2, -1))
        out[ok] = np.linalg.eigvals(monodromy[ok])
        return out


def test_paper_layout_as_structure_equals_named_form() -> None:
    """Impulse, phase, harmonics, reconstructed motion and multipliers of the general form on the paper's layout equal
    the named form's (:class:`NamedForm`: exact poles and residues of H22 and H12, the 4-state monodromy) over
    15-45 Hz, R = 0.2, 3 mm, 10 N; ``solve_one_impact`` of the named system is that general form.

    Tolerances: 1e-12 relative for J and phi; 1e-12 of the motion's scale Delta + q|H12| for harmonics and signals
    (near a resonance the periodic Green function amplifies a pole's last-bit difference by T|p| / |1 - e^{pT}| ~ 500,
    so relative to a small harmonic the two differ by up to 1e-11); multipliers to 1e-12 of the largest."""
    w = 2.0 * np.pi * FREQUENCIES
    named = NamedForm(w, 3e-3, 0.2, 10.0)
    general = solve_one_impact(paper_problem(), omega=w)
    assert isinstance(general, ImpactOrbit)
    from_system = solve_one_impact(PAPER_SYSTEM, omega=w, clearance=3e-3, restitution=0.2, amplitude=10.0)
    np.testing.assert_array_equal(from_system.impulse, general.impulse)  # NaN where none: the same arrays
    np.testing.assert_array_equal(general.exists, named.exists)
    e = named.exists
    assert e.sum() > 1000
    np.testing.assert_allclose(general.impulse[e], named.impulse[e], rtol=1e-12)
    np.testing.assert_allclose(np.angle(np.exp(1j * (general.phase[e] - named.phase[e]))), 0.0, atol=1e-12)
    scale = 3e-3 + 10.0 * np.abs(named.h.h12)
    assert np.max(np.abs(general.harmonics()[e] - named.harmonics()[e]) / scale[e, None]) < 1e-12
    t = np.linspace(0.0, 1.0, 41)[None, :] * named.period[:, None]
    assert np.max(np.abs(general.displacement(t)[e] - named.motion(t)[e]) / scale[e, None, None]) < 1e-12
    ours, theirs = floquet_multipliers(general)[e], named.multipliers()[e]
    nearest = np.min(np.abs(ours[:, :, None] - theirs[:, None, :]), axis=-1)  # each of ours to the closest of theirs
    largest = np.max(np.abs(theirs), axis=-1, keepdims=True)
    assert np.max(nearest / largest) < 1e-12


def test_linear_amplitudes_of_paper_layout_and_relative_coordinate() -> None:
    """linear_amplitudes equals paper_linear_response (q H11, q H12) on the paper's layout; a relative stop's amplitude is
    x2 - x1 = q (H12 - H11), to round-off."""
    w = 2.0 * np.pi * FREQUENCIES
    paper = paper_linear_response(PAPER_SYSTEM, omega=w, amplitude=10.0)
    general = linear_amplitudes(paper_problem(), omega=w)
    np.testing.assert_allclose(general.coordinate("x1"), paper.x1, rtol=1e-13)
    np.testing.assert_allclose(general.stop_amplitudes[..., 0], paper.x2, rtol=1e-13)
    relative = linear_amplitudes(relative_problem(25.0, phase=0.0), omega=w)
    np.testing.assert_allclose(relative.stop_amplitudes[..., 0], paper.x2 - paper.x1, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(relative.relative("x2", "x1"), paper.x2 - paper.x1, rtol=1e-12, atol=1e-15)


def reconstructed_impact_conditions(problem: ImpactProblem, orbit: ImpactOrbit) -> None:
    """u(0) = Delta, n.x'(0+) = -R n.x'(0-), J = m_eff (1 + R) n.x'(0-), and M (x'(0+) - x'(0-)) = -J n (momentum)."""
    n, mass = orbit.normal, problem.structure.mass_matrix
    size = problem.size
    after, before = orbit.state_after_impact(), orbit.state_before_impact()
    length, velocity = scales(problem, orbit)[0], scales(problem, orbit)[-1]
    assert n @ after[:size] == pytest.approx(float(orbit.clearance), abs=1e-14 * length)
    np.testing.assert_allclose(after[:size], before[:size], atol=1e-13 * length)
    restitution = float(orbit.restitution)
    assert n @ after[size:] == pytest.approx(-restitution * (n @ before[size:]), abs=1e-12 * velocity)
    assert float(orbit.impulse) == pytest.approx(orbit.layout.effective_mass * (1 + restitution) * (n @ before[size:]), rel=1e-12)
    np.testing.assert_allclose(mass @ (after[size:] - before[size:]), -float(orbit.impulse) * n, atol=1e-12 * float(orbit.impulse))


@pytest.mark.parametrize("frequency", [22.5, 42.0])
def test_relative_stop_orbit_repeats_under_independent_integration(frequency: float) -> None:
    """1928 layout (x2 - x1 <= 3 mm, R = 0.6): the closed-form state at t = 0, integrated over 3 periods by DOP853 with
    events, repeats to 1e-9 of the motion's scale, with one impact per period of the closed-form impulse (1e-9) at
    the closed-form time; the total momentum is unchanged by each impact (the stop acts on both bodies)."""
    problem = relative_problem(frequency)
    orbit = solve_impact_orbit(problem)
    assert orbit.exists and orbit.admissible()
    reconstructed_impact_conditions(problem, orbit)
    start = orbit.state_at(np.array([0.0]))[0]
    end, impacts = ImpactFlow(problem).run(start, 0.0, 3 * problem.period)
    assert np.max(np.abs(end - start) / scales(problem, orbit)) < 1e-9
    assert len(impacts) == 3
    mass = problem.structure.mass_matrix
    for k, impact in enumerate(impacts):
        assert impact.impulse == pytest.approx(float(orbit.impulse), rel=1e-9)
        assert impact.time == pytest.approx(float(orbit.impact_time) + k * problem.period, abs=1e-9 * problem.period)
        momentum = np.sum(mass @ impact.after) - np.sum(mass @ impact.before)
        assert abs(momentum) <= 1e-12 * impact.impulse


def test_stable_relative_orbit_attracts_a_perturbed_start() -> None:
    """Stable by Floquet (max |mu| = 0.98 at 42 Hz): a start 1e-4 off the orbit returns towards it; the strobe distance
    after 200 periods is below max|mu|^200 times the start's (within a factor 100 for the non-normal transient)."""
    problem = relative_problem(42.0)
    orbit = solve_impact_orbit(problem)
    modulus = float(np.max(np.abs(floquet_multipliers(orbit))))
    assert modulus < 1.0
    start = orbit.state_at(np.array([0.0]))[0]
    scale = scales(problem, orbit)
    perturbed = start + 1e-4 * scale * np.array([1.0, -0.5, 0.3, 0.2])
    end, _ = ImpactFlow(problem, rtol=1e-11).run(perturbed, 0.0, 200 * problem.period)
    distance = float(np.max(np.abs(end - start) / scale))
    assert distance < 100.0 * modulus**200 * 1e-4


def finite_difference_monodromy(problem: ImpactProblem, orbit: ImpactOrbit) -> np.ndarray:
    """The Jacobian of the integrated stroboscopic map over one period, from mid-flight, by central differences."""
    flow = ImpactFlow(problem)
    t0 = float(orbit.impact_time) + 0.5 * float(orbit.window)
    start = orbit.state_at(np.array([t0]))[0]
    scale = scales(problem, orbit)
    size = start.size
    jacobian = np.zeros((size, size))
    for k in range(size):
        step = np.zeros(size)
        step[k] = 1e-6 * scale[k]
        plus, _ = flow.run(start + step, t0, t0 + problem.period)
        minus, _ = flow.run(start - step, t0, t0 + problem.period)
        jacobian[:, k] = (plus - minus) / (2 * step[k])
    return jacobian


def test_three_dof_relative_stop_multipliers_equal_integrated_jacobian() -> None:
    """N = 3, a lower relative stop (tip - middle >= -2 mm) with a static load: the 6 x 6 monodromy's multipliers
    equal the eigenvalues of the finite-difference Jacobian of the integrated map (1e-5 of the largest)."""
    stop = Stop(RigidStop(2e-3, 0.5), 2, other=1, side="lower")
    load = HarmonicForce(30.0, 40.0, 0.2, weights=(1.0, 0.0, 0.0), static=(0.0, -5.0, 3.0))
    problem = ImpactProblem(THREE_DOF, (stop,), load)
    frequencies = np.linspace(20.0, 60.0, 401)
    survey = solve_impact_orbit(problem, omega=2 * np.pi * frequencies)
    good = np.flatnonzero(survey.admissible())
    assert good.size > 10
    frequency = float(frequencies[good[good.size // 2]])
    problem = ImpactProblem(THREE_DOF, (stop,), HarmonicForce(30.0, frequency, 0.2, weights=(1.0, 0.0, 0.0), static=(0.0, -5.0, 3.0)))
    orbit = solve_impact_orbit(problem)
    reconstructed_impact_conditions(problem, orbit)
    start = orbit.state_at(np.array([0.0]))[0]
    end, impacts = ImpactFlow(problem).run(start, 0.0, 2 * problem.period)
    assert np.max(np.abs(end - start) / scales(problem, orbit)) < 1e-9
    assert len(impacts) == 2 and all(i.stop == 0 for i in impacts)
    expected = np.linalg.eigvals(finite_difference_monodromy(problem, orbit))
    ours = floquet_multipliers(orbit)
    largest = float(np.max(np.abs(expected)))
    np.testing.assert_allclose(np.sort(np.abs(ours)), np.sort(np.abs(expected)), atol=1e-5 * largest)
    # det(monodromy) = det(S) det(exp(A T)) = R^2 exp(tr(A) T) (the saltation scales the normal position and velocity by -R)
    determinant = np.linalg.det(monodromy(orbit))
    assert determinant == pytest.approx(0.25 * np.exp(np.trace(THREE_DOF.state_matrix) * problem.period), rel=1e-9)


def test_static_load_shifts_the_clearance() -> None:
    """A static force moves the stopped coordinate by u_s = n K^-1 F0: the orbit with Delta and u_s has the impulse and
    phase of the orbit with Delta - u_s and no static load (1e-13), and its motion is shifted by K^-1 F0."""
    static = (4.0, -2.0)
    loaded = ImpactProblem(PAPER_SYSTEM.structure, (Stop(RigidStop(3e-3, 0.4), 1),), HarmonicForce(10.0, 25.0, static=static))
    orbit = solve_impact_orbit(loaded)
    shift = np.linalg.solve(PAPER_SYSTEM.stiffness_matrix, np.array(static))
    plain = solve_impact_orbit(paper_problem(0.4, clearance=3e-3 - shift[1]))
    assert float(orbit.impulse) == pytest.approx(float(plain.impulse), rel=1e-13)
    assert float(orbit.phase) == pytest.approx(float(plain.phase), abs=1e-13)
    t = np.linspace(0.0, 1.0, 9)[None, :] * orbit.period
    np.testing.assert_allclose(orbit.displacement(t), plain.displacement(t) + shift, atol=1e-15)


def test_refusals_name_the_reason() -> None:
    """No closed form: a rigid-body mode, a bumper, a swept sine, several stops that are not a symmetric pair."""
    free = LinearStructure([[1.0, 0.0], [0.0, 0.1]], [[4300.0, -4300.0], [-4300.0, 4300.0]])
    problem = ImpactProblem(free, (Stop(RigidStop(3e-3, 0.5), 1, other=0),), HarmonicForce(1.0, 20.0))
    with pytest.raises(ValueError, match="rigid-body mode"):
        solve_one_impact(problem)
    bumper = ImpactProblem(PAPER_SYSTEM.structure, (Stop(KelvinVoigtBumper(3e-3, 500.0, 0.1), 1),), HarmonicForce(10.0, 25.0))
    with pytest.raises(ValueError, match="rigid stops"):
        solve_one_impact(bumper)
    swept = ImpactProblem(PAPER_SYSTEM.structure, (Stop(RigidStop(3e-3, 0.5), 1),), SweptSine(10.0, 15.0, 45.0, 0.1))
    assert "harmonic force" in closed_form_refusal(swept)
    two = (Stop(RigidStop(3e-3, 0.5), 1), Stop(RigidStop(2e-3, 0.5), 1, side="lower"))
    with pytest.raises(ValueError, match="clearances or restitutions differ"):
        solve_one_impact(ImpactProblem(PAPER_SYSTEM.structure, two, HarmonicForce(10.0, 25.0)))
    three = (*two, Stop(RigidStop(3e-3, 0.5), 0))
    with pytest.raises(ValueError, match="3 stops"):
        solve_one_impact(ImpactProblem(PAPER_SYSTEM.structure, three, HarmonicForce(10.0, 25.0)))
    pair = (Stop(RigidStop(3e-3, 0.5), 1), Stop(RigidStop(3e-3, 0.5), 1, side="lower"))
    with pytest.raises(ValueError, match="solve_two_impacts"):
        solve_one_impact(ImpactProblem(PAPER_SYSTEM.structure, pair, HarmonicForce(10.0, 25.0)))
    assert closed_form_refusal(paper_problem()) is None
