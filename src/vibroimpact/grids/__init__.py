"""The frequency-grid study shared by the stepped and swept kinds: the grid of closed forms over frequency x
restitution x clearance (x bumper, x sweep direction) and what both kinds' datasets and pages share.

* ``grid``: :class:`~vibroimpact.grids.grid.StudyGrid`, the loop over solutions, the dataset's coordinates,
  attributes and metadata;
* ``closed_forms``: the closed-form solutions (``linear``, ``pgf``, ``pgf_paper``) over the grid, any layout;
* ``estimate``: a grid study's predicted time and memory;
* ``sections``: the page sections both kinds' pages open with (the linear system, a general layout's structure and
  stops);
* ``regime_map``: regime flags drawn as coloured bands.

A layer below the kinds (``vibroimpact.kinds.stepped`` and ``vibroimpact.kinds.swept`` import it, it imports no kind):
it writes datasets and draws.
"""
