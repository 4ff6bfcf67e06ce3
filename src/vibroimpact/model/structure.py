"""A linear structure of N degrees of freedom: mass, stiffness and damping matrices and the names of its coordinates.

Equations of motion, without contact forces::

    M x'' + C x' + K x = f(t)

``M`` must be symmetric positive definite, ``K`` and ``C`` symmetric positive semi-definite (a zero stiffness is a
free mass: a rigid-body mode). The paper's two-mass system (:class:`~vibroimpact.model.system.TwoDofSystem`) is one
such structure, whose :attr:`~vibroimpact.model.system.TwoDofSystem.structure` gives the same matrices.

Coordinates are displacements [m] measured from the position of the unloaded springs (relative to the base when the
excitation is a base motion, see :mod:`~vibroimpact.model.excitation`).
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from vibroimpact.model.keywords import suggest_keywords


__all__ = ["LinearStructure", "as_matrix_rows", "require_finite", "require_positive", "require_non_negative", "require_count", "require_in_range",
           "MASS_RATIO", "STIFFNESS_RATIO", "DAMPING_RATIO", "RIGID_MODE_RATIO", "SOFTEST_SPRING", "require_ratio", "CONDITION_LIMIT", "harmonic_condition",
           "resonance_refusal", "StiffnessModes", "stiffness_modes"]

#: Relative tolerance of the symmetry and definiteness checks.
_TOLERANCE = 1e-12

#: Largest ratio of two masses of one structure (of the largest to the smallest eigenvalue of M) [-]. The dynamics
#: mix the two in sums like K / M1 + K / M2: beyond ~1e12 double precision (eps 2.2e-16) keeps fewer than 4 digits of
#: the smaller term, and beyond 1e16 none (m2 = 1e300 gave x1 = 0 where it is 7.4e-4 m).
MASS_RATIO = 1e12
#: The one rule of a rigid-body mode (a free mass) [-]: an eigenvalue of a stiffness matrix at most this fraction of
#: its largest |eigenvalue| is one (:func:`stiffness_modes`, which every such judgement asks: the structure's
#: rigid-body modes, the closed forms' refusal, the exact flows' null space, a bumper's contact modes, the contact-free
#: stability, a static drift). Measured:
#:
#: * an exact zero comes out of ``eigh`` within 4.8e-16 of the largest (20,000 floating chains of 2-8 masses, springs
#:   spread over 1e9, alone and in contact with a relative bumper up to 1e11 times their stiffest spring): 2000x below;
#: * above it the exact flows compute a flexible mode right: the paper's system at 24 Hz, R = 0.2, against a bumper of
#:   8e7 Hz (its contact mode's softest stiffness 1.16e-12 of its stiffest) gives |X1| = the rigid stop's (2.567 mm)
#:   plus its 26.4 Hz / f term (26.49); at 9e7 Hz (9.2e-13) the mode is judged rigid and |X1| is 1.877 mm, 27 % low.
#:   With the rule at 1e-10 the same went wrong from 9e6 Hz (9.2e-11): a larger value only takes flexible modes for
#:   rigid sooner, and a bumper refusal 10x inside it would refuse, from 2.7e6 Hz, bumpers computed right;
#: * the golden suite's 139,512 judgements (every shipped scene) saw rigid eigenvalues of exactly 0 and flexible ones of
#:   at least 1.8e-6 of the largest: any value between moves no shipped number.
#:
#: What lies near it is refused before any work, the refusal edges strictly inside it: a contact mode whose softest
#: flexible stiffness is under :data:`~vibroimpact.model.bumper_limit.STIFFNESS_SPREAD` (1e-11, 10x above) of its
#: stiffest, and a scene's structure with an eigenvalue between :data:`_ROUND_OFF` (1e-13, 10x below) and
#: :data:`SOFTEST_SPRING` (1e-10, 100x above) of its largest (:meth:`LinearStructure.check_dynamic_range`).
RIGID_MODE_RATIO = 1e-12
#: The softest spring a scene's structure may have [-]: a nonzero eigenvalue of K under this fraction of the largest
#: is refused (:meth:`LinearStructure.check_dynamic_range`: "reads as a free mass"), 100x above
#: :data:`RIGID_MODE_RATIO`, so that no accepted spring is near the rule.
SOFTEST_SPRING = 1e-10
#: Largest ratio of two springs of the named system, k1 / k2 or k2 / k1 [-]: K's eigenvalue ratio is then at least
#: 2.5e-10 (k2 / k1 = 1e9; 1e-9 at k2 / k1 = 1e-9), above :data:`SOFTEST_SPRING`, so that no spring reads as a free
#: mass; k2 = 1e300 made the absorber's spring swallow the suspension's (all-NaN linear responses).
STIFFNESS_RATIO = 1e9
#: Largest b^2 / (k m) of a dashpot against its spring and mass [-] (4 zeta^2: the ratio of the fast to the slow pole
#: of an overdamped mode): beyond ~1e12 the slow pole is round-off next to the fast one.
DAMPING_RATIO = 1e12
#: Eigenvalues of K at most this fraction of the largest are zero to round-off (a free mass written as matrices) [-]:
#: 10x under :data:`RIGID_MODE_RATIO`, 200x over the round-off measured there; a scene's eigenvalue above it must be
#: a spring (above :data:`SOFTEST_SPRING`).
_ROUND_OFF = 1e-13


#: Largest condition number of a harmonic (or periodic) response that is evaluated [-]: the harmonic response
#: (:func:`harmonic_condition`) by the steady states and the exact engines, the Green function sums
#: (:func:`vibroimpact.analysis.greens.green_condition`) by the closed forms. Near an undamped natural frequency the
#: response is ~kappa times the motion it makes with the impacts, and their cancellation leaves an error ~eps kappa^2
#: (measured: closed form 1.4e-7 at kappa = 1.6e4, 7 % at 1.6e7; the exact engine 3e-3 at 1.6e7): 1e4 keeps it below
#: ~5e-8. kappa ~ 1 / (2 pi detuning) near an undamped natural frequency (refused within 1.6e-5 of it) and at most
#: ~1 / (2 pi zeta) at a resonance of damping ratio zeta (refused where zeta < 1.6e-5). The shipped scenes stay below
#: 146 (zeta >= 0.0022).
CONDITION_LIMIT = 1e4


@dataclass(frozen=True, eq=False)
class StiffnessModes:
    """A stiffness matrix K split by the rigid-mode rule (:func:`stiffness_modes`): its eigenvalues, ascending, and
    orthonormal eigenvectors, the stiffness they are judged against, and which are rigid-body modes.

    Attributes
    ----------
    values : ndarray, shape (N,)
        Eigenvalues of K [N m-1], ascending.
    vectors : ndarray, shape (N, N)
        Their eigenvectors (orthonormal columns); the identity where K is zero.
    scale : float
        The stiffness [N m-1] the eigenvalues are judged against (0: K is zero, every mode rigid).
    is_rigid : ndarray of bool, shape (N,)
        Which eigenvalues are rigid-body modes.
    """

    values: NDArray[np.float64]
    vectors: NDArray[np.float64]
    scale: float
    is_rigid: NDArray[np.bool_]

    @property
    def rigid(self) -> NDArray[np.float64]:
        """The rigid-body modes (orthonormal columns, shape (N, r)): a basis of K's null space."""
        return self.vectors[:, self.is_rigid]

    @property
    def flexible(self) -> NDArray[np.float64]:
        """The flexible modes (orthonormal columns, shape (N, N - r))."""
        return self.vectors[:, ~self.is_rigid]

    @property
    def flexible_values(self) -> NDArray[np.float64]:
        """The flexible modes' eigenvalues [N m-1], ascending."""
        return self.values[~self.is_rigid]

    @property
    def count(self) -> int:
        """r, the number of rigid-body modes."""
        return int(np.count_nonzero(self.is_rigid))


def stiffness_modes(stiffness: ArrayLike, floor: float = 0.0) -> StiffnessModes:
    """The rigid-body and flexible modes of a stiffness matrix K [N m-1], by the one rule: an eigenvalue at most
    :data:`RIGID_MODE_RATIO` of the stiffness scale (K's largest |eigenvalue|) is a rigid-body mode (a free mass).

    The null space of K is that of the generalized problem K v = w^2 M v too (M is definite), so the rule needs no
    masses: every caller judges K's own eigenvalues.

    Parameters
    ----------
    stiffness : array_like, shape (N, N)
        K [N m-1], symmetric.
    floor : float, optional
        The least stiffness scale [N m-1]: the scale is the largest of K's |eigenvalues| and this. A reduced (held)
        structure passes the full structure's, since its own K may be round-off alone (a free-free pair held together
        by a relative stop: T^T K T ~ 1e-29 of nothing).
    """
    matrix = np.asarray(stiffness, dtype=float)
    values, vectors = np.linalg.eigh(matrix)
    top = max(float(np.max(np.abs(values))) if values.size else 0.0, float(floor))
    if top > 0.0:
        return StiffnessModes(values, vectors, top, values <= RIGID_MODE_RATIO * top)
    return StiffnessModes(values, np.eye(matrix.shape[0]), 0.0, np.ones(values.size, dtype=bool))


def harmonic_condition(poles: ArrayLike, omega: ArrayLike) -> NDArray[np.float64]:
    """kappa = max_k |p_k| / (2 pi |j w - p_k|): the condition of the harmonic response (j w I - A)^-1 b [-].

    ~1 / (2 pi relative detuning) near an undamped natural frequency, 1 / (2 pi zeta) at a damped one's peak, inf at
    an undamped one; rigid-body poles (p = 0) add nothing.

    Parameters
    ----------
    poles : array_like of complex
        Eigenvalues of the state matrix [rad s-1].
    omega : array_like
        w [rad s-1], > 0.
    """
    p = np.asarray(poles, dtype=complex).reshape(-1)
    w = np.asarray(omega, dtype=float)
    if p.size == 0:
        return np.zeros(w.shape)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.abs(p) / (2.0 * np.pi * np.abs(1j * w[..., None] - p))
    return np.max(np.where(np.isnan(ratio), 0.0, ratio), axis=-1)


def resonance_refusal(poles: ArrayLike, omega: float) -> str | None:
    """Why a harmonic load at ``omega`` [rad s-1] has no well-conditioned response (:data:`CONDITION_LIMIT`), or None.

    The message names the frequency, the nearest natural frequency, its mode's damping ratio and what to do.
    """
    kappa = float(harmonic_condition(poles, omega))
    if kappa <= CONDITION_LIMIT:
        return None
    p = np.asarray(poles, dtype=complex).reshape(-1)
    nearest = p[np.argmax(np.abs(p) / np.maximum(np.abs(1j * omega - p), 1e-300))]
    detuning = abs(1j * omega - nearest) / abs(nearest)
    zeta = -nearest.real / abs(nearest)
    mode = "an undamped mode" if zeta < 1e-12 else f"a mode damped zeta = {zeta:.2g}"
    return (
        f"excitation.frequency = {omega / (2.0 * math.pi):.12g} Hz is {_short(detuning)} (relative) from the natural frequency "
        f"{abs(nearest) / (2.0 * math.pi):.12g} Hz of {mode}: the harmonic response there is ill-conditioned (condition "
        f"{_short(kappa)} > {_power(CONDITION_LIMIT)}, refused within {_short(1.0 / (2.0 * math.pi * CONDITION_LIMIT))} of an undamped "
        "natural frequency); move the frequency or add damping"
    )


def _short(value: float) -> str:
    """Two digits, exponent without padding: 1.6e-5, 3.2e8, 0.25."""
    mantissa, _, exponent = f"{value:.2g}".partition("e")
    return f"{mantissa}e{int(exponent)}" if exponent else mantissa


def _power(value: float) -> str:
    """1e12 for 1e+12, 1e-9 for 1e-09, 1 for 1."""
    if value == 1.0:
        return "1"
    mantissa, _, exponent = f"{value:.0e}".partition("e")
    return f"{mantissa}e{int(exponent)}"


def require_ratio(key: str, expression: str, ratio: float, high: float, low: float | None = None, why: str = "") -> None:
    """``ValueError`` naming ``key`` and ``expression`` where ``ratio`` lies outside [low, high] (low: 1 / high).

    Parameters
    ----------
    key : str
        Scene key of the message (e.g. ``system``).
    expression : str
        The ratio as the user reads it, e.g. ``m2 / m1``.
    ratio : float
        Its value [-] (inf or NaN are out of range).
    high : float
        Largest allowed value [-].
    low : float, optional
        Smallest allowed value [-]; 1 / ``high`` by default, 0 for a one-sided bound.
    why : str
        What goes wrong beyond the range, appended to the message.
    """
    low = 1.0 / high if low is None else low
    if not low <= ratio <= high:
        allowed = f"<= {_power(high)}" if low == 0.0 else f"[{_power(low)}, {_power(high)}]"
        raise ValueError(f"{key}: {expression} = {ratio:.3g} is out of range: allowed {allowed}{': ' + why if why else ''}")


def as_matrix_rows(name: str, value: object, size: int | None = None) -> tuple[tuple[float, ...], ...]:
    """``value`` as a square matrix of finite floats, in rows of tuples; ``ValueError`` naming ``name`` otherwise.

    Parameters
    ----------
    name : str
        Key of the matrix, for the message (e.g. ``system.mass``).
    value : array_like
        The matrix.
    size : int, optional
        The required number of rows and columns.
    """
    try:
        array = np.array(value, dtype=float)
    except (TypeError, ValueError) as error:
        raise ValueError(f"{name}: expected a square matrix of numbers (a list of rows), got {value!r}") from error
    if array.ndim != 2 or array.shape[0] != array.shape[1] or array.shape[0] == 0:
        raise ValueError(f"{name}: expected a square matrix (a list of N rows of N numbers), got shape {array.shape}")
    if size is not None and array.shape[0] != size:
        raise ValueError(f"{name}: expected {size} x {size} like system.mass, got {array.shape[0]} x {array.shape[1]}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name}: every entry must be a finite number, got {value!r}")
    return tuple(tuple(float(entry) for entry in row) for row in array)


def _check_symmetric_definite(name: str, matrix: NDArray[np.float64], positive: bool) -> None:
    scale = float(np.max(np.abs(matrix))) if matrix.size else 0.0
    asymmetry = float(np.max(np.abs(matrix - matrix.T))) if matrix.size else 0.0
    if asymmetry > _TOLERANCE * scale:
        raise ValueError(f"{name}: must be symmetric, but differs from its transpose by up to {asymmetry:.3g}")
    eigenvalues = np.linalg.eigvalsh(0.5 * (matrix + matrix.T))
    smallest = float(eigenvalues[0])
    if positive and smallest <= 0.0:
        raise ValueError(f"{name}: must be positive definite (every mass > 0), but its smallest eigenvalue is {smallest:.6g}")
    if positive:
        require_ratio(name, "largest / smallest eigenvalue (the masses' ratio)", float(eigenvalues[-1]) / smallest, MASS_RATIO, 1.0,
                      "the smaller masses are lost to round-off next to the larger ones in double precision")
    if not positive and smallest < -_TOLERANCE * scale:
        raise ValueError(f"{name}: must be positive semi-definite (no negative spring or dashpot), but it has the eigenvalue {smallest:.6g}")


def _check_dynamic_range(mass: NDArray[np.float64], stiffness: NDArray[np.float64], damping: NDArray[np.float64]) -> None:
    """``ValueError`` where K has an eigenvalue that is neither a spring nor a free mass to working precision, or C
    overdamps the structure beyond what double precision resolves (:data:`DAMPING_RATIO`)."""
    modes = stiffness_modes(stiffness)
    k_values, k_max = modes.values, modes.scale
    if k_max <= 0.0:
        return  # free masses only: no spring to compare with
    # every eigenvalue 10x below the rigid-mode rule (zero to round-off) or 100x above it (a spring): none near it
    soft = k_values[(k_values > _ROUND_OFF * k_max) & (k_values <= SOFTEST_SPRING * k_max)]
    if soft.size:
        require_ratio("system.stiffness", "largest / smallest nonzero eigenvalue", k_max / float(soft[0]), 1.0 / SOFTEST_SPRING, 1.0,
                      "a spring this soft next to the stiffest reads as a free mass (make it 0, or stiffer)")
    c_max = max(float(np.linalg.eigvalsh(damping)[-1]), 0.0)
    m_max = float(np.linalg.eigvalsh(mass)[-1])
    ratio = c_max / (math.sqrt(k_max) * math.sqrt(m_max))
    require_ratio("system.damping", "c^2 / (k m) of the largest eigenvalues of C, K and M", ratio * ratio, DAMPING_RATIO, 0.0,
                  "a mode that overdamped has a slow pole lost to round-off next to its fast one")


@suggest_keywords
@dataclass(frozen=True)
class LinearStructure:
    """Masses, springs and dashpots of a linear structure of N degrees of freedom.

    Parameters
    ----------
    mass : array_like, shape (N, N)
        M [kg], symmetric positive definite.
    stiffness : array_like, shape (N, N)
        K [N m-1], symmetric positive semi-definite (zero rows: free masses).
    damping : array_like, shape (N, N), optional
        C [N s m-1], symmetric positive semi-definite; zero by default.
    coordinates : sequence of str, optional
        Names of the coordinates, unique; ``x1, x2, ...`` by default.

    Raises
    ------
    ValueError
        Naming the key (``system.mass``, ``system.stiffness``, ``system.damping``, ``system.coordinates``) and what is
        wrong: shape, symmetry, definiteness, finiteness, names.
    """

    mass: tuple[tuple[float, ...], ...] = field(metadata={"units": "kg"})
    stiffness: tuple[tuple[float, ...], ...] = field(metadata={"units": "N m-1"})
    damping: tuple[tuple[float, ...], ...] = field(default=(), metadata={"units": "N s m-1"})
    coordinates: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        mass = as_matrix_rows("system.mass", self.mass)
        size = len(mass)
        stiffness = as_matrix_rows("system.stiffness", self.stiffness, size)
        if isinstance(self.damping, tuple) and len(self.damping) == 0:
            damping = tuple(tuple(0.0 for _ in range(size)) for _ in range(size))
        else:
            damping = as_matrix_rows("system.damping", self.damping, size)
        _check_symmetric_definite("system.mass", np.array(mass), positive=True)
        _check_symmetric_definite("system.stiffness", np.array(stiffness), positive=False)
        _check_symmetric_definite("system.damping", np.array(damping), positive=False)
        names = tuple(self.coordinates) if len(self.coordinates) else tuple(f"x{i + 1}" for i in range(size))
        if len(names) != size:
            raise ValueError(f"system.coordinates: expected {size} names (one per row of system.mass), got {len(names)}: {list(names)}")
        for name in names:
            if not isinstance(name, str) or not name.isidentifier():
                raise ValueError(f"system.coordinates: {name!r} is not a valid name (letters, digits and _, not starting with a digit)")
        if len(set(names)) != size:
            raise ValueError(f"system.coordinates: names must be unique, got {list(names)}")
        object.__setattr__(self, "mass", mass)
        object.__setattr__(self, "stiffness", stiffness)
        object.__setattr__(self, "damping", damping)
        object.__setattr__(self, "coordinates", names)

    def check_dynamic_range(self) -> None:
        """``ValueError`` where K has an eigenvalue that is neither a spring nor a free mass to working precision
        (between 1e-13 and :data:`SOFTEST_SPRING` of the largest, around the rigid-mode rule :data:`RIGID_MODE_RATIO`),
        or C overdamps the structure beyond :data:`DAMPING_RATIO` (its largest eigenvalue squared over K's times M's).
        M's ratio is checked on construction. The scene checker calls it (a scene is refused before any work); the Python API leaves such
        structures to its caller."""
        _check_dynamic_range(self.mass_matrix, self.stiffness_matrix, self.damping_matrix)

    # ------------------------------------------------------------------ matrices
    @property
    def size(self) -> int:
        """N, the number of degrees of freedom."""
        return len(self.mass)

    @property
    def mass_matrix(self) -> NDArray[np.float64]:
        """M [kg]."""
        return np.array(self.mass, dtype=float)

    @property
    def stiffness_matrix(self) -> NDArray[np.float64]:
        """K [N m-1]."""
        return np.array(self.stiffness, dtype=float)

    @property
    def damping_matrix(self) -> NDArray[np.float64]:
        """C [N s m-1]."""
        return np.array(self.damping, dtype=float)

    @property
    def state_matrix(self) -> NDArray[np.float64]:
        """First-order state matrix A [s-1] for the state (x, x'): y' = A y + (0, M^-1 f)."""
        n = self.size
        minv = np.linalg.inv(self.mass_matrix)
        return np.block([[np.zeros((n, n)), np.eye(n)], [-minv @ self.stiffness_matrix, -minv @ self.damping_matrix]])

    @property
    def structure(self) -> LinearStructure:
        """Itself (the paper's :class:`TwoDofSystem` answers the same with its matrices)."""
        return self

    def index(self, name: str, key: str = "coordinate") -> int:
        """Index of the coordinate called ``name``; ``ValueError`` naming ``key`` and the allowed names otherwise."""
        if name not in self.coordinates:
            raise ValueError(f"{key} = {name!r} is not a coordinate of the system: allowed {list(self.coordinates)}")
        return self.coordinates.index(name)

    # ---------------------------------------------------------------- receptances
    def receptance_matrix(self, omega: ArrayLike) -> NDArray[np.complex128]:
        """H(j w) = (K - w^2 M + j w C)^-1 [m N-1], shape omega.shape + (N, N), vectorised.

        Infinite (NaN) where the undamped structure resonates exactly, or at w = 0 for a free mass.
        """
        w = np.asarray(omega, dtype=float)[..., None, None]
        dynamic = self.stiffness_matrix - w**2 * self.mass_matrix + 1j * w * self.damping_matrix
        with np.errstate(all="ignore"):
            try:
                return np.linalg.inv(dynamic)
            except np.linalg.LinAlgError:
                out = np.full(dynamic.shape, np.nan + 0j)
                flat, fout = dynamic.reshape(-1, self.size, self.size), out.reshape(-1, self.size, self.size)
                for i, block in enumerate(flat):
                    if np.linalg.cond(block) < 1e15:
                        fout[i] = np.linalg.inv(block)
                return out

    def receptance(self, omega: ArrayLike, output: ArrayLike, load: ArrayLike) -> NDArray[np.complex128]:
        """output^T H(j w) load [m N-1]: the response of the coordinate combination ``output`` (e.g. e2 - e1, a
        relative displacement) to a unit harmonic load distributed as ``load`` (weights per coordinate)."""
        h = self.receptance_matrix(omega)
        return np.einsum("i,...ij,j->...", np.asarray(output, dtype=float), h, np.asarray(load, dtype=float))

    # ---------------------------------------------------------------- modes
    def rigid_body_modes(self) -> int:
        """Number of rigid-body modes: the dimension of the null space of K (free masses, floating structures), by the
        one rule (:func:`stiffness_modes`)."""
        return stiffness_modes(self.stiffness_matrix).count

    def natural_angular_frequencies(self) -> NDArray[np.float64]:
        """Undamped natural angular frequencies, ascending [rad s-1] (0 for each rigid-body mode)."""
        chol = np.linalg.cholesky(self.mass_matrix)
        inv = np.linalg.inv(chol)
        eigenvalues = np.linalg.eigvalsh(inv @ self.stiffness_matrix @ inv.T)
        return np.sqrt(np.maximum(eigenvalues, 0.0))

    def natural_frequencies(self) -> NDArray[np.float64]:
        """Undamped natural frequencies, ascending [Hz] (:meth:`natural_angular_frequencies` / 2 pi)."""
        return self.natural_angular_frequencies() / (2.0 * np.pi)

    def as_dict(self) -> dict[str, object]:
        """Plain dictionary of the matrices (SI units) and names, for dataset attributes."""
        return {"mass": [list(r) for r in self.mass], "stiffness": [list(r) for r in self.stiffness],
                "damping": [list(r) for r in self.damping], "coordinates": list(self.coordinates)}  # fmt: skip

    def __repr__(self) -> str:
        return f"LinearStructure(N={self.size}, coordinates={list(self.coordinates)}, natural frequencies {np.round(self.natural_angular_frequencies() / (2 * math.pi), 4).tolist()} Hz)"


# --------------------------------------------------------------------------------------------------------------------
# Checks of physical parameters that raise a ``ValueError`` naming the field, its value and the allowed range.
# --------------------------------------------------------------------------------------------------------------------

def _number(name: str, value: object) -> float:
    # any real number, numpy's included (np.int64, np.float32); not a bool
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise ValueError(f"{name}: expected a number, got {value!r} ({type(value).__name__})")
    number = float(value)
    if not math.isfinite(number):
        raise ValueError(f"{name}: expected a finite number, got {value!r}")
    return number


def require_finite(name: str, value: object) -> float:
    """Return ``value`` as float if it is a finite number, else raise ``ValueError`` naming ``name``."""
    return _number(name, value)


def require_positive(name: str, value: object) -> float:
    """Return ``value`` as float if it is a finite number > 0, else raise ``ValueError`` naming ``name``."""
    number = _number(name, value)
    if number <= 0.0:
        raise ValueError(f"{name} = {value!r} is out of range: allowed (0, inf)")
    return number


def require_non_negative(name: str, value: object) -> float:
    """Return ``value`` as float if it is a finite number >= 0, else raise ``ValueError`` naming ``name``."""
    number = _number(name, value)
    if number < 0.0:
        raise ValueError(f"{name} = {value!r} is out of range: allowed [0, inf)")
    return number


def require_count(name: str, value: object, low: int = 1, high: float = math.inf, why: str = "") -> int:
    """Return ``value`` as int if it is a whole count (an int or a numpy integer, not a bool) with low <= value <=
    high, else raise ``ValueError`` naming ``name`` (``why``: said after the range, e.g. what bounds it)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not low <= value <= high:
        upper = "inf)" if math.isinf(high) else f"{int(high)}]"
        raise ValueError(f"{name} = {value!r} is out of range: allowed an integer in [{low}, {upper}{why}")
    return int(value)


def require_in_range(name: str, value: object, low: float, high: float) -> float:
    """Return ``value`` as float if low <= value <= high, else raise ``ValueError`` naming ``name``."""
    number = _number(name, value)
    if not low <= number <= high:
        raise ValueError(f"{name} = {value!r} is out of range: allowed [{low:g}, {high:g}]")
    return number
