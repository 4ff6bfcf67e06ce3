"""Every kind of report figure reads well at 1400 px: shown unscaled, no small, clipped or overlapping text, and no
legend on a panel."""

from __future__ import annotations

import matplotlib.pyplot as plt
import pytest

from vibroimpact.reporting.style import MIN_FONT_SIZE

from tests.reporting.test_report_support import FIGURE_KINDS, PAGE_CONTENT_WIDTH, build, layout_problems, png_width


@pytest.mark.slow
@pytest.mark.parametrize("kind", FIGURE_KINDS)
def test_figure_reads_well_at_page_width(kind: str) -> None:
    for drawn in build(kind):
        problems = layout_problems(drawn.figure, MIN_FONT_SIZE)
        width = png_width(drawn.figure)
        plt.close(drawn.figure)
        assert not problems, f"{drawn.name}: {problems}"
        assert width <= PAGE_CONTENT_WIDTH, f"{drawn.name}: {width} px"
