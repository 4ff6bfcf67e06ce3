"""Pages that warn before they praise (issue 33): a user's absorber whose 2 mm stop destroys the notch, and the same
absorber with its clearance typed in mm (2 m, never reached). The operating point is the linear absorber's
anti-resonance sqrt(k2/m2) / 2 pi; |X1| there with the stop and without comes from the dataset and the closed form."""

from __future__ import annotations

import copy
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import xarray as xr
import yaml

from vibroimpact import cli
from vibroimpact.analysis.linear import linear_response
from vibroimpact.grids.sections import paper_study, structure_figure
from vibroimpact.kinds.stepped.operating import operating_point, unreached_text, warning_lines
from vibroimpact.model.system import TwoDofSystem
from vibroimpact.reporting.page import write_report
from vibroimpact.reporting.record import general_setting
from vibroimpact.reporting.style import fmt
from vibroimpact.runs.run import run_study
from vibroimpact.scene import parse_scene

from tests.golden.golden import page_text
from tests.reporting.test_report_pages import quick_save

#: The issue's absorber: m1 = 5 kg, k1 = 2e5 N/m, m2 = 0.25 kg tuned to 31.8 Hz (k2 = m2 (2 pi 31.8)^2), q = 50 N
#: (so that its free motion at the notch, q / k2, is 5 mm), a 2 mm stop with R = 0.5.
SYSTEM = {"m1": 5.0, "m2": 0.25, "k1": 200000.0, "k2": 9980.0, "b1": 4.0, "b2": 0.2}
SCENE: dict[str, Any] = {
    "name": "user_absorber",
    "system": SYSTEM,
    "excitation": {"amplitude": 50.0},
    "stop": {"clearance": 0.002, "restitution": 0.5},
    "sweep": {"frequency": {"start": 29.0, "stop": 35.0, "step": 0.05}},
    "solutions": ["linear", "pgf"],
}
ANTIRESONANCE = math.sqrt(SYSTEM["k2"] / SYSTEM["m2"]) / (2.0 * math.pi)


@pytest.fixture(scope="module")
def dataset() -> xr.Dataset:
    return run_study(parse_scene(copy.deepcopy(SCENE)), progress=None)


@pytest.fixture(scope="module")
def page(dataset: xr.Dataset, tmp_path_factory: pytest.TempPathFactory) -> list[str]:
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr("vibroimpact.reporting.page.save_figure", quick_save)
        path = write_report(dataset, tmp_path_factory.mktemp("user_absorber"))
    return page_text(path.read_text(encoding="utf-8")).splitlines()


def test_the_operating_point_is_the_anti_resonance_and_its_values_are_the_closed_form_s(dataset: xr.Dataset) -> None:
    """The operating frequency is sqrt(k2/m2) / 2 pi; |X1| without the stop is the linear closed form at the grid's
    nearest frequency (and the dataset's linear solution there), with the stop the dataset's pgf value there; the
    stop multiplies it by more than 100 (its free motion, about q/k2 = 5 mm, does not fit in 2 mm)."""
    point = operating_point(dataset)
    assert point is not None
    assert point.frequency == pytest.approx(ANTIRESONANCE, rel=1e-12)
    (row,) = point.rows
    assert row.solution == "pgf"
    assert abs(row.frequency - ANTIRESONANCE) <= 0.025 + 1e-9  # the nearest point of a 0.05 Hz grid
    system = TwoDofSystem(**SYSTEM)
    linear = float(np.abs(linear_response(system, row.frequency, 50.0).coordinate("x1")))
    assert row.linear == pytest.approx(linear, rel=1e-9)
    there = dataset.sel(frequency=row.frequency)
    assert row.linear == pytest.approx(float(there["x1_amplitude"].sel(solution="linear")), rel=1e-9)
    assert row.stopped == pytest.approx(float(there["x1_amplitude"].sel(solution="pgf")), rel=1e-12)
    assert row.ratio > 100.0
    ((coordinate, free, gap),) = point.free
    assert coordinate == "x2" and gap == pytest.approx(0.002, rel=1e-12)
    assert free == pytest.approx(50.0 / SYSTEM["k2"], rel=0.02)  # undamped: X2 = -q / k2 at the anti-resonance


def test_the_page_s_first_lines_say_the_stop_destroys_the_notch_with_the_two_numbers(dataset: xr.Dataset, page: list[str]) -> None:
    """Before the largest responses and the reduction factors: the warning with |X1| of the linear absorber and with the
    stop at the operating point and their ratio, then that the free motion does not fit in the gap."""
    point = operating_point(dataset)
    assert point is not None
    row = point.rows[0]
    start = page.index("h2: Largest responses") + 1
    first, second = page[start], page[start + 1]
    assert first.startswith("p: Warning. The stop makes the absorber worse at its operating point")
    for number in (f"{fmt(row.linear * 1e3, '.3g')} mm with the linear absorber", f"{fmt(row.stopped * 1e3, '.3g')} mm with the stop", f"×{fmt(row.ratio, '.3g')}", f"anti-resonance {fmt(ANTIRESONANCE, '.5g')} Hz"):
        assert number in first, number
    assert second.startswith("p: Warning. The absorber's free motion at its operating point does not fit in the gap") and "against a gap of 2 mm" in second
    praise = next(k for k, line in enumerate(page) if line.startswith("p: Reduction factors: the stop divides"))
    assert praise > start + 1
    assert any(line.startswith("p: At the absorber's operating point") and f"{fmt(row.stopped * 1e3, '.3g')} mm" in line for line in page[praise : praise + 2])


def test_a_user_system_gets_neutral_captions_and_no_paper_column(dataset: xr.Dataset, page: list[str]) -> None:
    """The user's absorber is on the paper's layout but not the paper's system: no caption cites the paper's figures
    or equations, and the reduction tables have no (always empty) 'paper' column."""
    assert not paper_study(dataset)
    drawn = structure_figure(general_setting(dataset), dataset["frequency"].values, paper_study(dataset))
    labels = [ax.get_title() for ax in drawn.figure.axes] + [t.get_text() for legend in drawn.figure.legends for t in legend.get_texts()]
    assert not any("paper" in label or "eq. " in label for label in labels), labels
    assert "paper" not in drawn.caption
    assert "th: paper" not in page
    assert not any("paper fig" in line for line in page)


@pytest.mark.slow
def test_a_clearance_typed_in_mm_is_said_on_the_console_and_the_page(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """clearance: 2 (meant in mm, read in m) is never reached: one console line and the page's first line say so,
    with the largest |x2| of the grid (the linear one: nothing strikes) against 2000 mm, and ask whether 2 mm was meant."""
    scene = copy.deepcopy(SCENE) | {"name": "user_mm", "stop": {"clearance": 2, "restitution": 0.5}, "sweep": {"frequency": {"start": 25.0, "stop": 40.0, "step": 0.5}}}
    path = tmp_path / "user_mm.yaml"
    path.write_text(yaml.safe_dump(scene), encoding="utf-8")
    assert cli.main([str(path), "--out", str(tmp_path / "out"), "--jobs", "1"]) == 0
    err = capsys.readouterr().err
    dataset = xr.open_dataset(tmp_path / "out" / "user_mm.nc")
    largest = float(np.max(np.abs(linear_response(TwoDofSystem(**SYSTEM), dataset["frequency"].values, 50.0).coordinate("x2"))))
    line = f"the largest |x2| on the grid is {fmt(largest * 1e3, '.3g')} mm against a 2000 mm clearance; did you mean 2 mm (0.002 m)?"
    warnings = [w for w in err.splitlines() if w.startswith("warning: The stop is never reached")]
    assert len(warnings) == 1 and warnings[0].endswith(line), err
    text = page_text((tmp_path / "out" / "report.html").read_text(encoding="utf-8")).splitlines()
    assert text[text.index("h2: Largest responses") + 1] == f"p: Warning. The stop is never reached: {line}"
    assert unreached_text(dataset) == f"The stop is never reached: {line}"


def test_a_stop_that_is_reached_is_not_said_unreached(dataset: xr.Dataset) -> None:
    assert unreached_text(dataset) == ""
    assert not any("never reached" in line for line in warning_lines(dataset))


def test_the_paper_s_notch_is_kept_by_its_stop() -> None:
    """The paper's absorber and stop (3 mm, R = 0.2): its free motion at the anti-resonance, 2.32 mm, fits, |X1| there
    is the linear absorber's, and the page warns of nothing."""
    scene = {"name": "paper", "system": {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0, "b1": 0.8, "b2": 0.08}, "excitation": {"amplitude": 10.0},
             "stop": {"clearance": 0.003, "restitution": 0.2}, "sweep": {"frequency": {"start": 32.0, "stop": 34.0, "step": 0.1}}, "solutions": ["linear", "pgf"]}  # fmt: skip
    data = run_study(parse_scene(scene), progress=None)
    point = operating_point(data)
    assert point is not None and point.frequency == pytest.approx(math.sqrt(4300.0 / 0.1) / (2.0 * math.pi), rel=1e-12)
    assert point.free == () and point.rows[0].ratio == pytest.approx(1.0, abs=1e-9)
    assert warning_lines(data) == []


def test_the_operating_sentence_over_many_points_reads_as_one_sentence() -> None:
    """Many solutions and swept points: the least and the most, each with its own frequency where it is not the
    first row's (before: 'from exact 0.00897 mm (x1) at R = 0, 33 Hz, where the linear absorber's is 0.00897 mm to
    pgf 0.00898 mm ...', a clause inside a range)."""
    from vibroimpact.kinds.stepped.operating import OperatingPoint, OperatingRow, operating_text

    linear = 8.97e-6
    rows = [OperatingRow("pgf", f"R = {r:g}", 33.003, linear, linear * (1.0 + r / 100.0)) for r in (0.2, 0.4, 0.6, 0.8)]
    rows += [OperatingRow("exact", f"R = {r:g}", 33.0, linear, linear * (1.0 - r / 1000.0)) for r in (0.0, 0.2, 0.4)]
    text = operating_text(OperatingPoint(33.003, "x1", tuple(rows), (), (23.0, 36.1)))
    assert "where the linear absorber's is" not in text and " to " not in text
    assert ("with the stop, over 7 solutions and swept points, the least is exact 0.00897 mm (×1) at R = 0.4 and 33 Hz (the linear absorber there: "
            "0.00897 mm) and the most pgf 0.00904 mm (×1.01) at R = 0.8; 0 of them are worse than the linear absorber") in text, text


def test_a_stable_impacting_motion_near_the_operating_point_is_warned_of() -> None:
    """The golden closed-form map (clearances down to 0.2 mm): at 32.14 Hz, 2.6 % below the anti-resonance, the
    closed form has a stable impacting motion 8 times the linear absorber's |X1|; said before any praise. The golden
    restitution study, whose stop is struck nowhere near 33 Hz, says nothing of it."""
    from vibroimpact.runs.run import read_dataset

    golden = Path(__file__).resolve().parents[2] / "golden" / "data"
    lines = warning_lines(read_dataset(golden / "closed_form_map.nc"))
    near = [line for line in lines if "a drift of the operating speed by that much can land on it" in line]
    assert near == ["At 32.14 Hz, 2.6 % below the absorber's operating point (33.003 Hz), pgf has a stable motion with the stop of |X1| = 0.836 mm at R = 0.495, "
                    "Delta = 0.2 mm beside the linear absorber's 0.105 mm: a drift of the operating speed by that much can land on it."]
    assert not any("drift of the operating speed" in line for line in warning_lines(read_dataset(golden / "restitution.nc")))
