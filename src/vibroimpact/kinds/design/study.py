"""The ``design`` kind of study: which absorber and stop to build.

Every number the answer states is a maximum over every motion the study reached, at every point it names, over the
whole tolerance box (issue 48):

1. The mistuning samples: the nominal design, the corners of the tolerance box (:func:`box_corners`) and a seeded
   Latin hypercube over it (:func:`mistuning_offsets`).
2. The search (:mod:`vibroimpact.kinds.design.search`): differential evolution and a Nelder-Mead polish, or a grid;
   each candidate's worst case under every sample (the closed forms, or bumper orbits grown from them) and its value
   at the operating frequency over every motion the screen finds there (the closed forms and seeded runs from rest,
   the linear state and random states: :mod:`vibroimpact.simulation.point_motions`), through the runner.
3. The comparisons: the scene's own design, and (``compare: linear_optimum``) the H-infinity optimum linear absorber of
   the same mass under the same mistuning (:func:`vibroimpact.analysis.linear_optimum.optimal_linear_absorber`), its
   band peaks exact: in this process, while the workers certify. A limit the absorber alone already breaks at the
   operating frequency is said before the search (:func:`_absorber_alone`).
4. The certification (:class:`~vibroimpact.kinds.design.evaluate.CertifyCase`, :func:`_certify`): the best
   candidates, one at a time, at the nominal sample, the one that sets their objective and the one that sets their
   operating value, and the scene's design at the nominal one: continuation of every branch, brute force over the
   band, and at the operating frequency 64 more runs with every periodic motion shot. A certified value above the
   screen's raises the candidate's score; a certificate that breaks the constraint the screen kept sends the search on
   to the next distinct candidate; the recommendation is the best certified candidate. Its worst case is then sought
   over the whole box (:func:`_box_worst`: a bounded maximisation from the worst sample, certified where it exceeds
   every sample).
5. The dataset (:mod:`vibroimpact.kinds.design.dataset`); the page refuses an answer anything stored contradicts
   (:mod:`vibroimpact.kinds.design.consistency`).
"""

from __future__ import annotations

import itertools
import math
import threading
import time
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import NDArray
from scipy import optimize
from scipy.stats import qmc

from vibroimpact.analysis.linear_optimum import band_peak, linear_measure, optimal_linear_absorber
from vibroimpact.kinds.design.dataset import design_dataset
from vibroimpact.kinds.design.quantity import quantity
from vibroimpact.kinds.design.evaluate import CHUNKS, SCREENS, CertifyCase, DesignSpace, screen_kind, screen_worst
from vibroimpact.kinds.design.outcome import Outcome
from vibroimpact.kinds.design.scene import DesignSettings
from vibroimpact.kinds.design.search import Evaluations, nelder_mead_polish, differential_evolution, grid_search
from vibroimpact.runs.cluster import Progress
from vibroimpact.runs.estimate import Costs, Estimate
from vibroimpact.runs.runner import Runner
from vibroimpact.engines.registry import BUMPER, RIGID, engine_for

__all__ = ["mistuning_offsets", "design_space", "Outcome", "run_design", "DesignStudy", "SECONDS_PER_SAMPLE", "SECONDS_PER_BUMPER_SAMPLE", "SECONDS_PER_CERTIFICATE", "POLISH_BUDGET"]

#: The polish's evaluations (Nelder-Mead's function evaluations).
POLISH_BUDGET = 80
#: Costs of :meth:`DesignStudy.estimate` on the calibration machine: one closed-form worst case (one design, one
#: sample), one bumper screen's (shot orbits, :mod:`vibroimpact.orbits.bumper_screen`) and one certification by
#: continuation [s].
SECONDS_PER_SAMPLE = 0.06
SECONDS_PER_BUMPER_SAMPLE = 0.15
SECONDS_PER_CERTIFICATE = 8.0
#: The screen's runs at the operating frequency, per sample [s] (8 runs of 264 periods, quiet machine).
SECONDS_PER_OPERATING = 0.015


#: The tolerance box's corners are samples where there are at most this many (2^M for M robust scalars); beyond, the
#: box's worst case is the local maximisation's (:func:`_box_worst`) [-].
MAX_CORNERS = 16


def box_corners(settings: DesignSettings) -> int:
    """How many corners of the tolerance box are samples: 2^M for M robust scalars, 0 where that exceeds
    :data:`MAX_CORNERS` or nothing is mistuned."""
    count = 2 ** len(settings.mistuning)
    return count if settings.mistuning and count <= MAX_CORNERS else 0


def mistuning_offsets(settings: DesignSettings) -> NDArray[np.float64]:
    """Offsets of the robust scalars, shape (1 + corners + samples, M): the nominal design (zeros), the corners of
    the box [-spread, +spread] of each (:func:`box_corners`), then a seeded Latin hypercube over the box (the samples:
    statistics of the spread; the corners and the local maximisation bound it)."""
    spreads = np.array([m.spread for m in settings.mistuning], dtype=float)
    if spreads.size == 0 or settings.samples == 0:
        return np.zeros((1, spreads.size))
    corners = np.array(list(itertools.product((-1.0, 1.0), repeat=spreads.size))) * spreads if box_corners(settings) else np.zeros((0, spreads.size))
    unit = qmc.LatinHypercube(d=spreads.size, seed=settings.seed).random(settings.samples)
    return np.vstack([np.zeros(spreads.size), corners, (2.0 * unit - 1.0) * spreads])


def design_space(scene: Any) -> DesignSpace:
    """The scene's problem (its own design) and how its variables and mistuning move it."""
    settings: DesignSettings = scene.settings
    bumper = settings.bumper_frequency is not None  # Kelvin-Voigt bumpers, their loss factor the inverse of R
    problem = scene.layout.problem(scene.amplitude, settings.band[0], settings.restitution, settings.clearance, bumper=bumper,
                                   bumper_frequency=settings.bumper_frequency if bumper else math.nan)  # fmt: skip
    offsets = mistuning_offsets(settings)
    operating = settings.operating[0] if settings.operating is not None else math.nan
    return DesignSpace(problem, settings.names, tuple(m.name for m in settings.mistuning), tuple(m.relative for m in settings.mistuning),
                       tuple(tuple(float(v) for v in row) for row in offsets), settings.band, settings.measure, operating,
                       constraint=settings.constraint if settings.constraint is not None else 0)  # fmt: skip


def run_design(scene: Any, progress: Progress | None = None, runner: Runner | None = None) -> xr.Dataset:
    """Search, compare and certify (module docstring); the dataset."""
    settings: DesignSettings = scene.settings
    say = progress if progress is not None else (lambda message: None)
    runner = runner if runner is not None else Runner(progress=progress is not None)
    space = design_space(scene)
    bounds = np.array([[v.low, v.high] for v in settings.variables])
    limit = settings.operating[1] if settings.operating is not None else math.nan
    evaluations = Evaluations(space, bounds, runner, settings.quantile, limit, box_corners(settings) if space.samples > 1 else 0)
    outcome = Outcome(settings, space, evaluations)
    outcome.alone = _absorber_alone(scene, space)
    if math.isfinite(outcome.alone) and outcome.alone > limit:  # said before any search: a stop must lower what the absorber alone gives
        shown = quantity(space.constraint.name)
        say(f"design: without a stop the scene's absorber already has {shown.symbol} = {shown.text(outcome.alone)} at {space.operating:.4g} Hz, above the allowed {shown.text(limit)}: "
            "only a stop that lowers it there can keep the limit")  # fmt: skip
    start = time.perf_counter()
    evaluations.evaluate(outcome.scene_design[None, :], "reference", verb="design: the scene's own design")
    search = settings.search
    if search.method == "grid":
        say(f"design: a grid of {search.points}^{bounds.shape[0]} candidates, {space.samples} samples each")
        grid_search(evaluations, search.points)
    else:
        say(f"design: differential evolution over {bounds.shape[0]} variables ({search.population * bounds.shape[0]} members, up to {search.generations} generations), {space.samples} samples each")
        differential_evolution(evaluations, search.population, search.generations, search.seed)
        if search.polish:
            nelder_mead_polish(evaluations, POLISH_BUDGET, say if progress is not None else None)
    outcome.wall_times["search"] = time.perf_counter() - start
    say(f"design: {len(evaluations.scores)} candidates evaluated in {outcome.wall_times['search']:.0f} s; best screened worst case {_amount(settings.objective, evaluations.objective(evaluations.results[evaluations.best()]))}")
    # the linear optimum in this process while the workers certify (a certification round often leaves one idle)
    failed: list[BaseException] = []

    def compare() -> None:
        try:
            _linear(outcome, scene.amplitude)
        except BaseException as error:  # said by the main thread, after the certification
            failed.append(error)

    # a daemon, not waited for after a Ctrl-C or SIGTERM: the run stops at once, not once it is done (design_vs_linear's
    # took 27 s at load 6); an interpreter that exits does not wait for it either
    linear = threading.Thread(target=compare, name="linear optimum", daemon=True) if settings.compare == "linear_optimum" else None
    if linear is not None:
        linear.start()
    interrupted = False
    try:
        _certify(outcome, runner, say)
    except KeyboardInterrupt:
        interrupted = True
        raise
    finally:
        if linear is not None and not interrupted:
            linear.join()
    if failed:
        raise failed[0]
    return design_dataset(scene, outcome)


def _absorber_alone(scene: Any, space: DesignSpace) -> float:
    """The constraint's value at the operating frequency of the scene's absorber without its stop, where no design
    variable changes the structure (NaN otherwise, or without a constraint): the closed form that shows a limit
    infeasible before any search."""
    if not math.isfinite(space.operating) or any(name not in ("clearance", "restitution", "bumper_stiffness") for name in space.variables):
        return math.nan
    system = space.problem.named_view()
    if system is None:
        return math.nan
    return float(linear_measure(system, scene.amplitude, 2.0 * math.pi * space.operating, space.constraint))


def _linear(outcome: Outcome, amplitude: float) -> None:
    """The optimum linear absorber of the same mass under the same (structural) mistuning, and its band peak under
    every sample."""
    space = outcome.space
    primaries = [space.problem_at(outcome.scene_design, s).named_view() for s in range(space.samples)]
    if any(p is None for p in primaries):
        return
    outcome.linear = optimal_linear_absorber(primaries[0], amplitude, space.band, mistuned=tuple(primaries[1:]), measure=space.objective)  # type: ignore[arg-type]
    k2, b2 = outcome.linear.system.k2, outcome.linear.system.b2
    systems = [p.with_absorber(k2, b2) for p in primaries]  # type: ignore[union-attr]
    outcome.linear_values = np.array([band_peak(system, amplitude, space.band, measure=space.objective).amplitude for system in systems])
    if math.isfinite(space.operating):  # the linear absorber's value of the constraint's measure there, worst over the samples
        outcome.linear_operating = max(float(linear_measure(system, amplitude, 2.0 * math.pi * space.operating, space.constraint)) for system in systems)


#: Candidates nearer than this share of each variable's range (in every variable) to one already certified are not
#: certified again: a motion that fooled the screen at one design fools it next to it too [-].
DISTINCT = 0.05


#: Candidates certified beyond ``certify.candidates`` while certificates contradict the screen (a candidate the screen
#: called feasible whose certificate breaks the constraint): the search's evidence returned to it, bounded.
MAX_CONTRADICTED = 4


def _certify(outcome: Outcome, runner: Runner, say: Progress) -> None:
    """Certify candidates one at a time, best screened first, each at its nominal and its worst sample (the first
    round also the scene's design, nominal), up to ``certify.candidates`` distinct ones: certification only raises a
    worst case, so once the best certified score is no larger than the next candidate's screened one, no later
    candidate can beat it and the rounds stop. A certificate that contradicts its screen (the screen kept the operating
    constraint, the certificate breaks it) returns to the search: that candidate is scored on its certificate, its
    neighbours (within :data:`DISTINCT`) are passed over, and one more candidate is certified, up to
    :data:`MAX_CONTRADICTED` more. The recommendation is the best certified candidate (none certified: the best
    screened); its worst case is then sought over the whole tolerance box (:func:`_box_worst`)."""
    evaluations, settings = outcome.evaluations, outcome.settings
    order = [int(i) for i in np.argsort(evaluations.scores, kind="stable") if math.isfinite(evaluations.scores[int(i)])]
    span = evaluations.bounds[:, 1] - evaluations.bounds[:, 0]
    reference = next(i for i, s in enumerate(evaluations.stages) if s == 3)  # the scene's own design, evaluated first
    chosen: list[int] = []
    outcome.wall_times["certification"] = 0.0
    for i in order:
        if len(chosen) >= settings.certified + len(outcome.contradicted) or len(outcome.contradicted) > MAX_CONTRADICTED:
            break
        if chosen and min(outcome.corrected[j] for j in chosen) <= evaluations.scores[i]:
            break  # no candidate screened this high can be certified lower
        if any(np.all(np.abs(evaluations.designs[i] - evaluations.designs[j]) <= DISTINCT * span) for j in chosen):
            continue
        targets = [i] + ([reference] if not chosen and reference != i else [])  # none certified: the scene's design neither
        chosen.append(i)
        _certify_round(outcome, runner, targets, chosen)
        if not _holds(outcome, i) and (evaluations.feasible(evaluations.results[i]) or not math.isfinite(outcome.corrected[i])):
            outcome.contradicted.append(i)
            say(f"design: the certificate of candidate {len(chosen)} (evaluation {i}) breaks the constraint its screen kept: {_operating_text(outcome, i)}; certifying the next candidate")
        say(f"design: certified candidate {len(chosen)} (evaluation {i}): {_worst_text(outcome, i)}")
    outcome.recommended = min(chosen, key=lambda i: outcome.corrected[i]) if chosen else (order[0] if order else -1)
    if chosen:
        say(f"design: certified {len(chosen)} candidates by continuation, brute force and the operating point's runs in {outcome.wall_times['certification']:.0f} s; recommended evaluation {outcome.recommended}")
    _box_worst(outcome, runner, say)


def _holds(outcome: Outcome, i: int) -> bool:
    """Candidate ``i``'s certificates all succeeded and its certified operating value keeps the limit (always,
    without a constraint)."""
    if any(str(c.get("error", "")) for c in outcome.certified if c["evaluation"] == i):
        return False  # a failed certificate certifies nothing
    limit = outcome.evaluations.limit
    return not math.isfinite(limit) or outcome.corrected_operating.get(i, math.inf) <= limit


def _operating_text(outcome: Outcome, i: int) -> str:
    """``0.776 mm at 33 Hz (a period-4 motion, 1 impact per 4 periods, reached from rest and from 63 of 63 other
    starts)`` of candidate ``i``'s largest certified operating value."""
    rows = [c for c in outcome.certified if c["evaluation"] == i and math.isfinite(float(c.get("operating_worst", math.nan)))]
    if not rows:
        return "not certified there"
    top = max(rows, key=lambda c: float(c["operating_worst"]))
    shown = quantity(outcome.settings.constraint.name) if outcome.settings.constraint is not None else quantity(outcome.settings.objective)
    return f"{shown.text(float(top['operating_worst']))} at {outcome.space.operating:.4g} Hz ({top['operating_motion']}, {top['operating_reached']})"


def _certify_round(outcome: Outcome, runner: Runner, targets: list[int], chosen: list[int]) -> None:
    """Certify ``targets`` (candidates in ``chosen``: the nominal sample and the one that sets the objective, the
    worst with quantile 1; others: nominal) in one batch; each one's score becomes the penalised score of its corrected
    objective and operating value (:func:`_corrected`)."""
    evaluations = outcome.evaluations
    cases, owners = [], []
    done = {(c["evaluation"], c["sample"]) for c in outcome.certified}  # the scene's design, certified in the first round
    for i in targets:
        values = evaluations.values(evaluations.results[i])
        # the sample that sets the objective (its quantile; the worst with quantile 1) and the one that sets the
        # operating value; the scene's design: nominal only
        worst_sample = int(np.nanargmin(np.abs(values - evaluations.objective(evaluations.results[i])))) if np.all(np.isfinite(values)) and i in chosen else 0
        operating = np.asarray(evaluations.results[i]["operating"], dtype=float)
        operating_sample = int(np.nanargmax(operating)) if i in chosen and np.any(np.isfinite(operating)) else 0
        for sample in dict.fromkeys((0, worst_sample, operating_sample)):
            if (i, sample) in done:
                continue
            cases.append(CertifyCase(outcome.space, tuple(float(v) for v in evaluations.designs[i]), sample))
            owners.append((i, sample))
    start = time.perf_counter()
    results = runner.map(cases) if cases else []
    outcome.wall_times["certification"] += time.perf_counter() - start
    for (i, sample), result in zip(owners, results):
        screened = float(evaluations.values(evaluations.results[i])[sample])
        outcome.certified.append({"evaluation": i, "sample": sample, "screened": screened, "screened_operating": float(np.asarray(evaluations.results[i]["operating"])[sample]), **result})
    for i in targets:
        _corrected(outcome, i)


def _corrected(outcome: Outcome, i: int) -> None:
    """Candidate ``i``'s objective and operating value with each certified sample's raised to its certificate where
    larger (the same rule over the samples), and its score from them: ``outcome.corrected`` and
    ``outcome.corrected_operating``."""
    evaluations = outcome.evaluations
    values = np.array(evaluations.values(evaluations.results[i]), dtype=float)
    operating = np.array(evaluations.results[i]["operating"], dtype=float)
    box = []
    for c in outcome.certified:
        if c["evaluation"] != i:
            continue
        worst, at = float(c["worst"]), float(c.get("operating_worst", math.nan))
        if int(c["sample"]) < 0:  # a point of the box that is no sample
            box.append((worst, at))
            continue
        if math.isfinite(worst):
            values[int(c["sample"])] = max(values[int(c["sample"])], worst)
        if math.isfinite(at):
            operating[int(c["sample"])] = max(operating[int(c["sample"])], at)
    objective, operating_value = evaluations.over_samples(values), evaluations.operating({"operating": operating})
    if evaluations.quantile >= 1.0:  # the worst case is over the whole box
        objective = max([objective] + [w for w, _ in box if math.isfinite(w)])
        operating_value = max([operating_value] + [a for _, a in box if math.isfinite(a)])
    failed = any(str(c.get("error", "")) for c in outcome.certified if c["evaluation"] == i)
    outcome.corrected[i] = math.inf if failed else evaluations.penalised(objective, operating_value)  # a failed certificate: never recommended on the screen's word
    outcome.corrected_operating[i] = operating_value


#: The local maximisation over the tolerance box: its evaluations, and how near the box's worst point must come to a
#: certified one's value for no new certificate to be needed [-].
BOX_BUDGET = 40
BOX_SAME = 1e-6


def _box_worst(outcome: Outcome, runner: Runner, say: Progress) -> None:
    """The recommended design's worst case over the whole tolerance box: a bounded Nelder-Mead maximisation of the
    screen's band worst case over the robust scalars' offsets, started from the worst sample (corners included), and
    where it finds more than every sample, that point certified too (its certificate counts in the worst case).
    ``outcome.box``: the box's worst offsets, the screened value there, and the evaluations spent."""
    space, i = outcome.space, outcome.recommended
    evaluations = outcome.evaluations
    if i < 0 or not space.mistuned or space.samples < 2 or evaluations.quantile < 1.0:
        return
    spreads = np.array([m.spread for m in outcome.settings.mistuning], dtype=float)  # the box itself, corners or not
    values = evaluations.values(evaluations.results[i])
    if not np.all(np.isfinite(values)) or not np.all(spreads > 0.0):
        return
    design = tuple(float(v) for v in evaluations.designs[i])
    kind = screen_kind(space.problem_at(design, 0))
    if kind == SCREENS[2]:
        return  # a brute-force screen: too coarse to climb; the corners stand
    start = time.perf_counter()
    count = [0]

    def negative(unit: NDArray[np.float64]) -> float:
        count[0] += 1
        offset = tuple(float(v) for v in np.clip(unit, -1.0, 1.0) * spreads)
        try:
            found = screen_worst(space.problem_at(design, 0, offset), space.band, space.objective, space.scan, kind)
        except ValueError:
            return 0.0
        return -max(found.amplitude, found.estimate if found.uncovered > 0.0 else 0.0)  # the samples' rule (Evaluations.values)

    worst = int(np.argmax(values))
    begin = np.array(space.offsets[worst]) / spreads
    found = optimize.minimize(negative, begin, method="Nelder-Mead", bounds=[(-1.0, 1.0)] * spreads.size,
                              options={"initial_simplex": _inward_simplex(begin), "maxfev": BOX_BUDGET, "xatol": 1e-4, "fatol": 1e-12})  # fmt: skip
    top = float(-found.fun) if found.fun < -float(values[worst]) else float(values[worst])
    offset = tuple(float(v) for v in np.clip(found.x, -1.0, 1.0) * spreads) if found.fun < -float(values[worst]) else tuple(float(v) for v in space.offsets[worst])
    outcome.box = {"offset": offset, "screened": top, "evaluations": count[0], "sample": worst if top == float(values[worst]) else -1}
    if top > float(np.max(values)) * (1.0 + BOX_SAME) and outcome.settings.certified > 0:
        say(f"design: the tolerance box's worst point is no sample ({_amount(outcome.settings.objective, top)} screened against {_amount(outcome.settings.objective, float(np.max(values)))}); certifying it")
        result = runner.map([CertifyCase(space, design, -1, offset)])[0]
        outcome.certified.append({"evaluation": i, "sample": -1, "screened": top, "screened_operating": math.nan, **result})
        _corrected(outcome, i)
        certified = sorted({int(c["evaluation"]) for c in outcome.certified if int(c["evaluation"]) in outcome.corrected})
        best = min(certified, key=lambda j: outcome.corrected[j])
        if best != i:  # the box's worst point lost it the recommendation: the best certified candidate instead
            say(f"design: the box's worst point raised evaluation {i} above evaluation {best}; recommending {best}")
            outcome.recommended = best
    outcome.wall_times["box"] = time.perf_counter() - start


def _inward_simplex(begin: NDArray[np.float64]) -> NDArray[np.float64]:
    """A first simplex at ``begin`` (a point of [-1, 1]^M), its edges a quarter of the box, pointing inward."""
    step = 0.25 * np.where(begin > 0.0, -1.0, 1.0)
    return np.vstack([begin, begin + np.diag(step)])


def _certified_max(outcome: Outcome, i: int) -> float:
    """The largest certified worst case of candidate ``i`` over its certificates [m] (NaN: none has a value)."""
    return max((float(c["worst"]) for c in outcome.certified if c["evaluation"] == i and math.isfinite(float(c["worst"]))), default=math.nan)


def _worst_text(outcome: Outcome, i: int) -> str:
    """``screened 1.712 mm, certified 2.506 mm`` of candidate ``i`` (its largest certified worst case)."""
    screened = outcome.evaluations.objective(outcome.evaluations.results[i])
    certified = _certified_max(outcome, i)
    return f"screened {_amount(outcome.settings.objective, screened)}, certified {_amount(outcome.settings.objective, certified)}"


def _amount(objective: str, value: float) -> str:
    """``value`` of the measure ``objective`` [SI] in the page's unit for the console (``2.506 mm``, ``73.02 N``)."""
    shown = quantity(objective)
    return f"{shown.scale * value:.4g} {shown.unit}"


class DesignStudy:
    """The ``design`` kind: :func:`run_design` on the scene."""

    name = "design"

    @staticmethod
    def engines(scene: Any) -> tuple[str, ...]:
        """The engine with exact Jacobians for the stops' contact law (the screen's shooting and the certification's
        continuation and brute force)."""
        settings: DesignSettings = scene.settings
        return (engine_for(RIGID if settings.bumper_frequency is None else BUMPER, "exact_jacobians"),)

    def batched_engines(self, scene: Any) -> tuple[str, ...]:
        """The same engine: its runs at the operating frequency and its brute force go many starts to one compiled call."""
        return self.engines(scene)

    def run(self, scene: Any, progress: Progress | None, runner: Runner) -> xr.Dataset:
        """The scene's dataset (its header is :func:`~vibroimpact.runs.run.run_study`'s), with the layout it designs
        (:meth:`~vibroimpact.model.layout.Layout.attributes`, its stops at the scene's own clearance and restitution)."""
        settings: DesignSettings = scene.settings
        dataset = run_design(scene, progress, runner)
        bumper = None if settings.bumper_frequency is None else np.array([settings.bumper_frequency])
        dataset.attrs.update(scene.layout.attributes(np.array([settings.restitution]), np.array([settings.clearance]), bumper))
        return dataset

    def estimate(self, scene: Any, jobs: int, costs: Costs) -> Estimate:
        """Predicted wall time and memory on the calibration machine, from :data:`SECONDS_PER_SAMPLE` and
        :data:`SECONDS_PER_CERTIFICATE`."""
        settings: DesignSettings = scene.settings
        n, samples = len(settings.variables), settings.samples + 1 + box_corners(settings)
        search = settings.search
        candidates = search.points**n if search.method == "grid" else search.population * n * (search.generations + 1) + (POLISH_BUDGET if search.polish else 0)
        per_sample = (SECONDS_PER_BUMPER_SAMPLE if settings.bumper_frequency is not None else SECONDS_PER_SAMPLE) + (SECONDS_PER_OPERATING if settings.operating is not None else 0.0)
        screen = candidates * samples * per_sample
        # at most: three certificates per candidate and the box's worst point (the rounds may stop after the first)
        certify = (3 * settings.certified + 2) * SECONDS_PER_CERTIFICATE + BOX_BUDGET * per_sample
        # a polish step's samples are shared by at most CHUNKS workers (one candidate at a time)
        polish = POLISH_BUDGET * samples * per_sample if search.method != "grid" and search.polish else 0.0
        wall = (screen - polish) / max(jobs, 1) + polish / max(min(jobs, CHUNKS, samples), 1) + certify / max(min(jobs, 2), 1) + 10.0
        return Estimate(wall_time=wall, memory=400e6, parts={"search": screen, "certification": certify, "report": 10.0},
                        points={"search": f"up to {candidates} candidates x {samples} samples"})  # fmt: skip
