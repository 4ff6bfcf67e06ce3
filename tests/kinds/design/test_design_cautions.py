"""The cautions a designer needs on the design page (issue 51), from the golden design_rigid_stop dataset moved to
each case: a variable on its bound, a restitution mistuning cut off at 0, and an impacting motion that coexists
within 5 % of the operating frequency above the allowed value; none on the dataset as it is."""

from __future__ import annotations

import math

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from vibroimpact import design_answer
from vibroimpact.kinds.design.answer import warnings
from vibroimpact.kinds.design.cautions import cautions
from vibroimpact.runs.run import read_dataset

GOLDEN = Path(__file__).resolve().parents[2] / "golden" / "data"


@pytest.fixture
def dataset() -> xr.Dataset:
    return read_dataset(GOLDEN / "design_rigid_stop.nc").load()


def test_the_golden_design_needs_no_caution(dataset: xr.Dataset) -> None:
    assert cautions(dataset) == []


def test_a_design_on_the_bound_of_its_range_is_said(dataset: xr.Dataset) -> None:
    dataset["design_restitution"].values[0] = dataset["variable_restitution"].attrs["valid_min"]  # R = 0
    said = cautions(dataset)
    assert any(line.startswith("The recommended design sits on a bound of the range searched (R = 0 is the lower bound of its range)") for line in said), said
    assert all(line in warnings(dataset) for line in said) and all(line in design_answer(dataset).warnings for line in said)


def test_a_mistuning_cut_off_at_zero_restitution_is_said(dataset: xr.Dataset) -> None:
    dataset["design_restitution"].values[0] = 0.02  # the +-0.05 of the scene reaches -0.03
    said = [line for line in cautions(dataset) if "mistuning is cut off" in line]
    assert said == ["The restitution's mistuning is cut off at 0, its lowest physical value, for the recommended design (R = 0.02): the tolerance box is one-sided there: its samples stop at 0, short of the offset the scene states."]


def test_an_impacting_motion_near_the_operating_frequency_is_said(dataset: xr.Dataset) -> None:
    f = dataset["response_frequency"].values
    stable = np.asarray(dataset["response_impact_plus_stable"].values[0]) == 1
    impacting = np.where(stable, dataset["response_impact_plus"].values[0], np.nan)
    where = int(np.nanargmax(impacting))
    dataset.attrs["operating_frequency_Hz"] = float(f[where]) * 1.02  # 2 % above the impacting motion's peak
    said = [line for line in cautions(dataset) if "a stable impacting motion" in line]
    assert len(said) == 1 and "% below the operating frequency, a stable impacting motion of the recommended design reaches" in said[0], said
    assert "against the allowed 0.05 mm" in said[0]
    dataset.attrs["operating_frequency_Hz"] = float(f[where]) * 1.2  # 20 % away: not near
    assert not any("a stable impacting motion" in line for line in cautions(dataset))


def test_a_linear_absorber_level_with_the_stop_design_does_as_well_not_better(dataset: xr.Dataset) -> None:
    """'2.974 mm against 2.974 mm' called the linear absorber 'the smaller': a tie is said as one."""
    from vibroimpact.kinds.design.answer import design_worst

    dataset["design_sample_value"].values[2] = design_worst(dataset, 0)
    said = [line for line in warnings(dataset) if line.startswith("Over the band the stop does not pay")]
    assert len(said) == 1 and "does as well" in said[0] and "smaller" not in said[0], said


def test_a_design_whose_stop_is_never_struck_is_named_so_where_its_star_is_drawn(dataset: xr.Dataset) -> None:
    from vibroimpact.kinds.design.answer import design_titles, never_strikes

    recommended = int(dataset.attrs["recommended_evaluation"])
    rows = dataset["certificate_evaluation"].values == recommended
    dataset["certificate_impacting"].values[rows] = 0.0
    if "certificate_operating_impacts" in dataset:
        dataset["certificate_operating_impacts"].values[rows] = 0.0
    dataset["sample_operating_impacts"].values[recommended] = 0.0
    dataset["sample_impulse"].values[recommended] = 0.0
    assert never_strikes(dataset) and design_titles(dataset)[0] == "recommended design (its stop never struck)"


def test_the_search_map_caption_speaks_of_a_hatched_region_only_where_one_is_drawn(dataset: xr.Dataset) -> None:
    """An infeasible limit (no candidate keeps it) drew no hatching while the caption described 'the hatched region'."""
    import matplotlib.pyplot as plt

    from vibroimpact.kinds.design.search_map import HATCHED, search_figure

    def hatched(drawn: object) -> bool:
        return any(c.get_gid() == HATCHED for ax in drawn.figure.axes for c in ax.collections)  # type: ignore[attr-defined]

    drawn = search_figure(dataset)
    assert hatched(drawn) and "the hatched region bounded by the purple line" in drawn.caption
    plt.close(drawn.figure)
    dataset["operating_amplitude"].values[:] = 1.0  # 1 m at the operating point: no candidate keeps 0.05 mm
    drawn = search_figure(dataset)
    assert not hatched(drawn) and "hatched region" not in drawn.caption and "no candidate keeps it, so no region is hatched" in drawn.caption
    plt.close(drawn.figure)


def test_the_search_figure_names_its_variables_in_words_not_scene_keys() -> None:
    """Issue 51 (review of every page): design_paper's search map titled a panel 'Worst case over clearance and
    bumper_stiffness' and labelled an axis 'bumper_stiffness [N/m]'. Every title, axis label and the caption now say
    'bumper stiffness K_b' (and 'clearance Delta', 'restitution R')."""
    import matplotlib.pyplot as plt

    from tests.golden.golden import DATA
    from vibroimpact.kinds.design.search_map import search_figure

    with xr.open_dataset(DATA / "design_paper.nc") as data:
        drawn = search_figure(data.load())
    texts = [drawn.caption] + [t for ax in drawn.figure.axes for t in (ax.get_title(), ax.get_xlabel(), ax.get_ylabel())]
    plt.close(drawn.figure)
    assert "bumper_stiffness" in str(data.attrs["variables"])
    assert not any("bumper_stiffness" in t for t in texts) and any("bumper stiffness K_b" in t for t in texts)


@pytest.mark.parametrize("name", ["design_paper", "design_vs_linear"])
def test_the_progress_panel_draws_no_penalised_score(name: str) -> None:
    """Review of every page: the 'best score so far' line of design_search.png began at a penalised score (~700 mm
    beside worst cases of a few mm), which is no worst case. The line is now the best worst case so far among the
    candidates that keep the operating limit: never above a worst case the panel plots, absent before the first."""
    import matplotlib.pyplot as plt

    from tests.golden.golden import DATA
    from vibroimpact.kinds.design.palette import PATH_COLOUR
    from vibroimpact.kinds.design.quantity import objective_quantity, operating_limit
    from vibroimpact.kinds.design.search_map import search_figure

    with xr.open_dataset(DATA / f"{name}.nc") as data:
        d = data.load()
    drawn = search_figure(d)
    panel = next(ax for ax in drawn.figure.axes if ax.get_title().startswith("Worst case in evaluation order"))
    lines = [line for line in panel.lines if line.get_color() == PATH_COLOUR and line.get_drawstyle().startswith("steps")]
    title = panel.get_title()
    plt.close(drawn.figure)
    keeps = d["feasible"].values == 1
    limited = math.isfinite(operating_limit(d))
    assert lines and ("best so far keeping the limit" in title) == limited
    best = np.asarray(lines[0].get_ydata(), dtype=float)
    objective = objective_quantity(d).value(d["objective"].values)
    assert np.nanmax(best) <= np.max(objective[keeps]) * (1 + 1e-12)
    assert np.all(np.isnan(best[: int(np.argmax(keeps))]))  # nothing before the first candidate that keeps it


def test_the_worst_case_markers_are_drawn_whole_at_a_band_edge() -> None:
    """Review of every page: design_response.png's worst-case ring at the band's 22 Hz edge was half clipped by the
    axes. The rings and the certified stars are drawn unclipped (the band ends where the axis does)."""
    import matplotlib.pyplot as plt

    from tests.golden.golden import DATA
    from vibroimpact.kinds.design.figures import response_figure

    with xr.open_dataset(DATA / "design_rigid_stop.nc") as data:
        drawn = response_figure(data.load())
    marks = [line for ax in drawn.figure.axes for line in ax.lines if line.get_marker() in ("o", "*") and line.get_linestyle() == "None" and line.get_markersize() >= 12]
    plt.close(drawn.figure)
    assert marks and not any(line.get_clip_on() for line in marks)
