"""The logs of a bifurcation study's run, as a reader meets them on the console, in the dataset and on the page.

* Branch labels: each restitution's continuation (:class:`~vibroimpact.kinds.bifurcation.cases.BranchCase`) numbers
  its branches from 0; the dataset numbers them across restitutions (R's labels follow the previous R's).
  :func:`numbered` moves a case's labels, in its arrays and in its notes, to the dataset's. The chart's own
  continuation (:class:`~vibroimpact.kinds.bifurcation.cases.ChartCase`, the branches its curves start from) numbers
  its branches once more: :func:`chart_labels` finds each one's branch in the dataset (same origin, the same stretch
  of frequency) and :func:`relabel` writes that label into the chart's notes.
* Failures: a run goes on past what fails (a branch that cannot be continued, a seed that does not converge, a curve
  that cannot be followed, a brute-force point where the engine makes no progress) and records it. :func:`tallies`
  counts each kind of work (:data:`FAILURES`) against its attempts; :func:`failure_summary` says, in one line per
  kind and restitution, what failed, how many of how many, and what that means for the results (the dataset's
  ``run_failures``), and keeps every raw message (``run_failure_details``); :func:`vibroimpact.runs.failures.console_line` is the one line the
  console gets.
"""

from __future__ import annotations

import re
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from vibroimpact.runs.runner import CaseResult

__all__ = [
    "relabel", "numbered", "numbered_across", "branch_offsets", "chart_labels", "continuation_log", "SAME_STRETCH",
    "FailureKind", "FAILURES", "FAILURE_FIELDS", "failure_arrays", "Tally", "tallies", "sweep_tally", "failure_summary",
]  # fmt: skip

#: "branch 12" in a note (not "branches", not "branch at").
_LABEL = re.compile(r"\bbranch (\d+)\b")
#: A chart branch is a dataset branch of the same origin when their frequency ranges overlap over at least this share
#: of their union [-] (the two continuations start at the same orbit; their step settings may differ).
SAME_STRETCH = 0.5


def relabel(note: str, labels: Mapping[int, str]) -> str:
    """``note`` with every "branch k" written "branch labels[k]" (unchanged where ``labels`` has no k)."""
    return _LABEL.sub(lambda m: f"branch {labels.get(int(m.group(1)), m.group(1))}", note)


def branch_offsets(results: list[CaseResult]) -> list[int]:
    """The first dataset label of each restitution's branches: its case's labels follow the previous cases'."""
    offsets, offset = [], 0
    for result in results:
        offsets.append(offset)
        offset += int(result["branch"].max()) + 1 if result["branch"].size else 0
    return offsets


def numbered(result: CaseResult, offset: int) -> CaseResult:
    """A copy of a branch case's arrays with every branch label moved by ``offset``: the points' and special points'
    labels, the branches each special point was found on, the labels in the notes, and those of the slowly settling
    seeds' orbits (``ss_branch``, -1 kept, and in ``ss_text``)."""
    labels = {k: str(k + offset) for k in range(int(result["branch"].max()) + 1 if result["branch"].size else 0)}
    moved = dict(result)
    moved["branch"] = result["branch"] + offset
    moved["sp_branch"] = result["sp_branch"] + offset
    moved["sp_found_on"] = np.array([" ".join(labels.get(int(b), b) for b in found.split()) for found in result["sp_found_on"]], dtype=str)
    moved["notes"] = np.array([relabel(str(note), labels) for note in result["notes"]], dtype=str)
    if "ss_branch" in result:  # the seeds that settle slowly: the branches their orbits were continued as
        moved["ss_branch"] = np.where(result["ss_branch"] >= 0, result["ss_branch"] + offset, -1)
        moved["ss_text"] = np.array([relabel(str(text), labels) for text in result["ss_text"]], dtype=str)
    return moved


def numbered_across(results: list[CaseResult]) -> list[CaseResult]:
    """The branch cases of every restitution, in order, :func:`numbered` as the dataset numbers them."""
    return [numbered(result, offset) for result, offset in zip(results, branch_offsets(results))]


def continuation_log(diagrams: Sequence[float | str], results: list[CaseResult]) -> str:
    """The branch cases' notes, one line each, "<diagram>: <note>" (``results`` :func:`numbered_across`), a diagram
    named by its label ("R = 0.2, bumper 250 Hz") or by its restitution R ("R = <R>")."""
    return "\n".join(f"{where if isinstance(where, str) else f'R = {where:g}'}: {note}" for where, result in zip(diagrams, results) for note in result["notes"])


def chart_labels(chart: CaseResult, branches: CaseResult | None) -> dict[int, str]:
    """The dataset's label of each branch of the chart's own continuation: the branch of ``branches`` (the chart
    restitution's branch case, already :func:`numbered`; None when the diagrams have no such R) with the same origin
    whose frequency range overlaps its own over at least :data:`SAME_STRETCH` of their union; else "k of the chart's
    own continuation"."""
    out = {}
    for label, origin, low, high in zip(chart["branch_label"], chart["branch_origin"], chart["branch_low"], chart["branch_high"]):
        best, share = None, SAME_STRETCH
        if branches is not None:
            for other in np.unique(branches["branch"][branches["origin"] == origin]):
                f = branches["frequency"][branches["branch"] == other]
                union = max(high, f.max()) - min(low, f.min())
                overlap = (min(high, f.max()) - max(low, f.min())) / union if union > 0 else 1.0
                if overlap >= share:
                    best, share = int(other), overlap
        out[int(label)] = str(best) if best is not None else f"{int(label)} of the chart's own continuation"
    return out


# --------------------------------------------------------------------------------------------------------------------
# Failures
# --------------------------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class FailureKind:
    """A kind of work of the run that may fail: what it is (the subject of "<what>: k of n failed") and what a
    failure means for the results."""

    what: str
    meaning: str


#: Every kind of work that may fail, by the key the cases record it under (a line says only the work the scene asked for:
#: each kind of branch its own key).
FAILURES: dict[str, FailureKind] = {
    "closed_form": FailureKind("continuing the branches started from the closed-form orbit (a bumper's: the rigid stop's orbit continued to the bumper in its stiffness)",
                               "those branches and their special points are missing from the diagrams and the tables; the branches found are unaffected"),
    "period_doubling": FailureKind("continuing the period-2 branches born at period doublings",
                                   "those branches and their special points are missing from the diagrams and the tables; the branches found are unaffected"),
    "grazing": FailureKind("continuing the branches born at grazing points",
                           "those branches and their special points are missing from the diagrams and the tables; the branches found are unaffected"),
    "seed": FailureKind("shooting from brute-force seeds (points where a sweep's strobes repeat) and running on those that settle slowly",
                        "an orbit the sweeps settle on only there may lack its continued branch (its brute-force dots are still drawn); the branches found are unaffected"),
    "sweep": FailureKind("brute-force frequencies (the engine made no progress, e.g. endless chattering)",
                         "those frequencies have no dots in the diagrams (regime 'failed'); the sweep went on from rest, the other frequencies are unaffected"),
    "map": FailureKind("regime-map points (the engine made no progress, e.g. endless chattering)",
                       "those points are blank ('failed') on the chart's regime map; the other points are unaffected"),
    **{f"chart_{kind}": FailureKind(f"continuing the chart's own {what}", "the chart lacks the curves of those branches' special points; the diagrams are unaffected")
       for kind, what in (("closed_form", "branches from the closed-form orbit"), ("period_doubling", "period-2 branches"), ("grazing", "branches born at grazing points"))},
    "curve": FailureKind("following special points in (frequency, clearance) for the chart",
                         "those curves are missing from the chart; the regime map and the other curves are unaffected"),
    "stiffness_curve": FailureKind("following the stiffest bumper's special points in the bumper's stiffness",
                                   "the convergence table matches those points to the rigid stop's by distance only; the branches are unaffected"),
}  # fmt: skip
#: Fields of a case's arrays that count its work and keep its failures (:func:`failure_arrays`).
FAILURE_FIELDS = ("attempt_kind", "attempt_count", "failure_kind", "failure_detail")


def failure_arrays(attempts: Mapping[str, int], failures: Sequence[tuple[str, str]]) -> CaseResult:
    """Attempts by kind of work (``attempt_kind``, ``attempt_count``) and each failure's kind and raw message
    (``failure_kind``, ``failure_detail``), keys of :data:`FAILURES`."""
    return {
        "attempt_kind": np.array(list(attempts), dtype=str), "attempt_count": np.array(list(attempts.values()), dtype=int),
        "failure_kind": np.array([kind for kind, _ in failures], dtype=str), "failure_detail": np.array([detail for _, detail in failures], dtype=str),
    }  # fmt: skip


@dataclass(frozen=True)
class Tally:
    """Failures of one kind of work (a key of :data:`FAILURES`) at one place (``where``: "R = 0.2"): how many
    attempts, and the raw message of each failure."""

    kind: str
    where: str
    total: int
    details: tuple[str, ...]


def tallies(result: CaseResult, where: str) -> list[Tally]:
    """The tallies of a case's :func:`failure_arrays`, one per kind of work it attempted."""
    out = []
    for kind, total in zip(result["attempt_kind"], result["attempt_count"]):
        details = tuple(str(d) for k, d in zip(result["failure_kind"], result["failure_detail"]) if str(k) == str(kind))
        out.append(Tally(str(kind), where, int(total), details))
    return out


def sweep_tally(kind: str, where: str, sweeps: Sequence[CaseResult], labels: Sequence[str], frequency: np.ndarray) -> Tally:
    """The brute-force points of ``sweeps`` (each labelled, e.g. "sweeping up") where the engine failed."""
    details = tuple(
        f"{label} at {f:.3f} Hz failed: {error}" for sweep, label in zip(sweeps, labels) for f, error in zip(frequency, sweep["error"]) if str(error)
    )  # fmt: skip
    return Tally(kind, where, sum(int(sweep["regime"].size) for sweep in sweeps), details)


#: What differs between messages of one reason: where (" at frequency = 37.574127748391014") and Newton's residuals
#: (" (scaled residual history: [0.244, 0.0915, ...])", cut short or not).
_PARTICULARS = re.compile(r" at \w+ = [-+0-9.e]+(?: s| Hz)?| \(scaled residual history:.*$")


def _reason(detail: str) -> str:
    """The reason a raw message gives ("ShootingError: the map returned a non-finite state" -> the message), without
    where it happened."""
    message = detail.split(" failed: ", 1)[-1]
    message = message.split(": ", 1)[-1] if re.match(r"^\w+(Error|Exception|Warning): ", message) else message
    return _PARTICULARS.sub("", message)


#: The most starts a failure line names (the raw messages name every one).
NAMED_STARTS = 6


def _start(detail: str) -> str:
    """Which start a raw message is of ("brute-force seed at 21.000 Hz (period 13)"), with the scaled residual
    Newton's method started from where it gives one (how far the start was from an orbit)."""
    subject = detail.split(" failed: ", 1)[0]
    first = re.search(r"scaled residual history: \[([-+0-9.e]+)", detail)
    return f"{subject}, residual {first.group(1)} at the start" if first else subject


def failure_summary(counted: Sequence[Tally]) -> tuple[list[str], list[str]]:
    """The run's failures: one line per tally that failed, "<what failed>, <where>: <k> of <n> failed (<k1> with
    '<reason 1>'; ...; which: <start>, ...); <what it means for the results>", and every raw message, "<where>:
    <message>" (both empty when nothing failed)."""
    lines, details = [], []
    for tally in counted:
        if not tally.details:
            continue
        kind = FAILURES[tally.kind]
        reasons = "; ".join(f"{count} with '{reason}'" for reason, count in Counter(_reason(d) for d in tally.details).most_common())
        starts = [_start(d) for d in tally.details]
        which = "; ".join(starts[:NAMED_STARTS]) + (f"; and {len(starts) - NAMED_STARTS} more" if len(starts) > NAMED_STARTS else "")
        lines.append(f"{kind.what}, {tally.where}: {len(tally.details)} of {tally.total} failed ({reasons}; which: {which}); {kind.meaning}")
        details += [f"{tally.where}: {detail}" for detail in tally.details]
    return lines, details
