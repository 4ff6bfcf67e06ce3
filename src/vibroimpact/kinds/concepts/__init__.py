"""Concepts studies: absorber concepts side by side (which absorber, with which stop) over one band; their page."""
