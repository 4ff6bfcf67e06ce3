"""The dataset of a design study: every evaluation, the mistuning samples, the certificates, and the designs the
page compares (the recommended one, the scene's own, the optimum linear absorber) with their frequency responses.

Dimensions: ``evaluation`` (every candidate, in the order evaluated), ``sample`` (the mistuning samples, 0 the
nominal design), ``certificate`` (each problem certified by continuation) with ``point`` (its branches' points),
``design`` (the compared designs, named by ``design_name``) and ``frequency`` [Hz] (their responses). Every
coordinate variable is numeric; labels are auxiliary variables (CF 1.8).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.analysis.layout import closed_form_refusal
from vibroimpact.orbits.bumper_screen import bumper_curves, bumper_screen_refusal
from vibroimpact.analysis.linear import linear_amplitudes
from vibroimpact.analysis.measures import Measure, as_measure
from vibroimpact.analysis.stability import MARGINAL_MODULUS, floquet_multipliers
from vibroimpact.kinds.design.evaluate import ATTRACTOR_POINTS, MAX_BRANCH_POINTS, OPERATING_STARTS, SCREEN_MOTIONS, SCREENS, SWEEP_ACCURACIES, screen_kind
from vibroimpact.simulation.certified_worst import SOURCES
from vibroimpact.kinds.design.scene import DesignSettings, safe_name
from vibroimpact.kinds.design.search import STAGES, pareto_front
from vibroimpact.kinds.design.outcome import Outcome
from vibroimpact.model.problem import ImpactProblem

__all__ = ["design_dataset", "response_curves", "equal_peaks", "RESPONSE_POINTS", "DESIGNS", "RIDGE"]

#: Frequencies of the compared designs' responses.
RESPONSE_POINTS = 601
#: The compared designs, in the order of the ``design`` dimension.
DESIGNS = ("recommended", "scene", "linear_optimum")
#: Two band maxima within this share of each other make an equal-peak ridge [-].
RIDGE = 0.02


def response_curves(problem: ImpactProblem, frequency: NDArray[np.float64], measure: Measure | int) -> dict[str, NDArray[np.float64]]:
    """The ``measure`` (a coordinate index: its |X| [m]) of the contact-free motion (everywhere), whether it fits; and of each root's period-1 impact orbit
    where it exists, with its state (-1 none or not admissible, 0 unstable, 1 stable; bumpers: the orbit grown from
    the rigid twin's root, :func:`~vibroimpact.orbits.bumper_screen.bumper_curves`; none on a layout without a closed
    form)."""
    omega = 2.0 * np.pi * frequency
    measure = as_measure(measure, problem)
    linear = linear_amplitudes(problem, omega=omega)
    out = {"linear": measure.of_harmonics(problem, omega, linear.amplitudes), "linear_fits": linear.fits(problem.clearances()).astype(np.int8)}
    bumpers = bool(problem.stops) and bumper_screen_refusal(problem) is None
    grown = bumper_curves(problem, frequency, measure) if bumpers else {}  # bumper orbits grown from the rigid twin's
    for root, name in (("+", "impact_plus"), ("-", "impact_minus")):
        x, state = np.full(frequency.shape, np.nan), np.full(frequency.shape, -1, dtype=np.int8)
        if bumpers:
            x, state = grown[root]
        elif problem.stops and closed_form_refusal(problem) is None:
            orbit = solve_impact_orbit(problem, frequency=frequency, root=root)
            ok = np.flatnonzero(np.asarray(orbit.admissible(), dtype=bool).reshape(-1))
            if ok.size:
                taken = orbit.take(ok)
                x[ok] = measure.of_orbit(taken).reshape(-1)
                modulus = np.max(np.abs(floquet_multipliers(taken)), axis=-1)
                state[ok] = np.where(modulus < 1.0 - MARGINAL_MODULUS, 1, 0)
        out[name], out[f"{name}_stable"] = x, state
    return out


def equal_peaks(frequency: NDArray[np.float64], curves: dict[str, NDArray[np.float64]]) -> tuple[float, float, float]:
    """(relative difference, f1, f2) of the two largest local maxima of the worst stable motion's |X| [Hz]; NaN
    where it has fewer than two. A point beside a gap (no stable motion known there) is no maximum: the curve may rise
    into the gap."""
    stable = [np.where(curves["linear_fits"] == 1, curves["linear"], np.nan)]
    stable += [np.where(curves[f"{n}_stable"] == 1, curves[n], np.nan) for n in ("impact_plus", "impact_minus")]
    worst = np.fmax.reduce(stable)
    filled = np.where(np.isfinite(worst), worst, np.nan)
    last = filled.size - 1
    peaks = [i for i in range(filled.size) if np.isfinite(filled[i]) and all(np.isfinite(filled[j]) and filled[i] >= filled[j] for j in (max(i - 1, 0), min(i + 1, last)))]
    if len(peaks) < 2:
        return math.nan, math.nan, math.nan
    top = sorted(peaks, key=lambda i: filled[i], reverse=True)[:2]
    return float((filled[top[0]] - filled[top[1]]) / filled[top[0]]), float(frequency[top[0]]), float(frequency[top[1]])


def _flag(values: Any, meanings: tuple[str, ...], long_name: str, dims: tuple[str, ...]) -> xr.Variable:
    return xr.Variable(dims, np.asarray(values, dtype=np.int8), {"long_name": long_name, "flag_values": np.arange(len(meanings), dtype=np.int8),
                                                                  "flag_meanings": " ".join(m.replace(" ", "_").replace(",", "") for m in meanings)})  # fmt: skip


def design_dataset(scene: Any, outcome: Outcome) -> xr.Dataset:
    """Assemble the dataset (module docstring)."""
    settings: DesignSettings = outcome.settings
    ev, space = outcome.evaluations, outcome.space
    unit, _, generic = measure_words(settings.measure)
    limit_unit, limit_symbol, _ = measure_words(settings.constraint)
    E, S = len(ev.scores), space.samples
    designs = np.array(ev.designs)
    data: dict[str, xr.Variable] = {}
    for k, v in enumerate(settings.variables):
        data[f"variable_{safe_name(v.name)}"] = xr.Variable("evaluation", designs[:, k], {"units": v.unit, "long_name": f"design variable {v.name}", "valid_min": v.low, "valid_max": v.high})
    values = np.array([ev.values(r) for r in ev.results])
    data["objective"] = xr.Variable("evaluation", [ev.objective(r) for r in ev.results], {"units": unit, "long_name": f"{settings.objective}: the {_quantile(settings.quantile)} over the samples of the largest stable {generic} over the band (closed-form screen)"})
    data["score"] = xr.Variable("evaluation", ev.scores, {"units": unit, "long_name": "the objective raised by the operating constraint's penalty (what the search minimised)"})
    data["operating_amplitude"] = xr.Variable("evaluation", [ev.operating(r) for r in ev.results], {"units": limit_unit, "long_name": f"worst coexisting {'|X|' if limit_symbol == '|X1|' else limit_symbol} at the operating frequency, same quantile"})
    data["feasible"] = _flag([ev.feasible(r) for r in ev.results], ("violates", "holds"), "the operating constraint", ("evaluation",))
    data["evaluation_stage"] = _flag(ev.stages, STAGES, "why the candidate was evaluated", ("evaluation",))
    data["sample_value"] = xr.Variable(("evaluation", "sample"), values, {"units": unit, "long_name": f"largest stable {generic} over the band under each sample (or the guess where uncovered)"})
    data["sample_frequency"] = xr.Variable(("evaluation", "sample"), np.array([r["frequency"] for r in ev.results]), {"units": "Hz", "long_name": "where the sample's worst case is"})
    data["sample_motion"] = _flag(np.array([r["motion"] for r in ev.results]), SCREEN_MOTIONS, "the motion that sets the sample's worst case", ("evaluation", "sample"))
    data["sample_uncovered"] = xr.Variable(("evaluation", "sample"), np.array([r["uncovered"] for r in ev.results]), {"units": "1", "long_name": "share of the band where no closed-form motion is stable"})
    impulses = np.array([r["impulse"] for r in ev.results], dtype=float)
    data["sample_impulse"] = xr.Variable(("evaluation", "sample"), impulses, {"units": "N s", "long_name": "largest impulse of one impact of the stable closed-form impact orbits on the scan (0: none impacts; NaN: screened by brute force; a lower bound where the band is partly uncovered)"})
    uncovered = np.array([r["uncovered"] for r in ev.results], dtype=float)
    # where a sample's band is partly uncovered its impulse is a lower bound; an impulse of 0 there (no impact orbit
    # stable anywhere) says nothing about the unknown motions: no value, off the front
    worst_impulse = np.array([float(np.max(row)) if np.all(np.isfinite(row)) and not (np.max(row) <= 0.0 and np.any(gap > 0.0)) else math.nan for row, gap in zip(impulses, uncovered)])
    data["impulse"] = xr.Variable("evaluation", worst_impulse, {"units": "N s", "long_name": "largest impulse of one impact over the samples (a lower bound where a sample's band is partly uncovered; NaN where it is 0 there)"})
    front = pareto_front(data["objective"].values, worst_impulse, [ev.feasible(r) for r in ev.results])
    data["pareto_front"] = _flag(front, ("dominated", "on_the_front"), "no other feasible candidate has a smaller or equal objective and impulse, one smaller", ("evaluation",))
    for key, units, name in (("operating_period", "1", "period of the motion that sets the sample's operating value [excitation periods]"),
                             ("operating_impacts", "1", "its impacts per period"), ("operating_starts", "1", f"how many of the screen's {OPERATING_STARTS} runs at the operating frequency reached it (0: a closed form's motion no run reached)")):  # fmt: skip
        data[f"sample_{key}"] = xr.Variable(("evaluation", "sample"), np.array([r[key] for r in ev.results], dtype=float), {"units": units, "long_name": name})
    data["sample_operating"] = xr.Variable(("evaluation", "sample"), np.array([r["operating"] for r in ev.results], dtype=float),
                                           {"units": limit_unit, "long_name": f"largest {limit_symbol} at the operating frequency under each sample over every motion the screen found there"})  # fmt: skip
    corners = ev.corners if S > 1 else 0
    data["sample_kind"] = _flag([0] + [1] * corners + [2] * (S - 1 - corners), SAMPLE_KINDS, "what the sample is: the nominal design, a corner of the tolerance box, or a Latin-hypercube sample", ("sample",))
    for k, m in enumerate(settings.mistuning):
        offsets = np.array([row[k] for row in space.offsets])
        data[f"mistuning_{safe_name(m.name)}"] = xr.Variable("sample", offsets, {"units": "1" if m.relative else ("m" if m.name == "clearance" else "1"),
                                                                                  "long_name": f"{'relative' if m.relative else 'absolute'} offset of {m.name} in each sample (sample 0: the nominal design)"})  # fmt: skip
    _certificates(data, outcome)
    attrs = _designs(data, scene, outcome)
    coords = {"evaluation": ("evaluation", np.arange(E, dtype=np.int32), {"units": "1", "long_name": "index of the candidate, in the order evaluated"}),
              "sample": ("sample", np.arange(S, dtype=np.int32), {"units": "1", "long_name": "mistuning sample (0: the nominal design)"}),
              "certificate": ("certificate", np.arange(len(outcome.certified), dtype=np.int32), {"units": "1", "long_name": "index of the certified problem"}),
              "point": ("point", np.arange(MAX_BRANCH_POINTS, dtype=np.int32), {"units": "1", "long_name": "index of a continued orbit"}),
              "attractor_point": ("attractor_point", np.arange(ATTRACTOR_POINTS, dtype=np.int32), {"units": "1", "long_name": "index of a brute-force frequency"}),
              "accuracy": ("accuracy", np.arange(len(SWEEP_ACCURACIES), dtype=np.int32), {"units": "1", "long_name": "index of sweep_accuracy"}),
              "design": ("design", np.arange(len(DESIGNS), dtype=np.int32), {"units": "1", "long_name": "index of the compared design (design_name)"})}  # fmt: skip
    for part in ("search", "certification", "box"):  # timings are variables: the golden suite and the page's fixed timings know them by long name
        data[f"{part}_wall_time"] = xr.Variable((), outcome.wall_times.get(part, math.nan), {"units": "s", "long_name": f"wall time of the {part}"})
    dataset = xr.Dataset(data, coords=coords)
    dataset.attrs.update(attrs)
    dataset.attrs.update({"band_low_Hz": settings.band[0], "band_high_Hz": settings.band[1], "objective": settings.objective,
                          "quantile": settings.quantile, "samples": settings.samples, "mistuning_seed": settings.seed, "search_method": settings.search.method,
                          "variables": ", ".join(v.name for v in settings.variables), "operating_frequency_Hz": settings.operating[0] if settings.operating else math.nan,
                          "operating_limit_m": settings.operating[1] if settings.operating else math.nan, "recommended_evaluation": outcome.recommended,
                          "excitation_amplitude_N": scene.amplitude, "screen": screen_kind(outcome.space.problem)})  # fmt: skip
    limited = settings.constraint
    if limited is not None and limited.name != "x1_amplitude":  # the notch of the primary is the default: no attribute
        dataset.attrs["operating_measure"] = limited.name
        if limited.unit != "m":  # the limit's attribute names its unit
            dataset.attrs[f"operating_limit_{limited.unit}"] = dataset.attrs.pop("operating_limit_m")
    errors = sorted({str(e) for r in ev.results for e in np.asarray(r["error"]).reshape(-1) if str(e)})
    if errors:
        dataset.attrs["run_failures"] = [f"{sum(1 for r in ev.results for e in np.asarray(r['error']).reshape(-1) if str(e))} samples of candidates have no value (scored infinite): {errors[0]}"]
    return dataset


def measure_words(measure: Measure | None) -> tuple[str, str, str]:
    """(unit, symbol, the generic symbol of a band's worst case) of a measure for the dataset's attributes: (m, |X1|,
    |X|) of a displacement, (N, |F|, |F|) of the base force; None: the primary's |X1| (the notch)."""
    if measure is None:
        return "m", "|X1|", "|X|"
    return measure.unit, measure.symbol, "|X|" if measure.coordinate is not None else measure.symbol


def _quantile(q: float) -> str:
    return "worst" if q >= 1.0 else f"{q:g} quantile"


#: What a mistuning sample is (``sample_kind``).
SAMPLE_KINDS = ("nominal", "corner", "random")


def _certificates(data: dict[str, xr.Variable], outcome: Outcome) -> None:
    rows = outcome.certified
    dims = ("certificate",)
    unit, symbol, _ = measure_words(outcome.settings.measure)

    def column(key: str) -> NDArray[np.float64]:
        return np.array([float(r[key]) for r in rows], dtype=float)

    data["certificate_evaluation"] = xr.Variable(dims, np.array([r["evaluation"] for r in rows], dtype=np.int32), {"units": "1", "long_name": "the certified candidate (index of evaluation)"})
    data["certificate_sample"] = xr.Variable(dims, np.array([r["sample"] for r in rows], dtype=np.int32), {"units": "1", "long_name": "the certified mistuning sample"})
    for key, units, name in (("worst", unit, f"certified largest stable {symbol} over the band: the larger of continuation and brute force, located exactly where continued"),
                             ("frequency", "Hz", "where the certified worst case is"), ("screened", unit, "the closed-form screen's value of the same problem"),
                             ("continuation_worst", unit, f"largest stable {symbol} of the branches continued from the closed-form orbits"),
                             ("continuation_time", "s", "wall time of the continuation"), ("brute_worst", unit, f"largest {symbol} of any attractor the brute force found (a grid sample)"),
                             ("brute_frequency", "Hz", "where the brute force found it"), ("brute_time", "s", "wall time of the brute force (and of continuing from its orbit)"),
                             ("screen_time", "s", "wall time of the closed-form screen of the same problem (the search's objective)")):  # fmt: skip
        data[f"certificate_{key}"] = xr.Variable(dims, column(key), {"units": units, "long_name": name})
    data["certificate_wall_time"] = xr.Variable(dims, column("continuation_time") + column("brute_time"), {"units": "s", "long_name": "wall time of the certification (continuation and brute force)"})
    data["certificate_source"] = _flag([max(int(r["source"]), 0) for r in rows], SOURCES, "which method sets the certified worst case", dims)
    data["certificate_motion"] = xr.Variable(dims, np.array([str(r["motion"]) for r in rows], dtype=str), {"long_name": "the motion that sets the certified worst case"})
    data["certificate_brute_motion"] = xr.Variable(dims, np.array([str(r["brute_motion"]) for r in rows], dtype=str), {"long_name": "the motion of the brute force's largest attractor"})
    data["certificate_error"] = xr.Variable(dims, np.array([str(r["error"]) for r in rows], dtype=str), {"long_name": "why a certification failed (empty: it did not)"})
    data["certificate_impacting"] = xr.Variable(dims, column("impacting"), {"units": "1", "long_name": "1 where a stable motion found in the band (a continued branch or a brute-force attractor) strikes a stop"})
    limit_unit, limit_symbol, _ = measure_words(outcome.settings.constraint)
    for key, units, name in (("operating_worst", limit_unit, f"largest {limit_symbol} at the operating frequency over every motion found there (closed forms, seeded runs with their periodic orbits shot, the brute force's attractors)"),
                             ("screened_operating", limit_unit, f"the screen's {limit_symbol} at the operating frequency for the same problem"),
                             ("operating_period", "1", "period of the motion that sets it [excitation periods]"), ("operating_impacts", "1", "its impacts per period"),
                             ("operating_runs", "1", "seeded runs at the operating frequency"), ("operating_time", "s", "wall time of the operating point's runs and shots")):  # fmt: skip
        data[f"certificate_{key}"] = xr.Variable(dims, column(key), {"units": units, "long_name": name})
    data["certificate_operating_motion"] = xr.Variable(dims, np.array([str(r["operating_motion"]) for r in rows], dtype=str), {"long_name": "the motion that sets the certified operating value"})
    data["certificate_operating_reached"] = xr.Variable(dims, np.array([str(r["operating_reached"]) for r in rows], dtype=str), {"long_name": "which runs reached it"})
    offsets = np.array([outcome.box["offset"] if r["sample"] < 0 and outcome.box else outcome.space.offsets[max(int(r["sample"]), 0)] for r in rows], dtype=float).reshape(len(rows), len(outcome.space.mistuned))
    for k, name in enumerate(outcome.space.mistuned):
        data[f"certificate_offset_{safe_name(name)}"] = xr.Variable(dims, offsets[:, k], {"units": "1" if outcome.space.relative[k] else ("m" if name == "clearance" else "1"), "long_name": f"offset of {name} of the certified problem (sample -1: the tolerance box's worst point)"})
    data["sweep_accuracy"] = xr.Variable("accuracy", np.array(SWEEP_ACCURACIES), {"units": "1", "long_name": "relative accuracy of a band maximum"})
    data["certificate_sweep_points"] = xr.Variable(("certificate", "accuracy"), np.array([r["sweep_points"] for r in rows], dtype=float).reshape(len(rows), len(SWEEP_ACCURACIES)),
                                                   {"units": "1", "long_name": "frequencies a stepped sweep needs to reach the certified maximum to the accuracy (from the curvature of its branch there)"})  # fmt: skip
    data["certificate_sweep_time"] = xr.Variable(("certificate", "accuracy"), np.array([r["sweep_time"] for r in rows], dtype=float).reshape(len(rows), len(SWEEP_ACCURACIES)),
                                                 {"units": "s", "long_name": "what that stepped sweep (one direction) costs at the brute force's measured wall time per point and run"})  # fmt: skip
    for key, units, name in (("frequency", "Hz", "frequency of a continued orbit"), ("amplitude", unit, f"{symbol} of a continued orbit"), ("stable", "1", "1 where the continued orbit is stable"),
                             ("impacts", "1", "impacts per period of a continued orbit"), ("index", "1", "which branch of its certificate"),
                             ("cut", "1", "1 where the continued orbit's branch stopped at the continuation's step limit (followed no further)")):  # fmt: skip
        block = np.array([r[f"branch_{key}"] for r in rows], dtype=float).reshape(len(rows), MAX_BRANCH_POINTS)
        data[f"branch_{key}"] = xr.Variable(("certificate", "point"), block, {"units": units, "long_name": name})
    for key, units, name in (("frequency", "Hz", "frequency of the brute force"), ("amplitude", unit, f"largest {symbol} of the attractors the brute force found there (every run)")):
        block = np.array([r[f"attractor_{key}"] for r in rows], dtype=float).reshape(len(rows), ATTRACTOR_POINTS)
        data[f"attractor_{key}"] = xr.Variable(("certificate", "attractor_point"), block, {"units": units, "long_name": name})


def _designs(data: dict[str, xr.Variable], scene: Any, outcome: Outcome) -> dict[str, object]:
    """The compared designs' variables, objectives and responses; the answer's attributes."""
    settings, ev, space = outcome.settings, outcome.evaluations, outcome.space
    unit, _, generic = measure_words(settings.measure)
    limit_unit, limit_symbol, _ = measure_words(settings.constraint)
    frequency = np.linspace(settings.band[0], settings.band[1], RESPONSE_POINTS)
    problems: list[ImpactProblem | None] = [space.problem_at(ev.designs[outcome.recommended]) if outcome.recommended >= 0 else None, space.problem]
    linear_problem = None
    if outcome.linear is not None:
        structure = outcome.linear.system
        far = 1e3 * space.problem.length_scale()
        out_of_reach = scene.layout.problem(scene.amplitude, settings.band[0], settings.restitution, far)  # the linear absorber has no stop
        linear_problem = ImpactProblem(structure, out_of_reach.stops, out_of_reach.harmonic)
    problems.append(linear_problem)
    keys = ("linear", "linear_fits", "impact_plus", "impact_plus_stable", "impact_minus", "impact_minus_stable")
    curves = {k: np.full((len(DESIGNS), frequency.size), np.nan) for k in keys}
    for d, problem in enumerate(problems):
        if problem is None:
            continue
        for k, v in response_curves(problem, frequency, settings.measure).items():
            curves[k][d] = v
    rows = ("design", "frequency")
    data["design_name"] = xr.Variable("design", np.array(DESIGNS, dtype=str), {"long_name": "the compared design"})
    data["response_frequency"] = xr.Variable("frequency", frequency, {"units": "Hz", "long_name": "excitation frequency of the compared designs' responses"})
    data["response_linear"] = xr.Variable(rows, curves["linear"], {"units": unit, "long_name": f"{generic} of the contact-free motion (where it fits: response_linear_fits)"})
    for name in ("linear_fits", "impact_plus_stable", "impact_minus_stable"):
        meanings = ("hits_a_stop", "clears_the_stops") if name == "linear_fits" else ("unstable", "stable")
        data[f"response_{name}"] = xr.Variable(rows, np.nan_to_num(curves[name], nan=-1).astype(np.int8), {"long_name": name.replace("_", " "), "_FillValue": np.int8(-1),
                                                                                                           "flag_values": np.array([0, 1], dtype=np.int8), "flag_meanings": " ".join(meanings)})  # fmt: skip
    for name in ("impact_plus", "impact_minus"):
        data[f"response_{name}"] = xr.Variable(rows, curves[name], {"units": unit, "long_name": f"{generic} of the admissible period-1 impact orbit, root {name[-5:]} of the impulse equation"})
    values = np.full((len(DESIGNS), space.samples), np.nan)
    if outcome.recommended >= 0:
        values[0] = ev.values(ev.results[outcome.recommended])
    values[1] = ev.values(ev.results[0])
    values[2] = outcome.linear_values
    # each stated operating value: the screen's over the samples, raised by every certificate of that design
    # the largest over every sample (corners included, whatever the quantile) and every certificate: a stated number
    operating = [float(np.fmax(np.nanmax(np.asarray(ev.results[i]["operating"], dtype=float), initial=-np.inf), outcome.corrected_operating.get(i, -math.inf)))
                 if i >= 0 and math.isfinite(ev.limit) else math.nan for i in (outcome.recommended, 0)] + [outcome.linear_operating]  # fmt: skip
    certified_at = [max((float(c.get("operating_worst", math.nan)) for c in outcome.certified if c["evaluation"] == i and math.isfinite(float(c.get("operating_worst", math.nan)))), default=-math.inf) for i in (outcome.recommended, 0)]
    operating[:2] = [max(v, c) if math.isfinite(v) or math.isfinite(c) else math.nan for v, c in zip(operating[:2], certified_at)]
    data["design_operating_amplitude"] = xr.Variable("design", np.array(operating, dtype=float), {"units": limit_unit, "long_name": f"worst coexisting {limit_symbol} at the operating frequency over the samples and every motion found there, certificates included (NaN: no constraint)"})
    data["design_sample_value"] = xr.Variable(("design", "sample"), values, {"units": unit, "long_name": f"largest stable {generic} over the band of each compared design under each sample"})
    for k, v in enumerate(settings.variables):
        column = [ev.designs[outcome.recommended][k] if outcome.recommended >= 0 else math.nan, ev.designs[0][k], math.nan]
        if outcome.linear is not None and v.name in ("k2", "b2"):
            column[2] = getattr(outcome.linear.system, v.name)
        data[f"design_{safe_name(v.name)}"] = xr.Variable("design", np.array(column, dtype=float), {"units": v.unit, "long_name": f"{v.name} of the compared design"})
    closed = outcome.recommended >= 0 and screen_kind(space.problem) == SCREENS[0]  # a ridge of the closed forms' curves only (a bumper's have gaps where shots fail)
    ridge = equal_peaks(frequency, {k: curves[k][0] for k in keys}) if closed else (math.nan, math.nan, math.nan)
    attrs: dict[str, object] = {"equal_peak_difference": ridge[0], "equal_peak_frequencies_Hz": np.array(ridge[1:], dtype=float)}
    if outcome.linear is not None:
        attrs.update({"linear_optimum_tuning": outcome.linear.tuning, "linear_optimum_damping_ratio": outcome.linear.damping_ratio,
                      "linear_optimum_k2_N_per_m": outcome.linear.system.k2, "linear_optimum_b2_N_s_per_m": outcome.linear.system.b2,
                      f"linear_optimum_worst_{settings.measure.unit}": outcome.linear.worst})  # fmt: skip
    if outcome.recommended >= 0:
        attrs["recommended_certified_score_m"] = outcome.corrected.get(outcome.recommended, math.nan)
        attrs["recommended_contradicted"] = np.array(outcome.contradicted, dtype=np.int32)  # candidates whose certificate broke the constraint their screen kept
    attrs["operating_absorber_alone"] = outcome.alone  # the scene's absorber without its stop at the operating frequency (NaN: the structure is a design variable)
    if outcome.box:
        attrs.update({"box_worst_screened": float(outcome.box["screened"]), "box_worst_sample": int(outcome.box["sample"]), "box_evaluations": int(outcome.box["evaluations"]),
                      "box_worst_offsets": np.array(outcome.box["offset"], dtype=float)})  # fmt: skip
    paper = space.problem.named_view()
    attrs["static_deflection_m"] = abs(scene.amplitude) / paper.k1 if paper is not None else math.nan
    return attrs
