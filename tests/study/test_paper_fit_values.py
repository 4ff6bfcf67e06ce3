"""``pgf_paper`` in a study: the values function of ``pgf`` with the paper's fitted Green function (PaperFit)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from vibroimpact.analysis.pgf import solve_one_impact
from vibroimpact.analysis.stability import Regime
from vibroimpact.grids.grid import StudyGrid
from vibroimpact.grids.closed_forms import general_pgf_values
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.runs.run import run_study
from vibroimpact.scene import parse_scene

DOCUMENT: dict[str, Any] = {
    "name": "paper_fit",
    "system": {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0, "b1": 0.8, "b2": 0.08},
    "excitation": {"amplitude": 10.0},
    "stop": {"clearance": 0.003, "restitution": 0.2},
    "sweep": {"frequency": {"start": 20.0, "stop": 40.0, "step": 0.25}},
    "solutions": ["pgf", "pgf_paper"],
    "report": False,
}


def test_pgf_paper_values_are_the_paper_s_orbit_without_floquet_analysis() -> None:
    """Where ``pgf_paper`` reports a one-impact orbit its |X1|, |X2| and impulse are those of
    ``solve_one_impact(..., variant='pgf_paper')`` (to 1e-12), it has no Floquet analysis (modulus NaN, stable -1,
    so no point is ``linear_with_unstable_one_impact``), and it differs from ``pgf`` somewhere (it is not the exact
    route under another name)."""
    dataset = run_study(parse_scene(DOCUMENT), progress=None)
    paper = dataset.sel(solution="pgf_paper")
    frequency = paper["frequency"].values
    orbit = solve_one_impact(PAPER_SYSTEM, frequency, 0.003, 0.2, 10.0, variant="pgf_paper")
    impact = np.isin(paper["regime"].values, [Regime.ONE_IMPACT, Regime.ONE_IMPACT_COEXISTING_LINEAR])
    assert impact.sum() > 20
    harmonics = np.abs(orbit.harmonics())
    np.testing.assert_allclose(paper["x1_amplitude"].values[impact], harmonics[impact, 0], rtol=1e-12)
    np.testing.assert_allclose(paper["x2_amplitude"].values[impact], harmonics[impact, 1], rtol=1e-12)
    np.testing.assert_allclose(paper["impulse"].values[impact], orbit.impulse[impact], rtol=1e-12)
    assert np.isnan(paper["floquet_modulus"].values).all() and (paper["stable"].values == -1).all()
    assert not (paper["regime"].values == Regime.LINEAR_WITH_UNSTABLE_ONE_IMPACT).any()
    exact = dataset.sel(solution="pgf")
    assert (exact["regime"].values == Regime.LINEAR_WITH_UNSTABLE_ONE_IMPACT).any() or np.isfinite(exact["floquet_modulus"].values).any()
    both = impact & np.isin(exact["regime"].values, [Regime.ONE_IMPACT, Regime.ONE_IMPACT_COEXISTING_LINEAR])
    assert np.max(np.abs(paper["impulse"].values[both] / exact["impulse"].values[both] - 1.0)) > 1e-3


def test_the_values_function_names_its_closed_forms() -> None:
    scene = parse_scene(DOCUMENT)
    grid = StudyGrid.of(scene)
    with pytest.raises(ValueError, match="'pgf' and 'pgf_paper'"):
        general_pgf_values(scene, grid.omega, grid.delta, grid.r, grid.base, "pgf_exact")
