"""The peers' tier (``pytest -m peers``): published examples of continuation and impact tools, each run by the
bifurcation kind from a scene in ``tests/peers/scenes`` and compared with the peer's numbers, its closed forms, or
its method computed here, with the tolerance each comparison is held to.

========================================  ==================================================================  =========
peer's example                            compared with                                                       tolerance
========================================  ==================================================================  =========
NLvib, example 03 (unilateral spring 100)  both contact onsets: the receptance's roots                          1e-8
                                          the folds in the band: NLvib's harmonic balance (H = 21, N = 2^10)  1e-4
                                          x2's fundamental along the contact branch: the same curve           1e-3
NLvib-PEACE, example 01 (spring 200)      the same, against its reference (H = 15, N = 2^9)                   the same; 7e-3
COCO, Recipes for Continuation Ex. 15.2   the grazing condition A = d |1 - w^2 + i c w| (its 'GR' curve)      1e-9
                                          impact velocities: the two-segment periodic orbit solved here       1e-8
Budd & Dux 1994                           impact velocities: their ellipse; grazing at sigma = |gamma|        1e-8, 1e-9
========================================  ==================================================================  =========

MATLAB is not run here: NLvib's harmonic balance is :mod:`tests.peers.harmonic_balance` (its method at its settings),
COCO's orbits are solved here from the demo's equations (two segments: the impact and the flight, exact flows).
Harmonic balance truncates the Fourier series of a response with a kink: its fold and amplitudes lie off the exact
orbit by O(1/H) (measured on example 03: the fold 4.1e-5 above the package's at H = 21, 2.4e-5 at H = 41).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from scipy.linalg import expm
from scipy.optimize import fsolve

from tests.peers.harmonic_balance import HarmonicBalanceCurve, UnilateralChain, harmonic_balance_curve
from vibroimpact.orbits.branch import SPECIAL_POINT_KINDS
from vibroimpact.runs.run import run_study
from vibroimpact.scene.reader import load_scene

pytestmark = pytest.mark.peers

SCENES = Path(__file__).parent / "scenes"
GRAZING, FOLD = SPECIAL_POINT_KINDS.index("grazing"), SPECIAL_POINT_KINDS.index("fold")
CHAIN_STIFFNESS = np.array([[1.0, -1.0], [-1.0, 2.0]])


def study(name: str) -> xr.Dataset:
    return run_study(load_scene(SCENES / f"{name}.yaml"), progress=None)


def specials(dataset: xr.Dataset, kind: int, period: int | None = None) -> np.ndarray:
    """The frequencies [Hz] of the special points of one kind (of period-``period`` orbits only, when given)."""
    chosen = dataset["special_point_kind"].values == kind
    if period is not None:
        chosen &= dataset["special_point_period_multiplicity"].values == period
    return np.sort(dataset["special_point_frequency"].values[chosen])


def chain_onsets(damping: float, low: float, high: float) -> list[float]:
    """Where the linear chain's |X1| reaches the gap of 1 [Hz], by bisection on its receptance."""

    def reach(f: float) -> float:
        w = 2.0 * math.pi * f
        return abs(np.linalg.solve(CHAIN_STIFFNESS - w * w * np.eye(2) + 1j * w * damping * CHAIN_STIFFNESS, [0.0, 0.1])[0]) - 1.0

    grid = np.linspace(low, high, 4001)
    values = np.array([reach(f) for f in grid])
    roots = []
    for k in np.flatnonzero(np.diff(np.sign(values))):
        a, b = grid[k], grid[k + 1]
        for _ in range(100):
            middle = 0.5 * (a + b)
            a, b = (middle, b) if np.sign(reach(middle)) == np.sign(values[k]) else (a, middle)
        roots.append(0.5 * (a + b))
    return roots


def off_curve(frequency: np.ndarray, amplitude: np.ndarray, curve: HarmonicBalanceCurve, coordinate: int) -> np.ndarray:
    """Each point's distance to the harmonic-balance curve, relative, in (frequency, amplitude) each scaled by the
    point's own value: the least over the curve's segments."""
    f_curve, a_curve = curve.omega / (2.0 * math.pi), curve.fundamental(coordinate)
    out = np.empty(frequency.size)
    for k, (f, a) in enumerate(zip(frequency, amplitude)):
        p = np.column_stack([f_curve / f, a_curve / a])
        start, end = p[:-1], p[1:]
        along = end - start
        t = np.clip(np.einsum("ij,ij->i", np.array([1.0, 1.0]) - start, along) / np.maximum(np.einsum("ij,ij->i", along, along), 1e-300), 0.0, 1.0)
        out[k] = float(np.min(np.linalg.norm(start + t[:, None] * along - np.array([1.0, 1.0]), axis=1)))
    return out


@pytest.mark.parametrize(
    "name, damping, spring, harmonics, samples, omega, step, curve_tolerance",
    [("nlvib_unilateral_spring", 0.03, 100.0, 21, 2**10, (0.8, 0.5), 0.02, 1e-3),
     ("nlvib_peace_unilateral_spring", 0.06, 200.0, 15, 2**9, (1.4 * 0.618034, 0.8 * 0.618034), 0.005, 7e-3)],
)  # fmt: skip
def test_nlvib_unilateral_spring(name: str, damping: float, spring: float, harmonics: int, samples: int, omega: tuple[float, float], step: float, curve_tolerance: float) -> None:
    """NLvib's chain with a unilateral spring (a lossless Kelvin-Voigt bumper here): both onsets of contact where the
    receptance says (to 1e-8: measured up to 2e-9), every fold in the band where NLvib's harmonic balance turns back
    (to 1e-4: measured 4.1e-5 and 7.2e-5, the truncation of H harmonics), and every point of the period-one contact branch on its
    curve (x2's fundamental, the amplitude NLvib's example plots), except within 1 % of an onset, where the curve has
    a corner that the harmonic-balance points, ``step`` of arclength apart, cut: to 1e-3 for example 03 (measured
    8.6e-4 at most), 7e-3 for PEACE's stiffer spring with 15 harmonics (measured 6.1e-3 at most, 2.1e-3 median: the
    truncated series of a stiffer contact)."""
    data = study(name)
    low, high = min(omega) / (2.0 * math.pi), max(omega) / (2.0 * math.pi)
    onsets = chain_onsets(damping, low, high)
    grazing = specials(data, GRAZING)
    assert len(onsets) == 2
    for onset in onsets:
        assert np.min(np.abs(grazing - onset)) <= 1e-8 * onset
    chain = UnilateralChain(np.eye(2), damping * CHAIN_STIFFNESS, CHAIN_STIFFNESS, np.array([0.0, 0.1]), np.array([1.0, 0.0]), spring, 1.0)
    curve = harmonic_balance_curve(chain, harmonics, samples, omega[0], omega[1], step)
    theirs = np.array([f for f in np.array(curve.folds()) / (2.0 * math.pi) if low < f < high])
    ours = specials(data, FOLD, period=1)
    assert theirs.size >= 1 and ours.size == theirs.size
    assert np.max(np.abs(np.sort(ours) - np.sort(theirs)) / theirs) <= 1e-4
    contact = (data["impacts_per_period"].values > 0) & (data["period_multiplicity"].values == 1)
    frequency, amplitude = data["branch_frequency"].values[contact], data["x2_amplitude"].values[contact]
    away = np.min(np.abs(frequency[:, None] - np.array(onsets)[None, :]) / np.array(onsets)[None, :], axis=1) > 1e-2
    distance = off_curve(frequency[away], amplitude[away], curve, 1)
    assert away.sum() > 50 and np.max(distance) <= curve_tolerance, np.max(distance)


def coco_orbit(frequency: float, guess_velocity: float, e: float = 0.8, c: float = 0.1, amplitude: float = 1.0, d: float = 1.0) -> tuple[float, float]:
    """COCO's impacting period-one orbit of x'' + c x' + x = A cos(w t) at w = 2 pi ``frequency``: an impact at x = d
    with approach speed V, then one flight of a forcing period back to x = d at speed V; the flight's exact flow (the
    matrix exponential and the steady harmonic response). Solved for (force phase at the impact, V) from each of 16
    phases and ``guess_velocity``; returns the V nearest the guess and the residual of its equations."""
    w = 2.0 * math.pi * frequency
    period = 1.0 / frequency
    flow = expm(np.array([[0.0, 1.0], [-1.0, -c]]) * period)
    receptance = amplitude / (1.0 - w * w + 1j * c * w)

    def steady(phase: float, t: float) -> np.ndarray:
        z = receptance * np.exp(1j * (w * t + phase))
        return np.array([z.real, (1j * w * z).real])

    def equations(unknown: np.ndarray) -> np.ndarray:
        phase, v = unknown
        start = np.array([d, -e * v])
        end = flow @ (start - steady(phase, 0.0)) + steady(phase, period)
        return end - np.array([d, v])

    best = (math.inf, math.nan, math.inf)
    for phase in np.linspace(0.0, 2.0 * math.pi, 16, endpoint=False):
        solution, info, ok, _ = fsolve(equations, [phase, guess_velocity], full_output=True, xtol=1e-14)
        residual = float(np.max(np.abs(equations(solution))))
        if ok == 1 and solution[1] > 0.0 and abs(solution[1] - guess_velocity) < best[0]:
            best = (abs(solution[1] - guess_velocity), float(solution[1]), residual)
    return best[1], best[2]


def test_coco_impact_oscillator() -> None:
    """COCO's impact oscillator at its starting parameters (A = 1, d = 1, e = 0.8, c = 0.1): the linear orbit grazes
    where COCO's grazing family passes A = 1, d |1 - w^2 + i c w| = A, i.e. w^2 = 1.99 (w = 1.41067 rad/s); every
    stable and unstable one-impact orbit continued in w has the impact speed of the two-segment orbit solved here."""
    data = study("coco_impact_oscillator")
    grazing = specials(data, GRAZING)
    onset = math.sqrt(1.99) / (2.0 * math.pi)
    assert np.min(np.abs(grazing - onset)) <= 1e-9 * onset
    one = (data["impacts_per_period"].values == 1) & (data["period_multiplicity"].values == 1)
    frequency, velocity = data["branch_frequency"].values[one], data["impact_velocity"].values[one, 0]
    assert one.sum() > 100
    for k in np.linspace(0, one.sum() - 1, 12).astype(int):
        expected, residual = coco_orbit(float(frequency[k]), float(velocity[k]))
        assert residual <= 1e-12 and velocity[k] == pytest.approx(expected, rel=1e-8, abs=1e-10)


def test_budd_dux_ellipse_and_grazing() -> None:
    """Budd & Dux's undamped oscillator x'' + x = cos(w t), x <= sigma = 0.1, r = 0.8: every continued one-impact
    orbit's approach speed V satisfies their ellipse, (sigma + V (1 + r) / (2 tan(pi / w)))^2 + (V (1 - r) / (2 w))^2
    = gamma^2 with gamma = 1 / (1 - w^2), to 1e-8 of gamma^2; the orbit grazes (V = 0) where |gamma| = sigma,
    w = sqrt(11)."""
    data = study("budd_dux_impact_oscillator")
    sigma, r = 0.1, 0.8
    grazing = specials(data, GRAZING)
    onset = math.sqrt(1.0 + 1.0 / sigma) / (2.0 * math.pi)
    assert np.min(np.abs(grazing - onset)) <= 1e-9 * onset
    one = (data["impacts_per_period"].values == 1) & (data["period_multiplicity"].values == 1)
    w = 2.0 * math.pi * data["branch_frequency"].values[one]
    v = data["impact_velocity"].values[one, 0]
    gamma = 1.0 / (1.0 - w * w)
    ellipse = (sigma + v * (1.0 + r) / (2.0 * np.tan(np.pi / w))) ** 2 + (v * (1.0 - r) / (2.0 * w)) ** 2
    assert one.sum() > 50 and np.max(np.abs(ellipse - gamma**2) / gamma**2) <= 1e-8
