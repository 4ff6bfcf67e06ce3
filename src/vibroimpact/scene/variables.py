"""Units, long names and CF flag attributes of the variables and coordinates more than one kind writes, and the
quantities a scene may ask for.

The stepped and swept kinds' grid quantities (:data:`VARIABLE_ATTRIBUTES`, :func:`quantity_attributes`), the
``converged`` and ``stable`` flags, the grid coordinates (also the bifurcation kind's) and CF flags of any integer
variable (:func:`flag_attributes`). A variable only one kind writes is declared in that kind's folder, where it is
made (``kinds/<kind>/variables.py``: the bifurcation kind's, the benchmark kind's and its sweep-cost table's, the
swept kind's statistics and running estimates). Reports read the attributes back from the datasets. A new grid
quantity gets its line here (and its place in :data:`QUANTITIES` if a scene may ask for it).
"""

from __future__ import annotations

import numpy as np

from vibroimpact.analysis.stability import regime_attributes
from vibroimpact.model.parameters import PARAMETERS

__all__ = ["VARIABLE_ATTRIBUTES", "CONVERGED_ATTRIBUTES", "STABLE_MARGINAL", "STABLE_ATTRIBUTES", "COORDINATE_ATTRIBUTES", "flag_attributes", "quantity_attributes", "QUANTITIES", "MOTION_QUANTITIES", "STOP_QUANTITIES", "quantities_for"]

#: Quantities of a stepped or swept study (solution, grid...).
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
    **{name: {"units": PARAMETERS[name].unit, "long_name": PARAMETERS[name].long_name} for name in ("frequency", "restitution", "clearance")},
    "solution": {"long_name": "solution method"},
    **{name: {"units": PARAMETERS[name].unit, "long_name": PARAMETERS[name].long_name} for name in ("bumper_frequency", "bumper_loss_factor")},
    "sweep": {"long_name": "direction of the swept-sine test"},
}


def flag_attributes(long_name: str, meanings: tuple[str, ...], dtype: type = np.int8) -> dict[str, object]:
    """CF flag attributes of an integer variable whose values 0, 1, ... mean ``meanings``."""
    return {"long_name": long_name, "units": "1", "flag_values": np.arange(len(meanings), dtype=dtype), "flag_meanings": " ".join(meanings)}


def quantity_attributes(quantity: str) -> dict[str, object]:
    """Units, long name and (for flags) CF flag attributes of a quantity."""
    return dict({"regime": regime_attributes(), "stable": STABLE_ATTRIBUTES, "converged": CONVERGED_ATTRIBUTES}.get(quantity, VARIABLE_ATTRIBUTES.get(quantity, {})))


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
