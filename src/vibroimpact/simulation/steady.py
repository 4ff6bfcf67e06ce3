"""Steady state at a fixed frequency: integrate until the stroboscopic state repeats, then measure whole periods.

Starts: ``linear`` (the linear steady state; answered without integrating when it stays inside the clearance, since
it is then an exact steady state), ``pgf`` (the exact one-impact orbit of a rigid stop, where it exists: the
problem's own stop, or for a bumper the stop a caller names), ``shooting`` (the periodic orbit that Newton's method
finds from the ``pgf`` orbit on the exact stroboscopic map: where it is stable, the run starts on it; else as
``pgf``), ``rest``, or an explicit state (a frequency sweep passes the previous frequency's end state).

Where the motion does not become periodic, the measured run says what it is (``motion``: quasi-periodic, chaotic or
undecided, with its Lyapunov exponent; :func:`vibroimpact.simulation.periodic.motion_evidence`).

Two refusals (``ValueError``, whatever the engine): a frequency where the harmonic response is ill-conditioned (near an
undamped natural frequency, :func:`~vibroimpact.model.structure.resonance_refusal`: the band the exact engines and the
closed forms refuse too), and a result whose amplitude exceeds :data:`AMPLITUDE_LIMIT` times the scene's scale
(:func:`amplitude_scale`): no physical steady state, whatever its strobes did.
"""

from __future__ import annotations

from collections import deque

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from vibroimpact.engines.base import Engine
from vibroimpact.model.contact import RIGID, RigidStop, Stop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.simulation.harmonics import HarmonicMeasures, measure, gaps, linear_state, resting_state, suspension_force
from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.analysis.layout import closed_form_refusal
from vibroimpact.simulation.periodic import motion_evidence, shoot_orbit
from vibroimpact.simulation.history import TimeHistory, engine_of, linear_history, time_history
from vibroimpact.simulation.settings import START_MODES, SteadySettings
from vibroimpact.model.structure import require_in_range, resonance_refusal
from vibroimpact.orbits.motion import MotionEvidence

__all__ = ["SteadySettings", "SteadyResult", "steady_state", "start_state", "pgf_guesses", "orbit_stop_of", "START_MODES", "strobes_repeat", "motion_scale", "march",
           "AMPLITUDE_LIMIT", "amplitude_scale", "check_steady_problem", "check_amplitude"]

#: Largest fundamental amplitude of a steady state, in multiples of :func:`amplitude_scale` [-]. Impacts remove energy
#: (R <= 1, dissipative bumpers) and limit the stopped coordinates, so a motion 1000 times the clearances plus the
#: linear response at its own frequency is no steady state of the scene. The golden scenes' 498 steady states reach at
#: most 8.0 times it (an impacting orbit at 26.5 Hz, where the linear response is small): a margin of 125.
AMPLITUDE_LIMIT = 1e3



@dataclass(frozen=True)
class SteadyResult:
    """Outcome of :func:`steady_state`.

    Attributes
    ----------
    measures : HarmonicMeasures
        Harmonics, RMS and impact statistics of the measured periods.
    converged : bool
        The stroboscopic state repeated to the tolerance.
    multiplicity : int
        Period of the steady motion in excitation periods (1 for period-one motion; 0 if not converged).
    periods_used : int
        Periods integrated in all, transient plus measurement (0: answered without integrating).
    end_time : float
        Time of the final state [s].
    end_state : ndarray, shape (2 N,)
        Final (x, x') (the paper's (X1, X2, X1', X2')), for the next point of a sweep.
    integrated : bool
        False when the answer is the linear steady state, given without integrating.
    motion : MotionEvidence or None
        Where the motion did not converge (and ``lyapunov_periods`` > 0): what it is, with the evidence.
    search_periods : int
        Periods spent finding the steady state (shooting's map evaluations, or marching), before measuring it.
    engine : Engine or None
        The engine that ran it (for :meth:`history`; not compared).
    problem : ImpactProblem or None
        The problem solved (for :meth:`history`; not compared).
    """

    measures: HarmonicMeasures
    converged: bool
    multiplicity: int
    periods_used: int
    end_time: float
    end_state: NDArray[np.float64] = field(repr=False)
    integrated: bool = True
    motion: MotionEvidence | None = None
    search_periods: int = 0
    engine: Engine | None = field(default=None, repr=False, compare=False)
    problem: ImpactProblem | None = field(default=None, repr=False, compare=False)

    def history(self, periods: int | None = None, samples_per_period: int = 200) -> TimeHistory:
        """The steady motion's time history from :attr:`end_time` on, ``samples_per_period`` samples a period.

        Parameters
        ----------
        periods : int, optional
            Periods to sample; by default the motion's own period (``multiplicity``, 1 if it did not converge).
        samples_per_period : int
            Samples per excitation period (evenly spaced; both ends included).

        Returns
        -------
        TimeHistory
            The engine's run from (:attr:`end_time`, :attr:`end_state`) (:func:`time_history`); where the answer is
            the linear steady state (``integrated`` False: it stays clear of every stop) its closed form x0 + Re(X
            e^{jwt}) (:func:`linear_history`, no contacts, ``engine`` "linear").
        """
        if self.problem is None or (self.integrated and self.engine is None):
            raise ValueError("this result does not know its engine and problem (made by hand, not by steady_state): it has no history")
        periods = max(self.multiplicity, 1) if periods is None else periods
        require_in_range("periods", periods, 1, 1e6)
        require_in_range("samples_per_period", samples_per_period, 1, 1e7)
        if int(periods) * int(samples_per_period) > MAX_HISTORY_SAMPLES:  # checked before anything is allocated
            raise ValueError(f"periods x samples_per_period = {int(periods)} x {int(samples_per_period)} = {int(periods) * int(samples_per_period):.3g} samples is out of range: allowed [1, {MAX_HISTORY_SAMPLES:.0e}] (the history holds every sample)")
        step = self.problem.period / samples_per_period
        times = self.end_time + step * np.arange(int(periods) * int(samples_per_period) + 1)
        if not self.integrated:
            return linear_history(self.problem, times)
        return time_history(self.engine, self.problem, self.end_state, self.end_time, times)  # type: ignore[arg-type]


#: Most samples :meth:`SteadyResult.history` gives (2 N states each: 320 MB for N = 2), checked before it allocates them.
MAX_HISTORY_SAMPLES = 10_000_000


def start_state(problem: ImpactProblem, mode: str, orbit_stop: RigidStop | tuple[Stop, ...] | None = None) -> tuple[float, NDArray[np.float64]]:
    """Initial (time, state) for a start mode; ``pgf`` falls back to ``linear`` where no one-impact orbit exists.

    ``orbit_stop`` is the rigid stop whose one-impact orbit a ``pgf`` start follows (see :func:`orbit_stop_of`).
    ``rest`` is at rest at the static position, on the stops it would cross (a negative clearance); ``linear`` is the
    linear steady state, or ``rest`` where that would start inside a stop.
    """
    if mode not in START_MODES:
        raise ValueError(f"start = {mode!r} is not allowed: use one of {', '.join(START_MODES)}")
    if mode == "rest":
        return 0.0, resting_state(problem)
    if mode in ("pgf", "shooting"):
        guess = pgf_guesses(problem, [problem.frequency], orbit_stop)[0]
        if guess is not None:
            return guess
    state = linear_state(problem).state(problem.omega)
    return (0.0, resting_state(problem)) if np.any(gaps(problem, state) < 0.0) else (0.0, state)


def orbit_stop_of(problem: ImpactProblem, orbit_stop: RigidStop | tuple[Stop, ...] | None = None) -> RigidStop | tuple[Stop, ...]:
    """The rigid stop(s) whose one-impact orbit starts a ``pgf`` run: ``orbit_stop`` if given, else the problem's own
    rigid stops, else (bumpers) the rigid stops of the bumpers' clearances and one-collision restitutions."""
    if orbit_stop is not None:
        return orbit_stop
    if isinstance(problem.contact, RigidStop):
        return problem.contact
    if isinstance(problem.contact, tuple):
        return tuple(stop if stop.rigid else Stop(RigidStop(stop.clearance, stop.law.restitution), stop.coordinate, stop.other, stop.side) for stop in problem.contact)
    return RigidStop(problem.clearance, problem.contact.restitution)


def pgf_guesses(problem: ImpactProblem, frequencies: Sequence[float], orbit_stop: RigidStop | tuple[Stop, ...] | None = None) -> list[tuple[float, NDArray[np.float64]] | None]:
    """The ``pgf`` start (time [s], state) at each of ``frequencies`` [Hz], from one vectorised closed-form solution;
    None where no admissible one-impact orbit exists.

    The start is midway between impacts (half a period after the impact, a quarter for a symmetric two-sided stop),
    away from them. ``problem`` gives the system, the force's amplitude and phase, and (with ``orbit_stop``, see
    :func:`orbit_stop_of`) the stop. Layouts without a closed form (one stop, or a symmetric two-sided stop) get None
    everywhere (the ``linear`` start).
    """
    rigid = ImpactProblem(problem.system, orbit_stop_of(problem, orbit_stop), problem.excitation)
    if closed_form_refusal(rigid) is not None:
        return [None] * len(frequencies)
    omega = 2.0 * np.pi * np.asarray(frequencies, dtype=float)
    orbit = solve_impact_orbit(rigid, omega=omega)
    with np.errstate(invalid="ignore"):
        ok = orbit.exists & orbit.admissible()
        offset = 0.5 * orbit.window  # half-way to the next impact (T/2, or T/4 for a two-sided stop)
        states = orbit.state(offset[:, None])[:, 0, :]
        times = orbit.impact_time + offset
    return [(float(times[i]), states[i]) if ok[i] else None for i in range(omega.size)]


def linear_fits(problem: ImpactProblem) -> bool:
    """The linear steady state stays clear of every stop (the paper's layout: q |H12| <= Delta)."""
    return linear_state(problem).fits(problem)


def motion_scale(problem: ImpactProblem) -> NDArray[np.float64]:
    """Scales of the state's entries for the repeat test [m, m s-1]: L for displacements, w L for velocities, with
    L the largest |Delta_k| + |n_k . X| (+ a static term): Delta + q |H12| on the paper's layout."""
    length = problem.length_scale()
    return np.concatenate([np.full(problem.size, length), np.full(problem.size, problem.omega * length)])


def amplitude_scale(problem: ImpactProblem) -> float:
    """The scene's scale of a steady motion [m]: the largest |Delta_k| plus the largest amplitude of the linear response
    (every coordinate) at the problem's frequency, plus a static load's excursion in 1/w (as
    :meth:`ImpactProblem.velocity_scale`). Finite wherever :func:`check_steady_problem` accepts the frequency."""
    _, static = problem.load()
    minv_static = np.linalg.solve(problem.structure.mass_matrix, static)
    linear = float(np.max(np.abs(linear_state(problem).amplitudes)))
    return float(np.max(np.abs(problem.clearances()))) + linear + float(np.max(np.abs(minv_static))) / problem.omega**2


def check_steady_problem(problem: ImpactProblem) -> None:
    """``ValueError`` where the harmonic load sits so near an undamped (or nearly undamped) natural frequency that
    its response is ill-conditioned: every steady state there is refused, by every engine (the band the exact engines
    and the closed forms refuse: :func:`~vibroimpact.model.structure.resonance_refusal`)."""
    if isinstance(problem.excitation, HarmonicForce) and np.any(problem.load()[0]):
        refusal = resonance_refusal(np.linalg.eigvals(problem.structure.state_matrix), problem.omega)
        if refusal is not None:
            raise ValueError(refusal)


def check_amplitude(problem: ImpactProblem, result: "SteadyResult") -> None:
    """``ValueError`` where a steady state's fundamental amplitude exceeds :data:`AMPLITUDE_LIMIT` times
    :func:`amplitude_scale`: beyond any physical scale of the scene, so not reported (converged or not)."""
    amplitudes = np.abs(np.array(result.measures.displacements, dtype=complex))
    if not np.any(np.isfinite(amplitudes)):
        return
    scale = amplitude_scale(problem)
    i = int(np.nanargmax(amplitudes))
    if amplitudes[i] > AMPLITUDE_LIMIT * scale:
        raise ValueError(
            f"the steady state found has |{problem.structure.coordinates[i]}| = {amplitudes[i]:.3g} m, beyond {AMPLITUDE_LIMIT:g} times the "
            f"scene's scale {scale:.3g} m (the largest clearance plus the largest linear amplitude at {problem.frequency:g} Hz): "
            "no physical steady state; not reported"
        )


@suggest_keywords
def steady_state(
    engine: Engine | str,
    problem: ImpactProblem,
    start: str | tuple[float, NDArray[np.float64]] = "linear",
    settings: SteadySettings = SteadySettings(),
    orbit_stop: RigidStop | tuple[Stop, ...] | None = None,
    guess: tuple[float, NDArray[np.float64]] | None | str = "compute",
) -> SteadyResult:
    """Integrate to the steady state and measure it.

    Parameters
    ----------
    engine : Engine or str
        Time-domain engine, or the name of a registered one (built with default :class:`~vibroimpact.engines.settings.EngineSettings`;
        ``ValueError`` naming the registered engines for an unknown name).
    problem : ImpactProblem
        System, stop and excitation.
    start : {'linear', 'pgf', 'rest', 'shooting'} or (time [s], state)
        Where to start.
    settings : SteadySettings
        Convergence and measurement settings.
    orbit_stop : RigidStop, optional
        The rigid stop whose one-impact orbit a ``pgf`` start follows (see :func:`orbit_stop_of`).
    guess : (time [s], state) or None, optional
        The ``pgf`` start, precomputed for a whole grid by :func:`pgf_guesses` (None: no admissible one-impact
        orbit); by default computed here.

    Returns
    -------
    SteadyResult
        The measures, and the engine and problem, so that :meth:`SteadyResult.history` samples the steady motion.

    Raises
    ------
    ValueError
        Near an undamped natural frequency (:func:`check_steady_problem`), or for an amplitude beyond any physical
        scale of the scene (:func:`check_amplitude`).
    """
    engine = engine_of(engine)
    check_steady_problem(problem)
    result = _steady_state(engine, problem, start, settings, orbit_stop, guess)
    check_amplitude(problem, result)
    return replace(result, engine=engine, problem=problem)


def _steady_state(
    engine: Engine,
    problem: ImpactProblem,
    start: str | tuple[float, NDArray[np.float64]],
    settings: SteadySettings,
    orbit_stop: RigidStop | tuple[Stop, ...] | None,
    guess: tuple[float, NDArray[np.float64]] | None | str,
) -> SteadyResult:
    """:func:`steady_state` with an engine."""
    if start in ("pgf", "shooting"):
        if isinstance(guess, str):
            guess = pgf_guesses(problem, [problem.frequency], orbit_stop)[0]
        if guess is None:
            start = "linear"  # where no admissible one-impact orbit exists, the pgf start is the linear one
    if start == "linear" and linear_fits(problem):
        return _linear_answer(problem)
    if start in ("pgf", "shooting"):
        t, y = guess[0], np.array(guess[1], dtype=float)  # type: ignore[index]
    else:
        t, y = start_state(problem, start, orbit_stop) if isinstance(start, str) else (float(start[0]), np.asarray(start[1], dtype=float))
    scale = motion_scale(problem)
    used = 0
    first_chunk = settings.chunk_periods
    if start == "shooting":
        own = problem.contact_law == RIGID  # shot on the problem itself, not on its rigid stand-in
        shot = shoot_orbit(problem if own else _rigid(problem, orbit_stop), t, y)
        used = shot.periods if shot is not None else 0
        if shot is not None and shot.stable:
            t, y = shot.time, shot.state
            if engine.capabilities.exact_flow and own:  # the orbit is the engine's own steady state: measure it
                return _measure(engine, problem, t, y, 1, used, settings, scale)
            first_chunk = 3  # an integrator starts on the orbit: it needs only to confirm that its state repeats
        else:
            start = "pgf"  # no stable orbit near the closed form: march from it, perturbed
    if start == "pgf":
        kick = np.zeros(y.size)
        kick[0] = 1.0
        y = y + settings.start_perturbation * scale * kick
    searched = used
    t, y, multiplicity, marched = march(engine, problem, t, y, settings, first_chunk=first_chunk, scale=scale)
    return _measure(engine, problem, t, y, multiplicity, searched + marched, settings, scale)


def march(
    engine: Engine, problem: ImpactProblem, t: float, y: NDArray[np.float64], settings: SteadySettings, max_periods: int | None = None,
    first_chunk: int | None = None, scale: NDArray[np.float64] | None = None,
) -> tuple[float, NDArray[np.float64], int, int]:  # fmt: skip
    """Integrate from (t [s], y) in chunks until the strobes repeat (:func:`strobes_repeat`), at most ``max_periods``
    (default the settings'); the first chunk ``first_chunk`` periods (default the settings' ``chunk_periods``).

    Returns
    -------
    tuple
        (time [s], state) of the last strobe, the period found in excitation periods (0: none), periods integrated.
    """
    scale = motion_scale(problem) if scale is None else scale
    limit = settings.max_periods if max_periods is None else int(max_periods)
    first = settings.chunk_periods if first_chunk is None else first_chunk
    # only the last strobes are read: a ring of them keeps memory independent of max_periods (a list of every strobe
    # held ~190 MB per 10^6 periods)
    strobes: deque[NDArray[np.float64]] = deque([y], maxlen=3 * settings.max_multiplicity + 1)
    used = multiplicity = 0
    while used < limit:
        chunk = min(first if used == 0 else settings.chunk_periods, limit - used)
        trajectory = engine.integrate(problem, y, t, chunk)
        used += chunk
        strobes.extend(trajectory.strobe_states[1:])
        t, y = float(trajectory.strobe_times[-1]), trajectory.final_state
        multiplicity = strobes_repeat(np.array(strobes), scale, settings)
        if multiplicity:
            break
    return t, y, multiplicity, used


#: Longest period [excitation periods] recognised in the strobes of the long run of a motion that marching did not
#: see repeat: stable orbits of period 4-10 on the paper's system converge too slowly for the marching window.
LONG_MULTIPLICITY = 32


def _measure(
    engine: Engine, problem: ImpactProblem, t: float, y: NDArray[np.float64], multiplicity: int, searched: int, settings: SteadySettings, scale: NDArray[np.float64]
) -> SteadyResult:
    """Measure whole periods from (t, y): a periodic motion over a multiple of its period.

    A motion that did not converge first runs ``lyapunov_periods`` more (with the exact Jacobians where the engine has them):
    if its strobes then repeat with a period up to :data:`LONG_MULTIPLICITY`, it is that periodic orbit, reached
    late (the same repeat test as marching's, on the same ``scale`` of the motion); otherwise that run says what the
    motion is (:func:`motion_evidence`), and ``irregular_measure_periods`` are measured after it.
    """
    motion = None
    periods = 0
    if not multiplicity and settings.lyapunov_periods:
        exact = engine.capabilities.exact_jacobians
        run = engine.integrate(problem, y, t, settings.lyapunov_periods, jacobians=True) if exact else engine.integrate(problem, y, t, settings.lyapunov_periods)
        periods = settings.lyapunov_periods
        t, y = float(run.strobe_times[-1]), run.final_state
        multiplicity = strobes_repeat(run.strobe_states[-(3 * LONG_MULTIPLICITY + 1) :], scale, replace(settings, max_multiplicity=LONG_MULTIPLICITY))
        if not multiplicity:
            motion = motion_evidence(engine, problem, run)
            periods += 0 if exact else settings.lyapunov_periods  # the perturbed copy of an integrator's run
    if multiplicity:
        measured = multiplicity * math.ceil(settings.measure_periods / multiplicity)
    else:
        measured = settings.irregular_measure_periods
    final = engine.integrate(problem, y, t, measured, moments=True)
    return SteadyResult(
        measures=measure(final),
        converged=multiplicity > 0,
        multiplicity=multiplicity,
        periods_used=searched + periods + measured,
        end_time=float(final.strobe_times[-1]),
        end_state=final.final_state.copy(),
        motion=motion,
        search_periods=searched + (periods if multiplicity else 0),
    )


def _rigid(problem: ImpactProblem, orbit_stop: RigidStop | tuple[Stop, ...] | None) -> ImpactProblem:
    """The problem with the rigid stop a ``pgf`` start follows in place of its bumper (shooting needs a rigid stop)."""
    return ImpactProblem(problem.system, orbit_stop_of(problem, orbit_stop), problem.excitation)


def strobes_repeat(strobes: NDArray[np.float64], scale: NDArray[np.float64], settings: SteadySettings) -> int:
    """Smallest p <= max_multiplicity such that the last 2 p + 1 strobes repeat with period p; 0 if none.

    A transient decaying with complex Floquet multipliers of angle near 2 pi / p repeats better after p periods than
    after one; a genuine period-p motion has macroscopically distinct strobe points. So p > 1 is accepted only when
    successive strobe states differ by more than 1000 times the tolerance.
    """
    step = float(np.max(np.abs(strobes[-1] - strobes[-2]) / scale)) if strobes.shape[0] >= 2 else 0.0
    for p in range(1, settings.max_multiplicity + 1):
        if p > 1 and step < 1e3 * settings.tolerance:
            break
        if strobes.shape[0] < 2 * p + 1:
            break
        recent = strobes[-(p + 1) :]
        earlier = strobes[-(2 * p + 1) : -p]
        if np.all(np.abs(recent - earlier) <= settings.tolerance * scale):
            return p
    return 0


def _linear_answer(problem: ImpactProblem) -> SteadyResult:
    """The linear steady state of any layout, where it stays clear of every stop (an exact steady state)."""
    linear = linear_state(problem)
    x, rms = linear.amplitudes, linear.rms()
    count = len(problem.stops)
    nan = complex(math.nan, math.nan)
    measures = HarmonicMeasures(
        x1=complex(x[0]),
        x2=complex(x[1]) if x.size > 1 else nan,
        suspension_force=suspension_force(problem.system, problem.omega, x),
        contact_force=0j,
        x1_rms=float(rms[0]),
        x2_rms=float(rms[1]) if x.size > 1 else math.nan,
        impacts_per_period=0.0,
        mean_impulse=0.0,
        impulse_per_period=0.0,
        periods=0,
        peak_contact_force=0.0,
        peak_acceleration=0.0,
        displacements=tuple(complex(v) for v in x),
        rms=tuple(float(v) for v in rms),
        stop_contact_forces=(0j,) * count,
        stop_impacts=(0.0,) * count,
        stop_impulses=(0.0,) * count,
        stop_peak_forces=(0.0,) * count,
        stop_peak_accelerations=(0.0,) * count,
    )
    return SteadyResult(measures=measures, converged=True, multiplicity=1, periods_used=0, end_time=0.0, end_state=linear.state(problem.omega), integrated=False)
