"""Brute-force sweeps of a bifurcation study: a motion whose exact Jacobian is undefined at one strobe is still
classified (from its strobes), instead of ending the study."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from vibroimpact.engines.exact import ExactEngine
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.contact import Stop
from vibroimpact.model.system import PAPER_SYSTEM
from vibroimpact.kinds.bifurcation import cases as bifurcation_cases
from vibroimpact.kinds.bifurcation.cases import MOTION_CLASSES, SweepCase

#: The paper's layout at R = 0.2, 34 Hz: a non-periodic attractor (Lyapunov exponent ~0.11 per period).
AT_34_HZ = ImpactProblem(PAPER_SYSTEM.structure, (Stop(RigidStop(3e-3, 0.2), coordinate=1),), HarmonicForce(10.0, 34.0))


class UndefinedJacobian(ExactEngine):
    """The compiled engine with one strobe's Jacobian undefined (NaN), as a chatter sequence that ends exactly as a
    release begins leaves it (met on the relative two-sided stops at 24 Hz, Delta = 3 mm)."""

    def integrate(self, problem, state, t_start, periods, **options):  # type: ignore[no-untyped-def]
        run = super().integrate(problem, state, t_start, periods, **options)
        if not options.get("jacobians"):
            return run
        jacobians = run.strobe_jacobians.copy()
        jacobians[jacobians.shape[0] // 2] = np.nan
        return dataclasses.replace(run, strobe_jacobians=jacobians)


#: The classes of a motion whose strobes do not repeat.
NON_PERIODIC = ("quasi_periodic", "chaotic", "irregular")


def test_a_non_periodic_point_is_classified_with_its_exponent() -> None:
    out = SweepCase(AT_34_HZ, "up", (34.0,), 100, 64).run()
    assert MOTION_CLASSES[int(out["regime"][0])] in NON_PERIODIC and out["lyapunov"][0] > 0.05


def test_an_undefined_jacobian_leaves_the_strobes_to_classify_the_motion(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(bifurcation_cases, "make_engine", lambda name: UndefinedJacobian())  # the registry's engine, replaced
    out = SweepCase(AT_34_HZ, "up", (34.0,), 100, 64).run()
    assert MOTION_CLASSES[int(out["regime"][0])] in NON_PERIODIC
    assert np.isnan(out["lyapunov"][0]) and out["period"][0] == 0 and out["impacts"][0] > 0.25
