"""The page of a concepts study: which absorber concept, with which stop.

First the answer (the table of :mod:`.concepts_table` with a verdict per concept and how each number is defined),
then the figures side by side (:mod:`.concepts_figures`), then what the continuation and the closed forms said.
Everything is read from the dataset.
"""

from __future__ import annotations

import html
import math
from pathlib import Path

import numpy as np
import xarray as xr

from vibroimpact.reporting.concepts_figures import impact_figure, overview_figure, response_figure
from vibroimpact.reporting.concepts_table import concepts_table
from vibroimpact.reporting.page import Section, Table, render_page, rendering, saved, write_page
from vibroimpact.reporting.record import stored_description
from vibroimpact.reporting.style import fmt

__all__ = ["ConceptsPage", "write_concepts_report", "DEFINITIONS"]

#: How the table's numbers are defined (HTML).
DEFINITIONS = (
    "<p>Definitions. <b>|X1|</b>: fundamental-harmonic amplitude of the primary mass. <b>Worst stable motion</b>: at each "
    "frequency the largest |X1| over every stable steady state found there: the linear motion where it clears the stops, the "
    "closed-form impact orbit where its Floquet multipliers are inside the unit circle, the stable stretches of the continued "
    "branches, and the exact engine's simulated steady state (an attractor, periodic or not). <b>Peak</b>: its largest value "
    "over the band. <b>Base force</b>: fundamental of k1 x1 + b1 x1' plus the force of the absolute stops (a stop between the "
    "masses pushes no force into the base). <b>With bumpers</b>: every rigid stop replaced by a Kelvin-Voigt bumper of the "
    "same clearance whose one collision restitutes the same R; the time-domain peak of the base force over the simulated "
    "steady states (from a dense replay of each, whose state after the replayed periods agrees with the compliant engine's "
    "to {mismatch} of the motion's scale; without a stop, the amplitude of the linear force), and the largest deceleration "
    "in contact. <b>Anti-resonance band</b>: {band}. <b>Impacts in the "
    "band</b>: share of the band where the motion impacts (wherever the linear motion hits a stop every steady motion "
    "impacts). <b>Notch depth</b>: 20 log10 of the smallest worst-stable |X1| in the band over q/k1 = {static} mm. "
    "★ bold: the best value of the column (smallest; deepest notch). (DH): Den Hartog's optimum. <b>Unstable orbits</b>: "
    "frequencies of the continued branches' and the closed form's unstable stretches.</p>"
)
#: Den Hartog's optimum as the page states it (HTML).
DEN_HARTOG = (
    "<p>Den Hartog's damped absorber (J. P. Den Hartog, <i>Mechanical Vibrations</i>, 4th ed., McGraw-Hill 1956, sec. 3.3; "
    "J. E. Brock, J. Appl. Mech. 13 (1946) A-284): with mu = m2/m1 and Omega_p = sqrt(k1/m1), the optimal tuning "
    "omega_a/Omega_p = 1/(1 + mu) makes the two fixed points P and Q of |X1| equally high, and the damping "
    "zeta = c2/(2 m2 Omega_p) = sqrt(3 mu / (8 (1 + mu)^3)) (Den Hartog's c_c = 2 m2 Omega_p, with the primary's natural "
    "frequency) makes the curve flat there; the table marks such values (DH). That optimum minimises the resonant peak; "
    "the scene's own k2 puts the anti-resonance (the smallest |X1| without a stop) at {anti} Hz instead, where the lightly damped "
    "absorber cuts |X1| far below q/k1. A stop between the masses (on x2 - x1) is the kind Ormondroyd and Den Hartog "
    "proposed (Trans. ASME APM-50-7, 1928), one against the base (on x2) the paper's.</p>"
)


class ConceptsPage:
    """The page of a ``concepts`` dataset."""

    def __init__(self, dataset: xr.Dataset) -> None:
        self.dataset = dataset

    def summary(self) -> str:
        """What was computed, for the page's heading."""
        d = self.dataset
        return (f"{d.sizes['concept']} absorber concepts; closed forms on {d.sizes['frequency']} frequencies, "
                f"steady states on {d.sizes['simulation_frequency']}, branches continued in frequency")  # fmt: skip

    def sections(self, out: Path) -> list[Section]:
        """The answer, the figures, the notes."""
        d = self.dataset
        low, high = float(d.attrs.get("band_low_Hz", math.nan)), float(d.attrs.get("band_high_Hz", math.nan))
        band = (f"{fmt(low, '.2f')}-{fmt(high, '.2f')} Hz around the anti-resonance at {fmt(d.attrs.get('anti_resonance_Hz'), '.2f')} Hz, where "
                "the scene's lightly damped absorber without a stop keeps |X1| below q/k1") if math.isfinite(low) else "none (|X1| never drops below q/k1)"  # fmt: skip
        mismatch = d["bumper_replay_mismatch"].values if "bumper_replay_mismatch" in d else np.zeros(0)
        worst = f"{np.nanmax(mismatch):.1e}" if np.any(np.isfinite(mismatch)) else "(no replay)"
        definitions = DEFINITIONS.format(band=html.escape(band), static=fmt(1e3 * float(d.attrs["static_deflection_m"]), ".2g"), mismatch=worst)
        intro = DEN_HARTOG.format(anti=fmt(d.attrs.get("anti_resonance_Hz"), ".2f"))
        answer = Section("Which absorber concept, with which stop", intro, tables=[Table("Concepts side by side", concepts_table(d) + definitions)])
        figures = Section("Figures", "", figures=saved((overview_figure(d), response_figure(d), impact_figure(d)), out))
        notes = "".join(f"<li><b>{html.escape(str(d['label'].values[i]))}</b>: {html.escape(str(d['notes'].values[i]) or 'closed forms only')}</li>" for i in range(d.sizes["concept"]))
        return [answer, figures, Section("How each concept was computed", f"<ul>{notes}</ul>")]


def write_concepts_report(dataset: xr.Dataset, out_dir: str | Path, jobs: int = 1) -> Path:
    """Write the figures and ``report.html`` of a concepts dataset into ``out_dir``; return the HTML path."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    page = ConceptsPage(dataset)
    with rendering(jobs):
        sections = page.sections(out)
    text = str(dataset.attrs.get("scene", ""))
    paragraphs = [stored_description(text), f"vibroimpact {dataset.attrs.get('vibroimpact_version', '?')}; {page.summary()}."]
    return write_page(out / "report.html", render_page(f"Study '{dataset.attrs.get('scene_name', '')}'", paragraphs, sections, text))
