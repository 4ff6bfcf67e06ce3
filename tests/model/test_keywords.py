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


def _public_callables() -> list[str]:
    import vibroimpact

    return [name for name in vibroimpact.__all__ if callable(getattr(vibroimpact, name)) and not name.startswith("_")]


@pytest.mark.parametrize("name", _public_callables())
def test_every_public_class_and_function_names_the_closest_keyword(name: str) -> None:
    """By rule, not by list: every public callable that takes named keywords (and no ``**kwargs``, which say
    themselves what they take) answers a keyword with its last letter doubled by the allowed ones and the right one,
    before any work (no other argument is given)."""
    import inspect

    import vibroimpact
    from vibroimpact.model.keywords import keyword_names

    target = getattr(vibroimpact, name)
    function = target.__init__ if isinstance(target, type) else target
    parameters = inspect.signature(function).parameters.values()
    names = [n for n in keyword_names(target) if len(n) > 1]
    if any(p.kind is inspect.Parameter.VAR_KEYWORD for p in parameters) or not names or issubclass_of_exception(target):
        pytest.skip(f"{name} takes **kwargs, no keyword of two letters or more, or is an exception")
    right = max(names, key=len)
    wrong = right + right[-1]
    with pytest.raises(TypeError, match=rf"{target.__name__}: unknown keyword '{wrong}' \(allowed: .*\); did you mean '{right}'\?"):
        target(**{wrong: 1})


def issubclass_of_exception(target: object) -> bool:
    return isinstance(target, type) and issubclass(target, BaseException)


def test_worst_case_names_the_closest_option_of_its_method() -> None:
    from vibroimpact import PAPER_SYSTEM, HarmonicForce, ImpactProblem, RigidStop, Stop, worst_case

    problem = ImpactProblem(PAPER_SYSTEM, (Stop(RigidStop(3e-3, 0.5), "x2"),), HarmonicForce(30.0, 10.0))
    with pytest.raises(TypeError, match=r"worst_case\(method='closed_form'\): unknown keyword 'scann' \(allowed: .*scan.*\); did you mean 'scan'\?"):
        worst_case(problem, (20.0, 40.0), method="closed_form", scann=11)
    with pytest.raises(TypeError, match=r"did you mean 'frequencies'\?"):
        worst_case(problem, (20.0, 40.0), method="certified", frequncies=11)
