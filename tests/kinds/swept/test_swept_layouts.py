"""Swept-sine studies of general scenes (matrices, a force on a named coordinate, a list of stops with bumpers): the
paper's layout written so equals its named form, and a layout the named form cannot express (the 1928 relative
stops between absorber and primary mass) runs end to end, against its stepped compliant steady states."""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import xarray as xr

from vibroimpact import cli
from vibroimpact.reporting.record import is_general
from vibroimpact.scene import SceneError, parse_scene
from vibroimpact.runs.run import run_study

from tests.scene.test_scene import PAPER_SYSTEM_SPEC

#: The paper's masses as matrices: k1 = 25000, k2 = 4300, b1 = 0.8, b2 = 0.08 [SI].
PAPER_MATRICES = {
    "mass": [[1.0, 0.0], [0.0, 0.1]],
    "stiffness": [[29300.0, -4300.0], [-4300.0, 4300.0]],
    "damping": [[0.88, -0.08], [-0.08, 0.08]],
    "coordinates": ["x1", "x2"],
}


def named_sweep(**changes: Any) -> dict[str, Any]:
    """The paper's swept-sine test shrunk: 24 -> 24.5 Hz at 0.5 Hz/s up and down, the 250 Hz bumper, R = 0.2."""
    document: dict[str, Any] = {
        "name": "named_sweep",
        "system": dict(PAPER_SYSTEM_SPEC),
        "excitation": {"amplitude": 10.0},
        "stop": {"clearance": 0.003, "restitution": 0.2},
        "bumper": {"frequency": 250.0},
        "sweep": {"frequency": {"start": 20.0, "stop": 30.0, "step": 0.25}},
        "swept_sine": {"start": 24.0, "stop": 24.5, "rate": 0.5, "sample_rate": 1000.0, "window_cycles": 8},
        "solutions": ["linear", "pgf", "compliant"],
        "simulation": {"rtol": 1e-6, "atol": 1e-10},
        "report": False,
    }
    document.update(changes)
    return document


def relative_sweep(**changes: Any) -> dict[str, Any]:
    """The paper's masses with two-sided relative bumpers |x2 - x1| <= 3 mm (R = 0.2, 250 Hz), swept 22 -> 23 Hz at
    0.1 Hz/s through the stable symmetric two-impact orbits."""
    document: dict[str, Any] = {
        "name": "relative_sweep",
        "system": copy.deepcopy(PAPER_MATRICES),
        "excitation": {"amplitude": 10.0, "on": "x1"},
        "stops": [
            {"between": ["x2", "x1"], "side": "upper", "clearance": 0.003, "restitution": 0.2},
            {"between": ["x2", "x1"], "side": "lower", "clearance": 0.003, "restitution": 0.2},
        ],
        "bumper": {"frequency": 250.0},
        "sweep": {"frequency": [22.4, 22.6]},
        "swept_sine": {"start": 22.0, "stop": 23.0, "rate": 0.1, "directions": ["up"], "sample_rate": 1000.0, "window_cycles": 8},
        "solutions": ["pgf", "compliant"],
        "simulation": {"rtol": 1e-6, "atol": 1e-10},
        "report": False,
    }
    document.update(changes)
    return document


@pytest.mark.timeout(120)
def test_the_paper_layout_as_matrices_gives_the_named_forms_dataset() -> None:
    """Every variable of the matrix form (a force on x1, one upper stop on x2 with its bumper) equals the named
    form's to 1e-12 of its largest magnitude (measured: identical), flags and counts exactly; the same names (the
    coordinates are x1, x2) and dimensions; only the dataset's layout attributes differ."""
    named = run_study(parse_scene(named_sweep()), progress=None)
    general_document = named_sweep(system=copy.deepcopy(PAPER_MATRICES), excitation={"amplitude": 10.0, "on": "x1"}, stop=None)
    general_document.pop("stop")
    general_document["stops"] = [{"coordinate": "x2", "side": "upper", "clearance": 0.003, "restitution": 0.2}]
    general = run_study(parse_scene(general_document), progress=None)
    assert general.attrs["system_coordinates"] == named.attrs["system_coordinates"] == "x1 x2"  # both record their layout
    assert set(general.data_vars) == set(named.data_vars)
    assert np.nanmax(named["swept_impacts_per_period"].values) >= 1.0  # the sweep reaches the stop
    for name in named.data_vars:
        a, b = general[name], named[name]
        assert a.dims == b.dims, name
        if "wall time" in str(b.attrs.get("long_name", "")):
            continue
        if b.dtype.kind in "iu":
            np.testing.assert_array_equal(a.values, b.values, err_msg=name)
        else:
            scale = float(np.nanmax(np.abs(b.values))) if np.isfinite(b.values).any() else 0.0
            np.testing.assert_allclose(a.values, b.values, rtol=0.0, atol=1e-12 * scale, err_msg=name)


@pytest.fixture(scope="module")
def relative_run() -> xr.Dataset:
    return run_study(parse_scene(relative_sweep()), progress=None)


@pytest.mark.timeout(120)
def test_relative_stops_sweep_names_each_coordinate_and_stop(relative_run: xr.Dataset) -> None:
    ds = relative_run
    assert is_general(ds) and ds.attrs["stop_count"] == 2
    assert ds["swept_x1_amplitude"].dims == ("sweep", "frequency") and ds["swept_x2_rms"].dims == ("sweep", "frequency")
    assert ds["swept_impulse"].dims == ("stop", "sweep", "frequency") and ds["impulse"].dims == ("solution", "stop", "frequency")
    assert ds["running_impulse"].dims == ("stop", "sweep", "elapsed_time") and ds["running_x2_amplitude"].dims == ("sweep", "elapsed_time")
    assert list(ds["stop_description"].values) == ["x2 - x1 <= 3 mm, R = 0.2", "x2 - x1 >= -3 mm, R = 0.2"]
    assert "coordinate x1" in ds["swept_x1_amplitude"].attrs["long_name"] and ds["swept_x1_amplitude"].attrs["units"] == "m"
    assert ds["running_force_amplitude"].attrs["units"] == "N"
    assert float(ds["sweep_failed"].sel(sweep="up")) == 0.0 and float(ds["sweep_contacts"].sel(sweep="up")) > 20  # exact: a flag stored as float


@pytest.mark.slow
@pytest.mark.timeout(120)
def test_relative_stops_sweep_follows_the_stepped_compliant_steady_state(relative_run: xr.Dataset) -> None:
    """At 22.4 and 22.6 Hz, reached at 0.1 Hz/s, the running estimates over 8 cycles are those of the compliant
    steady state stepped to there (same bumpers): |x1|, |x2| and the force on the base to 1 % (measured <= 0.7 %;
    halving the rate halves it: the sweep's lag), two contacts per period, one on each stop, and each stop's impulse
    to 3 % (measured <= 2 %); the rigid closed form (pgf) is within 6 % (measured 4.5 %: the 250 Hz bumper's own physics)."""
    stepped_document = relative_sweep(solutions=["pgf", "compliant"], simulation={"start": "pgf"})
    stepped_document.pop("swept_sine")
    stepped = run_study(parse_scene(stepped_document), progress=None)
    swept = relative_run.sel(sweep="up")
    compliant = stepped.sel(solution="compliant")
    assert np.all(compliant["converged"].values == 1)
    for quantity in ("x1_amplitude", "x2_amplitude", "force_amplitude"):
        np.testing.assert_allclose(swept[f"swept_{quantity}"].values, compliant[quantity].values, rtol=0.01, err_msg=quantity)
        np.testing.assert_allclose(swept[f"swept_{quantity}"].values, stepped[quantity].sel(solution="pgf").values, rtol=0.06, err_msg=quantity)
    np.testing.assert_array_equal(swept["swept_impacts_per_period"].values, [2.0, 2.0])
    np.testing.assert_allclose(swept["swept_impulse"].values, compliant["impulse"].values, rtol=0.03)
    assert np.all(swept["swept_regime"].values == 10)  # SWEPT_CONTACT


def test_a_swept_base_motion_is_refused_naming_the_key(tmp_path: Path) -> None:
    """A base motion's inertial load grows with the sweep's frequency squared: not a swept force; the scene says so
    (SceneError naming excitation.base_motion), and run-study exits with status 2 before any work."""
    document = relative_sweep(excitation={"amplitude": 0.001, "base_motion": True})
    with pytest.raises(SceneError) as caught:
        parse_scene(document)
    assert any("excitation.base_motion" in p and "swept base motion is not supported" in p for p in caught.value.problems)
    path = tmp_path / "base.yaml"
    path.write_text(
        "name: base\nsystem: {mass: [[1.0, 0.0], [0.0, 0.1]], stiffness: [[29300.0, -4300.0], [-4300.0, 4300.0]]}\n"
        "excitation: {amplitude: 0.001, base_motion: true}\nstops: [{coordinate: x2, clearance: 0.003, restitution: 0.2, bumper: {frequency: 250.0}}]\n"
        "sweep: {frequency: [22.4]}\nswept_sine: {start: 22.0, stop: 23.0, rate: 0.1}\nsolutions: [compliant]\n"
    )
    assert cli.main([str(path), "--out", str(tmp_path / "out")]) == 2
    assert not (tmp_path / "out").exists()


def test_a_stop_without_a_bumper_is_refused_for_a_sweep() -> None:
    """The swept test runs the compliant model: every stop needs its bumper (its own, or the scene's section)."""
    document = relative_sweep()
    document.pop("bumper")
    with pytest.raises(SceneError) as caught:
        parse_scene(document)
    assert any(p.startswith("stops[0].bumper.frequency: required") for p in caught.value.problems), caught.value.problems


@pytest.mark.slow
@pytest.mark.timeout(120)
def test_relative_stops_sweep_page_draws_every_coordinate_and_stop(relative_run: xr.Dataset, tmp_path: Path) -> None:
    """The general page: structure and stops with their linear responses, then one panel per coordinate, the force,
    one impulse panel per stop (its constraint in the title) and the contacts, each showing the sweep's estimate and
    the steady state; the comparison with pgf in one band (no anti-resonance split for a general structure)."""
    import matplotlib.pyplot as plt

    from vibroimpact.reporting.page import page_for
    from vibroimpact.kinds.swept.page import GeneralSweptPage, sweep_figures, sweep_layout, swept_sine_run
    from tests.reporting.test_report_support import shown_points

    ds = relative_run
    page = page_for(ds)
    assert isinstance(page, GeneralSweptPage)
    assert page.summary() == "solutions: pgf, compliant; stops: x2 - x1 <= 3 mm, R = 0.2; x2 - x1 >= -3 mm, R = 0.2"
    sections = page.sections(tmp_path)
    assert [s.title for s in sections] == ["Contacts and the steady states", "Structure and stops", "Swept sine against the steady states"]
    assert [f.path.stem for f in sections[2].figures] == ["sweep_displacements", "sweep_force_impulse", "sweep_regime", "sweep_time"]
    assert sections[2].tables[-1].title == "Swept sine against the stable pgf steady state (|X1| fundamental)" and "<td>all</td>" in sections[2].tables[-1].html
    layout = sweep_layout(ds)
    assert layout.coordinates == ("x1", "x2") and layout.labels == ("X1", "X2") and len(layout.stops) == 2
    figures = {drawn.name: drawn for drawn in sweep_figures(ds, swept_sine_run(ds))}
    assert "closed-form impact orbit" in figures["sweep_displacements"].caption and "one-impact closed form" not in figures["sweep_displacements"].caption
    axes = figures["sweep_force_impulse"].figure.axes
    assert [ax.get_title() for ax in axes] == ["|F| on the base", "impulse per period, stop 0: x2 - x1 <= 3 mm", "impulse per period, stop 1: x2 - x1 >= -3 mm", "contacts per period"]
    for ax in [*figures["sweep_displacements"].figure.axes, *axes]:
        assert shown_points(ax, "compliant") and shown_points(ax, "pgf"), ax.get_title()
    for drawn in figures.values():
        plt.close(drawn.figure)
