"""The linear model: natural frequencies, receptances, validation (eqs. 1, 4, 5, 11)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vibroimpact.analysis.linear import paper_linear_response
from vibroimpact.analysis.linear_optimum import resonance_peaks
from vibroimpact.model.system import TwoDofSystem

from tests.conftest import PAPER_AMPLITUDE


def test_natural_frequencies_match_eigenvalues_of_minv_k(system: TwoDofSystem) -> None:
    """Corrected eq. 11 equals the square roots of the eigenvalues of M^-1 K (independent computation)."""
    np.testing.assert_allclose(system.natural_angular_frequencies(), system.natural_angular_frequencies_eig(), rtol=1e-13)


@pytest.mark.parametrize("params", [dict(m1=2.0, m2=0.05, k1=1e5, k2=300.0), dict(m1=1e-3, m2=5.0, k1=7.0, k2=9e4), dict(m1=1.0, m2=1.0, k1=1.0, k2=1.0)])
def test_natural_frequencies_other_systems(params: dict[str, float]) -> None:
    """The closed form holds far from the paper's mass and stiffness ratios too."""
    s = TwoDofSystem(**params)
    np.testing.assert_allclose(s.natural_angular_frequencies(), s.natural_angular_frequencies_eig(), rtol=1e-12)


def test_paper_natural_frequencies(system: TwoDofSystem) -> None:
    """The paper's eq. 25 (numbering repeated in the paper) quotes 23.02 and 36.07 Hz."""
    f1, f2 = np.array(system.natural_angular_frequencies()) / (2 * math.pi)
    assert f1 == pytest.approx(23.02, abs=0.005) and f2 == pytest.approx(36.07, abs=0.005)


def test_printed_eq11_is_wrong(system: TwoDofSystem) -> None:
    """Erratum evidence: eq. 11 as printed (K1 M1 + K1 M2 + K2 M1) gives 9.3 and 89.3 Hz, not 23.02 and 36.07."""
    m1, m2, k1, k2 = system.m1, system.m2, system.k1, system.k2
    s = k1 * m1 + k1 * m2 + k2 * m1
    root = math.sqrt(s * s - 4 * k1 * k2 * m1 * m2)
    printed = [math.sqrt((s + sign * root) / (2 * m1 * m2)) / (2 * math.pi) for sign in (-1, 1)]
    np.testing.assert_allclose(printed, [9.3, 89.3], atol=0.05)


def test_receptances_match_direct_complex_solve(system: TwoDofSystem) -> None:
    """H from eqs. 4-5 equals the inverse of K - w^2 M + j w B, column by column, at many frequencies."""
    omega = 2 * np.pi * np.linspace(0.5, 80.0, 97)
    h = system.receptances(omega)
    for w, h11, h12, h22 in zip(omega, h.h11, h.h12, h.h22):
        dynamic = system.stiffness_matrix - w**2 * system.mass_matrix + 1j * w * system.damping_matrix
        on_primary = np.linalg.solve(dynamic, [1.0, 0.0])
        on_absorber = np.linalg.solve(dynamic, [0.0, 1.0])
        np.testing.assert_allclose([h11, h12], on_primary, rtol=1e-12)
        np.testing.assert_allclose([h12, h22], on_absorber, rtol=1e-12)


def test_receptances_are_vectorised_over_any_shape(system: TwoDofSystem) -> None:
    omega = np.linspace(10.0, 300.0, 12).reshape(3, 4)
    h = system.receptances(omega)
    assert h.h11.shape == h.h12.shape == h.h22.shape == (3, 4)
    np.testing.assert_array_equal(h.h22[1], system.receptances(omega[1]).h22)


def test_antiresonance_of_undamped_absorber() -> None:
    """With B2 = 0 the primary mass does not move at sqrt(K2/M2) (the absorber's purpose)."""
    s = TwoDofSystem(m1=1.0, m2=0.1, k1=25_000.0, k2=4_300.0, b1=0.8, b2=0.0)
    assert abs(s.receptances(s.antiresonance_angular_frequency()).h11) < 1e-15


def test_paper_impactless_band_and_antiresonant_amplitude(system: TwoDofSystem) -> None:
    """Erratum evidence: the model gives 26.03-33.97 Hz and 2.325 mm, not the paper's 27-34 Hz and 2.27 mm."""
    f = np.arange(20.0, 40.0, 1e-4)
    x2 = np.abs(paper_linear_response(system, omega=2 * np.pi * f, amplitude=PAPER_AMPLITUDE).x2)
    inside = f[(x2 <= 3e-3) & (f > 24) & (f < 35)]
    assert inside.min() == pytest.approx(26.03, abs=0.01) and inside.max() == pytest.approx(33.97, abs=0.01)
    x2_anti = abs(paper_linear_response(system, omega=system.antiresonance_angular_frequency(), amplitude=PAPER_AMPLITUDE).x2)
    assert x2_anti == pytest.approx(2.325e-3, abs=5e-7)


def test_resonance_peaks_beat_any_grid(system: TwoDofSystem) -> None:
    """Analytic peaks are maxima: no point of a fine grid around them is higher."""
    for peak in resonance_peaks(system, PAPER_AMPLITUDE, "x1"):
        f = peak.frequency + np.linspace(-0.2, 0.2, 20001)
        grid_max = np.abs(paper_linear_response(system, omega=2 * np.pi * f, amplitude=PAPER_AMPLITUDE).x1).max()
        assert peak.value >= grid_max * (1 - 1e-12)
        assert peak.value <= grid_max * (1 + 1e-6)


@pytest.mark.parametrize(
    ("field", "value", "fragment"),
    [("m1", -1.0, "system.m1 = -1.0 is out of range: allowed (0, inf)"), ("k2", 0.0, "system.k2 = 0.0 is out of range"), ("b1", -0.1, "system.b1 = -0.1 is out of range: allowed [0, inf)"), ("m2", float("nan"), "system.m2: expected a finite number")],
)
def test_invalid_parameters_name_the_field(field: str, value: float, fragment: str) -> None:
    params = dict(m1=1.0, m2=0.1, k1=25_000.0, k2=4_300.0, b1=0.8, b2=0.08)
    params[field] = value
    with pytest.raises(ValueError, match=__import__("re").escape(fragment)):
        TwoDofSystem(**params)


def test_named_view_of_a_chain_written_as_matrices(system: TwoDofSystem) -> None:
    """The paper's system written as matrices has the named view: the same parameters (K1, B1 to round-off)."""
    from vibroimpact.model.structure import LinearStructure

    written = LinearStructure([[1.0, 0.0], [0.0, 0.1]], [[29300.0, -4300.0], [-4300.0, 4300.0]], [[0.88, -0.08], [-0.08, 0.08]], ("x1", "x2"))
    named = TwoDofSystem.of(written)
    assert named is not None
    np.testing.assert_allclose(list(named.as_dict().values()), [1.0, 0.1, 25000.0, 4300.0, 0.8, 0.08], rtol=1e-15)
    assert TwoDofSystem.of(system) is system
    assert TwoDofSystem.of(system.structure) == system


@pytest.mark.parametrize(
    ("mass", "stiffness", "damping", "names"),
    [
        ([[1.0, 0.0], [0.0, 0.1]], [[29300.0, -4300.0], [-4300.0, 4300.0]], [[0.88, -0.08], [-0.08, 0.08]], ("primary", "absorber")),  # other names
        ([[0.1, 0.0], [0.0, 1.0]], [[4300.0, -4300.0], [-4300.0, 29300.0]], [[0.08, -0.08], [-0.08, 0.88]], ("x1", "x2")),  # absorber first
        ([[1.0, 0.0], [0.0, 0.1]], [[29300.0, -4300.0], [-4300.0, 5300.0]], [[0.88, -0.08], [-0.08, 0.08]], ("x1", "x2")),  # absorber grounded too
        ([[1.0, 0.0], [0.0, 0.1]], [[4300.0, -4300.0], [-4300.0, 4300.0]], [[0.08, -0.08], [-0.08, 0.08]], ("x1", "x2")),  # no suspension (K1 = 0)
        ([[1.0, 0.01], [0.01, 0.1]], [[29300.0, -4300.0], [-4300.0, 4300.0]], [[0.88, -0.08], [-0.08, 0.08]], ("x1", "x2")),  # coupled masses
        ([[1.0, 0.0], [0.0, 0.1]], [[29300.0, -4300.0], [-4300.0, 4300.0]], [[0.88, -0.08], [-0.08, 0.1]], ("x1", "x2")),  # dashpot to ground
        ([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 0.1]], [[2e4, -1e4, 0], [-1e4, 1.5e4, -5e3], [0, -5e3, 5e3]], [], ("x1", "x2", "x3")),  # three masses
    ],
)
def test_no_named_view_of_other_structures(mass: list, stiffness: list, damping: list, names: tuple[str, ...]) -> None:
    """Anything but the two-mass chain with coordinates x1 (primary) and x2 (absorber) has no named view."""
    from vibroimpact.model.structure import LinearStructure

    assert TwoDofSystem.of(LinearStructure(mass, stiffness, tuple(map(tuple, damping)), names)) is None
