"""The ``concepts`` kind of study: absorber concepts side by side (which absorber, with which stop) over one band.

For every concept of the scene (:mod:`vibroimpact.kinds.concepts.scene`):

1. closed forms on the fine grid (:mod:`~vibroimpact.kinds.concepts.study`): the linear steady state, and the impact orbit with its
   Floquet stability where a closed form applies;
2. time-domain steady states on the simulation grid (:mod:`~vibroimpact.kinds.concepts.cases`): the rigid stops through ``exact``, and
   each stop's Kelvin-Voigt twin through ``compliant`` for the peak impact acceleration and contact force;
3. branches continued in frequency from the simulated periodic motions and the closed-form orbit
   (:mod:`~vibroimpact.kinds.concepts.branches`): stable and unstable stretches;
4. the worst stable response and the figures of merit (:mod:`~vibroimpact.measures.figures_of_merit`).

Steps 2 and 3 run in ``jobs`` processes through :meth:`vibroimpact.runs.runner.Runner.map` (resumable cache).
Output contract: dimensions ``concept`` (names), ``frequency`` [Hz] (fine grid), ``simulation_frequency`` [Hz] and
``point`` (continued orbits); see :func:`concepts_dataset` for the variables.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.analysis.linear import base_force, linear_amplitudes
from vibroimpact.analysis.stability import MARGINAL_MODULUS, floquet_multipliers
from vibroimpact.kinds.concepts.branches import BranchCase, branch_seeds
from vibroimpact.kinds.concepts.cases import CASE_FIELDS, ConceptCase
from vibroimpact.measures.figures_of_merit import anti_resonance_band, band_metrics, envelope, stretches
from vibroimpact.kinds.concepts.scene import Concept, ConceptsSettings
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.runs.cluster import Progress
from vibroimpact.runs.estimate import Costs, Estimate
from vibroimpact.runs.runner import Runner
from vibroimpact.engines.registry import BUMPER, RIGID, engine_for

__all__ = ["ClosedForms", "closed_forms", "MARGINAL_MODULUS", "concepts_dataset", "ConceptsStudy", "run_concepts", "CHUNK"]


# --------------------------------------------------------------------------------------------------------------------
# The closed forms of each absorber concept on the fine frequency grid: the linear steady state (no stop, or a stop
# it does not reach), and the impact orbit where a closed form applies, with its admissibility and Floquet stability.
# --------------------------------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class ClosedForms:
    """A concept's closed forms at ``frequency``.

    Attributes
    ----------
    frequency : ndarray, shape (F,)
        [Hz].
    linear_x1, linear_base_force : ndarray, shape (F,)
        |X1| [m] and |base force| [N] of the linear steady state without a stop (fundamental amplitudes).
    linear_fits : ndarray of bool, shape (F,)
        The linear motion stays clear of every stop (always true without one): it is then a stable steady state.
    impact_x1, impact_base_force : ndarray, shape (F,)
        The same of the closed-form impact orbit where it exists and is admissible; NaN elsewhere.
    impact_stable : ndarray of int8, shape (F,)
        1 stable, 0 unstable, -1 no admissible orbit or stability unknown.
    impacts_per_period : int
        Of the impact orbit (1; 2 for a two-sided stop); 0 without one.
    note : str
        Why no impact orbit is given, if none is.
    """

    frequency: NDArray[np.float64]
    linear_x1: NDArray[np.float64]
    linear_base_force: NDArray[np.float64]
    linear_fits: NDArray[np.bool_]
    impact_x1: NDArray[np.float64]
    impact_base_force: NDArray[np.float64]
    impact_stable: NDArray[np.int8]
    impacts_per_period: int = 0
    note: str = ""


def closed_forms(concept: Concept, amplitude: float, frequency: NDArray[np.float64]) -> ClosedForms:
    """Linear and impact closed forms of ``concept`` under q = ``amplitude`` [N] on the primary mass."""
    f = np.asarray(frequency, dtype=float)
    w = 2.0 * np.pi * f
    problem = ImpactProblem(concept.system, concept.stops, HarmonicForce(amplitude, float(f[0])))  # without a stop too
    linear = linear_amplitudes(problem, omega=w)
    x = linear.amplitudes
    base = base_force(problem.structure, w, x)
    fits = linear.fits(problem.clearances())  # always true without a stop
    nan = np.full(f.shape, np.nan)
    empty = ClosedForms(f, np.abs(x[:, 0]), np.abs(base), fits, nan, nan, np.full(f.shape, -1, dtype=np.int8))
    if not concept.stops:
        return empty
    return _orbit(concept, amplitude, empty)


def _orbit(concept: Concept, amplitude: float, linear: ClosedForms) -> ClosedForms:
    """The general closed form (one stop, or a symmetric two-sided pair) with its Floquet multipliers; a layout that
    has none (e.g. two stops on different coordinates) gets a note instead."""
    problem = concept.problem(amplitude, float(linear.frequency[0]))
    try:
        orbit = solve_impact_orbit(problem, omega=2.0 * np.pi * linear.frequency)
    except ValueError as error:
        return _with_note(linear, f"no closed form: {error}")
    admissible = orbit.admissible()
    x1 = np.where(admissible, np.abs(orbit.harmonics()[..., 0]), np.nan)
    force = np.where(admissible, np.abs(orbit.base_force()), np.nan)  # suspension and absolute stops
    stable = np.full(orbit.omega.shape, -1, dtype=np.int8)
    index = np.flatnonzero(admissible)
    if index.size:
        modulus = np.max(np.abs(floquet_multipliers(orbit.take(index))), axis=-1)
        stable[index] = np.where(modulus < 1.0 - MARGINAL_MODULUS, 1, 0)
    return ClosedForms(linear.frequency, linear.linear_x1, linear.linear_base_force, linear.linear_fits, x1, force, stable, orbit.impacts_per_period)


def _with_note(linear: ClosedForms, note: str) -> ClosedForms:
    return ClosedForms(linear.frequency, linear.linear_x1, linear.linear_base_force, linear.linear_fits, linear.impact_x1, linear.impact_base_force, linear.impact_stable, 0, note)


# --------------------------------------------------------------------------------------------------------------------
# The dataset of a concepts study: every concept's curves and figures of merit, labelled, with CF units.
# --------------------------------------------------------------------------------------------------------------------

_UNITS = {"x1_amplitude": "m", "base_force_amplitude": "N", "peak_acceleration": "m s-2", "contact_force": "N"}
#: The notch depth is kept in decibels, as the page and the metrics give it; UDUNITS (and so CF) has no dB, so its units
#: are "1" and its long name and comment say the scale.
NOTCH_DEPTH_ATTRIBUTES = {
    "units": "1",
    "long_name": "notch depth in dB: 20 log10 of the smallest worst-stable |X1| in the anti-resonance band over q / k1",
    "comment": "decibels of an amplitude ratio (negative: below the static deflection q / k1); the ratio is 10**(notch_depth / 20)",
}


def _text(spans: list[tuple[float, float]]) -> str:
    return ", ".join(f"{a:.2f}-{b:.2f}" if b > a else f"{a:.2f}" for a, b in spans) or "none"


def concepts_dataset(settings: ConceptsSettings, closed: dict[str, ClosedForms], simulated: dict[str, dict[str, np.ndarray]], branches: dict[str, dict[str, Any]]) -> xr.Dataset:
    """Assemble the dataset (module docstring) from the three kinds of results, keyed by concept name."""
    names = [c.name for c in settings.concepts]
    f, fs = settings.frequency, settings.simulation_frequency
    static = settings.static_deflection
    reference = closed_forms(Concept("reference", "", settings.system), settings.amplitude, f)
    low, high, anti = anti_resonance_band(f, reference.linear_x1, static)
    points = max([b["frequency"].size for b in branches.values()] + [1])
    fine = {k: np.full((len(names), f.size), np.nan) for k in ("linear_x1", "closed_x1", "closed_force", "worst_x1", "worst_force")}
    flags = {k: np.full((len(names), f.size), -1, dtype=np.int8) for k in ("linear_fits", "closed_stable", "worst_impacts")}
    sim_keys = ("x1", "base_force", "impacts_per_period", "impulse_per_period", "converged", "multiplicity", "bumper_x1", "bumper_base_force", "bumper_impacts_per_period",
                "bumper_peak_acceleration", "bumper_peak_contact_force", "bumper_peak_base_force", "bumper_replay_mismatch", "bumper_converged")  # fmt: skip
    sim = {k: np.full((len(names), fs.size), np.nan) for k in sim_keys}
    branch_keys = ("frequency", "x1_amplitude", "base_force_amplitude", "floquet_modulus", "impacts_per_period", "period", "branch")
    orbit = {k: np.full((len(names), points), np.nan) for k in branch_keys}
    per: dict[str, list[Any]] = {k: [] for k in ("peak_x1", "peak_x1_f", "peak_force", "peak_force_f", "accel", "contact", "depth", "depth_f",
                                                 "fraction", "coverage", "band_impacts", "base_peak", "unstable", "nonperiodic", "notes")}  # fmt: skip
    failures: list[str] = []  # one line per concept whose simulations failed somewhere
    for i, concept in enumerate(settings.concepts):
        cf = closed[concept.name]
        fine["linear_x1"][i], fine["closed_x1"][i], fine["closed_force"][i] = cf.linear_x1, cf.impact_x1, cf.impact_base_force
        flags["linear_fits"][i], flags["closed_stable"][i] = cf.linear_fits, cf.impact_stable
        s = simulated.get(concept.name)
        notes = [cf.note] if cf.note else []
        sim_tuple: tuple = (fs, np.full(fs.size, np.nan), np.full(fs.size, np.nan), np.zeros(fs.size))
        if s is not None:
            for k in sim_keys:
                sim[k][i] = np.abs(s[k]) if np.iscomplexobj(s[k]) else s[k]
            sim_tuple = (fs, sim["x1"][i], sim["base_force"][i], sim["impacts_per_period"][i])
            failed = int(np.nansum(s["failed"]) + np.nansum(s["bumper_failed"]))
            if failed:
                notes.append(f"{failed} simulated points failed")
                failures.append(f"concept {concept.name}: {failed} of {fs.size * (2 if math.isfinite(settings.bumper_frequency) else 1)} simulated points failed (rigid stops and bumpers together): "
                                "they are blank (NaN) in the dataset and missing from the figures; the closed forms and the other points are unaffected")
        b = branches.get(concept.name)
        empty = np.zeros(0)
        branch_tuple: tuple = (empty,) * 6
        unstable: list[tuple[float, float]] = []
        if b is not None:
            count = b["frequency"].size
            for k in branch_keys:
                orbit[k][i, :count] = b[k]
            branch_tuple = (b["frequency"], b["x1_amplitude"], b["base_force_amplitude"], b["floquet_modulus"], b["impacts_per_period"], b["branch"])
            unstable = _unstable(b)
            notes.append(str(b["note"][0]))
        if concept.stops:
            closed_unstable = stretches(f, cf.impact_stable == 0, 1.5 * float(np.median(np.diff(f))) if f.size > 1 else 0.0)
            unstable = _union(unstable + closed_unstable)
        worst = envelope(f, (cf.linear_x1, cf.linear_base_force, cf.linear_fits), (cf.impact_x1, cf.impact_base_force, cf.impact_stable, cf.impacts_per_period), sim_tuple, branch_tuple)
        fine["worst_x1"][i], fine["worst_force"][i], flags["worst_impacts"][i] = worst.x1, worst.base_force, worst.impacts
        m = band_metrics(f, worst, (low, high), static)
        nonperiodic = stretches(fs, (sim["converged"][i] == 0.0), 1.5 * float(np.median(np.diff(fs))) if fs.size > 1 else 0.0) if s is not None else []
        accel = np.nanmax(sim["bumper_peak_acceleration"][i]) if np.any(np.isfinite(sim["bumper_peak_acceleration"][i])) else (0.0 if not concept.stops else math.nan)
        contact = np.nanmax(sim["bumper_peak_contact_force"][i]) if np.any(np.isfinite(sim["bumper_peak_contact_force"][i])) else (0.0 if not concept.stops else math.nan)
        # without a stop the force on the base is a pure sinusoid: its time-domain peak is its amplitude
        base_peak = np.nanmax(sim["bumper_peak_base_force"][i]) if np.any(np.isfinite(sim["bumper_peak_base_force"][i])) else (m.peak_force if not concept.stops else math.nan)
        for key, value in (("peak_x1", m.peak_x1), ("peak_x1_f", m.peak_x1_frequency), ("peak_force", m.peak_force), ("peak_force_f", m.peak_force_frequency),
                           ("accel", accel), ("contact", contact), ("base_peak", base_peak), ("depth", m.notch_depth), ("depth_f", m.notch_frequency), ("fraction", m.band_impact_fraction),
                           ("coverage", m.band_coverage), ("band_impacts", _text(m.band_impacts)), ("unstable", _text(unstable)),
                           ("nonperiodic", _text(nonperiodic)), ("notes", "; ".join(n for n in notes if n))):  # fmt: skip
            per[key].append(value)
    cf_dims, sim_dims, pt_dims = ("concept", "frequency"), ("concept", "simulation_frequency"), ("concept", "point")
    data = {
        "label": ("concept", [c.label for c in settings.concepts], {"long_name": "what the concept is"}),
        "absorber": ("concept", [c.absorber for c in settings.concepts], {"long_name": "absorber stiffness and damping, and how they were chosen"}),
        "stops": ("concept", [c.describe_stops() for c in settings.concepts], {"long_name": "rigid stops"}),
        "absorber_stiffness": ("concept", [c.system.k2 for c in settings.concepts], {"units": "N m-1", "long_name": "absorber stiffness k2"}),
        "absorber_damping": ("concept", [c.system.b2 for c in settings.concepts], {"units": "N s m-1", "long_name": "absorber damping b2"}),
        "peak_x1_amplitude": ("concept", per["peak_x1"], {"units": "m", "long_name": "largest |X1| of the worst stable motion over the band"}),
        "peak_x1_frequency": ("concept", per["peak_x1_f"], {"units": "Hz", "long_name": "where |X1| peaks"}),
        "peak_base_force_amplitude": ("concept", per["peak_force"], {"units": "N", "long_name": "largest fundamental of the force on the base (suspension and absolute stops), worst stable motion"}),
        "peak_base_force_frequency": ("concept", per["peak_force_f"], {"units": "Hz", "long_name": "where the base force peaks"}),
        "peak_impact_acceleration": ("concept", per["accel"], {"units": "m s-2", "long_name": "largest contact deceleration with the Kelvin-Voigt bumpers (compliant steady states)"}),
        "peak_contact_force": ("concept", per["contact"], {"units": "N", "long_name": "largest bumper force (time domain, compliant steady states)"}),
        "peak_base_force_bumper": ("concept", per["base_peak"], {"units": "N", "long_name": "largest force on the base in the time domain with the bumpers (dense replay of the compliant steady states; without a stop, the amplitude of the linear one)"}),
        "notch_depth": ("concept", per["depth"], NOTCH_DEPTH_ATTRIBUTES),
        "notch_frequency": ("concept", per["depth_f"], {"units": "Hz", "long_name": "where the notch is deepest"}),
        "band_impact_fraction": ("concept", per["fraction"], {"units": "1", "long_name": "share of the anti-resonance band where the motion impacts"}),
        "band_coverage": ("concept", per["coverage"], {"units": "1", "long_name": "share of the anti-resonance band where a stable motion was found"}),
        "band_impacts": ("concept", per["band_impacts"], {"long_name": "where in the anti-resonance band the motion impacts [Hz]"}),
        "unstable_stretches": ("concept", per["unstable"], {"long_name": "frequencies [Hz] of unstable continued or closed-form orbits"}),
        "nonperiodic_stretches": ("concept", per["nonperiodic"], {"long_name": "simulated frequencies [Hz] where the steady motion is not periodic"}),
        "notes": ("concept", per["notes"], {"long_name": "how the concept's branches and closed forms went"}),
        "linear_x1_amplitude": (cf_dims, fine["linear_x1"], {"units": "m", "long_name": "|X1| of the linear steady state without a stop"}),
        "linear_fits": (cf_dims, flags["linear_fits"], {"long_name": "the linear motion clears every stop", "flag_values": np.array([0, 1], dtype=np.int8), "flag_meanings": "hits_a_stop clears_the_stops"}),
        "closed_x1_amplitude": (cf_dims, fine["closed_x1"], {"units": "m", "long_name": "|X1| of the closed-form impact orbit (admissible)"}),
        "closed_base_force_amplitude": (cf_dims, fine["closed_force"], {"units": "N", "long_name": "base force fundamental of the closed-form impact orbit"}),
        "closed_stable": (cf_dims, flags["closed_stable"], {"long_name": "Floquet stability of the closed-form impact orbit", "flag_values": np.array([-1, 0, 1], dtype=np.int8), "flag_meanings": "none_or_unknown unstable stable"}),
        "worst_x1_amplitude": (cf_dims, fine["worst_x1"], {"units": "m", "long_name": "largest |X1| over the stable motions found"}),
        "worst_base_force_amplitude": (cf_dims, fine["worst_force"], {"units": "N", "long_name": "largest base force fundamental over the stable motions found"}),
        "worst_impacts": (cf_dims, flags["worst_impacts"], {"long_name": "does the motion impact", "flag_values": np.array([-1, 0, 1], dtype=np.int8), "flag_meanings": "unknown no yes"}),
        **{f"simulated_{k}" if not k.startswith("bumper") else k: (sim_dims, sim[k], _attrs(k)) for k in sim_keys},
        **{f"branch_{k}": (pt_dims, orbit[k], _attrs(k)) for k in branch_keys},
    }
    coords = {"concept": names, "frequency": ("frequency", f, {"units": "Hz", "long_name": "excitation frequency"}),
              "simulation_frequency": ("simulation_frequency", fs, {"units": "Hz", "long_name": "excitation frequency of the simulations"}),
              "point": ("point", np.arange(points, dtype=np.int32), {"units": "1", "long_name": "index of the point along each concept's continued branch"})}  # fmt: skip
    dataset = xr.Dataset({k: xr.Variable(*v) for k, v in data.items()}, coords=coords)
    dataset.attrs.update({"band_low_Hz": low, "band_high_Hz": high, "anti_resonance_Hz": anti, "static_deflection_m": static,
                          "excitation_amplitude_N": settings.amplitude, "bumper_frequency_Hz": settings.bumper_frequency})  # fmt: skip
    if failures:
        dataset.attrs["run_failures"] = failures  # said on the page and in the console (vibroimpact.runs.failures)
    return dataset


def _attrs(key: str) -> dict[str, str]:
    units = {"x1": "m", "base_force": "N", "x1_amplitude": "m", "base_force_amplitude": "N", "frequency": "Hz", "impacts_per_period": "1",
             "bumper_x1": "m", "bumper_base_force": "N", "bumper_peak_acceleration": "m s-2", "bumper_peak_contact_force": "N", "floquet_modulus": "1",
             "bumper_impacts_per_period": "1", "period": "1", "multiplicity": "1", "impulse_per_period": "N s",
             "bumper_peak_base_force": "N", "bumper_replay_mismatch": "1"}  # fmt: skip
    out = {"long_name": key.replace("_", " ")}
    if key in units:
        out["units"] = units[key]
    return out


def _unstable(branch: dict[str, Any]) -> list[tuple[float, float]]:
    """Frequency spans [Hz] between consecutive unstable orbits of one branch."""
    f, modulus, label = (np.asarray(branch[k], dtype=float) for k in ("frequency", "floquet_modulus", "branch"))
    spans = [tuple(sorted((float(f[a]), float(f[a + 1])))) for a in range(f.size - 1) if label[a] == label[a + 1] and modulus[a] >= 1.0 and modulus[a + 1] >= 1.0]
    return _union(spans)  # type: ignore[arg-type]


def _union(spans: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """Overlapping or touching spans (within 0.02 Hz) joined, sorted."""
    out: list[tuple[float, float]] = []
    for a, b in sorted(spans):
        if out and a <= out[-1][1] + 0.02:
            out[-1] = (out[-1][0], max(out[-1][1], b))
        else:
            out.append((a, b))
    return out

#: Frequencies per simulation case (load balancing between processes).
CHUNK = 8
#: Costs of :meth:`ConceptsStudy.estimate` on the calibration machine: seconds per simulated frequency point of one
#: concept (exact march, bumper twin and replay where it impacts), per continued concept, and for the report. Measured
#: on the shipped scene: 100 s with --jobs 2 on 2 cores shared at load ~3 (warm caches; 171 s compiling from a fresh
#: tree), the speed probe reading 1.2-2.7 over that hour.
SECONDS_PER_POINT = 0.12
SECONDS_PER_BRANCH_CASE = 8.0
SECONDS_REPORT = 10.0


def run_concepts(settings: ConceptsSettings, progress: Progress | None = None, runner: Runner | None = None) -> xr.Dataset:
    """Every concept's closed forms, simulations and branches, and the figures of merit (module docstring)."""
    say = progress if progress is not None else (lambda message: None)
    runner = runner if runner is not None else Runner(progress=progress is not None)
    closed = {c.name: closed_forms(c, settings.amplitude, settings.frequency) for c in settings.concepts}
    say(f"closed forms of {len(closed)} concepts on {settings.frequency.size} frequencies")
    stopped = [c for c in settings.concepts if c.stops]
    cases, owners = [], []
    for concept in stopped:
        for first in range(0, settings.simulation_frequency.size, CHUNK):
            chunk = tuple(float(f) for f in settings.simulation_frequency[first : first + CHUNK])
            cases.append(ConceptCase(concept, settings.amplitude, chunk, settings.engine, settings.steady, settings.bumper_frequency))
            owners.append(concept.name)
    results = runner.map(cases)
    simulated: dict[str, dict[str, np.ndarray]] = {}
    for concept in stopped:
        parts = [r for r, owner in zip(results, owners) if owner == concept.name]
        simulated[concept.name] = {name: np.concatenate([p[name] for p in parts]) for name in CASE_FIELDS}
    say(f"simulated {len(stopped)} concepts on {settings.simulation_frequency.size} frequencies")
    branches: dict[str, dict[str, Any]] = {}
    if settings.continuation_steps > 0 and stopped:
        low, high = float(settings.frequency[0]), float(settings.frequency[-1])
        branch_cases = []
        for concept in stopped:
            s = simulated[concept.name]
            seeds = branch_seeds(settings.simulation_frequency, s["converged"], s["multiplicity"], s["impacts_per_period"], s["end_state"], s["end_time"])
            branch_cases.append(BranchCase(concept, settings.amplitude, low, high, seeds, settings.continuation_steps))
        for concept, result in zip(stopped, runner.map(branch_cases)):
            branches[concept.name] = result
            say(f"{concept.name}: {str(result['note'][0])}")
    return concepts_dataset(settings, closed, simulated, branches)


class ConceptsStudy:
    """The ``concepts`` kind: :func:`run_concepts` on the scene's :class:`ConceptsSettings`."""

    name = "concepts"

    @staticmethod
    def engines(scene: Any) -> tuple[str, ...]:
        """The rigid stop's exact engine (simulations and branches); with bumpers, the bumper's closed-form engine
        (branches) and the integrator the simulations cross-check it with."""
        settings: ConceptsSettings = scene.settings
        rigid = engine_for(RIGID, "exact_jacobians")
        if not math.isfinite(settings.bumper_frequency):
            return (rigid,)
        return (rigid, engine_for(BUMPER, "exact_jacobians"), "compliant")

    def run(self, scene: Any, progress: Progress | None, runner: Runner) -> xr.Dataset:
        """The scene's dataset (its header is :func:`~vibroimpact.runs.run.run_study`'s), with the structure and load
        every concept shares (:meth:`~vibroimpact.model.layout.Layout.attributes`: ``system_*``, ``excitation_*``).
        The ``stop_*`` attributes are left out: each concept has its own stops (variable ``stops``) and absorber
        (``absorber_stiffness``, ``absorber_damping``), the scene none of its own."""
        dataset = run_concepts(scene.settings, progress, runner)
        shared = scene.layout.attributes(np.array([]), np.array([]))
        dataset.attrs.update({key: value for key, value in shared.items() if not key.startswith("stop_")})
        return dataset

    def estimate(self, scene: Any, jobs: int, costs: Costs) -> Estimate:
        """Predicted wall time and memory on the calibration machine, from this kind's own measured costs per point
        (:data:`SECONDS_PER_POINT`, :data:`SECONDS_PER_BRANCH_CASE`; ``costs`` has none for it)."""
        settings: ConceptsSettings = scene.settings
        stopped = sum(1 for c in settings.concepts if c.stops)
        points = stopped * settings.simulation_frequency.size
        simulations = points * SECONDS_PER_POINT * (1.0 if math.isfinite(settings.bumper_frequency) else 0.1)
        branches = SECONDS_PER_BRANCH_CASE * stopped if settings.continuation_steps else 0.0
        wall = simulations / max(jobs, 1) + branches / max(min(jobs, max(stopped, 1)), 1) + SECONDS_REPORT
        parts = {"simulations": simulations, "continuation": branches, "report": SECONDS_REPORT}
        return Estimate(wall_time=wall, memory=300e6, parts=parts, points={"simulations": f"{points} points of {stopped} concepts"})
