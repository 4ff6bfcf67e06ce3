"""The bifurcation page renders every figure and the special points' table."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from vibroimpact.kinds.bifurcation.page import BifurcationPage
from vibroimpact.reporting.page import page_for, write_report

pytestmark = pytest.mark.slow  # a whole study per module: the slow tier (issue 49, measured)


@pytest.fixture
def dataset(small_bifurcation: xr.Dataset) -> xr.Dataset:
    return small_bifurcation


def test_the_report_has_every_figure(dataset: xr.Dataset, tmp_path: Path) -> None:
    assert isinstance(page_for(dataset), BifurcationPage)
    html = write_report(dataset, tmp_path).read_text(encoding="utf-8")
    names = {p.stem for p in tmp_path.glob("*.png")}
    assert names == {"bifurcation_R0", "multipliers_R0", "chart"}
    assert html.count("<figure") == 3 and "Special points" in html and "Neimark-Sacker" in html
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
    assert f"special points: {counts[0]} fold, {counts[1]} period doubling, {counts[2]} Neimark-Sacker, {counts[3]} grazing." in text
    # R = 0.8: the one-impact orbit exists from the band's start, is stable from its Neimark-Sacker point (23.39 Hz) up
    one = dataset.where(dataset["branch_origin"] == 1, drop=True)
    stable = one.where(one["stable"] == 1, drop=True)
    torus = dataset["special_point_frequency"].values[dataset["special_point_kind"].values == 2]
    lost = torus[np.argmin(np.abs(torus - 23.386))]  # the Neimark-Sacker point where it gains stability
    assert abs(lost - 23.386) < 0.01 and 0.0 <= float(stable["branch_frequency"].min()) - lost < 0.05  # the next point
    assert (f"the closed-form orbit (1 impact per period) exists over {one['branch_frequency'].values.min():.2f}-" in text
            and f"is stable over {stable['branch_frequency'].values.min():.2f}-" in text and "Neimark-Sacker at 23.39" in text)  # fmt: skip


def test_the_answer_lists_every_kind_of_orbit(dataset: xr.Dataset) -> None:
    """The table after the answer has a row per class of continued branch, with its branches and where it exists."""
    from vibroimpact.kinds.bifurcation.figures import branch_class, orbit_label
    from vibroimpact.kinds.bifurcation.page import orbit_rows

    classes: dict[tuple[int, int], list[int]] = {}
    for label in np.unique(dataset["branch"].values):
        branch = dataset.isel(branch_point=np.flatnonzero(dataset["branch"].values == label))
        classes.setdefault(branch_class(branch["impacts_per_period"].values, branch["period_multiplicity"].values), []).append(int(label))
        f = branch["branch_frequency"].values
        row = next(r for r in orbit_rows(dataset, 0.8) if int(label) in r["branches"])
        assert any(a <= f.min() + 1e-9 and f.max() <= b + 1e-9 for a, b in row["exists"])  # where the branch exists
    rows = orbit_rows(dataset, 0.8)
    assert {r["key"]: r["branches"] for r in rows} == classes and [r["name"] for r in rows] == [orbit_label(k) for k in sorted(classes, key=lambda k: (k[1], k[0]))]


def test_every_kind_of_orbit_has_its_own_look(dataset: xr.Dataset) -> None:
    """Within a restitution no two classes of orbit are drawn alike (colour and marker), none in the brute-force
    dots' colours; the linear orbit is black."""
    from vibroimpact.kinds.bifurcation.figures import orbit_looks
    from vibroimpact.reporting.style import SWEEP_COLOURS

    impacts, period = np.array([0, 1, 2, 1, 2, 1, 3, 3, 2, 3, 4, 7, 13, 12]), np.array([1, 1, 1, 2, 2, 3, 3, 5, 6, 7, 7, 10, 17, 13])
    labels = np.repeat(np.arange(impacts.size), 2)  # 14 branches of two points: the linear orbit and 13 classes, as the shipped study has
    zeros = np.zeros(labels.size)
    many = xr.Dataset(
        {name: ("branch_point", zeros) for name in ("x1_amplitude", "floquet_modulus", "stable")}
        | {"impacts_per_period": ("branch_point", impacts[labels] / period[labels]), "period_multiplicity": ("branch_point", period[labels]),
           "impact_velocity": (("branch_point", "orbit_impact"), zeros[:, None])},
        coords={"branch": ("branch_point", labels), "branch_restitution": ("branch_point", np.full(labels.size, 0.8))},
    )  # fmt: skip
    for data in (dataset, many):
        looks = orbit_looks(data, 0.8)
        drawn = [(look["color"], look.get("marker", "")) for key, look in looks.items() if key[0]]
        assert len(set(drawn)) == len(drawn) and not {c for c, _ in drawn} & set(SWEEP_COLOURS.values())
        assert all(look["color"] == "k" for key, look in looks.items() if not key[0])
    assert len(orbit_looks(many, 0.8)) == 14


def test_the_orbits_table_takes_its_own_restitution_s_special_points(dataset: xr.Dataset) -> None:
    """Branch labels run across restitutions: a row of R = 0.8 lists the special points of R = 0.8 only (half the
    points moved to another R must leave it)."""
    from vibroimpact.kinds.bifurcation.page import orbit_rows

    n = dataset.sizes["special_point"]
    moved = dataset.assign_coords(special_point_restitution=("special_point", np.where(np.arange(n) % 2 == 1, 0.5, 0.8)))
    listed = sorted(f for row in orbit_rows(moved, 0.8) for values in row["special"].values() for f in values)
    kept = moved["special_point_frequency"].values[np.arange(n) % 2 == 0]
    assert n > 2 and np.allclose(listed, np.sort(kept))


def _bumper_dataset() -> xr.Dataset:
    """Branch and special points of the rigid stop and of bumpers of 250, 1000 and 4000 Hz (one-impact branches, as
    the bumper study measured them): a fold moving as 1/Omega_b, a grazing point shared by all."""
    from vibroimpact.kinds.bifurcation.branches import ORIGINS
    from vibroimpact.orbits.branch import SPECIAL_POINT_KINDS
    from vibroimpact.scene.variables import flag_attributes

    bumpers = np.array([np.inf, 250.0, 1000.0, 4000.0])
    fold = 26.7027 - np.array([0.0, 0.2722, 0.0751, 0.0193])
    return xr.Dataset(
        {"branch_origin": ("branch_point", np.ones(4, dtype=np.int8), flag_attributes("how", ORIGINS)),
         "special_point_period_multiplicity": ("special_point", np.ones(8, dtype=np.int16))},
        coords={
            "branch": ("branch_point", np.arange(4)), "branch_bumper_frequency": ("branch_point", bumpers),
            "special_point_kind": ("special_point", np.array([0, 3] * 4, dtype=np.int8), flag_attributes("kind", SPECIAL_POINT_KINDS)),
            "special_point_frequency": ("special_point", np.ravel([[f, 20.617667574] for f in fold])),
            "special_point_restitution": ("special_point", np.full(8, 0.2)), "special_point_branch": ("special_point", np.repeat(np.arange(4), 2)),
            "special_point_bumper_frequency": ("special_point", np.repeat(bumpers, 2)), "restitution": [0.2],
        },
    )  # fmt: skip


def test_the_bumpers_special_points_are_matched_to_the_rigid_stops_with_their_observed_order() -> None:
    """Each rigid special point against the same kind at each bumper: differences and p = ln(e_a / e_b) / ln(fb / fa);
    a point shared by every bumper is the same point (no order), and the rest of the page sees the rigid stop's only."""
    from vibroimpact.kinds.bifurcation.bumper import bumper_answer, convergence_rows, rigid_view

    data = _bumper_dataset()
    rows = {row["kind"]: row for row in convergence_rows(data, 0.2)}
    np.testing.assert_allclose(rows["fold"]["errors"], [-0.2722, -0.0751, -0.0193], rtol=1e-9)
    expected = [np.log(0.2722 / 0.0751) / np.log(4.0), np.log(0.0751 / 0.0193) / np.log(4.0)]
    np.testing.assert_allclose(rows["fold"]["orders"], expected, rtol=1e-12)
    assert rows["grazing"]["same"] and all(np.isnan(rows["grazing"]["orders"]))
    answer = bumper_answer(data)
    assert "between the 1000 Hz and 4000 Hz bumpers their observed order of convergence in 1/Omega_b is 0.98 (fold 0.98; 1 is first order)" in answer
    assert "moves them by up to 0.272 Hz (the fold at 26.703 Hz)" in answer and "contact onsets at tangency at 20.618 Hz" in answer
    rigid = rigid_view(data)
    assert rigid.sizes["special_point"] == 2 and "branch_bumper_frequency" not in rigid.coords


def _crowded_dataset(curves: bool) -> xr.Dataset:
    """Two Neimark-Sacker points of the rigid stop 0.54 Hz apart whose bumper counterparts move by up to 1.3 Hz (the
    38-40 Hz crowd of the shipped study), and a small branch whose two folds meet at a cusp at a 839 Hz bumper (found at
    4 kHz only); with ``curves``, each followed in the bumper's stiffness (straight lines in T_b, as first order makes
    them, the fold pair one curve that turns back at T_b = 1/839 s)."""
    from vibroimpact.kinds.bifurcation.branches import ORIGINS
    from vibroimpact.orbits.branch import SPECIAL_POINT_KINDS
    from vibroimpact.scene.variables import flag_attributes

    ns = [(39.0256, -325.3), (39.5635, -292.3)]  # (rigid [Hz], slope [Hz s-1] in T_b)
    cusp = 1.0 / 839.0
    folds = [(18.2519, (18.40 - 18.2519) / cusp), (18.7126, (18.40 - 18.7126) / cusp)]
    bumpers = [250.0, 1000.0, 4000.0]
    kinds, frequencies, owners = [], [], []
    for fb in (np.inf, *bumpers):
        t = 0.0 if np.isinf(fb) else 1.0 / fb
        for f0, slope in ns:
            kinds, frequencies, owners = kinds + [2], frequencies + [f0 + slope * t], owners + [fb]
        if t <= 1.0 / 4000.0:  # the small branch: started at the rigid stop and at 4 kHz only
            for f0, slope in folds:
                kinds, frequencies, owners = kinds + [0], frequencies + [f0 + slope * t], owners + [fb]
    n = len(kinds)
    coords = {
        "branch": ("branch_point", np.arange(4)), "branch_bumper_frequency": ("branch_point", np.array([np.inf, *bumpers])),
        "special_point_kind": ("special_point", np.array(kinds, dtype=np.int8), flag_attributes("kind", SPECIAL_POINT_KINDS)),
        "special_point_frequency": ("special_point", np.array(frequencies)), "special_point_restitution": ("special_point", np.full(n, 0.2)),
        "special_point_branch": ("special_point", np.zeros(n, dtype=int)), "special_point_bumper_frequency": ("special_point", np.array(owners)), "restitution": [0.2],
    }  # fmt: skip
    if curves:
        t = np.linspace(1.0 / 64000.0, 1.0 / 200.0, 40)
        near = np.linspace(1.0 / 64000.0, cusp, 30)
        rows = [(0, 2, f0 + s * t, t) for f0, s in ns[:1]] + [(1, 2, f0 + s * t, t) for f0, s in ns[1:]]
        rows.append((2, 0, np.concatenate([folds[0][0] + folds[0][1] * near, (folds[1][0] + folds[1][1] * near)[::-1][1:]]), np.concatenate([near, near[::-1][1:]])))
        coords |= {
            "stiffness_curve": ("stiffness_point", np.concatenate([np.full(r[3].size, r[0]) for r in rows]).astype(np.int32)),
            "stiffness_kind": ("stiffness_point", np.concatenate([np.full(r[3].size, r[1]) for r in rows]).astype(np.int8), flag_attributes("kind", SPECIAL_POINT_KINDS)),
            "stiffness_restitution": ("stiffness_point", np.full(sum(r[3].size for r in rows), 0.2)),
            "stiffness_frequency": ("stiffness_point", np.concatenate([r[2] for r in rows])),
            "stiffness_bumper_frequency": ("stiffness_point", 1.0 / np.concatenate([r[3] for r in rows])),
        }  # fmt: skip
    return xr.Dataset({"branch_origin": ("branch_point", np.ones(4, dtype=np.int8), flag_attributes("how", ORIGINS)),
                       "special_point_period_multiplicity": ("special_point", np.ones(n, dtype=np.int16))}, coords=coords)  # fmt: skip


def test_curves_in_the_bumpers_stiffness_match_crowded_points_and_say_where_a_branch_ends() -> None:
    """By distance, the 1 kHz counterparts of two Neimark-Sacker points 0.54 Hz apart are ambiguous (each chain's two
    candidates are about equally near); along their curves in the stiffness each is the other's neighbour's, order 1.
    A fold pair whose curve turns back at 839 Hz: at 1 kHz the curve gives the points (no branch was started there),
    at 250 Hz there are none, and the page says so."""
    from vibroimpact.kinds.bifurcation.bumper import bumper_answer, convergence_rows, convergence_table
    from vibroimpact.kinds.bifurcation.stiffness import monotone_pieces

    by_distance = {round(row["rigid"], 4): row for row in convergence_rows(_crowded_dataset(False), 0.2)}
    assert by_distance[39.0256]["ambiguous"][1] and not np.isfinite(by_distance[39.0256]["bumpers"][1])
    rows = {round(row["rigid"], 4): row for row in convergence_rows(_crowded_dataset(True), 0.2)}
    for f0, slope in ((39.0256, -325.3), (39.5635, -292.3)):
        row = rows[f0]
        np.testing.assert_allclose(row["bumpers"], [f0 + slope / fb for fb in (250.0, 1000.0, 4000.0)], rtol=0, atol=1e-9)
        assert row["followed"] and not any(row["continued"]) and np.allclose(row["orders"], 1.0, atol=1e-6)
    for f0 in (18.2519, 18.7126):
        row = rows[f0]
        assert row["followed"] and row["continued"] == [False, True, False] and np.isnan(row["bumpers"][0])
        assert row["ends"] == pytest.approx(839.0, rel=1e-9)
    table = convergence_table(_crowded_dataset(True)).html
    assert table.count("none: its curve ends at 839 Hz") == 2 and table.count("by the continuation alone") == 2 and "ambiguous" not in table
    answer = bumper_answer(_crowded_dataset(True))
    assert "the fold at 18.252 Hz has no counterpart below 839 Hz, where its curve in the bumper's stiffness ends" in answer
    assert "2 of the table's points are found by the continuation in the stiffness alone" in answer
    pieces = monotone_pieces(np.array([1.0, 2.0, 3.0, 2.5, 1.5]), np.array([10.0, 11.0, 12.0, 13.0, 14.0]))
    assert [p[0].tolist() for p in pieces] == [[1.0, 2.0, 3.0], [1.5, 2.5, 3.0]] and pieces[1][1].tolist() == [14.0, 13.0, 12.0]
