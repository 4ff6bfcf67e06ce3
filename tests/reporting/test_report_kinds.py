"""One page type per kind of study, chosen from the dataset alone; what a page knows of its study comes from the
dataset (coordinates, variables, attributes), never from a re-validated scene."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from vibroimpact.reporting import page as page_module
from vibroimpact.kinds.benchmark.page import AccuracyPage
from vibroimpact.kinds.stepped.page import BumperStiffnessPage
from vibroimpact.reporting.record import StudyRecord, stored_description, study_kind, study_record, study_setting
from vibroimpact.reporting.page import page_for, write_report
from vibroimpact.kinds.stepped.page import FrequencyResponsePage
from vibroimpact.kinds.swept.page import SweptSinePage, swept_sine_run

from tests.reporting.test_report_pages import quick_save
from tests.reporting.test_report_support import benchmark_dataset, steady_dataset, stiffness_dataset, swept_dataset


@pytest.fixture(autouse=True)
def _no_png(monkeypatch: pytest.MonkeyPatch) -> None:
    """Pages are composed without rendering PNGs (seconds each); the figures themselves are tested elsewhere."""
    monkeypatch.setattr(page_module, "save_figure", quick_save)


def _names(section: page_module.Section) -> tuple[list[str], list[str]]:
    """File names of a section's figures and titles of its tables."""
    return [f.path.stem for f in section.figures], [t.title for t in section.tables]


def test_stepped_page_has_responses_simulations_peaks_agreement_and_reduction_factors(tmp_path: Path) -> None:
    ds = steady_dataset()
    page = page_for(ds)
    assert isinstance(page, FrequencyResponsePage)
    assert page.summary() == "solutions: linear, pgf, pgf_paper, exact, momentary, compliant, compliant_exact; stops: x2 <= 3 mm"
    sections = {s.title: s for s in page.sections(tmp_path)}
    assert list(sections) == [
        "Largest responses",  # the answer first, in numbers: peaks against R, contact peaks, reduction factors
        "Resonance peaks against the restitution",
        "Reduction factors",  # what the stop buys
        "Linear system",
        "Frequency responses, Delta = 3 mm",
        "Simulations against the closed form, Delta = 3 mm",
        "Simulation against the closed form: agreement by band",
    ]
    assert _names(sections["Largest responses"]) == ([], ["Largest value of every response, per solution"])
    answer = sections["Largest responses"].intro
    assert "Resonance peaks of |X1| [mm] at R = 0.2, 0.6" in answer and "Largest contact deceleration: compliant" in answer and "Reduction factors: the stop divides" in answer
    assert _names(sections["Linear system"]) == (["structure"], ["Modal parameters of H22", "Structure", "Stops and load"])
    assert _names(sections["Resonance peaks against the restitution"]) == (["peaks_vs_restitution"], ["Resonance peaks of |X1| against the restitution: values"])
    figures, _ = _names(sections["Frequency responses, Delta = 3 mm"])
    assert figures == ["x2_amplitude", "x1_amplitude", "force_amplitude", "suspension_force_amplitude", "impulse", "regime", "stability", "peak_acceleration"]
    assert _names(sections["Simulations against the closed form, Delta = 3 mm"])[0] == [f"simulation_{q}" for q in ("x1_amplitude", "x2_amplitude", "force_amplitude", "impulse")] + ["lyapunov"]
    assert [t.title for t in sections["Reduction factors"].tables] == [f"Reduction factors: {q}" for q in ("|X1| fundamental", "|F| on the base", "|F| through the suspension", "|X2| fundamental")]


def test_bumper_stiffness_page_shows_convergence_and_cost(tmp_path: Path) -> None:
    ds = stiffness_dataset()
    page = page_for(ds)
    assert isinstance(page, BumperStiffnessPage)
    assert page.summary() == "solutions: pgf, exact, compliant"
    sections = page.sections(tmp_path)
    assert [s.title for s in sections] == ["Compliant bumper against the rigid stop", "Linear system"]  # the answer first
    assert _names(sections[0]) == (["bumper_stiffness"], ["compliant against exact: convergence and cost"])
    assert "differs from the rigid stop&#x27;s (exact) by" in sections[0].intro and "observed order" in sections[0].intro
    # the simulated frequencies come from the data: the dataset has no simulation_frequency_Hz attribute
    np.testing.assert_array_equal(study_setting(ds).simulation_frequency, [24.0, 25.0])


def test_swept_sine_page_shows_the_sweeps_against_the_steady_states(tmp_path: Path) -> None:
    ds = swept_dataset()
    page = page_for(ds)
    assert isinstance(page, SweptSinePage)
    assert page.summary() == "solutions: linear, pgf, compliant", "the swept solution is not along the solution dimension"
    sections = page.sections(tmp_path)
    assert [s.title for s in sections] == ["Contacts and the steady states", "Linear system", "Swept sine against the steady states"]
    assert "Contacts of the &#x27;compliant&#x27; sweeps" in sections[0].intro and "sweeping up over" in sections[0].intro
    figures, tables = _names(sections[2])
    assert figures == ["sweep_displacements", "sweep_force_impulse", "sweep_regime", "sweep_time"]
    assert tables == ["Cost of the swept-sine runs (one process each)", "Swept sine against the stable pgf steady state (|X1| fundamental)"]
    run = swept_sine_run(ds)
    assert run.text() == "21 <-> 29 Hz at 1 Hz/s, bumper 250 Hz, xi_b = 0.7312, estimator window 8 cycles"
    assert run.duration == pytest.approx(8.0, rel=1e-15)


def test_benchmark_page_shows_work_precision_and_every_point(tmp_path: Path) -> None:
    ds = benchmark_dataset()
    page = page_for(ds)
    assert isinstance(page, AccuracyPage)
    assert page.summary() == "methods: momentary_adams, compliant_ida, solve_ivp_DOP853"
    sections = page.sections(tmp_path)
    assert [s.title for s in sections] == ["Work-precision"]
    figures, tables = _names(sections[0])
    assert figures == ["work_precision"]
    assert tables[:3] == ["Cheapest way to the X1 fundamental within a target", "Tolerance guidance: loosest rtol meeting each target", "momentary (Adams) against exact and against solve_ivp at equal impact-time error"]
    assert tables[-2:] == ["Every point: one_impact", "Every point: irregular"]


@pytest.mark.parametrize(
    ("dataset", "kind"),
    [(steady_dataset, "stepped"), (stiffness_dataset, "stepped"), (swept_dataset, "swept"), (benchmark_dataset, "benchmark")],
)
def test_kind_comes_from_the_attribute_else_from_the_dimensions(dataset: object, kind: str) -> None:
    ds = dataset()  # type: ignore[operator]
    assert study_kind(ds) == kind
    without = ds.copy()
    without.attrs = {k: v for k, v in ds.attrs.items() if k != "study_kind"}
    assert study_kind(without) == kind


def test_the_study_kind_attribute_decides_and_is_checked() -> None:
    ds = steady_dataset().copy()
    ds.attrs = dict(ds.attrs, study_kind="benchmark")
    assert study_kind(ds) == "benchmark"
    ds.attrs["study_kind"] = "continuation"
    with pytest.raises(ValueError, match="study_kind must be one of design, concepts, validation, benchmark, bifurcation, swept, stepped"):
        study_kind(ds)
    with pytest.raises(ValueError, match="kind must be one of"):
        StudyRecord(kind="other", name="x", description="", scene_text="", version="0")


def test_a_dataset_whose_scene_no_longer_validates_is_still_reported(tmp_path: Path) -> None:
    """The stored scene has a key today's parser refuses; the page is made from the dataset all the same, the scene
    text shown verbatim, the description read from it as plain YAML."""
    ds = steady_dataset(engines=("exact",), restitution=(0.2,), step=0.5).copy()
    scene = "name: old_study\ndescription: written by an older version\nobsolete_key: {anything: 1}\nsystem: not a mapping\n"
    ds.attrs = dict(ds.attrs, scene=scene, scene_name="old_study")
    path = write_report(ds, tmp_path)
    text = path.read_text()
    assert "<h1>Study &#x27;old_study&#x27;</h1>" in text
    assert "<p>written by an older version</p>" in text
    assert "obsolete_key: {anything: 1}" in text
    assert "Reduction factors" in text
    assert study_record(ds).description == "written by an older version"


@pytest.mark.parametrize("text", ["", "- a list\n- not a mapping\n", "description: [not, text]\n", "name: [unclosed\n"])
def test_a_missing_or_unreadable_description_is_empty(text: str) -> None:
    assert stored_description(text) == ""


def test_the_setting_is_what_the_dataset_stores() -> None:
    ds = steady_dataset()
    setting = study_setting(ds)
    assert setting.system.as_dict() == {key: float(ds.attrs[f"system_{key}"]) for key in ("m1", "m2", "k1", "k2", "b1", "b2")}
    assert setting.amplitude == pytest.approx(10.0, rel=0.0)
    np.testing.assert_array_equal(setting.frequency, ds["frequency"].values)
    np.testing.assert_array_equal(setting.clearance, [0.003])
    np.testing.assert_allclose(setting.simulation_frequency, np.arange(15.0, 45.0 + 1e-9, 0.5), rtol=0.0, atol=1e-9)
    np.testing.assert_array_equal(setting.bumper_frequency, [250.0])
    stored = xr.Dataset(ds.data_vars, coords=ds.coords, attrs=dict(ds.attrs, simulation_frequency_Hz=np.array([20.0, 30.0])))
    np.testing.assert_array_equal(study_setting(stored).simulation_frequency, [20.0, 30.0])


@pytest.mark.slow
def test_one_restitution_draws_each_quantity_once(tmp_path: Path) -> None:
    """With one R, a quantity's panels per solution would each hold one series of what the simulation figure
    overlays: it is drawn once, there (a study sweeping the clearance had 32 figures of 82 twice). Another closed form
    (``pgf_paper``) and the raw one-impact values are not in the simulation figure: with either, both figures stay."""
    full = steady_dataset().isel(restitution=0)
    raw = [str(name) for name in full.data_vars if str(name).startswith("one_impact_")]
    assert raw
    held = full.drop_vars(raw).sel(solution=[s for s in full["solution"].values if s != "pgf_paper"])
    sections = {s.title: s for s in page_for(held).sections(tmp_path)}
    assert "Frequency responses, Delta = 3 mm" not in sections and "Simulations against the closed form, Delta = 3 mm" not in sections
    figures, _ = _names(sections["Frequency responses and simulations, Delta = 3 mm"])
    assert figures == [f"simulation_{q}" for q in ("x1_amplitude", "x2_amplitude", "force_amplitude", "impulse")] + ["suspension_force_amplitude", "regime", "stability", "peak_acceleration", "lyapunov"]
    for name, part in (("paper", full.drop_vars(raw)), ("raw", full.sel(solution=held["solution"].values))):
        (tmp_path / name).mkdir()
        sections = {s.title: s for s in page_for(part).sections(tmp_path / name)}
        assert _names(sections["Frequency responses, Delta = 3 mm"])[0][:3] == ["x2_amplitude", "x1_amplitude", "force_amplitude"], name
        assert _names(sections["Simulations against the closed form, Delta = 3 mm"])[0][0] == "simulation_x1_amplitude", name
