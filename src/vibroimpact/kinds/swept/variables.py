"""Units and long names of the variables the ``swept`` kind writes beyond the stepped grid's quantities (those, shared
with the stepped kind, are in :mod:`vibroimpact.scene.variables`): whole-run statistics, the running estimates' time
axes, and the attributes of an estimate from a swept-sine run.
"""

from __future__ import annotations

__all__ = ["SWEEP_STAT_ATTRIBUTES", "SWEEP_TIME_ATTRIBUTES", "swept_attributes", "running_attributes"]

#: Whole-run statistics of a swept-sine run (sweep...).
SWEEP_STAT_ATTRIBUTES: dict[str, dict[str, str]] = {
    "sweep_wall_time": {"units": "s", "long_name": "wall time of the whole swept-sine run"},
    "sweep_steps": {"units": "1", "long_name": "integrator steps of the swept-sine run"},
    "sweep_contacts": {"units": "1", "long_name": "bumper contacts during the swept-sine run"},
    "sweep_rhs_calls": {"units": "1", "long_name": "right-hand-side (residual) evaluations of the swept-sine run"},
    "sweep_linear_start": {"units": "1", "long_name": "1: the run started on the linear steady state at its first frequency; 0: at rest (asked for, or the linear state would cross the stop)"},
    "sweep_failed": {"units": "1", "long_name": "1: the integrator failed (values NaN, regime failed); 0: the run finished"},
}
#: The time axes of a swept-sine study's running estimates. ``elapsed_time`` is an elapsed duration, not a date: CF's
#: standard_name ``time`` would need "seconds since <epoch>" units, which readers decode into calendar dates; so no
#: standard_name, and not the reserved name ``time``.
SWEEP_TIME_ATTRIBUTES: dict[str, dict[str, str]] = {
    "elapsed_time": {"units": "s", "long_name": "simulated time since the start of the sweep"},
    "instantaneous_frequency": {"units": "Hz", "long_name": "instantaneous excitation frequency f0 + alpha t"},
}


def swept_attributes(solution: str, attrs: dict[str, object]) -> dict[str, object]:
    """Attributes of a swept-sine estimate on the frequency grid: the quantity's, with the run named."""
    long_name = attrs.get("long_name", "")
    return attrs | {"long_name": f"{solution} swept-sine running estimate centred at each frequency: {long_name}"}


def running_attributes(attrs: dict[str, object]) -> dict[str, object]:
    """Attributes of a running estimate against the sweep's elapsed time, from its quantity's."""
    return {"units": attrs.get("units", "1"), "long_name": f"running estimate over the sweep's window: {attrs.get('long_name', '')}"}
