"""Closed forms: linear receptances and peaks (any coordinate and stop coordinate), periodic and antiperiodic Green
functions, the PGF one-impact solution (the paper's named form, and any structure with one rigid stop), the symmetric
two-impacts solution of a two-sided stop, their Floquet stability and the regime flag. Imports only
:mod:`vibroimpact.model`."""
