"""The grids of a general scene's stop values: what each stop of a ``stops`` list takes from the sweep, from itself,
or from the scene's ``bumper`` section (:func:`stop_grids`, used by :mod:`vibroimpact.scene.grid`)."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from vibroimpact.model.collision import MAX_LOSS_FACTOR, MIN_BUMPER_RESTITUTION, restitution_from_loss_factor
from vibroimpact.model.layout import StopSpec
from vibroimpact.scene.checker import Checker, interval

__all__ = ["stop_grids"]



#: Swept parameter -> (field of StopSpec, key of a stop entry, key of the scene's ``bumper`` section).
_PARAMETERS = {
    "restitution": ("restitution", "restitution", None),
    "clearance": ("clearance", "clearance", None),
    "bumper_frequency": ("bumper_frequency", "bumper.frequency", "frequency"),
    "bumper_loss_factor": ("bumper_loss_factor", "bumper.loss_factor", "loss_factor"),
}


def stop_grids(
    c: Checker,
    specs: tuple[StopSpec, ...],
    grids: dict[str, np.ndarray | None],
    sweep: dict[str, Any],
    bumper: dict[str, Any],
    targets: tuple[int, ...] | None,
    needs_bumper: bool,
) -> tuple[StopSpec, ...]:
    """Check which stop gets which value and fill ``grids`` (restitution, clearance, bumper_frequency,
    bumper_loss_factor); return the stops with the values they take from the grid set to None.

    Parameters
    ----------
    c : Checker
        Records the problems.
    specs : tuple of StopSpec
        The stops as given.
    grids : dict
        The swept grids already checked (key: parameter); unswept ones are added here.
    sweep : dict
        The ``sweep`` section.
    bumper : dict
        The scene's ``bumper`` section (values every stop without its own bumper takes), checked by the caller.
    targets : tuple of int or None
        ``sweep.stop``: the stops swept values apply to (None: all).
    needs_bumper : bool
        A solution needs a bumper on every stop (``compliant``).
    """
    swept_to = set(range(len(specs))) if targets is None else set(targets)
    out = [dataclasses.asdict(spec) for spec in specs]
    for parameter, (field, key, bumper_key) in _PARAMETERS.items():
        if parameter == "bumper_loss_factor" and "bumper_loss_factor" not in sweep and "loss_factor" not in bumper and all(s.bumper_loss_factor is None for s in specs):
            continue  # each stop's loss factor follows its restitution
        if parameter == "bumper_frequency" and not needs_bumper and "bumper_frequency" not in sweep:
            continue  # no solution needs a bumper: the stops' own bumpers are not used
        derived = parameter == "restitution" and "bumper_loss_factor" in sweep
        values: list[float | None] = []
        for k, spec in enumerate(specs):
            own = getattr(spec, field)
            if (parameter in sweep or derived) and k in swept_to:
                if own is not None:
                    given = {"bumper_frequency": ("bumper.stiffness", spec.bumper_stiffness), "bumper_loss_factor": ("bumper.damping", spec.bumper_damping)}.get(parameter)
                    written = given[0] if given is not None and given[1] is not None else key  # the key the scene wrote
                    c.fail(f"stops[{k}].{written}", f"also swept in sweep.{'bumper_loss_factor' if derived else parameter}: give it in one place only")
                values.append(None)
                continue
            if own is None and bumper_key is not None and bumper_key in bumper:
                own = bumper[bumper_key]
            if own is None and parameter == "restitution" and spec.bumper_loss_factor is not None:
                own = restitution_from_loss_factor(spec.bumper_loss_factor)  # R(xi_b) of the stop's own bumper
            if own is None and parameter == "restitution" and "loss_factor" in bumper and isinstance(bumper["loss_factor"], (int, float)):
                own = restitution_from_loss_factor(float(bumper["loss_factor"]))
            if own is None and parameter != "bumper_loss_factor":
                where = f"sweep.{parameter}" + ("" if targets is None else " with sweep.stop naming it")
                extra = " or the scene's bumper section" if bumper_key is not None else ""
                c.fail(f"stops[{k}].{key}", f"required unless swept ({where}{extra})")
            values.append(own)
            out[k][field] = own
        given = [v for v in values if v is not None]
        if parameter in sweep or derived:
            if derived and grids.get("bumper_loss_factor") is not None:
                grids["restitution"] = np.array([restitution_from_loss_factor(x) for x in grids["bumper_loss_factor"]])  # type: ignore[union-attr]
            continue
        if parameter == "bumper_loss_factor" and len(given) < len(values):
            grids[parameter] = None  # some stops follow their restitution: no one loss factor
            continue
        if given and len(given) == len(values) and all(math.isclose(v, given[0], rel_tol=0.0, abs_tol=0.0) for v in given):
            grids[parameter] = np.array([given[0]])
            for entry in out:
                entry[field] = None  # shared: the grid's one value
        else:
            grids[parameter] = np.array([math.nan])
    _check_zero_restitution(c, out, grids, needs_bumper)
    return tuple(StopSpec(**entry) for entry in out)


def _check_zero_restitution(c: Checker, specs: list[dict[str, Any]], grids: dict[str, np.ndarray | None], needs_bumper: bool) -> None:
    """R = 0 needs an infinitely damped bumper: a compliant solution needs the loss factor given for such a stop."""
    if not needs_bumper or grids.get("bumper_loss_factor") is not None:
        return
    r_grid = grids.get("restitution")
    for k, spec in enumerate(specs):
        if spec["bumper_loss_factor"] is not None:
            continue
        values = [spec["restitution"]] if spec["restitution"] is not None else ([] if r_grid is None else list(r_grid))
        if any(v < MIN_BUMPER_RESTITUTION for v in values):
            least = "R = 0 needs an infinitely damped bumper" if any(v == 0.0 for v in values) else f"R = {min(values):g} needs a bumper more damped than loss factor {MAX_LOSS_FACTOR:g}"
            c.fail(f"stops[{k}].restitution", f"{least} for the compliant solution: give the stop's bumper.loss_factor in {interval(0.0, MAX_LOSS_FACTOR)}, or R >= {MIN_BUMPER_RESTITUTION:.2g}")
