"""Benchmark tier (``pytest -m benchmark -n 0 -s``): what brute force costs, measured as ratios in one run, printed and
written to ``results/benchmarks/brute_force_cost.json``. Nothing here asserts a speed (a timed assertion fails on a
busy machine); each part asserts only that what it timed agrees with its single-run counterpart.

1. Per period, for both exact engines: the compiled loop's own cost (one long run), the single-run path (one engine
   call per run, :func:`~vibroimpact.simulation.attractors.measure_motion`) and a batch of 1 000 starts in one compiled
   call (:func:`~vibroimpact.simulation.attractors.measure_motions`), each start run 200 periods then measured 64.
2. Brute force of one design over the band at the certification's coverage (121 frequencies, sweeps up and down and
   2 starts each, 200 + 64 periods: :func:`~vibroimpact.simulation.band_attractors.band_attractors`), batched and one
   run at a time, against the certification of the same design (continuation, that brute force and 64 shot runs at
   the operating frequency: :class:`~vibroimpact.kinds.design.evaluate.CertifyCase`), each the shortest of several
   runs (on a 2-core machine single runs of 0.6 s varied by 0.5-1.0 s).
3. ``studies/design_paper.yaml`` with 1 and with 2 dask workers (``--jobs``), nothing kept between them.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path
from typing import Callable, TypeVar

import numpy as np
import pytest

from vibroimpact.engines.registry import make_engine
from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop, Stop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.simulation.attractors import at_frequency, measure_motion, measure_motions, sweep_arrays
from vibroimpact.simulation.point_motions import point_starts

pytestmark = pytest.mark.benchmark

ROOT = Path(__file__).resolve().parents[2]
OUT = ROOT / "results" / "benchmarks" / "brute_force_cost.json"
#: The paper's absorber at the design point of issue 48 (at 33 Hz a period-4 motion beside the notch), and with a
#: Kelvin-Voigt bumper of 300 Hz.
LAWS = {"exact": RigidStop(2.3596e-3, 0.1893), "compliant_exact": KelvinVoigtBumper(2.3596e-3, 300.0, 0.2)}
TRANSIENT, STROBES = 200, 64
#: Timings of the brute force taken, the shortest kept (the certification: 2).
REPEATS = 5
T = TypeVar("T")


def _best_of(repeats: int, work: Callable[[], T]) -> tuple[float, T]:
    """The shortest wall time of ``repeats`` runs of ``work`` [s] and its last result (timeit's rule: the others
    measured the machine's other load, not the work)."""
    times, result = [], None
    for _ in range(repeats):
        begin = time.perf_counter()
        result = work()
        times.append(time.perf_counter() - begin)
    return min(times), result


def _record(part: str, values: dict) -> None:
    found = json.loads(OUT.read_text()) if OUT.exists() else {}
    found[part] = values | {"load": os.getloadavg()[0]}
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text(json.dumps(found, indent=1))
    print(f"\n{part}: " + ", ".join(f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}" for k, v in found[part].items()))


def _problem(engine: str, frequency: float) -> ImpactProblem:
    return at_frequency(ImpactProblem(PAPER_SYSTEM, (Stop(LAWS[engine], coordinate=1),), HarmonicForce(10.0, 33.0)), frequency)


@pytest.mark.parametrize("engine_name", ["exact", "compliant_exact"])
def test_per_period_cost_of_one_run_and_of_a_batch(engine_name: str) -> None:
    engine = make_engine(engine_name)
    problems = [_problem(engine_name, f) for f in (25.0, 33.0)]
    starts = [(c, state) for c, problem in enumerate(problems) for _label, state in point_starts(problem, 500, seed=c)]
    case_of, states = [c for c, _s in starts], [s for _c, s in starts]
    measure_motions(engine, problems, case_of[:2], states[:2], 2, 16)  # compiled or loaded before timing
    periods = len(states) * (TRANSIENT + STROBES)
    begin = time.perf_counter()
    batch = measure_motions(engine, problems, case_of, states, TRANSIENT, STROBES)
    batch_cost = (time.perf_counter() - begin) / periods
    single = sweep_arrays(100, STROBES, 4)
    picked = np.linspace(0, len(states) - 1, 100).astype(int)
    begin = time.perf_counter()
    for row, i in enumerate(picked):
        measure_motion(engine, problems[case_of[i]], states[i], TRANSIENT, STROBES, single, row)
    single_cost = (time.perf_counter() - begin) / (100 * (TRANSIENT + STROBES))
    for name, values in single.items():
        assert np.array_equal(values, batch[name][picked], equal_nan=values.dtype.kind == "f"), name
    # the loop's own cost: one long run per problem from a settled state, as many periods as the batch's runs,
    # the measured share with moments and Jacobians
    begin = time.perf_counter()
    for c, problem in enumerate(problems):
        settled = batch["state"][case_of.index(c)]
        engine.integrate(problem, settled, 0.0, 500 * TRANSIENT)
        engine.integrate(problem, settled, 0.0, 500 * STROBES, moments=True, jacobians=True)
    kernel_cost = (time.perf_counter() - begin) / periods
    _record(f"per_period_{engine_name}", {
        "kernel_us": kernel_cost * 1e6, "single_run_us": single_cost * 1e6, "batch_of_1000_us": batch_cost * 1e6,
        "batch_over_kernel": batch_cost / kernel_cost, "single_over_batch": single_cost / batch_cost,
    })  # fmt: skip


@pytest.mark.timeout(1200)
def test_brute_force_of_one_design_against_its_certification() -> None:
    from vibroimpact.kinds.design.evaluate import ATTRACTOR_POINTS, CertifyCase
    from vibroimpact.kinds.design.study import design_space
    from vibroimpact.scene.reader import load_scene
    from vibroimpact.simulation.band_attractors import band_attractors

    space = design_space(load_scene(str(ROOT / "studies" / "design_rigid_stop.yaml")))
    design = (2.3596e-3, 0.1893)
    problem = space.problem_at(design, 0)
    options = {"frequencies": ATTRACTOR_POINTS, "starts": 2, "transient": TRANSIENT, "strobes": STROBES, "measure": space.objective}
    band_attractors(problem, (30.0, 31.0), frequencies=2, starts=2, transient=2, strobes=16)  # compiled or loaded
    batched_time, batched = _best_of(REPEATS, lambda: band_attractors(problem, space.band, **options))

    class _OneByOne:  # the exact engine, one run at a time
        def __init__(self) -> None:
            self.inner = make_engine("exact")
            self.capabilities = type(self.inner.capabilities)(**{**self.inner.capabilities.__dict__, "batched": False})

        def __getattr__(self, name: str):
            return getattr(self.inner, name)

    single_time, single = _best_of(REPEATS, lambda: band_attractors(problem, space.band, engine=_OneByOne(), **options))
    assert np.array_equal(single.amplitude, batched.amplitude, equal_nan=True)
    certify_time, certificate = _best_of(2, lambda: CertifyCase(space, design, 0).run())
    assert float(certificate["brute_worst"]) == pytest.approx(float(np.nanmax(batched.amplitude)), rel=1e-9)
    runs = ATTRACTOR_POINTS * 4
    _record("brute_force", {
        "runs": runs, "best_of": REPEATS, "periods_per_run": TRANSIENT + STROBES, "batched_s": batched_time, "one_by_one_s": single_time, "certification_s": certify_time,
        "one_by_one_over_batched": single_time / batched_time, "certification_over_batched": certify_time / batched_time,
    })  # fmt: skip


@pytest.mark.timeout(2400)
def test_design_paper_with_one_and_two_workers() -> None:
    from vibroimpact.runs.run import run_study
    from vibroimpact.scene.reader import load_scene

    scene = load_scene(str(ROOT / "studies" / "design_paper.yaml"))
    seconds = {}
    answers = {}
    for jobs in (1, 2):
        begin = time.perf_counter()
        dataset = run_study(scene, progress=None, jobs=jobs)
        seconds[jobs] = time.perf_counter() - begin
        answers[jobs] = dataset["certificate_worst"].values.copy()
    np.testing.assert_array_equal(answers[1], answers[2])  # the same answer, whatever the workers
    _record("design_paper_workers", {"one_worker_s": seconds[1], "two_workers_s": seconds[2], "speed_up": seconds[1] / seconds[2]})
