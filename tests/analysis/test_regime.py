"""The ``regime`` flag: its CF attributes, the closed-form classification, and the paper's system."""

from __future__ import annotations

import re

import numpy as np
import pytest

from vibroimpact.analysis.linear import paper_linear_response
from vibroimpact.analysis.pgf import solve_one_impact
from vibroimpact.analysis.stability import Regime, classify, regime_attributes
from vibroimpact.model.system import PAPER_SYSTEM

from tests.conftest import PAPER_AMPLITUDE, PAPER_CLEARANCE

#: CF 1.8 section 3.5: each flag meaning is one word of alphanumerics and '_', '-', '.', '+', '@'.
CF_FLAG_WORD = re.compile(r"[A-Za-z0-9_.+@-]+")


# ------------------------------------------------------------------ CF attributes


def test_every_flag_value_has_one_distinct_meaning() -> None:
    """flag_values and flag_meanings pair up one to one, in order, each meaning the enum member's lower-case name."""
    attrs = regime_attributes()
    values = attrs["flag_values"]
    meanings = attrs["flag_meanings"].split(" ")
    assert values.dtype == np.int8  # the stored variable is int8: CF wants flag_values of the variable's type
    assert len(values) == len(meanings) == len(Regime)
    assert len(set(values.tolist())) == len(values) and len(set(meanings)) == len(meanings)
    for value, meaning in zip(values.tolist(), meanings):
        assert Regime(value).name.lower() == meaning
        assert CF_FLAG_WORD.fullmatch(meaning), meaning
    assert attrs["units"] == "1" and attrs["long_name"]


def test_flag_values_cover_every_regime_a_study_writes() -> None:
    """Every member is listed (NOT_COMPUTED = -1 included) and fits the int8 the studies store."""
    values = regime_attributes()["flag_values"].tolist()
    assert sorted(values) == sorted(int(r) for r in Regime)
    assert min(values) >= np.iinfo(np.int8).min and max(values) <= np.iinfo(np.int8).max
    assert Regime.NOT_COMPUTED == -1 and Regime.LINEAR == 0  # exact: integer codes written to every dataset


# ------------------------------------------------------------------ classify: the truth table

#: (linear fits, one-impact solution exists, it is admissible) -> regime. "Admissible" means nothing without a solution.
TRUTH_TABLE = [
    (True, False, False, Regime.LINEAR),
    (True, False, True, Regime.LINEAR),
    (True, True, True, Regime.ONE_IMPACT_COEXISTING_LINEAR),
    (True, True, False, Regime.LINEAR_WITH_INADMISSIBLE_ONE_IMPACT),
    (False, True, True, Regime.ONE_IMPACT),
    (False, True, False, Regime.NONE_INADMISSIBLE_ONE_IMPACT),
    (False, False, False, Regime.NONE),
    (False, False, True, Regime.NONE),
]


@pytest.mark.parametrize(("fits", "exists", "admissible", "expected"), TRUTH_TABLE)
def test_classify_each_combination(fits: bool, exists: bool, admissible: bool, expected: Regime) -> None:
    flag = classify(fits, exists, admissible)
    assert flag.dtype == np.int8 and flag.shape == ()
    assert Regime(int(flag)) is expected


def test_classify_gives_six_regimes_and_only_those() -> None:
    """All eight combinations at once: the six closed-form regimes, each where the table says."""
    fits, exists, admissible, expected = (np.array(column) for column in zip(*TRUTH_TABLE))
    flags = classify(fits, exists, admissible)
    np.testing.assert_array_equal(flags, expected.astype(np.int8))
    closed_form = {Regime.LINEAR, Regime.ONE_IMPACT, Regime.ONE_IMPACT_COEXISTING_LINEAR, Regime.LINEAR_WITH_INADMISSIBLE_ONE_IMPACT, Regime.NONE_INADMISSIBLE_ONE_IMPACT, Regime.NONE}
    assert {Regime(int(f)) for f in flags} == closed_form


def test_classify_broadcasts_its_inputs() -> None:
    """A scalar 'linear fits' against a grid of solutions, e.g. one frequency and several restitutions."""
    exists = np.array([[True, True], [False, True]])
    admissible = np.array([[True, False], [True, True]])
    np.testing.assert_array_equal(
        classify(False, exists, admissible),
        [[Regime.ONE_IMPACT, Regime.NONE_INADMISSIBLE_ONE_IMPACT], [Regime.NONE, Regime.ONE_IMPACT]],
    )
    np.testing.assert_array_equal(classify(np.array([True, False])[:, None], True, np.array([True, False])), [[2, 3], [1, 4]])


# ------------------------------------------------------------------ the paper's system: PGF and linear computed

#: Where q |H12| = Delta for the paper's system, q = 10 N, Delta = 3 mm (the linear motion fits strictly between) [Hz].
FITS_FROM, FITS_TO = 26.0265, 33.9722


def paper_regimes(frequency: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Regime flags of the paper's system at R = 0.2 from the exact PGF solution, and whether the linear motion fits."""
    omega = 2.0 * np.pi * np.asarray(frequency, dtype=float)
    solution = solve_one_impact(PAPER_SYSTEM, omega=omega, clearance=PAPER_CLEARANCE, restitution=0.2, amplitude=PAPER_AMPLITUDE)
    fits = PAPER_AMPLITUDE * np.abs(paper_linear_response(PAPER_SYSTEM, omega=omega, amplitude=1.0).x2) <= PAPER_CLEARANCE
    return classify(fits, solution.exists, solution.admissible()), fits


def test_paper_linear_motion_fits_only_around_the_anti_resonance() -> None:
    """q |H12| <= Delta between 26.03 and 33.97 Hz (around the absorber's anti-resonance) and nowhere near outside."""
    frequency = np.array([25.9, 26.0, 26.05, 30.0, 33.95, 34.0, 34.1])
    _flags, fits = paper_regimes(frequency)
    np.testing.assert_array_equal(fits, (frequency > FITS_FROM) & (frequency < FITS_TO))


@pytest.mark.parametrize(
    ("frequency", "expected"),
    [
        (25.0, Regime.ONE_IMPACT),  # the linear motion would cross the stop; the impacting orbit is admissible
        (22.0, Regime.ONE_IMPACT),
        (30.0, Regime.LINEAR),  # the anti-resonance: the absorber moves least, no one-impact orbit exists
        (33.0, Regime.LINEAR),
        (38.0, Regime.ONE_IMPACT_COEXISTING_LINEAR),  # above the band: both fit (the study then checks stability)
        (18.5, Regime.LINEAR_WITH_INADMISSIBLE_ONE_IMPACT),  # a root of eqs. 15-16 whose X2(t) passes the stop
        (45.0, Regime.LINEAR),
    ],
)
def test_paper_regimes(frequency: float, expected: Regime) -> None:
    flags, _fits = paper_regimes(np.array([frequency]))
    assert Regime(int(flags[0])) is expected


def test_paper_impact_free_band_is_linear_throughout() -> None:
    """Inside 27-33.5 Hz every point is linear; from 21 to 26 Hz every point is one-impact (the linear motion crosses)."""
    flags, _fits = paper_regimes(np.arange(27.0, 33.51, 0.25))
    assert bool(np.all(flags == Regime.LINEAR))
    flags, _fits = paper_regimes(np.arange(21.0, 26.01, 0.25))
    assert bool(np.all(flags == Regime.ONE_IMPACT))


def test_the_kinds_of_non_periodic_motion_are_appended_without_renumbering() -> None:
    """Datasets written before keep their meaning: irregular stays 9, failed 11; the kinds added later are appended:
    quasi-periodic 12, chaotic 13, held on the stop 14."""
    assert (Regime.IRREGULAR, Regime.FAILED, Regime.QUASI_PERIODIC, Regime.CHAOTIC, Regime.HELD_ON_STOP) == (9, 11, 12, 13, 14)
    meanings = regime_attributes()["flag_meanings"].split(" ")
    assert meanings[-3:] == ["quasi_periodic", "chaotic", "held_on_stop"]
