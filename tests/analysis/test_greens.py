"""Periodic Green functions: closed form (eq. 12 generalised) vs the Fourier series of eq. 7."""

from __future__ import annotations

import numpy as np
import pytest

from vibroimpact.analysis.greens import paper_periodic_green, periodic_green
from vibroimpact.model.modal import exact_pole_residue, fit_modal_parameters
from vibroimpact.model.system import TwoDofSystem


def fourier_series_chi(system: TwoDofSystem, omega: float, t: np.ndarray, terms: int) -> np.ndarray:
    """chi22(t) = (1/T) sum_{|m| <= terms} H22(j m w) exp(j m w t), summed directly (eq. 7)."""
    period = 2 * np.pi / omega
    total = np.full(t.shape, system.receptances(0.0).h22.real / period)
    for start in range(1, terms + 1, 65536):
        m = np.arange(start, min(start + 65536, terms + 1))
        h = system.receptances(m * omega).h22
        total += 2.0 * np.real(h[None, :] * np.exp(1j * np.outer(t, m) * omega)).sum(axis=1) / period
    return total


@pytest.mark.parametrize("frequency", [15.0, 22.9, 25.0, 33.0, 36.2, 44.0])
def test_closed_form_matches_converged_fourier_series(system: TwoDofSystem, frequency: float) -> None:
    """The series converges like 1/m^2: with 2^20 terms its tail is about 2/(M2 w^2 T terms); tolerance 1.5x that."""
    omega = 2 * np.pi * frequency
    period = 2 * np.pi / omega
    t = period * np.array([0.0, 0.13, 0.5, 0.77, 0.999])
    terms = 2**20
    series = fourier_series_chi(system, omega, t, terms)
    closed = periodic_green(exact_pole_residue(system), omega, t)
    tail_bound = 2.0 / (system.m2 * omega**2 * period * terms)
    np.testing.assert_allclose(closed, series, rtol=0, atol=1.5 * tail_bound)
    # the bound is tight enough to mean something: it is far below the function's size
    assert tail_bound < 1e-5 * np.abs(closed).max()


def test_paper_eq12_equals_pole_residue_form(system: TwoDofSystem) -> None:
    """Eq. 12 as printed (A read as A_i) is the periodic sum of the fitted modes' impulse responses."""
    fit = fit_modal_parameters(system)
    omega = 2 * np.pi * np.linspace(15.0, 45.0, 301)[:, None]
    t = (2 * np.pi / omega) * np.linspace(0.0, 1.0, 17)[None, :]
    np.testing.assert_allclose(paper_periodic_green(fit, omega, t), periodic_green(fit.to_pole_residue(), omega, t), rtol=1e-10, atol=1e-14)


def test_velocity_jump_is_inverse_mass(system: TwoDofSystem) -> None:
    """chi22'(0+) - chi22'(0-) = 1/M2: a unit impulse on the absorber changes its velocity by 1/M2."""
    model = exact_pole_residue(system)
    omega = 2 * np.pi * np.linspace(15.0, 45.0, 61)
    jump = periodic_green(model, omega, 0.0, 1) - periodic_green(model, omega, 2 * np.pi / omega, 1)
    np.testing.assert_allclose(jump, 1.0 / system.m2, rtol=1e-9)


def test_chi_is_continuous_across_the_period(system: TwoDofSystem) -> None:
    model = exact_pole_residue(system)
    omega = 2 * np.pi * np.linspace(15.0, 45.0, 61)
    np.testing.assert_allclose(periodic_green(model, omega, 0.0), periodic_green(model, omega, 2 * np.pi / omega), rtol=1e-9)


def test_paper_constant_velocity_is_wrong_near_resonance(system: TwoDofSystem) -> None:
    """Erratum evidence: chi22'(0-) is close to -1/(2 M2) away from the resonances and far from it near them."""
    model = exact_pole_residue(system)
    constant = -1.0 / (2.0 * system.m2)

    def rate(f: float) -> float:
        omega = 2 * np.pi * f
        return float(periodic_green(model, omega, 2 * np.pi / omega, 1))

    assert rate(30.0) == pytest.approx(constant, rel=0.05)
    assert abs(rate(23.02) - constant) > 10 * abs(constant)
    assert abs(rate(36.07) - constant) > 10 * abs(constant)


@pytest.mark.parametrize("antiperiodic", [False, True])
@pytest.mark.parametrize("derivative", [0, 1, 2])
def test_paired_sum_equals_the_full_sum(system: TwoDofSystem, derivative: int, antiperiodic: bool) -> None:
    """Conjugate terms summed once (``paired``, the admissibility search's fast path) give the full sum to round-off,
    for pairs of complex poles, for a real pole added (an overdamped term), and (every term taken) for poles that do not
    pair."""
    from vibroimpact.model.modal import PoleResidueModel

    model = exact_pole_residue(system)
    omega = 2 * np.pi * np.linspace(15.0, 45.0, 31)[:, None]
    t = (np.pi / omega if antiperiodic else 2 * np.pi / omega) * np.linspace(0.0, 1.0, 33)[None, :]
    with_real = PoleResidueModel(np.append(model.poles, -300.0 + 0j), np.append(model.residues, 0.02 + 0j))
    unpaired = PoleResidueModel(model.poles[:3], model.residues[:3])  # one pole lost its partner: no real sum any more
    for case in (model, with_real, unpaired):
        full = periodic_green(case, omega, t, derivative, antiperiodic)
        paired = periodic_green(case, omega, t, derivative, antiperiodic, paired=True)
        np.testing.assert_allclose(paired, full, rtol=0, atol=1e-13 * np.max(np.abs(full)))
    # and the fast path is another sum (rounded otherwise), not the default one by another name
    assert np.any(periodic_green(model, omega, t, derivative, antiperiodic, paired=True) != periodic_green(model, omega, t, derivative, antiperiodic))  # exact: differs in rounding
