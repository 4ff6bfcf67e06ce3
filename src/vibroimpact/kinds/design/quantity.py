"""How a design page writes the measures its dataset records: the objective's (attribute ``objective``) and the
operating constraint's (``operating_measure``, by default the primary's ``x1_amplitude``), each with its symbol and
its display unit (a displacement [m] in mm, a force [N] in N), and the constraint's limit (``operating_limit_m`` or
``operating_limit_N``, :func:`vibroimpact.kinds.design.dataset.design_dataset`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import xarray as xr

from vibroimpact.analysis.measures import BASE_FORCE, symbol_of
from vibroimpact.reporting.style import fmt

__all__ = ["Quantity", "quantity", "objective_quantity", "constraint_quantity", "operating_limit", "DEFAULT_CONSTRAINT"]

#: The operating constraint's measure where the dataset names none: the primary's notch.
DEFAULT_CONSTRAINT = "x1_amplitude"


@dataclass(frozen=True)
class Quantity:
    """A measure as a page writes it.

    Attributes
    ----------
    name : str
        The measure's name (``x1_amplitude``, ``force_amplitude``).
    symbol : str
        ``|X1|``, ``|X2|``, ``|F|``; ``|<name>|`` of a general layout's coordinate not named x<digits>.
    unit : str
        The page's unit: ``mm`` or ``N``.
    scale : float
        The dataset's SI value times this is the page's [unit per SI unit]: 1e3 (m to mm) or 1 (N).
    description : str
        What it is, in words (``fundamental amplitude of the primary mass``).
    """

    name: str
    symbol: str
    unit: str
    scale: float
    description: str

    @property
    def displacement(self) -> bool:
        """A displacement amplitude (else the force to the base)."""
        return self.name != BASE_FORCE

    @property
    def label(self) -> str:
        """An axis label's tail: ``|X1| [mm]``."""
        return f"{self.symbol} [{self.unit}]"

    def value(self, value: float) -> float:
        """An SI value (or array) in the page's unit."""
        return self.scale * value

    def text(self, value: float) -> str:
        """``2.538 mm``, ``12.3 N`` (4 significant digits); ``not known`` for NaN."""
        return f"{fmt(self.scale * value, '.4g')} {self.unit}" if math.isfinite(value) else "not known"

    def number(self, value: float) -> str:
        """The number alone (a table cell): ``2.538``; ``n/a`` for NaN."""
        return fmt(self.scale * value, ".4g") or "n/a"


def quantity(name: str) -> Quantity:
    """The :class:`Quantity` of the measure ``name``.

    Raises
    ------
    ValueError
        A name that is neither ``force_amplitude`` nor ``<coordinate>_amplitude``.
    """
    symbol = symbol_of(name)  # the one rule of datasets and pages; refuses an unknown name
    if name == BASE_FORCE:
        return Quantity(name, symbol, "N", 1.0, "fundamental amplitude of the force transmitted to the base")
    coordinate = name.removesuffix("_amplitude")
    what = "the primary mass" if coordinate == "x1" else f"the displacement {coordinate}"
    return Quantity(name, symbol, "mm", 1e3, f"fundamental amplitude of {what}")


def objective_quantity(dataset: xr.Dataset) -> Quantity:
    """What the design's objective (its worst cases, responses and certificates) measures."""
    return quantity(str(dataset.attrs.get("objective", DEFAULT_CONSTRAINT)))


def constraint_quantity(dataset: xr.Dataset) -> Quantity:
    """What the operating constraint limits (``operating_amplitude``, ``design_operating_amplitude``)."""
    return quantity(str(dataset.attrs.get("operating_measure", DEFAULT_CONSTRAINT)))


def operating_limit(dataset: xr.Dataset) -> float:
    """The operating constraint's largest allowed value [SI: m or N]; NaN without a constraint."""
    unit = "m" if constraint_quantity(dataset).displacement else "N"
    return float(dataset.attrs.get(f"operating_limit_{unit}", math.nan))
