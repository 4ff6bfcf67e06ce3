"""How stiff a Kelvin-Voigt bumper a structure holds beside its own stiffness in double precision.

In contact a bumper adds K_k n_k n_k^T to the structure's stiffness matrix. An exact flow tells a rigid-body mode from
a flexible one by the one rule (its stiffness eigenvalue at most
:data:`~vibroimpact.model.structure.RIGID_MODE_RATIO` = 1e-12 of the largest: rigid,
:func:`~vibroimpact.model.structure.stiffness_modes`); once K_k is about 1e12 times the structure's softest
flexible stiffness, that mode is taken for a rigid one and the answer converges, wrong (the paper's system at 24 Hz,
R = 0.2: |X1| 1.877 mm from 9e7 Hz on, against the rigid stop's 2.567 mm; right to 5e-9 up to 8e7 Hz). Each contact
mode's softest flexible stiffness must therefore be at least :data:`STIFFNESS_SPREAD` of its stiffest (10x from that
edge: 2.7e7 Hz on the paper's system, 2.7e5 Hz on one whose frequencies are 100x lower). The edge is a ratio of
stiffnesses, not a frequency, so it is the structure's: :func:`bumper_refusal` says it for a problem, with the
largest bumper frequency it accepts.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from vibroimpact.model.structure import stiffness_modes

if TYPE_CHECKING:
    from vibroimpact.model.problem import ImpactProblem

__all__ = ["STIFFNESS_SPREAD", "bumper_refusal"]

#: A contact mode's softest flexible stiffness as a fraction of its stiffest, below which a bumper is refused [-]:
#: strictly inside the rigid-mode rule (10x above :data:`~vibroimpact.model.structure.RIGID_MODE_RATIO`), so that no
#: accepted contact mode has a flexible mode the flows take for a rigid one.
STIFFNESS_SPREAD = 1e-11


def bumper_refusal(problem: ImpactProblem) -> str | None:
    """Why ``problem``'s bumpers are too stiff for its structure (naming the stop, its frequency [Hz], the largest
    frequency accepted and the rigid stop it stands for), or None where every contact mode keeps each flexible mode
    of the structure at least :data:`STIFFNESS_SPREAD` of its stiffest. Rigid-body modes the pushing bumpers do not
    stop stay rigid in contact and are not judged."""
    structure = problem.structure
    stiffness = structure.stiffness_matrix
    normals = problem.normals()
    count = normals.shape[0]
    laws = [stop.law for stop in problem.stops]
    k_b = np.array([law.stiffness(stop.effective_mass(structure.mass_matrix)) for law, stop in zip(laws, problem.stops)])  # type: ignore[union-attr]
    rigid = stiffness_modes(stiffness).rigid
    for mask in range(1, 1 << count):
        pushing = [k for k in range(count) if (mask >> k) & 1]
        k_mode = stiffness + sum(k_b[k] * np.outer(normals[k], normals[k]) for k in pushing)
        stopped = normals[pushing] @ rigid
        expected = rigid.shape[1] - (int(np.linalg.matrix_rank(stopped)) if stopped.size else 0)
        mu = np.sort(np.linalg.eigvalsh(k_mode))
        if expected >= mu.size:
            continue
        top = float(np.max(np.abs(mu)))
        softest = float(mu[expected])
        if softest > STIFFNESS_SPREAD * top:
            continue
        k = max(pushing, key=lambda j: k_b[j])
        law = laws[k]
        limit = law.frequency * math.sqrt(max(softest, 0.0) / (STIFFNESS_SPREAD * top))  # type: ignore[union-attr]  # K_k dominates: top ~ f^2
        if limit > 0.0:
            unit = 10.0 ** (math.floor(math.log10(limit)) - 1)
            limit = math.floor(limit / unit) * unit  # two digits, rounded down: the bound said is one that holds
        return (
            f"stop {k}: bumper frequency = {law.frequency:.6g} Hz is too stiff for this structure: allowed (0, {limit:.2g}] Hz here "  # type: ignore[union-attr]
            f"(in contact its softest mode is {softest / top:.2g} of its stiffest, K = {k_b[k]:.3g} N/m: below {STIFFNESS_SPREAD:g} double "
            f"precision cannot hold both, and the answer converges, wrong); a stiffer bumper is the rigid stop "
            f"RigidStop(clearance={law.clearance!r}, restitution={law.restitution:.6g})"  # type: ignore[union-attr]
        )
    return None
