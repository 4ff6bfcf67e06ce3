"""The concepts page from a dataset assembled without engines: the table's best marks and verdicts follow the numbers,
the figures are drawn with a colour per concept and captions that say what was drawn."""

from __future__ import annotations

import copy
import re
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from vibroimpact.kinds.concepts.page import concept_colour, impact_figure, overview_figure, response_figure
from vibroimpact.kinds.concepts.page import write_concepts_report
from vibroimpact.kinds.concepts.page import COLUMNS, best_rows, verdicts
from vibroimpact.kinds.concepts.scene import parse_concepts
from vibroimpact.kinds.concepts.branches import BRANCH_FIELDS
from vibroimpact.kinds.concepts.cases import CASE_FIELDS, COMPLEX_FIELDS
from vibroimpact.kinds.concepts.study import closed_forms
from vibroimpact.kinds.concepts.study import concepts_dataset

DOCUMENT = {
    "name": "page",
    "system": {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0, "b1": 0.8, "b2": 0.08},
    "excitation": {"amplitude": 10.0},
    "frequency": {"start": 20.0, "stop": 40.0, "step": 0.1},
    "simulation": {"frequency": [22.0, 30.0, 34.4]},
    "bumper": {"frequency": 250.0},
    "concepts": [
        {"name": "dh", "label": "(a) Den Hartog", "absorber": {"stiffness": "den_hartog", "damping": "den_hartog"}},
        {"name": "stop", "label": "(b) absolute stop", "stops": [{"coordinate": "x2", "side": "upper", "clearance": 0.003, "restitution": 0.2}]},
        {"name": "rel", "label": "(c) relative stop", "stops": [{"between": ["x2", "x1"], "side": "upper", "clearance": 0.003, "restitution": 0.2}]},
    ],
}


def _simulated(x1: list[float], impacts: list[float], acceleration: list[float]) -> dict[str, np.ndarray]:
    out = {name: np.zeros(3, dtype=complex if name in COMPLEX_FIELDS else float) for name in CASE_FIELDS}
    out["end_state"] = np.zeros((3, 4))
    out["x1"], out["base_force"] = np.array(x1, dtype=complex), 25000.0 * np.array(x1, dtype=complex)
    out["impacts_per_period"], out["converged"], out["multiplicity"] = np.array(impacts), np.array([1.0, 1.0, 0.0]), np.array([1.0, 1.0, 0.0])
    out["bumper_peak_acceleration"], out["bumper_peak_contact_force"] = np.array(acceleration), 0.1 * np.array(acceleration)
    out["bumper_peak_base_force"] = 0.2 * np.array(acceleration)
    return out


def _branch(f: list[float], x1: list[float], modulus: list[float]) -> dict[str, np.ndarray]:
    out = {name: np.zeros(len(f)) for name in BRANCH_FIELDS[:-1]}
    out["frequency"], out["x1_amplitude"], out["floquet_modulus"] = np.array(f), np.array(x1), np.array(modulus)
    out["base_force_amplitude"], out["impacts_per_period"], out["period"] = 25000.0 * np.array(x1), np.ones(len(f)), np.ones(len(f))
    out["note"] = np.array(["branch 0: synthetic"])
    return out


@pytest.fixture(scope="module")
def dataset() -> xr.Dataset:
    settings = parse_concepts(copy.deepcopy(DOCUMENT))[3]
    closed = {c.name: closed_forms(c, settings.amplitude, settings.frequency) for c in settings.concepts}
    simulated = {"stop": _simulated([2e-3, 3e-4, 2e-4], [1.0, 0.0, 0.5], [3000.0, 0.0, 900.0]),
                 "rel": _simulated([8e-3, 3e-4, 1e-4], [1.0, 0.0, 0.5], [5000.0, 0.0, 1200.0])}  # fmt: skip
    branches = {"stop": _branch([21.0, 22.0, 23.0, 24.0], [1.5e-3, 2e-3, 2.4e-3, 2.6e-3], [1.2, 0.5, 0.6, 0.7]), "rel": _branch([22.0, 23.0], [8e-3, 9e-3], [0.5, 1.5])}
    data = concepts_dataset(settings, closed, simulated, branches)
    data.attrs.update({"scene": "name: page\ndescription: a page test\n", "scene_name": "page", "vibroimpact_version": "test"})
    return data


def test_the_best_of_each_column_is_marked_and_the_verdicts_follow_the_numbers(dataset: xr.Dataset) -> None:
    accelerations = dataset["peak_impact_acceleration"].values
    assert accelerations[0] == 0.0 and accelerations[1] == 3000.0 and accelerations[2] == 5000.0  # exact: maxima of the values given
    peaks = dataset["peak_x1_amplitude"].values
    assert best_rows(peaks).tolist() == (peaks == peaks.min()).tolist()
    lines = verdicts(dataset)
    best = int(np.argmin(peaks))
    assert lines[best].startswith("best peak |X1|")
    assert "impact acceleration" in lines[1].split(":")[0] and lines[1].startswith("best")  # (b) beats (c): 3000 < 5000
    assert "worst" in lines[2] and "impact acceleration" in lines[2].split(":")[0]
    assert "no notch" in lines[0] and "impacts on" in lines[1]


def test_the_page(dataset: xr.Dataset, tmp_path: Path) -> None:
    path = write_concepts_report(dataset, tmp_path)
    text = path.read_text(encoding="utf-8")
    table = text[text.index("<table"): text.index("</table>")]
    assert table.count("<tr>") == 1 + dataset.sizes["concept"]
    assert table.count("★") >= len(COLUMNS)
    for label in dataset["label"].values:
        assert str(label) in table
    low = f"{dataset.attrs['band_low_Hz']:.2f}"
    assert "sqrt(3 mu / (8 (1 + mu)^3))" in text and "Ormondroyd" in text and f"{low}-" in text
    for name in ("concepts_overview", "concepts_x1", "concepts_impacts"):
        assert (tmp_path / f"{name}.png").is_file()
    assert len(re.findall("<figcaption>", text)) == 3


def test_the_figures_say_what_they_draw(dataset: xr.Dataset) -> None:
    colours = {concept_colour(i) for i in range(5)}
    assert len(colours) == 5
    response = response_figure(dataset)
    labels = {line.get_label() for ax in response.figure.axes for line in ax.get_lines()}
    assert {"continued orbit, stable", "continued orbit, unstable", "simulated steady state, periodic", "closed-form impact orbit, stable"} <= labels
    assert "dashed where not" in response.caption and f"anti-resonance band ({dataset.attrs['band_low_Hz']:.2f}-" in response.caption
    overview = overview_figure(dataset)
    assert len(overview.figure.axes[0].get_lines()) >= dataset.sizes["concept"]
    impacts = impact_figure(dataset)
    assert impacts is not None and "dense replay" in impacts.caption
    for drawn in (response, overview, impacts):
        drawn.figure.clf()
