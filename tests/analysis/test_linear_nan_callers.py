"""The callers of the linear response at an undamped resonance, where it is NaN (not evaluated: within ~1.6e-5
relative of the natural frequency, the response unbounded): each caller's result at the natural frequency and within
1e-6 of it is correct, not a NaN taken for a number (np.argmax at the NaN, brentq stopped by it)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vibroimpact.analysis.band_worst import contact_free_curve
from vibroimpact.analysis.linear import linear_amplitudes, structure_peaks
from vibroimpact.kinds.bifurcation.branches import linear_segments
from vibroimpact.kinds.bifurcation.cases import _grazing_curves
from vibroimpact.model.contact import RigidStop
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.model.system import TwoDofSystem

pytestmark = pytest.mark.timeout(60)

#: The paper's system with b1 = b2 = 0 and its natural frequencies [Hz] (tests/faults/test_non_finite.py).
UNDAMPED = TwoDofSystem(m1=1.0, m2=0.1, k1=25000.0, k2=4300.0, b1=0.0, b2=0.0)
F1, F2 = 23.02212512577005, 36.07439741740175
#: The natural frequency and 1e-6 on either side (all inside the refused band, 1.6e-5 relative).
NEAR = (0.0, -1e-6, 1e-6)
#: Half-width of the refused band around F1 [Hz] (condition 1e4: 1 / (2 pi 1e4) relative, ~1.59e-5).
BAND = F1 / (2.0 * np.pi * 1e4)


def _problem(clearance: float = 0.003) -> ImpactProblem:
    return ImpactProblem(UNDAMPED, RigidStop(clearance, 0.2), HarmonicForce(10.0, F1))


def test_the_linear_response_is_nan_near_the_natural_frequency() -> None:
    """The premise of every test below."""
    linear = linear_amplitudes(_problem(), F1 * (1.0 + np.array(NEAR)))
    assert np.all(np.isnan(linear.amplitudes)) and not np.any(linear.conditioned)


def test_structure_peaks_are_unbounded_at_the_natural_frequencies() -> None:
    """inf at the natural frequency (before: NaN at 23.02199 Hz and 36.07418 Hz, where the bounded search stopped)."""
    peaks = structure_peaks(_problem(), [1.0, 0.0])
    assert [peak.mode for peak in peaks] == [1, 2]
    assert all(math.isinf(peak.value) and peak.value > 0.0 for peak in peaks)
    assert peaks[0].frequency == pytest.approx(F1, rel=1e-12) and peaks[1].frequency == pytest.approx(F2, rel=1e-12)


@pytest.mark.parametrize("detuning", NEAR)
def test_linear_segments_step_off_the_undamped_resonance(detuning: float) -> None:
    """A clearance of 100 m: the linear orbit fits everywhere but in the refused band, sampled at the natural
    frequency (or 1e-6 from it): two segments ending at the band's edges (before: brentq's ValueError 'The function
    value at x=... is NaN')."""
    centre = F1 * (1.0 + detuning)
    segments = linear_segments(_problem(100.0), centre - 0.001, centre + 0.001, 0.0002)
    assert len(segments) == 2
    below, above = segments
    assert np.all(np.diff(below) > 0.0) and np.all(np.diff(above) > 0.0)
    assert below[-1] == pytest.approx(F1 - BAND, rel=1e-8) and above[0] == pytest.approx(F1 + BAND, rel=1e-8)
    linear = linear_amplitudes(_problem(100.0), np.concatenate(segments))
    assert np.all(linear.conditioned) and np.all(linear.fits([100.0]))  # every point evaluated and clear of the stop


def test_linear_segments_graze_outside_the_band_as_before() -> None:
    """1 m, the natural frequency among the samples: the segments end at the grazes, far from the band (brentq
    between finite gaps, as before: already correct, held)."""
    segments = linear_segments(_problem(1.0), F1 - 0.5, F1 + 0.5, 0.05)
    assert len(segments) == 2 and segments[0][-1] < F1 - 10.0 * BAND and segments[1][0] > F1 + 10.0 * BAND
    linear = linear_amplitudes(_problem(1.0), [segments[0][-1], segments[1][0]])
    ends = np.abs(linear.stop_amplitudes[:, 0])
    assert np.all(linear.conditioned)
    np.testing.assert_allclose(ends, 1.0, rtol=1e-9)  # the inner ends graze the stop


@pytest.mark.parametrize("detuning", NEAR)
def test_the_contact_free_curve_leaves_out_the_resonance(detuning: float) -> None:
    """Already correct: fits() is False where the response is NaN, so the clear curve is NaN there (unknown)."""
    f = np.array([F1 - 0.5, F1 * (1.0 + detuning), F1 + 0.5])
    clear, everywhere = contact_free_curve(_problem(100.0), f, 0)
    assert np.isnan(clear[1]) and np.isnan(everywhere[1]) and np.all(np.isfinite(clear[[0, 2]]))


@pytest.mark.parametrize("detuning", NEAR)
def test_the_grazing_curves_split_at_the_resonance(detuning: float) -> None:
    """Already correct: the grazing clearance is NaN in the band, never inside [low_c, high_c]: the curve is split
    there, no NaN in either part."""
    centre = F1 * (1.0 + detuning)
    curves = _grazing_curves(_problem(), centre - 0.05, centre + 0.05, 0.0, 1e3, step=F1 * 1e-6)
    assert len(curves) == 2 and all(np.all(np.isfinite(d)) for _f, d in curves)
    assert curves[0][0][-1] < F1 - 0.9 * BAND and curves[1][0][0] > F1 + 0.9 * BAND


def test_a_benchmark_case_below_an_unbounded_linear_amplitude_is_refused_naming_the_frequency() -> None:
    """``clearance_below_linear`` measures from the linear amplitude, unbounded (NaN, refused) at an undamped natural
    frequency: the case is refused naming its frequency and why (before: the stop's clearance became NaN and the stop
    refused it, 'clearance: expected a finite number, got nan', naming neither the frequency nor the cause)."""
    from pathlib import Path

    from vibroimpact.scene import SceneError, parse_scene
    from vibroimpact.scene.reader import read_yaml

    document = read_yaml((Path(__file__).resolve().parents[2] / "studies" / "engine_cost.yaml").read_text(encoding="utf-8"))
    document["system"].update(b1=0.0, b2=0.0)
    document["benchmark"]["cases"] = [{"name": "graze", "frequency": F1, "restitution": 0.9, "clearance_below_linear": 5e-10, "start": "linear"}]
    with pytest.raises(SceneError) as caught:
        parse_scene(document)
    assert any(p.startswith("benchmark.cases[0].frequency: 23.0221 Hz: the linear amplitude is unbounded there") for p in caught.value.problems), caught.value.problems


class _ClosedFormOnly:
    """A map whose contact-free orbit's clearance [-] is ``clearance(frequency)`` (None: no orbit there)."""

    def __init__(self, clearance: object) -> None:
        self.clearance = clearance

    def linear_orbit(self, q: np.ndarray) -> tuple[np.ndarray, float] | None:
        value = self.clearance(float(q[0]))  # type: ignore[operator]
        return None if value is None else (np.zeros(4), value)


def test_a_pole_the_clearance_changes_sign_across_is_no_onset() -> None:
    """A clearance that jumps from +inf to -inf (1 / (20 - f)) changes sign with no zero: brentq converges on the
    pole, which is no grazing (before: returned as the onset at 20 Hz)."""
    from vibroimpact.orbits.onsets import contact_free_onset

    p = np.array([19.99])
    pole = _ClosedFormOnly(lambda f: 1.0 / (20.0 - f) if f != 20.0 else math.inf)  # exact: the pole itself
    assert contact_free_onset(pole, p, 0, 19.99, 0.1) is None  # type: ignore[arg-type]
    root, q = contact_free_onset(_ClosedFormOnly(lambda f: 20.0 - f), p, 0, 19.99, 0.1)  # type: ignore[arg-type, misc]
    assert root == pytest.approx(20.0, rel=1e-14) and q[0] == root


def test_a_peak_beside_a_gap_of_the_worst_case_curve_is_no_peak() -> None:
    """The worst stable motion's local maxima (design.dataset.equal_peaks): a point beside a stretch where no stable
    motion is known is no maximum, the curve may rise into the gap (before: 2.8 at index 1 beside the gap counted, and
    the two 'equal peaks' were 3.0 and 2.8)."""
    from vibroimpact.kinds.design.dataset import equal_peaks

    linear = np.array([1.0, 2.8, np.nan, np.nan, 2.5, 3.0, 2.0, 1.0, 2.6, 1.0])
    curves = {"linear": linear, "linear_fits": np.ones(10), **{f"impact_{s}{suffix}": np.full(10, np.nan) for s in ("plus", "minus") for suffix in ("", "_stable")}}
    frequency = np.arange(10.0)
    difference, first, second = equal_peaks(frequency, curves)
    assert (first, second) == (5.0, 8.0) and difference == pytest.approx((3.0 - 2.6) / 3.0, rel=1e-15)
    curves["linear"] = np.array([1.0, 2.8, np.nan, np.nan, 3.0, 2.0, 1.0, 0.5, 0.4, 0.2])  # the one maximum beside the gap
    assert all(math.isnan(value) for value in equal_peaks(frequency, curves))
