"""What a stepped page says before it praises a stop: the response at the absorber's operating point, and whether the
stop is reached at all.

An absorber exists for its notch: at its operating point, the anti-resonance of the linear absorber sqrt(k2/m2) / 2 pi
(the zero of the primary's receptance without damping), the primary mass barely moves. A stop whose clearance is
smaller than the absorber's free motion there is struck at the very frequency the absorber was tuned to, and the notch
is gone, whatever the reduction factors at the two resonances say. So a page states, beside those factors:

* :func:`operating_point`: |X1| of every solution with the stop against the linear absorber's, at the grid frequency
  nearest to the anti-resonance (the same frequency for both, so that their ratio is the stop's effect alone), and
  the free (linear) motion of every stop's coordinate there against its gap;
* :func:`operating_text`: that in one sentence, beside the reduction factors;
* :func:`warning_lines`: the page's first lines, before any praise: the stop makes the response at the operating
  point worse than the linear absorber's (the two numbers and the factor, and the stop's largest |X1| between the two
  resonances, where the notch was), the absorber's free motion there does not fit in the gap, or the stop is never
  reached on the grid (:func:`unreached_text`, which the console prints too).

The operating point needs the structure's named view (the two-mass chain: its k2 and m2) with an absorber spring
(k2 > 0); another structure has no notch to speak of, and only :func:`unreached_text` applies. Units as on every page:
displacements in mm, frequencies in Hz.
"""

from __future__ import annotations

import html
import math
from dataclasses import dataclass

import numpy as np
import xarray as xr

from vibroimpact.kinds.stepped.crosscheck import subset_solutions
from vibroimpact.kinds.stepped.tables import computed_part
from vibroimpact.measures.figures_of_merit import NEAR_OPERATING, NEAREST, WORSE_RATIO
from vibroimpact.reporting.record import GeneralSetting, general_setting, study_kind
from vibroimpact.reporting.style import DISPLACEMENT_SCALE, fmt

__all__ = ["warnings_html", "OperatingRow", "OperatingPoint", "operating_point", "operating_text", "warning_lines", "unreached_text", "WORSE_RATIO", "NEAREST", "MM_HINT_CLEARANCE"]

#: A clearance at least this large [m] that no motion reaches was probably typed in mm: the warning asks.
MM_HINT_CLEARANCE = 0.05
#: At most this many rows are listed one by one; more are summarised (range and count).
_LISTED = 6


@dataclass(frozen=True)
class OperatingRow:
    """|X1| of one solution at one swept point, at the operating point, against the linear absorber's.

    Attributes
    ----------
    solution : str
        The solution (``pgf``, ``exact``, ...).
    where : str
        The swept point in words (``R = 0.5, Delta = 2 mm``; empty where nothing is swept).
    frequency : float
        The grid frequency nearest to the operating frequency among those the solution computed [Hz].
    linear : float
        |X1| of the linear absorber (no stop) at ``frequency`` [m].
    stopped : float
        |X1| with the stop at ``frequency`` [m]; NaN where the solution has no realisable value there (none, or a
        closed-form orbit known to be unstable).
    """

    solution: str
    where: str
    frequency: float
    linear: float
    stopped: float

    def __post_init__(self) -> None:
        if not self.frequency > 0.0 or not self.linear >= 0.0:
            raise ValueError(f"an operating row needs a positive frequency [Hz] and a linear |X1| >= 0 [m], got {self.frequency!r} and {self.linear!r}")

    @property
    def ratio(self) -> float:
        """stopped / linear [-] (NaN without a value)."""
        return self.stopped / self.linear if self.linear > 0.0 else math.nan


@dataclass(frozen=True)
class OperatingPoint:
    """The absorber's operating point and what the stop does there.

    Attributes
    ----------
    frequency : float
        The operating frequency [Hz]: the linear absorber's anti-resonance sqrt(k2/m2) / 2 pi.
    coordinate : str
        The primary coordinate's name (``x1``).
    rows : tuple of OperatingRow
        One per solution with a stop and swept point (empty where the grid does not reach the operating frequency).
    free : tuple of (str, float, float)
        Per stop whose free motion at the operating frequency does not fit in its gap: the stopped coordinate in words,
        its linear amplitude there [m] and the gap, the clearance less the static deflection's share [m] (one entry
        per swept clearance that is too small).
    resonances : tuple of float
        The structure's two natural frequencies [Hz] (the notch lies between them).
    """

    frequency: float
    coordinate: str
    rows: tuple[OperatingRow, ...]
    free: tuple[tuple[str, float, float], ...]
    resonances: tuple[float, float]

    def __post_init__(self) -> None:
        if not self.frequency > 0.0:
            raise ValueError(f"the operating frequency must be positive [Hz], got {self.frequency!r}")

    def worse(self) -> list[OperatingRow]:
        """The rows where the stop makes |X1| worse than the linear absorber (:data:`WORSE_RATIO`), worst first."""
        return sorted((r for r in self.rows if r.ratio > WORSE_RATIO), key=lambda r: -r.ratio)


def _mm(value: float, spec: str = ".3g") -> str:
    """A displacement [m] in mm, 3 significant digits unless ``spec`` says (``n/a`` where not finite)."""
    return f"{fmt(value * DISPLACEMENT_SCALE, spec) or 'n/a'} mm"


def _coordinate(words: str) -> str:
    """The stopped coordinate of a stop in words: ``x2 - x1 >= -3 mm, R = 0.2`` -> ``x2 - x1``."""
    constraint = words.split(",")[0]
    for sign in (" <=", " >="):
        if sign in constraint:
            return constraint.split(sign)[0].strip()
    return constraint.strip()


def _swept(data: xr.DataArray) -> list[str]:
    """The dimensions of ``data`` that are swept points (not the solution, frequency or stop)."""
    return [d for d in data.dims if d not in ("solution", "frequency", "stop")]


def _where(data: xr.DataArray, dims: list[str], index: tuple[int, ...]) -> str:
    """A swept point in words: ``R = 0.5, Delta = 2 mm, bumper 250 Hz``."""
    words = []
    for dim, i in zip(dims, index):
        value = float(data[dim].values[i]) if dim in data.coords else math.nan
        if dim == "restitution":
            words.append(f"R = {fmt(value, 'g')}")
        elif dim == "clearance":
            words.append(f"Delta = {fmt(value * DISPLACEMENT_SCALE, 'g')} mm")
        elif dim == "bumper_frequency":
            words.append(f"bumper {fmt(value, 'g')} Hz")
        else:
            words.append(f"{dim} {i}")
    return ", ".join(words)


def _gaps(layout: GeneralSetting, dataset: xr.Dataset) -> list[tuple[int, float]]:
    """(stop, gap [m]) of every stop and swept clearance: Delta_k less the static deflection's share n_k . x_static."""
    static = layout.static_deflection()
    shift = layout.normals @ static if static is not None else np.zeros(len(layout.stops))
    swept = np.atleast_1d(np.asarray(dataset["clearance"].values, dtype=float)) if "clearance" in dataset.coords else np.array([math.nan])
    out = []
    for k, delta in enumerate(layout.clearances):
        for value in ([float(delta)] if math.isfinite(float(delta)) else [float(v) for v in swept]):
            out.append((k, value - float(shift[k])))
    return out


def operating_point(dataset: xr.Dataset, layout: GeneralSetting | None = None) -> OperatingPoint | None:
    """The absorber's operating point in ``dataset`` (module doc); None where the structure has no named view or no
    absorber spring, or the dataset has no |X1|."""
    layout = layout if layout is not None else general_setting(dataset)
    named = layout.named
    quantity = f"{layout.names[0]}_amplitude"
    if named is None or not named.k2 > 0.0 or quantity not in dataset or "frequency" not in dataset.dims:
        return None
    fa = named.antiresonance_frequency()
    wa = 2.0 * np.pi * fa
    free_motion = np.abs(layout.linear(np.array([wa]))[0] @ layout.normals.T)
    free = tuple((_coordinate(layout.stops[k]), float(free_motion[k]), gap) for k, gap in _gaps(layout, dataset) if free_motion[k] > gap)
    rows = []
    on_subset = subset_solutions(dataset)
    for solution in (str(s) for s in dataset["solution"].values if s != "linear" and s not in on_subset):
        part = computed_part(dataset, solution)
        f = np.asarray(part["frequency"].values, dtype=float)
        at = float(f[int(np.argmin(np.abs(f - fa)))]) if f.size else math.nan
        if not abs(at - fa) <= NEAREST * fa:
            continue
        point = part.sel(frequency=at)
        data = point[quantity].sel(solution=solution)
        stable = point["stable"].sel(solution=solution) if "stable" in point and "stable" in dataset.data_vars else None
        dims = _swept(data)
        data = data.transpose(*dims, ...)
        linear = float(layout.linear_value(quantity, np.array([2.0 * np.pi * at]))[0])
        for index in np.ndindex(*(data.sizes[d] for d in dims)):
            value = float(np.max(np.atleast_1d(data.values[index])))
            if stable is not None and np.any(np.atleast_1d(stable.transpose(*dims, ...).values[index]) == 0):  # exact: a flag
                value = math.nan  # an unstable closed-form orbit is not the motion
            rows.append(OperatingRow(solution, _where(data, dims, index), at, linear, value))
    return OperatingPoint(fa, layout.names[0], tuple(rows), free, tuple(float(w) / (2.0 * np.pi) for w in named.natural_angular_frequencies()[:2]))  # type: ignore[arg-type]


def _row_text(row: OperatingRow, frequency: float | None) -> str:
    """``pgf 4.81 mm (x240) at R = 0.5``; with the row's own frequency where it differs from ``frequency``:
    ``exact 0.00897 mm (x1) at R = 0 and 33 Hz (the linear absorber there: 0.00897 mm)``."""
    value = f"{_mm(row.stopped)} ({fmt(row.ratio, '.3g', '×{}')})" if math.isfinite(row.stopped) else "no realisable value (no stable orbit known there)"
    where = [row.where] if row.where else []
    own = frequency is None or abs(row.frequency - frequency) > 1e-9
    if own:
        where.append(f"{fmt(row.frequency, '.4g')} Hz")
    return f"{row.solution} {value}" + (f" at {' and '.join(where)}" if where else "") + (f" (the linear absorber there: {_mm(row.linear)})" if own else "")


def operating_text(point: OperatingPoint | None) -> str:
    """The response at the operating point in one sentence, beside the reduction factors (empty: no operating point)."""
    if point is None:
        return ""
    head = f"At the absorber's operating point, its anti-resonance {fmt(point.frequency, '.5g')} Hz (sqrt(k2/m2) / 2 pi)"
    if not point.rows:
        return f"{head}, no solution with the stop was computed within {fmt(100 * NEAREST, 'g')} % of it: the grid does not say what the stop does there."
    first = point.rows[0]
    c = point.coordinate
    lead = f"{head}, |{c.upper()}| of the linear absorber (no stop) is {_mm(first.linear)} at the grid's nearest frequency {fmt(first.frequency, '.4g')} Hz; with the stop"
    finite = [r for r in point.rows if math.isfinite(r.stopped)]
    if len(point.rows) <= _LISTED or not finite:
        return f"{lead}: " + "; ".join(_row_text(r, first.frequency) for r in point.rows) + " (the factor: with the stop / without)."
    worse = point.worse()
    low, high = min(finite, key=lambda r: r.stopped), max(finite, key=lambda r: r.stopped)
    return (f"{lead}, over {len(point.rows)} solutions and swept points, the least is {_row_text(low, first.frequency)} and the most {_row_text(high, first.frequency)}; "
            f"{len(worse)} of them {'is' if len(worse) == 1 else 'are'} worse than the linear absorber (factor above {fmt(WORSE_RATIO, 'g')}).")  # fmt: skip


def _notch_peak(dataset: xr.Dataset, point: OperatingPoint, row: OperatingRow) -> str:
    """The largest |X1| of ``row``'s solution and swept point between the two linear resonances, where the notch
    was (a clause; empty where it has none)."""
    quantity = f"{point.coordinate}_amplitude"
    part = computed_part(dataset, row.solution)
    f = np.asarray(part["frequency"].values, dtype=float)
    data = part[quantity].sel(solution=row.solution)
    dims = _swept(data)
    chosen = [i for i in np.ndindex(*(data.sizes[d] for d in dims)) if _where(data, dims, i) == row.where]
    if not chosen:
        return ""
    values = np.asarray(data.transpose(*dims, ..., "frequency").values[chosen[0]], dtype=float)
    values = values.max(axis=tuple(range(values.ndim - 1))) if values.ndim > 1 else values
    if "stable" in part:
        stable = np.asarray(part["stable"].sel(solution=row.solution).transpose(*dims, ..., "frequency").values[chosen[0]])
        values = np.where((stable == 0).any(axis=tuple(range(stable.ndim - 1))) if stable.ndim > 1 else stable == 0, np.nan, values)  # exact: a flag
    inside = (f > point.resonances[0]) & (f < point.resonances[1]) & np.isfinite(values)
    if not inside.any():
        return ""
    k = int(np.nanargmax(np.where(inside, values, -np.inf)))
    return (f"; between the two linear resonances ({fmt(point.resonances[0], '.4g')} and {fmt(point.resonances[1], '.4g')} Hz), where the notch was, "
            f"|{point.coordinate.upper()}| with the stop peaks at {_mm(float(values[k]))} at {fmt(float(f[k]), '.4g')} Hz")  # fmt: skip


def warning_lines(dataset: xr.Dataset, layout: GeneralSetting | None = None) -> list[str]:
    """The page's first lines, before any praise: the stop never reached (:func:`unreached_text`), the stop making
    the operating point worse than the linear absorber, the absorber's free motion there not fitting in the gap.
    Empty when none applies."""
    layout = layout if layout is not None else general_setting(dataset)
    lines = []
    unreached = unreached_text(dataset, layout)
    if unreached:
        lines.append(unreached)
    point = operating_point(dataset, layout)
    if point is None:
        return lines
    worse = point.worse()
    c = point.coordinate.upper()
    if worse:
        row = worse[0]
        where = f" ({row.solution}{', ' + row.where if row.where else ''})"
        count = f" Worse at {len(worse)} of the {len(point.rows)} solutions and swept points." if len(point.rows) > 1 else ""
        lines.append(f"The stop makes the absorber worse at its operating point: at {fmt(row.frequency, '.4g')} Hz (anti-resonance {fmt(point.frequency, '.5g')} Hz) |{c}| is "
                     f"{_mm(row.linear)} with the linear absorber against {_mm(row.stopped)} with the stop{where}, ×{fmt(row.ratio, '.3g')}{_notch_peak(dataset, point, row)}.{count}")  # fmt: skip
    nearby = _nearby_impacts(dataset, point, layout, {row.solution for row in worse})
    if nearby:
        lines.append(nearby)
    if point.free:
        parts = [f"|{coordinate}| = {_mm(motion)} against a gap of {_mm(gap, '.6g')}" for coordinate, motion, gap in point.free]
        lines.append(f"The absorber's free motion at its operating point does not fit in the gap: without the stop, at {fmt(point.frequency, '.4g')} Hz, " + "; ".join(parts)
                     + ". The stop is struck at the frequency the absorber is tuned to.")  # fmt: skip
    return lines


def _nearby_impacts(dataset: xr.Dataset, point: OperatingPoint, layout: GeneralSetting, said: set[str]) -> str:
    """The largest stable motion with the stop within :data:`~vibroimpact.measures.figures_of_merit.NEAR_OPERATING` of the operating point that exceeds the
    linear absorber's there by the factor :data:`WORSE_RATIO`, of a solution not already said worse at the point
    itself, in one sentence; "" where none."""
    quantity = f"{point.coordinate}_amplitude"
    found: tuple[float, float, float, str, str] | None = None
    for solution in sorted({row.solution for row in point.rows} - said):
        part = computed_part(dataset, solution)
        f = np.asarray(part["frequency"].values, dtype=float)
        near = np.flatnonzero(np.abs(f - point.frequency) <= NEAR_OPERATING * point.frequency)
        if not near.size:
            continue
        data = part[quantity].sel(solution=solution).isel(frequency=near)
        if "stable" in part and "stable" in dataset.data_vars:
            data = data.where(part["stable"].sel(solution=solution).isel(frequency=near) != 0)
        dims = _swept(data)
        values = data.transpose(*dims, "frequency", ...).values
        values = values.reshape(values.shape[: len(dims) + 1] + (-1,)).max(axis=-1) if values.ndim > len(dims) + 1 else values
        linear = np.asarray(layout.linear_value(quantity, 2.0 * np.pi * f[near]), dtype=float)
        ratio = np.where(np.isfinite(values), values / linear, np.nan)
        if not np.any(ratio > WORSE_RATIO):
            continue
        index = np.unravel_index(int(np.nanargmax(ratio)), ratio.shape)
        if found is None or float(ratio[index]) > found[0]:
            found = (float(ratio[index]), float(f[near][index[-1]]), float(values[index]), solution, _where(data, dims, tuple(int(i) for i in index[:-1])))
    if found is None:
        return ""
    _ratio, at, value, solution, where = found
    share = 100.0 * (at - point.frequency) / point.frequency
    linear_there = float(layout.linear_value(quantity, np.array([2.0 * np.pi * at]))[0])
    return (f"At {fmt(at, '.4g')} Hz, {fmt(abs(share), '.2g')} % {'below' if share < 0 else 'above'} the absorber's operating point ({fmt(point.frequency, '.5g')} Hz), "
            f"{solution} has a stable motion with the stop of |{point.coordinate.upper()}| = {_mm(value)}{' at ' + where if where else ''} beside the linear absorber's "
            f"{_mm(linear_there)}: a drift of the operating speed by that much can land on it.")  # fmt: skip


def unreached_text(dataset: xr.Dataset, layout: GeneralSetting | None = None) -> str:
    """One line where no point of a stepped study's grid reaches a stop (empty otherwise, and for other kinds): the
    largest free motion of each stop's coordinate over the grid's frequencies against its gap, and, for a gap of
    :data:`MM_HINT_CLEARANCE` or more, whether it was meant in mm. A stop counts as reached where the linear motion
    crosses it at some frequency of the grid, or some solution recorded an impulse."""
    if study_kind(dataset) != "stepped" or "stop_layout" not in dataset.attrs or "frequency" not in dataset.dims:
        return ""
    layout = layout if layout is not None else general_setting(dataset)
    if "impulse" in dataset and float(np.nanmax(np.abs(np.asarray(dataset["impulse"].values, dtype=float)), initial=0.0)) > 0.0:
        return ""
    w = 2.0 * np.pi * np.asarray(dataset["frequency"].values, dtype=float)
    static = layout.static_deflection()
    shift = layout.normals @ static if static is not None else np.zeros(len(layout.stops))
    motion = np.abs(layout.linear(w) @ layout.normals.T).max(axis=0)
    gaps = _gaps(layout, dataset)
    if any(motion[k] >= gap for k, gap in gaps):
        return ""
    parts, hints = [], []
    for k in range(len(layout.stops)):
        gap = min(g for j, g in gaps if j == k)
        word = "clearance" if float(shift[k]) == 0.0 else "gap (the clearance less the static deflection)"  # exact: no static load
        parts.append(f"the largest |{_coordinate(layout.stops[k])}| on the grid is {_mm(float(motion[k]))} against a {_mm(gap, '.6g')} {word}")
        if gap >= MM_HINT_CLEARANCE:
            hints.append(f"{fmt(gap, 'g')} mm ({fmt(gap * 1e-3, 'g')} m)")
    subject = "The stop is never reached" if len(layout.stops) == 1 else "No stop is ever reached"
    hint = f"; did you mean {' and '.join(dict.fromkeys(hints))}?" if hints else "."
    return f"{subject}: {'; '.join(dict.fromkeys(parts))}{hint}"


def warnings_html(lines: list[str]) -> str:
    """The page's first lines (:func:`warning_lines`) as HTML paragraphs, each marked a warning (empty: none)."""
    return "".join(f"<p><b>Warning.</b> {html.escape(line)}</p>" for line in lines)
