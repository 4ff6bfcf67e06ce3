"""Closed forms that know their limits (issue 22, item 3): near an undamped natural frequency the Green function sums
are ill-conditioned, and the closed form says so (regime ``failed``, values NaN) instead of giving a number.

The paper's system with b1 = b2 = 0 has its first natural frequency at F0 = 23.02212512577005 Hz. Before the guard
the one-impact orbit was 17 % too large at 1e-8 relative detuning, 15 x at 1e-9, and 1.3e12 m with stable = 1 at F0
while its own x1_rms was 3.5 mm.
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from vibroimpact import cli
from vibroimpact.analysis.greens import GREEN_CONDITION_LIMIT, green_condition
from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.analysis.two_sided import solve_two_impacts
from vibroimpact.analysis.pgf import PgfVariant, solve_one_impact
from vibroimpact.analysis.stability import Regime
from vibroimpact.model.contact import RigidStop, Stop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM, TwoDofSystem
from vibroimpact.runs.run import read_dataset
from vibroimpact.simulation.steady import SteadySettings, steady_state

from tests.scene.test_scene import base_scene, write_yaml

UNDAMPED = TwoDofSystem(1.0, 0.1, 25000.0, 4300.0, 0.0, 0.0)
F0 = 23.02212512577005  # the first natural frequency of UNDAMPED [Hz]
#: Relative detunings from F0: two the closed form evaluates (kappa 160, 1600), the issue's three it refuses.
DETUNINGS = (-1e-3, -1e-4, -1e-8, -1e-9, 0.0, 1e-9, 1e-4)


def _problem(frequency: float = F0) -> ImpactProblem:
    return ImpactProblem(UNDAMPED, RigidStop(0.003, 0.2), HarmonicForce(10.0, frequency))


def test_the_condition_number_grows_as_one_over_the_detuning_and_flags_the_issue_s_points() -> None:
    omega = 2.0 * np.pi * F0 * (1.0 + np.array([1e-4, 1e-8, 1e-9, 0.0]))
    orbit = solve_impact_orbit(_problem(), omega=omega)
    np.testing.assert_allclose(orbit.condition[:3], 1.0 / (2.0 * np.pi * np.array([1e-4, 1e-8, 1e-9])), rtol=1e-3)
    assert orbit.condition[3] > 1e14
    assert orbit.conditioned.tolist() == [True, False, False, False]
    assert orbit.exists.tolist() == [True, False, False, False]
    assert np.all(np.isnan(orbit.impulse[1:])) and np.all(np.isnan(orbit.phase[1:]))
    assert not orbit.with_root("-").exists[1:].any()  # the other root is refused there too


def test_the_paper_variant_and_the_two_sided_orbit_are_flagged_too() -> None:
    omega = 2.0 * np.pi * F0 * (1.0 + np.array([1e-4, 1e-9]))
    for variant in PgfVariant:
        assert solve_one_impact(UNDAMPED, omega=omega, clearance=0.003, restitution=0.2, amplitude=10.0, variant=variant).exists.tolist() == [True, False]
    # psi's sums are singular where exp(p T/2) = -1, i.e. w = Omega (and 2 Omega / odd)
    pair = (Stop(RigidStop(0.003, 0.2), 1, side="upper"), Stop(RigidStop(0.003, 0.2), 1, side="lower"))
    two_sided = solve_two_impacts(ImpactProblem(UNDAMPED, pair, HarmonicForce(10.0, F0)), omega=omega)
    assert two_sided.conditioned.tolist() == [True, False]


def test_the_shipped_damping_is_far_from_the_limit() -> None:
    """The paper's damping keeps kappa <= 73 (one stop) and <= 146 (antiperiodic) at any frequency: 68 x below."""
    omega = 2.0 * np.pi * np.linspace(1.0, 200.0, 200_001)
    poles = np.linalg.eigvals(PAPER_SYSTEM.state_matrix)
    one, two = green_condition(poles, omega).max(), green_condition(poles, omega, True).max()
    assert one < 74.0 and two < 147.0 and GREEN_CONDITION_LIMIT / two > 68.0


def test_outside_the_flagged_band_the_closed_form_matches_the_exact_engine() -> None:
    """At 1e-4 detuning (kappa = 1.6e3) the orbit is evaluated: |X1| agrees with the exact engine's steady state
    to 1e-7 (the engine's own tolerance)."""
    frequency = F0 * (1.0 - 1e-4)
    orbit = solve_impact_orbit(_problem(frequency))
    steady = steady_state("exact", _problem(frequency), "shooting", SteadySettings(tolerance=1e-10))
    assert steady.converged and steady.measures.impacts_per_period == pytest.approx(1.0)
    assert abs(orbit.harmonics()[0]) == pytest.approx(abs(steady.measures.x1), rel=1e-7)


def _dataset(tmp_path: Path) -> xr.Dataset:
    document = copy.deepcopy(base_scene())
    document["system"].update(b1=0.0, b2=0.0)
    document["sweep"] = {"frequency": [F0 * (1.0 + d) for d in DETUNINGS]}
    document["solutions"] = ["pgf"]
    out = tmp_path / "out"
    assert cli.main([str(write_yaml(tmp_path / "undamped.yaml", document)), "--out", str(out), "--jobs", "1", "--no-report"]) == 0
    return read_dataset(out / "tiny.nc").sel(solution="pgf").squeeze()


def test_a_study_flags_the_ill_conditioned_points_and_reports_only_self_consistent_stable_orbits(tmp_path: Path) -> None:
    """Regime ``failed`` with NaN values at 1e-8, 1e-9 and 0 detuning; every stable = 1 point has |X_i| <=
    sqrt(2) x_i,rms (Parseval: the fundamental cannot carry more than the whole signal)."""
    data = _dataset(tmp_path)
    flagged = np.isin(DETUNINGS, (-1e-8, -1e-9, 0.0, 1e-9))
    assert np.all(data["regime"].values[flagged] == Regime.FAILED)
    assert np.all(data["regime"].values[~flagged] == Regime.ONE_IMPACT)
    for name in ("x1_amplitude", "x2_amplitude", "x1_rms", "force_amplitude", "impulse", "one_impact_x1_amplitude"):
        assert np.all(np.isnan(data[name].values[..., flagged])), name
    assert np.all(data["stable"].values[flagged] == -1)
    stable = data["stable"].values == 1
    assert stable.sum() == 3
    for i in (1, 2):
        amplitude, rms = data[f"x{i}_amplitude"].values[stable], data[f"x{i}_rms"].values[stable]
        assert np.all(amplitude <= np.sqrt(2.0) * rms * (1.0 + 1e-9)), (amplitude, rms)
        assert np.all(amplitude < 0.01)  # mm, as both engines find (2.25 mm for x1)
