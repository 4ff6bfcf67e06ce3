"""How a steady state is sought: the settings of :func:`vibroimpact.simulation.steady.steady_state`."""

from __future__ import annotations

from dataclasses import dataclass

from vibroimpact.model.structure import require_in_range
from vibroimpact.model.keywords import suggest_keywords

__all__ = ["SteadySettings", "START_MODES", "SWEEP_STARTS"]

#: Where a steady state at one frequency starts: the linear steady state, the one-impact (PGF) orbit, rest, or the
#: periodic orbit found by shooting from the PGF orbit (:mod:`vibroimpact.simulation.periodic`).
START_MODES = ("linear", "pgf", "rest", "shooting")
#: Stepped sweeps over a frequency grid: each point starts from the previous one's end state (up or down in frequency).
SWEEP_STARTS = ("sweep_up", "sweep_down")


@suggest_keywords
@dataclass(frozen=True)
class SteadySettings:
    """How a steady state is sought.

    Parameters
    ----------
    tolerance : float
        The stroboscopic state repeats when successive states (p periods apart) differ by less than this fraction of
        the motion's scale (positions: Delta + q |H12|; velocities: w times that) [-].
    max_periods : int
        Give up (``converged = False``) after this many periods, and measure anyway.
    chunk_periods : int
        Periods integrated between convergence checks.
    measure_periods : int
        Whole periods measured after convergence (rounded up to a multiple of the detected period).
    irregular_measure_periods : int
        Whole periods measured when the motion did not converge (averages of irregular motion need longer).
    max_multiplicity : int
        Longest period (in excitation periods) recognised as periodic motion.
    start_perturbation : float
        Relative displacement of the ``pgf`` start from the orbit [-], so that the simulation tests the orbit's
        stability rather than sitting on an unstable orbit until round-off grows.
    lyapunov_periods : int
        Where the motion does not become periodic, its largest Lyapunov exponent is estimated over this many periods
        on the attractor: the measured run is extended to this length; ``exact`` takes the exponent from its exact
        Jacobians (nearly free), other engines from a perturbed copy of the run (as many periods again). 0: measure
        ``irregular_measure_periods`` only and classify nothing (``irregular``).
    """

    tolerance: float = 1e-7
    max_periods: int = 1000
    chunk_periods: int = 20
    measure_periods: int = 8
    irregular_measure_periods: int = 64
    max_multiplicity: int = 4
    start_perturbation: float = 1e-6
    lyapunov_periods: int = 1024

    def __post_init__(self) -> None:
        require_in_range("tolerance", self.tolerance, 1e-14, 1e-1)
        require_in_range("max_periods", self.max_periods, 1, 1e8)
        require_in_range("chunk_periods", self.chunk_periods, 2, 1e6)
        require_in_range("measure_periods", self.measure_periods, 1, 1e6)
        require_in_range("irregular_measure_periods", self.irregular_measure_periods, 1, 1e6)
        require_in_range("max_multiplicity", self.max_multiplicity, 1, 64)
        require_in_range("start_perturbation", self.start_perturbation, 0.0, 1e-2)
        require_in_range("lyapunov_periods", self.lyapunov_periods, 0, 1e7)
