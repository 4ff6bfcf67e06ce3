"""A solution run on a subset of the grid against its contact law's exact-flow reference: the page's sentence and
table say the largest difference over the points both found periodic and the cost ratio measured in the run."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from vibroimpact.analysis.stability import Regime
from vibroimpact.kinds.stepped.crosscheck import cross_check_section, cross_check_text, cross_checks

from tests.reporting.test_report_support import steady_dataset


def subset_dataset() -> xr.Dataset:
    """The fake study with IDA ('compliant', values x 1.03 of pgf) kept at 24, 26 and 36 Hz of R = 0.6 only, each
    steady state 100 times as costly as the closed-form bumper's ('compliant_exact', x 1.04)."""
    data = steady_dataset().copy(deep=True)
    f, r = data["frequency"], data["restitution"]
    kept = (r == 0.6) & f.isin([24.0, 26.0, 36.0])  # exact: grid coordinates, parsed inputs
    for name in data.data_vars:
        if "solution" in data[name].dims and data[name].dtype.kind == "f":
            data[name].loc[{"solution": "compliant"}] = data[name].sel(solution="compliant").where(kept)
    data["regime"].loc[{"solution": "compliant"}] = data["regime"].sel(solution="compliant").where(kept, int(Regime.NOT_COMPUTED))
    data["converged"].loc[{"solution": "compliant"}] = data["converged"].sel(solution="compliant").where(kept, -1)
    data["wall_time"].loc[{"solution": "compliant"}] = xr.where(kept, 1.0, np.nan)
    data.attrs["simulation_subset_compliant"] = "frequency 24, 26, 36 Hz; restitution 0.6"
    return data


def test_the_subset_engine_is_checked_against_the_exact_flow_of_its_contact() -> None:
    (check,) = [c for c in cross_checks(subset_dataset()) if c.checked == "compliant"]
    assert check.reference == "compliant_exact" and check.points == 3
    assert check.periodic == 2  # 36 Hz is quasi-periodic in both: its window averages are not compared
    assert check.largest["x1_amplitude"] == pytest.approx(1.0 - 1.03 / 1.04, rel=1e-9)
    assert check.cost_ratio == pytest.approx(100.0, rel=1e-12)


def test_the_sentence_and_table_state_agreement_cost_and_every_point() -> None:
    (check,) = [c for c in cross_checks(subset_dataset()) if c.checked == "compliant"]
    text = cross_check_text(check)
    assert f"largest relative difference of |X1| fundamental {1.0 - 1.03 / 1.04:.1e}" in text, text
    assert "over the 2 points both found periodic" in text and "1 not compared" in text, text
    assert "costs 1/100 of one of 'compliant'" in text and "1000 ms against 10 ms" in text, text
    section = cross_check_section([check])
    assert section is not None and section.tables[0].html.count("<tr>") == 1 + 3


def test_no_cross_check_without_a_subset() -> None:
    assert cross_checks(steady_dataset()) == []


def test_the_subset_is_said_in_the_page_units() -> None:
    """The dataset keeps its subset in SI ('clearance 0.002 m'); the page writes every clearance in mm, as 'Delta = 2 mm'
    a few words later (the golden clearance_peaks page said 'clearance 0.002 m')."""
    data = subset_dataset()
    data.attrs["simulation_subset_compliant"] = "frequency 24, 26, 36 Hz; clearance 0.002, 0.0025 m"
    (check,) = cross_checks(data)
    assert check.subset == "frequency 24, 26, 36 Hz; clearance 2, 2.5 mm"
    assert "run on frequency 24, 26, 36 Hz; clearance 2, 2.5 mm, against" in cross_check_text(check) and " m," not in cross_check_text(check)


def test_a_dearer_reference_is_said_as_a_multiple_not_one_over_a_fraction() -> None:
    """The golden clearance_peaks page said 'costs 1/0.467 of one of 'compliant''."""
    from vibroimpact.kinds.stepped.crosscheck import cost_words

    said = [cost_words(ratio) for ratio in (100.0, 0.467, 1.0004)]
    assert said == ["costs 1/100 of", "costs 2.14 times", "costs as much as"]
