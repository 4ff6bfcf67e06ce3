"""A design study's answer as values (``vibroimpact.design_answer``), read from the golden suite's design datasets:
the page's own sentence, each compared design's variables and worst case as the dataset holds them, the
certificates, the candidates as a table, and the notebook's view; a dataset of another kind is refused."""

from __future__ import annotations

import html
import math
from pathlib import Path

import numpy as np
import pytest

from vibroimpact import DesignAnswer, design_answer
from vibroimpact.kinds.design.answer import answer_text, design_worst, warnings
from vibroimpact.runs.run import read_dataset

GOLDEN = Path(__file__).resolve().parents[2] / "golden" / "data"


@pytest.fixture(scope="module")
def rigid() -> tuple[object, DesignAnswer]:
    dataset = read_dataset(GOLDEN / "design_rigid_stop.nc")
    return dataset, design_answer(dataset)


def test_the_answer_is_the_page_s_sentence_and_warnings(rigid: tuple[object, DesignAnswer]) -> None:
    dataset, answer = rigid
    assert answer.headline == answer_text(dataset) and answer.warnings == tuple(warnings(dataset))  # type: ignore[arg-type]
    page = (GOLDEN / "design_rigid_stop.txt").read_text()
    assert f"p: {answer.headline}" in page.splitlines()  # the golden page's own line, word for word
    assert str(answer).splitlines()[0] == answer.headline and answer.objective == "x1_amplitude" and answer.unit == "m"


def test_each_compared_design_holds_the_dataset_s_values(rigid: tuple[object, DesignAnswer]) -> None:
    dataset, answer = rigid
    titles = [design.title for design in answer.designs]
    assert titles == ["recommended design", "the scene's design", "best linear absorber"]
    recommended = answer.recommended
    assert recommended is not None and recommended is answer.designs[0]
    assert recommended.variables == {"clearance": float(dataset["design_clearance"].values[0]), "restitution": float(dataset["design_restitution"].values[0])}  # type: ignore[index]
    assert recommended.description == "Delta = 3.553 mm, R = 0.08104"
    for k, design in enumerate(answer.designs):
        assert design.worst_case == design_worst(dataset, k)  # type: ignore[arg-type]  # exact: the same function's value
        assert design.operating == float(dataset["design_operating_amplitude"].values[k])  # type: ignore[index]  # exact: read as stored
    assert answer.designs[2].variables == {} and answer.designs[2].description.startswith("no stop, k2 = ")
    assert math.isclose(recommended.worst_case, 3.224e-3, rel_tol=5e-4)  # the page's 3.224 mm


def test_the_certificates_and_the_candidates_are_tables(rigid: tuple[object, DesignAnswer]) -> None:
    dataset, answer = rigid
    assert len(answer.certificates) == dataset.sizes["certificate"] >= 1  # type: ignore[attr-defined]
    first = answer.certificates[0]
    assert first.worst_case == float(dataset["certificate_worst"].values[0]) and first.error == ""  # type: ignore[index]  # exact: read as stored
    recommended = [c.worst_case for c in answer.certificates if c.evaluation == int(dataset.attrs["recommended_evaluation"])]  # type: ignore[attr-defined]
    assert recommended and max(recommended) == answer.designs[0].certified_worst_case  # exact: the largest of them
    table = answer.to_dataframe()
    assert len(table) == dataset.sizes["evaluation"] and {"variable_clearance", "variable_restitution", "objective", "score"} <= set(table.columns)  # type: ignore[attr-defined]
    np.testing.assert_array_equal(table["objective"].to_numpy(), dataset["objective"].values)  # type: ignore[index]


def test_a_notebook_shows_the_answer_first_then_the_designs(rigid: tuple[object, DesignAnswer]) -> None:
    _, answer = rigid
    shown = answer._repr_html_()
    assert shown.startswith(f"<p><b>{html.escape(answer.headline)}</b></p>")
    assert shown.count("<tr>") == 1 + len(answer.designs) and "worst case [m]" in shown


def test_a_dataset_of_another_kind_is_refused_naming_what_to_run() -> None:
    with pytest.raises(ValueError, match="not a design study's dataset .* run a scene with a 'design' section"):
        design_answer(read_dataset(GOLDEN / "restitution.nc"))
