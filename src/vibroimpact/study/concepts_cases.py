"""Time-domain steady states of the absorber concepts, as cases for :func:`vibroimpact.study.runner.run_cases`.

A case is one concept over a chunk of frequencies. At each frequency the ``exact`` engine marches the rigid stops to
their steady state (from the closed-form impact orbit where the package has one, else from the linear steady state,
or rest if that starts inside a stop), and, when the scene has a bumper, the ``compliant`` engine marches each stop's
Kelvin-Voigt twin from that rigid steady state: its peak contact acceleration and force, and the fundamental of the
force on the base. Every value is per frequency; a point that fails is NaN and flagged, never fatal.
"""

from __future__ import annotations

import math
import sys
import time
from dataclasses import asdict, dataclass

import numpy as np
from numpy.typing import NDArray

from vibroimpact.engines.registry import make_engine
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.scene.concepts import Concept
from vibroimpact.simulation.settings import SteadySettings
from vibroimpact.study.concepts_steady import linear_start, march
from vibroimpact.study.fingerprint import case_key
from vibroimpact.study.runner import CaseResult, ProgressReport

__all__ = ["ConceptCase", "CASE_FIELDS", "COMPLEX_FIELDS"]

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
    "bumper_failed",
    "wall_time",
)
#: Most periods a bumper twin marches from the rigid steady state (IDA costs ~4 ms a period).
MAX_BUMPER_PERIODS = 400


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
            out["x1"][i], out["x2"][i], out["base_force"][i] = m.x[0], m.x[1], m.base_force
            out["impacts_per_period"][i], out["impulse_per_period"][i] = m.impacts_per_period, m.impulse_per_period
            out["converged"][i], out["multiplicity"][i], out["failed"][i] = float(outcome.converged), float(outcome.multiplicity), 0.0
            out["end_time"][i], out["end_state"][i] = outcome.time, outcome.state
            if bumper is not None:
                self._bumper(bumper, frequency, outcome.time, outcome.state, out, i)
            out["wall_time"][i] = time.perf_counter() - started
            if report is not None:
                report(float(i + 1))
        return out

    def _bumper(self, engine: object, frequency: float, t: float, y: NDArray[np.float64], out: dict[str, NDArray], i: int) -> None:
        """The bumper twins' steady state from the rigid one (t [s], y)."""
        problem = self.concept.problem(self.amplitude, frequency, bumper_frequency=self.bumper_frequency)
        try:
            outcome = march(engine, problem, t, y, self.steady_settings, min(self.steady_settings.max_periods, MAX_BUMPER_PERIODS))
        except (RuntimeError, ValueError, TypeError, ArithmeticError, np.linalg.LinAlgError) as error:
            print(f"concept {self.concept.name}: compliant, f = {frequency:g} Hz failed: {error}", file=sys.stderr)
            out["bumper_failed"][i] = 1.0
            return
        m = outcome.measures
        out["bumper_x1"][i], out["bumper_base_force"][i] = m.x[0], m.base_force
        out["bumper_impacts_per_period"][i] = m.impacts_per_period
        out["bumper_converged"][i], out["bumper_failed"][i] = float(outcome.converged), 0.0
        out["bumper_peak_acceleration"][i], out["bumper_peak_contact_force"][i] = m.peak_acceleration, m.peak_contact_force


def start(concept: Concept, problem: ImpactProblem, settings: SteadySettings) -> tuple[float, NDArray[np.float64]]:
    """Where the rigid march starts: on the closed-form impact orbit (slightly perturbed, so that an unstable orbit is
    left) where the package has one, else the linear steady state (rest if that is inside a stop)."""
    if concept.paper_layout:
        from vibroimpact.simulation.steady import pgf_guesses

        guess = pgf_guesses(problem, [problem.frequency])[0]
        if guess is not None:
            t, y = guess
            length = problem.velocity_scale() / problem.omega
            return t, np.asarray(y, dtype=float) + settings.start_perturbation * length * np.eye(1, y.size, 0)[0]
    return 0.0, linear_start(problem)
