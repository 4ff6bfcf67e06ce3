"""The table a designer reads in a minute: one row per absorber concept, one column per figure of merit, the best
value of each column marked, and a one-line verdict per concept written from the numbers.

Every number comes from the dataset of a ``concepts`` study (:mod:`vibroimpact.study.concepts_dataset`). A column's
best is its smallest value (largest depth of the notch: its most negative dB), among the concepts that have the
quantity at all (a concept without a stop has no impact acceleration to compare).
"""

from __future__ import annotations

import html
import math
from dataclasses import dataclass

import numpy as np
import xarray as xr

from vibroimpact.reporting.style import fmt

__all__ = ["Column", "COLUMNS", "best_rows", "verdict", "verdicts", "concepts_table"]


@dataclass(frozen=True)
class Column:
    """One figure of merit of the table.

    Attributes
    ----------
    variable : str
        Dataset variable (per concept).
    title : str
        Column heading with units.
    scale : float
        Factor from the dataset's units to the table's (1e3: m -> mm).
    spec : str
        Number format.
    short : str
        How a verdict names it.
    where : str or None
        Variable with the frequency of the value [Hz], shown after it.
    stops_only : bool
        Only concepts with a stop have it (others show "no stop" and take no part in the ranking).
    """

    variable: str
    title: str
    scale: float
    spec: str
    short: str
    where: str | None = None
    stops_only: bool = False


COLUMNS = (
    Column("peak_x1_amplitude", "peak |X1| [mm]", 1e3, ".3g", "peak |X1|", "peak_x1_frequency"),
    Column("peak_base_force_amplitude", "peak base force, fundamental [N]", 1.0, ".3g", "base force", "peak_base_force_frequency"),
    Column("peak_base_force_bumper", "peak base force with bumpers, time domain [N]", 1.0, ".3g", "time-domain base force"),
    Column("peak_impact_acceleration", "peak impact acceleration, bumper [m/s²]", 1.0, ".0f", "impact acceleration", stops_only=True),
    Column("band_impact_fraction", "impacts in the anti-resonance band [% of band]", 100.0, ".0f", "impacts in the band", stops_only=True),
    Column("notch_depth", "notch depth, min |X1| / (q/k1) [dB]", 1.0, ".1f", "notch depth", "notch_frequency"),
)


def _values(dataset: xr.Dataset, column: Column) -> np.ndarray:
    values = np.asarray(dataset[column.variable].values, dtype=float) * column.scale
    if column.stops_only:
        values = np.where(_has_stops(dataset), values, np.nan)
    return values


def _has_stops(dataset: xr.Dataset) -> np.ndarray:
    return np.array([str(s) != "no stop" for s in dataset["stops"].values])


def best_rows(values: np.ndarray, tolerance: float = 1e-9) -> np.ndarray:
    """Rows holding the column's smallest finite value (within a relative ``tolerance``: ties all count)."""
    finite = np.isfinite(values)
    if not np.any(finite):
        return np.zeros(values.shape, dtype=bool)
    low = float(np.min(values[finite]))
    return finite & (values <= low + tolerance * max(abs(low), 1e-300))


def verdict(dataset: xr.Dataset, row: int) -> str:
    """One line on concept ``row``: where it is best and worst, and its key numbers, from the dataset."""
    best, worst = [], []
    for column in COLUMNS:
        values = _values(dataset, column)
        if not np.isfinite(values[row]) or np.sum(np.isfinite(values)) < 2:
            continue
        if best_rows(values)[row]:
            best.append(column.short)
        elif best_rows(-values)[row]:
            worst.append(column.short)
    peak = float(dataset["peak_x1_amplitude"].values[row])
    peaks = np.asarray(dataset["peak_x1_amplitude"].values, dtype=float)
    lowest = float(np.nanmin(peaks)) if np.any(np.isfinite(peaks)) else math.nan
    depth = float(dataset["notch_depth"].values[row])
    fraction = float(dataset["band_impact_fraction"].values[row])
    facts = [f"peak |X1| {fmt(peak * 1e3, '.3g')} mm" + (f" ({fmt(peak / lowest, '.2g')}x the lowest)" if math.isfinite(lowest) and peak > lowest * (1 + 1e-9) else "")]
    if math.isfinite(depth):
        facts.append(f"notch {fmt(depth, '+.0f')} dB" if depth < 0.0 else f"no notch (|X1| stays {fmt(depth, '.1f')} dB above q/k1 in the band)")
    if math.isfinite(fraction) and _has_stops(dataset)[row]:
        facts.append("no impacts in the band" if fraction == 0.0 else f"impacts on {fmt(100.0 * fraction, '.0f')} % of the band")
    unstable = str(dataset["unstable_stretches"].values[row])
    nonperiodic = str(dataset["nonperiodic_stretches"].values[row])
    if nonperiodic not in ("none", ""):
        facts.append(f"not periodic at {nonperiodic} Hz")
    elif unstable not in ("none", ""):
        facts.append(f"unstable orbits at {unstable} Hz")
    head = []
    if best:
        head.append("best " + ", ".join(best))
    if worst:
        head.append("worst " + ", ".join(worst))
    return ("; ".join(head) + ": " if head else "") + "; ".join(facts) + "."


def verdicts(dataset: xr.Dataset) -> list[str]:
    """:func:`verdict` of every concept, in the dataset's order."""
    return [verdict(dataset, row) for row in range(dataset.sizes["concept"])]


def concepts_table(dataset: xr.Dataset) -> str:
    """The HTML table: concept, absorber k2 and b2, the figures of merit (best marked ★ and bold), the unstable
    stretches and the verdict."""
    rows = dataset.sizes["concept"]
    has_stops = _has_stops(dataset)
    wrap = "style='white-space:normal'"
    head = "".join(f"<th {wrap}>{html.escape(c.title)}</th>" for c in COLUMNS)
    lines = [f"<table style='font-size:93%'><tr><th {wrap}>concept</th><th {wrap}>k2 [N/m], b2 [N s/m]</th>{head}<th {wrap}>unstable orbits [Hz]</th><th style='text-align:left'>verdict</th></tr>"]
    marks = {c.variable: best_rows(_values(dataset, c)) for c in COLUMNS}
    texts = verdicts(dataset)
    for row in range(rows):
        cells = []
        for column in COLUMNS:
            value = _values(dataset, column)[row]
            if column.stops_only and not has_stops[row]:
                text = "no stop"
            else:
                text = fmt(value, column.spec) or "n/a"
                if column.where is not None and math.isfinite(value):
                    text += f"<br><small>at {fmt(dataset[column.where].values[row], '.2f')} Hz</small>"
                if column.variable == "band_impact_fraction" and has_stops[row] and value > 0:
                    text += f"<br><small>{html.escape(str(dataset['band_impacts'].values[row]))} Hz</small>"
            if marks[column.variable][row]:
                text = f"<b>★ {text}</b>"
            cells.append(f"<td>{text}</td>")
        label = html.escape(str(dataset["label"].values[row]))
        absorber = str(dataset["absorber"].values[row])
        k2, b2 = (fmt(dataset[name].values[row], ".4g") for name in ("absorber_stiffness", "absorber_damping"))
        k2 += " <small>(DH)</small>" if "Den Hartog" in absorber.split(", b2")[0] else ""
        b2 += " <small>(DH)</small>" if "Den Hartog" in absorber.split(", b2")[-1] else ""
        unstable = html.escape(str(dataset["unstable_stretches"].values[row]))
        lines.append(f"<tr><td style='white-space:normal;min-width:10em'>{label}</td><td title='{html.escape(absorber)}'>{k2}<br>{b2}</td>{''.join(cells)}"
                     f"<td style='white-space:normal;min-width:6em'><small>{unstable}</small></td><td style='white-space:normal;min-width:17em;text-align:left'>{html.escape(texts[row])}</td></tr>")  # fmt: skip
    lines.append("</table>")
    return "".join(lines)
