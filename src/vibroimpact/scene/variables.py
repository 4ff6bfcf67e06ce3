"""Units, long names and CF flag attributes of every variable and coordinate the package writes: one table.

Studies (:mod:`vibroimpact.study`), the accuracy benchmark and the sweep-cost table take their attributes from here,
and reports read them back from the datasets. A new quantity gets its line here (and its place in
:data:`vibroimpact.scene.schema.QUANTITIES` if a scene may ask for it).
"""

from __future__ import annotations

import numpy as np

from vibroimpact.analysis.stability import regime_attributes

__all__ = ["VARIABLE_ATTRIBUTES", "SWEEP_STAT_ATTRIBUTES", "CONVERGED_ATTRIBUTES", "STABLE_MARGINAL", "STABLE_ATTRIBUTES", "COORDINATE_ATTRIBUTES", "SWEEP_TIME_ATTRIBUTES", "BENCHMARK_ATTRIBUTES", "LADDER_ATTRIBUTES", "SWEEP_COST_ATTRIBUTES", "BIFURCATION_ATTRIBUTES", "flag_attributes", "quantity_attributes", "swept_attributes", "running_attributes", "QUANTITIES", "MOTION_QUANTITIES", "STOP_QUANTITIES", "quantities_for", "CLOSED_FORM_METHODS"]

#: Quantities of a study (solution, grid...).
VARIABLE_ATTRIBUTES: dict[str, dict[str, str]] = {
    "x1_amplitude": {"units": "m", "long_name": "fundamental-harmonic amplitude of the primary-mass displacement X1"},
    "x2_amplitude": {"units": "m", "long_name": "fundamental-harmonic amplitude of the absorber displacement X2"},
    "force_amplitude": {"units": "N", "long_name": "fundamental-harmonic amplitude of the force transmitted to the base (suspension plus impacts, eq. 23)"},
    "suspension_force_amplitude": {"units": "N", "long_name": "fundamental-harmonic amplitude of the force through the suspension alone (eq. 21)"},
    "impulse": {"units": "N s", "long_name": "impact impulse per period (0 where the motion is linear; simulations: total impulse of the impacts per period)"},
    "phase": {"units": "rad", "long_name": "phase of the impact relative to the linear absorber motion (varphi + psi12, eq. 15)"},
    "floquet_modulus": {"units": "1", "long_name": "largest modulus of the Floquet multipliers of the admissible closed-form impact orbit (one impact per period; two on a symmetric pair of stops) (< 1: stable); solution pgf only"},
    "one_impact_x1_amplitude": {"units": "m", "long_name": "|X1| fundamental of the one-impact solution of eqs. 15-17 wherever it exists, unchecked (admissible or not, stable or not)"},
    "one_impact_x2_amplitude": {"units": "m", "long_name": "|X2| fundamental of the one-impact solution of eqs. 15-18 wherever it exists, unchecked"},
    "one_impact_force_amplitude": {"units": "N", "long_name": "force fundamental (eq. 23) of the one-impact solution wherever it exists, unchecked"},
    "one_impact_impulse": {"units": "N s", "long_name": "impulse (eq. 16) of the one-impact solution wherever it exists, unchecked"},
    "impacts_per_period": {"units": "1", "long_name": "impacts per excitation period (simulations: measured over whole periods)"},
    "x1_rms": {"units": "m", "long_name": "RMS of x1(t) over a period, static offset included (simulations: integrated exactly over the measured whole periods; closed-form impact orbits: Gauss-Legendre quadrature of the reconstructed orbit, 64 nodes; linear motion: sqrt(static^2 + |X1|^2 / 2))"},
    "x2_rms": {"units": "m", "long_name": "RMS of x2(t) over a period, static offset included (simulations: integrated exactly over the measured whole periods; closed-form impact orbits: Gauss-Legendre quadrature of the reconstructed orbit, 64 nodes; linear motion: sqrt(static^2 + |X2|^2 / 2))"},
    "peak_acceleration": {"units": "m s-2", "long_name": "largest deceleration of the absorber on the bumper, bumper force less absorber spring over M2 (compliant: measured; pgf: (M2 Gamma(xi_b) Omega_b J / (M2 (1 + R)) - absorber spring force at the impact) / M2; rigid engines: NaN; no contact: 0)"},
    "peak_contact_force": {"units": "N", "long_name": "largest bumper force (compliant: measured; pgf: Gamma(xi_b) Omega_b J / (1 + R); rigid engines: NaN; no contact: 0)"},
    "wall_time": {"units": "s", "long_name": "wall time of the simulation at this point (one process; swept-sine tests: the whole sweep)"},
    "lyapunov_exponent": {"units": "1", "long_name": "largest Lyapunov exponent of the stroboscopic map per excitation period where the simulated motion is not periodic (exact: from its exact Jacobians; other engines: from a perturbed copy of their own run)"},
    "lyapunov_error": {"units": "1", "long_name": "standard error of lyapunov_exponent per excitation period (spread of block averages)"},
    "rotation_number": {"units": "1", "long_name": "rotation number of the strobe points around their centre, cycles per excitation period, where they lie on a closed curve (quasi-periodic motion)"},
    "spectral_line_fraction": {"units": "1", "long_name": "fraction of the power of the X1 strobe sequence in its 5 largest spectral lines (near 1: a line spectrum, quasi-periodic; low: broadband, chaotic)"},
}
#: Whole-run statistics of a swept-sine run (sweep...).
SWEEP_STAT_ATTRIBUTES: dict[str, dict[str, str]] = {
    "sweep_wall_time": {"units": "s", "long_name": "wall time of the whole swept-sine run"},
    "sweep_steps": {"units": "1", "long_name": "integrator steps of the swept-sine run"},
    "sweep_contacts": {"units": "1", "long_name": "bumper contacts during the swept-sine run"},
    "sweep_rhs_calls": {"units": "1", "long_name": "right-hand-side (residual) evaluations of the swept-sine run"},
    "sweep_linear_start": {"units": "1", "long_name": "1: the run started on the linear steady state at its first frequency; 0: at rest (asked for, or the linear state would cross the stop)"},
    "sweep_failed": {"units": "1", "long_name": "1: the integrator failed (values NaN, regime failed); 0: the run finished"},
}
CONVERGED_ATTRIBUTES = {
    "long_name": "the simulated stroboscopic state repeated to the steady-state tolerance",
    "units": "1",
    "flag_values": np.array([-1, 0, 1], dtype=np.int8),
    "flag_meanings": "not_applicable not_converged converged",
}
#: The ``stable`` flag of an orbit whose largest |Floquet multiplier| is 1 within round-off.
STABLE_MARGINAL = 2
STABLE_ATTRIBUTES = {
    "long_name": "Floquet stability of the reported closed-form impact orbit (one impact per period; two on a symmetric pair of stops) (solution pgf only)",
    "units": "1",
    "flag_values": np.array([-1, 0, 1, STABLE_MARGINAL], dtype=np.int8),
    "flag_meanings": "not_applicable unstable stable marginal",
}
COORDINATE_ATTRIBUTES: dict[str, dict[str, str]] = {
    "frequency": {"units": "Hz", "long_name": "excitation frequency"},
    "restitution": {"units": "1", "long_name": "restitution ratio R"},
    "clearance": {"units": "m", "long_name": "clearance Delta between absorber and stop"},
    "solution": {"long_name": "solution method"},
    "bumper_frequency": {"units": "Hz", "long_name": "apparent natural frequency Omega_b / 2 pi of the compliant bumper"},
    "bumper_loss_factor": {"units": "1", "long_name": "loss factor xi_b of the compliant bumper"},
    "sweep": {"long_name": "direction of the swept-sine test"},
}
#: The time axes of a swept-sine study's running estimates. ``elapsed_time`` is an elapsed duration, not a date: CF's
#: standard_name ``time`` would need "seconds since <epoch>" units, which readers decode into calendar dates; so no
#: standard_name, and not the reserved name ``time``.
SWEEP_TIME_ATTRIBUTES: dict[str, dict[str, str]] = {
    "elapsed_time": {"units": "s", "long_name": "simulated time since the start of the sweep"},
    "instantaneous_frequency": {"units": "Hz", "long_name": "instantaneous excitation frequency f0 + alpha t"},
}
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

#: A bifurcation study (branch_point, special_point, brute force over (restitution, sweep, frequency, ...), chart).
BIFURCATION_ATTRIBUTES: dict[str, dict[str, str]] = {
    "branch": {"units": "1", "long_name": "label of the continued branch the point belongs to"},
    "branch_frequency": {"units": "Hz", "long_name": "excitation frequency of the branch point"},
    "branch_restitution": {"units": "1", "long_name": "restitution ratio R of the branch point"},
    "branch_bumper_frequency": {"units": "Hz", "long_name": "Omega_b / 2 pi of the branch point's Kelvin-Voigt bumpers (inf: the rigid stop)"},
    "x1_amplitude": {"units": "m", "long_name": "fundamental-harmonic amplitude of X1 over the orbit's period"},
    "x2_amplitude": {"units": "m", "long_name": "fundamental-harmonic amplitude of X2 over the orbit's period"},
    "impulse": {"units": "N s", "long_name": "total impact impulse of the orbit per excitation period"},
    "floquet_modulus": {"units": "1", "long_name": "largest modulus of the orbit's Floquet multipliers (< 1: stable)"},
    "impacts_per_period": {"units": "1", "long_name": "impacts per excitation period of the orbit (impacts per orbit period / period_multiplicity)"},
    "period_multiplicity": {"units": "1", "long_name": "the orbit's period in excitation periods (1: period one, 2: born at a period doubling ...)"},
    "floquet_multiplier_real": {"units": "1", "long_name": "real part of the Floquet multipliers (eigenvalues of the monodromy), by decreasing modulus"},
    "floquet_multiplier_imag": {"units": "1", "long_name": "imaginary part of the Floquet multipliers, by decreasing modulus"},
    "impact_velocity": {"units": "m s-1", "long_name": "approach velocity of each impact over the orbit's period (NaN-padded)"},
    "special_point_frequency": {"units": "Hz", "long_name": "excitation frequency of the special point"},
    "special_point_restitution": {"units": "1", "long_name": "restitution ratio R of the special point"},
    "special_point_bumper_frequency": {"units": "Hz", "long_name": "Omega_b / 2 pi of the special point's Kelvin-Voigt bumpers (inf: the rigid stop)"},
    "special_point_branch": {"units": "1", "long_name": "label of the branch on which the special point was located"},
    "special_point_x1_amplitude": {"units": "m", "long_name": "fundamental-harmonic amplitude of X1 of the orbit at the special point"},
    "special_point_impulse": {"units": "N s", "long_name": "impact impulse per excitation period of the orbit at the special point"},
    "special_point_floquet_modulus": {"units": "1", "long_name": "largest |Floquet multiplier| at the special point"},
    "special_point_impacts_per_period": {"units": "1", "long_name": "impacts per excitation period of the orbit at the special point"},
    "special_point_period_multiplicity": {"units": "1", "long_name": "period of the orbit at the special point, in excitation periods"},
    "special_point_multiplier_real": {"units": "1", "long_name": "real part of the Floquet multipliers at the special point"},
    "special_point_multiplier_imag": {"units": "1", "long_name": "imaginary part of the Floquet multipliers at the special point"},
    "special_point_note": {"long_name": "what happens at the special point"},
    "special_point_branches": {"long_name": "labels of every branch the special point was found on, space-separated (the first: special_point_branch, whose orbit the other variables describe)"},
    "brute_x1": {"units": "m", "long_name": "brute force: X1 at each kept strobe t = k T (force q cos(w t))"},
    "brute_x1_amplitude": {"units": "m", "long_name": "brute force: fundamental-harmonic amplitude of X1 over each kept period"},
    "brute_impact_velocity": {"units": "m s-1", "long_name": "brute force: approach velocity of the impacts over the kept periods (the last ones; NaN-padded)"},
    "brute_impacts_per_period": {"units": "1", "long_name": "brute force: impacts per excitation period over the kept periods"},
    "brute_period": {"units": "1", "long_name": "brute force: period of the strobes in excitation periods (0: none found up to 8)"},
    "brute_lyapunov_exponent": {"units": "1", "long_name": "brute force: largest Lyapunov exponent per excitation period where the strobes do not repeat (exact Jacobians)"},
    "chart_curve": {"units": "1", "long_name": "label of the curve of special points in (frequency, clearance)"},
    "stiffness_curve": {"units": "1", "long_name": "label of the curve of a bumper's special point in (frequency, bumper frequency)"},
    "stiffness_restitution": {"units": "1", "long_name": "collision restitution R of the curve's bumpers"},
    "stiffness_frequency": {"units": "Hz", "long_name": "excitation frequency of the special point at the curve point's bumper frequency"},
    "stiffness_bumper_frequency": {"units": "Hz", "long_name": "Omega_b / 2 pi of the bumpers at the curve point (1 / T_b, T_b the bumper period)"},
    "chart_frequency": {"units": "Hz", "long_name": "excitation frequency of the chart's curve point"},
    "chart_clearance": {"units": "m", "long_name": "clearance Delta of the chart's curve point"},
    "map_frequency": {"units": "Hz", "long_name": "excitation frequency of the regime map"},
    "map_clearance": {"units": "m", "long_name": "clearance Delta of the regime map"},
    "chart_impacts_per_period": {"units": "1", "long_name": "regime map: impacts per excitation period over the kept periods"},
    "chart_period": {"units": "1", "long_name": "regime map: period of the strobes in excitation periods (0: none found up to 8)"},
    "strobe": {"units": "1", "long_name": "index of the kept strobe (excitation period) at each frequency"},
}


def flag_attributes(long_name: str, meanings: tuple[str, ...], dtype: type = np.int8) -> dict[str, object]:
    """CF flag attributes of an integer variable whose values 0, 1, ... mean ``meanings``."""
    return {"long_name": long_name, "units": "1", "flag_values": np.arange(len(meanings), dtype=dtype), "flag_meanings": " ".join(meanings)}


def quantity_attributes(quantity: str) -> dict[str, object]:
    """Units, long name and (for flags) CF flag attributes of a quantity."""
    return dict({"regime": regime_attributes(), "stable": STABLE_ATTRIBUTES, "converged": CONVERGED_ATTRIBUTES}.get(quantity, VARIABLE_ATTRIBUTES.get(quantity, {})))


def swept_attributes(solution: str, attrs: dict[str, object]) -> dict[str, object]:
    """Attributes of a swept-sine estimate on the frequency grid: the quantity's, with the run named."""
    long_name = attrs.get("long_name", "")
    return attrs | {"long_name": f"{solution} swept-sine running estimate centred at each frequency: {long_name}"}


def running_attributes(name: str) -> dict[str, str]:
    """Attributes of a running estimate against the sweep's elapsed time (``running_<quantity>``)."""
    quantity = name.removeprefix("running_")
    base = VARIABLE_ATTRIBUTES.get(quantity, {})
    return {"units": base.get("units", "1"), "long_name": f"running estimate over the sweep's window: {base.get('long_name', quantity)}"}


# --------------------------------------------------------------------------------------------------------------------
# The quantities a scene can ask for: the paper's names, and the per-coordinate names of a general scene.
# --------------------------------------------------------------------------------------------------------------------

#: Quantities a scene can ask for (``regime`` is always written: it says what the others mean).
QUANTITIES = (
    "x1_amplitude",
    "x2_amplitude",
    "force_amplitude",
    "suspension_force_amplitude",
    "impulse",
    "phase",
    "regime",
    "stable",
    "floquet_modulus",
    "one_impact_x1_amplitude",
    "one_impact_x2_amplitude",
    "one_impact_force_amplitude",
    "one_impact_impulse",
    "impacts_per_period",
    "converged",
    "x1_rms",
    "x2_rms",
    "peak_acceleration",
    "peak_contact_force",
    "wall_time",
    "lyapunov_exponent",
    "lyapunov_error",
    "rotation_number",
    "spectral_line_fraction",
)
#: The evidence of what a non-periodic simulated motion is (NaN where the motion is periodic, and for closed forms).
MOTION_QUANTITIES = ("lyapunov_exponent", "lyapunov_error", "rotation_number", "spectral_line_fraction")
#: Quantities with one value per stop (a ``stop`` dimension in a general scene with several stops).
STOP_QUANTITIES = ("impulse", "one_impact_impulse", "peak_acceleration", "peak_contact_force")
#: Quantities with one value per coordinate: ``x1``/``x2`` in the paper's names, ``<name>`` in a general scene.
_PER_COORDINATE = {"x1_amplitude": "{}_amplitude", "one_impact_x1_amplitude": "one_impact_{}_amplitude", "x1_rms": "{}_rms"}


def quantities_for(coordinates: tuple[str, ...]) -> tuple[str, ...]:
    """The quantities a scene with these coordinates can ask for: :data:`QUANTITIES` with the per-coordinate ones
    (``x1_amplitude``, ``x2_amplitude`` ...) named after each coordinate (the same tuple for ``x1, x2``)."""
    out: list[str] = []
    for quantity in QUANTITIES:
        if quantity in _PER_COORDINATE:
            out += [_PER_COORDINATE[quantity].format(name) for name in coordinates]
        elif quantity.replace("x2", "x1") not in _PER_COORDINATE:
            out.append(quantity)
    return tuple(out)


#: How the closed forms and the base force are computed: recorded beside the layout of every grid study (stepped,
#: swept) and of a benchmark of a layout other than the paper's.
CLOSED_FORM_METHODS = {
    "method_pgf": "closed-form impact orbit (periodic Green function of the stopped coordinate n^T H n; one impact per period on one stop, two on a symmetric two-sided stop); stable (+) root",
    "method_force": "force on the base: 1^T (K x + C x') through springs and dashpots plus (1^T n_k) lambda_k of each absolute stop",
}
