"""Reduction factors: realisable maxima per band, exclusions counted, paper values only for the paper's case."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from vibroimpact.analysis.linear import paper_linear_response
from vibroimpact.analysis.linear_optimum import resonance_peaks
from vibroimpact.model.system import TwoDofSystem
from vibroimpact.reporting.record import GeneralSetting
from vibroimpact.kinds.stepped.tables import paper_reduction_factors, reduction_factors

from tests.scene.test_scene import PAPER_SYSTEM_SPEC

FREQUENCY = np.round(np.arange(15.0, 45.0 + 1e-9, 0.005), 6)
#: The paper's system (eq. 24), built from its parameters (equal to, not the same object as, PAPER_SYSTEM).
SYSTEM = TwoDofSystem(**PAPER_SYSTEM_SPEC)
#: The paper's excitation amplitude q [N].
AMPLITUDE = 10.0
#: The paper's layout: force on x1, one upper stop on x2 (3 mm).
SETTING = GeneralSetting(SYSTEM.structure, AMPLITUDE, False, np.array([1.0, 0.0]), np.zeros(2), ("x2 <= 3 mm",), np.array([[0.0, 1.0]]), ("pgf",), np.array([0.003]), SYSTEM)


def dataset(values: np.ndarray, stable: np.ndarray | None = None) -> xr.Dataset:
    dims = ("solution", "restitution", "frequency")
    data = {"x1_amplitude": (dims, values[None, None, :])}
    if stable is not None:
        data["stable"] = (dims, stable[None, None, :].astype(np.int8))
    return xr.Dataset(data, coords={"solution": ["pgf"], "restitution": [0.2], "frequency": FREQUENCY, "clearance": 0.003})


def test_factor_is_linear_peak_over_largest_realisable_value() -> None:
    values = np.full(FREQUENCY.size, 1e-4)
    row = reduction_factors(dataset(values, np.ones(FREQUENCY.size)), SETTING, "x1_amplitude", "pgf")[0]
    linear = np.abs(paper_linear_response(SYSTEM, omega=2 * np.pi * FREQUENCY, amplitude=AMPLITUDE).x1)
    fits = np.abs(paper_linear_response(SYSTEM, omega=2 * np.pi * FREQUENCY, amplitude=AMPLITUDE).x2) <= 0.003
    split = FREQUENCY < SYSTEM.antiresonance_angular_frequency() / (2 * np.pi)
    for band, mask in enumerate([split, ~split]):
        expected = max(1e-4, linear[mask & fits].max())
        assert row.largest[band] == pytest.approx(expected, rel=1e-12)
        assert row.factor[band] == pytest.approx(resonance_peaks(SYSTEM, AMPLITUDE, "x1")[band].value / expected, rel=1e-12)
    assert row.undefined == (0, 0) and row.unstable == (0, 0) and row.coarse == (False, False)


def test_unstable_and_undefined_values_are_left_out_and_counted() -> None:
    values = np.full(FREQUENCY.size, 1e-4)
    stable = np.ones(FREQUENCY.size)
    values[100], stable[100] = 1.0, 0  # an unstable orbit with a huge amplitude in band 1
    values[5000] = np.nan  # undefined in band 2
    row = reduction_factors(dataset(values, stable), SETTING, "x1_amplitude", "pgf")[0]
    assert row.largest[0] < 0.1
    assert row.unstable == (1, 0) and row.undefined == (0, 1)


def test_without_stability_information_nothing_is_excluded() -> None:
    values = np.full(FREQUENCY.size, 1e-4)
    values[100] = 1.0
    row = reduction_factors(dataset(values), SETTING, "x1_amplitude", "pgf")[0]
    assert row.largest[0] == 1.0 and row.unstable is None  # exact: the value put in


def test_coarse_grid_is_flagged() -> None:
    coarse = FREQUENCY[::100]  # 0.5 Hz: much wider than the 0.1 Hz half-power width
    data = xr.Dataset(
        {"x1_amplitude": (("solution", "restitution", "frequency"), np.full((1, 1, coarse.size), 1e-4))},
        coords={"solution": ["pgf"], "restitution": [0.2], "frequency": coarse, "clearance": 0.003},
    )
    assert reduction_factors(data, SETTING, "x1_amplitude", "pgf")[0].coarse == (True, True)


def test_paper_values_only_for_the_papers_case() -> None:
    assert paper_reduction_factors(SYSTEM, AMPLITUDE, "x1_amplitude", 0.2, 0.003) == (28.0, 23.0)
    assert paper_reduction_factors(SYSTEM, AMPLITUDE, "x1_amplitude", 0.4, 0.003) is None
    assert paper_reduction_factors(SYSTEM, AMPLITUDE, "x1_amplitude", 0.2, 0.002) is None
    assert paper_reduction_factors(SYSTEM, 5.0, "x1_amplitude", 0.2, 0.003) is None
    assert paper_reduction_factors(TwoDofSystem(**(PAPER_SYSTEM_SPEC | {"b1": 1.0})), AMPLITUDE, "x1_amplitude", 0.2, 0.003) is None
