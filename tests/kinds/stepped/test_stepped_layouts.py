"""Stepped studies of any layout: the paper written with matrices gives the paper's dataset; relative, two-sided and
3-dof layouts give outputs named after their coordinates and stops."""

from __future__ import annotations

import copy
from typing import Any

import numpy as np
import pytest
import xarray as xr

from vibroimpact.analysis.stability import Regime
from vibroimpact.scene import parse_scene
from vibroimpact.runs.run import run_study

NAMED = {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0, "b1": 0.8, "b2": 0.08}
MATRICES = {"mass": [[1.0, 0.0], [0.0, 0.1]], "stiffness": [[29300.0, -4300.0], [-4300.0, 4300.0]], "damping": [[0.88, -0.08], [-0.08, 0.08]]}
SWEEP = {"restitution": [0.0, 0.5, 1.0], "clearance": [0.002, 0.003], "frequency": {"start": 20.0, "stop": 40.0, "step": 0.5}}


def named_document() -> dict[str, Any]:
    return {"name": "named", "system": dict(NAMED), "excitation": {"amplitude": 10.0}, "bumper": {"frequency": 250.0}, "sweep": copy.deepcopy(SWEEP), "solutions": ["linear", "pgf"], "report": False}


def general_document() -> dict[str, Any]:
    document = named_document()
    document.update(name="general", system=copy.deepcopy(MATRICES), excitation={"amplitude": 10.0, "on": "x1"}, stops=[{"coordinate": "x2", "side": "upper"}])
    return document


@pytest.fixture(scope="module")
def paper_pair() -> tuple[xr.Dataset, xr.Dataset]:
    """The paper's closed forms from the named and from the general form of the same scene."""
    return run_study(parse_scene(named_document()), progress=None), run_study(parse_scene(general_document()), progress=None)


def test_paper_in_general_form_equals_named_form(paper_pair: tuple[xr.Dataset, xr.Dataset]) -> None:
    """Same variables, dimensions and coordinates; values to 1e-10 relative (measured 4e-12: receptances by matrix
    inversion and the general PGF against the paper's closed forms); flags identical."""
    named, general = paper_pair
    assert set(named.data_vars) == set(general.data_vars)
    assert dict(named.sizes) == dict(general.sizes)
    for name in named.data_vars:
        if named[name].dtype.kind in "iu":
            xr.testing.assert_equal(named[name], general[name])
        else:
            xr.testing.assert_allclose(named[name], general[name], rtol=1e-10, atol=1e-300)
    assert general.attrs["stop_layout"] == named.attrs["stop_layout"] == "x2 <= Delta"
    different = {key for key in set(named.attrs) | set(general.attrs) if str(named.attrs.get(key)) != str(general.attrs.get(key))}
    assert different == {"title", "scene_name", "scene"}, "one dataset layout: the same attributes, named ones included (the scene text is each one's own)"


def test_paper_general_form_has_one_impact_orbits(paper_pair: tuple[xr.Dataset, xr.Dataset]) -> None:
    """The comparison above is not vacuous: the grid holds one-impact orbits and linear points."""
    regime = paper_pair[1]["regime"].sel(solution="pgf").values
    assert np.count_nonzero(regime == Regime.ONE_IMPACT) > 10 and np.count_nonzero(regime == Regime.LINEAR) > 10


def relative_document() -> dict[str, Any]:
    return {
        "name": "relative",
        "system": {**copy.deepcopy(MATRICES), "coordinates": ["primary", "absorber"]},
        "excitation": {"amplitude": 10.0, "on": "primary"},
        "stops": [
            {"between": ["absorber", "primary"], "side": "upper", "clearance": 0.003, "restitution": 0.2},
            {"between": ["absorber", "primary"], "side": "lower", "clearance": 0.003, "restitution": 0.2},
        ],
        "sweep": {"frequency": {"start": 15.0, "stop": 45.0, "step": 0.25}},
        "solutions": ["linear", "pgf"],
        "report": False,
    }


@pytest.fixture(scope="module")
def relative() -> xr.Dataset:
    return run_study(parse_scene(relative_document()), progress=None)


def test_relative_two_sided_outputs(relative: xr.Dataset) -> None:
    """Amplitudes per named coordinate; impulses per stop on a ``stop`` dimension described in words."""
    assert {"primary_amplitude", "absorber_amplitude", "primary_rms", "absorber_rms"} <= set(relative.data_vars)
    assert "x1_amplitude" not in relative
    assert relative["impulse"].dims == ("solution", "stop", "frequency")
    assert relative["primary_amplitude"].dims == ("solution", "frequency")
    assert list(relative["stop_description"].values) == ["absorber - primary <= 3 mm, R = 0.2", "absorber - primary >= -3 mm, R = 0.2"]
    assert float(relative["clearance"]) == pytest.approx(0.003, rel=1e-15)


def test_relative_stop_does_not_load_the_base(relative: xr.Dataset) -> None:
    """A relative stop acts inside the structure: the force on the base is the suspension's alone (same numbers)."""
    pgf = relative.sel(solution="pgf")
    impacting = pgf["regime"].values == Regime.ONE_IMPACT
    assert impacting.any()
    np.testing.assert_allclose(pgf["force_amplitude"].values[impacting], pgf["suspension_force_amplitude"].values[impacting], rtol=1e-15)


def test_symmetric_orbit_has_equal_impulses_on_both_sides(relative: xr.Dataset) -> None:
    """The symmetric two-sided orbit: the same impulse on the upper and the lower stop, two impacts per period."""
    pgf = relative.sel(solution="pgf")
    impacting = pgf["regime"].values == Regime.ONE_IMPACT
    upper, lower = pgf["impulse"].sel(stop=0).values, pgf["impulse"].sel(stop=1).values
    np.testing.assert_allclose(upper[impacting], lower[impacting], rtol=1e-15)
    assert np.all(upper[impacting] > 0.0)
    np.testing.assert_allclose(pgf["impacts_per_period"].values[impacting], 2.0, rtol=0)


def test_linear_amplitude_of_the_relative_coordinate_decides_the_regime(relative: xr.Dataset) -> None:
    """``linear`` is flagged as crossing the stop exactly where |X2 - X1| of the linear state exceeds Delta."""
    from vibroimpact.model.structure import LinearStructure

    structure = LinearStructure(MATRICES["mass"], MATRICES["stiffness"], MATRICES["damping"])
    w = 2.0 * np.pi * relative["frequency"].values
    h = structure.receptance_matrix(w)
    relative_amplitude = np.abs(10.0 * (h[:, 1, 0] - h[:, 0, 0]))
    flags = relative["regime"].sel(solution="linear").values
    np.testing.assert_array_equal(flags == Regime.LINEAR_EXCEEDS_CLEARANCE, relative_amplitude > 0.003)


def test_three_dof_names_and_no_stop_dimension_for_one_stop() -> None:
    """A 3-dof chain with one absolute stop: three amplitudes, ``impulse`` without a stop dimension."""
    document = {
        "name": "chain3",
        "system": {"mass": [[1.0, 0, 0], [0, 0.5, 0], [0, 0, 0.1]], "stiffness": [[2e4, -1e4, 0], [-1e4, 1.5e4, -5e3], [0, -5e3, 5e3]],
                   "damping": [[2.0, -1.0, 0], [-1.0, 1.5, -0.5], [0, -0.5, 0.5]], "coordinates": ["a", "b", "c"]},  # fmt: skip
        "excitation": {"amplitude": 10.0, "on": "a"},
        "stops": [{"coordinate": "c", "side": "lower", "clearance": 0.002, "restitution": 0.5}],
        "sweep": {"frequency": {"start": 5.0, "stop": 40.0, "step": 1.0}},
        "solutions": ["linear", "pgf"],
        "report": False,
    }
    dataset = run_study(parse_scene(document), progress=None)
    assert {"a_amplitude", "b_amplitude", "c_amplitude"} <= set(dataset.data_vars)
    assert dataset["impulse"].dims == ("solution", "frequency")
    assert "stop" not in dataset.dims
    assert dataset.attrs["stop_layout"] == "c >= -2 mm, R = 0.5"
    assert (dataset["regime"].sel(solution="pgf").values == Regime.ONE_IMPACT).any()


def test_paper_in_general_form_simulates_like_the_named_form() -> None:
    """Engines on the paper written with matrices (shooting starts, 2N-wide states, moments per coordinate and stop)
    give the named form's steady states: every flag equal, values to 1e-10 (measured 1.5e-14) on these periodic
    points (a non-periodic motion would amplify round-off, so none is compared)."""
    named = named_document()
    named.update(sweep={"frequency": [18.0, 24.0, 25.0, 26.0, 30.0]}, stop={"clearance": 0.003, "restitution": 0.5}, solutions=["pgf", "exact", "momentary"])
    named["simulation"] = {"start": "shooting", "max_periods": 100, "lyapunov_periods": 0, "irregular_measure_periods": 16}
    named.pop("bumper")
    general = copy.deepcopy(named)
    general.pop("stop")
    general.update(system=copy.deepcopy(MATRICES), excitation={"amplitude": 10.0, "on": "x1"}, stops=[{"coordinate": "x2", "clearance": 0.003, "restitution": 0.5}])
    a, b = run_study(parse_scene(named), progress=None), run_study(parse_scene(general), progress=None)
    assert np.all(a["converged"].sel(solution=["exact", "momentary"]).values == 1)
    assert (a["regime"].sel(solution="exact").values == Regime.ONE_IMPACT).sum() == 3
    for name in ("regime", "converged", "stable"):
        xr.testing.assert_equal(a[name], b[name])
    for name in ("x1_amplitude", "x2_amplitude", "force_amplitude", "impulse", "x1_rms", "x2_rms", "impacts_per_period"):
        xr.testing.assert_allclose(a[name], b[name], rtol=1e-10, atol=1e-300)


def test_three_dof_base_motion_exact_repeats_the_closed_form() -> None:
    """A 3-dof chain moved by its base with a lower stop on its last mass: where the closed-form orbit is stable,
    shooting with the exact engine finds it (amplitudes and impulse to 1e-9; measured 3e-15)."""
    document = {
        "name": "chain3_base",
        "system": {"mass": [[1.0, 0, 0], [0, 0.5, 0], [0, 0, 0.1]], "stiffness": [[2e4, -1e4, 0], [-1e4, 1.5e4, -5e3], [0, -5e3, 5e3]],
                   "damping": [[2.0, -1.0, 0], [-1.0, 1.5, -0.5], [0, -0.5, 0.5]], "coordinates": ["a", "b", "c"]},  # fmt: skip
        "excitation": {"amplitude": 1e-3, "base_motion": True},
        "stops": [{"coordinate": "c", "side": "lower", "clearance": 0.002, "restitution": 0.5}],
        "sweep": {"frequency": [19.0, 26.0, 28.0]},
        "solutions": ["pgf", "exact"],
        "simulation": {"start": "shooting", "max_periods": 200, "lyapunov_periods": 0, "irregular_measure_periods": 16},
        "report": False,
    }
    dataset = run_study(parse_scene(document), progress=None)
    pgf, exact = dataset.sel(solution="pgf"), dataset.sel(solution="exact")
    assert np.all(pgf["stable"].values == 1) and np.all(exact["regime"].values == Regime.ONE_IMPACT)
    for name in ("a_amplitude", "b_amplitude", "c_amplitude", "impulse", "force_amplitude"):
        np.testing.assert_allclose(exact[name].values, pgf[name].values, rtol=1e-9)


def test_sweep_of_one_stop_among_stops_with_their_own_values() -> None:
    """``sweep.stop`` sweeps the clearance of stop 0 only; stop 1 keeps its own values. The swept parameter is a
    dimension, each stop is described with what it takes (``Delta`` where swept), and no scalar restitution or
    bumper loss factor pretends to be shared."""
    document = {
        "name": "mixed",
        "system": copy.deepcopy(MATRICES),
        "excitation": {"amplitude": 10.0, "on": "x1"},
        "stops": [{"coordinate": "x2", "side": "upper", "restitution": 0.2, "bumper": {"frequency": 300.0}},
                  {"between": ["x2", "x1"], "side": "lower", "clearance": 0.002, "restitution": 0.6}],  # fmt: skip
        "bumper": {"frequency": 250.0},
        "sweep": {"clearance": [0.002, 0.004], "stop": 0, "frequency": {"start": 20.0, "stop": 26.0, "step": 0.5}},
        "solutions": ["linear", "exact"],
        "simulation": {"frequency": [24.0], "max_periods": 100, "lyapunov_periods": 0, "irregular_measure_periods": 16},
        "report": False,
    }
    dataset = run_study(parse_scene(document), progress=None)
    assert dataset["impulse"].dims == ("solution", "stop", "clearance", "frequency")
    assert list(dataset["stop_description"].values) == ["x2 <= Delta, R = 0.2, bumper 300 Hz", "x2 - x1 >= -2 mm, R = 0.6"]
    assert "restitution" not in dataset.coords and "bumper_loss_factor" not in dataset.coords
    impulses = dataset["impulse"].sel(solution="exact", frequency=24.0).values  # (stop, clearance)
    assert np.all(impulses > 0.0), "both stops are hit at 24 Hz, whichever clearance stop 0 has"
    assert not np.allclose(impulses[:, 0], impulses[:, 1], rtol=1e-3), "stop 0's clearance changes the motion"


def test_a_mass_held_on_a_preloading_stop_is_not_called_linear(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """k = 1e4 N/m pressed 1 mm into its stop (x1 <= -1 mm: a 10 N preload) by nothing; a 5 N force never lifts it. The
    exact engine holds it (amplitude ~0, contact force = the force's fundamental): held on the stop (regime 14), not
    the linear regime, whose response would cross the stop (regime 6), nor periodic impacts (regime 8: there is none)."""
    from vibroimpact.analysis.stability import Regime
    from vibroimpact.scene import load_scene
    from vibroimpact.runs.run import run_study

    text = """
name: held
description: a preloaded mass the force never lifts
system: {mass: [[1.0]], stiffness: [[10000.0]], damping: [[1.0]]}
excitation: {amplitude: 5.0, on: x1}
stops:
  - {coordinate: x1, side: upper, clearance: -0.001, restitution: 0.5}
sweep:
  frequency: {start: 2.0, stop: 4.0, step: 1.0}
solutions: [linear, exact]
simulation:
  frequency: {start: 2.0, stop: 4.0, step: 1.0}
"""
    path = tmp_path / "held.yaml"
    path.write_text(text, encoding="utf-8")
    dataset = run_study(load_scene(path), progress=None, jobs=1)
    exact = dataset.sel(solution="exact").squeeze()
    assert np.all(exact.regime.values == Regime.HELD_ON_STOP)  # no impact, not the linear motion: held by the preload
    assert np.all(exact.x1_amplitude.values <= 1e-12)
    assert np.all(dataset.sel(solution="linear").squeeze().regime.values == Regime.LINEAR_EXCEEDS_CLEARANCE)
