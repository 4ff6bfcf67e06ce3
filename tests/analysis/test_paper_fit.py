"""The paper's own route (``pgf_paper``) as an option of the one closed form: ``solve_impact_orbit(..., green=PaperFit)``.

Checked against the paper's formulas written out here independently of the solver: its eq. 26 (the fitted modal
parameters), eq. 12 / 14 as printed (chi22 from real modal parameters), eq. 16 (corrected bracket) with the paper's
c = (1 - R) / (2 (1 + R) M2 w), and eq. 8 (the motion: exact chi12 for x1, the fitted chi22 for x2).
"""

from __future__ import annotations

import numpy as np
import pytest

from vibroimpact.analysis.greens import paper_periodic_green, periodic_green
from vibroimpact.analysis.impact_orbit import ImpactOrbit, solve_impact_orbit
from vibroimpact.analysis.paper_fit import PaperFit
from vibroimpact.analysis.pgf import solve_one_impact
from vibroimpact.model.contact import RigidStop, Stop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.modal import exact_pole_residue
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM, TwoDofSystem

from tests.conftest import PAPER_AMPLITUDE, PAPER_CLEARANCE

FREQUENCIES = np.arange(15.0, 45.0, 0.01)


def paper_problem(system: TwoDofSystem = PAPER_SYSTEM) -> ImpactProblem:
    return ImpactProblem(system, RigidStop(PAPER_CLEARANCE, 0.2), HarmonicForce(PAPER_AMPLITUDE, 25.0))


def paper_orbit(restitution: float, frequency: np.ndarray = FREQUENCIES) -> ImpactOrbit:
    problem = paper_problem()
    return solve_impact_orbit(problem, omega=2.0 * np.pi * frequency, restitution=restitution, green=PaperFit.of(problem))


def test_the_fit_is_the_paper_s_eq_26() -> None:
    """A = 2.75, 7.25 [kg-1]; xi = 0.0022, 0.0023 (the paper's eq. 26, second of that number); Omega from eq. 25."""
    fit = PaperFit.of(paper_problem())
    np.testing.assert_allclose(fit.parameters.form_factor, [2.75, 7.25], atol=0.01)
    np.testing.assert_allclose(np.round(fit.parameters.loss_factor, 4), [0.0022, 0.0023])
    np.testing.assert_allclose(fit.parameters.omega / (2.0 * np.pi), [23.02, 36.07], atol=0.005)


@pytest.mark.parametrize("restitution", [0.0, 0.2, 0.8])
def test_impulse_and_phase_are_the_paper_s_eqs_14_to_16(restitution: float) -> None:
    """chi0 is eq. 14 (eq. 12 at t = 0 from the fitted modal parameters), chi22'(0-) the constant -1/(2 M2), and J the
    '+' root of eq. 16 with the paper's c, written out here; sin(phi) = -J c / a (eq. 15). Tolerances 1e-10: next to a
    resonance the sums amplify round-off by kappa ~ 1 / (2 pi xi) ~ 70 (1.4e-12 for chi0 at 23.02 Hz), and the direct
    quadratic formula loses a few digits where its terms nearly cancel."""
    system = PAPER_SYSTEM
    orbit = paper_orbit(restitution)
    w = orbit.omega
    fit = PaperFit.of(paper_problem())
    chi0 = paper_periodic_green(fit.parameters, w, 0.0)
    np.testing.assert_allclose(orbit.chi0, chi0, rtol=1e-10)
    np.testing.assert_allclose(orbit.chi_rate_before, -1.0 / (2.0 * system.m2), rtol=1e-15)
    c = (1.0 - restitution) / (2.0 * (1.0 + restitution) * system.m2 * w)
    a = PAPER_AMPLITUDE * np.abs(system.receptances(w).h12)
    quad = c**2 + chi0**2
    with np.errstate(invalid="ignore"):
        impulse = (-PAPER_CLEARANCE * chi0 + np.sqrt((PAPER_CLEARANCE * chi0) ** 2 - quad * (PAPER_CLEARANCE**2 - a**2))) / quad
    e = orbit.exists
    assert e.sum() > 500
    np.testing.assert_array_equal(e, np.isfinite(impulse) & (impulse >= 0.0))
    np.testing.assert_allclose(orbit.impulse[e], impulse[e], rtol=1e-10)
    np.testing.assert_allclose(np.sin(orbit.phase[e]), -impulse[e] * c[e] / a[e], rtol=1e-9, atol=1e-12)


def test_the_motion_is_eq_8_with_the_exact_chi12_and_the_fitted_chi22() -> None:
    """x1(t) = q |H11| cos(wt + psi11 + phi - psi12) - J chi12(t) with the exact chi12, x2(t) = q |H12| cos(wt + phi) -
    J chi22(t) with eq. 12 of the fitted parameters, to 1e-11 of Delta + q |H12|; x2(0) = Delta."""
    system = PAPER_SYSTEM
    orbit = paper_orbit(0.2, FREQUENCIES[::10])
    e = orbit.exists
    w, phi, impulse = orbit.omega[e, None], orbit.phase[e, None], orbit.impulse[e, None]
    t = np.linspace(0.0, 1.0, 21)[None, :] * 2.0 * np.pi / w
    h = system.receptances(w)
    fit = PaperFit.of(paper_problem())
    x1 = PAPER_AMPLITUDE * np.abs(h.h11) * np.cos(w * t + np.angle(h.h11) + phi - np.angle(h.h12)) - impulse * periodic_green(exact_pole_residue(system, 1, 2), w, t)
    x2 = PAPER_AMPLITUDE * np.abs(h.h12) * np.cos(w * t + phi) - impulse * paper_periodic_green(fit.parameters, w, t)
    scale = PAPER_CLEARANCE + PAPER_AMPLITUDE * np.abs(h.h12)
    motion = orbit.take(np.flatnonzero(e)).displacement(t)
    assert np.max(np.abs(motion[..., 0] - x1) / scale) < 1e-11
    assert np.max(np.abs(motion[..., 1] - x2) / scale) < 1e-11
    np.testing.assert_allclose(motion[:, 0, 1], PAPER_CLEARANCE, rtol=1e-12)


def test_the_fit_is_refused_off_the_paper_s_layout() -> None:
    """A relative stop, or a fit of another system, is not the paper's route: ValueError naming pgf."""
    relative = ImpactProblem(PAPER_SYSTEM.structure, (Stop(RigidStop(3e-3, 0.2), 1, other=0),), HarmonicForce(10.0, 25.0))
    with pytest.raises(ValueError, match="use pgf"):
        PaperFit.of(relative)
    other = paper_problem(TwoDofSystem(m1=1.0, m2=0.1, k1=25_000.0, k2=4_000.0, b1=0.8, b2=0.08))
    with pytest.raises(ValueError, match="another system"):
        solve_impact_orbit(other, green=PaperFit.of(paper_problem()))


def test_solve_one_impact_takes_the_paper_s_route_on_its_layout_only() -> None:
    """``solve_one_impact(..., variant='pgf_paper')`` is the option: from the named system or from a problem of the
    paper's layout the same orbit (an ImpactOrbit), refused (ValueError naming pgf) on another layout."""
    w = 2.0 * np.pi * FREQUENCIES[::50]
    named = solve_one_impact(PAPER_SYSTEM, omega=w, clearance=PAPER_CLEARANCE, restitution=0.2, amplitude=PAPER_AMPLITUDE, variant="pgf_paper")
    assert isinstance(named, ImpactOrbit)
    np.testing.assert_array_equal(named.impulse, paper_orbit(0.2, FREQUENCIES[::50]).impulse)
    np.testing.assert_array_equal(solve_one_impact(paper_problem(), omega=w, variant="pgf_paper").impulse, named.impulse)
    relative = ImpactProblem(PAPER_SYSTEM.structure, (Stop(RigidStop(3e-3, 0.2), 1, other=0),), HarmonicForce(10.0, 25.0))
    with pytest.raises(ValueError, match="use pgf"):
        solve_one_impact(relative, variant="pgf_paper")


def test_the_fit_asks_its_own_problem_s_layout_once() -> None:
    """The fit remembers the problem it found to be the paper's layout and computes its fitted model once: the modes of
    that problem are those of any problem of the same layout (bit for bit), and the fitted model's poles are eq. 10's
    -xi Omega +- j Theta; another layout is still refused."""
    problem = paper_problem()
    fit = PaperFit.of(problem)
    assert fit.problem is problem and fit.model is fit.model  # one computation
    own, other = fit.modes(problem), fit.modes(paper_problem())
    np.testing.assert_array_equal(own.poles, other.poles)  # exact: the same structure and fit
    np.testing.assert_array_equal(own.residues, other.residues)  # exact: the same structure and fit
    parameters = fit.parameters
    upper = -parameters.loss_factor * parameters.omega + 1j * parameters.damped_omega
    np.testing.assert_allclose(np.sort_complex(own.poles[-4:]), np.sort_complex(np.concatenate([upper, np.conj(upper)])), rtol=1e-14)
    relative = ImpactProblem(PAPER_SYSTEM.structure, (Stop(RigidStop(3e-3, 0.2), 1, other=0),), HarmonicForce(10.0, 25.0))
    with pytest.raises(ValueError, match="another system or layout"):
        fit.modes(relative)
