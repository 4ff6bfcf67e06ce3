"""A misspelt keyword of a public settings class names the closest one (issue 51: "a misspelt key gets no 'did you
mean'"); Python itself says only "unexpected keyword argument"."""

from __future__ import annotations

import dataclasses

import pytest

from vibroimpact import ContinuationSettings, EngineSettings, SteadySettings


@pytest.mark.parametrize("cls, wrong, right", [(ContinuationSettings, "mx_steps", "max_steps"), (SteadySettings, "tolerence", "tolerance"), (EngineSettings, "rtl", "rtol")])
def test_a_misspelt_keyword_names_the_closest_one(cls: type, wrong: str, right: str) -> None:
    with pytest.raises(TypeError, match=rf"{cls.__name__}: unknown keyword '{wrong}' \(allowed: .*{right}.*\); did you mean '{right}'\?"):
        cls(**{wrong: 1})


def test_a_keyword_like_none_names_only_what_is_allowed_and_right_ones_still_work() -> None:
    with pytest.raises(TypeError, match=r"unknown keyword 'colour' \(allowed: step, .*\)$"):
        ContinuationSettings(colour=1)  # type: ignore[call-arg]
    settings = dataclasses.replace(ContinuationSettings(max_steps=5), upper=30.0)
    assert settings.max_steps == 5 and settings.upper == 30.0  # exact: as given
