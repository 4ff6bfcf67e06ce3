"""Units and long names of the variables the ``benchmark`` kind writes: the accuracy benchmark, its model-cost ladder
and the swept-sine cost table of ``run-study sweep-cost`` (the variables shared with other kinds are in
:mod:`vibroimpact.scene.variables`).
"""

from __future__ import annotations

__all__ = ["BENCHMARK_ATTRIBUTES", "LADDER_ATTRIBUTES", "SWEEP_COST_ATTRIBUTES"]

#: The accuracy benchmark (case, engine, rtol; case, reference).
BENCHMARK_ATTRIBUTES: dict[str, dict[str, str]] = {
    "wall_time": {"units": "s", "long_name": "median wall time of one run"},
    "rhs_calls": {"units": "1", "long_name": "right-hand-side (or residual) evaluations"},
    "steps": {"units": "1", "long_name": "integrator steps where the engine counts them (NaN otherwise)"},
    "impacts": {"units": "1", "long_name": "impacts (contacts) found"},
    "missed_impacts": {"units": "1", "long_name": "impacts of the reference not found within 1e-3 of a period"},
    "extra_impacts": {"units": "1", "long_name": "impacts found that the reference does not have"},
    "impact_time_error": {"units": "s", "long_name": "largest impact-time error over matched impacts"},
    "impulse_error": {"units": "1", "long_name": "largest relative impulse error over matched impacts"},
    "final_state_error": {"units": "1", "long_name": "error of the final state relative to the reference's largest values (stepped cases)"},
    "x1_error": {"units": "1", "long_name": "error of the X1 fundamental relative to the reference (stepped: over the whole run; swept: largest difference of the running 8-cycle fundamental over its largest value)"},
    "reference_wall_time": {"units": "s", "long_name": "wall time of the reference run"},
    "reference_impacts": {"units": "1", "long_name": "impacts of the reference"},
    "reference_x1": {"units": "m", "long_name": "X1 fundamental of the reference (swept: its largest running value)"},
    "exact_wall_time": {"units": "s", "long_name": "median wall time of the exact reference"},
    "periods": {"units": "1", "long_name": "whole excitation periods of a stepped run (NaN: swept case)"},
    "time_per_period": {"units": "s", "long_name": "wall time per excitation period, wall_time / periods (stepped cases; an engine without tolerances: one run, stored at every rtol)"},
    "reference_time_per_period": {"units": "s", "long_name": "wall time per excitation period of the exact reference (compiled engine with its Python face, moments included)"},
    "floor_time_per_period": {"units": "s", "long_name": "wall time per excitation period of the exact engine's compiled kernel alone (exact_core.run_periods, arguments prepared untimed) on the same run, moments included: the exact reference's floor"},
    "floor_no_moments_time_per_period": {"units": "s", "long_name": "as floor_time_per_period without the per-period Fourier moments (strobes, impacts and segments only)"},
    "rtol": {"units": "1", "long_name": "relative tolerance rtol (atol = rtol x atol_ratio)"},
    "reference": {"long_name": "reference of the rigid-stop methods (exact), of the compliant methods on stepped cases (compliant_exact, the bumper in closed form) and on swept ones (CVODE Adams, rtol 1e-13: a chirp has no closed form)"},
}
#: The benchmark's model-cost ladder (model).
LADDER_ATTRIBUTES: dict[str, dict[str, str]] = {
    "ladder_wall_time": {"units": "s", "long_name": "wall time of one steady-state point (pgf: one closed-form point), median"},
    "ladder_x1_amplitude": {"units": "m", "long_name": "steady-state |X1| fundamental"},
    "ladder_x1_difference": {"units": "1", "long_name": "relative difference of |X1| from the exact engine"},
}
#: The swept-sine cost table of ``run-study sweep-cost`` (run).
SWEEP_COST_ATTRIBUTES: dict[str, dict[str, str]] = {
    "span": {"long_name": "simulated sweep (full, or the slice run from rest)"},
    "simulated_time": {"units": "s", "long_name": "simulated time"},
    "wall_time": {"units": "s", "long_name": "wall time of the run"},
    "wall_per_simulated_second": {"units": "s s-1", "long_name": "wall time per simulated second"},
    "cost_ratio": {"units": "1", "long_name": "wall time per simulated second over IDA's on the same span (IDA at the default tolerances)"},
    "projected_full_time": {"units": "s", "long_name": "wall time the full sweep would take at this run's cost ratio to IDA"},
    "rhs_calls": {"units": "1", "long_name": "residual (IDA) or right-hand-side (solve_ivp nfev) evaluations"},
    "steps": {"units": "1", "long_name": "IDA step attempts (not reported by solve_ivp: NaN)"},
    "jacobians": {"units": "1", "long_name": "Jacobian evaluations (solve_ivp njev; NaN for IDA)"},
    "contacts": {"units": "1", "long_name": "contacts begun"},
    "ida_contacts": {"units": "1", "long_name": "contacts of IDA over the same span"},
    "x1_fundamental_max_diff": {"units": "m", "long_name": "largest |difference| of the running X1 fundamental from IDA's on the same span"},
    "x1_fundamental_rel_diff": {"units": "1", "long_name": "the same, over the largest running X1 fundamental of IDA"},
    "x1_fundamental_diff_at": {"units": "Hz", "long_name": "instantaneous frequency where the largest difference occurs"},
    "band_rel_diff": {"units": "1", "long_name": "largest |difference| of the running X1 fundamental from IDA's within the slice's frequency band, over IDA's largest value there"},
    "band_contacts": {"units": "1", "long_name": "contacts begun within the slice's frequency band"},
    "band_ida_contacts": {"units": "1", "long_name": "contacts of IDA within the slice's frequency band on the same span"},
}
