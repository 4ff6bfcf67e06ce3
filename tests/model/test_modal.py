"""Modal decomposition of H22 (eq. 10): exact poles and residues, and the paper's curve fit."""

from __future__ import annotations

import numpy as np
import pytest

from vibroimpact.model.modal import ModalParameters, exact_modal_parameters, exact_pole_residue, fit_modal_parameters
from vibroimpact.model.system import TwoDofSystem

OMEGA = 2 * np.pi * np.linspace(1.0, 100.0, 20001)


@pytest.mark.parametrize(("output", "load"), [(1, 1), (1, 2), (2, 2)])
def test_exact_residues_reproduce_receptance(system: TwoDofSystem, output: int, load: int) -> None:
    """sum r/(j w - p) equals the receptance of eq. 4 to ~1e-12 (relative) over 1-100 Hz, peaks included."""
    model = exact_pole_residue(system, output, load)
    h = getattr(system.receptances(OMEGA), f"h{output}{load}")
    np.testing.assert_allclose(model(1j * OMEGA), h, rtol=1e-12, atol=0)


def test_residue_sums(system: TwoDofSystem) -> None:
    """Impulse response of H22 starts at h(0+) = sum r = 0 with slope h'(0+) = sum r p = 1/M2 (unit impulse on M2)."""
    model = exact_pole_residue(system)
    assert abs(model.residues.sum()) < 1e-12 * np.abs(model.residues).max()
    assert (model.residues * model.poles).sum() == pytest.approx(1.0 / system.m2, rel=1e-12)
    assert model.impulse_response(0.0, derivative=1) == pytest.approx(1.0 / system.m2, rel=1e-12)


def test_form_factors_sum_to_inverse_absorber_mass(system: TwoDofSystem) -> None:
    """The real form factors A_i of eq. 10 sum to 1/M2 up to terms of the order of the damping."""
    exact = exact_modal_parameters(system)
    assert np.real(exact.form_factor).sum() == pytest.approx(1.0 / system.m2, rel=1e-4)
    assert np.abs(np.imag(exact.form_factor)).max() < 2e-3 * np.abs(exact.form_factor).max()


def test_exact_modal_parameters_are_the_poles(system: TwoDofSystem) -> None:
    exact = exact_modal_parameters(system)
    np.testing.assert_allclose(exact.omega, system.natural_angular_frequencies(), rtol=1e-6)
    assert np.all((exact.loss_factor > 0.002) & (exact.loss_factor < 0.0025))


def test_curve_fit_reproduces_exact_values(system: TwoDofSystem) -> None:
    """A least-squares fit of |H22| with Omega fixed lands on the exact modal values (a different route, same answer)."""
    exact = exact_modal_parameters(system)
    fit = fit_modal_parameters(system)
    np.testing.assert_allclose(np.real(fit.form_factor), np.real(exact.form_factor), rtol=2e-3)
    np.testing.assert_allclose(fit.loss_factor, exact.loss_factor, rtol=2e-2)
    assert np.all(np.isreal(fit.form_factor))


def test_curve_fit_reproduces_paper_values(system: TwoDofSystem) -> None:
    """The paper's eq. 26 (second of that number): A = 2.75, 7.25; xi = 0.0022, 0.0023."""
    fit = fit_modal_parameters(system)
    np.testing.assert_allclose(np.real(fit.form_factor), [2.75, 7.25], atol=0.01)
    np.testing.assert_allclose(np.round(fit.loss_factor, 4), [0.0022, 0.0023])


def test_curve_fit_is_accurate_at_the_peaks(system: TwoDofSystem) -> None:
    """The fitted eq. 10 follows |H22| within 2 % over 15-45 Hz except next to the anti-resonance of H22."""
    fit = fit_modal_parameters(system)
    omega = 2 * np.pi * np.linspace(15.0, 45.0, 6001)
    exact = np.abs(system.receptances(omega).h22)
    error = np.abs(np.abs(fit.receptance(omega)) - exact) / exact
    # H22 vanishes where M1 w^2 = K1 + K2 (no damping): 27.4 Hz for eq. 24
    zero = np.sqrt((system.k1 + system.k2) / system.m1)
    away = np.abs(omega - zero) > 0.03 * zero
    assert error[away].max() < 0.02


def test_modal_parameters_round_trip_to_pole_residue() -> None:
    modes = ModalParameters(omega=np.array([100.0, 250.0]), loss_factor=np.array([0.01, 0.3]), form_factor=np.array([2.0, -0.5]))
    model = modes.to_pole_residue()
    np.testing.assert_allclose(model(1j * OMEGA), modes.receptance(OMEGA), rtol=1e-12)


def test_complex_form_factor_cannot_become_eq10_terms(system: TwoDofSystem) -> None:
    with pytest.raises(ValueError, match="form_factor must be real"):
        exact_modal_parameters(system).to_pole_residue()


def test_fit_refuses_systems_without_two_underdamped_modes() -> None:
    """An overdamped absorber has one oscillatory mode: eq. 10 with two modes does not describe it."""
    overdamped = TwoDofSystem(m1=1.0, m2=0.1, k1=25_000.0, k2=4_300.0, b1=0.8, b2=200.0)
    with pytest.raises(ValueError, match="needs two underdamped modes; this system has 1"):
        fit_modal_parameters(overdamped)
