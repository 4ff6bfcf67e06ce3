"""How a branch is followed: the settings of :mod:`~vibroimpact.orbits.continuation` and
:mod:`~vibroimpact.orbits.special_curves`."""

from __future__ import annotations

import math
from dataclasses import dataclass

from vibroimpact.model.structure import require_in_range, require_positive
from vibroimpact.orbits.branch import SPECIAL_POINT_KINDS
from vibroimpact.model.keywords import suggest_keywords

__all__ = ["ContinuationSettings"]


@suggest_keywords
@dataclass(frozen=True)
class ContinuationSettings:
    """How a branch is followed.

    Parameters
    ----------
    step : float
        First arclength step, in scaled variables (state / state_scale, parameter / parameter_scale) [-].
    min_step, max_step : float
        Limits of the adapted step [-].
    max_steps : int
        Most points on the branch (per direction).
    lower, upper : float
        Bounds of the continued parameter (its own unit, e.g. Hz).
    tolerance : float
        Scaled residual at which the corrector stops [-].
    max_corrector_iterations : int
        Newton iterations per corrector.
    max_turn : float
        Largest angle between consecutive tangents [rad]; a larger turn halves the step.
    locate_tolerance : float
        Relative precision of a located special point's parameter [-].
    detect : tuple of str
        Special points to detect (subset of ``SPECIAL_POINT_KINDS``).
    stop_at_grazing : bool
        End the branch at a grazing point (True), or carry on with the new impact count when an orbit exists there
        (False, the default: through contact onsets, on to the contact-free orbit and back).
    clear : float
        Without ``stop_at_grazing``: a contact-free stretch ends the branch (``end = 'clear'``) once its clearance
        to every stop exceeds this fraction [-] of the stop's clearance and grows (the linear orbit then moves less
        than half the gap): it is known in closed form, and it would go on to zero or infinite frequency.
    grazing_margin : float
        A failed step from a point whose grazing margin is below this is searched for a grazing point [-].
    """

    step: float = 0.05
    min_step: float = 1e-7
    max_step: float = 0.3
    max_steps: int = 2000
    lower: float = -math.inf
    upper: float = math.inf
    tolerance: float = 1e-11
    max_corrector_iterations: int = 8
    max_turn: float = 0.35
    locate_tolerance: float = 1e-10
    detect: tuple[str, ...] = SPECIAL_POINT_KINDS
    stop_at_grazing: bool = False
    grazing_margin: float = 0.05
    clear: float = 0.5

    def __post_init__(self) -> None:
        for name in ("step", "min_step", "max_step", "tolerance", "locate_tolerance", "grazing_margin", "clear"):
            require_positive(name, getattr(self, name))
        require_in_range("max_steps", self.max_steps, 1, 10**7)
        require_in_range("max_turn", self.max_turn, 1e-3, math.pi / 2)
        if not self.lower < self.upper:
            raise ValueError(f"lower = {self.lower!r} must be below upper = {self.upper!r}")
        unknown = set(self.detect) - set(SPECIAL_POINT_KINDS)
        if unknown:
            raise ValueError(f"detect: unknown kinds {sorted(unknown)}; allowed {SPECIAL_POINT_KINDS}")
