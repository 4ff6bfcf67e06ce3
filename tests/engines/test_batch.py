"""Many runs in one compiled call (:mod:`vibroimpact.engines.batch`): bit for bit the single runs, for both exact
engines, over starts, frequencies and mistuned parameters at once; failures kept per run; any other engine runs one by
one through the same function."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from vibroimpact.engines.registry import make_engine
from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop, Stop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.simulation.attractors import MAX_PERIOD, at_frequency, measure_motion, measure_motions, sweep_arrays
from vibroimpact.simulation.point_motions import point_starts

#: The paper's absorber at its design point of issue 48 (a period-4 motion at 33 Hz beside the notch).
RIGID = ImpactProblem(PAPER_SYSTEM, (Stop(RigidStop(2.3596e-3, 0.1893), coordinate=1),), HarmonicForce(10.0, 33.0))
#: The same absorber with a Kelvin-Voigt bumper of 300 Hz, loss factor 0.2.
BUMPER = ImpactProblem(PAPER_SYSTEM, (Stop(KelvinVoigtBumper(2.3596e-3, 300.0, 0.2), coordinate=1),), HarmonicForce(10.0, 33.0))


def _cases(problem: ImpactProblem) -> tuple[list[ImpactProblem], list[int], list[np.ndarray]]:
    """Four frequencies and a mistuned clearance (another case of the same layout), 6 starts each."""
    problems = [at_frequency(problem, f) for f in (25.0, 31.0, 33.0, 36.0)]
    stop = problem.stops[0]
    problems.append(ImpactProblem(problem.system, (dataclasses.replace(stop, law=dataclasses.replace(stop.law, clearance=2.0e-3)),), problem.excitation))
    case_of, starts = [], []
    for c, moved in enumerate(problems):
        for _label, start in point_starts(moved, 6, seed=c):
            case_of.append(c)
            starts.append(start)
    return problems, case_of, starts


def _one_by_one(engine, problems, case_of, starts, transient, strobes):
    out = sweep_arrays(len(starts), strobes, 2 * problems[0].size)
    for i, (c, start) in enumerate(zip(case_of, starts)):
        try:
            measure_motion(engine, problems[c], start, transient, strobes, out, i)
        except RuntimeError:
            out["regime"][i] = -1
    return out


@pytest.mark.parametrize(("name", "problem"), [("exact", RIGID), ("compliant_exact", BUMPER)])
def test_a_batch_is_bit_for_bit_the_single_runs(name: str, problem: ImpactProblem) -> None:
    engine = make_engine(name)
    assert engine.capabilities.batched
    problems, case_of, starts = _cases(problem)
    batch = measure_motions(engine, problems, case_of, starts, 120, 64)
    single = _one_by_one(engine, problems, case_of, starts, 120, 64)
    for field, values in single.items():
        assert np.array_equal(batch[field], values, equal_nan=values.dtype.kind == "f"), field
    # the cases cover what the batch must keep apart: contact-free, period-1 and longer periods
    assert {0, 1} <= set(batch["regime"].tolist()) and np.any(batch["period"] > 1)


def test_no_transient_and_the_kept_arrays() -> None:
    engine = make_engine("exact")
    problems, case_of, starts = _cases(RIGID)
    batch = measure_motions(engine, problems, case_of, starts, 0, 40)
    single = _one_by_one(engine, problems, case_of, starts, 0, 40)
    for field, values in single.items():
        assert np.array_equal(batch[field], values, equal_nan=values.dtype.kind == "f"), field
    # the raw batch: the strobes start where the runs start, the repeat test is inf past strobes // 2
    scales = np.ones((len(problems), 4))
    raw = engine.run_many(problems, np.array(case_of), np.array(starts), 0, 40, scales, MAX_PERIOD)
    assert np.array_equal(raw.strobes[:, 0], np.array(starts))
    assert np.all(np.isinf(raw.mismatch[:, 20:])) and np.all(np.isfinite(raw.mismatch[:, :20]))
    assert np.array_equal(raw.after[:, 0], raw.impacts) and np.all(np.diff(raw.after, axis=1) <= 0)


def test_a_run_without_progress_keeps_its_status_and_the_others_run(monkeypatch: pytest.MonkeyPatch) -> None:
    # the loop says "no progress" for run 3 (as it does after too many events in a period): that run is no attractor,
    # the others are measured as before
    from vibroimpact.engines import batch_kernels

    real = batch_kernels.run_rigid_batch

    def failing(*arguments):
        out = real(*arguments)
        out[0][3], out[1][3] = 1, 0.25
        return out

    engine = make_engine("exact")
    problems, case_of, starts = _cases(RIGID)
    whole = measure_motions(engine, problems, case_of, starts, 60, 32)
    monkeypatch.setattr(batch_kernels, "run_rigid_batch", failing)
    failed = measure_motions(engine, problems, case_of, starts, 60, 32)
    assert failed["regime"][3] == -1 and np.all(np.isnan(failed["amplitude"][3])) and whole["regime"][3] >= 0
    keep = np.arange(len(starts)) != 3
    for field, values in whole.items():
        assert np.array_equal(failed[field][keep], values[keep], equal_nan=values.dtype.kind == "f"), field


class _OneByOne:
    """The exact engine, saying it cannot batch: :func:`measure_motions` runs it one by one."""

    def __init__(self) -> None:
        self.inner = make_engine("exact")
        self.capabilities = dataclasses.replace(self.inner.capabilities, batched=False)

    def integrate(self, *arguments, **options):
        return self.inner.integrate(*arguments, **options)


def test_an_engine_that_cannot_batch_runs_one_by_one() -> None:
    problems, case_of, starts = _cases(RIGID)
    slow = measure_motions(_OneByOne(), problems, case_of, starts, 60, 32)
    fast = measure_motions(make_engine("exact"), problems, case_of, starts, 60, 32)
    for field, values in fast.items():
        assert np.array_equal(slow[field], values, equal_nan=values.dtype.kind == "f"), field


def test_no_runs() -> None:
    out = measure_motions(make_engine("exact"), [RIGID], [], [], 10, 16)
    assert out["regime"].shape == (0,)


def test_only_a_study_that_runs_many_starts_compiles_the_batch_entry() -> None:
    from vibroimpact.runs.run import batched_engines, study_kind
    from vibroimpact.scene.reader import load_scene

    design = load_scene("studies/design_rigid_stop.yaml")
    assert batched_engines(study_kind(design), design) == ("exact",)
    stepped = load_scene("studies/restitution.yaml")
    assert batched_engines(study_kind(stepped), stepped) == ()
    # an engine without a batch entry has nothing more to compile for it
    from vibroimpact.engines.registry import engine_spec

    assert engine_spec("momentary").prepare_kernels(batched=True) == 0.0 and engine_spec("momentary").kernels_cached(batched=True)  # exact: no compile, 0.0 returned as such


@pytest.mark.parametrize(("name", "problem"), [("exact", RIGID), ("compliant_exact", BUMPER)])
def test_a_chained_batch_is_the_stepped_sweep_bit_for_bit(name: str, problem: ImpactProblem) -> None:
    # each point from the previous one's end state: stepped_sweep's single runs, in one compiled call
    from vibroimpact.simulation.attractors import linear_start, stepped_sweep

    engine = make_engine(name)
    frequencies = np.linspace(30.0, 36.0, 7)
    swept = stepped_sweep(problem, "down", frequencies, 80, 32, engine)
    problems = [at_frequency(problem, f) for f in frequencies[::-1]]
    starts = [linear_start(problems[0])] + [np.zeros(4)] * 6  # the fallbacks: never used (no run fails)
    chained = measure_motions(engine, problems, list(range(7)), starts, 80, 32, chain_from=[-1, 0, 1, 2, 3, 4, 5])
    for field, values in chained.items():
        assert np.array_equal(values[::-1], swept[field], equal_nan=values.dtype.kind == "f"), field
    assert np.all(chained["regime"] >= 0)
    one_by_one = measure_motions(_OneByOne(), problems, list(range(7)), starts, 80, 32, chain_from=[-1, 0, 1, 2, 3, 4, 5]) if name == "exact" else chained
    for field, values in chained.items():
        assert np.array_equal(values, one_by_one[field], equal_nan=values.dtype.kind == "f"), field


def test_a_chain_runs_forward_only() -> None:
    with pytest.raises(ValueError, match="chain_from"):
        make_engine("exact").run_many([RIGID], np.zeros(2, dtype=np.int64), np.zeros((2, 4)), 1, 16, np.ones((1, 4)), 4, np.array([1, -1]))
