"""Whether anything a design study stored contradicts a number its answer states (:func:`contradictions`).

A stated number is a promise: the recommended design's worst case over the band and the tolerance box, and its value
at the operating point. Every motion the study reached and stored must lie at or below it: the screen's per-sample
values, every certificate's worst case, the stable points of every branch it continued, every attractor its brute
force found, and every motion its runs settled on at the operating point. A page whose dataset contradicts its answer
refuses the answer (:func:`vibroimpact.kinds.design.answer.answer_text`) and says which stored motion exceeds it.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from vibroimpact.kinds.design.answer import design_evaluation, design_worst
from vibroimpact.kinds.design.quantity import constraint_quantity, objective_quantity
from vibroimpact.reporting.style import fmt

__all__ = ["contradictions", "SLACK"]

#: A stored value exceeds a stated one where it is larger by more than this share [-] (the stated values are maxima
#: of the same stored numbers: only round-off separates them).
SLACK = 1e-9


def _exceeds(value: float, stated: float) -> bool:
    return math.isfinite(value) and (not math.isfinite(stated) or value > stated * (1.0 + SLACK) + 1e-300)


def contradictions(dataset: xr.Dataset, design: int = 0) -> list[str]:
    """Each stored motion of the compared ``design`` (0: the recommended one) that exceeds a number the answer states
    for it, in words; empty where none does."""
    d = dataset
    evaluation = design_evaluation(d, design)
    if evaluation < 0:
        return []
    q, c = objective_quantity(d), constraint_quantity(d)
    worst = design_worst(d, design)
    found: list[str] = []
    screened = d["sample_value"].values[evaluation]
    for sample, value in enumerate(screened):
        if _exceeds(float(value), worst):
            found.append(f"the screen's {q.text(float(value))} under sample {sample} exceeds the stated worst case {q.text(worst)}")
    rows = np.flatnonzero(d["certificate_evaluation"].values == evaluation) if "certificate_evaluation" in d else np.zeros(0, dtype=int)
    for r in rows:
        sample = int(d["certificate_sample"].values[r])
        where = f"sample {sample}" if sample >= 0 else "the tolerance box's worst point"
        certified = float(d["certificate_worst"].values[r])
        if _exceeds(certified, worst):
            found.append(f"the certificate of {where}, {q.text(certified)}, exceeds the stated worst case {q.text(worst)}")
        if "attractor_amplitude" in d:
            attractors = d["attractor_amplitude"].values[r]
            if np.any(np.isfinite(attractors)):
                k = int(np.nanargmax(attractors))
                if _exceeds(float(attractors[k]), max(worst, certified) if math.isfinite(certified) else worst):
                    found.append(f"an attractor the brute force of {where} stored at {fmt(float(d['attractor_frequency'].values[r, k]), '.4g')} Hz, {q.text(float(attractors[k]))}, exceeds the stated worst case {q.text(worst)}")
        if "branch_amplitude" in d:
            stable = d["branch_stable"].values[r] == 1.0  # exact: a 0/1 flag
            branch = d["branch_amplitude"].values[r][stable]
            if branch.size and np.any(np.isfinite(branch)):
                k = int(np.nanargmax(branch))
                if _exceeds(float(branch[k]), worst):
                    found.append(f"a stable continued orbit of {where} at {fmt(float(d['branch_frequency'].values[r][stable][k]), '.4g')} Hz, {q.text(float(branch[k]))}, exceeds the stated worst case {q.text(worst)}")
    stated = float(d["design_operating_amplitude"].values[design]) if "design_operating_amplitude" in d else math.nan
    if math.isfinite(stated):
        if "sample_operating" in d:
            for sample, value in enumerate(d["sample_operating"].values[evaluation]):
                if _exceeds(float(value), stated):
                    found.append(f"the screen's {c.text(float(value))} at the operating frequency under sample {sample} exceeds the stated {c.text(stated)}")
        operating_frequency = float(d.attrs.get("operating_frequency_Hz", math.nan))
        if "attractor_amplitude" in d and c.name == q.name and math.isfinite(operating_frequency):  # the brute force judged the same measure there
            for r in rows:
                at = np.flatnonzero(np.abs(d["attractor_frequency"].values[r] - operating_frequency) <= 1e-9 * operating_frequency)
                for k in at:
                    value = float(d["attractor_amplitude"].values[r, k])
                    if _exceeds(value, stated):
                        found.append(f"an attractor the brute force stored at the operating frequency, {c.text(value)}, exceeds the stated {c.text(stated)}")
        if "certificate_operating_worst" in d:
            for r in rows:
                value = float(d["certificate_operating_worst"].values[r])
                if _exceeds(value, stated):
                    found.append(f"the certified operating value {c.text(value)} ({d['certificate_operating_motion'].values[r]}) exceeds the stated {c.text(stated)}")
    return found
