"""The motion that sets a certified worst case, named as a noun in the page's sentences: the golden impact damper's
page said 'set at 25.017 Hz by contact-free (brute force, up run)' and '33.64 mm (contact-free (brute force, up run)
at 25.02 Hz)'."""

from __future__ import annotations

from pathlib import Path

import pytest

from vibroimpact import design_answer
from vibroimpact.kinds.design.answer import motion_noun
from vibroimpact.runs.run import read_dataset

GOLDEN = Path(__file__).resolve().parents[2] / "golden" / "data"


@pytest.mark.parametrize(
    ("stored", "said"),
    [
        ("1 impact per period (interior of its branch)", "the motion with 1 impact per period (interior of its branch)"),
        ("contact-free (brute force, up run)", "the contact-free motion (brute force, up run)"),
        ("period 2, 3 impacts (brute force, down run)", "the period-2 motion with 3 impacts (brute force, down run)"),
        ("irregular, 0.22 impacts per period (brute force, up run)", "an irregular motion, 0.22 impacts per period (brute force, up run)"),
        ("chaotic, 1.5 impacts per period", "a chaotic motion, 1.5 impacts per period"),
    ],
)
def test_each_kind_of_motion_reads_as_a_noun(stored: str, said: str) -> None:
    assert motion_noun(stored) == said


def test_the_impact_damper_answer_names_its_contact_free_motion() -> None:
    answer = design_answer(read_dataset(GOLDEN / "impact_damper.nc"))
    text = " ".join([answer.headline, *answer.warnings])
    assert "by the contact-free motion (brute force, up run) at the nominal design" in answer.headline
    assert "by contact-free" not in text and "(contact-free (" not in text
