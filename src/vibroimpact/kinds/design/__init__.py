"""The ``design`` kind: which absorber and stop to build (issue 32)."""
