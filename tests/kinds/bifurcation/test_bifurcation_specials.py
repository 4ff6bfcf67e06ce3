"""A bifurcation study lists each special point once, with every branch it was found on."""

from __future__ import annotations

import itertools

import numpy as np
import xarray as xr

from tests.golden.golden import DATA
from vibroimpact.kinds.bifurcation.branches import SAME_POINT_FREQUENCY, SAME_POINT_ORBIT, OrbitSet, same_special_point


def _points(dataset: xr.Dataset) -> list[dict]:
    """The special points of a dataset as records of :meth:`OrbitSet.add_special` (the first coordinate's amplitude)."""
    return [
        {"kind": int(k), "restitution": float(r), "frequency": float(f), "amplitudes": np.array([float(a)]), "branch": int(b)}
        for k, r, f, a, b in zip(*(dataset[name].values for name in ("special_point_kind", "special_point_restitution", "special_point_frequency", "special_point_x1_amplitude", "special_point_branch")))
    ]  # fmt: skip


def test_no_two_special_points_of_the_golden_scene_coincide() -> None:
    """Same kind and R, frequencies within the tolerance: none in the golden bifurcation scenes (the shipped study had
    each of four folds six times, and the golden scene two grazing points twice)."""
    for name in ("bifurcation", "bifurcation_relative_stop"):
        dataset = xr.load_dataset(DATA / f"{name}.nc")
        points = _points(dataset)
        for a, b in itertools.combinations(points, 2):
            if a["kind"] == b["kind"] and a["restitution"] == b["restitution"]:
                assert abs(a["frequency"] - b["frequency"]) > SAME_POINT_FREQUENCY * a["frequency"], (name, a, b)
        found_on = [str(labels).split() for labels in dataset["special_point_branches"].values]
        assert all(labels[0] == str(p["branch"]) for labels, p in zip(found_on, points))
    # the golden scene's grazing points at 26.03 Hz (one-impact branch 3 and the branch born at 27.05 Hz, 7), at
    # 27.05 Hz (the period-two branch 6, where branch 7 is born) and at 33.97 Hz (one-impact branch 4 and the period-7
    # branch 8), and where the seeded branches' grazing points give birth (34.47, 38.49, 38.99 Hz: seeded 10, 9, 11 and
    # born 14, 13, 15; 34.32 Hz: born 14 and the branch born from it, 16): each once, with both branches
    dataset = xr.load_dataset(DATA / "bifurcation.nc")
    twice = {round(float(f), 2): str(b) for f, b in zip(dataset["special_point_frequency"].values, dataset["special_point_branches"].values) if " " in str(b)}
    assert twice == {26.03: "3 7", 27.05: "6 7", 33.97: "4 8", 34.32: "14 16", 34.47: "10 14", 38.49: "9 13", 38.99: "11 15"}


def test_every_distinct_special_point_is_kept_once() -> None:
    """The golden scene's points, each found again from another branch as the continuation finds a point twice (to
    3.5e-12 in frequency, 4.5e-6 in amplitude), plus points just outside the tolerances and one of another kind at the
    same place: every distinct point is kept, once, with both branches; no distinct point is merged away."""
    distinct = [p for p in _points(xr.load_dataset(DATA / "bifurcation.nc"))]
    again = [p | {"frequency": p["frequency"] * (1 + 3.5e-12), "amplitudes": p["amplitudes"] * (1 + 4.5e-6), "branch": p["branch"] + 100} for p in distinct]
    base = distinct[0]
    apart = [
        base | {"frequency": base["frequency"] * (1 + 5 * SAME_POINT_FREQUENCY), "branch": 200},  # too far in frequency
        base | {"amplitudes": base["amplitudes"] * (1 + 5 * SAME_POINT_ORBIT), "branch": 201},  # another orbit at the same frequency
        base | {"kind": (base["kind"] + 1) % 4, "branch": 202},  # another kind at the same place
    ]
    found = OrbitSet()
    for record in [*distinct, *again, *apart]:
        found.add_special(record)
    assert len(found.specials) == len(distinct) + len(apart)
    for point in [*distinct, *apart]:
        kept = [s for s in found.specials if same_special_point(s, point)]
        assert len(kept) == 1 and kept[0]["branch"] == point["branch"]
    assert [s["found_on"] for s in found.specials[: len(distinct)]] == [[p["branch"], p["branch"] + 100] for p in distinct]
    assert [s["found_on"] for s in found.specials[len(distinct) :]] == [[200], [201], [202]]
