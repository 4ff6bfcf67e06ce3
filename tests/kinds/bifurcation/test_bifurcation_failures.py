"""A bifurcation run's internal failures are counted and summarised (what failed, how many of how many, what it means
for the results) for the dataset, the page and one console line; the raw messages are kept apart."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from vibroimpact.engines.exact import ExactEngine
from vibroimpact.kinds.bifurcation.branches import OrbitSet
from vibroimpact.kinds.bifurcation.cases import Seed, seed_branches
from vibroimpact.runs.failures import console_line
from vibroimpact.kinds.bifurcation.logs import FAILURES, failure_arrays, failure_summary, sweep_tally, tallies
from vibroimpact.kinds.bifurcation.study import _say_notes
from vibroimpact.model.contact import RigidStop, Stop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.orbits.continuation import ContinuationSettings
from vibroimpact.reporting.page import write_report

PROBLEM = ImpactProblem(PAPER_SYSTEM.structure, (Stop(RigidStop(3e-3, 0.2), coordinate=1),), HarmonicForce(10.0, 25.0))


@pytest.mark.skipif(not hasattr(ExactEngine, "strobe_map"), reason="needs the compiled exact core (ExactEngine.strobe_map)")
def test_seeds_that_fail_are_counted_and_summarised() -> None:
    """Two seeds whose state is not finite: shooting from them fails, saying so of the guess, the run goes on,
    and the summary says 2 of 2 failed, why, and what that means; the raw messages are kept, one per seed."""
    nan = (float("nan"),) * 4
    found = OrbitSet()
    settings = ContinuationSettings(lower=24.0, upper=26.0, stop_at_grazing=True)
    added = seed_branches(found, PROBLEM, 24.0, 26.0, [Seed(25.0, 1, nan), Seed(25.5, 2, nan)], settings)
    assert added == 0 and found.attempts == {"seed": 2} and [kind for kind, _ in found.failures] == ["seed", "seed"]
    result = failure_arrays(found.attempts, found.failures) | {"notes": np.array(found.notes, dtype=str)}
    lines, details = failure_summary(tallies(result, "R = 0.2"))
    meaning = FAILURES["seed"].meaning
    which = "which: brute-force seed at 25.000 Hz (period 1); brute-force seed at 25.500 Hz (period 2)"
    assert lines == [f"{FAILURES['seed'].what}, R = 0.2: 2 of 2 failed (2 with 'the guess is not finite: no orbit can be shot from it'; {which}); {meaning}"]
    assert len(details) == 2 and all(d.startswith("R = 0.2: brute-force seed at 25") and "ShootingError" in d for d in details)
    said: list[str] = []
    _say_notes(said.append, "R = 0.2", result)  # the console: the notes without the raw failures
    assert said and not any("ShootingError" in line for line in said)
    line = console_line(lines)  # the run's one console line (vibroimpact.runs.failures)
    assert "\n" not in line and "2 of 2 failed" in line and meaning in line


def test_brute_force_points_that_fail_are_counted() -> None:
    """The engine's failures at brute-force points (regime -1 with a message) count against every point swept, the
    reasons grouped without where they happened; nothing failed, nothing is said."""
    f = np.array([20.0, 20.5, 21.0])
    up = {"regime": np.array([1, -1, -1], dtype=np.int8), "error": np.array(["", "RuntimeError: no progress at t = 1.5 s: 70 events", "RuntimeError: no progress at t = 2.25 s: 70 events"])}
    down = {"regime": np.array([1, 1, 1], dtype=np.int8), "error": np.array(["", "", ""])}
    tally = sweep_tally("sweep", "R = 0.8", [up, down], ["sweeping up", "sweeping down"], f)
    lines, details = failure_summary([tally])
    which = "which: sweeping up at 20.500 Hz; sweeping up at 21.000 Hz"
    assert lines == [f"{FAILURES['sweep'].what}, R = 0.8: 2 of 6 failed (2 with 'no progress: 70 events'; {which}); {FAILURES['sweep'].meaning}"]
    assert details == ["R = 0.8: sweeping up at 20.500 Hz failed: RuntimeError: no progress at t = 1.5 s: 70 events",
                       "R = 0.8: sweeping up at 21.000 Hz failed: RuntimeError: no progress at t = 2.25 s: 70 events"]  # fmt: skip
    assert failure_summary([sweep_tally("sweep", "R = 0.8", [down], ["sweeping down"], f)]) == ([], [])


@pytest.mark.slow
def test_the_page_says_what_failed_after_its_answer_and_the_raw_messages_at_its_end(small_bifurcation: xr.Dataset, tmp_path: Path) -> None:
    """The summary comes right after the answer, before any figure; nothing raw comes before the collapsed logs at
    the end, and the raw messages are collapsed there; a run where nothing failed says nothing of failures."""
    kept = {k: v for k, v in small_bifurcation.attrs.items() if not k.startswith("run_failure")}
    dataset = small_bifurcation.copy()
    dataset.attrs = kept | {  # a new dict: the session's dataset is left as it is
        "run_failures": ["shooting from brute-force seeds, R = 0.8: 3 of 41 failed (3 with 'the map returned a non-finite state'); those attractors lack a branch"],
        "run_failure_details": ["R = 0.8: brute-force seed at 22.000 Hz (period 6) failed: ShootingError: the map returned a non-finite state"] * 3,
    }  # fmt: skip
    path = dataset.to_netcdf(tmp_path / "failed.nc") or tmp_path / "failed.nc"
    page = write_report(xr.load_dataset(path), tmp_path).read_text(encoding="utf-8")  # a one-line list comes back as a string
    answer, summary, figure = page.index("<b>R = 0.8</b>"), page.index("3 of 41 failed"), page.index("<figure")
    assert answer < summary < figure
    logs, details = page.index("Continuation logs</h2>"), page.index("<details><summary>The raw messages of what failed (3)")
    assert page.index("Error:") > logs  # nothing raw before the collapsed logs at the end
    assert details > logs and page[details:].count("ShootingError") == 3
    clean = small_bifurcation.copy()
    clean.attrs = kept
    assert "What failed" not in write_report(clean, tmp_path / "clean").read_text(encoding="utf-8")


@pytest.mark.slow
def test_a_run_records_its_failures_in_its_dataset(small_bifurcation: xr.Dataset) -> None:
    """The small study's run: every "k of n failed" of ``run_failures`` adds up to its raw messages, each of which is
    also a line of the continuation log (at its place among the branches)."""
    lines = small_bifurcation.attrs.get("run_failures", [])
    details = small_bifurcation.attrs.get("run_failure_details", [])
    lines, details = ([lines] if isinstance(lines, str) else list(lines)), ([details] if isinstance(details, str) else list(details))
    counts = [int(re.search(r": (\d+) of \d+ failed \(", line).group(1)) for line in lines]
    assert sum(counts) == len(details)
    log = small_bifurcation.attrs["continuation_notes"] + "\n" + small_bifurcation.attrs.get("chart_notes", "")
    for detail in details:
        where, message = detail.split(": ", 1)
        assert message in log or "sweeping" in message, detail


def test_a_failure_line_names_its_starts_and_how_far_newton_began() -> None:
    """Each failed start is named in its line, with the scaled residual Newton's method began from where the message
    gives it (a seed 6 % of the state scale off a periodic orbit says why it failed); past six, how many more."""
    from vibroimpact.kinds.bifurcation.logs import Tally

    details = tuple(f"brute-force seed at {20.0 + k:.3f} Hz (period 13) failed: ShootingError: the line search failed (scaled residual history: [0.0637, 0.0548])" for k in range(8))
    lines, _ = failure_summary([Tally("seed", "R = 0.2", 32, details)])
    assert "which: brute-force seed at 20.000 Hz (period 13), residual 0.0637 at the start; " in lines[0]
    assert "brute-force seed at 25.000 Hz (period 13), residual 0.0637 at the start; and 2 more)" in lines[0]
