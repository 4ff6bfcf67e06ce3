"""The design page (issue 32) from tiny studies run here: it answers first ("Build ..."), warns before any figure,
writes every figure, marks the best of each column of its table, and draws a one-variable study with neither a linear
comparison nor an operating constraint, and a study that recommended nothing.

The scenes' own stop is 1 m away (never reached): the scene's design is always certified by continuation, and
without impacts that takes milliseconds rather than the paper's 3 mm stop's tens of seconds."""

from __future__ import annotations

import copy
import html
import math
import re
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

from vibroimpact.kinds.design.answer import answer_text, design_titles, linear_wins, mistuning_text, search_path, warnings
from vibroimpact.kinds.design.figures import DESIGN_COLOURS, response_figure, robustness_figure, search_figure
from vibroimpact.kinds.design.page import DesignPage, best_marks, designs_table
from vibroimpact.kinds.design.tradeoff import front_text, tradeoff_figure
from vibroimpact.runs.run import run_study
from vibroimpact.reporting.page import write_report
from vibroimpact.scene.reader import parse_scene

import matplotlib.pyplot as plt

pytestmark = pytest.mark.slow  # a whole study per module: the slow tier (issue 49, measured)

FIGURES = {"design_search", "design_response", "design_robustness", "design_tradeoff"}

TWO_VARIABLES = {
    "name": "page_two",
    "description": "two variables, a notch to keep, compared with the linear optimum",
    "system": {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0, "b1": 0.8, "b2": 0.08},
    "excitation": {"amplitude": 10.0},
    "stop": {"clearance": 1.0, "restitution": 0.2},
    "design": {
        "variables": {"clearance": [0.002, 0.006], "restitution": [0.1, 0.8]},
        "band": {"start": 15.0, "stop": 45.0},
        "constraints": {"operating": {"frequency": 33.0, "x1_amplitude": 5e-5}},
        "robust": {"clearance": 0.0002, "samples": 2, "seed": 1},
        "compare": "linear_optimum",
        "search": {"population": 4, "generations": 2, "seed": 1, "polish": False},
        "certify": {"candidates": 0},
    },
}


def _run(document: dict) -> xr.Dataset:
    scene = parse_scene(copy.deepcopy(document), text=yaml.safe_dump(document, sort_keys=False))
    return run_study(scene, progress=None)


@pytest.fixture(scope="module")
def two() -> xr.Dataset:
    return _run(TWO_VARIABLES)


@pytest.fixture(scope="module")
def one() -> xr.Dataset:
    document = copy.deepcopy(TWO_VARIABLES)
    document["name"] = "page_one"
    design = document["design"]
    design["variables"] = {"clearance": [0.002, 0.006]}
    design["compare"] = "none"
    del design["constraints"]
    return _run(document)


def _text(fragment: str) -> str:
    return html.unescape(re.sub(r"<[^>]+>", "", fragment)).strip()


def test_the_page_answers_first_and_warns_before_any_figure(two: xr.Dataset, tmp_path: Path) -> None:
    sections = DesignPage(two).sections(tmp_path)
    assert sections[0].title == "Which design to build" and not sections[0].figures
    assert _text(sections[0].intro).startswith("Build Delta = ")
    page = write_report(two, tmp_path).read_text(encoding="utf-8")
    body = page[page.index("</nav>") :]
    first_figure = body.index("<figure")
    assert body.index("Build Delta = ") < body.index("Before you build it") < first_figure
    for warning in warnings(two):
        assert body.index(html.escape(warning)) < first_figure


def test_every_figure_file_is_written_and_embedded(two: xr.Dataset, tmp_path: Path) -> None:
    page = write_report(two, tmp_path).read_text(encoding="utf-8")
    written = {path.stem for path in tmp_path.glob("*.png")}
    assert written == FIGURES
    assert all((tmp_path / f"{name}.png").stat().st_size > 10_000 for name in FIGURES)
    assert page.count("<img ") == len(FIGURES)
    assert all(f"({name}.png)" in page for name in FIGURES)


def test_the_answer_names_the_spreads_the_scene_states_and_the_comparisons(two: xr.Dataset) -> None:
    # as stated, not the samples' largest offset; the box's corners and its worst point are samples too
    assert mistuning_text(two) == "+-0.2 mm of the clearance (the box's 2 corners, its worst point and 2 random samples)"
    text = answer_text(two)
    assert "over 15-45 Hz and +-0.2 mm of the clearance (the box's 2 corners, its worst point and 2 random samples)" in text
    assert "best linear absorber of the same mass: " in text and "the scene's design, Delta = 1000 mm, R = 0.2: " in text
    assert "at 33 Hz" in text
    assert any("was not certified" in w for w in warnings(two))  # certify: candidates 0


def test_the_search_map_draws_the_contours_the_path_and_the_designs(two: xr.Dataset) -> None:
    drawn = search_figure(two)
    ax = drawn.figure.axes[0]
    assert any(type(c).__name__ == "TriContourSet" for c in ax.collections)
    path = search_path(two)
    scores = two["score"].values
    assert path[0] == 0 and np.all(np.diff(scores[path]) < 0.0)
    assert scores[path[-1]] == np.min(scores)  # exact: the last improvement is the best score
    lines = {line.get_label(): line for line in ax.get_lines()}
    trace = lines["the search's path: best design so far, in evaluation order"]
    assert len(trace.get_xdata()) == len(path)
    star = lines["recommended design"]
    assert star.get_xdata()[0] == pytest.approx(1e3 * float(two["design_clearance"].values[0]), rel=1e-12)
    assert star.get_ydata()[0] == pytest.approx(float(two["design_restitution"].values[0]), rel=1e-12)
    assert "log-spaced" in drawn.caption and "exceeds" in drawn.caption
    plt.close(drawn.figure)


def test_the_responses_are_coloured_by_design_and_say_whose(two: xr.Dataset) -> None:
    drawn = response_figure(two)
    axes = drawn.figure.axes
    assert len(axes) == 4  # the comparison, then the recommended, the scene's and the linear absorber
    for ax, colour in zip(axes[1:], DESIGN_COLOURS):
        assert any(line.get_color() == colour and np.any(np.isfinite(np.asarray(line.get_ydata(), dtype=float))) for line in ax.get_lines())
    labels = [text.get_text() for text in drawn.figure.legends[0].get_texts()]
    assert labels[0].startswith("recommended design: Delta = ") and labels[2].startswith("best linear absorber: no stop, k2 = ")
    assert any(label.startswith("operating frequency 33 Hz") for label in labels)
    plt.close(drawn.figure)


def test_the_robustness_caption_says_how_many_samples_and_what_spreads(two: xr.Dataset) -> None:
    drawn = robustness_figure(two)
    assert "5 samples: the nominal design, the 2 corners of the tolerance box and 2 of a Latin hypercube (seed 1) over +-0.2 mm of the clearance" in drawn.caption
    assert "best linear absorber" in drawn.caption  # no stop: the clearance's spread does not reach it
    plt.close(drawn.figure)


def test_the_table_marks_the_least_of_each_column(two: xr.Dataset) -> None:
    assert best_marks([2.0, 1.0, math.nan]) == [False, True, False]
    assert best_marks([1.0, math.nan, math.nan]) == [False, False, False]  # nothing to compare with
    table = designs_table(two)
    rows = table.split("<tr>")[2:]
    worst = [float(np.nanmax(row)) for row in two["design_sample_value"].values]
    best = int(np.argmin(worst))
    assert "★" in rows[best].split("</td>")[3]  # design, clearance, restitution, then the worst case over the samples
    assert all("★" not in row.split("</td>")[3] for k, row in enumerate(rows) if k != best)
    assert "not certified" in rows[0] and "exact (no stop" in rows[2]


def test_one_variable_without_comparison_or_constraint_draws(one: xr.Dataset, tmp_path: Path) -> None:
    assert math.isnan(float(one.attrs["operating_limit_m"])) and np.all(np.isnan(one["design_sample_value"].values[2]))
    text = answer_text(one)
    assert text.startswith("Build Delta = ") and "linear" not in text and "allowed" not in text
    page = write_report(one, tmp_path).read_text(encoding="utf-8")
    assert {path.stem for path in tmp_path.glob("*.png")} == FIGURES
    assert "allowed" not in designs_table(one)
    drawn = search_figure(one)
    assert len(drawn.figure.axes) == 1 and drawn.figure.axes[0].get_yscale() == "log"
    plt.close(drawn.figure)
    assert page.index("Before you build it") < page.index("<figure")


def test_a_study_that_recommended_nothing_still_draws(two: xr.Dataset, tmp_path: Path) -> None:
    """What the dataset holds when no candidate had a finite worst case: no recommended row."""
    nothing = two.copy(deep=True)
    nothing.attrs["recommended_evaluation"] = -1
    for name in [n for n in nothing.data_vars if str(n).startswith(("design_", "response_")) and "design" in nothing[n].dims and str(n) != "design_name"]:
        values = nothing[name].values
        values[0] = -1 if values.dtype.kind == "i" else np.nan
    assert answer_text(nothing).startswith("No design could be recommended")
    write_report(nothing, tmp_path)
    assert {path.stem for path in tmp_path.glob("*.png")} == FIGURES


def test_where_the_linear_absorber_beats_every_stop_the_answer_says_build_no_stop(two: xr.Dataset) -> None:
    """The recommended design's worst case raised above the linear absorber's: without a notch to keep the answer
    recommends no stop (and names the best design with one); with the notch, which the linear absorber misses, it
    still recommends the stop, and the warning says what the stop costs over the band."""
    worse = two.copy(deep=True)
    linear = float(np.nanmax(worse["design_sample_value"].values[2]))
    worse["design_sample_value"].values[0] = 1.5 * linear
    worse.attrs["box_worst_screened"] = 1.5 * linear  # the box's worst point with them
    assert not linear_wins(worse) and answer_text(worse).startswith("Build Delta = ")  # the linear absorber has no notch
    assert any(w.startswith("Over the band the stop does not pay") and "but it has no notch" in w for w in warnings(worse))
    worse.attrs["operating_limit_m"] = math.nan
    assert linear_wins(worse)
    text = answer_text(worse)
    assert text.startswith("Build no stop: the best linear absorber of the same mass (no stop, k2 = ")
    assert f"|X1| = {1e3 * linear:.4g} mm over 15-45 Hz" in text and "the best design with a stop found, Delta = " in text
    assert f"{1e3 * 1.5 * linear:.4g} mm" in text
    assert design_titles(worse)[0] == "best design with a stop" and design_titles(two)[0] == "recommended design"
    labels = [t.get_text() for t in robustness_figure(worse).figure.legends[0].get_texts()]
    assert labels[0].startswith("best design with a stop: worst ") and not any("recommended" in label for label in labels)
    plt.close("all")
    worse["design_sample_value"].values[0] = 0.5 * linear  # the stop wins again
    worse.attrs["box_worst_screened"] = 0.5 * linear
    assert not linear_wins(worse) and answer_text(worse).startswith("Build Delta = ")


def test_the_tradeoff_draws_the_front_and_the_designs(two: xr.Dataset) -> None:
    """Every candidate with an impulse, the front's steps through exactly the flagged candidates, the recommended
    design at its own impulse and worst case; the page's sentence spans the front."""
    drawn = tradeoff_figure(two)
    ax = drawn.figure.axes[0]
    front = np.flatnonzero(two["pareto_front"].values == 1)
    assert front.size >= 1
    lines = {line.get_label(): line for line in ax.get_lines()}
    steps = next(line for label, line in lines.items() if label.startswith("the front: "))
    assert sorted(np.asarray(steps.get_xdata(), dtype=float)) == sorted(two["impulse"].values[front])  # exact: the values drawn
    r = int(two.attrs["recommended_evaluation"])
    if np.isfinite(two["impulse"].values[r]):
        star = lines["recommended design"]
        assert star.get_xdata()[0] == two["impulse"].values[r] and star.get_ydata()[0] == 1e3 * two["objective"].values[r]  # exact: the values drawn
    else:  # no stable impact orbit, its band partly uncovered: its impulse is not known, and it is not drawn
        assert np.any(two["sample_uncovered"].values[r] > 0.0) and "recommended design" not in lines
    unknown = np.any(two["sample_uncovered"].values > 0.0, axis=1) & (np.max(two["sample_impulse"].values, axis=1) <= 0.0)
    assert np.all(np.isnan(two["impulse"].values[unknown])) and not np.any(two["pareto_front"].values[unknown] == 1)
    assert np.all(two["sample_impulse"].values >= 0.0) and np.any(two["impulse"].values > 0.0)
    assert front_text(two).startswith(f"The trade-off: {front.size} candidates form the front")
    plt.close(drawn.figure)


def test_the_robustness_figure_marks_a_certified_sample_above_the_screen() -> None:
    """The golden design_rigid_stop dataset with the recommended design's worst certified sample raised to twice its
    screened value: a vermillion star at that value, on that sample's step, and the caption names it."""
    d = xr.open_dataset(Path(__file__).parents[2] / "golden" / "data" / "design_rigid_stop.nc").load()
    r = int(d.attrs["recommended_evaluation"])
    row = int(np.flatnonzero(d["certificate_evaluation"].values == r)[-1])
    sample = int(d["certificate_sample"].values[row])
    screened = float(d["design_sample_value"].values[0, sample])
    d["certificate_worst"].values[row] = 2.0 * screened
    drawn = robustness_figure(d)
    stars = [line for line in drawn.figure.axes[0].get_lines() if line.get_marker() == "*"]
    assert len(stars) == 1 and stars[0].get_xdata()[0] == pytest.approx(2e3 * screened, rel=1e-12)
    assert f"sample {sample}: {2e3 * screened:.4g} mm" in drawn.caption and "certified up to" in drawn.figure.legends[0].get_texts()[0].get_text()
    plt.close(drawn.figure)


def test_a_branch_cut_at_the_step_limit_is_warned_with_where_and_how_large_it_was() -> None:
    """The golden design_paper dataset (a bumper) with the first branch of the recommended design's first certificate
    marked as stopped at the continuation's step limit: the warnings say so, with that branch's frequency span and
    largest |X1|, and nothing is said while no branch is cut."""
    d = xr.open_dataset(Path(__file__).parents[2] / "golden" / "data" / "design_paper.nc").load()
    r = int(d.attrs["recommended_evaluation"])
    row = int(np.flatnonzero(d["certificate_evaluation"].values == r)[0])
    assert not any("step limit" in w for w in warnings(d))
    branch = d["branch_index"].values[row] == 0.0  # exact: an index
    assert np.count_nonzero(branch) > 2
    d["branch_cut"].values[row] = np.where(branch, 1.0, 0.0)
    said = [w for w in warnings(d) if "step limit" in w]
    f, x = d["branch_frequency"].values[row][branch], d["branch_amplitude"].values[row][branch]
    assert len(said) == 1 and "followed 1 branch only as far as the continuation's step limit (2000 steps)" in said[0]
    assert f"between {np.min(f):.4g} and {np.max(f):.4g} Hz, |X1| up to {1e3 * np.max(x):.4g} mm on it" in said[0]


def test_a_limit_the_absorber_alone_breaks_is_said_before_the_search_and_answered_no_design() -> None:
    """A notch limit of 1 um at 33 Hz, where the paper's absorber alone gives 8.97 um (|q H11|, closed form): the
    dataset keeps that closed form, no candidate keeps the limit, and the answer begins "No design in these bounds
    holds" with both numbers, never "Build"; the least violation is named."""
    document = copy.deepcopy(TWO_VARIABLES)
    document["name"] = "page_infeasible"
    document["design"]["constraints"] = {"operating": {"frequency": 33.0, "x1_amplitude": 1e-6}}
    document["design"]["robust"] = {"clearance": 0.0002, "samples": 1, "seed": 1}
    document["design"]["compare"] = "none"
    d = _run(document)
    alone = float(d.attrs["operating_absorber_alone"])
    assert alone == pytest.approx(8.973115761e-6, rel=1e-8)
    assert not np.any(d["feasible"].values == 1)
    text = answer_text(d)
    assert text.startswith("No design found in these bounds keeps the operating limit (|X1| at most 0.001 mm at 33 Hz; without a stop the absorber already has 0.008973 mm there")
    assert "the best found (the least penalised score) is Delta = " in text and "Build" not in text
