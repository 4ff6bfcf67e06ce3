"""The design pages' colours and markers: one per compared design, the search's path, the certified worst case and
the operating limit (Okabe-Ito, safe for colour-blind readers), and the objective's grey scale."""

from __future__ import annotations

import numpy as np
from matplotlib.colors import ListedColormap

import vibroimpact.reporting.style  # noqa: F401  (selects the Agg backend before pyplot)

import matplotlib.pyplot as plt

__all__ = ["DESIGN_COLOURS", "DESIGN_MARKERS", "PATH_COLOUR", "CERTIFIED_COLOUR", "LIMIT_COLOUR", "OBJECTIVE_PERCENTILE", "OBJECTIVE_MAP"]

#: The compared designs' colours (recommended, the scene's, the linear optimum): Okabe-Ito blue, orange, green.
DESIGN_COLOURS = ("#0072B2", "#E69F00", "#009E73")
#: The compared designs' markers on the search's map.
DESIGN_MARKERS = ("*", "s", "D")
#: The search's path (Okabe-Ito vermillion).
PATH_COLOUR = "#D55E00"
#: The certified worst case, the feasibility boundary (Okabe-Ito vermillion, reddish purple).
CERTIFIED_COLOUR, LIMIT_COLOUR = "#D55E00", "#CC79A7"
#: The objective's colour scale ends at this percentile of the candidates' values (worse ones share its top colour).
OBJECTIVE_PERCENTILE = 90.0
#: The objective's colours: light where it is small (good), never darker than mid-grey (the dots stay visible).
OBJECTIVE_MAP = ListedColormap(plt.get_cmap("Greys")(np.linspace(0.03, 0.7, 256)), name="design_objective")
