"""What a design study answers, in words: the design to build and its worst case against the comparisons
(:func:`answer_text`), and what the reader must know before building it (:func:`warnings`), read from the dataset;
and the facts the page's figures and tables share: the compared designs present, their worst cases, the search's
path, the evaluations by stage, the mistuning's spreads."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np
import xarray as xr
import yaml
from numpy.typing import NDArray

from vibroimpact.kinds.design.cautions import SYMBOLS as _SYMBOLS, at_bounds, cautions, variable_names
from vibroimpact.kinds.design.quantity import constraint_quantity, objective_quantity, operating_limit
from vibroimpact.kinds.design.scene import safe_name
from vibroimpact.orbits.continuation_settings import ContinuationSettings
from vibroimpact.reporting.style import fmt

__all__ = ["answer_text", "worst_motion", "offset_text", "sample_counts", "samples_text", "operating_motion", "at_bounds", "never_strikes", "ties", "TIE", "design_titles", "screen_words", "linear_wins", "warnings", "variable_names", "variable_text", "design_text", "unit_text", "Spread", "mistuning_spreads", "mistuning_text", "DESIGN_TITLES", "design_evaluation", "certified_worst", "design_worst", "present_designs", "search_path", "stage_counts"]

#: How the page names the compared designs (the dataset's ``design`` dimension, in order).
DESIGN_TITLES = ("recommended design", "the scene's design", "best linear absorber")
_UNITS = {"1": "", "N m-1": "N/m", "N s m-1": "N s/m"}


def unit_text(unit: str) -> str:
    """A UDUNITS string as the page writes it: ``N m-1`` -> ``N/m``; empty for ``1``."""
    return _UNITS.get(unit, unit)


def variable_text(dataset: xr.Dataset, design: int) -> str:
    """``Delta = 2.1 mm, R = 0.35, k2 = 4120 N/m`` of a compared design (its variables with a value)."""
    parts = []
    for name in variable_names(dataset):
        variable = dataset[f"design_{safe_name(name)}"]
        value = float(variable.values[design])
        if not math.isfinite(value):
            continue
        if name == "clearance":
            parts.append(f"Delta = {fmt(1e3 * value, '.4g')} mm")
        else:
            unit = unit_text(str(variable.attrs.get("units", "1")))
            parts.append(f"{_SYMBOLS.get(name, name)} = {fmt(value, '.4g')}{' ' + unit if unit else ''}")
    return ", ".join(parts)


def design_text(dataset: xr.Dataset, design: int) -> str:
    """:func:`variable_text`, and for the linear absorber (no stop) its k2 and b2: ``no stop, k2 = 2061 N/m, b2 = 5.337 N s/m``."""
    if DESIGN_TITLES[design] != "best linear absorber":
        return variable_text(dataset, design)
    k2, b2 = (float(dataset.attrs.get(key, math.nan)) for key in ("linear_optimum_k2_N_per_m", "linear_optimum_b2_N_s_per_m"))
    absorber = f", k2 = {fmt(k2, '.4g')} N/m, b2 = {fmt(b2, '.4g')} N s/m" if math.isfinite(k2) and math.isfinite(b2) else ""
    return f"no stop{absorber}"


@dataclass(frozen=True)
class Spread:
    """How far one scalar was mistuned.

    Attributes
    ----------
    name : str
        The scalar (``k1``, ``clearance``, ...).
    spread : float
        Half-width of the samples' range: relative [-] or absolute [m] for the clearance, [-] for the restitution.
    relative : bool
        The spread is a share of the scalar.
    stated : bool
        Read from the stored scene's ``design.robust`` (False: the largest offset of the samples, a lower bound).
    """

    name: str
    spread: float
    relative: bool
    stated: bool

    def text(self) -> str:
        """``+-5 % of k1``, ``+-0.2 mm of the clearance``, ``+-0.05 of the restitution`` (``offsets up to +-...``
        when not stated)."""
        lead = "+-" if self.stated else "offsets up to +-"
        if self.relative:
            return f"{lead}{fmt(100 * self.spread, '.2g')} % of {self.name}"
        if self.name == "clearance":
            return f"{lead}{fmt(1e3 * self.spread, '.2g')} mm of the clearance"
        return f"{lead}{fmt(self.spread, '.2g')} of the {self.name}"


def sample_name(sample: int) -> str:
    """How the page names a certified sample: ``sample 3``, or ``the tolerance box's worst point`` (-1)."""
    return "the tolerance box's worst point" if sample < 0 else f"sample {sample}"


def offset_text(name: str, offset: float, relative: bool) -> str:
    """One robust scalar's offset: ``+5 % of k1``, ``-0.2 mm of the clearance``, ``+0.05 of the restitution``."""
    sign = "+" if offset >= 0.0 else "-"
    if relative:
        return f"{sign}{fmt(100 * abs(offset), '.2g')} % of {name}"
    if name == "clearance":
        return f"{sign}{fmt(1e3 * abs(offset), '.2g')} mm of the clearance"
    return f"{sign}{fmt(abs(offset), '.2g')} of the {name}"


def _stored_robust(scene_text: str) -> dict[str, object]:
    """The stored scene's ``design.robust`` read as plain YAML, unchecked (as the page reads its description); empty
    if it has none."""
    try:
        document = yaml.safe_load(scene_text)
    except yaml.YAMLError:
        return {}
    design = document.get("design") if isinstance(document, dict) else None
    robust = design.get("robust") if isinstance(design, dict) else None
    return robust if isinstance(robust, dict) else {}


def mistuning_spreads(dataset: xr.Dataset) -> list[Spread]:
    """Each mistuned scalar's spread: as the stored scene states it (``design.robust``, read as plain YAML), else the
    largest offset the samples drew (the dataset keeps the offsets, not the spreads)."""
    robust = _stored_robust(str(dataset.attrs.get("scene", "")))
    out = []
    for name in dataset.data_vars:
        if not str(name).startswith("mistuning_"):
            continue
        variable = dataset[name]
        what = str(variable.attrs.get("long_name", "")).split(" offset of ")[-1].split(" in each")[0]
        relative = str(variable.attrs.get("long_name", "")).startswith("relative")
        stated = robust.get(what)
        if isinstance(stated, (int, float)) and not isinstance(stated, bool) and math.isfinite(float(stated)):
            out.append(Spread(what, float(stated), relative, True))
        else:
            out.append(Spread(what, float(np.max(np.abs(variable.values))), relative, False))
    return out


def sample_counts(dataset: xr.Dataset) -> tuple[int, int]:
    """(corners of the tolerance box, random samples) among the mistuning samples (``sample_kind``; a dataset
    without it: every sample but the nominal is random)."""
    if "sample_kind" not in dataset:
        return 0, dataset.sizes["sample"] - 1
    kinds = dataset["sample_kind"].values
    return int(np.count_nonzero(kinds == 1)), int(np.count_nonzero(kinds == 2))


def samples_text(dataset: xr.Dataset) -> str:
    """``the box's 4 corners, its worst point and 6 random samples``; ``32 samples`` without corners."""
    corners, random = sample_counts(dataset)
    if not corners:
        return f"{random} sample{'s' if random != 1 else ''}"
    box = ", its worst point" if "box_worst_screened" in dataset.attrs else ""
    return f"the box's {corners} corners{box} and {random} random sample{'s' if random != 1 else ''}"


def mistuning_text(dataset: xr.Dataset) -> str:
    """``+-5 % of k1 and +-0.2 mm of the clearance (the box's 4 corners, its worst point and 6 random samples)``, or
    empty."""
    spreads = mistuning_spreads(dataset)
    if not spreads:
        return ""
    return f"{' and '.join(s.text() for s in spreads)} ({samples_text(dataset)})"


def design_evaluation(dataset: xr.Dataset, design: int) -> int:
    """The evaluation a compared design is (the recommended one, the scene's: the first); -1 for the linear
    absorber, which the search did not evaluate, or when nothing was recommended."""
    return (int(dataset.attrs.get("recommended_evaluation", -1)), 0, -1)[design]


def certified_worst(dataset: xr.Dataset, design: int) -> tuple[float, int]:
    """The largest certified worst case [the objective's unit: m or N] of a compared design over its certificates, and that certificate's
    index; (NaN, -1) where none has a value."""
    evaluation = design_evaluation(dataset, design)
    rows = np.flatnonzero(dataset["certificate_evaluation"].values == evaluation) if evaluation >= 0 else np.zeros(0, dtype=int)
    worst = dataset["certificate_worst"].values
    rows = [int(r) for r in rows if math.isfinite(float(worst[r]))]
    if not rows:
        return math.nan, -1
    row = max(rows, key=lambda r: float(worst[r]))
    return float(worst[row]), row


def design_worst(dataset: xr.Dataset, design: int) -> float:
    """A compared design's worst case [the objective's unit]: the largest of its samples' screened values, its
    certificates' and (the recommended design) the screen's value at the tolerance box's worst point (NaN when it has
    none)."""
    row = dataset["design_sample_value"].values[design]
    screened = float(np.nanmax(row)) if np.any(np.isfinite(row)) else math.nan
    certified = certified_worst(dataset, design)[0]
    box = float(dataset.attrs.get("box_worst_screened", math.nan)) if design == 0 else math.nan
    return float(np.fmax(np.fmax(screened, certified), box))


def present_designs(dataset: xr.Dataset) -> list[int]:
    """The compared designs the dataset has a response of (the linear absorber only when compared)."""
    return [k for k in range(dataset.sizes["design"]) if np.any(np.isfinite(dataset["response_linear"].values[k]))]


def search_path(dataset: xr.Dataset) -> NDArray[np.int64]:
    """Indices of the evaluations that lowered the best score so far, in evaluation order (the first one included):
    the best design after each step of the search."""
    best, path = math.inf, []
    for i, score in enumerate(dataset["score"].values):
        if score < best:
            best = float(score)
            path.append(i)
    return np.array(path, dtype=np.int64)


def stage_counts(dataset: xr.Dataset) -> dict[str, int]:
    """How many candidates each stage of the search evaluated (``evaluation_stage``), by the stage's name."""
    flags = dataset["evaluation_stage"]
    meanings = str(flags.attrs.get("flag_meanings", "")).split()
    counts = np.bincount(flags.values.astype(int), minlength=len(meanings))
    return {name: int(counts[k]) for k, name in enumerate(meanings)}


#: Two worst cases within this share of each other tie [-]: the certificate's own tolerance is far finer (continuation
#: 1e-7, the brute force's shots 1e-6), but mistuned designs differ in their last digits.
TIE = 1e-3


def ties(first: float, second: float) -> bool:
    """Whether two worst cases tie (:data:`TIE`)."""
    return math.isfinite(first) and math.isfinite(second) and abs(first - second) <= TIE * max(abs(first), abs(second))


def operating_motion(dataset: xr.Dataset, design: int) -> str:
    """Which motion sets a compared design's stated operating value and who reached it: ``a period-4 motion, 1 impact
    per 4 periods, reached from rest and from 63 of 63 other starts`` (its certificate's), else the screen's (its
    period and impacts, and how many of its runs reached it); "" where nothing says."""
    d = dataset
    value = float(d["design_operating_amplitude"].values[design])
    evaluation = design_evaluation(d, design)
    if evaluation < 0 or not math.isfinite(value):
        return ""
    if "certificate_operating_worst" in d:
        rows = [int(r) for r in np.flatnonzero(d["certificate_evaluation"].values == evaluation) if math.isfinite(float(d["certificate_operating_worst"].values[r]))]
        top = max(rows, key=lambda r: float(d["certificate_operating_worst"].values[r]), default=None)
        if top is not None and float(d["certificate_operating_worst"].values[top]) >= value * (1.0 - 1e-9):
            return f"{d['certificate_operating_motion'].values[top]}, {d['certificate_operating_reached'].values[top]}"
    if "sample_operating" not in d:
        return ""
    row = d["sample_operating"].values[evaluation]
    if not np.any(np.isfinite(row)):
        return ""
    k = int(np.nanargmax(row))
    period, impacts, starts = (float(d[f"sample_operating_{key}"].values[evaluation, k]) for key in ("period", "impacts", "starts"))
    if not math.isfinite(period):
        return ""
    count = int(round(impacts)) if math.isfinite(impacts) else 0
    motion = "the contact-free motion" if count == 0 and period == 1 else (f"a period-{int(period)} motion, {count} impact{'s' if count != 1 else ''} per {'period' if period == 1 else f'{int(period)} periods'}" if period else "a non-periodic motion")
    return motion + (f", reached by {int(starts)} of the screen's runs" if starts > 0 else "")


def never_strikes(dataset: xr.Dataset, design: int = 0) -> bool:
    """Whether no stable motion any certificate of the compared design found in the band strikes its stop (every
    certificate says so, at least one exists): the design is a linear absorber with an idle stop."""
    d = dataset
    if "certificate_impacting" not in d:
        return False
    evaluation = design_evaluation(d, design)
    rows = np.flatnonzero(d["certificate_evaluation"].values == evaluation) if evaluation >= 0 else np.zeros(0, dtype=int)
    if not rows.size or not np.all(d["certificate_impacting"].values[rows] == 0.0):  # exact: 0/1 flags
        return False
    if "certificate_operating_impacts" in d and np.any(d["certificate_operating_impacts"].values[rows] > 0.0):
        return False  # a motion at the operating point strikes it
    screened = [np.asarray(d[name].values[evaluation], dtype=float) for name in ("sample_operating_impacts",) if name in d]
    if any(np.any(v > 0.0) for v in screened):
        return False
    impulses = np.asarray(d["sample_impulse"].values[evaluation], dtype=float) if "sample_impulse" in d else np.zeros(0)
    return not np.any(impulses > 0.0)  # no stable impact orbit on any sample's scan (NaN: screened by brute force, whose runs the certificates judge)


def _where_in_box(d: xr.Dataset, sample: int, certificate: int | None = None) -> str:
    """`` at the box's corner +0.2 mm of the clearance, -0.05 of the restitution`` (a corner), `` under sample 5 (...)``,
    `` at the box's worst point (...)`` (sample -1); "" for the nominal design or without mistuning."""
    if sample == 0:
        return " at the nominal design"
    names = [str(v).removeprefix("mistuning_") for v in d.data_vars if str(v).startswith("mistuning_")]
    parts = []
    for name in names:
        variable = d[f"mistuning_{name}"]
        relative = str(variable.attrs.get("long_name", "")).startswith("relative")
        if certificate is not None and f"certificate_offset_{name}" in d:
            value = float(d[f"certificate_offset_{name}"].values[certificate])
        elif sample >= 0:
            value = float(variable.values[sample])
        else:
            continue
        what = str(variable.attrs.get("long_name", "")).split(" offset of ")[-1].split(" in each")[0]
        parts.append(offset_text(what, value, relative))
    if not parts:
        return ""
    kind = int(d["sample_kind"].values[sample]) if "sample_kind" in d and sample >= 0 else -1
    where = "the box's worst point" if sample < 0 else ("the box's corner" if kind == 1 else f"sample {sample}")
    return f" at {where}, {', '.join(parts)}"


def motion_noun(motion: str) -> str:
    """A certificate's motion (``certificate_motion``) as the noun that follows "set at 25 Hz by": ``the motion with 1
    impact per period (...)``, ``the contact-free motion (brute force, up run)``, ``the period-2 motion with 3 impacts
    (...)``, ``an irregular motion, 0.2 impacts per period (...)``."""
    period = re.match(r"period (\d+), (.*)", motion)
    if motion[:1].isdigit() or period:
        return f"the period-{period[1]} motion with {period[2]}" if period else f"the motion with {motion}"
    kind = motion.split(",")[0].split(" (")[0]
    if kind in ("contact-free", "irregular", "chaotic", "quasi-periodic"):
        return f"{'the' if kind == 'contact-free' else 'an' if kind[0] in 'aeiou' else 'a'} {kind} motion{motion[len(kind) :]}"
    return motion


def worst_motion(dataset: xr.Dataset, design: int = 0) -> str:
    """What sets a compared design's stated worst case, where and under which offsets: ``set at 24.34 Hz by the
    motion with 1 impact per period (interior of its branch) at the box's corner, +0.2 mm of the clearance, -0.05 of
    the restitution`` (its certificate's, else its screen's); "" where nothing says."""
    d = dataset
    evaluation = design_evaluation(d, design)
    worst = design_worst(d, design)
    if evaluation < 0 or not math.isfinite(worst):
        return ""
    value, row = certified_worst(d, design)
    if row >= 0 and value >= worst * (1.0 - 1e-9):
        named = motion_noun(str(d["certificate_motion"].values[row]))
        return f"set at {fmt(float(d['certificate_frequency'].values[row]), '.5g')} Hz by {named}{_where_in_box(d, int(d['certificate_sample'].values[row]), row)}"
    values = d["sample_value"].values[evaluation]
    if not np.any(np.isfinite(values)):
        return ""
    sample = int(np.nanargmax(values))
    if float(values[sample]) < worst * (1.0 - 1e-9):  # the box's worst point, screened only
        return "set at the box's worst point (screened)"
    meanings = str(d["sample_motion"].attrs.get("flag_meanings", "")).split()
    code = int(d["sample_motion"].values[evaluation, sample])
    motion = meanings[code].replace("_", " ") if 0 <= code < len(meanings) else "a motion"
    return f"set at {fmt(float(d['sample_frequency'].values[evaluation, sample]), '.5g')} Hz by the screen's {motion} motion{_where_in_box(d, sample)}"


def answer_text(dataset: xr.Dataset) -> str:
    """The page's first sentence (module docstring): what to build, its worst case and operating value with the
    motions that set them; "No design in these bounds holds ..." where none keeps the operating limit; "Build no stop"
    where the linear absorber is better or the recommended stop is never struck; ties named."""
    d = dataset
    low, high = fmt(d.attrs["band_low_Hz"], ".4g"), fmt(d.attrs["band_high_Hz"], ".4g")
    values = d["design_sample_value"].values
    worst = [float(np.nanmax(row)) if np.any(np.isfinite(row)) else math.nan for row in values]
    mistuned = mistuning_text(d)
    over = f"over {low}-{high} Hz" + (f" and {mistuned}" if mistuned else "")
    recommended = int(d.attrs.get("recommended_evaluation", -1))
    if recommended < 0:
        return f"No design could be recommended: no candidate had a finite worst case {over}."
    q, c, limit = objective_quantity(d), constraint_quantity(d), operating_limit(d)
    operating = d["design_operating_amplitude"].values
    at = fmt(d.attrs.get("operating_frequency_Hz"), ".4g")
    of = "" if c.name == q.name else f"{c.symbol} = "  # the constraint's measure named where it is not the objective's

    def notch(k: int) -> str:
        if not math.isfinite(limit) or not math.isfinite(float(operating[k])):
            return ""
        motion = operating_motion(d, k)
        which = f" ({motion})" if motion else ""
        if operating[k] > limit:
            return f", {of}{c.text(float(operating[k]))} at {at} Hz{which}, above the allowed {c.text(limit)}"
        return f", {of}{c.text(float(operating[k]))} at {at} Hz{which}" + (f", where {c.text(limit)} is allowed" if k == 0 else "")

    scene = variable_text(d, 1)
    scene_part = f"the scene's design{', ' + scene if scene else ''}: {q.text(design_worst(d, 1))}{notch(1)}"
    best = design_worst(d, 0)
    if math.isfinite(limit) and not float(operating[0]) <= limit:
        alone = float(d.attrs.get("operating_absorber_alone", math.nan))
        why = f"; without a stop the absorber already has {c.text(alone)} there, and no stop in these bounds lowers it enough" if math.isfinite(alone) and alone > limit else ""
        linear = f"; the best linear absorber of the same mass: {q.text(worst[2])}{notch(2)}" if np.any(np.isfinite(values[2])) else ""
        return (f"No design found in these bounds keeps the operating limit ({c.symbol} at most {c.text(limit)} at {at} Hz{why}): the best found (the least penalised score) is {variable_text(d, 0)}{at_bounds(d)}, "
                f"worst case {q.symbol} = {q.text(best)} {over}{notch(0)} ({scene_part}{linear}).")  # fmt: skip
    if linear_wins(d):  # no design with a stop found beats the linear absorber: say so first
        tie = ties(worst[2], best)
        verb = "ties with the best design with a stop found" if tie else "has the smallest worst case"
        return (f"Build no stop: the best linear absorber of the same mass ({design_text(d, 2)}) {verb}, {q.symbol} = {q.text(worst[2])} {over}{notch(2)} "
                f"(the best design with a stop found, {variable_text(d, 0)}: {q.text(best)}{notch(0)}; {scene_part}).")  # fmt: skip
    if never_strikes(d):
        return (f"Build no stop: no motion found in the band strikes the recommended stop ({variable_text(d, 0)}{at_bounds(d)}), so it is a linear absorber with an idle stop; "
                f"worst case {q.symbol} = {q.text(best)} {over}{notch(0)} ({scene_part}).")  # fmt: skip
    others = []
    if np.any(np.isfinite(values[2])):
        tie = " (a tie)" if ties(worst[2], best) else ""
        others.append(f"best linear absorber of the same mass: {q.text(worst[2])}{notch(2)}{tie}")
    others.append(scene_part)
    motion = worst_motion(d, 0)
    setting = f", {motion}" if motion else ""
    kept = notch(0)
    kept = "; " + kept.removeprefix(", ") if setting and kept else kept
    return f"Build {variable_text(d, 0)}{at_bounds(d)}: worst case {q.symbol} = {q.text(best)} {over}{setting}{kept} ({'; '.join(others)})."


def screen_words(dataset: xr.Dataset) -> str:
    """How the page names the search's screen (attribute ``screen``): ``closed-form`` (rigid stops), ``bumper``
    (period-1 bumper orbits shot from the rigid twin's closed forms) or ``brute-force``."""
    return {"bumper_orbits": "bumper", "brute_force": "brute-force"}.get(str(dataset.attrs.get("screen", "")), "closed-form")


def design_titles(dataset: xr.Dataset) -> tuple[str, str, str]:
    """How the page names the compared designs: :data:`DESIGN_TITLES`, the first called "best design with a stop"
    where the linear absorber is the one to build (:func:`linear_wins`), and "recommended design (its stop never
    struck)" where the answer is to build it without its stop (:func:`never_strikes`): its star marks the absorber;
    "best found (above the operating limit)" where no design in the bounds keeps the operating limit (the answer's
    first words), so that no marker calls a design that breaks the limit a recommendation."""
    limit = operating_limit(dataset)
    if math.isfinite(limit) and int(dataset.attrs.get("recommended_evaluation", -1)) >= 0 and not float(dataset["design_operating_amplitude"].values[0]) <= limit:
        return ("best found (above the operating limit)", *DESIGN_TITLES[1:])  # type: ignore[return-value]
    if linear_wins(dataset):
        return ("best design with a stop", *DESIGN_TITLES[1:])  # type: ignore[return-value]
    if never_strikes(dataset):
        return ("recommended design (its stop never struck)", *DESIGN_TITLES[1:])  # type: ignore[return-value]
    return DESIGN_TITLES  # type: ignore[return-value]


def linear_wins(dataset: xr.Dataset) -> bool:
    """Whether the best linear absorber of the same mass beats the recommended design with a stop: a smaller worst
    case than the recommended design's (screened or certified, whichever is larger), and, with an operating
    constraint, keeping it."""
    d = dataset
    row = d["design_sample_value"].values[2]
    if int(d.attrs.get("recommended_evaluation", -1)) < 0 or not np.any(np.isfinite(row)):
        return False
    limit = operating_limit(d)
    notch = float(d["design_operating_amplitude"].values[2])
    keeps = not math.isfinite(limit) or (math.isfinite(notch) and notch <= limit)
    linear = float(np.nanmax(row))
    return keeps and (linear < design_worst(d, 0) or ties(linear, design_worst(d, 0)))


def warnings(dataset: xr.Dataset) -> list[str]:
    """What got worse, what was not reached, what was not checked: each a sentence, worst first."""
    d = dataset
    out: list[str] = []
    recommended = int(d.attrs.get("recommended_evaluation", -1))
    values = d["design_sample_value"].values
    q, c, limit = objective_quantity(d), constraint_quantity(d), operating_limit(d)
    if np.any(np.isfinite(values[2])) and recommended >= 0 and design_worst(d, 0) >= np.nanmax(values[2]):
        linear_notch = float(d["design_operating_amplitude"].values[2])
        keeps = math.isfinite(limit) and math.isfinite(linear_notch) and linear_notch > limit
        cost = f", but it has no notch: {c.symbol} at {fmt(d.attrs['operating_frequency_Hz'], '.4g')} Hz is {c.text(linear_notch)}, above the allowed {c.text(limit)}" if keeps else ""
        best_linear = float(np.nanmax(values[2]))
        if ties(best_linear, design_worst(d, 0)):
            out.append(f"Over the band the stop does not pay: the best linear absorber of the same mass does as well ({q.text(best_linear)}, level with the best design with a stop){cost}.")
        else:
            out.append(f"Over the band the stop does not pay: the best linear absorber of the same mass has the smaller worst case ({q.text(best_linear)} against {q.text(design_worst(d, 0))}){cost}.")
    if math.isfinite(limit) and recommended >= 0:
        operating = float(d["operating_amplitude"].values[recommended])
        if not operating <= limit:
            tail = "; the best linear absorber does" if linear_wins(d) else "; the recommendation is the least bad"
            out.append(f"No design with a stop keeps the notch: at {fmt(d.attrs['operating_frequency_Hz'], '.4g')} Hz {c.symbol} reaches {c.text(operating)} against the allowed {c.text(limit)}{tail}.")
    if recommended >= 0:
        rows = np.flatnonzero(d["certificate_evaluation"].values == recommended)
        uncovered = float(np.nanmax(d["sample_uncovered"].values[recommended]))
        checked = "the certification found the motions there by brute force" if rows.size else "nothing checked it"
        if uncovered > 0.0:
            if d.attrs.get("screen") == "bumper_orbits":
                out.append(f"On {fmt(100 * uncovered, '.2g')} % of the band the screen found no stable period-1 motion of the {design_titles(d)[0]} (none there, or a bumper orbit its shots did not reach): there its motion may be one the screen does not know (more contacts, a longer period, or not periodic); the screen guessed its size from the rigid twin's orbits, and {checked}.")
            else:
                out.append(f"On {fmt(100 * uncovered, '.2g')} % of the band no period-1 motion of the {design_titles(d)[0]} is stable: there its motion is of a kind the closed forms do not know (more impacts, a longer period, or not periodic); the screen guessed its size from the unstable orbits, and {checked}.")
        if not rows.size:
            out.append(f"The {design_titles(d)[0]} was not certified (certify: candidates 0): its worst case is the screen's alone.")
        for r in rows:
            worst, screened = float(d["certificate_worst"].values[r]), float(d["certificate_screened"].values[r])
            if math.isfinite(worst) and worst > screened * (1.0 + 1e-6):
                out.append(f"The certification found a larger stable motion than the screen under {sample_name(int(d['certificate_sample'].values[r]))}: {q.text(worst)}, {motion_noun(str(d['certificate_motion'].values[r]))} at {fmt(d['certificate_frequency'].values[r], '.4g')} Hz, against {q.text(screened)}.")
            cut = _cut_branches(d, int(r))
            if cut:
                out.append(cut)
            error = str(d["certificate_error"].values[r])
            if error:
                out.append(f"The certification of {sample_name(int(d['certificate_sample'].values[r]))} failed: {error}")
    ridge = float(d.attrs.get("equal_peak_difference", math.nan))
    if math.isfinite(ridge) and ridge < 0.02:
        f1, f2 = (float(x) for x in np.atleast_1d(d.attrs["equal_peak_frequencies_Hz"]))
        out.append(f"The {design_titles(d)[0]} sits on an equal-peak ridge: its two largest band maxima ({fmt(f1, '.4g')} and {fmt(f2, '.4g')} Hz) differ by {fmt(100 * ridge, '.2g')} %; a small change of any variable raises one of them.")
    if d.sizes.get("certificate", 0):
        points = d.sizes.get("attractor_point", 0)
        out.append(f"What the certification can miss: an attractor whose basin none of its runs entered (sweeps both ways and two more starts at each of {points} frequencies), or one that lives only between those frequencies; "
                   + ("the search itself ranked candidates on period-1 bumper orbits shot from the rigid twin's closed forms, which a design with a larger multi-contact or non-periodic motion can fool until it is certified."
                      if d.attrs.get("screen") == "bumper_orbits" else
                      "the search itself ranked candidates on closed forms (period-1 motions), which a design with a larger multi-impact or non-periodic motion can fool until it is certified."
                      if not np.any(d["sample_motion"].values == 3) else "the search itself ranked candidates by a coarse brute force (no closed form applies to this layout), whose grid and few starts a narrow or rarely reached motion escapes."))
    for failure in d.attrs.get("run_failures", []) if isinstance(d.attrs.get("run_failures"), list) else []:
        out.append(str(failure))
    out += cautions(d)  # a variable on its bound, a mistuning cut off, an impacting motion near the operating frequency
    return out


def _cut_branches(d: xr.Dataset, row: int) -> str:
    """What certificate ``row`` says of its branches that stopped at the continuation's step limit ("": none)."""
    if "branch_cut" not in d:
        return ""
    cut = d["branch_cut"].values[row] == 1.0  # exact: a 0/1 flag
    if not np.any(cut):
        return ""
    frequency, amplitude, stable = (d[name].values[row][cut] for name in ("branch_frequency", "branch_amplitude", "branch_stable"))
    count = np.unique(d["branch_index"].values[row][cut]).size
    steady = amplitude[stable == 1.0]  # exact: a 0/1 flag
    q = objective_quantity(d)  # the branches' amplitude is the objective's measure
    stable_text = f", stable up to {q.text(float(np.max(steady)))}" if steady.size else ", none of it stable"
    return (f"The certification of {sample_name(int(d['certificate_sample'].values[row]))} followed {count} branch{'es' if count > 1 else ''} only as far as the continuation's "
            f"step limit ({ContinuationSettings().max_steps} steps): between {fmt(float(np.min(frequency)), '.4g')} and {fmt(float(np.max(frequency)), '.4g')} Hz, {q.symbol} up to "
            f"{q.text(float(np.max(amplitude)))} on {'them' if count > 1 else 'it'}{stable_text}; past that point {'they are' if count > 1 else 'it is'} not known, and only the brute force looked there.")
