"""The logs of a bifurcation study's run, as a reader meets them on the console, in the dataset and on the page.

* Branch labels: each restitution's continuation (:class:`~vibroimpact.kinds.bifurcation.cases.BranchCase`) numbers
  its branches from 0; the dataset numbers them across restitutions (R's labels follow the previous R's).
  :func:`numbered` moves a case's labels, in its arrays and in its notes, to the dataset's. The chart's own
  continuation (:class:`~vibroimpact.kinds.bifurcation.cases.ChartCase`, the branches its curves start from) numbers
  its branches once more: :func:`chart_labels` finds each one's branch in the dataset (same origin, the same stretch
  of frequency) and :func:`relabel` writes that label into the chart's notes.
"""

from __future__ import annotations

import re
from collections.abc import Mapping

import numpy as np

from vibroimpact.runs.runner import CaseResult

__all__ = ["relabel", "numbered", "numbered_across", "branch_offsets", "chart_labels", "continuation_log", "SAME_STRETCH"]

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
    labels, the branches each special point was found on, and the labels in the notes."""
    labels = {k: str(k + offset) for k in range(int(result["branch"].max()) + 1 if result["branch"].size else 0)}
    moved = dict(result)
    moved["branch"] = result["branch"] + offset
    moved["sp_branch"] = result["sp_branch"] + offset
    moved["sp_found_on"] = np.array([" ".join(labels.get(int(b), b) for b in found.split()) for found in result["sp_found_on"]], dtype=str)
    moved["notes"] = np.array([relabel(str(note), labels) for note in result["notes"]], dtype=str)
    return moved


def numbered_across(results: list[CaseResult]) -> list[CaseResult]:
    """The branch cases of every restitution, in order, :func:`numbered` as the dataset numbers them."""
    return [numbered(result, offset) for result, offset in zip(results, branch_offsets(results))]


def continuation_log(restitutions: tuple[float, ...], results: list[CaseResult]) -> str:
    """The branch cases' notes, one line each, "R = <R>: <note>" (``results`` :func:`numbered_across`)."""
    return "\n".join(f"R = {r:g}: {note}" for r, result in zip(restitutions, results) for note in result["notes"])


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
