"""Engine ``exact``: piecewise-exact propagation, the reference every integrator is measured against.

Between events the motion is linear with harmonic and constant loads, so it is propagated in closed form (eigenvectors
of the state matrix plus the harmonic particular solution, and a polynomial for rigid-body modes, :mod:`~vibroimpact.engines.exact_flows`).
Any N-dof structure with any rigid stops: contacts are found by guaranteed root bracketing (Taylor bounds of each
stop's gap, :func:`.linear_flow.first_crossing`): no contact is missed however tangent, and contact times are exact to
round-off. An impact on stop k restitutes its gap velocity, n_k . x' -> -R_k n_k . x', by an impulse along M^-1 n_k
(two bodies' momentum is conserved on a relative stop). When impacts accumulate (chattering, small R) and the stop
pushes the structure, it sticks: the flow held on the stop's surface (n_k . x = Delta_k, n_k . x' = 0) runs until the
holding force (:meth:`~vibroimpact.model.problem.ImpactProblem.contact_holding`; B2 X1' + K2 (X1 - Delta) on the
paper's layout) turns negative (found by the same root search), or an impact on another stop frees it (unless the
impulse leaves it closed, at rest on it, n_k . x' = 0 to round-off, and pushed: then it holds on, as in the
``momentary`` engine). Sticking on two stops at once is refused (``NotImplementedError`` naming both).

The event loop runs compiled (:mod:`~vibroimpact.engines.exact_core`, numba); this module is its thin Python face. It also returns the
exact Jacobian of the stroboscopic map (state-transition matrices times the saltation matrices of impacts, sticking
and release), for shooting, continuation and Lyapunov exponents (:mod:`vibroimpact.orbits`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from vibroimpact.engines.registry import ENGINES, Capabilities
from vibroimpact.engines import batch_kernels, exact_core, exact_moments
from vibroimpact.engines.base import MODE_STUCK, Trajectory, check_run, start_state
from vibroimpact.engines.batch import BatchRuns, run_batch
from vibroimpact.engines.exact_flows import Flow, ExactModel, build_model
from vibroimpact.engines.exact_python import PythonExactEngine
from vibroimpact.engines.interruptible import call_interruptibly
from vibroimpact.engines.kernel_arguments import LoopArguments, LoopOutput, StackedFlows, leading_arguments
from vibroimpact.engines.linear_flow import gauss_legendre
from vibroimpact.engines.rigid_kernels import RigidContact
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.problem import ImpactProblem

__all__ = ["ExactEngine", "StrobeMap", "loop_setup", "loop_strobe_map", "loop_trajectory", "restacked", "stack_flows"]


def chained_jacobian(factors: NDArray[np.float64], size: int) -> NDArray[np.float64]:
    """The Jacobian of several periods' stroboscopic map from each period's (``factors[k]``, in order): their product,
    the last on the left; the identity of ``size`` for none."""
    product = np.eye(size)
    for factor in factors:
        product = factor @ product
    return product


@dataclass(frozen=True, eq=False)
class StrobeMap:
    """The stroboscopic map over ``periods`` periods from one state, with its exact Jacobian.

    Attributes
    ----------
    state : ndarray, shape (2 N,)
        Image (x, x') after the periods [m, m s-1]; (X1, X2, X1', X2') on the paper's layout.
    jacobian : ndarray, shape (2 N, 2 N)
        d state / d start [-, s-1 or s]: NaN where the map is not differentiable (a grazing touch at zero speed).
    impact_times : ndarray
        Times of the impacts [s].
    impact_velocities : ndarray
        Approach speed n_k . x' just before each impact, > 0 [m s-1].
    sticks, releases : int
        Impacts that ended in sticking, and releases from a stop.
    closest_approach : float
        Largest n_k . x - Delta_k (minus the gap) at an interior local maximum of a flight, over the stops not held
        [m] (<= 0; -inf if none): a new impact is born (grazing) where it reaches 0.
    closest_approach_time : float
        When it happens [s] (NaN if none).
    impact_stops : ndarray of int
        Stop index of each impact.
    closest_approach_stop : int
        The stop of the closest approach (-1 if none).
    surface_onsets : ndarray of bool, optional
        Per impact, whether it began at the stop's surface (a Kelvin-Voigt bumper's contact may also begin beyond it,
        where a released, still compressed bumper catches up again); None: every one did (rigid stops).
    onset_curvatures : ndarray, optional
        Bumpers: n_k . x'' of the free flight at each impact that began at the surface [m s-2] (0 for the others);
        None for rigid stops.
    """

    state: NDArray[np.float64]
    jacobian: NDArray[np.float64]
    impact_times: NDArray[np.float64]
    impact_velocities: NDArray[np.float64]
    sticks: int
    releases: int
    closest_approach: float
    closest_approach_time: float
    stats: dict[str, int] = field(default_factory=dict)
    impact_stops: NDArray[np.int64] = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    closest_approach_stop: int = -1
    surface_onsets: NDArray[np.bool_] | None = None
    onset_curvatures: NDArray[np.float64] | None = None


def _half(lam: NDArray[np.complex128]) -> NDArray[np.complex128]:
    """The eigenvalues a real observable needs, in order: one of each complex-conjugate pair (Im > 0) and the real ones."""
    return lam[lam.imag >= 0.0]


def stack_flows(flows: tuple[Flow, ...], omega: float) -> StackedFlows:
    """The flows as the compiled loops' stacked arrays (see :mod:`~vibroimpact.engines.exact_core`), by the loops'
    parameter names: flow f is entry f of each array (the exact engine's free and held flights; the bumper engine's
    contact modes); ``omega`` [rad s-1]."""
    return restacked(_frequency_free_stack(flows), flows, [flow.harmonic for flow in flows], omega)


def _frequency_free_stack(flows: tuple[Flow, ...]) -> StackedFlows:
    """What :func:`stack_flows` stacks whatever the forcing frequency (its harmonic parts left empty)."""
    count, n = len(flows), flows[0].harmonic.size
    widest = max(flow.eigenvalues.size for flow in flows)
    lams = np.zeros((count, widest), dtype=complex)
    hlams = np.zeros((count, widest), dtype=complex)
    vecs = np.zeros((count, n, widest), dtype=complex)
    invs = np.zeros((count, widest, n), dtype=complex)
    counts, hcounts = np.zeros(count, dtype=np.int64), np.zeros(count, dtype=np.int64)
    for f, flow in enumerate(flows):
        m = flow.eigenvalues.size
        half = _half(flow.eigenvalues)
        counts[f], hcounts[f] = m, half.size
        lams[f, :m], hlams[f, : half.size], vecs[f, :, :m], invs[f, :m, :] = flow.eigenvalues, half, flow.vectors, flow.inverse
    csts = np.array([flow.constant for flow in flows], dtype=float).reshape(count, n)
    zpros = np.array([flow.projector for flow in flows], dtype=float).reshape(count, n, n)
    znils = np.array([flow.nilpotent for flow in flows], dtype=float).reshape(count, n, n)
    zdrvs = np.array([flow.drift for flow in flows], dtype=float).reshape(count, n)
    zdrv2s = np.array([flow.drift2 for flow in flows], dtype=float).reshape(count, n)
    polys = np.array([flow.polynomial for flow in flows], dtype=np.bool_)
    empty = np.zeros(0)
    return StackedFlows(
        lams=lams, counts=counts, vecs=vecs, invs=invs, hrms=empty.astype(complex), csts=csts, zpros=zpros, znils=znils, zdrvs=zdrvs, zdrv2s=zdrv2s,
        polys=polys, hlams=hlams, hcounts=hcounts, rates_all=empty.astype(complex), rinv_all=empty.astype(complex), fastests=empty,
    )  # fmt: skip


def restacked(stacked: StackedFlows, flows: tuple[Flow, ...], harmonics: list[NDArray[np.complex128]], omega: float) -> StackedFlows:
    """``stacked`` (the ``flows``' stack at any frequency) at ``omega`` [rad s-1], their harmonic responses
    ``harmonics``: bit for bit :func:`stack_flows` of the flows with those responses (a scan in frequency keeps the
    rest of a stack, :func:`_frequency_free_stack`, and makes only this)."""
    count, widest = stacked.lams.shape
    rates = np.zeros((count, widest + 2), dtype=complex)
    rinv = np.zeros((count, widest + 3, widest + 2), dtype=complex)
    for f, flow in enumerate(flows):
        m = flow.eigenvalues.size
        r, inverse = exact_moments.moment_rates(np.ascontiguousarray(flow.eigenvalues), omega)
        rates[f, : m + 2], rinv[f, : m + 3, : m + 2] = r, inverse
    hrms = np.array(harmonics, dtype=complex).reshape(count, -1)
    fastests = np.array([omega + (float(np.max(np.abs(flow.eigenvalues))) if flow.eigenvalues.size else 0.0) for flow in flows])
    return stacked._replace(hrms=hrms, rates_all=rates, rinv_all=rinv, fastests=fastests)


def loop_strobe_map(out: LoopOutput, size: int, events: NDArray[np.float64], sticks: int, releases: int, stats: dict[str, int], **more: NDArray) -> StrobeMap:
    """A compiled loop's run with its Jacobians and closest approach (``out``: a
    :class:`~vibroimpact.engines.kernel_arguments.LoopOutput` or a ``BumperLoopOutput``) as the :class:`StrobeMap` of
    its periods, N = ``size``: ``events`` (time, speed, stop) the map's impacts, and the ``more`` fields of an
    engine's own."""
    approach = out.approach
    return StrobeMap(
        state=out.strobes[-1].copy(), jacobian=chained_jacobian(out.jacobians, 2 * size), impact_times=events[:, 0].copy(), impact_velocities=events[:, 1].copy(),
        sticks=sticks, releases=releases, closest_approach=float(approach[0]), closest_approach_time=float(approach[1]), stats=stats,
        impact_stops=events[:, 2].astype(np.int64), closest_approach_stop=int(approach[2]), **more,
    )  # fmt: skip


def loop_trajectory(
    problem: ImpactProblem, t_start: float, periods: int, out: LoopOutput, moments: bool, jacobians: bool, modes: NDArray, segment_stops: NDArray[np.int64], stats: dict[str, int], **more: NDArray
) -> Trajectory:
    """A compiled loop's run from ``t_start`` [s] (``out``: a :class:`~vibroimpact.engines.kernel_arguments.LoopOutput`
    or a ``BumperLoopOutput``) as a :class:`Trajectory`: its strobes at the loop's period boundaries, each segment
    running to the next one's start (empty ones dropped) with its mode and stop (``modes``, ``segment_stops``, one per
    segment), its impacts (time, speed and impulse its first columns, the stop its last), ``stats``, the moments and
    Jacobians if asked for, and the ``more`` fields of an engine's own."""
    n, width = 2 * problem.size, 2 * problem.size + len(problem.stops)
    times = float(t_start) + np.arange(periods + 1) * problem.period  # the loop's boundaries, bit for bit
    starts = out.segments[:, 0]
    ends = np.append(starts[1:], times[-1]) if starts.size else starts
    keep = ends > starts
    impacts = out.impacts
    return Trajectory(
        problem=problem, strobe_times=times, strobe_states=out.strobes,
        impact_times=impacts[:, 0].copy(), impact_velocities=impacts[:, 1].copy(), impulses=impacts[:, 2].copy(),
        segments=np.column_stack([starts, ends, modes])[keep], segment_states=out.segment_states[keep],
        moments=out.moments if moments else np.zeros((0, width), dtype=complex), stats=stats,
        strobe_jacobians=out.jacobians if jacobians else np.zeros((0, n, n)),
        impact_stops=impacts[:, -1].astype(np.int64), segment_stops=segment_stops[keep], **more,
    )  # fmt: skip


@dataclass(frozen=True, eq=False)
class _Setup:
    """What the compiled loop needs of one problem: its flows and thresholds, as the loop's leading arguments."""

    law: RigidContact
    model: ExactModel
    arguments: LoopArguments
    #: the leading arguments of :func:`~vibroimpact.engines.exact_core.sample_states`, picked from ``arguments`` by
    #: its parameter names: the flows, the stops' gaps
    sampling: tuple


@lru_cache(maxsize=512)
def loop_setup(problem: ImpactProblem, settings: EngineSettings) -> _Setup:
    """Once per problem (continuation and Lyapunov runs call the map of one problem thousands of times)."""
    law = RigidContact("exact", problem, settings, 0)
    length = law.length_scale
    model = build_model(problem, length)
    size, count = model.size, len(problem.stops)
    n = 2 * size
    zero = np.zeros((count, size))
    gapw = np.ascontiguousarray(np.hstack([model.normals, zero]))
    velw = np.ascontiguousarray(np.hstack([zero, model.normals]))
    kickw = np.ascontiguousarray(np.hstack([zero, model.kicks]))
    signs = np.array([model.normals[k, i] if i >= 0 else 0.0 for k, i in enumerate(model.simple)])
    nodes, weights = gauss_legendre(16)
    arguments = LoopArguments(
        **stack_flows((model.free, *model.stuck), problem.omega)._asdict(),
        a_matrix=model.matrix, load=np.ascontiguousarray(model.load), static=np.ascontiguousarray(model.static), omega=problem.omega, period=problem.period,
        gapw=gapw, velw=velw, kickw=kickw, clearances=model.clearances, restitutions=model.restitutions, masses=model.masses, simple=model.simple, signs=signs,
        hold_w=np.ascontiguousarray(model.hold_weights.reshape(count, n)), hold_off=model.hold_offsets, hold_har=model.hold_harmonics,
        force_tolerances=model.force_tolerances, bounce=model.bounce, stick=model.stick, touch=model.touch,
        sticking_velocity=law.sticking_velocity, max_impacts=law.max_impacts, tolerance=1e-15 * length, resolution_velocity=1e-14 * law.velocity_scale,
        gl_nodes=nodes, gl_weights=weights,
    )  # fmt: skip
    return _Setup(law, model, arguments, leading_arguments(exact_core.sample_states, arguments))


def _checked_setup(name: str, problem: ImpactProblem, settings: EngineSettings, periods: int) -> _Setup:
    """:func:`loop_setup` after the checks of every run (:func:`~vibroimpact.engines.base.check_run`)."""
    check_run(name, problem, RigidStop, periods)
    return loop_setup(problem, settings)


class ExactEngine:
    """Exact piecewise-linear reference engine, compiled (see module docstring)."""

    name = "exact"
    #: what it can do when built directly (the registry's row; :func:`~vibroimpact.engines.registry.make_engine` sets its own)
    capabilities: Capabilities = ENGINES["exact"].capabilities

    def __init__(self, settings: EngineSettings = EngineSettings()) -> None:
        self.settings = settings

    def _run(self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float, periods: int, moments: bool, jacobians: bool, approach: bool) -> LoopOutput:
        setup = _checked_setup(self.name, problem, self.settings, periods)
        state = start_state(problem, state, t_start)  # finite, 2 N values, a writable copy (one compiled overload)
        setup.law.check_start(state)
        out = LoopOutput._make(call_interruptibly(
            lambda cancel: exact_core.run_periods_until(*setup.arguments, state, float(t_start), int(periods), moments, jacobians, approach, cancel), int(periods)
        ))  # a long run in a helper thread: Ctrl-C stops it at once
        if out.status == exact_core.STATUS_NO_PROGRESS:
            raise RuntimeError(f"no progress at t = {out.t!r} s: more than {10 * setup.law.max_impacts} events in one period")
        if out.status == exact_core.STATUS_TWO_STICKS:
            first, second = int(out.counters[4]), int(out.approach[2])
            names = setup.law.names
            raise NotImplementedError(
                f"at t = {out.t!r} s the structure would stick on two stops at once (stop {first}: "
                f"{problem.stops[first].describe(names)}, stop {second}: {problem.stops[second].describe(names)}); "
                "the exact engine holds one stop at a time"
            )
        return out

    def run_many(
        self, problems: Sequence[ImpactProblem], case_of: NDArray[np.int64], starts: NDArray[np.float64], transient: int, strobes: int,
        scales: NDArray[np.float64], max_period: int, chain_from: NDArray[np.int64] | None = None,
    ) -> BatchRuns:  # fmt: skip
        """Many runs in one compiled call (:mod:`~vibroimpact.engines.batch_kernels`): run i is ``problems[case_of[i]]``
        from ``starts[i]`` at t = 0, ``transient`` periods dropped, ``strobes`` measured with moments and Jacobians,
        bit for bit :meth:`integrate`'s two runs; ``scales`` (cases, 2 N) the strobes' repeat test's [m, m s-1] up to
        ``max_period``; ``chain_from``: runs that start where an earlier one ended (a stepped sweep,
        :func:`~vibroimpact.engines.batch.run_batch`). A run with no progress keeps its status; one that would stick on two stops at once raises
        :meth:`integrate`'s ``NotImplementedError``."""
        setups = [_checked_setup(self.name, problem, self.settings, max(transient, strobes)) for problem in problems]
        case_of = np.asarray(case_of, dtype=np.int64)
        begun = np.array([start_state(problems[c], state, 0.0) for c, state in zip(case_of, starts)], dtype=float).reshape(case_of.size, -1)
        for c, state in zip(case_of, begun):
            setups[c].law.check_start(state)
        runs = run_batch(batch_kernels.run_rigid_batch, [setup.arguments for setup in setups], case_of, begun, transient, strobes, scales, max_period, chain_from)
        stuck = np.flatnonzero(runs.status == exact_core.STATUS_TWO_STICKS)
        if stuck.size:
            i = int(stuck[0])  # its single runs raise their message, naming both stops
            problem = problems[case_of[i]]
            end = self._run(problem, begun[i], 0.0, transient, False, False, False).strobes[-1] if transient else begun[i]
            self._run(problem, end, 0.0, strobes, True, True, False)
            raise NotImplementedError(f"run {i} would stick on two stops at once (from a sweep's previous state); the exact engine holds one stop at a time")
        return runs

    def integrate(
        self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float, periods: int, moments: bool = False, jacobians: bool = False
    ) -> Trajectory:
        """Integrate ``periods`` whole periods from ``state`` (x, x') at ``t_start`` [s].

        With ``jacobians``, ``strobe_jacobians[k]`` is the exact Jacobian of period k's stroboscopic map.
        """
        out = self._run(problem, state, t_start, periods, moments, jacobians, False)
        segments = out.segments
        return loop_trajectory(problem, t_start, periods, out, moments, jacobians, segments[:, 1], segments[:, 2].astype(np.int64), _stats(out.counters, out.impacts.shape[0]))

    def strobe_map(self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float = 0.0, periods: int = 1) -> StrobeMap:
        """The stroboscopic map over ``periods`` periods from ``state`` at ``t_start`` [s], with its exact Jacobian
        and what a continuation watches (impact speeds, closest approach of the gaps)."""
        out = self._run(problem, state, t_start, periods, False, True, True)
        impacts, counters = out.impacts, out.counters
        return loop_strobe_map(out, problem.size, impacts[:, [0, 1, 3]], int(counters[2]), int(counters[3]), _stats(counters, impacts.shape[0]))

    def dense(self, trajectory: Trajectory, times: NDArray[np.float64], side: str = "right") -> NDArray[np.float64]:
        """States at arbitrary ``times`` inside a trajectory, shape (n, 2 N), exact (from its segments).

        At an event's time, ``side="right"`` gives the state just after it and ``"left"`` the state just before it
        (the end of the earlier segment: e.g. the velocities before an impact). Evaluated by the pure-Python flows
        (the studies that read it keep their numbers); :meth:`states` is the compiled twin, the same to round-off."""
        return PythonExactEngine(self.settings).dense(trajectory, times, side)

    def states(self, trajectory: Trajectory, times: NDArray[np.float64], side: str = "right") -> NDArray[np.float64]:
        """As :meth:`dense`, compiled (:func:`~vibroimpact.engines.exact_core.sample_states`): states (x, x') at
        ``times`` [s] inside the trajectory, shape (n, 2 N) [m, m s-1], each piece evaluated as the run's own loop
        evaluates it (a time on a strobe gives its strobe state)."""
        if side not in ("left", "right"):
            raise ValueError(f"side = {side!r} is not allowed: use 'left' or 'right'")
        times = np.ascontiguousarray(times, dtype=float).reshape(-1)
        segments = trajectory.segments
        if segments.shape[0] == 0:
            raise ValueError("the trajectory has no segments (0 periods): there is nothing to sample")
        setup = loop_setup(trajectory.problem, self.settings)
        pieces = np.clip(np.searchsorted(segments[:, 0], times, side=side) - 1, 0, segments.shape[0] - 1)  # type: ignore[call-overload]
        flows = np.where(segments[:, 2] == MODE_STUCK, trajectory.segment_stops + 1, 0).astype(np.int64)
        starts = np.ascontiguousarray(segments[:, 0])
        return exact_core.sample_states(*setup.sampling, starts, flows, np.ascontiguousarray(trajectory.segment_states), times, pieces.astype(np.int64))

    def sample(self, problem: ImpactProblem, state: NDArray[np.float64], t_start: float, periods: int, times: NDArray[np.float64]) -> tuple[Trajectory, NDArray[np.float64]]:
        """Integrate ``periods`` periods from ``state`` at ``t_start`` [s] and give the states at ``times`` [s] (inside
        the run, increasing), shape (n, 2 N) [m, m s-1]: exact, from the trajectory's segments (:meth:`states`); at an
        event's time, the state just after it."""
        times = np.asarray(times, dtype=float).reshape(-1)
        trajectory = self.integrate(problem, state, t_start, periods)
        t_end = float(trajectory.strobe_times[-1])
        if times.size and (np.any(np.diff(times) < 0.0) or times[0] < t_start or times[-1] > t_end):
            raise ValueError(f"times: expected increasing times inside the run [{t_start!r}, {t_end!r}] s, got [{times.min()!r}, {times.max()!r}] s")
        return trajectory, self.states(trajectory, times)

    def model(self, problem: ImpactProblem) -> ExactModel:
        """The flows and stop maps the engine prepared for ``problem`` (cached per problem)."""
        check_run(self.name, problem, RigidStop)
        return loop_setup(problem, self.settings).model


def _stats(counters: NDArray[np.int64], impacts: int) -> dict[str, int]:
    steps, events, sticks, releases, touches = (int(c) for c in counters)
    return {"impacts": impacts, "sticks": sticks, "releases": releases, "steps": steps, "events": events, "touches": touches}


def kernels_cached(batched: bool = False) -> bool:
    """Whether numba's on-disk cache holds the engine's compiled core (with ``batched``, its batch entry too; a check
    of their indexes; False where unsure)."""
    kernels = (exact_core.run_periods_until, batch_kernels.run_rigid_batch) if batched else (exact_core.run_periods_until,)
    try:
        return all(bool(kernel._cache._cache_file._load_index()) for kernel in kernels)  # numba's index of cached overloads
    except (AttributeError, OSError, EOFError, ValueError):  # another numba's layout: compile (or load) to be sure
        return False


def prepare_kernels(batched: bool = False) -> float:
    """Compile the engine's core in this process, every overload a study runs (or load it from numba's on-disk cache),
    and with ``batched`` its batch entry (:meth:`ExactEngine.run_many`); return the seconds spent compiling [s] (0
    where cached).

    numba compiles the core on first use and caches it on disk (``@njit(cache=True)``); a cold cache costs
    :data:`~vibroimpact.engines.registry.FIRST_COMPILE_TIME` of compiling, the batch entry ~10-15 s more (it calls the
    core's own overload). Done once before parallel
    workers start, they load the cached code instead of each compiling it.
    """
    import time

    from vibroimpact.model.contact import Stop
    from vibroimpact.model.excitation import HarmonicForce
    from vibroimpact.model.system import PAPER_SYSTEM

    cached = kernels_cached(batched)
    start = time.perf_counter()
    problem = ImpactProblem(PAPER_SYSTEM, (Stop(RigidStop(3e-3, 0.2), coordinate=1),), HarmonicForce(10.0, 25.0))
    engine = ExactEngine()
    engine.integrate(problem, np.zeros(4), 0.0, 2, moments=True)
    if batched:
        engine.run_many([problem], np.zeros(1, dtype=np.int64), np.zeros((1, 4)), 1, 2, np.ones((1, 4)), 1)
    return 0.0 if cached else time.perf_counter() - start
