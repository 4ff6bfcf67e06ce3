"""The bifurcation page renders every figure and the special points' table."""

from __future__ import annotations

from pathlib import Path

import pytest
import xarray as xr

from vibroimpact.kinds.bifurcation.page import BifurcationPage
from vibroimpact.reporting.page import page_for, write_report


@pytest.fixture
def dataset(small_bifurcation: xr.Dataset) -> xr.Dataset:
    return small_bifurcation


def test_the_report_has_every_figure(dataset: xr.Dataset, tmp_path: Path) -> None:
    assert isinstance(page_for(dataset), BifurcationPage)
    html = write_report(dataset, tmp_path).read_text(encoding="utf-8")
    names = {p.stem for p in tmp_path.glob("*.png")}
    assert names == {"bifurcation_R0", "multipliers_R0", "chart"}
    assert html.count("<figure") == 3 and "Special points" in html and "neimark-sacker" in html
    assert "Two-parameter chart" in html and "brute-force" in html


def test_the_page_opens_with_its_answer(dataset: xr.Dataset) -> None:
    """The headline and the answer say what the dataset holds: the largest |X1| the brute force settles on, where it
    settles on no periodic motion, where the closed-form orbit is stable, how many special points of each kind."""
    import numpy as np

    from vibroimpact.kinds.bifurcation.page import answer_text, headline

    amplitude = np.nanmax(dataset["brute_x1_amplitude"].values[0], axis=-1)  # (sweep, frequency)
    sweep, k = np.unravel_index(int(np.nanargmax(amplitude)), amplitude.shape)
    regime = dataset["brute_regime"].values[0]
    wild = int(np.isin(regime, (3, 4, 5)).any(axis=0).sum())
    top = f"|X1| = {amplitude[sweep, k] * 1e3:.3g} mm (at {dataset['frequency'].values[k]:.2f} Hz)"
    assert headline(dataset) == f"R = 0.8: up to {top}, no periodic motion at {wild} of {dataset.sizes['frequency']} frequencies"
    text = answer_text(dataset)
    counts = np.bincount(dataset["special_point_kind"].values, minlength=4)
    assert f"special points: {counts[0]} fold, {counts[1]} period-doubling, {counts[2]} neimark-sacker, {counts[3]} grazing." in text
    # R = 0.8: the one-impact orbit is stable from its Neimark-Sacker point (23.39 Hz) up
    one = dataset.where((dataset["branch_origin"] == 1) & (dataset["stable"] == 1), drop=True)
    assert f"the closed-form orbit is stable over {one['branch_frequency'].values.min():.2f}-" in text
    assert abs(float(one["branch_frequency"].min()) - 23.386) < 0.01
