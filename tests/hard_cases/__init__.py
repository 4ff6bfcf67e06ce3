"""Stability suite: a standing table of hard cases run against every time-domain engine (issue 5, item 5).

``cases.py`` holds the engines and the table (what each case is, and per engine what must hold);
``checks.py`` measures a trajectory and asserts the table's requirements; ``test_hard_cases.py`` runs the table;
``test_properties.py`` runs hypothesis over random valid parameter sets.
"""
