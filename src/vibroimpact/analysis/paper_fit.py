"""The paper's own route to the one-impact orbit (``pgf_paper``): its fitted Green function and constant chi22'(0-).

The closed form of :func:`~vibroimpact.analysis.impact_orbit.solve_impact_orbit` takes the periodic Green function
chi_u of the stopped coordinate and its left derivative chi_u'(0-) at the impact from the exact poles and residues
of n^T H(s) n. The seed paper, on its layout (two masses, one upper stop on the absorber x2, the force on x1),
replaces both:

* chi22 by eq. 12 with the modal parameters of eq. 10 fitted to |H22| with Omega_i fixed at the undamped values of
  eq. 11 (:func:`~vibroimpact.model.modal.fit_modal_parameters`; chi22(0) is then eq. 14);
* chi22'(0-) by the constant -1/(2 M2) (half the jump 1/M2 of chi22' at the impact, as if chi22' were odd about
  it), which turns c of eq. 15 into (1 - R) / (2 (1 + R) M2 w).

Everything else stays exact: chi12 (the primary mass's response to the impacts), the receptances H11, H12, H22 of
the harmonics (eqs. 17-23) and the linear part of the motion. :class:`PaperFit` is that choice, an option of the
one closed form: ``solve_impact_orbit(problem, ..., green=PaperFit.of(problem))``. Its orbit reconstructs x1 with
the exact chi12 and x2 with the fitted chi22, so x2(0) = Delta holds, while x2'(0-) is the fitted chi22's and not
the J / (M2 (1 + R)) of the impact law: the paper's orbits are not orbits of the real system. Near the linear
resonances chi22'(0-) is far from the constant, which gives the spurious spikes of the paper's figures 5-8 (and
one-impact "orbits" at Delta = 1 m for R = 1, where c = 0): ``pgf_paper`` is kept to show where the shortcut
misleads.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike, NDArray

from vibroimpact.model.layout import Layout
from vibroimpact.model.modal import ModalParameters, ModalResponse, PoleResidueModel, fit_modal_parameters, impulse_modes
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import TwoDofSystem

__all__ = ["PaperFit"]

#: The paper's layout stops the absorber: coordinate x2 (index 1), approached from below (n = e2).
_STOPPED = 1


@dataclass(frozen=True, eq=False)
class PaperFit:
    """The paper's Green model of the stopped coordinate: eq. 10 fitted to |H22| and the constant chi22'(0-).

    Attributes
    ----------
    system : TwoDofSystem
        The paper's named system whose H22 was fitted.
    parameters : ModalParameters
        Omega_i [rad s-1] (eq. 11, fixed), fitted loss factors xi_i [-] and real form factors A_i [kg-1] (eq. 10).
    problem : ImpactProblem or None
        The problem :meth:`of` found to be the paper's layout on ``system`` (its paper view computed once, there):
        :meth:`modes` asks no more of it.
    """

    system: TwoDofSystem
    parameters: ModalParameters
    problem: ImpactProblem | None = field(default=None, repr=False)

    @classmethod
    def of(cls, problem: ImpactProblem) -> "PaperFit":
        """The fit for ``problem``, which must be the paper's layout on its named system.

        Raises
        ------
        ValueError
            If ``problem`` is not the paper's layout (a two-mass chain x1, x2; one upper stop on x2; force on x1), or
            its system does not have two underdamped modes (eq. 10 then does not describe it).
        """
        system = Layout.of_problem(problem).paper_view()
        if system is None:
            raise ValueError("pgf_paper is the paper's route for its layout (a two-mass chain x1, x2; one upper stop on x2; force on x1): use pgf")
        return cls(system, fit_modal_parameters(system), problem)

    @cached_property
    def model(self) -> PoleResidueModel:
        """The fitted H22 as poles and residues (eq. 10): the transform of the fitted chi22's impulse response
        (computed once)."""
        return self.parameters.to_pole_residue()

    def modes(self, problem: ImpactProblem) -> ModalResponse:
        """Every coordinate's response to a unit impulse on the stop: x1's exact, x2's the fitted H22.

        The poles are the exact ones followed by the fitted ones; x1's residues at the fitted poles and x2's at the
        exact ones are zero, so that n . x = x2 is the fitted model alone and x1 the exact chi12.

        Raises
        ------
        ValueError
            If ``problem`` is not the paper's layout on this fit's system.
        """
        if problem is not self.problem and Layout.of_problem(problem).paper_view() != self.system:
            raise ValueError("green: the paper's fit belongs to another system or layout; build it with PaperFit.of(problem)")
        size = problem.size
        normal = np.zeros(size)
        normal[_STOPPED] = 1.0
        exact = impulse_modes(problem.structure, normal)
        fitted = self.model
        count = exact.poles.size
        residues = np.concatenate([exact.residues, np.zeros((size, fitted.poles.size), dtype=complex)], axis=1)
        residues[_STOPPED, :count] = 0.0
        residues[_STOPPED, count:] = fitted.residues
        return ModalResponse(poles=np.concatenate([exact.poles, fitted.poles]), residues=residues)

    def rate_before(self, omega: ArrayLike) -> NDArray[np.float64]:
        """The paper's chi22'(0-) = -1/(2 M2) at every angular frequency ``omega`` [m N-1 s-2]."""
        return np.full(np.shape(omega), -1.0 / (2.0 * self.system.m2))
