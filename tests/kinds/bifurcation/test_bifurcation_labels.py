"""A bifurcation study numbers its branches one way everywhere: the dataset, the special points' table, the
continuation log (console and page) and the chart's log."""

from __future__ import annotations

import re

import numpy as np
import xarray as xr

from tests.golden.golden import DATA
from vibroimpact.kinds.bifurcation.branches import ORIGINS, OrbitSet
from vibroimpact.kinds.bifurcation.cases import branch_arrays
from vibroimpact.kinds.bifurcation.logs import chart_labels, continuation_log, numbered_across, relabel
from vibroimpact.kinds.bifurcation.study import _branches

#: "R = 0.8: branch 5 (one_impact): 103 points, 24.0000-27.8597 Hz" of a continuation log.
LINE = re.compile(r"^(?:R = (?P<r>[\d.]+): )?branch (?P<label>\d+) \((?P<origin>\w+)\): (?P<n>\d+) points, (?P<low>[\d.]+)-(?P<high>[\d.]+) Hz")


def _orbit_set(branches: list[tuple[str, list[float]]], special: list[tuple[int, float]]) -> OrbitSet:
    """An OrbitSet of hand-made branches (origin, frequencies [Hz]) and special points (branch, frequency [Hz]) of a
    two-coordinate structure, with the notes :meth:`OrbitSet.add_branch` writes."""
    found = OrbitSet()
    for label, (origin, frequency) in enumerate(branches):
        for f in frequency:
            found.points.append({"branch": label, "origin": ORIGINS.index(origin), "frequency": f, "amplitudes": np.array([1e-3, 2e-3]), "impulse": 0.01,
                                 "floquet_modulus": 0.5, "stable": 1, "impacts": 1, "period": 1, "multipliers": np.full(4, 0.5 + 0j), "velocities": np.array([0.1])})  # fmt: skip
        found.notes.append(f"branch {label} ({origin}): {len(frequency)} points, {min(frequency):.4f}-{max(frequency):.4f} Hz, ends: grazing, grazing")
        found.count += 1
    for label, f in special:
        found.add_special({"branch": label, "kind": 0, "frequency": f, "amplitudes": np.array([1e-3, 2e-3]) * f, "impulse": 0.01, "floquet_modulus": 1.0,
                           "impacts": 1, "period": 1, "multipliers": np.full(4, 1.0 + 0j), "velocities": np.array([0.1]), "note": "the branch turns back"})  # fmt: skip
    found.notes.append("branch 1 born at the grazing point; period-2 branch at 26.584 Hz failed: ShootingError")
    return found


def _described(log: str) -> list[tuple[float, int, str, int, float, float]]:
    return [(float(m["r"]), int(m["label"]), m["origin"], int(m["n"]), float(m["low"]), float(m["high"])) for m in map(LINE.match, log.splitlines()) if m]


def test_every_restitution_s_branches_are_numbered_as_the_dataset_numbers_them() -> None:
    """Two restitutions (the second's labels follow the first's): the log's lines, the points and the special points
    (their branch and every branch they were found on) all say the same label for the same branch."""
    first = _orbit_set([("linear", [26.0, 27.0, 28.0]), ("one_impact", [24.0, 25.0, 26.0])], [(1, 25.5)])
    second = _orbit_set([("linear", [26.0, 28.0]), ("one_impact", [24.0, 26.0, 27.0, 27.5]), ("grazing", [26.5, 27.0])], [(1, 27.2), (2, 27.2)])
    results = numbered_across([branch_arrays(first, 2), branch_arrays(second, 2)])
    dataset = _branches(results, (0.2, 0.8), ("x1", "x2"), False)
    log = continuation_log((0.2, 0.8), results)
    lines = _described(log)
    assert [line[:3] for line in lines] == [(0.2, 0, "linear"), (0.2, 1, "one_impact"), (0.8, 2, "linear"), (0.8, 3, "one_impact"), (0.8, 4, "grazing")]
    for r, label, origin, n, low, high in lines:
        points = dataset.isel(branch_point=np.flatnonzero(dataset["branch"].values == label))
        assert np.allclose(points["branch_restitution"].values, r) and points.sizes["branch_point"] == n
        assert {ORIGINS[int(o)] for o in points["branch_origin"].values} == {origin}
        assert abs(float(points["branch_frequency"].min()) - low) < 1e-4 and abs(float(points["branch_frequency"].max()) - high) < 1e-4
    # the other notes' labels move too ("branch 1 born ..." of R = 0.8 is the dataset's branch 3); "branch at" does not
    assert "R = 0.8: branch 3 born at the grazing point; period-2 branch at 26.584 Hz failed" in log
    assert list(dataset["special_point_branch"].values) == [1, 3]
    assert list(dataset["special_point_branches"].values) == ["1", "3 4"]


def test_the_chart_s_branches_take_the_dataset_s_labels() -> None:
    """The chart's own continuation (no linear branches: its labels start lower) names each branch as the dataset
    does: same origin, the same stretch of frequency; a branch the diagrams lack says so."""
    diagrams = numbered_across([branch_arrays(_orbit_set([("linear", [26.0, 28.0]), ("one_impact", [20.6, 26.7]), ("one_impact", [34.0, 40.0])], []), 2)])[0]
    chart = {"branch_label": np.array([0, 1, 2]), "branch_origin": np.array([1, 1, 2]), "branch_low": np.array([20.62, 33.99, 26.58]), "branch_high": np.array([26.70, 40.0, 27.05])}
    labels = chart_labels(chart, diagrams)
    assert labels == {0: "1", 1: "2", 2: "2 of the chart's own continuation"}
    assert relabel("branch 0 (one_impact): 94 points; branch 2 (period_doubling)", labels) == "branch 1 (one_impact): 94 points; branch 2 of the chart's own continuation (period_doubling)"


def test_the_golden_scenes_logs_describe_the_dataset_s_branches() -> None:
    """In the golden bifurcation datasets every "branch k (origin): n points, a-b Hz" line of the continuation log is
    the dataset's branch k, and of the chart's log a branch k of the same origin over an overlapping stretch."""
    for name in ("bifurcation", "bifurcation_relative_stop"):
        dataset = xr.load_dataset(DATA / f"{name}.nc")
        origins = dataset["branch_origin"].attrs["flag_meanings"].split()
        for r, label, origin, n, low, high in _described(dataset.attrs["continuation_notes"]):
            mask = dataset["branch"].values == label
            assert np.allclose(dataset["branch_restitution"].values[mask], r) and np.count_nonzero(mask) == n, (name, label)
            assert {origins[int(o)] for o in dataset["branch_origin"].values[mask]} == {origin}
        chart = [m for m in map(LINE.match, dataset.attrs["chart_notes"].splitlines()) if m]
        assert chart
        for m in chart:
            mask = dataset["branch"].values == int(m["label"])
            f = dataset["branch_frequency"].values[mask]
            assert {origins[int(o)] for o in dataset["branch_origin"].values[mask]} == {m["origin"]}, (name, m[0])
            assert f.min() < float(m["high"]) and float(m["low"]) < f.max()
