"""Engine ``compliant_exact``: the Kelvin-Voigt bumper of eq. 25 in closed form, the reference the compliant
integrators are measured against.

The bumper model (:mod:`~vibroimpact.engines.compliant.model`: stop k pushes with F_k = K_k d_k + B_k n_k . x' while
its penetration d_k = n_k . x - Delta_k >= 0 and F_k > 0, K_k = m_k Omega_b^2, B_k = 2 m_k xi_b Omega_b) is piecewise
linear: between switches each contact mode, the set of bumpers pushing, is a linear structure with harmonic and
constant loads, the structure's K and C plus K_k n_k n_k^T and B_k n_k n_k^T for each, loaded by K_k Delta_k n_k.
Each mode's flow is the ``exact`` engine's closed form (:func:`~vibroimpact.engines.exact_flows.decompose`: the
eigen-decomposition, the harmonic particular solution, a polynomial on rigid-body modes), made once per problem for
every mode (2^K of them) and stacked as the exact engine stacks its flows; the switches, the moments and the Jacobian
come from the same compiled machinery (:mod:`~vibroimpact.engines.compliant.exact_loop` calls the exact engine's
kernels: :mod:`~vibroimpact.engines.exact_pieces`, :mod:`~vibroimpact.engines.exact_roots`,
:mod:`~vibroimpact.engines.exact_core`, :mod:`~vibroimpact.engines.exact_moments`): one piecewise-linear loop with
the bumper's contact law in place of the impact map. Onsets (the gap closing, or, after a release with the bumper
still compressed, its force rising through zero while d > 0) and releases (the force falling through zero) are found
by guaranteed root bracketing: none is missed however tangent, and their times are exact to round-off. No tolerance:
the settings are not used (but for the event budget, ``max_impacts_per_period``).

Records are those of the compliant integrators (:class:`~vibroimpact.engines.compliant.ida.CompliantEngine`): each
completed contact is an impact (onset time, entry speed n_k . x' at the onset, impulse = integral of F_k) with its
largest force and largest deceleration -n_k . x'' (``contact_peaks``, each the maximum over the contact, found in
closed form); segments are free (``MODE_FREE``) or in contact (``MODE_CONTACT``, the lowest stop in contact); the
moments' contact-force channels are the integrals of F_k e^{-jwt}.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from functools import lru_cache
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from vibroimpact.engines.base import MODE_FREE, Trajectory, check_run, start_state
from vibroimpact.engines.batch import BatchRuns, run_batch
from vibroimpact.engines.compliant import batch_loop, exact_loop
from vibroimpact.engines.compliant.model import MODE_CONTACT
from vibroimpact.engines.exact import StrobeMap, loop_strobe_map, loop_trajectory, restacked, stack_flows
from vibroimpact.engines.exact_flows import Flow, harmonic_response, mechanical_null_basis, unforced_flow
from vibroimpact.engines.interruptible import call_interruptibly
from vibroimpact.engines.kernel_arguments import BumperLoopArguments, BumperLoopOutput, StackedFlows, leading_arguments
from vibroimpact.engines.linear_flow import gauss_legendre
from vibroimpact.engines.registry import ENGINES, Capabilities
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.model.bumper_limit import bumper_refusal
from vibroimpact.model.contact import KelvinVoigtBumper
from vibroimpact.model.problem import ImpactProblem

__all__ = ["CompliantExactEngine", "bumper_flows", "contact_modes", "loop_arguments", "forget_problems"]

#: Most bumpers of one problem: the engine prepares every contact mode, 2^K flows.
MAX_BUMPERS = 8


def bumper_flows(problem: ImpactProblem) -> tuple[tuple[Flow, ...], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The closed-form flow of every contact mode of a problem with bumpers, and each stop's K_k, B_k and m_k.

    The modes' decompositions do not depend on the forcing frequency: they are kept per problem at any frequency
    (:func:`contact_modes`), and only the harmonic particular solution is made here (a continuation in frequency
    evaluates the map of a new problem at every step).

    Returns
    -------
    tuple
        (flows, stiffness [N m-1], damping [N s m-1], effective masses [kg]): ``flows[mask]`` is the flow of y = (x, x')
        with the bumpers of the stops in the bit mask pushing (``flows[0]`` the free flight).
    """
    return _flows(problem, _at_one_hertz(problem))


def _at_one_hertz(problem: ImpactProblem) -> ImpactProblem:
    """``problem`` forced at 1 Hz: the key of what does not depend on the forcing frequency."""
    return dataclasses.replace(problem, excitation=dataclasses.replace(problem.harmonic, frequency=1.0))


def _flows(problem: ImpactProblem, unit: ImpactProblem) -> tuple[tuple[Flow, ...], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """:func:`bumper_flows`, ``unit`` the problem at 1 Hz."""
    modes, k_b, b_b, masses = contact_modes(unit)
    flows = tuple(dataclasses.replace(flow, harmonic=harmonic, omega=float(problem.omega)) for (_a, flow), harmonic in zip(modes, _harmonics(problem, modes)))
    return flows, k_b, b_b, masses


def _harmonics(problem: ImpactProblem, modes: tuple) -> list[NDArray[np.complex128]]:
    """Each contact mode's harmonic particular solution at ``problem``'s frequency (``modes``: its
    :func:`contact_modes`); its load is the problem's own, which may depend on the frequency (a base
    motion's inertial load grows with w^2)."""
    harmonic, _static = problem.load()
    b = np.concatenate([np.zeros(problem.size, dtype=complex), np.linalg.solve(problem.structure.mass_matrix.astype(complex), harmonic)])
    out = []
    for mask, (a, unforced) in enumerate(modes):
        with _in_contact(mask, [stop.law for stop in problem.stops]):  # type: ignore[misc]
            out.append(harmonic_response(unforced, a, b, problem.omega))
    return out


@lru_cache(maxsize=256)
def _unforced_stack(unit: ImpactProblem) -> tuple[tuple[Flow, ...], StackedFlows]:
    """The contact modes' flows and their stack at any frequency (:func:`~vibroimpact.engines.exact.restacked` makes
    the rest)."""
    modes, *_ = contact_modes(unit)
    flows = tuple(flow for _a, flow in modes)
    return flows, stack_flows(flows, 1.0)


@lru_cache(maxsize=256)
def contact_modes(problem: ImpactProblem) -> tuple[tuple[tuple[NDArray[np.float64], Flow], ...], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Per contact mode, its state matrix A [s-1] and :func:`~vibroimpact.engines.exact_flows.unforced_flow`, with each
    stop's K_k, B_k and m_k: what :func:`bumper_flows` keeps of a problem whatever its forcing frequency (``problem``
    is given at 1 Hz)."""
    structure = problem.structure
    mass, stiffness, damping = structure.mass_matrix, structure.stiffness_matrix, structure.damping_matrix
    size, count = problem.size, len(problem.stops)
    normals, clearances = problem.normals(), problem.clearances()
    kicks = np.linalg.solve(mass, normals.T).T.reshape(count, size)
    masses = 1.0 / np.einsum("ki,ki->k", normals, kicks)
    laws: list[KelvinVoigtBumper] = [stop.law for stop in problem.stops]  # type: ignore[misc]
    k_b = np.array([law.stiffness(m) for law, m in zip(laws, masses)])
    b_b = np.array([law.damping(m) for law, m in zip(laws, masses)])
    _harmonic, static = problem.load()
    if (refusal := bumper_refusal(problem)) is not None:  # converged and wrong beyond it
        raise ValueError(f"the engine 'compliant_exact': {refusal}, with the engine 'exact'")
    modes = []
    for mask in range(1 << count):
        k_mode, c_mode, load = stiffness.copy(), damping.copy(), static.copy()
        for k in range(count):
            if (mask >> k) & 1:
                outer = np.outer(normals[k], normals[k])
                k_mode += k_b[k] * outer
                c_mode += b_b[k] * outer
                load += k_b[k] * clearances[k] * normals[k]
        a = np.block([[np.zeros((size, size)), np.eye(size)], [-np.linalg.solve(mass, k_mode), -np.linalg.solve(mass, c_mode)]])
        b0 = np.concatenate([np.zeros(size), np.linalg.solve(mass, load)])
        with _in_contact(mask, laws):
            modes.append((a, unforced_flow(a, b0, mechanical_null_basis(mass, k_mode, c_mode))))
    return tuple(modes), k_b, b_b, masses


@contextmanager
def _in_contact(mask: int, laws: Sequence[KelvinVoigtBumper]) -> Iterator[None]:
    """A mode's refusal (``ValueError``) said as the contact's, naming each pushing stop's loss factor; the free
    flight's as it is."""
    try:
        yield
    except ValueError as error:
        if not mask:
            raise
        pushing = [k for k in range(len(laws)) if (mask >> k) & 1]
        losses = ", ".join(f"stop {k}: loss_factor = {laws[k].loss_factor:g}" for k in pushing)
        raise ValueError(
            f"contact: in contact with stop(s) {', '.join(map(str, pushing))} ({losses}): {error} (a critically damped bumper, "
            "loss factor 1, on a body nothing else holds has a repeated eigenvalue): use a loss factor off 1, or the integrating engine 'compliant'"
        ) from error


@dataclass(frozen=True, eq=False)
class _Setup:
    """What the compiled loop needs of one problem, as its leading arguments, and the flows for sampling (the leading
    arguments of :func:`~vibroimpact.engines.compliant.exact_loop.sample_pieces`, picked from ``arguments`` by its
    parameter names)."""

    arguments: BumperLoopArguments
    sampling: tuple


@lru_cache(maxsize=256)
def _contact_geometry(unit: ImpactProblem) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """What the compiled loop watches, whatever the forcing frequency (``unit``: the problem at 1 Hz): per stop, the
    observables d, -d, F, -F as weights over y and offsets, the weights of n_k . x' and the onset's saltation matrix."""
    _modes, k_b, b_b, _masses = contact_modes(unit)
    count, size = len(unit.stops), unit.size
    n = 2 * size
    normals, clearances = unit.normals(), unit.clearances()
    zero = np.zeros(size)
    obsw = np.zeros((4 * count, n))
    obso = np.zeros(4 * count)
    velw = np.zeros((count, n))
    salts = np.tile(np.eye(n), (count, 1, 1))
    for k in range(count):
        gap = np.concatenate([normals[k], zero])
        force = np.concatenate([k_b[k] * normals[k], b_b[k] * normals[k]])
        obsw[4 * k : 4 * k + 4] = gap, -gap, force, -force
        obso[4 * k : 4 * k + 4] = -clearances[k], clearances[k], -k_b[k] * clearances[k], k_b[k] * clearances[k]
        velw[k] = np.concatenate([zero, normals[k]])
        # onset at d = 0: the field jumps by -(0, M^-1 n) B d', d' = n . x' the crossing speed
        salts[k, size:, :size] -= b_b[k] * np.outer(np.linalg.solve(unit.structure.mass_matrix, normals[k]), normals[k])
    return obsw, obso, velw, salts


@lru_cache(maxsize=512)
def _setup(problem: ImpactProblem, settings: EngineSettings) -> _Setup:
    """Once per problem (a continuation calls the map of one problem thousands of times); what does not depend on the
    forcing frequency once per problem at any frequency (a scan in frequency sets up a new problem at every step)."""
    count = len(problem.stops)
    if count > MAX_BUMPERS:
        raise ValueError(f"contact: {count} bumpers; the engine 'compliant_exact' prepares every contact mode (2^K flows) and takes at most {MAX_BUMPERS}")
    unit = _at_one_hertz(problem)
    modes, k_b, b_b, _masses = contact_modes(unit)
    flows, unforced = _unforced_stack(unit)
    stacked = restacked(unforced, flows, _harmonics(problem, modes), problem.omega)
    obsw, obso, velw, salts = _contact_geometry(unit)
    velocity = problem.velocity_scale()
    length = velocity / problem.omega  # problem.length_scale(), without computing the velocity again
    force_tolerances = 1e-15 * (k_b * length + b_b * velocity)
    nodes, weights = gauss_legendre(16)
    arguments = BumperLoopArguments(
        **stacked._asdict(), omega=problem.omega, period=problem.period, obsw=obsw, obso=obso, velw=velw, salts=salts,
        zero_har=np.zeros(4 * count, dtype=complex), gap_tolerance=1e-15 * length, force_tolerances=force_tolerances,
        max_events=10 * settings.max_impacts_per_period, gl_nodes=nodes, gl_weights=weights,
    )  # fmt: skip
    return _Setup(arguments, leading_arguments(exact_loop.sample_pieces, arguments))


def _checked_setup(name: str, problem: ImpactProblem, settings: EngineSettings, periods: int) -> _Setup:
    """:func:`_setup` after the checks of every run: :func:`~vibroimpact.engines.base.check_run`, and a harmonic
    excitation (``TypeError`` naming it otherwise: a sweep has no closed form)."""
    check_run(name, problem, KelvinVoigtBumper, periods)
    problem.harmonic
    return _setup(problem, settings)


def loop_arguments(problem: ImpactProblem, settings: EngineSettings = EngineSettings()) -> BumperLoopArguments:
    """The compiled loop's leading arguments for ``problem`` (kept per problem, and what does not depend on its
    forcing frequency per problem at any frequency)."""
    return _setup(problem, settings).arguments


def forget_problems() -> None:
    """Drop everything kept per problem (the loop's arguments, the contact modes and their stack, the contact
    geometry): the memory back, and the next problem set up from nothing."""
    for cached in (_setup, contact_modes, _unforced_stack, _contact_geometry):
        cached.cache_clear()


class CompliantExactEngine:
    """The Kelvin-Voigt bumper in closed form, compiled (see module docstring)."""

    name = "compliant_exact"
    #: what it can do when built directly (the registry's row; :func:`~vibroimpact.engines.registry.make_engine` sets its own)
    capabilities: Capabilities = ENGINES["compliant_exact"].capabilities

    def __init__(self, settings: EngineSettings = EngineSettings()) -> None:
        self.settings = settings

    def _run(self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float, periods: int, moments: bool, jacobians: bool, approach: bool = False) -> BumperLoopOutput:
        setup = _checked_setup(self.name, problem, self.settings, periods)
        state = start_state(problem, state, t_start)  # finite, 2 N values, a writable copy (one compiled overload)
        out = BumperLoopOutput._make(call_interruptibly(
            lambda cancel: exact_loop.run_bumper_periods_until(*setup.arguments, state, float(t_start), int(periods), bool(moments), bool(jacobians), bool(approach), cancel), int(periods)
        ))  # a long run in a helper thread: Ctrl-C stops it at once
        if out.status == exact_loop.STATUS_NO_PROGRESS:
            raise RuntimeError(f"no progress at t = {out.t!r} s: more than {10 * self.settings.max_impacts_per_period} contact switches in one period")
        return out

    def run_many(
        self, problems: Sequence[ImpactProblem], case_of: NDArray[np.int64], starts: NDArray[np.float64], transient: int, strobes: int,
        scales: NDArray[np.float64], max_period: int, chain_from: NDArray[np.int64] | None = None,
    ) -> BatchRuns:  # fmt: skip
        """Many runs in one compiled call, bit for bit :meth:`integrate`'s (as
        :meth:`~vibroimpact.engines.exact.ExactEngine.run_many`); a run with no progress keeps its status."""
        arguments = [_checked_setup(self.name, problem, self.settings, max(transient, strobes)).arguments for problem in problems]
        case_of = np.asarray(case_of, dtype=np.int64)
        begun = np.array([start_state(problems[c], state, 0.0) for c, state in zip(case_of, starts)], dtype=float).reshape(case_of.size, -1)
        return run_batch(batch_loop.run_bumper_batch, arguments, case_of, begun, transient, strobes, scales, max_period, chain_from)

    def integrate(
        self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float, periods: int, moments: bool = False, jacobians: bool = False
    ) -> Trajectory:
        """Integrate ``periods`` whole periods from ``state`` (x, x') at ``t_start`` [s].

        With ``jacobians``, ``strobe_jacobians[k]`` is the exact Jacobian of period k's stroboscopic map.
        """
        out = self._run(problem, state, t_start, periods, moments, jacobians)
        return _trajectory(problem, float(t_start), periods, out, moments, jacobians)

    def strobe_map(self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float = 0.0, periods: int = 1) -> StrobeMap:
        """The stroboscopic map over ``periods`` periods from ``state`` at ``t_start`` [s], with its exact Jacobian
        and what a continuation watches.

        Contacts are its impacts: ``impact_times``, ``impact_velocities`` and ``impact_stops`` are the onsets after
        the start (a contact under way at the start is not one; one under way at the end is), each with its entry
        speed n_k . x' [m s-1]: > 0 for an onset at the bumper's surface (d = 0), <= 0 for a re-contact while a
        released bumper is still compressed (d > 0, its force rising through zero: ``surface_onsets`` tells them
        apart); ``onset_curvatures`` is the free flight's d_k'' at each onset at the surface [m s-2] (0 for the
        others). ``closest_approach`` is the largest interior local maximum of a penetration d_k = n_k . x - Delta_k
        over free flights below the surface (< 0; -inf without one) [m]: the compliant counterpart of the rigid
        stop's, so that contact onset at tangency (a free flight touching d = 0, or an onset whose entry speed goes
        to 0) is where either reaches 0.
        """
        out = self._run(problem, state, t_start, periods, False, True, True)
        counters, onsets = out.counters, out.onsets
        return loop_strobe_map(out, problem.size, onsets[:, :3], 0, int(counters[4]), _stats(counters, out.impacts.shape[0]), surface_onsets=onsets[:, 3] > 0.5, onset_curvatures=onsets[:, 4].copy())

    def compiled_period(self, problem: ImpactProblem) -> "CompiledPeriod":
        """``problem``'s stroboscopic map over one period from t = 0 as the compiled loop alone computes it
        (:class:`CompiledPeriod`): the map :class:`~vibroimpact.orbits.bumper_map.CompiledPeriodMap` gives
        :func:`~vibroimpact.orbits.shooting.shoot`."""
        check_run(self.name, problem, KelvinVoigtBumper, 1)
        return CompiledPeriod(_setup(problem, self.settings).arguments)

    def sample(self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float, periods: int, times: NDArray[np.float64]) -> tuple[Trajectory, NDArray[np.float64]]:
        """Integrate ``periods`` periods from ``state`` at ``t_start`` [s] and give the states (x, x') at ``times`` [s]
        (inside the run, increasing), shape (n, 2 N) [m, m s-1]: exact, from the run's pieces (at a switch's time, the
        state after it, which is the same: the bumper's switches are continuous in the state)."""
        times = np.ascontiguousarray(times, dtype=float).reshape(-1)
        t_end = float(t_start) + periods * problem.period
        if times.size and (np.any(np.diff(times) < 0.0) or times[0] < t_start or times[-1] > t_end):
            raise ValueError(f"times: expected increasing times inside the run [{t_start!r}, {t_end!r}] s, got [{times.min()!r}, {times.max()!r}] s")
        out = self._run(problem, state, t_start, periods, False, False)
        segments, states = out.segments, out.segment_states
        starts = np.ascontiguousarray(segments[:, 0])
        pieces = np.clip(np.searchsorted(starts, times, side="right") - 1, 0, max(starts.size - 1, 0)).astype(np.int64)
        flows = segments[:, 1].astype(np.int64)
        sampled = exact_loop.sample_pieces(*_setup(problem, self.settings).sampling, starts, flows, np.ascontiguousarray(states), times, pieces)
        return _trajectory(problem, float(t_start), periods, out, False, False), sampled


def _stats(counters: NDArray[np.int64], impacts: int) -> dict[str, int]:
    steps, events, onsets, touches, releases = (int(c) for c in counters)
    return {"impacts": impacts, "contacts": onsets, "releases": releases, "touches": touches, "steps": steps, "events": events}


class PeriodImage(NamedTuple):
    """One period of :class:`CompiledPeriod`."""

    state: NDArray[np.float64]  # (x, x') at its end [m, m s-1]
    jacobian: NDArray[np.float64]  # the exact Jacobian of the period's stroboscopic map
    contacts: int  # contact onsets in it


#: The compiled period's cancel flag: never set (a period is short; the loop reads it and changes no number).
_NEVER = np.zeros(1, dtype=np.int64)


@dataclass(frozen=True, eq=False)
class CompiledPeriod:
    """One problem's stroboscopic map over one period from t = 0, its exact Jacobian and its contacts, as the compiled
    loop computes them with nothing around it (no checks, no thread, no records, no closest approach): the map the
    bumper screen shoots some 150 orbits of per design, where through :meth:`CompliantExactEngine.strobe_map` three
    quarters of each evaluation's time was Python around the compiled period. The loop's own overload (the engine's
    runs'): nothing more to compile."""

    arguments: BumperLoopArguments

    def __call__(self, state: NDArray[np.float64]) -> PeriodImage | None:
        """The period from ``state`` (x, x') at t = 0 [m, m s-1]; None for a non-finite state, or a period on which the
        loop makes no progress (more contact switches than its budget)."""
        if not np.isfinite(state).all():
            return None
        out = BumperLoopOutput._make(exact_loop.run_bumper_periods_until(*self.arguments, np.array(state, dtype=float), 0.0, 1, False, True, False, _NEVER))
        if out.status == exact_loop.STATUS_NO_PROGRESS:
            return None
        return PeriodImage(out.strobes[1], out.jacobians[0], int(out.onsets.shape[0]))


def _trajectory(problem: ImpactProblem, t_start: float, periods: int, out: BumperLoopOutput, moments: bool, jacobians: bool) -> Trajectory:
    """The compiled loop's output as a :class:`Trajectory` (:func:`~vibroimpact.engines.exact.loop_trajectory`): a
    segment in contact is with its lowest stop in contact; each contact's largest force and deceleration."""
    masks = out.segments[:, 1].astype(np.int64)
    lowest = np.array([(int(mask) & -int(mask)).bit_length() - 1 for mask in masks], dtype=np.int64)
    contacts = out.impacts
    return loop_trajectory(
        problem, t_start, periods, out, moments, jacobians, np.where(masks > 0, MODE_CONTACT, MODE_FREE), lowest, _stats(out.counters, contacts.shape[0]),
        contact_peaks=contacts[:, 3:5].copy(), contact_peak_stops=contacts[:, 5].astype(np.int64),
    )


def kernels_cached(batched: bool = False) -> bool:
    """Whether numba's on-disk cache holds the engine's loop (its runs' and :class:`CompiledPeriod`'s; with
    ``batched``, its batch entry too; a check of their indexes; False where unsure)."""
    kernels = (exact_loop.run_bumper_periods_until, batch_loop.run_bumper_batch) if batched else (exact_loop.run_bumper_periods_until,)
    try:
        return all(bool(kernel._cache._cache_file._load_index()) for kernel in kernels)  # numba's index of cached overloads
    except (AttributeError, OSError, EOFError, ValueError):  # another numba's layout: compile (or load) to be sure
        return False


def prepare_kernels(batched: bool = False) -> float:
    """Compile the engine's loop in this process, every overload a study runs (or load it from numba's on-disk cache),
    and with ``batched`` its batch entry (:meth:`CompliantExactEngine.run_many`); return the seconds spent compiling
    [s] (0 where cached). Run once before parallel workers start, they load it instead of each compiling it at once
    (~25 s of CPU each on a loaded 2-core machine, the batch entry ~20 s more)."""
    import time

    from vibroimpact.model.contact import Stop
    from vibroimpact.model.excitation import HarmonicForce
    from vibroimpact.model.structure import LinearStructure

    cached = kernels_cached(batched)
    start = time.perf_counter()
    problem = ImpactProblem(LinearStructure(mass=[[1.0]], stiffness=[[1e4]]), (Stop(KelvinVoigtBumper(1e-3, 100.0, 0.3), coordinate=0),), HarmonicForce(100.0, 10.0))
    engine = CompliantExactEngine()
    engine.integrate(problem, np.zeros(2), 0.0, 2, moments=True, jacobians=True)
    engine.sample(problem, np.zeros(2), 0.0, 1, np.array([0.05]))
    if batched:
        engine.run_many([problem], np.zeros(1, dtype=np.int64), np.zeros((1, 2)), 1, 2, np.ones((1, 2)), 1)
    return 0.0 if cached else time.perf_counter() - start
