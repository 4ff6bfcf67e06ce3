"""Reading a Kelvin-Voigt bumper in a scene, in either form (a stop's ``bumper`` or the scene's ``bumper`` section).

* the frequency form: ``{frequency: Omega_b / 2 pi [Hz], loss_factor: xi_b [-]}``, as in the seed paper;
* physical units: ``{stiffness: K_b [N/m], damping: B_b [N s/m]}`` or ``{stiffness: K_b [N/m], loss_factor: xi_b [-]}``,
  as a datasheet gives them, converted with the effective mass m_eff [kg] of the stop the bumper sits on, on the
  scene's structure (:meth:`~vibroimpact.model.layout.StopSpec.effective_mass`): Omega_b = sqrt(K_b / m_eff),
  xi_b = B_b / (2 m_eff Omega_b) (:meth:`~vibroimpact.model.contact.KelvinVoigtBumper.from_stiffness`).

Every part may be left out (the sweep, the scene's ``bumper`` section or the restitution gives it), but the two forms
do not mix: ``frequency`` with ``stiffness`` or ``damping``, and ``damping`` with ``loss_factor``, are refused naming
the keys; ``damping`` needs ``stiffness`` beside it. A converted value outside the frequency form's range is refused
naming the key the scene wrote, with its allowed range in the scene's units.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, NamedTuple

from vibroimpact.model.collision import MAX_LOSS_FACTOR
from vibroimpact.model.contact import KelvinVoigtBumper
from vibroimpact.model.layout import Layout, StopSpec
from vibroimpact.scene.checker import Checker
from vibroimpact.scene.declared import DERIVED, Key, Section
from vibroimpact.model.parameters import MAX_BUMPER_FREQUENCY as _MAX_FREQUENCY

__all__ = ["BUMPER", "BUMPER_KEYS", "PHYSICAL_KEYS", "MAX_BUMPER_LOSS_FACTOR", "BumperSpec", "parse_bumper", "read_bumper", "convert_bumper", "bumper_form_problem", "scene_bumper"]

#: A Kelvin-Voigt bumper, declared (:mod:`vibroimpact.scene.declared`): frequency with loss_factor, or stiffness with
#: damping or loss_factor (converted with its stop's effective mass); read at ``bumper``, ``stop.bumper``, ``stops[k].bumper``.
BUMPER = Section("bumper", (
    Key("frequency", float, "Omega_b / 2 pi on the stop's effective mass", DERIVED, 0.0, _MAX_FREQUENCY, "Hz", open_low=True),
    Key("loss_factor", float, "xi_b, the bumper's loss (derived: from the restitution, or from damping)", DERIVED, 0.0, MAX_LOSS_FACTOR),
    Key("stiffness", float, "K_b, instead of frequency", DERIVED, 0.0, math.inf, "N m-1", open_low=True),
    Key("damping", float, "B_b, with stiffness, instead of loss_factor", DERIVED, 0.0, math.inf, "N s m-1"),
), "a Kelvin-Voigt bumper on a stop (the compliant contact model)")  # fmt: skip
#: Keys of a bumper, in either form.
BUMPER_KEYS = set(BUMPER.names)
#: Keys of a bumper in physical units only.
PHYSICAL_KEYS = {"stiffness", "damping"}
#: Most damped bumper accepted, as xi_b [-]: the model's own limit.
MAX_BUMPER_LOSS_FACTOR = MAX_LOSS_FACTOR


class BumperSpec(NamedTuple):
    """A bumper as a scene gave it; each value None where not given.

    Attributes
    ----------
    frequency : float or None
        Omega_b / 2 pi [Hz]: given, or converted from ``stiffness`` (None where the effective mass is not known).
    loss_factor : float or None
        xi_b [-]: given, or converted from ``damping``.
    stiffness : float or None
        K_b [N m-1] as given (physical units).
    damping : float or None
        B_b [N s m-1] as given.
    """

    frequency: float | None = None
    loss_factor: float | None = None
    stiffness: float | None = None
    damping: float | None = None


def bumper_form_problem(keys: set[str]) -> str | None:
    """Why the bumper keys ``keys`` mix the two forms (the message names them), None where they do not."""
    if "frequency" in keys and keys & {"stiffness", "damping"}:
        physical = " and ".join(sorted(keys & {"stiffness", "damping"}))
        return (f"give the bumper either as frequency [Hz] (with loss_factor [-]) or as stiffness [N/m] (with damping [N s/m] or loss_factor [-]), "
                f"not both: remove frequency or {physical}")  # fmt: skip
    if "damping" in keys and "loss_factor" in keys:
        return "give damping [N s/m] or loss_factor [-], not both: each sets the bumper's loss, xi_b = B_b / (2 sqrt(K_b m_eff))"
    if "damping" in keys and "stiffness" not in keys:
        return "damping [N s/m] needs stiffness [N/m] beside it (xi_b = B_b / (2 sqrt(K_b m_eff))): give both, or frequency [Hz] with loss_factor [-]"
    return None


def parse_bumper(c: Checker, key: str, value: Any, effective_mass: float | None) -> BumperSpec | None:
    """The bumper at ``key`` in either form, converted to Omega_b / 2 pi [Hz] and xi_b [-] with ``effective_mass``
    m_eff [kg] (None: not known, the structure is unusable; its problem is recorded where it is read); None where
    a value is unusable (every problem recorded in ``c``, naming the key the scene wrote)."""
    spec = read_bumper(c, key, value)
    return None if spec is None else convert_bumper(c, key, spec, effective_mass)


def read_bumper(c: Checker, key: str, value: Any) -> BumperSpec | None:
    """The bumper at ``key`` as given, each value checked against its own range, the forms not mixed; not converted."""
    read = BUMPER.at(key).read(c, value, partial=True)
    if read is None:
        return None
    problem = bumper_form_problem(set(map(str, value)) & BUMPER_KEYS)
    if problem is not None:
        c.fail(key, problem)
        return None
    if any(read[name] is None for name in value if name in BUMPER_KEYS) or set(map(str, value)) - BUMPER_KEYS:
        return None
    return BumperSpec(read["frequency"], read["loss_factor"], read["stiffness"], read["damping"])


def convert_bumper(c: Checker, key: str, spec: BumperSpec, effective_mass: float | None, where: str = "this stop") -> BumperSpec | None:
    """``spec`` with its stiffness [N m-1] and damping [N s m-1] converted to Omega_b / 2 pi [Hz] and xi_b [-] on a
    stop of ``effective_mass`` m_eff [kg] (``where``: that stop, in the messages); unchanged in the frequency form or
    where m_eff is not known (None); None where a converted value is out of range (recorded, naming ``key``'s
    stiffness or damping and its allowed range in N/m or N s/m)."""
    stiffness, damping = spec.stiffness, spec.damping
    if stiffness is None or effective_mass is None:
        return spec
    if not math.sqrt(stiffness / effective_mass) / (2.0 * math.pi) <= _MAX_FREQUENCY:  # also inf
        most = effective_mass * (2.0 * math.pi * _MAX_FREQUENCY) ** 2
        c.fail(f"{key}.stiffness", f"{stiffness:g} N/m is out of range: allowed (0, {most:.4g}] N/m on {where} (effective mass {effective_mass:.6g} kg, "
               f"Omega_b / 2 pi <= {_MAX_FREQUENCY:g} Hz)")  # fmt: skip
        return None
    try:
        law = KelvinVoigtBumper.from_stiffness(0.0, stiffness, effective_mass, damping, (spec.loss_factor or 0.0) if damping is None else None)
    except ValueError:  # a loss factor beyond double precision
        law = None
    if damping is not None and (law is None or not law.loss_factor <= MAX_BUMPER_LOSS_FACTOR):
        most = 2.0 * MAX_BUMPER_LOSS_FACTOR * math.sqrt(stiffness * effective_mass)
        c.fail(f"{key}.damping", f"{damping:g} N s/m is out of range: allowed [0, {most:.4g}] N s/m with this stiffness on {where} "
               f"(effective mass {effective_mass:.6g} kg, loss factor xi_b <= {MAX_BUMPER_LOSS_FACTOR:g})")  # fmt: skip
        return None
    assert law is not None
    return BumperSpec(law.frequency, law.loss_factor if damping is not None else spec.loss_factor, stiffness, damping)


def scene_bumper(c: Checker, value: dict, sweep: dict[str, Any], layout: Layout | None, stops_given: bool) -> tuple[dict[str, float], Layout | None]:
    """A grid scene's ``bumper`` section in physical units, {stiffness, damping} or {stiffness, loss_factor}: the
    values the grid reads (``frequency`` [Hz], ``loss_factor`` [-], as the frequency form gives them) and the layout
    whose stops record the stiffness and damping as given (their words and attributes say them).

    With the paper's ``stop``, the bumper is converted with that stop's effective mass; with ``stops``, each stop
    that gives no bumper frequency or stiffness of its own takes the scene's, converted with its own effective mass
    (equal values are then shared by the grid, different ones kept per stop). A ``stiffness`` or ``damping`` also
    swept (``sweep.bumper_frequency``, ``sweep.bumper_loss_factor``) is refused naming both keys, as is a stop with
    its own bumper frequency (or stiffness) and no loss of its own beside the scene's ``damping`` (B_b needs the
    stiffness it damps).
    """
    spec = read_bumper(c, "bumper", value)
    for name, parameter in (("stiffness", "bumper_frequency"), ("damping", "bumper_loss_factor")):
        if name in value and parameter in sweep:
            c.fail(f"bumper.{name}", f"also swept in sweep.{parameter}: give the bumper in one place only (sweeps are in Omega_b / 2 pi [Hz] and xi_b [-])")
            spec = None
    if spec is None or layout is None:
        return {}, layout
    shared = {"loss_factor": spec.loss_factor} if spec.damping is None and spec.loss_factor is not None else {}
    if not stops_given:  # the paper's stop above x2
        converted = convert_bumper(c, "bumper", spec, layout.stops[0].effective_mass(layout.structure), "the stop")
        if converted is None:
            return {}, layout
        stop = dataclasses.replace(layout.stops[0], bumper_stiffness=spec.stiffness, bumper_damping=spec.damping)
        return {"frequency": converted.frequency} | ({} if converted.loss_factor is None else {"loss_factor": converted.loss_factor}), layout.with_stops((stop,))
    stops: list[StopSpec] = []
    for k, stop in enumerate(layout.stops):
        if stop.bumper_frequency is not None or stop.bumper_stiffness is not None:
            if spec.damping is not None and stop.bumper_loss_factor is None:
                c.fail(f"stops[{k}].bumper", "gives its own bumper frequency (or stiffness) but no loss, while the scene's bumper gives damping [N s/m]: "
                       "give this stop's damping or loss_factor too")  # fmt: skip
            stops.append(stop)
            continue
        converted = convert_bumper(c, "bumper", spec, stop.effective_mass(layout.structure), f"stops[{k}]")
        if converted is None:
            return {}, layout
        changes: dict[str, Any] = {"bumper_frequency": converted.frequency, "bumper_stiffness": spec.stiffness}
        if spec.damping is not None and stop.bumper_loss_factor is None:
            changes |= {"bumper_loss_factor": converted.loss_factor, "bumper_damping": spec.damping}
        stops.append(dataclasses.replace(stop, **changes))
    return shared, layout.with_stops(tuple(stops))
