"""vibroimpact: vibration protection by a tuned dynamic absorber whose motion is limited by a stop on the base.

Linear two-degree-of-freedom model, closed-form periodic-Green-function (PGF) solution of the one-impact regime,
and studies that put them side by side (seed paper: the absorber with a stop mounted on the base).
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("vibroimpact")
except PackageNotFoundError:  # running from a source tree without installation
    __version__ = "0+unknown"

__all__ = ["__version__"]
