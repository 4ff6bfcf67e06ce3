"""The compiled loops' arguments by name: their Python faces build them once per problem as named tuples whose fields
are the loop's leading parameters, in its order, and pick a kernel's share of them by the kernel's parameter names.

A compiled loop takes ~40 positional arguments (numba compiles no keyword calls into one overload per signature, and
a named tuple unpacked with ``*`` is the same positional arguments, bit for bit). Slicing one long tuple by position
(``(*a[:11], a[19], a[21], ...)``) broke silently at any reordering of a signature; here every field is named, and
``tests/engines/test_kernel_arguments.py`` fails when a tuple's fields and its loop's parameters disagree in name or
order:

* :class:`StackedFlows`: what :func:`~vibroimpact.engines.exact.stack_flows` returns, the leading parameters of both
  loops (flow f is entry f of each array, see :mod:`~vibroimpact.engines.exact_core`);
* :class:`LoopArguments`: :func:`~vibroimpact.engines.exact_core.run_periods_until` before :data:`RUN_PARAMETERS`
  (the stacked flows' fields, then its own);
* :class:`BumperLoopArguments`: :func:`~vibroimpact.engines.compliant.exact_loop.run_bumper_periods_until` before them;
* :func:`leading_arguments`: a kernel's leading arguments taken from such a tuple by its parameter names
  (:func:`~vibroimpact.engines.exact_core.sample_states`, :func:`~vibroimpact.engines.compliant.exact_loop.sample_pieces`).

What the loops return is named too: :class:`LoopOutput` and :class:`BumperLoopOutput`, made of the compiled call's
tuple right after it (``LoopOutput._make(...)``: 0.3-0.5 us, measured against 12-16 us for the shortest call, one
period from rest on the paper's system), so that no caller reads a result by its position.
"""

from __future__ import annotations

import inspect
from functools import lru_cache
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

__all__ = ["StackedFlows", "LoopArguments", "BumperLoopArguments", "LoopOutput", "BumperLoopOutput", "RUN_PARAMETERS", "leading_arguments"]

#: The parameters of both loops after their named leading ones: the run's start state (x, x') [m, m s-1], its start
#: time [s], its number of periods, and what to record.
RUN_PARAMETERS = ("y_start", "t_start", "periods", "want_moments", "want_jacobians", "want_approach")


class StackedFlows(NamedTuple):
    """A problem's flows stacked (flow f is entry f of each array; :mod:`~vibroimpact.engines.exact_core`)."""

    lams: NDArray[np.complex128]  # nonzero eigenvalues [s-1], (F, widest)
    counts: NDArray[np.int64]  # how many of them per flow
    vecs: NDArray[np.complex128]  # eigenvectors, (F, n, widest)
    invs: NDArray[np.complex128]  # rows giving the modal coordinates, (F, widest, n)
    hrms: NDArray[np.complex128]  # harmonic particular solution's amplitude, (F, n)
    csts: NDArray[np.float64]  # constant particular solution, (F, n)
    zpros: NDArray[np.float64]  # projectors on the rigid-body modes, (F, n, n)
    znils: NDArray[np.float64]  # their nilpotent parts [s-1], (F, n, n)
    zdrvs: NDArray[np.float64]  # drifts c, (F, n)
    zdrv2s: NDArray[np.float64]  # drifts q2, (F, n)
    polys: NDArray[np.bool_]  # which flows have rigid-body modes
    hlams: NDArray[np.complex128]  # one eigenvalue of each conjugate pair and the real ones [s-1]
    hcounts: NDArray[np.int64]  # how many of them per flow
    rates_all: NDArray[np.complex128]  # the moments' rates [s-1], (F, widest + 2)
    rinv_all: NDArray[np.complex128]  # their factors' inverses, (F, widest + 3, widest + 2)
    fastests: NDArray[np.float64]  # omega + the largest |lambda| per flow [rad s-1]


def _after_flows(name: str, doc: str, fields: list[tuple[str, Any]]) -> Any:
    """A named tuple of :class:`StackedFlows`' fields followed by ``fields`` (a loop's own leading parameters)."""
    made = NamedTuple(name, [*StackedFlows.__annotations__.items(), *fields])  # type: ignore[misc]
    made.__doc__ = doc
    return made


LoopArguments = _after_flows("LoopArguments", """The leading arguments of :func:`~vibroimpact.engines.exact_core.run_periods_until`: the stacked flows,
    then the free flight's A [s-1, s-2], harmonic load b and constant load b0, omega [rad s-1], the period [s]; per stop
    the gap's weights over y (n_k, 0), its velocity's (0, n_k), an impulse's direction (0, M^-1 n_k) [kg-1], the
    clearance [m], restitution, effective mass [kg], the coordinate it moves alone (-1: none) and its sign in n_k;
    minus the holding force's weights [N m-1, N s m-1], offsets and harmonic parts [N], its force tolerances [N], the
    impact maps (K, n, n) of a bounce, a stick and a touch; the sticking velocity [m s-1], impacts per period before
    sticking, the gap tolerance [m], the velocity resolution [m s-1] and the Gauss-Legendre nodes and weights on [-1, 1]
    (:class:`~vibroimpact.engines.exact_flows.ExactModel` for the stops' arrays).""", [
    ("a_matrix", NDArray[np.float64]), ("load", NDArray[np.complex128]), ("static", NDArray[np.float64]), ("omega", float), ("period", float),
    ("gapw", NDArray[np.float64]), ("velw", NDArray[np.float64]), ("kickw", NDArray[np.float64]), ("clearances", NDArray[np.float64]),
    ("restitutions", NDArray[np.float64]), ("masses", NDArray[np.float64]), ("simple", NDArray[np.int64]), ("signs", NDArray[np.float64]),
    ("hold_w", NDArray[np.float64]), ("hold_off", NDArray[np.float64]), ("hold_har", NDArray[np.complex128]), ("force_tolerances", NDArray[np.float64]),
    ("bounce", NDArray[np.float64]), ("stick", NDArray[np.float64]), ("touch", NDArray[np.float64]),
    ("sticking_velocity", float), ("max_impacts", int), ("tolerance", float), ("resolution_velocity", float),
    ("gl_nodes", NDArray[np.float64]), ("gl_weights", NDArray[np.float64]),
])  # fmt: skip

BumperLoopArguments = _after_flows("BumperLoopArguments", """The leading arguments of :func:`~vibroimpact.engines.compliant.exact_loop.run_bumper_periods_until`:
    the stacked flows (one per contact mode), then omega [rad s-1], the period [s]; the weights of d_k, -d_k, F_k, -F_k
    over y (4 K, n) and their offsets [m, N], per stop (0, n_k) and the saltation matrix of an onset at d = 0 (K, n, n);
    zeros (4 K,) as the observables' harmonic parts; the gap tolerance [m], the force tolerances [N], the contact
    switches per period before giving up, and the Gauss-Legendre nodes and weights.""", [
    ("omega", float), ("period", float), ("obsw", NDArray[np.float64]), ("obso", NDArray[np.float64]), ("velw", NDArray[np.float64]),
    ("salts", NDArray[np.float64]), ("zero_har", NDArray[np.complex128]), ("gap_tolerance", float), ("force_tolerances", NDArray[np.float64]),
    ("max_events", int), ("gl_nodes", NDArray[np.float64]), ("gl_weights", NDArray[np.float64]),
])  # fmt: skip


class LoopOutput(NamedTuple):
    """What :func:`~vibroimpact.engines.exact_core.run_periods_until` returns, by name."""

    status: int  # STATUS_OK, or why the run stopped at ``t``
    t: float  # where it stopped [s]
    strobes: NDArray[np.float64]  # the states at the periods' boundaries, (periods + 1, n)
    jacobians: NDArray[np.float64]  # each period's stroboscopic map's exact Jacobian, (periods, n, n) (if wanted)
    impacts: NDArray[np.float64]  # (m, 4): time, speed, impulse, stop
    segments: NDArray[np.float64]  # (s, 3): start, mode, stop
    segment_states: NDArray[np.float64]  # the state at each segment's start, (s, n)
    moments: NDArray[np.complex128]  # per period, (periods, 2 N + K) (if wanted)
    counters: NDArray[np.int64]  # steps, events, sticks, releases, touches
    approach: NDArray[np.float64]  # the closest approach: value, time, stop (if wanted)


#: What :func:`~vibroimpact.engines.compliant.exact_loop.run_bumper_periods_until` returns, by name: the fields of
#: :class:`LoopOutput` with the bumper's columns (``impacts`` (c, 6): each completed contact's onset time, entry
#: speed, impulse, largest force, largest deceleration, stop; ``segments`` (s, 2): start, contact mode; ``counters``:
#: steps, events, onsets, touches, releases) and ``onsets`` (o, 5) before ``approach`` (the loop's docstring).
BumperLoopOutput = NamedTuple("BumperLoopOutput", [*tuple(LoopOutput.__annotations__.items())[:-1], ("onsets", NDArray[np.float64]), ("approach", NDArray[np.float64])])  # type: ignore[misc]


@lru_cache(maxsize=None)
def _parameters(kernel: Any) -> tuple[str, ...]:
    """The parameter names of a numba dispatcher's Python function (or of a function), in order."""
    return tuple(inspect.signature(getattr(kernel, "py_func", kernel)).parameters)


def leading_arguments(kernel: Any, arguments: tuple) -> tuple:
    """``kernel``'s leading arguments taken from the named tuple ``arguments`` by name: its parameters in order, up
    to the first that is not one of the tuple's fields (the caller gives the rest after them)."""
    names = []
    for name in _parameters(kernel):
        if name not in arguments._fields:  # type: ignore[attr-defined]
            break
        names.append(name)
    return tuple(getattr(arguments, name) for name in names)
