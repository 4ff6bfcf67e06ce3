"""The quantities a scene can ask for: the paper's names, and the per-coordinate names of a general scene."""

from __future__ import annotations

__all__ = ["QUANTITIES", "MOTION_QUANTITIES", "STOP_QUANTITIES", "quantities_for"]

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
