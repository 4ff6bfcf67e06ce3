"""Every page opens with its answer in numbers, computed from its dataset: the golden scenes' blessed page text (which
the golden suite keeps equal to the page drawn) states, in its first section, the numbers the README quotes from the
shipped study, as the golden scene's dataset gives them."""

from __future__ import annotations

import re

import numpy as np
import pytest

from tests.golden.golden import DATA, machine_free
from vibroimpact.kinds.stepped.crosscheck import cross_check_text, cross_checks
from vibroimpact.runs.run import read_dataset

#: The golden scenes of the stepped and swept kinds, whose first section must state its result in numbers.
ANSWERING = ("restitution", "clearance_peaks", "restitution_peaks", "relative_stop", "base_motion_frame", "bumper_stiffness", "bumper_sweep", "peak_acceleration")
#: A number with the units of a result (mm, Hz, m/s², N, %).
_RESULT = re.compile(r"\d (mm|Hz|m/s²|N|%)(?![A-Za-z])")


def first_section(name: str) -> str:
    """The paragraphs of the first section of golden scene ``name``'s page (after the contents), one per line."""
    lines = (DATA / f"{name}.txt").read_text(encoding="utf-8").splitlines()
    heads = [k for k, line in enumerate(lines) if line.startswith("h2: ") and line != "h2: Contents"]
    section = lines[heads[0] : heads[1] if len(heads) > 1 else None]
    return "\n".join(line for line in section if line.startswith("p: "))


@pytest.mark.parametrize("name", ANSWERING)
def test_the_first_section_states_the_result_in_numbers_with_units(name: str) -> None:
    text = first_section(name)
    assert len(_RESULT.findall(text)) >= 3, f"{name}: {text!r}"


def test_the_peak_acceleration_page_opens_with_the_largest_contact_deceleration_against_the_estimate() -> None:
    """The README quotes the shipped study's largest deceleration of the closed-form bumper against the pgf estimate,
    and the median over the stable one-impact points; here the golden scene's own numbers (IDA, on a subset of the
    points, is left to the cross-check)."""
    data = _read(DATA / "peak_acceleration.nc")
    measured = data["peak_acceleration"].sel(solution="compliant_exact").values
    k = int(np.nanargmax(measured))
    f = float(data["frequency"].values[k])
    estimate = data["peak_acceleration"].sel(solution="pgf").values
    force = data["peak_contact_force"].sel(solution="compliant_exact").values[k]
    text = first_section("peak_acceleration")
    assert f"compliant_exact {measured[k]:.4g} m/s² ({measured[k] / 9.80665:.3g} g) at {f:.4g} Hz, contact force {force:.3g} N" in text, text
    assert f"the pgf estimate there {estimate[k]:.4g} m/s² ({data['peak_contact_force'].sel(solution='pgf').values[k]:.3g} N)" in text, text
    usable = (measured > 0) & (estimate > 0) & (data["stable"].sel(solution="pgf").values == 1) & (data["converged"].sel(solution="compliant_exact").values == 1)
    usable &= np.isin(data["regime"].sel(solution="pgf").values, (1, 2))
    median = float(np.median((measured[usable] - estimate[usable]) / estimate[usable]))
    assert f"On the {int(usable.sum())} points" in text and f"compliant_exact is {100 * abs(median):.2g} % {'above' if median > 0 else 'below'} the estimate" in text, text


def test_the_bumper_sweep_page_opens_with_where_each_sweep_touches_the_stop() -> None:
    """The README quotes the shipped sweep's contact ranges per direction (e.g. up: 20.6-26.7 and 34.0-39.6 Hz); here
    the golden sweep's, each in its own direction, and its distance from the stable pgf orbit."""
    data = _read(DATA / "bumper_sweep.nc")
    f = data["frequency"].values
    text = first_section("bumper_sweep")
    for direction in data["sweep"].values:
        contact = np.flatnonzero(data["swept_regime"].sel(sweep=direction).values == 10)
        assert contact.size and np.all(np.diff(contact) == 1)  # one stretch in the golden sweep
        low, high = f[contact[0]], f[contact[-1]]
        first, last = (high, low) if direction == "down" else (low, high)
        assert f"sweeping {direction} over {first:.1f}-{last:.1f} Hz" in text, text
        sim, pgf = data["swept_x1_amplitude"].sel(sweep=direction).values, data["x1_amplitude"].sel(solution="pgf").values
        good = (data["swept_regime"].sel(sweep=direction).values == 10) & (data["stable"].sel(solution="pgf").values == 1) & (f < 33.0)
        median = float(np.median((sim[good] - pgf[good]) / pgf[good]))
        assert f"{100 * abs(median):.1f} % {'above' if median > 0 else 'below'} sweeping {direction} ({int(good.sum())} points)" in text, text


def test_the_bumper_stiffness_page_opens_with_the_convergence_to_the_rigid_stop() -> None:
    data = _read(DATA / "bumper_stiffness.nc")
    simulated = np.flatnonzero(np.isfinite(data["x1_amplitude"].sel(solution="compliant_exact").isel(bumper_frequency=0).values))
    part = data.isel(frequency=simulated)
    difference = np.abs(part["x1_amplitude"].sel(solution="compliant_exact") - part["x1_amplitude"].sel(solution="exact")) / part["x1_amplitude"].sel(solution="exact")
    medians = difference.median("frequency").values
    text = first_section("bumper_stiffness")
    assert ", ".join(f"{100 * m:.2g} %" for m in medians) in text, text
    assert "observed order" in text


def _read(path: object) -> object:
    """A golden dataset as the run gave it (its groups joined), without what the writer adds of the machine."""
    return machine_free(read_dataset(path))  # type: ignore[arg-type]


@pytest.mark.parametrize("name", ["restitution_peaks", "clearance_peaks", "peak_acceleration", "bumper_stiffness"])
def test_the_bumper_studies_open_with_ida_against_the_closed_form_bumper(name: str) -> None:
    """Their grids are the closed-form bumper's; IDA on a subset agrees with it to its tolerance (rtol 1e-7 or 1e-9:
    well within 1e-5 relative where both are periodic), and the first section says so, with the cost ratio measured
    in the run (here the golden page's fixed timings: the stored dataset has none, so the sentence read from it stops
    before the cost), as the dataset gives them."""
    data = _read(DATA / f"{name}.nc")
    (check,) = [c for c in cross_checks(data) if c.checked == "compliant"]
    assert check.reference == "compliant_exact" and check.periodic >= 2
    assert check.largest["x1_amplitude"] < 1e-5 and check.largest["x2_amplitude"] < 1e-5
    text = first_section(name)
    assert cross_check_text(check) in text and "A steady state of 'compliant_exact' costs " in text, text
