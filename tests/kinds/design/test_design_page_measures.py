"""The design page says what its numbers are (:mod:`vibroimpact.kinds.design.quantity`): with an |X2| or a force
objective, or a constraint on another measure than the objective's, every sentence, table header, axis label and
caption names the measure it states and its unit, and prints the dataset's values in it (m as mm, N as N).

Three tiny studies of the paper's two masses (a 1 m scene stop, a few seconds each): an |X2| objective under the
default |X1| notch; a force objective under a force constraint (no |X1| anywhere on the page); a force objective under
the |X1| notch (|X1| only where the constraint is meant)."""

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

from vibroimpact.kinds.design.answer import answer_text, design_worst, warnings
from vibroimpact.kinds.design.figures import response_figure, robustness_figure, search_figure
from vibroimpact.kinds.design.operating import design_operating, operating_sentence, operating_warnings
from vibroimpact.kinds.design.page import certificates_table, designs_table, method_text
from vibroimpact.kinds.design.quantity import Quantity, constraint_quantity, objective_quantity, operating_limit, quantity
from vibroimpact.runs.run import run_study
from vibroimpact.kinds.design.tradeoff import front_text, tradeoff_figure
from vibroimpact.model.system import TwoDofSystem
from vibroimpact.reporting.page import write_report
from vibroimpact.reporting.style import fmt
from vibroimpact.scene.reader import parse_scene

from tests.golden.golden import page_text
from tests.kinds.design.test_design_page import TWO_VARIABLES

import matplotlib.pyplot as plt

pytestmark = pytest.mark.slow  # a whole study per module: the slow tier (issue 49, measured)

#: The studies' operating frequency [Hz] and their limits: |X1| [m], |F| [N].
AT, X1_LIMIT, FORCE_LIMIT = 33.0, 5e-5, 2.0


def _run(name: str, objective: str, limit: dict[str, float], compare: str = "linear_optimum") -> xr.Dataset:
    document = copy.deepcopy(TWO_VARIABLES)
    document["name"] = name
    document["design"]["objective"] = objective
    document["design"]["compare"] = compare
    document["design"]["constraints"] = {"operating": {"frequency": AT, **limit}}
    scene = parse_scene(copy.deepcopy(document), text=yaml.safe_dump(document, sort_keys=False))
    return run_study(scene, progress=None)


@pytest.fixture(scope="module")
def absorber() -> xr.Dataset:
    """|X2| objective, the default |X1| notch; no linear comparison (|X2| has none: a detached absorber moves least)."""
    return _run("page_x2", "x2_amplitude", {"x1_amplitude": X1_LIMIT}, compare="none")


@pytest.fixture(scope="module")
def force() -> xr.Dataset:
    """Force objective, force constraint."""
    return _run("page_force", "force_amplitude", {"force_amplitude": FORCE_LIMIT})


@pytest.fixture(scope="module")
def force_notch() -> xr.Dataset:
    """Force objective, the |X1| notch."""
    return _run("page_force_notch", "force_amplitude", {"x1_amplitude": X1_LIMIT})


def _page(dataset: xr.Dataset, folder: Path) -> str:
    """The page's text (headings, paragraphs, captions, table cells), as the golden suite compares it."""
    return page_text(write_report(dataset, folder).read_text(encoding="utf-8"))


def _cells(table: str) -> list[list[str]]:
    """A table's rows of cells' text (header row first)."""
    rows = table.split("</table>")[0].split("<tr>")[1:]
    return [[html.unescape(re.sub(r"<[^>]+>", " ", c)).strip() for c in re.split(r"</t[dh]>", row) if c.strip() and c.strip() != "</tr>"] for row in rows]


def _figure_words(dataset: xr.Dataset) -> list[str]:
    """Every axis label, title, colour-bar label and legend entry of the page's figures."""
    words = []
    for drawn in (search_figure(dataset), response_figure(dataset), robustness_figure(dataset), tradeoff_figure(dataset)):
        words.append(drawn.title)
        for ax in drawn.figure.axes:
            words += [ax.get_xlabel(), ax.get_ylabel(), ax.get_title()]
        words += [t.get_text() for legend in drawn.figure.legends for t in legend.get_texts()]
        plt.close(drawn.figure)
    return [w for w in words if w]


# ---------------------------------------------------------------------------------------------- the helper
def test_the_quantity_of_each_measure() -> None:
    x1, x2, f = quantity("x1_amplitude"), quantity("x2_amplitude"), quantity("force_amplitude")
    assert (x1.symbol, x1.unit, x1.scale, x1.description) == ("|X1|", "mm", 1e3, "fundamental amplitude of the primary mass")  # exact: constants
    assert (x2.symbol, x2.unit, x2.scale) == ("|X2|", "mm", 1e3) and x2.displacement
    assert (f.symbol, f.unit, f.scale, f.label) == ("|F|", "N", 1.0, "|F| [N]") and not f.displacement  # exact: constants
    assert quantity("x12_amplitude").symbol == "|X12|" and quantity("top_amplitude").symbol == "|top|"  # a general layout's coordinate
    assert x1.text(2.5377e-3) == "2.538 mm" and f.text(12.345) == "12.35 N" and f.text(math.nan) == "not known"
    assert x1.number(2.5377e-3) == "2.538" and x1.number(math.nan) == "n/a" and f.number(0.5) == "0.5"
    with pytest.raises(ValueError, match="unknown measure 'speed'"):
        quantity("speed")


def test_the_dataset_names_the_objective_the_constraint_and_the_limit(absorber: xr.Dataset, force: xr.Dataset, force_notch: xr.Dataset) -> None:
    assert (objective_quantity(absorber).symbol, constraint_quantity(absorber).symbol, operating_limit(absorber)) == ("|X2|", "|X1|", X1_LIMIT)  # exact: the parsed limit
    assert (objective_quantity(force).symbol, constraint_quantity(force).symbol, operating_limit(force)) == ("|F|", "|F|", FORCE_LIMIT)  # exact: the parsed limit
    assert (objective_quantity(force_notch).symbol, constraint_quantity(force_notch).symbol, operating_limit(force_notch)) == ("|F|", "|X1|", X1_LIMIT)  # exact: the parsed limit
    bare = xr.Dataset(attrs={"objective": "x1_amplitude"})  # no constraint
    assert constraint_quantity(bare) == quantity("x1_amplitude") and math.isnan(operating_limit(bare))
    assert isinstance(objective_quantity(bare), Quantity)


# --------------------------------------------------------------------------------------------- |X2| objective
def test_an_absorber_objective_is_said_as_x2_and_the_notch_as_x1(absorber: xr.Dataset) -> None:
    d, q = absorber, objective_quantity(absorber)
    text = answer_text(d)
    worst = design_worst(d, 0)
    assert text.startswith("Build Delta = ") and f"worst case |X2| = {fmt(1e3 * worst, '.4g')} mm over 15-45 Hz" in text
    notch = float(d["design_operating_amplitude"].values[0])
    assert re.search(rf"\|X1\| = {re.escape(fmt(1e3 * notch, '.4g'))} mm at 33 Hz \([^)]*motion[^)]*\), where 0.05 mm is allowed", text)  # the notch named (and its motion): not the objective
    assert q.text(worst) in text
    head, *rows = _cells(designs_table(d))
    assert head[3:] == ["worst case |X2| over the 5 samples [mm]", "nominal worst case |X2| [mm]", "certified worst case |X2| [mm] and the motion that sets it",
                        "|X1| at 33 Hz [mm] (allowed 0.05)"]  # fmt: skip
    values = d["design_sample_value"].values
    for k, row in enumerate(rows):
        assert row[4].lstrip("★ ") == fmt(1e3 * values[k, 0], ".4g")  # nominal, mm
        assert row[6].lstrip("★ ").split(" ")[0] == fmt(1e3 * float(d["design_operating_amplitude"].values[k]), ".4g")
    assert "Worst case: the largest stable |X2| over the band" in designs_table(d)


def test_an_absorber_objective_labels_the_figures_in_x2(absorber: xr.Dataset) -> None:
    response = response_figure(absorber)
    assert {ax.get_ylabel() for ax in response.figure.axes} == {"|X2| [mm]"}
    assert response.caption.startswith("|X2| (fundamental amplitude of the displacement x2, mm, log scale)")
    assert "where the operating constraint limits |X1| (allowed 0.05 mm), a measure these axes do not show" in response.caption
    bars = [line for ax in response.figure.axes for line in ax.get_lines() if line.get_marker() == "_"]
    assert not bars  # the |X1| limit is not drawn on |X2| axes
    plt.close(response.figure)
    search = search_figure(absorber)
    assert search.figure.axes[-1].get_ylabel() == "worst case |X2| over the band and the samples [mm]"  # the colour bar
    assert "worst case |X2| over the band and the mistuning samples (closed-form screen), in mm" in search.caption
    assert "Crosses mark candidates whose |X1| at 33 Hz exceeds the allowed 0.05 mm" in search.caption
    plt.close(search.figure)
    robust = robustness_figure(absorber)
    assert robust.figure.axes[0].get_xlabel() == "worst case |X2| over the band [mm]"
    worst = 1e3 * float(np.nanmax(absorber["design_sample_value"].values[0]))
    assert any(t.get_text().endswith(f"worst {fmt(worst, '.3g')} mm, median " + t.get_text().split("median ")[-1]) for t in robust.figure.legends[0].get_texts())
    plt.close(robust.figure)


# --------------------------------------------------------------------------------------------- force objective
def test_a_force_page_says_newtons_and_never_x1(force: xr.Dataset, tmp_path: Path) -> None:
    d = force
    text = answer_text(d)
    worst, notch = design_worst(d, 0), float(d["design_operating_amplitude"].values[0])
    assert text.startswith("Build Delta = ")  # the linear absorber's 33 Hz force breaks the 2 N limit
    assert f"worst case |F| = {fmt(worst, '.4g')} N over 15-45 Hz" in text and re.search(rf"[,;] {re.escape(fmt(notch, '.4g'))} N at 33 Hz \([^)]*motion[^)]*\), where 2 N is allowed", text)
    linear, linear_notch = float(np.nanmax(d["design_sample_value"].values[2])), float(d["design_operating_amplitude"].values[2])
    assert f"best linear absorber of the same mass: {fmt(linear, '.4g')} N, {fmt(linear_notch, '.4g')} N at 33 Hz, above the allowed 2 N" in text
    page = _page(d, tmp_path)
    assert "|X1|" not in page and "|F|" in page
    assert not [w for w in _figure_words(d) if "|X1|" in w or "[mm]" in w and "clearance" not in w]
    head, *rows = _cells(designs_table(d))
    assert head[3:] == ["worst case |F| over the 5 samples [N]", "nominal worst case |F| [N]", "certified worst case |F| [N] and the motion that sets it", "|F| at 33 Hz [N] (allowed 2)"]
    values = d["design_sample_value"].values
    for k, row in enumerate(rows):
        assert row[3].lstrip("★ ").split(" ")[0] == fmt(float(np.nanmax(values[k])), ".4g")  # N: scale 1
        assert row[4].lstrip("★ ") == fmt(values[k, 0], ".4g")
    method = html.unescape(re.sub(r"<[^>]+>", "", method_text(d)))
    assert "the largest |F| over 15-45 Hz" in method and "|F| at 33 Hz must stay at or below 2 N on every motion found there, under every sample" in method
    assert "10 times the relative excess over the limit" in method
    trade = front_text(d)
    assert trade.startswith("The trade-off: ") and " mm" not in trade and " N at " in trade


def test_a_force_page_draws_newtons_and_the_force_limit(force: xr.Dataset) -> None:
    response = response_figure(force)
    assert {ax.get_ylabel() for ax in response.figure.axes} == {"|F| [N]"}
    assert "the black bar on it the allowed |F| there (2 N)" in response.caption
    bars = [line for ax in response.figure.axes for line in ax.get_lines() if line.get_marker() == "_"]
    assert bars and all(float(np.asarray(line.get_ydata())[0]) == FORCE_LIMIT for line in bars)  # exact: the parsed limit in N, unscaled
    curve = np.asarray(response.figure.axes[0].get_lines()[-2].get_ydata(), dtype=float)  # the recommended design, drawn last
    assert np.nanmax(curve) <= 1.0001 * float(np.nanmax(force["response_linear"].values[0]))  # newtons, not times 1e3
    plt.close(response.figure)
    trade = tradeoff_figure(force)
    assert trade.title == "Worst |F| against the impact: the trade-off" and trade.figure.axes[0].get_ylabel() == "worst case |F| [N]"
    plt.close(trade.figure)


def test_a_force_page_under_the_notch_says_x1_only_of_the_notch(force_notch: xr.Dataset, tmp_path: Path) -> None:
    """Every |X1| on the page is the constraint's: its value at 33 Hz, its limit, "that |X1|", or the operating point's
    sentence (at 33 Hz); the worst cases are |F| in N."""
    d = force_notch
    page = _page(d, tmp_path)
    allowed = (r"\|X1\| at 33 Hz", r"\|X1\| = [0-9.e+-]+ mm at 33 Hz", r"that \|X1\|", r"limits \|X1\|", r"design's \|X1\| is [0-9.e+-]+ mm with its stop")
    rest = page
    for pattern in allowed:
        rest = re.sub(pattern, "", rest)
    assert "|X1|" in page and "|X1|" not in rest
    text = answer_text(d)
    assert f"worst case |F| = {fmt(design_worst(d, 0), '.4g')} N over" in text
    assert re.search(rf"\|X1\| = {re.escape(fmt(1e3 * float(d['design_operating_amplitude'].values[0]), '.4g'))} mm at 33 Hz \([^)]*motion[^)]*\), where 0.05 mm is allowed", text)
    words = _figure_words(d)
    assert "|F| [N]" in words and "operating frequency 33 Hz (its constraint limits |X1|, not drawn)" in words
    assert all("33 Hz" in w for w in words if "|X1|" in w)  # the feasibility line's label and the operating frequency's
    head = _cells(designs_table(d))[0]
    assert head[3] == "worst case |F| over the 5 samples [N]" and head[-1] == "|X1| at 33 Hz [mm] (allowed 0.05)"
    assert certificates_table(d) == ""  # certify: candidates 0


# ------------------------------------------------------------------------------------------ the operating point
def test_the_operating_point_compares_the_constraint_measure_with_the_same_measure_without_the_stop(force: xr.Dataset) -> None:
    """A declared force constraint: with the stop, the search's worst |F| at 33 Hz; without it, |(k1 + j w b1) X1|
    of the same linear absorber (the force to the base through the suspension); the free |X2| against the clearance
    stays a displacement in mm."""
    point = design_operating(force)
    assert point is not None and point.declared and point.measure == quantity("force_amplitude")
    system = TwoDofSystem(m1=1.0, m2=0.1, k1=25000.0, k2=4300.0, b1=0.8, b2=0.08)
    omega = 2.0 * math.pi * AT
    h = system.receptances(np.array([omega]))
    x1, x2 = 10.0 * h.h11[0], 10.0 * h.h12[0]
    assert point.linear == pytest.approx(abs((25000.0 + 1j * omega * 0.8) * x1), rel=1e-12)
    assert point.free == pytest.approx(abs(x2), rel=1e-12)
    assert point.stopped == pytest.approx(float(force["design_operating_amplitude"].values[0]), rel=1e-12)
    assert point.ratio == pytest.approx(1.0, rel=1e-3)  # the stop is not struck at 33 Hz: the same motion
    assert operating_warnings(point) == []
    sentence = operating_sentence(point)
    assert f"the recommended design's |F| is {fmt(point.stopped, '.4g')} N with its stop" in sentence and f"against {fmt(point.linear, '.4g')} N for the same absorber" in sentence


def test_the_warnings_name_the_measures(force_notch: xr.Dataset) -> None:
    """The linear absorber's notch warning is |X1| in mm; the comparison over the band is |F| in N."""
    lines = [w for w in warnings(force_notch) if w.startswith("Over the band the stop does not pay")]
    for line in lines:
        before, _, after = line.partition("but it has no notch")
        assert " mm" not in before and " N against " in before
        assert not after or after.startswith(": |X1| at 33 Hz is ") and after.endswith(" mm, above the allowed 0.05 mm.")


# ------------------------------------------------------------------------------------ the linear absorber's values
def _linear_absorber(dataset: xr.Dataset) -> TwoDofSystem:
    return TwoDofSystem(m1=1.0, m2=0.1, k1=25000.0, k2=float(dataset.attrs["linear_optimum_k2_N_per_m"]), b1=0.8, b2=float(dataset.attrs["linear_optimum_b2_N_s_per_m"]))


def test_the_linear_absorber_is_judged_by_the_objective(force: xr.Dataset) -> None:
    """The best linear absorber's band peak is the objective's measure (|F|), not |X1|: at or above its response
    curve's largest value on the 601-point grid (that curve is the measure's), and within 0.1 % of it."""
    d = force
    curve = float(np.nanmax(d["response_linear"].values[2]))
    peaks = d["design_sample_value"].values[2]
    assert np.all(peaks >= curve * (1.0 - 1e-9)) and np.all(peaks <= curve * 1.001)


def test_the_linear_absorber_is_judged_by_the_constraint(force: xr.Dataset, force_notch: xr.Dataset) -> None:
    """At 33 Hz the best linear absorber's value is the constraint's measure: |(k1 + j w b1) q H11| under the force
    constraint, |q H11| under the notch (the mistuning moves only the clearance, which it has not)."""
    omega = 2.0 * math.pi * AT
    h11 = _linear_absorber(force).receptances(np.array([omega])).h11[0]
    assert float(force["design_operating_amplitude"].values[2]) == pytest.approx(abs((25000.0 + 1j * omega * 0.8) * 10.0 * h11), rel=1e-12)
    assert float(force_notch["design_operating_amplitude"].values[2]) == pytest.approx(abs(10.0 * h11), rel=1e-12)
