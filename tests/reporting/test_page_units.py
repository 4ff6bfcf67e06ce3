"""One unit convention on every page: displacements in mm, accelerations in m/s², forces in N, frequencies in Hz. The
datasets keep SI (CF) units; only the pages convert."""

from __future__ import annotations

import re

import matplotlib.pyplot as plt
import pytest

from tests.golden.golden import DATA
from tests.reporting.test_report_support import FIGURE_KINDS, build

#: Units a page must not write: the dataset's CF spelling of an acceleration, an ASCII power, a displacement in metres.
_FOREIGN = (re.compile(r"m s-2"), re.compile(r"m/s\^2"), re.compile(r"\[m\]"))
#: An axis of a displacement: an amplitude, the fundamental of a coordinate (|X1|, |x2|, |floor1| ...), its peak.
_DISPLACEMENT = re.compile(r"^(peak |running )?(\|[A-Za-z]+[0-9]*\| fundamental|([A-Za-z]+[0-9]* )?amplitude) \[")


def _page_texts() -> list[tuple[str, str]]:
    return [(path.stem, path.read_text(encoding="utf-8")) for path in sorted(DATA.glob("*.txt"))]


@pytest.mark.parametrize("name,text", _page_texts(), ids=[name for name, _ in _page_texts()])
def test_no_golden_page_writes_cf_or_metre_units(name: str, text: str) -> None:
    for pattern in _FOREIGN:
        found = pattern.search(text)
        assert found is None, f"{name}: {found.group(0)!r} in {text[max(0, found.start() - 80): found.end() + 20]!r}" if found else ""


@pytest.mark.parametrize("kind", FIGURE_KINDS)
def test_displacement_axes_are_in_mm_and_accelerations_in_m_per_s2(kind: str) -> None:
    figures = build(kind)
    try:
        labels = [label for drawn in figures for ax in drawn.figure.axes for label in (ax.get_xlabel(), ax.get_ylabel()) if label]
        for label in labels:
            assert not any(pattern.search(label) for pattern in _FOREIGN), (kind, label)
            if _DISPLACEMENT.search(label) and not label.startswith("|F|"):
                assert "[mm]" in label, (kind, label)
            if "acceleration" in label or "deceleration" in label:
                assert "[m/s²]" in label, (kind, label)
        if kind in ("linear", "response_x1", "simulation_x1", "peaks_vs_restitution", "sweep"):
            assert any("[mm]" in label for label in labels), (kind, labels)
        if kind == "peak_acceleration":
            assert any("[m/s²]" in label for label in labels), labels
    finally:
        for drawn in figures:
            plt.close(drawn.figure)
