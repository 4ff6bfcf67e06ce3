"""Closed forms: linear receptances and peaks, periodic Green functions, the PGF one-impact solution, its Floquet
stability and the regime flag. Imports only :mod:`vibroimpact.model`."""
