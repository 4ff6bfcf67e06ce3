"""Units and long names of the variables the ``bifurcation`` kind writes (the flags and coordinates it shares with
other kinds are in :mod:`vibroimpact.scene.variables`).
"""

from __future__ import annotations

__all__ = ["BIFURCATION_ATTRIBUTES"]

#: A bifurcation study (branch_point, special_point, brute force over (restitution, sweep, frequency, ...), chart).
BIFURCATION_ATTRIBUTES: dict[str, dict[str, str]] = {
    "branch": {"units": "1", "long_name": "label of the continued branch the point belongs to"},
    "branch_frequency": {"units": "Hz", "long_name": "excitation frequency of the branch point"},
    "branch_restitution": {"units": "1", "long_name": "restitution ratio R of the branch point"},
    "branch_bumper_frequency": {"units": "Hz", "long_name": "Omega_b / 2 pi of the branch point's Kelvin-Voigt bumpers (inf: the rigid stop)"},
    "bumper_frequency": {"units": "Hz", "long_name": "Omega_b / 2 pi of the brute force's Kelvin-Voigt bumpers (inf: the rigid stop)"},
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
    "special_point_induced_by": {"units": "Hz", "long_name": "frequency of the contact onset within 1e-3 of whose grazing the point was found, its multipliers' jump there (NaN: a smooth bifurcation)"},
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
