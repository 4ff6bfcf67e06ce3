"""Time-domain steady states of the absorber concepts, as cases for :meth:`vibroimpact.runs.runner.Runner.map`.

A case is one concept over a chunk of frequencies. At each frequency the ``exact`` engine marches the rigid stops to
their steady state (from the closed-form impact orbit where the package has one, else from the linear steady state,
or rest if that starts inside a stop), and, when the scene has a bumper, the ``compliant`` engine marches each stop's
Kelvin-Voigt twin from that rigid steady state (where the rigid motion impacts; elsewhere that impactless motion is the
bumpers' too): its peak contact acceleration and force, the fundamental of the force on the base, and the peak of that
force in the time domain from a dense replay (:mod:`~vibroimpact.kinds.concepts.cases`), whose agreement with the engine is recorded. Every value is per frequency; a point that fails is NaN and flagged, never fatal.
"""

from __future__ import annotations

import math
import sys
import time
from dataclasses import dataclass, asdict

import numpy as np
from numpy.typing import NDArray
from scipy.integrate import solve_ivp

from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.engines.registry import make_engine
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.kinds.concepts.branches import march
from vibroimpact.simulation.steady import motion_scale, start_state
from vibroimpact.kinds.concepts.scene import Concept
from vibroimpact.model.contact import KelvinVoigtBumper
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.runs.runner import CaseResult, ProgressReport
from vibroimpact.runs.fingerprints import case_key
from vibroimpact.simulation.settings import SteadySettings

__all__ = ["Replay", "replay_base_force", "SAMPLES_PER_PERIOD", "ConceptCase", "CASE_FIELDS", "COMPLEX_FIELDS"]


# --------------------------------------------------------------------------------------------------------------------
# The force on the base in the time domain with Kelvin-Voigt bumpers: a dense replay of a bumper steady state.
# --------------------------------------------------------------------------------------------------------------------

#: Samples of the force per excitation period (a 250 Hz bumper's contact of ~2 ms at 25 Hz: ~100 samples).
SAMPLES_PER_PERIOD = 4000


@dataclass(frozen=True)
class Replay:
    """A dense replay.

    Attributes
    ----------
    peak_base_force : float
        Largest |f(t)| over the replayed periods [N].
    end_state : ndarray, shape (2 N,)
        State after the periods.
    times, base_force : ndarray
        The samples [s] and f(t) [N].
    """

    peak_base_force: float
    end_state: NDArray[np.float64]
    times: NDArray[np.float64]
    base_force: NDArray[np.float64]


def replay_base_force(problem: ImpactProblem, t0: float, y0: NDArray[np.float64], periods: int = 1, rtol: float = 1e-10) -> Replay:
    """Integrate ``periods`` periods of ``problem`` (bumper stops only) from (``t0`` [s], ``y0``) and sample the force
    on the base."""
    stops = problem.stops
    if not all(isinstance(stop.law, KelvinVoigtBumper) for stop in stops):
        raise TypeError("replay_base_force: every stop must be a KelvinVoigtBumper")
    structure = problem.structure
    n = problem.size
    m, k, c = structure.mass_matrix, structure.stiffness_matrix, structure.damping_matrix
    minv = np.linalg.inv(m)
    harmonic, static = problem.load()
    normals, clearances = problem.normals(), problem.clearances()
    m_eff = np.array([stop.effective_mass(m) for stop in stops])
    omega_b = np.array([stop.law.omega for stop in stops])  # type: ignore[union-attr]
    xi = np.array([stop.law.loss_factor for stop in stops])  # type: ignore[union-attr]
    spring, dashpot = m_eff * omega_b**2, 2.0 * m_eff * xi * omega_b
    w = problem.omega
    ones = np.ones(n)
    through = normals.sum(axis=1)

    def contact(y: NDArray[np.float64]) -> NDArray[np.float64]:
        gap = clearances - normals @ y[:n]
        rate = -(normals @ y[n:])
        return np.where(gap < 0.0, np.maximum(spring * (-gap) + dashpot * (-rate), 0.0), 0.0)

    def field(t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        force = (harmonic * complex(math.cos(w * t), math.sin(w * t))).real + static - normals.T @ contact(y) - k @ y[:n] - c @ y[n:]
        return np.concatenate([y[n:], minv @ force])

    end = t0 + periods * problem.period
    times = t0 + np.arange(periods * SAMPLES_PER_PERIOD + 1) * (problem.period / SAMPLES_PER_PERIOD)
    y = np.asarray(y0, dtype=float)
    scale = float(np.max(np.abs(y[:n]))) + 1e-12
    # the dashpot's force jumps at a contact's onset: DOP853's error control shrinks the step onto it (no restart needed)
    solution = solve_ivp(field, (t0, end), y, method="DOP853", t_eval=times, rtol=rtol, max_step=0.05 / float(np.max(omega_b / (2.0 * math.pi))),
                         atol=rtol * scale * np.concatenate([np.ones(n), np.full(n, w)]))  # fmt: skip
    if solution.status != 0:
        raise RuntimeError(f"replay failed: {solution.message}")
    samples = solution.y.T
    lam = np.array([contact(sample) for sample in samples])
    force = samples[:, :n] @ k.T @ ones + samples[:, n:] @ c.T @ ones + lam @ through
    return Replay(float(np.max(np.abs(force))), samples[-1].copy(), times, force)

#: Complex fields of a case result (fundamental amplitudes).
COMPLEX_FIELDS = ("x1", "x2", "base_force", "bumper_x1", "bumper_base_force")
#: Fields of a case result, one value per frequency (``end_state``: one row of 2 N per frequency).
CASE_FIELDS = (
    *COMPLEX_FIELDS,
    "impacts_per_period",
    "impulse_per_period",
    "converged",
    "multiplicity",
    "failed",
    "end_time",
    "end_state",
    "bumper_impacts_per_period",
    "bumper_converged",
    "bumper_peak_acceleration",
    "bumper_peak_contact_force",
    "bumper_peak_base_force",
    "bumper_replay_mismatch",
    "bumper_failed",
    "wall_time",
)
#: Most periods a bumper twin marches where the rigid motion is not periodic either: enough to leave the rigid
#: attractor's neighbourhood for the bumper's, whose impacts are then measured over ``irregular_measure_periods``.
SETTLE_PERIODS = 60
#: Periods replayed densely where the bumper motion is not periodic (for its time-domain peak base force).
REPLAY_PERIODS = 4
#: Most periods a bumper twin marches from the rigid steady state (IDA costs ~4 ms a period; from the rigid orbit a
#: periodic bumper motion repeats within ~20-60).
MAX_BUMPER_PERIODS = 200


@dataclass(frozen=True)
class ConceptCase:
    """One concept over some frequencies.

    Attributes
    ----------
    concept : Concept
        The system and its rigid stops (at least one).
    amplitude : float
        q [N] on the primary mass.
    frequencies : tuple of float
        [Hz].
    engine_settings : EngineSettings
        Tolerances of the bumper's integrator.
    steady_settings : SteadySettings
        Convergence and measurement.
    bumper_frequency : float
        Omega_b / 2 pi of the bumper twins [Hz]; NaN: no bumper run.
    """

    concept: Concept
    amplitude: float
    frequencies: tuple[float, ...]
    engine_settings: EngineSettings
    steady_settings: SteadySettings
    bumper_frequency: float = math.nan

    engine = "exact"
    fields = CASE_FIELDS
    progress_unit = "points"

    @property
    def progress_total(self) -> float:
        """Frequency points in the case."""
        return float(len(self.frequencies))

    def key(self) -> str:
        """A stable hash of everything that determines the result (and of the package's source)."""
        return case_key({"kind": "concepts", "concept": asdict(self.concept), "amplitude": self.amplitude, "frequencies": list(self.frequencies),
                         "engine_settings": asdict(self.engine_settings), "steady_settings": asdict(self.steady_settings), "bumper": self.bumper_frequency})  # fmt: skip

    def run(self, report: ProgressReport | None = None) -> CaseResult:
        """Steady states at every frequency of the case."""
        n = len(self.frequencies)
        size = self.concept.system.size
        out: dict[str, NDArray] = {name: np.full(n, np.nan, dtype=complex if name in COMPLEX_FIELDS else float) for name in CASE_FIELDS}
        out["end_state"] = np.full((n, 2 * size), np.nan)
        rigid = make_engine("exact")
        bumper = make_engine("compliant", self.engine_settings) if math.isfinite(self.bumper_frequency) else None
        for i, frequency in enumerate(self.frequencies):
            started = time.perf_counter()
            problem = self.concept.problem(self.amplitude, frequency)
            try:
                t, y = start(self.concept, problem, self.steady_settings)
                outcome = march(rigid, problem, t, y, self.steady_settings)
            except (RuntimeError, ValueError, TypeError, ArithmeticError, np.linalg.LinAlgError) as error:
                print(f"concept {self.concept.name}: exact, f = {frequency:g} Hz failed: {error}", file=sys.stderr)
                out["failed"][i] = 1.0
                out["wall_time"][i] = time.perf_counter() - started
                continue
            m = outcome.measures
            out["x1"][i], out["x2"][i], out["base_force"][i] = m.displacements[0], m.displacements[1], m.force
            out["impacts_per_period"][i], out["impulse_per_period"][i] = m.impacts_per_period, m.impulse_per_period
            out["converged"][i], out["multiplicity"][i], out["failed"][i] = float(outcome.converged), float(outcome.multiplicity), 0.0
            out["end_time"][i], out["end_state"][i] = outcome.time, outcome.state
            if bumper is not None and m.impacts_per_period == 0.0:
                # the rigid steady state never touches: it is the bumpers' too (the same linear motion, no contact)
                out["bumper_x1"][i], out["bumper_base_force"][i] = m.displacements[0], m.force
                out["bumper_impacts_per_period"][i], out["bumper_converged"][i], out["bumper_failed"][i] = 0.0, float(outcome.converged), 0.0
                out["bumper_peak_acceleration"][i] = out["bumper_peak_contact_force"][i] = 0.0
                out["bumper_peak_base_force"][i], out["bumper_replay_mismatch"][i] = abs(m.force), 0.0
            elif bumper is not None:
                self._bumper(bumper, frequency, outcome.time, outcome.state, out, i, MAX_BUMPER_PERIODS if outcome.converged else SETTLE_PERIODS)
            out["wall_time"][i] = time.perf_counter() - started
            if report is not None:
                report(float(i + 1))
        return out

    def _bumper(self, engine: object, frequency: float, t: float, y: NDArray[np.float64], out: dict[str, NDArray], i: int, periods: int) -> None:
        """The bumper twins' steady state from the rigid one (t [s], y), marching at most ``periods``."""
        problem = self.concept.problem(self.amplitude, frequency, bumper_frequency=self.bumper_frequency)
        try:
            outcome = march(engine, problem, t, y, self.steady_settings, min(self.steady_settings.max_periods, periods))
            periods = outcome.multiplicity if outcome.converged else REPLAY_PERIODS
            replay = replay_base_force(problem, outcome.time, outcome.state, periods)
            check = engine.integrate(problem, outcome.state, outcome.time, periods)  # type: ignore[attr-defined]
        except (RuntimeError, ValueError, TypeError, ArithmeticError, np.linalg.LinAlgError) as error:
            print(f"concept {self.concept.name}: compliant, f = {frequency:g} Hz failed: {error}", file=sys.stderr)
            out["bumper_failed"][i] = 1.0
            return
        m = outcome.measures
        out["bumper_x1"][i], out["bumper_base_force"][i] = m.displacements[0], m.force
        out["bumper_impacts_per_period"][i] = m.impacts_per_period
        out["bumper_converged"][i], out["bumper_failed"][i] = float(outcome.converged), 0.0
        out["bumper_peak_acceleration"][i], out["bumper_peak_contact_force"][i] = m.peak_acceleration, m.peak_contact_force
        scale = motion_scale(problem)
        out["bumper_peak_base_force"][i] = replay.peak_base_force
        out["bumper_replay_mismatch"][i] = float(np.max(np.abs(replay.end_state - check.final_state) / scale))


def start(concept: Concept, problem: ImpactProblem, settings: SteadySettings) -> tuple[float, NDArray[np.float64]]:
    """Where the rigid march starts: on the closed-form impact orbit where it exists and is admissible (moved by the
    settings' start perturbation, so that an unstable orbit is left), else the linear steady state (rest if that is
    inside a stop)."""
    length = problem.length_scale()
    nudge = settings.start_perturbation * length * np.eye(1, 2 * problem.size, 0)[0]
    try:
        orbit = solve_impact_orbit(problem)
    except ValueError:  # no closed form for this layout
        return start_state(problem, "linear")
    if bool(orbit.admissible()):
        return 0.0, orbit.state_at(np.zeros(1))[0] + nudge
    return start_state(problem, "linear")
