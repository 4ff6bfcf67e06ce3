"""What a bifurcation scene says, as frozen dataclasses: the brute force, the continued branches and the
two-parameter chart (the parser, :mod:`vibroimpact.scene.bifurcation`, builds them from checked values).

This module imports nothing from the rest of the scene layer, so that :class:`vibroimpact.scene.schema.Scene` can
name :class:`BifurcationSettings` without a circle of imports.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from vibroimpact.model.validation import require_in_range, require_positive

__all__ = ["BIFURCATION_TOP_KEYS", "CHART_KINDS", "BruteForceSettings", "BranchSettings", "ChartSettings", "BifurcationSettings", "coordinate_label"]

#: Top-level keys of a bifurcation scene (``stop`` is the paper's stop on x2, ``stops`` any layout).
BIFURCATION_TOP_KEYS = {"name", "description", "system", "excitation", "stop", "stops", "bifurcation", "report"}
#: Special points whose curves the two-parameter chart can follow (the order of the CF flags of ``special_point_kind``).
CHART_KINDS = ("fold", "period_doubling", "neimark_sacker", "grazing")
#: Most brute-force periods of one scene (frequencies x restitutions x directions x periods per point).
MAX_BRUTE_PERIODS = 50_000_000


def coordinate_label(name: str) -> str:
    """How a bifurcation study's texts name a coordinate: ``X1`` for ``x1`` (a letter and digits, capitalised, as
    the paper writes them), any other name as it is (``floor2``)."""
    return name.upper() if re.fullmatch(r"[a-z][0-9]+", name) else name


@dataclass(frozen=True)
class BruteForceSettings:
    """Stepped sweeps of the time simulation (``exact``), the end state carried to the next frequency.

    Attributes
    ----------
    step : float
        Frequency step [Hz].
    transient_periods : int
        Periods integrated and dropped at each frequency.
    strobes : int
        Strobes (whole periods) kept at each frequency.
    directions : tuple of str
        ``up`` and/or ``down``.
    """

    step: float = 0.05
    transient_periods: int = 300
    strobes: int = 64
    directions: tuple[str, ...] = ("up", "down")  # scene.schema.SWEEP_DIRECTIONS (the parser checks against it)

    def __post_init__(self) -> None:
        require_positive("step", self.step)
        require_in_range("transient_periods", self.transient_periods, 0, 1_000_000)
        require_in_range("strobes", self.strobes, 1, 100_000)


@dataclass(frozen=True)
class BranchSettings:
    """Which branches are continued in frequency, and how far.

    Attributes
    ----------
    one_impact : bool
        The branches of the closed-form impact orbit, started at both roots of eq. 16 (corrected): one impact per
        period on one stop, the symmetric two impacts per period on a two-sided stop; none where the layout has no
        closed form.
    period_doubling : bool
        Period-2 branches switched at every period doubling of a period-1 branch.
    grazing : bool
        Branches born at grazing points where an orbit with another (non-zero) impact count continues.
    linear : bool
        The impactless (linear) orbit wherever it fits inside every stop (closed form).
    brute_force : bool
        Branches seeded from the brute force: where a sweep's strobes repeat with a period k on an orbit no other
        branch passes through, that orbit continued as a fixed point of the k-period map.
    max_steps : int
        Most continuation steps per direction of a branch.
    max_step : float
        Largest arclength step, in the continuation's scaled variables [-].
    """

    one_impact: bool = True
    period_doubling: bool = True
    grazing: bool = True
    linear: bool = True
    brute_force: bool = True
    max_steps: int = 2000
    max_step: float = 0.1

    def __post_init__(self) -> None:
        require_in_range("max_steps", self.max_steps, 1, 100_000)
        require_in_range("max_step", self.max_step, 1e-4, 1.0)


@dataclass(frozen=True)
class ChartSettings:
    """The two-parameter chart (frequency x clearance at one restitution).

    Attributes
    ----------
    restitution : float
        R of the chart [-].
    clearance : (float, float)
        Clearance range [m].
    kinds : tuple of str
        Special points followed in (frequency, clearance), from :data:`CHART_KINDS`.
    max_steps : int
        Most continuation steps per direction of a curve.
    frequency_step : float
        Frequency step of the regime map's brute-force sweeps [Hz].
    clearance_num : int
        Clearances of the regime map (evenly spaced over the range).
    transient_periods, strobes : int
        Periods dropped, and kept for the classification, at each point of the regime map.
    """

    restitution: float = 0.2
    clearance: tuple[float, float] = (1e-3, 6e-3)
    kinds: tuple[str, ...] = CHART_KINDS
    max_steps: int = 300
    frequency_step: float = 0.25
    clearance_num: int = 12
    transient_periods: int = 300
    strobes: int = 128

    def __post_init__(self) -> None:
        require_in_range("restitution", self.restitution, 0.0, 1.0)
        if not 0.0 < self.clearance[0] < self.clearance[1]:
            raise ValueError(f"clearance = {self.clearance!r}: expected 0 < start < stop [m]")
        require_in_range("max_steps", self.max_steps, 1, 100_000)
        require_positive("frequency_step", self.frequency_step)
        require_in_range("clearance_num", self.clearance_num, 2, 1000)
        require_in_range("transient_periods", self.transient_periods, 0, 1_000_000)
        require_in_range("strobes", self.strobes, 64, 100_000)

    @property
    def clearances(self) -> np.ndarray:
        """The regime map's clearances [m]."""
        return np.linspace(self.clearance[0], self.clearance[1], self.clearance_num)


@dataclass(frozen=True, eq=False)
class BifurcationSettings:
    """What a bifurcation study computes.

    Attributes
    ----------
    low, high : float
        The frequency band [Hz].
    restitution : tuple of float
        R of each bifurcation diagram [-].
    brute_force : BruteForceSettings
        Stepped sweeps up and down.
    branches : BranchSettings
        Continued branches.
    chart : ChartSettings or None
        The two-parameter chart (None: none).
    """

    low: float
    high: float
    restitution: tuple[float, ...]
    brute_force: BruteForceSettings = BruteForceSettings()
    branches: BranchSettings = BranchSettings()
    chart: ChartSettings | None = None

    def __post_init__(self) -> None:
        if not 0.0 < self.low < self.high:
            raise ValueError(f"frequency band ({self.low!r}, {self.high!r}): expected 0 < start < stop [Hz]")

    @property
    def frequency(self) -> np.ndarray:
        """The brute-force frequency grid [Hz], increasing."""
        count = math.floor((self.high - self.low) / self.brute_force.step * (1.0 + 1e-12)) + 1
        return np.round(self.low + self.brute_force.step * np.arange(count), 10)

    @property
    def chart_frequency(self) -> np.ndarray:
        """The regime map's frequency grid [Hz] (empty without a chart)."""
        if self.chart is None:
            return np.zeros(0)
        count = math.floor((self.high - self.low) / self.chart.frequency_step * (1.0 + 1e-12)) + 1
        return np.round(self.low + self.chart.frequency_step * np.arange(count), 10)
