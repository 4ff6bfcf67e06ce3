"""Design maps: bands, peak picking, the worst-regime order, NaN handling, the recommendation's tie rules, and the
page of a real small study."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

from vibroimpact.analysis.linear import resonance_peaks
from vibroimpact.analysis.stability import Regime
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.kinds.stepped.design_metrics import (
    DesignRegime,
    FrequencyBands,
    band_peaks,
    design_regimes,
    design_solution,
    frequency_bands,
    no_stop_peaks,
    regime_map,
)
from vibroimpact.kinds.stepped.design_page import DesignMapPage, frequency_ranges
from vibroimpact.kinds.stepped.design_ranking import Candidate, design_map, rank, recommend
from vibroimpact.reporting.page import page_for, write_report
from vibroimpact.scene import parse_scene
from vibroimpact.runs.run import run_study

#: Synthetic system: natural frequencies 20 and 40 Hz, anti-resonance 30 Hz; splits at 25 and 35 Hz, working band
#: 29.1-30.9 Hz (3 %).
F = np.arange(15.0, 45.01, 0.5)
LOWER, WORKING, UPPER = 20.0, 30.0, 40.0


def synthetic(restitution: list[float], clearance: list[float], solutions: tuple[str, ...] = ("linear", "pgf")) -> xr.Dataset:
    """Every design linear everywhere: |X1| 1 mm except 2 mm at 20 Hz, 1.5 mm at 40 Hz and in the working band 0.1,
    0.05, 0.08 mm at 29.5, 30, 30.5 Hz; |X2| 1 mm."""
    shape = (len(solutions), len(restitution), len(clearance), F.size)
    x1 = np.full(shape, 1e-3)
    x1[..., F == LOWER], x1[..., F == UPPER] = 2e-3, 1.5e-3
    x1[..., (F > 29.0) & (F < 31.0)] = [1e-4, 0.5e-4, 0.8e-4]
    dims = ("solution", "restitution", "clearance", "frequency")
    data = {
        "x1_amplitude": (dims, x1),
        "x2_amplitude": (dims, np.full(shape, 1e-3)),
        "regime": (dims, np.full(shape, int(Regime.LINEAR), dtype=np.int8)),
        "stable": (dims, np.full(shape, -1, dtype=np.int8)),
        "impacts_per_period": (dims, np.zeros(shape)),
        "converged": (dims, np.full(shape, -1, dtype=np.int8)),
    }
    coords = {"solution": list(solutions), "restitution": restitution, "clearance": clearance, "frequency": F}
    attrs = {"natural_frequencies_Hz": np.array([LOWER, UPPER]), "antiresonance_frequency_Hz": WORKING, "study_kind": "stepped", "report_page": "design_map"}
    return xr.Dataset(data, coords=coords, attrs=attrs)


def at(ds: xr.Dataset, solution: str, r: int, c: int, f: float) -> dict[str, object]:
    """Index of one point for ``ds[name][index] = value``."""
    return {"solution": solution, "restitution": ds["restitution"].values[r], "clearance": ds["clearance"].values[c], "frequency": f}


def put(ds: xr.Dataset, where: dict[str, object], **values: float) -> None:
    for name, value in values.items():
        ds[name].loc[where] = value


def test_bands_split_at_the_midpoints_and_the_working_band_is_a_share_of_the_anti_resonance() -> None:
    bands = frequency_bands(synthetic([0.0], [1e-3]))
    assert bands.splits == pytest.approx((25.0, 35.0))
    assert bands.limits("working") == pytest.approx((29.1, 30.9))
    np.testing.assert_array_equal(bands.mask(np.array([24.9, 25.0, 29.1, 30.0, 30.9, 31.0, 35.0, 35.1]), "lower"), [1, 0, 0, 0, 0, 0, 0, 0])
    np.testing.assert_array_equal(bands.mask(np.array([24.9, 29.0, 29.1, 30.9, 31.0, 35.1]), "working"), [0, 0, 1, 1, 0, 0])
    np.testing.assert_array_equal(bands.mask(np.array([34.9, 35.0, 35.1, 45.0]), "upper"), [0, 0, 1, 1])
    assert FrequencyBands((20.0, 40.0), 30.0, 0.5).limits("working") == pytest.approx((25.0, 35.0))  # kept inside the splits
    with pytest.raises(ValueError, match="anti-resonance"):
        FrequencyBands((20.0, 40.0), 45.0)


def test_peaks_are_picked_per_band_over_realised_motion_only() -> None:
    """An unstable orbit's |X1| is never a peak, a NaN never a zero: both are counted as unknown points."""
    ds = synthetic([0.0, 0.5], [1e-3, 2e-3])
    put(ds, at(ds, "pgf", 0, 0, 22.0), x1_amplitude=9e-3, regime=int(Regime.ONE_IMPACT), stable=0, impacts_per_period=1.0)  # unstable: not a peak
    put(ds, at(ds, "pgf", 0, 0, 21.0), x1_amplitude=3e-3, regime=int(Regime.ONE_IMPACT), stable=1, impacts_per_period=1.0)  # stable: the peak
    put(ds, at(ds, "pgf", 0, 0, 40.0), x1_amplitude=np.nan, regime=int(Regime.NONE), impacts_per_period=np.nan)  # no orbit where the peak was
    peaks = band_peaks(ds, "pgf", frequency_bands(ds)).isel(restitution=0, clearance=0)
    assert peaks["peak_x1_amplitude"].values == pytest.approx([3e-3, 1e-4, 1e-3])
    assert peaks["peak_frequency"].values == pytest.approx([21.0, 29.5, 35.5])  # upper: first of the equal 1 mm values
    np.testing.assert_array_equal(peaks["unknown_points"].values, [1, 0, 1])
    np.testing.assert_array_equal(peaks["band_points"].values, [20, 3, 20])
    other = band_peaks(ds, "pgf", frequency_bands(ds)).isel(restitution=1, clearance=1)
    assert other["peak_x1_amplitude"].values == pytest.approx([2e-3, 1e-4, 1.5e-3])
    np.testing.assert_array_equal(other["unknown_points"].values, [0, 0, 0])


def test_a_band_without_any_realised_value_has_no_peak() -> None:
    ds = synthetic([0.0], [1e-3])
    upper = at(ds, "pgf", 0, 0, F[F > 35.0])
    put(ds, upper, x1_amplitude=np.nan, regime=int(Regime.FAILED), impacts_per_period=np.nan)
    dm = design_map(ds, "pgf")
    assert math.isnan(float(dm.peaks["peak_x1_amplitude"].sel(band="upper")[0, 0]))
    design = dm.designs[0]
    assert math.isnan(design.objective) and design.missing_points == 20 and design.worst_regime == DesignRegime.NOT_COMPUTED
    assert math.isnan(float(dm.regimes["impact_fraction"][0, 0])) is False  # the known points still count
    assert int(dm.regimes["unknown_impact_points"][0, 0]) == 20


def test_the_worst_regime_follows_the_documented_order() -> None:
    ds = synthetic([0.0, 0.5, 0.9], [1e-3, 2e-3])
    put(ds, at(ds, "pgf", 0, 1, 26.0), regime=int(Regime.LINEAR_WITH_UNSTABLE_ONE_IMPACT))  # linear motion persists: no impact
    put(ds, at(ds, "pgf", 1, 0, 21.0), regime=int(Regime.ONE_IMPACT), stable=1, impacts_per_period=1.0)
    put(ds, at(ds, "pgf", 1, 1, 21.0), regime=int(Regime.ONE_IMPACT_COEXISTING_LINEAR), stable=1, impacts_per_period=1.0)
    put(ds, at(ds, "pgf", 1, 1, 22.0), regime=int(Regime.PERIODIC_IMPACTS), impacts_per_period=2.0)
    put(ds, at(ds, "pgf", 2, 0, 22.0), regime=int(Regime.CHAOTIC), impacts_per_period=1.3)
    put(ds, at(ds, "pgf", 2, 0, 23.0), regime=int(Regime.PERIODIC_IMPACTS), impacts_per_period=2.0)
    put(ds, at(ds, "pgf", 2, 1, 22.0), regime=int(Regime.QUASI_PERIODIC), impacts_per_period=0.5)
    put(ds, at(ds, "pgf", 2, 1, 23.0), regime=int(Regime.ONE_IMPACT), stable=0, impacts_per_period=1.0)  # unstable: unresolved
    worst = regime_map(ds, "pgf", frequency_bands(ds))["worst_regime"].values
    expected = [[DesignRegime.NO_IMPACT, DesignRegime.NO_IMPACT], [DesignRegime.ONE_IMPACT, DesignRegime.PERIODIC_OTHER], [DesignRegime.IRREGULAR, DesignRegime.UNRESOLVED]]
    np.testing.assert_array_equal(worst, np.array(expected, dtype=int))
    assert list(DesignRegime) == sorted(DesignRegime)  # the enum's order is the documented one
    classes = design_regimes(ds, "pgf")
    assert int(classes.sel(restitution=0.9, clearance=2e-3, frequency=23.0)) == DesignRegime.UNRESOLVED


def test_the_solutions_own_grid_and_not_computed_points() -> None:
    """'exact' is chosen where computed; frequencies it never ran at are not its grid; a point of its grid that it
    did not compute is the worst class and counted."""
    ds = synthetic([0.0], [1e-3, 2e-3], ("linear", "pgf", "exact"))
    off_grid = F[1::2]
    put(ds, at(ds, "exact", 0, 0, off_grid), regime=int(Regime.NOT_COMPUTED), x1_amplitude=np.nan, impacts_per_period=np.nan)
    ds["regime"].loc[{"solution": "exact", "frequency": off_grid}] = int(Regime.NOT_COMPUTED)
    assert design_solution(ds) == "exact"
    put(ds, at(ds, "exact", 0, 1, 22.0), regime=int(Regime.FAILED), x1_amplitude=np.nan, impacts_per_period=np.nan)
    dm = design_map(ds)
    assert dm.solution == "exact" and dm.frequency.size == F[::2].size
    first, second = dm.designs
    assert first.worst_regime == DesignRegime.NO_IMPACT and first.missing_points == 0
    assert second.worst_regime == DesignRegime.NOT_COMPUTED and second.missing_points == 1 and second.unknown_points["lower"] == 1
    assert design_solution(ds.sel(solution=["linear", "pgf"])) == "pgf"
    with pytest.raises(ValueError, match="'exact' or 'pgf'"):
        design_solution(ds.sel(solution=["linear"]))


def test_a_simulations_peak_counts_the_closed_forms_coexisting_stable_state() -> None:
    """A simulation settles on one attractor: where the closed form's stable state is larger (here the fitting linear
    motion beside a simulated impacting one) it is the peak; a stable impact orbit of the closed form in the working
    band makes the band impact, whatever the simulation found."""
    ds = synthetic([0.0], [1e-3, 2e-3], ("linear", "pgf", "exact"))
    for c in (0, 1):
        put(ds, at(ds, "exact", 0, c, 40.0), x1_amplitude=0.4e-3, regime=int(Regime.PERIODIC_IMPACTS), converged=1, impacts_per_period=2.0)
        put(ds, at(ds, "pgf", 0, c, 40.0), regime=int(Regime.LINEAR_WITH_UNSTABLE_ONE_IMPACT))  # the linear 1.5 mm fits
    put(ds, at(ds, "pgf", 0, 1, 30.0), regime=int(Regime.ONE_IMPACT_COEXISTING_LINEAR), stable=1, impacts_per_period=1.0)
    dm = design_map(ds)
    assert dm.solution == "exact"
    first, second = dm.designs
    assert first.peaks["upper"] == pytest.approx(1.5e-3) and first.peak_frequencies["upper"] == pytest.approx(40.0)
    assert first.peak_from_closed_form == {"lower": False, "working": False, "upper": True}
    assert first.working_impact_free and not second.working_impact_free
    assert first.unknown_points["upper"] == 0


def test_impact_fraction_counts_known_points_and_the_linear_motion_crossing_the_stop() -> None:
    ds = synthetic([0.0], [1e-3])
    put(ds, at(ds, "pgf", 0, 0, 21.0), regime=int(Regime.ONE_IMPACT), stable=1, impacts_per_period=1.0)
    put(ds, at(ds, "pgf", 0, 0, 22.0), regime=int(Regime.NONE), impacts_per_period=np.nan, x1_amplitude=np.nan)  # impacts, motion unknown
    put(ds, at(ds, "pgf", 0, 0, 23.0), regime=int(Regime.FAILED), impacts_per_period=np.nan, x1_amplitude=np.nan)  # unknown
    regimes = regime_map(ds, "pgf", frequency_bands(ds))
    assert float(regimes["impact_fraction"][0, 0]) == pytest.approx(2.0 / (F.size - 1))
    assert int(regimes["unknown_impact_points"][0, 0]) == 1


def test_eligibility_needs_an_impact_free_working_band_and_a_clearance_above_the_linear_reach() -> None:
    """The working band's no-stop |X2| is 1 mm (from the 'linear' solution, no system stored): a clearance of 0.8 mm
    impact-free on the grid is still excluded; an impact in the band at 2 mm excludes that design."""
    ds = synthetic([0.0, 0.5], [0.8e-3, 2e-3, 3e-3])
    put(ds, at(ds, "pgf", 1, 1, 29.5), regime=int(Regime.ONE_IMPACT_COEXISTING_LINEAR), stable=1, impacts_per_period=1.0)
    dm = design_map(ds, "pgf")
    assert dm.working_clearance == pytest.approx(1e-3)
    eligible = {(d.restitution, round(d.clearance * 1e3, 3)): d.eligible for d in dm.designs}
    assert eligible == {(0.0, 0.8): False, (0.0, 2.0): True, (0.0, 3.0): True, (0.5, 0.8): False, (0.5, 2.0): False, (0.5, 3.0): True}
    assert dm.designs[0].working_impact_free and not dm.designs[0].clears_working_band
    np.testing.assert_allclose(dm.restitution_dependent, [2e-3])  # R decides at 2 mm: a coexisting impact orbit


def design(r: float, c: float, objective: float, *, eligible: bool = True, irregular: int = 0, unresolved: int = 0) -> Candidate:
    """A candidate with the larger resonance peak ``objective`` [m] in the lower band."""
    bands = ("lower", "working", "upper")
    return Candidate(r, c, dict(zip(bands, (objective, 1e-4, 0.5 * objective))), dict(zip(bands, (20.0, 30.0, 40.0))), dict.fromkeys(bands, 0),
                     dict(zip(bands, (8e-2, 1e-4, 1e-2))), DesignRegime.ONE_IMPACT, 0.3, tuple(range(irregular)), unresolved, 0, eligible, True)  # fmt: skip


def test_near_ties_prefer_the_larger_clearance_then_the_lower_restitution() -> None:
    designs = [design(0.5, 2e-3, 1.000e-3), design(0.2, 3e-3, 1.015e-3), design(0.1, 3e-3, 1.019e-3), design(0.0, 4e-3, 1.05e-3), design(0.0, 1e-3, 0.5e-3, eligible=False)]
    best = recommend(designs)
    assert best is not None and (best.design.restitution, best.design.clearance) == (0.1, 3e-3)
    assert best.tied == 3 and best.eligible == 4
    order = [(d.restitution, d.clearance) for d in rank(designs)]
    assert order == [(0.1, 3e-3), (0.2, 3e-3), (0.5, 2e-3), (0.0, 4e-3)]
    assert recommend(designs, tie_tolerance=0.0).design.clearance == 2e-3  # type: ignore[union-attr]  # exact: the input clearance, passed through
    assert best.design.reduction_dB["lower"] == pytest.approx(20.0 * math.log10(8e-2 / 1.019e-3))


def test_tiers_come_before_peaks_and_nothing_eligible_gives_no_recommendation() -> None:
    regular = design(0.3, 2e-3, 2e-3)
    irregular = design(0.1, 4e-3, 1e-3, irregular=3)
    unresolved = design(0.0, 5e-3, 0.5e-3, unresolved=2)
    assert recommend([unresolved, irregular, regular]).design is regular  # type: ignore[union-attr]
    assert recommend([unresolved, irregular]).design is irregular  # type: ignore[union-attr]
    assert recommend([unresolved]).tier == 2  # type: ignore[union-attr]
    assert recommend([design(0.0, 1e-3, 1e-3, eligible=False)]) is None


def test_no_stop_peaks_are_analytic_where_the_system_is_stored() -> None:
    ds = synthetic([0.0], [1e-3])
    ds.attrs.update({f"system_{k}": getattr(PAPER_SYSTEM, k) for k in ("m1", "m2", "k1", "k2", "b1", "b2")} | {"excitation_amplitude_N": 10.0})
    natural = np.asarray(PAPER_SYSTEM.natural_angular_frequencies()) / (2.0 * np.pi)
    ds.attrs.update({"natural_frequencies_Hz": natural, "antiresonance_frequency_Hz": PAPER_SYSTEM.antiresonance_angular_frequency() / (2.0 * np.pi)})
    peaks = no_stop_peaks(ds, frequency_bands(ds), "pgf")
    exact = resonance_peaks(PAPER_SYSTEM, 10.0)
    assert peaks["lower"].source == "analytic" and peaks["lower"].value == pytest.approx(exact[0].value, rel=1e-6)
    assert peaks["upper"].value == pytest.approx(exact[1].value, rel=1e-6) and peaks["upper"].frequency == pytest.approx(exact[1].frequency, abs=2e-3)
    assert peaks["working"].source == "grid" and peaks["working"].value == pytest.approx(1e-3)  # the linear solution on the grid


def test_frequency_ranges_join_consecutive_grid_points() -> None:
    grid = np.arange(20.0, 25.01, 0.5)
    assert frequency_ranges((20.5, 21.0, 21.5, 23.0, 24.5, 25.0), grid) == "20.5-21.5, 23, 24.5-25"
    assert frequency_ranges((), grid) == "none"


@pytest.fixture(scope="module")
def paper_map() -> xr.Dataset:
    """The paper's system, closed forms only: R 0, 0.4, 0.8 x Delta 1, 3.5, 6 mm x 201 frequencies."""
    document = {
        "name": "design_map_small",
        "description": "Small design map of the paper's system",
        "system": {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0, "b1": 0.8, "b2": 0.08},
        "excitation": {"amplitude": 10.0},
        "sweep": {"restitution": [0.0, 0.4, 0.8], "clearance": [0.001, 0.0035, 0.006], "frequency": {"start": 15.0, "stop": 45.0, "step": 0.15}},
        "solutions": ["linear", "pgf"],
    }
    dataset = run_study(parse_scene(document, yaml.safe_dump(document)), progress=None)
    dataset.attrs["report_page"] = "design_map"
    return dataset


def test_the_page_of_a_real_study_names_its_recommendation(paper_map: xr.Dataset, tmp_path: Path) -> None:
    dm = design_map(paper_map)
    assert dm.solution == "pgf"
    # without a stop |X2| reaches ~3 mm in the working band: 1 mm is excluded at every R, 3.5 and 6 mm are not
    assert 2.9e-3 < dm.working_clearance < 3.2e-3
    assert dm.restitution_dependent.size == 0
    assert {round(d.clearance * 1e3, 1) for d in dm.designs if d.eligible} == {3.5, 6.0}
    best = dm.recommendation
    assert best is not None and best.design.clearance == pytest.approx(3.5e-3)
    assert best.design.reduction_dB["lower"] > 20.0 and best.design.reduction_dB["upper"] > 10.0  # the stop cuts both resonance peaks
    assert isinstance(page_for(paper_map), DesignMapPage)
    text = write_report(paper_map, tmp_path).read_text(encoding="utf-8")
    name = f"R = {best.design.restitution:g}, Delta = 3.5 mm"
    assert f"Recommended: {name}" in text and f"recommended {name}" in text
    for figure in ("design_peaks", "design_regimes", "design_response"):
        assert (tmp_path / f"{figure}.png").stat().st_size > 10_000
    row = re.search(r"<tr><td><b>★ 1</b></td><td><b>([0-9.]+)</b></td><td><b>([0-9.]+)</b></td>", text)
    assert row is not None and float(row.group(1)) == pytest.approx(best.design.restitution) and float(row.group(2)) == pytest.approx(3.5)


@pytest.mark.parametrize(("simulated", "closed_form_larger"), [(3e-3 * (1.0 - 1e-12), False), (3e-3 * (1.0 + 1e-12), False), (2e-3, True)])
def test_the_closed_form_coexists_only_where_it_is_another_orbit(simulated: float, closed_form_larger: bool) -> None:
    """The simulation settled on the closed form's own orbit (|X1| equal to round-off) is one steady state, not two
    coexisting ones: the page's dagger and "coexists" once followed a 1e-14 change of the simulated amplitude."""
    from vibroimpact.kinds.stepped.design_metrics import worst_stable_x1

    ds = synthetic([0.2], [1e-3], ("linear", "pgf", "exact"))
    put(ds, at(ds, "pgf", 0, 0, 24.0), x1_amplitude=3e-3, regime=int(Regime.ONE_IMPACT), stable=1, impacts_per_period=1.0)
    put(ds, at(ds, "exact", 0, 0, 24.0), x1_amplitude=simulated, regime=int(Regime.ONE_IMPACT), converged=1, impacts_per_period=1.0)
    worst, realised, larger = worst_stable_x1(ds, "exact")
    k = int(np.flatnonzero(F == 24.0)[0])  # exact: a grid value
    assert bool(realised[0, 0, k]) and bool(larger[0, 0, k]) is closed_form_larger
    assert worst[0, 0, k] == pytest.approx(3e-3 if closed_form_larger else simulated, rel=1e-15)
