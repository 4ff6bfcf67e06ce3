"""The impacting system as a parametrised map: the stroboscopic map of an :class:`ImpactProblem` over k periods.

``ImpactMap(problem, periods=k)`` maps the state (x, x') at t = 0 (mod T), 2N wide ((X1, X2, X1', X2') on the
paper's layout), to the state k excitation periods later, with the exact Jacobian of a compiled engine that gives one
(the first registered with ``exact_jacobians`` for the stops' contact law,
:func:`~vibroimpact.engines.registry.engine_for`: state-transition matrices times saltation matrices of impacts,
sticking and release for rigid stops; of contact onsets for bumpers). Its parameters are
``frequency`` [Hz], ``restitution`` [-], ``clearance`` [m], ``amplitude`` [N] (or the base amplitude [m] of a base
motion) and ``phase`` [rad], the force's phase at the strobe; a parameter vector becomes a new problem (the frequency
changes the period, the strobes stay at t = 0 mod T; the force's distribution over the coordinates and static part
are kept). The phase only places the section: continuation holds it, and moves it (:meth:`ImpactMap.resectioned`)
when an impact nears the strobe, so every orbit of a branch carries the section its state is taken at. With several stops, ``stop``
says which one ``restitution`` and ``clearance`` belong to: an index k (that stop alone), or ``"all"`` (every stop
takes the values; they must be equal in the base problem, e.g. a two-sided stop); by default ``"all"`` where the
stops' values are equal (one stop always), else a ``ValueError`` asks for a choice. dP/dp comes from central
differences (see :data:`vibroimpact.orbits.shooting.FD_RELATIVE_STEP`). Each evaluation carries the hybrid
information continuation watches: impacts per orbit period, the slowest impact, the closest approach of a free
flight to any stop, sticks.

Kelvin-Voigt bumpers (every stop a :class:`~vibroimpact.model.contact.KelvinVoigtBumper`): ``restitution`` is the
restitution of one collision with the bumper, R(xi_b) of the corrected eq. 26, and setting it sets the loss factor
xi_b = :func:`~vibroimpact.model.contact.loss_factor_from_restitution` (R) with the bumper's Omega_b kept (a base
problem's own R gives back its own xi_b, bit for bit); ``clearance`` moves the bumper's surface. Contacts are the
impacts (their onsets, each with its entry speed), there are no sticks, and the closest approach is that of a free
flight to the bumper's surface (d = 0): the grazing the continuation detects is contact onset at tangency, a free
flight touching d = 0 or an onset at the surface whose entry speed goes to 0. (A re-contact while a released bumper
is still compressed, d > 0, is counted but has no speed margin: its vector field is continuous.) A state inside a
bumper is a valid state.

:func:`orbit_measures` says what an orbit means physically (impulse per impact, harmonic amplitudes);
:func:`resection` (:mod:`~vibroimpact.orbits.sections`) moves a strobe away from the impacts. The closed-form starts (:func:`closed_form_state`,
:func:`with_impulse`, :func:`section_phase`) live in :mod:`~vibroimpact.orbits.shooting` and are re-exported here.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from typing import Any

from vibroimpact.analysis.impact_orbit import solve_impact_orbit
from vibroimpact.analysis.linear import LinearAmplitudes, linear_amplitudes
from vibroimpact.engines.registry import BUMPER, engine_for, make_engine
from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop, loss_factor_from_restitution
from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.structure import require_count
from vibroimpact.orbits.branch import Branch, HybridInfo, MapEvaluation, PeriodicOrbit
from vibroimpact.model.parameters import LayoutParameter, check_independent, layout_parameter, parameter, with_layout
from vibroimpact.orbits.sections import StrobeGap, moved_phase, moved_state, resection, strobe_gap
from vibroimpact.orbits.shooting import closed_form_state, section_phase, with_impulse

__all__ = ["ImpactMap", "closed_form_state", "with_impulse", "section_phase", "resection", "PARAMETERS", "SECTION_PARAMETER", "stop_selection", "Resection", "ContactFreeOrbit"]

#: The parameters of an :class:`ImpactMap`, in order, with their units.
PARAMETERS = {name: parameter(name).unit for name in ("frequency", "restitution", "clearance", "amplitude", "phase")}
#: The parameter that places the strobe: the force's phase at t = 0 (a section of the orbit, not a physical property).
SECTION_PARAMETER = "phase"


def stop_selection(problem: ImpactProblem, stop: int | str | None) -> tuple[int, ...]:
    """The stops whose clearance and restitution an :class:`ImpactMap`'s parameters set (module docstring).

    Raises
    ------
    ValueError
        ``stop`` out of range, ``"all"`` over stops whose values differ, or no choice where they differ.
    TypeError
        Stops of both laws (rigid and bumper) in one problem.
    """
    stops = problem.stops
    for k, item in enumerate(stops):
        if item.rigid != stops[0].rigid:
            raise TypeError(f"contact: stops[{k}] is a {type(item.law).__name__} and stops[0] a {type(stops[0].law).__name__}; an ImpactMap needs one contact law for every stop")
    values = {(item.clearance, item.law.restitution) for item in stops}
    if stop is None or stop == "all":
        if len(values) > 1:
            raise ValueError(f"stop = {stop!r}: the {len(stops)} stops have different clearances or restitutions; choose the one the parameters set: allowed 0 ... {len(stops) - 1}")
        return tuple(range(len(stops)))
    if isinstance(stop, bool) or not isinstance(stop, int) or not 0 <= stop < len(stops):
        raise ValueError(f"stop = {stop!r} is out of range: allowed 0 ... {len(stops) - 1} or 'all'")
    return (stop,)


@suggest_keywords
class ImpactMap:
    """Stroboscopic map over ``periods`` excitation periods of a problem with rigid stops or Kelvin-Voigt bumpers under
    a harmonic force.

    Parameters
    ----------
    problem : ImpactProblem
        The base problem (rigid stops or bumpers, harmonic force); its values are the default parameter vector.
    periods : int
        k >= 1: excitation periods per map iteration.
    engine : optional
        The engine that computes the map: one with exact Jacobians for the stops' contact law (default: the first
        registered, :func:`~vibroimpact.engines.registry.engine_for`, default settings).
    bounds : dict, optional
        Parameter name -> (lower, upper): outside this box the map has no image (NaN, a failed step), e.g. to keep a
        continuation's trials at physical frequencies. Parameters outside their own ranges (a negative frequency,
        R > 1) never have one.
    stop : int or 'all', optional
        The stop(s) whose clearance and restitution the parameters are (module docstring).
    parameter_scale : array_like, shape (m,), optional
        A unit of arclength for each of the m parameters (default :meth:`natural_scale` of the problem: 4 % of its
        frequency, 0.1, 15 % of its length scale, 10 % of its amplitude, 1 rad; on the paper's 25 Hz, 10 N problem
        1 Hz, 0.1, 1.1 mm, 1 N), so that a 0.1 Hz structure and a 30 Hz one take the same steps in their own units.
    layout : sequence of str, optional
        Layout scalars appended to the parameters (:mod:`~vibroimpact.model.parameters`: ``"k2"``,
        ``"mass[x2]"``, ``"spring[x1,x2]"``, ``"bumper_stiffness"`` ...), so that any of them can be continued or be
        the second parameter of a special point's curve; their scale is 10 % of their value.

    Attributes
    ----------
    parameters : ndarray, shape (m,)
        The base problem's (frequency [Hz], restitution [-], clearance [m], amplitude [N], phase [rad]), in the order
        of ``parameter_names`` (a subclass may add more: :class:`~vibroimpact.orbits.bumper_map.BumperPeriodMap`).
    dimension : int
        2N, the state's length.
    stops : tuple of int
        The stops the parameters set.
    state_scale : ndarray, shape (2N,)
        (L, ..., V, ...) with L = Delta + q |H12(w)| [m] on the paper's layout (in general the largest |Delta_k| +
        |n_k H F| plus a static load's excursion, :meth:`ImpactProblem.velocity_scale` / w) and V = w L [m s-1].
    parameter_scale : ndarray, shape (m,)
        What counts as a unit of arclength for each parameter.
    """

    parameter_names: tuple[str, ...] = tuple(PARAMETERS)
    @staticmethod
    def natural_scale(problem: ImpactProblem) -> tuple[float, ...]:
        """One unit of arclength per parameter, in the order of ``parameter_names``, from the problem's own
        magnitudes: 0.04 f [Hz], 0.1 [-], 0.15 L [m] (L the length scale, :meth:`ImpactProblem.length_scale`),
        0.1 |q| [N] (1 for q = 0), 1 [rad]."""
        amplitude = abs(problem.amplitude)
        return (0.04 * problem.frequency, 0.1, 0.15 * problem.length_scale(), 0.1 * amplitude if amplitude > 0.0 else 1.0, 1.0)

    def __init__(self, problem: ImpactProblem, periods: int = 1, engine: Any = None, bounds: dict[str, tuple[float, float]] | None = None,
                 stop: int | str | None = None, parameter_scale: ArrayLike | None = None, layout: Sequence[str] = ()) -> None:  # fmt: skip
        problem.harmonic  # noqa: B018 - raises TypeError naming the part unless a harmonic force
        self.stops = stop_selection(problem, stop)
        self.stop = stop
        self.problem, self.periods = problem, require_count("periods", periods)  # 1.7 is no count of periods
        self.contact = problem.contact_law
        self.engine = engine if engine is not None else make_engine(engine_for(self.contact, "exact_jacobians"))
        chosen = problem.stops[self.stops[0]]
        self.layout = tuple(layout_parameter(str(name), problem) for name in layout)
        self.parameter_names = (*type(self).parameter_names, *(item.name for item in self.layout))
        if len(set(self.parameter_names)) != len(self.parameter_names):
            raise ValueError(f"layout = {list(layout)!r}: a parameter is named twice among {list(self.parameter_names)}")
        check_independent(self.layout)
        self._fixed = len(self.parameter_names) - len(self.layout)
        layout_values = [item.value(problem, self.stops) for item in self.layout]
        self.parameters = np.array([problem.frequency, chosen.law.restitution, chosen.clearance, problem.amplitude, problem.phase, *self._more_parameters(chosen.law), *layout_values])
        self.dimension = 2 * problem.size
        length = problem.length_scale()  # Delta + q |H12| on the paper's layout
        self.state_scale = np.repeat([length, problem.omega * length], problem.size)
        names = self.parameter_names
        natural = (*self.natural_scale(problem), *(0.1 * abs(v) if v != 0.0 else 0.1 * _typical(problem, item) for item, v in zip(self.layout, layout_values)))  # exact: a zero entry
        self.parameter_scale = np.array(natural if parameter_scale is None else parameter_scale, dtype=float)
        if self.parameter_scale.shape != (len(names),) or not np.all(self.parameter_scale > 0.0):
            raise ValueError(f"parameter_scale = {parameter_scale!r}: expected {len(names)} positive numbers ({', '.join(names)})")
        self.bounds = dict(bounds or {})
        unknown = set(self.bounds) - set(names)
        if unknown:
            raise ValueError(f"bounds: unknown parameters {sorted(unknown)}; allowed {list(names)}")
        self._box = [(self.parameter_names.index(name), float(low), float(high)) for name, (low, high) in self.bounds.items()]
        self._last: tuple[bytes, ImpactProblem] | None = None  # the last problem built: Newton's iterates share their p

    def __getstate__(self) -> dict[str, Any]:
        """The map without its last problem (a cache: a pickled map sent to a worker carries none)."""
        state = self.__dict__.copy()
        state["_last"] = None
        return state

    def resectioned(self, y: NDArray[np.float64], p: NDArray[np.float64], times: int = 1) -> "Resection | None":
        """The orbit through ``y`` (at parameters ``p``) seen through the strobe in the middle of the widest gap its
        contacts leave over ``times`` map iterations: its state there and ``p`` with the moved force phase [rad]
        (:mod:`~vibroimpact.orbits.sections`); None where it has no contact or no gap, or ``p`` is no problem."""
        try:
            problem = self.problem_at(p)
        except ValueError:
            return None
        periods = self.periods * int(times)
        state = np.asarray(y, dtype=float)
        try:
            gap, run = strobe_gap(problem, state, periods, self.engine)
        except RuntimeError:  # the engine made no progress (endless chattering)
            return None
        if gap is None:
            return None
        moved = np.asarray(p, dtype=float).copy()
        moved[self.parameter_names.index(SECTION_PARAMETER)] = moved_phase(problem, gap.shift)
        return Resection(moved_state(problem, state, periods, self.engine, run, gap.shift), moved, gap)

    def linear_orbit(self, p: NDArray[np.float64]) -> tuple[NDArray[np.float64], float] | None:
        """The contact-free steady state at parameters ``p``, in closed form: its state at the strobe and its least
        relative clearance to a stop (:meth:`contact_free_orbit`, which also gives its amplitudes). None where ``p``
        is no problem, or the structure has no static equilibrium under the load."""
        found = self.contact_free_orbit(p)
        return None if found is None else (found.state, found.clearance)

    def contact_free_orbit(self, p: NDArray[np.float64]) -> "ContactFreeOrbit | None":
        """The contact-free steady state at parameters ``p``, in closed form (:func:`~vibroimpact.analysis.linear.
        linear_amplitudes`): its state at the strobe, its least relative clearance to a stop, min_k (Delta_k -
        |n_k . X| - n_k . x0) / max(|Delta_k|, L / 1000) with L the length scale [-] (negative: it would cross that
        stop; zero: it touches it, an onset; 1: it does not move towards any stop), and its complex amplitudes. None
        where ``p`` is no problem, or the structure has no static equilibrium under the load."""
        try:
            problem = self.problem_at(p)
        except ValueError:
            return None
        linear = linear_amplitudes(problem)
        if not np.all(np.isfinite(linear.static)):
            return None
        x = linear.amplitudes
        state = np.concatenate([linear.static + x.real, (1j * problem.omega * x).real])
        reach = np.abs(linear.stop_amplitudes) + linear.stop_static
        clearances = problem.clearances()
        return ContactFreeOrbit(state, float(np.min((clearances - reach) / np.maximum(np.abs(clearances), 1e-3 * self.state_scale[0]))), linear)

    def impact_orbit(self, p: NDArray[np.float64]) -> tuple[NDArray[np.float64], float] | None:
        """The closed-form one-impact orbit at parameters ``p`` with the least impulse of its admissible roots
        (:func:`~vibroimpact.analysis.impact_orbit.solve_impact_orbit`, eqs. 15-18; next to a grazing onset, the
        orbit born there): its state at the strobe and its distance to grazing, the approach speed over the velocity
        scale w L [-]. None for a map over several periods, where the closed form does not apply (bumpers, several
        stops), or where no admissible root exists."""
        if self.periods != 1:
            return None
        try:
            problem = self.problem_at(p)
            roots = [solve_impact_orbit(problem, root=root) for root in ("+", "-")]
        except ValueError:  # no problem at p, or no closed form for it (closed_form_layout says why)
            return None
        admissible = [orbit for orbit in roots if bool(np.all(orbit.admissible()))]
        if not admissible:
            return None
        orbit = min(admissible, key=lambda item: float(np.ravel(item.impulse)[0]))
        speed = float(np.ravel(orbit.pre_impact_velocity)[0])
        return closed_form_state(problem, orbit), speed / (problem.omega * self.state_scale[0])

    def with_periods(self, periods: int) -> "ImpactMap":
        """The same map over ``periods`` excitation periods (one compiled call per evaluation, unlike ``Iterated``)."""
        return type(self)(self.problem, periods, self.engine, self.bounds, self.stop, self.parameter_scale, tuple(item.name for item in self.layout))

    def _more_parameters(self, law: RigidStop | KelvinVoigtBumper) -> tuple[float, ...]:
        """Values of the parameters after those of :data:`PARAMETERS` (none here) for the chosen stop's ``law``."""
        return ()

    def problem_at(self, p: NDArray[np.float64]) -> ImpactProblem:
        """The problem with parameter vector ``p``: its layout scalars (``layout``) set last, on the problem of the
        other parameters (the last one built is kept: a shot's Newton iterates and its line search share ``p``)."""
        key = np.asarray(p, dtype=float).tobytes()
        last = self._last  # read once: another thread may replace it
        if last is not None and last[0] == key:
            return last[1]
        problem = self._problem_before_layout(p)
        if self.layout:
            problem = with_layout(problem, self.layout, p[self._fixed :], self.stops)
        self._last = (key, problem)
        return problem

    def _problem_before_layout(self, p: NDArray[np.float64]) -> ImpactProblem:
        """The problem with the parameters before the layout scalars."""
        frequency, restitution, clearance, amplitude, phase = (float(x) for x in p[: len(PARAMETERS)])
        base = self.problem
        excitation = dataclasses.replace(base.harmonic, amplitude=amplitude, frequency=frequency, phase=phase)
        stops = tuple(dataclasses.replace(item, law=_law(item.law, clearance, restitution)) if k in self.stops else item for k, item in enumerate(base.stops))
        return ImpactProblem(base.system, stops, excitation)

    def image_problem(self, y: NDArray[np.float64], p: NDArray[np.float64]) -> ImpactProblem | None:
        """The problem at ``p`` where ``y`` has an image (:meth:`evaluate`), else None: a non-finite state, parameters
        outside ``bounds`` or their ranges, or a state inside a stop."""
        if not (np.isfinite(y).all() and all(low <= p[i] <= high for i, low, high in self._box)):
            return None
        try:
            problem = self.problem_at(p)
        except ValueError:  # a Newton iterate outside the parameters' ranges (negative frequency, R > 1, ...)
            return None
        return problem if self.contact == BUMPER or _outside_stops(problem, y) else None

    def evaluate(self, y: NDArray[np.float64], p: NDArray[np.float64]) -> MapEvaluation:
        """The state k periods after ``y`` at t = 0, its Jacobian and the hybrid information.

        A state inside a stop (a negative gap), a non-finite state, invalid parameters (e.g. a Newton iterate at a
        negative frequency, R > 1), parameters outside ``bounds`` and a flight on which the engine makes no progress
        (endless chattering) have no image: NaN, which Newton's method and the corrector treat as a failed step.
        """
        problem = self.image_problem(y, p)
        strobe = None
        if problem is not None:
            try:
                strobe = self.engine.strobe_map(problem, np.asarray(y, dtype=float), 0.0, self.periods)
            except RuntimeError:  # the engine made no progress (endless chattering)
                strobe = None
        if strobe is None:
            n = self.dimension
            return MapEvaluation(np.full(n, np.nan), np.full((n, n), np.nan), None, None)
        velocities = strobe.impact_velocities
        surface = velocities if strobe.surface_onsets is None else velocities[strobe.surface_onsets]
        depth = None
        if strobe.onset_curvatures is not None:  # bumpers: how far beyond the surface each flight would have gone
            pull = np.maximum(-strobe.onset_curvatures[strobe.surface_onsets], 0.0)
            with np.errstate(divide="ignore"):
                depths = np.where(pull > 0.0, surface**2 / (2.0 * pull), math.inf)
            depth = float(depths.min()) if depths.size else math.inf
        length = self.state_scale[0]
        hybrid = HybridInfo(
            impacts=int(velocities.size),
            min_impact_velocity=float(surface.min()) if surface.size else math.inf,
            closest_approach=float(strobe.closest_approach),
            sticks=int(strobe.sticks),
            length_scale=length,
            velocity_scale=problem.omega * length,
            onset_depth=depth,
        )
        return MapEvaluation(strobe.state, strobe.jacobian, None, hybrid)


@dataclass(frozen=True, eq=False)
class Resection:
    """A point of an :class:`ImpactMap` seen through another strobe (:meth:`ImpactMap.resectioned`).

    Attributes
    ----------
    state : ndarray, shape (2N,)
        The orbit's state at the new strobe.
    parameters : ndarray, shape (m,)
        The parameter vector with the new force phase [rad].
    gap : StrobeGap
        The old strobe's distance to the nearest contact and the new one's, in fractions of the period.
    """

    state: NDArray[np.float64]
    parameters: NDArray[np.float64]
    gap: StrobeGap


@dataclass(frozen=True, eq=False)
class ContactFreeOrbit:
    """The contact-free steady state of an :class:`ImpactMap` at a parameter vector (:meth:`ImpactMap.contact_free_orbit`).

    Attributes
    ----------
    state : ndarray, shape (2N,)
        Its state at the strobe (x [m], x' [m s-1]).
    clearance : float
        Its least relative clearance to a stop [-] (negative: it would cross that stop; zero: it touches it).
    amplitudes : LinearAmplitudes
        Its complex amplitudes (:func:`~vibroimpact.analysis.linear.linear_amplitudes` of the map's problem there) [m].
    """

    state: NDArray[np.float64]
    clearance: float
    amplitudes: LinearAmplitudes


def _law(law: RigidStop | KelvinVoigtBumper, clearance: float, restitution: float) -> RigidStop | KelvinVoigtBumper:
    """``law`` with the clearance [m] and restitution [-] of a parameter vector: a rigid stop's R, or a bumper's loss
    factor matched to R with its Omega_b kept (its own loss factor where R is its own)."""
    if isinstance(law, RigidStop):
        return RigidStop(clearance, restitution)
    xi = law.loss_factor if restitution == law.restitution else loss_factor_from_restitution(restitution)
    return KelvinVoigtBumper(clearance, law.frequency, xi)


def _typical(problem: ImpactProblem, item: LayoutParameter) -> float:
    """A magnitude for a layout scalar that is 0 in the base problem: the largest diagonal entry of its matrix, or of
    the stiffness (for a bumper) [its unit]."""
    structure = problem.structure
    matrix = {"mass": structure.mass_matrix, "damping": structure.damping_matrix}.get(item.matrix, structure.stiffness_matrix)
    typical = float(np.max(np.abs(np.diag(matrix))))
    return typical if typical > 0.0 else 1.0


def _outside_stops(problem: ImpactProblem, y: NDArray[np.float64]) -> bool:
    """Every gap Delta_k - n_k . x >= 0 (on the paper's layout: X2 <= Delta): rigid stops (any state of a bumper
    problem has an image: a bumper may be compressed)."""
    return bool(np.all(problem.clearances() - problem.normals() @ np.asarray(y[: problem.size], dtype=float) >= 0.0))
