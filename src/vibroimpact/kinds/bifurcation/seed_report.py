"""The brute-force seeds that settle slowly in a bifurcation study's dataset and on its page
(:mod:`~vibroimpact.kinds.bifurcation.slow_seeds`: what the motion from each reached when shooting from it did not
converge).

Dataset: dimension ``slow_seed``, coordinates ``slow_seed_frequency`` [Hz] and ``slow_seed_restitution``; variables
``slow_seed_outcome`` (CF flags ``failed periodic quasi_periodic chaotic undecided``), ``slow_seed_sweep_period``,
``slow_seed_periods_run``, ``slow_seed_orbit_period``, ``slow_seed_lyapunov_exponent`` and ``_error`` [1/period],
``slow_seed_rotation_number``, ``slow_seed_rotation_period``, ``slow_seed_neimark_sacker_frequency`` [Hz],
``slow_seed_neimark_sacker_angle``, ``slow_seed_branch`` (-1: none) and ``slow_seed_note`` (what it reached, in
words). Absent when no seed settled slowly.
"""

from __future__ import annotations

import html

import numpy as np
import xarray as xr

from vibroimpact.kinds.bifurcation.slow_seeds import SEED_OUTCOMES, SLOW_SEED_FIELDS
from vibroimpact.reporting.style import fmt
from vibroimpact.runs.runner import CaseResult
from vibroimpact.scene.variables import flag_attributes

__all__ = ["SLOW_SEED_ATTRIBUTES", "slow_seed_dataset", "slow_seed_text"]

#: Units and long names of the ``slow_seed`` variables, by field of the branch case's arrays.
SLOW_SEED_ATTRIBUTES: dict[str, tuple[str, dict[str, str]]] = {
    "ss_sweep_period": ("slow_seed_sweep_period", {"units": "1", "long_name": "period the sweep's strobes repeated best with at the seed, in excitation periods"}),
    "ss_periods_run": ("slow_seed_periods_run", {"units": "1", "long_name": "excitation periods the motion from the seed was run on for"}),
    "ss_orbit_period": ("slow_seed_orbit_period", {"units": "1", "long_name": "least period of the periodic orbit the motion reached, in excitation periods (0: none)"}),
    "ss_lyapunov": ("slow_seed_lyapunov_exponent", {"units": "1", "long_name": "largest Lyapunov exponent per excitation period of the motion run on (exact Jacobians; NaN: none estimated)"}),
    "ss_lyapunov_error": ("slow_seed_lyapunov_error", {"units": "1", "long_name": "standard error of slow_seed_lyapunov_exponent per excitation period (block means)"}),
    "ss_rotation": ("slow_seed_rotation_number", {"units": "1", "long_name": "rotation number of the torus's strobes of every slow_seed_rotation_period-th period, in [0, 1/2] (NaN: no torus)"}),
    "ss_rotation_period": ("slow_seed_rotation_period", {"units": "1", "long_name": "excitation periods of the map whose rotation is measured: the closed curves the torus's strobes visit in turn (0: no torus)"}),
    "ss_ns_frequency": ("slow_seed_neimark_sacker_frequency", {"units": "Hz", "long_name": "frequency of the Neimark-Sacker point of a continued branch the torus comes from (NaN: none)"}),
    "ss_ns_angle": ("slow_seed_neimark_sacker_angle", {"units": "1", "long_name": "angle / 2 pi of that point's critical Floquet multipliers, in [0, 1/2], to compare with slow_seed_rotation_number"}),
    "ss_branch": ("slow_seed_branch", {"units": "1", "long_name": "label of the branch the periodic orbit reached was continued as or lies on (-1: none)"}),
    "ss_text": ("slow_seed_note", {"long_name": "what the motion from the seed reached, in words"}),
}


#: The integer variables' types (the others keep the arrays' own: float, text).
_DTYPES = {"ss_sweep_period": np.int16, "ss_orbit_period": np.int16, "ss_rotation_period": np.int16, "ss_periods_run": np.int32, "ss_branch": np.int32}


def slow_seed_dataset(results: list[CaseResult], restitutions: tuple[float, ...]) -> xr.Dataset:
    """The ``slow_seed`` variables of every branch case (``results`` numbered across them, of restitution
    ``restitutions[i]``); an empty dataset where no seed settled slowly."""
    rows = [(r, result) for r, result in zip(restitutions, results) if "ss_outcome" in result and result["ss_outcome"].size]
    if not rows:
        return xr.Dataset()
    joined = {field: np.concatenate([result[field] for _r, result in rows]) for field in SLOW_SEED_FIELDS}
    restitution = np.concatenate([np.full(result["ss_outcome"].size, r) for r, result in rows])
    dim = ("slow_seed",)
    data = {name: (dim, joined[field].astype(_DTYPES.get(field, joined[field].dtype)), attrs) for field, (name, attrs) in SLOW_SEED_ATTRIBUTES.items()}
    data["slow_seed_outcome"] = (dim, joined["ss_outcome"].astype(np.int8), flag_attributes("what the motion from a brute-force seed shooting did not converge from reached", SEED_OUTCOMES))
    coords = {
        "slow_seed_frequency": (dim, joined["ss_frequency"], {"units": "Hz", "long_name": "frequency of the brute-force seed that settles slowly"}),
        "slow_seed_restitution": (dim, restitution, {"units": "1", "long_name": "restitution ratio R of the seed's sweep"}),
    }
    return xr.Dataset(data, coords=coords)


#: How the page counts each outcome.
_WORDS = {"periodic": "periodic", "quasi_periodic": "on a torus", "chaotic": "chaotic", "undecided": "undecided", "failed": "failed (the engine)"}


def slow_seed_text(dataset: xr.Dataset) -> str:
    """The seeds that settle slowly as HTML: per restitution how many and what they reached, then each seed's sentence
    (a list); empty where none did."""
    if "slow_seed_outcome" not in dataset or dataset.sizes.get("slow_seed", 0) == 0:
        return ""
    meanings = str(dataset["slow_seed_outcome"].attrs["flag_meanings"]).split()
    values = dataset["slow_seed_outcome"].values
    restitution = dataset["slow_seed_restitution"].values
    order = np.lexsort((dataset["slow_seed_frequency"].values, restitution))
    parts = []
    for r in np.unique(restitution):
        at = restitution == r
        counts = [f"{int(np.count_nonzero(values[at] == code))} {_WORDS.get(kind, kind)}" for code, kind in enumerate(meanings) if np.any(values[at] == code)]
        parts.append(f"R = {fmt(float(r), 'g')}: {int(at.sum())} ({', '.join(counts)})")
    items = "".join(f"<li>R = {fmt(float(restitution[k]), 'g')}: {html.escape(str(dataset['slow_seed_note'].values[k]))}</li>" for k in order)
    return (f"<p><b>Brute-force seeds that settle slowly</b> (shooting from the sweep's state did not converge; each motion was run on until its "
            f"strobes repeated, or its Lyapunov exponent and strobes said what it is): {'; '.join(parts)}.</p><ul>{items}</ul>")  # fmt: skip
