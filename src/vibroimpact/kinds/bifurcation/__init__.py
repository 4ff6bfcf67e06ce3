"""Bifurcation studies: every periodic orbit of a frequency band with its stability and special points, brute force
beside continued branches, and two-parameter charts; their page."""
