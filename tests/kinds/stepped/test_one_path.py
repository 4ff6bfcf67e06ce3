"""One stepped path: the paper's system written with m1 ... b2 and written as matrices (coordinates x1, x2, force on
x1, one upper stop on x2) is one study: the same dataset, the same page."""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import xarray as xr

from vibroimpact.reporting.page import page_for, write_report
from vibroimpact.scene import parse_scene
from vibroimpact.runs.run import run_study

from tests.golden.golden import fixed_timings, page_text

NAMED = {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0, "b1": 0.8, "b2": 0.08}
MATRICES = {"mass": [[1.0, 0.0], [0.0, 0.1]], "stiffness": [[29300.0, -4300.0], [-4300.0, 4300.0]], "damping": [[0.88, -0.08], [-0.08, 0.08]], "coordinates": ["x1", "x2"]}
COMMON: dict[str, Any] = {
    "name": "paper",
    "description": "The paper's system, R = 0.2, Delta = 3 mm",
    "sweep": {"frequency": {"start": 20.0, "stop": 40.0, "step": 0.5}},
    "solutions": ["linear", "pgf", "pgf_paper", "exact"],
    "simulation": {"frequency": [24.0, 30.0, 36.0], "start": "shooting", "max_periods": 100, "lyapunov_periods": 128, "irregular_measure_periods": 32},
}
#: The scenes' own text (stored, shown verbatim on the page, outside the compared text) and the timings differ.
MACHINE = {"scene", "history", "run_wall_time_s", "run_jobs", "run_scheduler", "run_peak_memory_bytes", "run_peak_memory_worker_bytes"}


def named_scene() -> dict[str, Any]:
    return copy.deepcopy(COMMON) | {"system": dict(NAMED), "excitation": {"amplitude": 10.0}, "stop": {"clearance": 0.003, "restitution": 0.2}}


def matrix_scene() -> dict[str, Any]:
    stops = [{"coordinate": "x2", "side": "upper", "clearance": 0.003, "restitution": 0.2}]
    return copy.deepcopy(COMMON) | {"system": copy.deepcopy(MATRICES), "excitation": {"amplitude": 10.0, "on": "x1"}, "stops": stops}


@pytest.fixture(scope="module")
def pair() -> tuple[xr.Dataset, xr.Dataset]:
    """The named and the matrix form, run."""
    return run_study(parse_scene(named_scene()), progress=None), run_study(parse_scene(matrix_scene()), progress=None)


def test_same_dataset(pair: tuple[xr.Dataset, xr.Dataset]) -> None:
    """Same variables (the paper's names), dimensions, coordinates, variable and dataset attributes (the named ones
    included); values to 1e-12 relative (measured: identical, the matrices are those of the named system bit for
    bit), flags equal; the wall times are the machine's."""
    named, matrix = pair
    assert {"x1_amplitude", "x2_amplitude", "force_amplitude", "impulse", "regime", "stable", "x1_rms", "one_impact_x2_amplitude"} <= set(named.data_vars)
    assert set(named.data_vars) == set(matrix.data_vars) and dict(named.sizes) == dict(matrix.sizes)
    assert "stop" not in named.dims and set(named.coords) == set(matrix.coords)
    for name in named.variables:
        assert str(named[name].attrs) == str(matrix[name].attrs), name
        if "wall time" in str(named[name].attrs.get("long_name", "")):
            continue
        if named[name].dtype.kind in "iuO":
            xr.testing.assert_equal(named[name], matrix[name])
        else:
            xr.testing.assert_allclose(named[name], matrix[name], rtol=1e-12, atol=0.0)
    different = {key for key in set(named.attrs) | set(matrix.attrs) if str(named.attrs.get(key)) != str(matrix.attrs.get(key))}
    assert different <= MACHINE
    assert named.attrs["system_k1"] == pytest.approx(25000.0, rel=1e-15) and matrix.attrs["system_b1"] == pytest.approx(0.8, rel=1e-15)
    assert "method_pgf_paper" in matrix.attrs and "pgf_paper_loss_factors" in matrix.attrs


def test_the_comparison_sees_every_regime(pair: tuple[xr.Dataset, xr.Dataset]) -> None:
    """Not vacuous: the paper's route, the closed form and the simulations all have impacting and linear points."""
    regime = pair[1]["regime"]
    for solution in ("pgf", "pgf_paper"):
        values = regime.sel(solution=solution).values
        assert np.count_nonzero(values == 1) > 3 and np.count_nonzero(values == 0) > 3, solution  # one_impact, linear
    simulated = pair[1]["x1_amplitude"].sel(solution="exact").values
    assert np.count_nonzero(np.isfinite(simulated)) == 3


@pytest.mark.slow  # 13 s: both pages drawn; the golden suite holds every shipped page's text
def test_same_page(pair: tuple[xr.Dataset, xr.Dataset], tmp_path: Path) -> None:
    """The same page, chosen by what the dataset holds: its text (headings, paragraphs, captions, table cells) is
    the same line for line."""
    named, matrix = pair
    assert type(page_for(named)) is type(page_for(matrix))
    texts = [page_text(write_report(fixed_timings(dataset), tmp_path / label).read_text(encoding="utf-8")) for label, dataset in (("named", named), ("matrix", matrix))]
    assert texts[0] == texts[1]
    assert "Reduction factors" in texts[0] and "Modal parameters of H22" in texts[0]


THREE = {"mass": [[1.0, 0, 0], [0, 1.0, 0], [0, 0, 0.1]], "stiffness": [[2e4, -1e4, 0], [-1e4, 1.5e4, -5e3], [0, -5e3, 5e3]], "coordinates": ["x1", "x2", "x3"]}
RELATIVE = [{"between": ["x2", "x1"], "side": side, "clearance": 0.003, "restitution": 0.2} for side in ("upper", "lower")]


@pytest.mark.parametrize(
    ("changes", "extras", "panels"),
    [
        ({}, True, False),
        ({"excitation": {"amplitude": 0.001, "base_motion": True}}, True, False),  # the paper's masses on a moving base
        ({"stops": RELATIVE}, True, True),  # the paper's masses, the 1928 two-sided relative stop
        ({"system": MATRICES | {"coordinates": ["primary", "absorber"]}, "excitation": {"amplitude": 10.0, "on": "primary"}, "stops": [{"coordinate": "absorber", "side": "upper", "clearance": 0.003, "restitution": 0.2}]}, False, True),
        ({"system": THREE, "stops": [{"coordinate": "x3", "side": "upper", "clearance": 0.003, "restitution": 0.2}]}, False, True),
    ],
)
def test_the_sections_follow_what_the_dataset_holds(changes: dict[str, Any], extras: bool, panels: bool, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """One page for every stepped layout: the paper's extras (modal table, reduction factors) where the structure is
    the paper's two-mass chain x1, x2 (another load or stop included), a panel per coordinate and stop where there are
    several stops or no named view, the paper's figure per quantity otherwise."""
    from vibroimpact.reporting import page as page_module
    from vibroimpact.kinds.stepped.page import FrequencyResponsePage
    from tests.reporting.test_report_pages import quick_save

    monkeypatch.setattr(page_module, "save_figure", quick_save)
    document = matrix_scene() | {"solutions": ["linear", "pgf"], "sweep": {"frequency": [20.0, 25.0, 30.0]}} | changes
    document.pop("simulation")
    dataset = run_study(parse_scene(document), progress=None)
    page = page_for(dataset)
    assert isinstance(page, FrequencyResponsePage)
    sections = page.sections(tmp_path)
    titles = [section.title for section in sections]
    tables = {table.title for section in sections for table in section.tables}
    assert titles[0] == "Largest responses" and titles[1 + extras] == "Linear system"  # the answer first, with the reduction factors
    assert ("Modal parameters of H22" in tables) is extras and ("Reduction factors" in titles) is extras
    assert extras is False or titles[1] == "Reduction factors"
    assert any(title.startswith("Responses, ") for title in titles) is panels
    assert any(title.startswith("Frequency responses") for title in titles) is not panels


def test_the_paper_layout_as_matrices_may_ask_for_pgf_paper() -> None:
    """What the named form may ask for, the matrix form of the same layout may too (the paper's route); the same
    masses with another stop may not (tests/scene/test_scene_layout.py)."""
    document = matrix_scene() | {"solutions": ["linear", "pgf", "pgf_paper"]}
    document.pop("simulation")
    document["stops"][0].pop("clearance")
    document["stops"][0].pop("restitution")
    document["sweep"] = {"restitution": [0.2, 0.8], "clearance": [0.002, 0.003], "frequency": [20.0, 25.0]}
    scene = parse_scene(document)
    assert scene.settings.solutions == ("linear", "pgf", "pgf_paper")
