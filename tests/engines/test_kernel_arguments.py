"""The compiled loops' arguments travel by name: each named tuple's fields are its loop's leading parameters in the
loop's order, so a reordered signature fails here instead of feeding the loop a wrong array."""

from __future__ import annotations

import inspect
from typing import NamedTuple

import pytest

from vibroimpact.engines import exact_core
from vibroimpact.engines.compliant import exact_loop
from vibroimpact.engines.exact import loop_setup
from vibroimpact.engines.kernel_arguments import RUN_PARAMETERS, BumperLoopArguments, LoopArguments, StackedFlows, leading_arguments
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM

from tests.conftest import PAPER_AMPLITUDE, PAPER_CLEARANCE


def _parameters(kernel: object) -> tuple[str, ...]:
    return tuple(inspect.signature(kernel.py_func).parameters)  # type: ignore[attr-defined]


@pytest.mark.parametrize(("fields", "kernel"), [(LoopArguments, exact_core.run_periods_until), (BumperLoopArguments, exact_loop.run_bumper_periods_until)], ids=["exact", "bumper"])
def test_the_fields_are_the_loops_leading_parameters_in_order(fields: type, kernel: object) -> None:
    assert fields._fields + RUN_PARAMETERS + ("cancel",) == _parameters(kernel)  # type: ignore[attr-defined]
    assert fields._fields[: len(StackedFlows._fields)] == StackedFlows._fields  # the stacked flows lead both loops


def test_a_kernel_takes_its_leading_arguments_by_name() -> None:
    """In the kernel's order, whatever the tuple's, up to its first parameter that is no field."""

    class Fields(NamedTuple):
        a: int
        b: int
        c: int

    def kernel(c: int, a: int, later: int, b: int) -> None:  # the helper reads a dispatcher's py_func, or a function
        del c, a, later, b

    assert leading_arguments(kernel, Fields(1, 2, 3)) == (3, 1)


def test_the_sampling_kernel_gets_the_loops_arrays_by_name() -> None:
    """:func:`sample_states`' leading arguments are the loop's own arrays, the very objects, each by its name (the
    bumper engine's sampling is checked against its run in tests/engines/test_compliant_exact.py)."""
    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(PAPER_CLEARANCE, 0.6), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    setup = loop_setup(problem, EngineSettings())
    names = _parameters(exact_core.sample_states)[: len(setup.sampling)]
    assert names == (*StackedFlows._fields[:11], "omega", "gapw", "clearances", "simple", "signs")
    assert all(value is getattr(setup.arguments, name) for name, value in zip(names, setup.sampling))
    assert isinstance(setup.arguments, LoopArguments) and setup.arguments.gapw.shape == (1, 4)


def test_each_loop_s_result_has_a_name_for_each_entry() -> None:
    """A run of each loop gives exactly its named output's entries, each the array its name says (what callers read
    by name, no caller by position)."""
    import numpy as np

    from vibroimpact.engines.compliant.exact import loop_arguments
    from vibroimpact.engines.kernel_arguments import BumperLoopOutput, LoopOutput
    from vibroimpact.model.contact import KelvinVoigtBumper

    never = np.zeros(1, dtype=np.int64)
    rigid = ImpactProblem(PAPER_SYSTEM, RigidStop(PAPER_CLEARANCE, 0.6), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    out = LoopOutput._make(exact_core.run_periods_until(*loop_setup(rigid, EngineSettings()).arguments, np.zeros(4), 0.0, 3, True, True, True, never))
    assert out.status == exact_core.STATUS_OK and out.strobes.shape == (4, 4) and out.jacobians.shape == (3, 4, 4) and out.moments.shape == (3, 5)
    assert out.impacts.shape[1] == 4 and out.segments.shape[1] == 3 and out.segment_states.shape[1] == 4 and out.counters.size == 5 and out.approach.size == 3
    assert exact_core.run_periods(*loop_setup(rigid, EngineSettings()).arguments, np.zeros(4), 0.0, 3, True, True, True).strobes.tobytes() == out.strobes.tobytes()
    bumper = ImpactProblem(PAPER_SYSTEM, KelvinVoigtBumper(PAPER_CLEARANCE, 250.0, 0.3), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    raw = exact_loop.run_bumper_periods_until(*loop_arguments(bumper), np.zeros(4), 0.0, 3, True, True, True, never)
    out = BumperLoopOutput._make(raw)
    assert BumperLoopOutput._fields[:-2] == LoopOutput._fields[:-1] and BumperLoopOutput._fields[-2:] == ("onsets", "approach")
    assert out.status == exact_loop.STATUS_NO_PROGRESS - 1 and out.strobes.shape == (4, 4) and out.jacobians.shape == (3, 4, 4) and out.moments.shape == (3, 5)
    assert out.impacts.shape[1] == 6 and out.segments.shape[1] == 2 and out.counters.size == 5 and out.onsets.shape[1] == 5 and out.approach.size == 3
    assert out.impacts.shape[0] >= 1 and out.onsets.shape[0] >= 1  # the absorber reaches its bumper within three periods
