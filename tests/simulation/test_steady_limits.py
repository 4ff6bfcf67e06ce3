"""Steady states that know their limits (issue 22, item 3): no engine reports a steady state near an undamped natural
frequency, where the exact engine and the closed form refuse, and no result beyond any physical scale of the scene.

Before: at the first natural frequency of the undamped paper system (F0), ``momentary`` from the linear start reported
converged = 1 with impacts_per_period = 1.125 (a transient measured as a steady state: its repeat test ran on the
linear amplitude, 2.8e12 m), and at 1e-9 detuning the exact engine reported x1 = 2.25 mm with x1_rms = 0.
"""

from __future__ import annotations

import copy
import dataclasses
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from vibroimpact import cli
from vibroimpact.analysis.stability import Regime
from vibroimpact.runs.labels import decode_labels
from vibroimpact.simulation import steady
from vibroimpact.simulation.history import engine_of
from vibroimpact.simulation.steady import AMPLITUDE_LIMIT, amplitude_scale, check_amplitude, steady_state

from tests.analysis.test_closed_form_limits import F0, _problem
from tests.scene.test_scene import base_scene, write_yaml


@pytest.mark.parametrize("detuning", [0.0, 1e-10, -1e-9, 1e-8, 1e-6])
@pytest.mark.parametrize("engine", ["momentary", "exact"])
def test_no_engine_reports_a_steady_state_near_an_undamped_natural_frequency(engine: str, detuning: float) -> None:
    for start in ("linear", "shooting"):
        with pytest.raises(ValueError, match=r"of an undamped mode: the harmonic response there is ill-conditioned \(condition .* > 1e4"):
            steady_state(engine, _problem(F0 * (1.0 + detuning)), start)


def test_a_study_near_the_undamped_resonance_flags_every_solution_and_reports_the_rest(tmp_path: Path) -> None:
    """pgf, momentary and exact are ``failed`` at 0 and 1e-9 detuning (and linear is the huge linear response,
    ``linear_exceeds_clearance``); at 1e-4 both engines and the closed form agree on |X1| = 2.2506 mm."""
    document = copy.deepcopy(base_scene())
    document["system"].update(b1=0.0, b2=0.0)
    frequencies = [F0 * (1.0 - 1e-4), F0 * (1.0 - 1e-9), F0]
    document["sweep"] = {"frequency": frequencies}
    document["solutions"] = ["pgf", "momentary", "exact"]
    document["simulation"] = {"start": "linear"}
    out = tmp_path / "out"
    assert cli.main([str(write_yaml(tmp_path / "undamped.yaml", document)), "--out", str(out), "--jobs", "1", "--no-report"]) == 0
    closed = decode_labels(xr.load_dataset(out / "tiny.nc")).sel(solution="pgf").squeeze()
    simulated = decode_labels(xr.load_dataset(out / "tiny.nc", group="simulated")).squeeze()  # on the simulated frequencies
    assert closed["regime"].values.tolist() == [Regime.ONE_IMPACT, Regime.FAILED, Regime.FAILED]
    for name in ("momentary", "exact"):
        run = simulated.sel(solution=name)
        assert run["regime"].values.tolist() == [Regime.ONE_IMPACT, Regime.FAILED, Regime.FAILED], name
        assert run["converged"].values.tolist() == [1, -1, -1], name
        assert np.all(np.isnan(run["x1_amplitude"].values[1:])) and np.all(np.isnan(run["x1_rms"].values[1:]))
        assert float(run["x1_amplitude"][0]) == pytest.approx(float(closed["x1_amplitude"][0]), rel=1e-5)
    assert float(closed["x1_amplitude"][0]) == pytest.approx(2.2506e-3, rel=1e-4)


def test_a_steady_state_beyond_any_physical_scale_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    """A result of 35 m (what momentary reported at F0 before) where the scene's scale (3 mm clearance plus the
    linear response, 3.4 m at 1e-4 detuning) allows at most 1000 times that: ValueError, not a number."""
    problem = _problem(F0 * (1.0 - 1e-4))
    scale = amplitude_scale(problem)
    assert 3.0 < scale < 4.0
    honest = steady.steady_state("momentary", problem, "shooting")
    check_amplitude(problem, honest)  # 2.25 mm: accepted
    absurd = dataclasses.replace(honest, measures=dataclasses.replace(honest.measures, displacements=(1.5 * AMPLITUDE_LIMIT * scale + 0j, 1e-3 + 0j)))
    with pytest.raises(ValueError, match=r"\|x1\| = 5\.\d+e\+03 m, beyond 1000 times the scene's scale 3\.\d+ m"):
        check_amplitude(problem, absurd)
    monkeypatch.setattr(steady, "_steady_state", lambda *args: absurd)
    with pytest.raises(ValueError, match="no physical steady state; not reported"):
        steady.steady_state("momentary", problem, "shooting")


def test_the_exact_engine_itself_refuses_the_band_the_closed_form_refuses() -> None:
    """Integrating (not only steady states): the exact flows need the harmonic response, ill-conditioned within
    1.6e-5 of F0 (before: refused only within 1e-10, and at 1e-9 it reported x1_rms = 0 with |X1| = 2.25 mm)."""
    engine = engine_of("exact")
    with pytest.raises(ValueError, match="ill-conditioned"):
        engine.integrate(_problem(F0 * (1.0 + 1e-6)), np.zeros(4), 0.0, 1)
    engine.integrate(_problem(F0 * (1.0 + 1e-4)), np.zeros(4), 0.0, 1)  # kappa = 1.6e3: integrated
