"""Lengths are written in a unit chosen from their magnitude, and a stop's description reads back in any of them."""

from __future__ import annotations

import pytest

from vibroimpact.model.layout import _described_clearance
from vibroimpact.model.units import length_text, length_unit


@pytest.mark.parametrize(("metres", "text"), [(1.0, "1 m"), (2.5, "2.5 m"), (3e-3, "3 mm"), (5e-4, "0.5 mm"), (5e-5, "50 µm"), (-3e-3, "-3 mm")])
def test_a_length_is_written_in_the_unit_of_its_magnitude(metres: float, text: str) -> None:
    assert length_text(metres) == text


def test_a_length_can_take_the_unit_of_another_magnitude() -> None:
    """The chart's clearances are written in the unit of the diagrams' clearance."""
    assert length_text(0.0005, ".4g", magnitude=0.003) == "0.5 mm" and length_unit(1.0) == ("m", 1.0)


@pytest.mark.parametrize("words", ["x1 <= 1 m", "x1 <= 1000 mm", "x1 <= 1e+06 µm"])
def test_a_stops_description_reads_back_in_any_unit(words: str) -> None:
    assert _described_clearance(words, "upper") == pytest.approx(1.0, rel=1e-12)
