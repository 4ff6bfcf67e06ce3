"""The linear two-degree-of-freedom system: primary mass on a suspension, absorber on the primary mass.

Equations of motion (seed paper eq. 1, without the contact force)::

    M1 X1'' + B1 X1' + B2 (X1' - X2') + K1 X1 + K2 (X1 - X2) = Q(t)
    M2 X2'' + B2 (X2' - X1') + K2 (X2 - X1)                 = -Phi

``X1`` and ``X2`` are absolute displacements [m]; the force ``Q`` acts on the primary mass, the contact force
``Phi`` on the absorber.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike, NDArray

from vibroimpact.model.excitation import angular_frequency, check_closed_form_inputs
from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.model.structure import DAMPING_RATIO, MASS_RATIO, STIFFNESS_RATIO, LinearStructure, require_non_negative, require_positive, require_ratio

__all__ = ["TwoDofSystem", "Receptances", "PAPER_SYSTEM", "NAMED_KEYS", "named_system", "LinearResponse", "paper_linear_response"]


@dataclass(frozen=True)
class Receptances:
    """Complex dynamic compliances H(j omega) of the system [m N-1], arrays over frequency.

    Attributes
    ----------
    h11 : ndarray of complex
        Displacement of the primary mass per unit force on the primary mass [m N-1].
    h12 : ndarray of complex
        Displacement of the absorber per unit force on the primary mass (and, by reciprocity, the other way
        round) [m N-1].
    h22 : ndarray of complex
        Displacement of the absorber per unit force on the absorber [m N-1].
    """

    h11: NDArray[np.complex128]
    h12: NDArray[np.complex128]
    h22: NDArray[np.complex128]


@suggest_keywords
@dataclass(frozen=True)
class TwoDofSystem:
    """Masses, springs and dashpots of the vibration protection system (paper fig. 1).

    Parameters
    ----------
    m1 : float
        Primary mass M1 [kg], > 0.
    m2 : float
        Absorber mass M2 [kg], > 0.
    k1 : float
        Suspension stiffness K1 between base and primary mass [N m-1], > 0.
    k2 : float
        Absorber stiffness K2 between primary mass and absorber [N m-1], > 0.
    b1 : float
        Suspension damping B1 [N s m-1], >= 0.
    b2 : float
        Absorber damping B2 [N s m-1], >= 0.
    """

    m1: float = field(metadata={"units": "kg"})
    m2: float = field(metadata={"units": "kg"})
    k1: float = field(metadata={"units": "N m-1"})
    k2: float = field(metadata={"units": "N m-1"})
    b1: float = field(default=0.0, metadata={"units": "N s m-1"})
    b2: float = field(default=0.0, metadata={"units": "N s m-1"})

    def __post_init__(self) -> None:
        for name in ("m1", "m2", "k1", "k2"):
            require_positive(f"system.{name}", getattr(self, name))
        for name in ("b1", "b2"):
            require_non_negative(f"system.{name}", getattr(self, name))

    def check_ratios(self) -> None:
        """``ValueError`` naming the parameters and the allowed ratio where double precision cannot hold them together:
        m2 / m1 beyond :data:`~vibroimpact.model.structure.MASS_RATIO` (or below its inverse), k2 / k1 beyond
        :data:`~vibroimpact.model.structure.STIFFNESS_RATIO`, b^2 / (k m) of a dashpot beyond
        :data:`~vibroimpact.model.structure.DAMPING_RATIO`.

        The scene checker calls it, so that a scene is refused before any work; the Python API leaves such systems to
        its caller (a test models a free absorber by k2 = 1e-12 k1).
        """
        require_ratio("system", "m2 / m1", self.m2 / self.m1, MASS_RATIO, why="one mass is lost to round-off next to the other")
        require_ratio("system", "k2 / k1", self.k2 / self.k1, STIFFNESS_RATIO, why="one spring is lost to round-off next to the other")
        for b, k, m in (("b1", "k1", "m1"), ("b2", "k2", "m2")):
            zeta = getattr(self, b) / (math.sqrt(getattr(self, k)) * math.sqrt(getattr(self, m)))
            require_ratio("system", f"{b}^2 / ({k} {m})", zeta * zeta, DAMPING_RATIO, 0.0, why="an overdamped mode's slow pole is lost to round-off")

    @classmethod
    def of(cls, structure: "TwoDofSystem | LinearStructure") -> "TwoDofSystem | None":
        """The named view of ``structure``: the paper's two-mass chain it is, or None if it is not one.

        A :class:`LinearStructure` is the named system when its coordinates are ``x1`` (primary) and ``x2``
        (absorber), its mass matrix is diagonal, and its stiffness and damping matrices are those of a suspension
        (K1, B1: base to x1) and an absorber spring and dashpot (K2, B2: x1 to x2) and nothing else::

            K = [[K1 + K2, -K2], [-K2, K2]],  C = [[B1 + B2, -B2], [-B2, B2]],  K1, K2 > 0,  B1, B2 >= 0

        The absorber's row is compared exactly (a chain written in a scene repeats the same number); K1 = K[0, 0] - K2
        and B1 = C[0, 0] - B2 [SI]. This is the one place that decides whether a structure has the named view (its
        parameters m1 ... b2, natural and anti-resonance frequencies, the paper's fit of H22).

        Parameters
        ----------
        structure : TwoDofSystem or LinearStructure
            A named system (returned as it is) or any structure.

        Returns
        -------
        TwoDofSystem or None
            The named system with the same matrices (K1 and B1 to round-off), or None.
        """
        if isinstance(structure, TwoDofSystem):
            return structure
        if structure.size != 2 or tuple(structure.coordinates) != ("x1", "x2"):
            return None
        m, k, c = structure.mass_matrix, structure.stiffness_matrix, structure.damping_matrix
        k2, b2 = -float(k[0, 1]), -float(c[0, 1])
        chain = m[0, 1] == 0.0 and m[1, 0] == 0.0 and k[1, 0] == k[0, 1] and c[1, 0] == c[0, 1] and k[1, 1] == k2 and c[1, 1] == b2  # exact: see above
        k1, b1 = float(k[0, 0]) - k2, float(c[0, 0]) - b2
        if not (chain and k1 > 0.0 and k2 > 0.0 and b1 >= 0.0 and b2 >= 0.0):
            return None
        return cls(m1=float(m[0, 0]), m2=float(m[1, 1]), k1=k1, k2=k2, b1=b1, b2=b2)

    def with_absorber(self, stiffness: float, damping: float) -> "TwoDofSystem":
        """The same primary (m1, k1, b1) and absorber mass m2 with the absorber's stiffness k2 = ``stiffness``
        [N m-1] and damping b2 = ``damping`` [N s m-1] (each checked as the constructor checks it)."""
        return TwoDofSystem(self.m1, self.m2, self.k1, stiffness, self.b1, damping)

    # ------------------------------------------------------------------ matrices
    @property
    def mass_matrix(self) -> NDArray[np.float64]:
        """Mass matrix M [kg]."""
        return np.diag([self.m1, self.m2])

    @property
    def stiffness_matrix(self) -> NDArray[np.float64]:
        """Stiffness matrix K [N m-1]."""
        return np.array([[self.k1 + self.k2, -self.k2], [-self.k2, self.k2]])

    @property
    def damping_matrix(self) -> NDArray[np.float64]:
        """Damping matrix B [N s m-1]."""
        return np.array([[self.b1 + self.b2, -self.b2], [-self.b2, self.b2]])

    @property
    def state_matrix(self) -> NDArray[np.float64]:
        """First-order state matrix A [s-1] for the state (X1, X2, X1', X2'): y' = A y + forcing."""
        minv = np.linalg.inv(self.mass_matrix)
        zero, eye = np.zeros((2, 2)), np.eye(2)
        return np.block([[zero, eye], [-minv @ self.stiffness_matrix, -minv @ self.damping_matrix]])

    @cached_property
    def structure(self) -> LinearStructure:
        """The same system as a :class:`LinearStructure` with coordinates ``x1`` (primary) and ``x2`` (absorber)."""
        return LinearStructure(self.mass_matrix, self.stiffness_matrix, self.damping_matrix, ("x1", "x2"))

    @property
    def size(self) -> int:
        """N = 2 degrees of freedom."""
        return 2

    @property
    def coordinates(self) -> tuple[str, str]:
        """Names of the coordinates: ``x1`` (primary mass), ``x2`` (absorber)."""
        return ("x1", "x2")

    def index(self, name: str, key: str = "coordinate") -> int:
        """Index of the coordinate called ``name`` (``x1`` or ``x2``)."""
        return self.structure.index(name, key)

    def receptance_matrix(self, omega: ArrayLike) -> NDArray[np.complex128]:
        """H(j w) [m N-1], shape omega.shape + (2, 2) (see :meth:`LinearStructure.receptance_matrix`)."""
        return self.structure.receptance_matrix(omega)

    def receptance(self, omega: ArrayLike, output: ArrayLike, load: ArrayLike) -> NDArray[np.complex128]:
        """output^T H(j w) load [m N-1] (see :meth:`LinearStructure.receptance`)."""
        return self.structure.receptance(omega, output, load)

    def rigid_body_modes(self) -> int:
        """Number of rigid-body modes of its stiffness matrix, by the one rule
        (:meth:`LinearStructure.rigid_body_modes`): 0 unless a spring is under ~1e-12 of the other (k2 = 1e-12 k1, a
        free absorber of the Python API; a scene keeps k2 / k1 within 1e-9 ... 1e9)."""
        return self.structure.rigid_body_modes()

    # --------------------------------------------------------------- polynomials
    def characteristic_polynomial(self) -> NDArray[np.float64]:
        """Coefficients of D(s) (eq. 5 with s = j omega), highest power first [kg2, ..., N2 m-2]."""
        p1 = np.array([self.m1, self.b1 + self.b2, self.k1 + self.k2])
        p2 = np.array([self.m2, self.b2, self.k2])
        coupling = np.array([self.b2, self.k2])
        return np.polysub(np.polymul(p1, p2), np.polymul(coupling, coupling))

    def numerator_polynomial(self, output: int, load: int) -> NDArray[np.float64]:
        """Coefficients of the numerator of H_{output,load}(s) (eq. 4), highest power first.

        Parameters
        ----------
        output, load : {1, 2}
            Index of the displacement and of the loaded mass.
        """
        if {output, load} == {1, 2}:
            return np.array([self.b2, self.k2])
        if output == load == 1:
            return np.array([self.m2, self.b2, self.k2])
        if output == load == 2:
            return np.array([self.m1, self.b1 + self.b2, self.k1 + self.k2])
        raise ValueError(f"output and load must be 1 or 2, got output={output!r}, load={load!r}")

    # ---------------------------------------------------------------- receptances
    def receptances(self, omega: ArrayLike) -> Receptances:
        """Receptances H11, H12, H22 at angular frequencies ``omega`` [rad s-1] (eqs. 4-5), vectorised.

        Parameters
        ----------
        omega : array_like
            Angular excitation frequency [rad s-1].

        Returns
        -------
        Receptances
            Arrays shaped like ``omega`` [m N-1].
        """
        w = np.asarray(omega, dtype=float)
        jw = 1j * w
        d11 = -self.m1 * w**2 + jw * (self.b1 + self.b2) + self.k1 + self.k2
        d22 = -self.m2 * w**2 + jw * self.b2 + self.k2
        coupling = jw * self.b2 + self.k2
        det = d11 * d22 - coupling**2
        return Receptances(h11=d22 / det, h12=coupling / det, h22=d11 / det)

    # ---------------------------------------------------------------- frequencies
    def natural_angular_frequencies(self) -> tuple[float, float]:
        """Undamped natural angular frequencies Omega_1 < Omega_2 [rad s-1] from the corrected eq. 11.

        The printed eq. 11 has ``K1*M1 + K1*M2 + K2*M1`` as the first term; the roots of D(j omega) = 0 with
        B = 0 need ``K1*M2 + K2*M1 + K2*M2`` (see the README's errata).
        """
        s = self.k1 * self.m2 + self.k2 * self.m1 + self.k2 * self.m2
        root = math.sqrt(s * s - 4.0 * self.k1 * self.k2 * self.m1 * self.m2)
        denominator = 2.0 * self.m1 * self.m2
        # (s - root) loses digits when K1 K2 M1 M2 << s^2; the product of the two roots is exact.
        omega2_high = (s + root) / denominator
        omega2_low = self.k1 * self.k2 / (self.m1 * self.m2) / omega2_high
        return math.sqrt(omega2_low), math.sqrt(omega2_high)

    def natural_frequencies(self) -> tuple[float, float]:
        """Undamped natural frequencies f_1 < f_2 [Hz] (:meth:`natural_angular_frequencies` / 2 pi)."""
        low, high = self.natural_angular_frequencies()
        return low / (2.0 * math.pi), high / (2.0 * math.pi)

    def natural_angular_frequencies_eig(self) -> tuple[float, float]:
        """Undamped natural angular frequencies [rad s-1] from the eigenvalues of M^-1 K (independent check)."""
        eigenvalues = np.linalg.eigvals(np.linalg.solve(self.mass_matrix, self.stiffness_matrix)).real
        low, high = np.sqrt(np.sort(eigenvalues))
        return float(low), float(high)

    def antiresonance_angular_frequency(self) -> float:
        """Undamped anti-resonance of the primary mass, sqrt(K2/M2) [rad s-1]: H11 = 0 there when B2 = 0."""
        return math.sqrt(self.k2 / self.m2)

    def antiresonance_frequency(self) -> float:
        """Undamped anti-resonance of the primary mass, sqrt(K2/M2) / 2 pi [Hz]."""
        return self.antiresonance_angular_frequency() / (2.0 * math.pi)

    def as_dict(self) -> dict[str, float]:
        """Plain dictionary of the parameters (SI units), for dataset attributes."""
        return {name: float(getattr(self, name)) for name in NAMED_KEYS}


#: The named system's parameters, in the order of its fields.
NAMED_KEYS = ("m1", "m2", "k1", "k2", "b1", "b2")


def named_system(values: Mapping[str, float]) -> TwoDofSystem:
    """The paper's named system of ``values`` (m1, m2, k1, k2 and optionally b1, b2 [SI]), as a scene's ``system``,
    a dataset's ``system_<key>`` attributes or a validation case write them: the view's one constructor from its
    parameters (``TypeError`` for another key, ``ValueError`` for a value out of range).

    Its :attr:`~TwoDofSystem.structure` is the one model's structure of these values; where a structure exists,
    :meth:`TwoDofSystem.of` (or :meth:`Layout.named_view <vibroimpact.model.layout.Layout.named_view>`) is its view.
    """
    return TwoDofSystem(**{key: float(value) for key, value in values.items()})


@dataclass(frozen=True, eq=False)
class LinearResponse:
    """Complex amplitudes of the paper's linear steady state under the force q cos(w t), by eqs. 4-5
    (:func:`paper_linear_response`; the public form of any problem is
    :class:`~vibroimpact.analysis.linear.LinearAmplitudes`).

    Attributes
    ----------
    x1, x2 : ndarray of complex
        Displacement amplitudes of the primary mass and the absorber [m].
    force : ndarray of complex
        Force transmitted to the base through the suspension, (K1 + j w B1) X1 [N].
    """

    x1: NDArray[np.complex128]
    x2: NDArray[np.complex128]
    force: NDArray[np.complex128]


def paper_linear_response(system: TwoDofSystem, frequency: ArrayLike | None = None, amplitude: float | None = None, *, omega: ArrayLike | None = None) -> LinearResponse:
    """Linear steady-state amplitudes of the paper's system by its receptances (eqs. 4-5) at ``frequency`` [Hz] (or
    angular frequencies ``omega`` [rad s-1], keyword only) for force amplitude q [N] (``amplitude``, finite): the
    arithmetic of the paper's studies (:func:`~vibroimpact.analysis.linear.linear_response` is the public form, of
    any problem)."""
    if amplitude is None:
        raise TypeError("paper_linear_response(system, frequency, amplitude): the force amplitude q [N] is needed")
    check_closed_form_inputs(None, None, amplitude)
    w = np.asarray(angular_frequency(frequency, omega), dtype=float)
    h = system.receptances(w)
    x1 = amplitude * h.h11
    return LinearResponse(x1=x1, x2=amplitude * h.h12, force=(system.k1 + 1j * w * system.b1) * x1)


#: The paper's numerical example (eq. 24).
PAPER_SYSTEM = TwoDofSystem(m1=1.0, m2=0.1, k1=25_000.0, k2=4_300.0, b1=0.8, b2=0.08)
