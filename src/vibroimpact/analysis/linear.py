"""Steady-state response of the linear system (no stop, Delta -> infinity) and its resonance peaks.

:func:`paper_linear_response` is the paper's named two-mass system by its receptances (X1, X2, suspension force;
defined with the paper's other formulas in :mod:`vibroimpact.model.system`; its resonance peaks are
:func:`vibroimpact.analysis.linear_optimum.resonance_peaks`). :func:`linear_response` (also named :func:`linear_amplitudes`) is any problem under its
load (the paper's system a view of its problem): the complex amplitude of every coordinate,
H(jw) F(w), and of every stop's coordinate n_k . H F (a relative coordinate x_i - x_j for a relative stop, signed
by the stop's side), plus the static deflection K^-1 F0 where K is invertible (:func:`structure_amplitudes` the same
from the structure, load and stop directions alone; :func:`linear_reach` each stop's |n_k . X| + n_k . x0 of a
layout); :func:`structure_peaks` finds the
maxima of any of them near each natural frequency. :func:`base_force` is the force such a steady state (or any
motion's fundamentals) transmits to the base through the springs and dashpots, plus the stops' contact forces when
given: the one formula of every closed form and study.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from vibroimpact.analysis.layout import harmonic_load_of
from vibroimpact.model.excitation import HarmonicForce, angular_frequency, check_closed_form_inputs
from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.model.layout import Layout
from vibroimpact.model.problem import ImpactProblem, ProblemLike, problem_of
from vibroimpact.model.structure import CONDITION_LIMIT, LinearStructure, harmonic_condition, stiffness_modes
from vibroimpact.model.system import LinearResponse, paper_linear_response

__all__ = ["contact_free_is_stable", "base_coupling", "base_force", "peaks_near", "LinearResponse", "paper_linear_response", "linear_response", "ResonancePeak", "LinearAmplitudes", "linear_amplitudes", "linear_reach", "structure_amplitudes", "structure_peaks"]


def contact_free_is_stable(system: LinearStructure) -> bool:
    """Whether the contact-free steady state is a stable motion: every rigid-body mode of K (a free mass) is resisted
    by a dashpot. An undamped one (an impact damper's free mass in its cavity) only drifts at a constant speed when
    disturbed, into a stop: its contact-free motion is no attractor, however well it fits."""
    stiffness, damping = system.stiffness_matrix, system.damping_matrix
    rigid = stiffness_modes(stiffness).rigid
    if rigid.shape[1] == 0:
        return True
    inner = rigid.T @ damping @ rigid
    return bool(np.min(np.linalg.eigvalsh(0.5 * (inner + inner.T))) > 1e-12 * max(float(np.max(np.abs(damping))), 1e-300))


def base_coupling(system: LinearStructure) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(1^T K, 1^T C): the force on the base through the springs [N m-1] and dashpots [N s m-1] per coordinate
    ((K1, 0) and (B1, 0) for the paper's system)."""
    return system.stiffness_matrix.sum(axis=0), system.damping_matrix.sum(axis=0)


def base_force(system: LinearStructure, omega: ArrayLike, x: ArrayLike, through: ArrayLike | None = None, contact: ArrayLike | None = None) -> NDArray[np.complex128]:
    """Fundamental of the force on the base [N]: 1^T (K + j w C) x through the springs and dashpots, plus
    sum_k (1^T n_k) F_k of the stops' contact forces when given; the one formula of every closed form and study.

    Parameters
    ----------
    system : LinearStructure
        The structure (K, C).
    omega : array_like
        Angular frequency [rad s-1], broadcast against ``x``'s leading axes.
    x : array_like of complex, shape (..., N)
        Fundamentals of the coordinates [m].
    through : array_like, shape (K,), optional
        1^T n_k of each stop (:func:`~vibroimpact.simulation.harmonics.base_weights`): +1 an upper stop against the base, -1 a lower one, 0 relative.
    contact : array_like of complex, shape (..., K), optional
        Fundamentals of the stops' contact forces [N].
    """
    stiffness, damping = base_coupling(system)
    force = np.einsum("...i,...i->...", stiffness + 1j * np.asarray(omega, dtype=float)[..., None] * damping, np.asarray(x))
    if contact is not None and through is not None:
        force = force + np.einsum("...k,k->...", np.asarray(contact), np.asarray(through, dtype=float))
    return force


@dataclass(frozen=True)
class ResonancePeak:
    """Maximum of a linear amplitude near one natural frequency.

    Attributes
    ----------
    mode : int
        1 or 2.
    frequency : float
        Frequency of the maximum [Hz].
    value : float
        Peak amplitude (units of the quantity: [m] or [N]); inf at an undamped resonance (unbounded).
    """

    mode: int
    frequency: float
    value: float


@suggest_keywords
@dataclass(frozen=True, eq=False)
class LinearAmplitudes:
    """The linear steady state of a structure under its problem's load, without stops: what
    :func:`linear_response` returns.

    Attributes
    ----------
    omega : ndarray
        Angular frequencies w [rad s-1], shape S (:attr:`frequency` f [Hz]).
    amplitudes : ndarray of complex, shape S + (N,)
        H(jw) F(w): complex amplitude of each coordinate in the problem's time [m], columns in the order of
        ``coordinates`` (:meth:`coordinate` by name); NaN where the response is ill-conditioned (:attr:`conditioned`).
    stop_amplitudes : ndarray of complex, shape S + (K,)
        n_k . H F: complex amplitude of each stop's coordinate (the quantity its gap Delta_k - n_k . x subtracts) [m];
        NaN where :attr:`amplitudes` is.
    static : ndarray, shape (N,)
        K^-1 F0, the static deflection [m] (NaN where K is singular and a static load is given; zeros without one).
    stop_static : ndarray, shape (K,)
        n_k . K^-1 F0 [m].
    coordinates : tuple of str
        The coordinates' names (as :attr:`TimeHistory.coordinates <vibroimpact.simulation.history.TimeHistory.coordinates>`).
    structure : LinearStructure
        The structure (its K and C give :attr:`force`).
    condition : ndarray, shape S
        kappa of the harmonic response [-] (:func:`~vibroimpact.model.structure.harmonic_condition`, ~1 / (2 pi
        relative detuning) near an undamped natural frequency): beyond
        :data:`~vibroimpact.model.structure.CONDITION_LIMIT` (within ~1.6e-5 relative of an undamped natural
        frequency, or at a resonance damped zeta < 1.6e-5) the response is not evaluated, as the other closed forms'
        (:attr:`ImpactOrbit.conditioned <vibroimpact.analysis.impact_orbit.ImpactOrbit.conditioned>`) and the steady
        states' band: :attr:`amplitudes` NaN there (before: 1.4e12 m at an undamped resonance).
    """

    omega: NDArray[np.float64]
    amplitudes: NDArray[np.complex128]
    stop_amplitudes: NDArray[np.complex128]
    static: NDArray[np.float64]
    stop_static: NDArray[np.float64]
    coordinates: tuple[str, ...]
    structure: LinearStructure
    condition: NDArray[np.float64]

    @property
    def conditioned(self) -> NDArray[np.bool_]:
        """Where the response is evaluated: condition <= CONDITION_LIMIT, shape S (False near an undamped natural
        frequency, where the amplitudes are NaN: unknown, not absent)."""
        return self.condition <= CONDITION_LIMIT

    @property
    def frequency(self) -> NDArray[np.float64]:
        """f = w / (2 pi) [Hz]."""
        return self.omega / (2.0 * np.pi)

    @property
    def force(self) -> NDArray[np.complex128]:
        """Fundamental of the force on the base through the springs and dashpots, 1^T (K + j w C) X [N], shape S
        ((K1 + j w B1) X1 on the paper's system; :func:`base_force`)."""
        return base_force(self.structure, self.omega, self.amplitudes)

    def coordinate(self, name: str) -> NDArray[np.complex128]:
        """The complex amplitude of the coordinate called ``name`` [m], shape S."""
        if name not in self.coordinates:
            raise ValueError(f"coordinate = {name!r} is not a coordinate of the system: allowed {list(self.coordinates)}")
        return self.amplitudes[..., self.coordinates.index(name)]

    def relative(self, first: str, second: str) -> NDArray[np.complex128]:
        """The complex amplitude of x_first - x_second [m]."""
        return self.coordinate(first) - self.coordinate(second)

    def fits(self, clearances: ArrayLike) -> NDArray[np.bool_]:
        """True where every stop's linear coordinate stays inside its clearance: |n_k H F| + n_k K^-1 F0 <= Delta_k
        (``clearances`` Delta_k [m])."""
        return np.all(np.abs(self.stop_amplitudes) + self.stop_static <= np.asarray(clearances, dtype=float), axis=-1)


@suggest_keywords
def linear_response(system: ProblemLike, frequency: ArrayLike | None = None, amplitude: ArrayLike | None = None, *,
                    omega: ArrayLike | None = None) -> LinearAmplitudes:  # fmt: skip
    """The complex amplitudes of every coordinate and every stop's coordinate over ``frequency`` (module docstring).

    Parameters
    ----------
    system : ImpactProblem or the paper's named system
        Structure, stops and a harmonic load (force on any coordinates, or base motion: then the coordinates are
        relative to the base); the paper's named system is a view of its problem (the force on x1, the stop on x2),
        which needs ``frequency`` and ``amplitude``.
    frequency : array_like, optional
        f [Hz], > 0; default the problem's.
    amplitude : array_like, optional
        q [N] (base motion: Y [m]); default the problem's.
    omega : array_like, optional
        w [rad s-1] instead of ``frequency`` (keyword only).

    Returns
    -------
    LinearAmplitudes
        ``amplitudes`` per coordinate [m] (``coordinate(name)``), ``frequency`` [Hz] beside ``omega`` [rad s-1],
        the base ``force`` [N], ``fits(clearances)``; NaN (and ``fits`` False) where ``conditioned`` is False, within
        ~1.6e-5 (relative) of an undamped natural frequency, where the response is ill-conditioned.
    """
    problem = problem_of(system, "linear_response", frequency=frequency if omega is None else omega, amplitude=amplitude)
    if problem is not system:  # the paper's named system: its layout, with the values given
        check_closed_form_inputs(None, None, amplitude)
    return structure_amplitudes(problem.structure, problem.harmonic, problem.normals(), frequency, amplitude, omega=omega)


#: The same function: the name of the studies' code.
linear_amplitudes = linear_response


def structure_amplitudes(
    structure: LinearStructure, excitation: HarmonicForce, normals: ArrayLike, frequency: ArrayLike | None = None, amplitude: ArrayLike | None = None,
    *, omega: ArrayLike | None = None,
) -> LinearAmplitudes:  # fmt: skip
    """:func:`linear_amplitudes` without a problem: the linear steady state does not depend on the stops, only on
    where they act (``normals``, for the stops' coordinates).

    Parameters
    ----------
    structure : LinearStructure
        M, K, C.
    excitation : HarmonicForce
        The harmonic load (its frequency, amplitude and phase the defaults).
    normals : array_like, shape (K, N)
        n_k of every stop [-].
    frequency, amplitude, omega : array_like, optional
        As :func:`linear_amplitudes`.
    """
    w = np.asarray(angular_frequency(frequency, omega, excitation.omega), dtype=float)
    load = harmonic_load_of(structure, excitation, w, amplitude)
    x = np.einsum("...ij,...j->...i", structure.receptance_matrix(w), load)
    condition = harmonic_condition(np.linalg.eigvals(structure.state_matrix), w)
    refused = np.broadcast_to(condition > CONDITION_LIMIT, x.shape[:-1])
    if np.any(refused):
        x = np.where(refused[..., None], np.nan, x)  # the closed forms' and the engines' band: no number
    normals = np.asarray(normals, dtype=float)
    static_load = excitation.static_vector(structure.size)
    if not np.any(static_load):
        static = np.zeros(structure.size)
    elif structure.rigid_body_modes():
        static = np.full(structure.size, np.nan)
    else:
        static = np.linalg.solve(structure.stiffness_matrix, static_load)
    return LinearAmplitudes(w, x, x @ normals.T, static, normals @ static, tuple(structure.coordinates), structure, condition)


def linear_reach(layout: Layout, amplitude: float, frequency: float) -> NDArray[np.float64]:
    """|n_k . X| + n_k . x0 of every stop of ``layout`` [m], shape (K,): how far the linear steady state at
    ``frequency`` [Hz] under amplitude q [N] (base motion: Y [m]) carries each stop's coordinate towards it, the
    amplitude plus the static offset (NaN where K is singular under a static load). It does not depend on the stops'
    values: the layout's geometry and load answer it, the numbers those of :func:`linear_amplitudes` of any problem
    of the layout at that point."""
    linear = structure_amplitudes(layout.problem_structure, layout.load.force(amplitude, frequency), layout.normals())
    return np.abs(linear.stop_amplitudes) + linear.stop_static


def structure_peaks(problem: ImpactProblem, output: ArrayLike, span: float = 0.05) -> list[ResonancePeak]:
    """Maxima of |output . H F| near each non-zero natural frequency of the problem's structure: inf at the natural
    frequency of an undamped mode (:func:`peaks_near`).

    Parameters
    ----------
    problem : ImpactProblem
        The structure and its load.
    output : array_like, shape (N,)
        Weights of the coordinates (e.g. e_i, or e_i - e_j for a relative coordinate) [-].
    span : float
        Relative half-width of the search window around each natural frequency [-].
    """
    weights = np.asarray(output, dtype=float)

    def magnitude(w: ArrayLike) -> NDArray[np.float64]:
        return np.abs(linear_amplitudes(problem, omega=np.asarray(w, dtype=float)).amplitudes @ weights)

    return peaks_near([wn for wn in problem.structure.natural_angular_frequencies() if wn > 0.0], magnitude, span)


def peaks_near(frequencies: ArrayLike, magnitude: Callable[[ArrayLike], NDArray[np.float64]], span: float) -> list[ResonancePeak]:
    """The maximum of ``magnitude`` within a relative ``span`` of each angular frequency [rad s-1] in turn: the best
    of 4001 samples, refined by a bounded scalar search to 1e-10 of the frequency.

    Where ``magnitude`` is NaN on a sample (not evaluated: the band within ~1.6e-5 of an undamped natural frequency,
    :attr:`LinearAmplitudes.conditioned`, where the response is unbounded), the peak is unbounded: value inf at the
    NaN sample nearest the natural frequency (the natural frequency itself when undamped; before: a NaN value at
    wherever the search stopped, np.argmax taking the first NaN). The samples' spacing (2.5e-5 relative at the
    default ``span``) is finer than that band's width (3.2e-5): a sample always lands in it.
    """
    peaks = []
    for mode, omega_n in enumerate(frequencies, start=1):
        grid = omega_n * np.linspace(1.0 - span, 1.0 + span, 4001)
        values = np.asarray(magnitude(grid), dtype=float)
        unknown = np.flatnonzero(np.isnan(values))
        if unknown.size:
            nearest = grid[unknown[np.argmin(np.abs(grid[unknown] - omega_n))]]
            peaks.append(ResonancePeak(mode=mode, frequency=float(nearest) / (2.0 * np.pi), value=float("inf")))
            continue
        k = int(np.argmax(values))
        lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
        from scipy.optimize import minimize_scalar  # here, not at import: reading a scene must not load scipy's solvers

        best = minimize_scalar(lambda w: -float(magnitude(w)), bounds=(lo, hi), method="bounded", options={"xatol": 1e-10 * omega_n})
        peaks.append(ResonancePeak(mode=mode, frequency=float(best.x) / (2.0 * np.pi), value=float(-best.fun)))
    return peaks
