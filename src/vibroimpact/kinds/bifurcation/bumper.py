"""The bumper part of a bifurcation page: how the branches of Kelvin-Voigt bumpers (``bifurcation.bumper``) and their
special points converge to the rigid stop's as the bumper stiffens.

Dataset layout read here: :mod:`vibroimpact.kinds.bifurcation.study` with ``branch_bumper_frequency`` and
``special_point_bumper_frequency`` [Hz] (inf: the rigid stop), and the curves of the stiffest bumper's special points
in the bumper's stiffness (``stiffness_*``, :mod:`vibroimpact.kinds.bifurcation.stiffness`).

Which bumper point continues which rigid one: along a curve where there is one. A rigid fold, period doubling or
Neimark-Sacker point is continued by the curve (a piece of it monotone in T_b) whose stiff end, extrapolated to
T_b = 0 by Richardson's rule (first-order convergence), lands on it within :data:`RICHARDSON` of the distance it
removes; at each bumper its counterpart is the located point within
:data:`~vibroimpact.kinds.bifurcation.stiffness.ON_CURVE` of the curve, or the curve's own value where no branch of
that bumper passes it, or none where the curve ends short of that bumper (the branch's folds meet at a cusp).
Otherwise (contact onsets at tangency, which do not depend on Omega_b; a dataset without curves) by distance: the
stiffest bumper's nearest point of the same kind on its closed-form branches within :data:`MATCH_WINDOW` of the rigid
one, then each softer bumper's point within :data:`GROWTH` times the previous distance times the ratio of the bumper
frequencies (at least :data:`MATCH_FLOOR`) of the previous match: a chain along which the distance may grow at most
like first order, doubled. A match must be clear: the chain's nearest candidate, at most :data:`SEPARATION` times as
far as its next, and nearer to this chain's previous match than to any other chain's of the kind; otherwise the
chain stops and the table says "ambiguous". The observed order of convergence between two bumper frequencies
fa < fb is p = ln(|e_a| / |e_b|) / ln(fb / fa), e the difference from the rigid stop's frequency (p = 1: first order
in 1/Omega_b). A difference below :data:`SAME_POINT` of the frequency is the same point (the contact onset at tangency
of the one-contact orbit is where the linear orbit touches the surface, whatever the bumper).
"""

from __future__ import annotations

import html
import math

import numpy as np
import xarray as xr

from vibroimpact.kinds.bifurcation.bumper_start import STIFF_START
from vibroimpact.kinds.bifurcation.figures import KIND_NAMES, SPECIAL_MARKERS, first_coordinate, flags, length_of
from vibroimpact.kinds.bifurcation.scene import coordinate_label
from vibroimpact.kinds.bifurcation.stiffness import ON_CURVE, SOFTER, STIFFER, curve_pieces, on_piece
from vibroimpact.reporting.page import DrawnFigure, Table
from vibroimpact.runs.failures import as_lines
from vibroimpact.reporting.style import MIN_FONT_SIZE, OKABE_ITO, STABLE_STYLE, UNSTABLE_STYLE, finish_axes, fmt, new_figure, ordered_colours

__all__ = ["has_bumpers", "has_rigid", "diagram_models", "model_view", "rigid_view", "bumper_frequencies", "bumper_name", "convergence_rows", "convergence_table", "bumper_answer", "absent_text", "bumper_figure", "MATCH_WINDOW", "SAME_POINT"]

#: Largest distance [Hz] of the stiffest bumper's special point from the rigid stop's it is matched with.
MATCH_WINDOW = 0.5
#: Each softer bumper's match lies within GROWTH x (frequency ratio) x the previous distance of the previous match [-] ...
GROWTH = 2.0
#: ... or within this [Hz], whichever is larger.
MATCH_FLOOR = 0.05
#: A match is clear when the next candidate is at least 1 / SEPARATION times as far from the previous match [-].
SEPARATION = 0.5
#: A bumper's special point within this of the rigid stop's, relative, is the same point [-] (the location's accuracy).
SAME_POINT = 1e-9
#: A curve continues a rigid special point when Richardson's extrapolation of its stiff end lands within this share of
#: the distance it removes [-] (first-order convergence: the extrapolation removes nearly all of it; measured 1e-3 of it
#: for the fold at 26.7 Hz, 64 kHz).
RICHARDSON = 0.1
#: A curve that stops short of the softest bumper by more than this share of its period "ends" there [-].
REACH = 0.01
#: Colour of the rigid stop's branches; the bumpers take the ordered palette (:func:`ordered_colours`) in order of
#: frequency.
RIGID_COLOUR = "k"
#: Line colours of the convergence panel, one per special point (Okabe-Ito's and grey; black is the rigid stop's).
CONVERGENCE_COLOURS = (*OKABE_ITO[:6], "#999999", OKABE_ITO[6])
#: Origins of the branches started from the closed form (flags of ``branch_origin``).
_CLOSED = ("one_impact", "two_impacts")


def has_bumpers(dataset: xr.Dataset) -> bool:
    """Does the dataset hold bumper branches (``branch_bumper_frequency``)?"""
    return "branch_bumper_frequency" in dataset.coords or "branch_bumper_frequency" in dataset


def diagram_models(dataset: xr.Dataset) -> list[float]:
    """The contact models of a bumper dataset's diagrams, Omega_b / 2 pi [Hz]: the bumpers by increasing frequency,
    then inf for the rigid stop where it ran (a dataset without the brute force's ``bumper_frequency`` holds the rigid
    stop's brute force alone, and its diagram)."""
    if "bumper_frequency" not in dataset.dims:
        return [math.inf]
    values = [float(f) for f in dataset["bumper_frequency"].values]
    return sorted(f for f in values if math.isfinite(f)) + [f for f in values if math.isinf(f)]


def has_rigid(dataset: xr.Dataset) -> bool:
    """Does a bumper dataset hold the rigid stop's diagram, the reference its bumpers converge to?"""
    return math.inf in diagram_models(dataset)


def model_view(dataset: xr.Dataset, bumper: float) -> xr.Dataset:
    """One diagram of a bumper dataset, shaped as a rigid scene's: the branch and special points of the bumpers of
    ``bumper`` Hz (inf: the rigid stop) and their brute force (without the ``bumper_frequency`` dimension), with
    ``diagram_label`` ("bumper 250 Hz", "rigid stop") and ``diagram_tag`` (a file-name suffix) in its attributes."""
    points = np.flatnonzero(_of(dataset["branch_bumper_frequency"].values, bumper))
    specials = np.flatnonzero(_of(dataset["special_point_bumper_frequency"].values, bumper))
    view = dataset.isel(branch_point=points, special_point=specials).drop_vars(["branch_bumper_frequency", "special_point_bumper_frequency"])
    if "bumper_frequency" in view.dims:
        index = [float(f) for f in view["bumper_frequency"].values].index(bumper)
        view = view.isel(bumper_frequency=index).drop_vars("bumper_frequency")
    rigid = math.isinf(bumper)
    return view.assign_attrs(diagram_label="rigid stop" if rigid else f"bumper {bumper_name(dataset, bumper)}", diagram_tag="_rigid" if rigid else f"_bumper{fmt(bumper, 'g')}Hz",
                             brute_force_engine="compiled exact engine" if rigid else "the bumper's compiled closed-form engine")  # fmt: skip


def bumper_name(dataset: xr.Dataset, bumper: float) -> str:
    """A bumper in the scene's own units: ``250 Hz``, or ``K_b = 2.467e+05 N/m (250 Hz)`` where the scene gave its
    stiffness (the attribute ``bumper_stiffnesses_N_per_m``, in the order of ``bumper_frequencies_Hz``)."""
    frequency = f"{fmt(bumper, 'g')} Hz"
    stiffnesses, frequencies = dataset.attrs.get("bumper_stiffnesses_N_per_m"), dataset.attrs.get("bumper_frequencies_Hz")
    if stiffnesses is None or frequencies is None or math.isinf(bumper):
        return frequency
    match = [k for k, f in zip(np.atleast_1d(stiffnesses), np.atleast_1d(frequencies)) if abs(float(f) - bumper) <= 1e-12 * bumper]
    return f"K_b = {float(match[0]):.4g} N/m ({frequency})" if match else frequency


def _of(values: np.ndarray, bumper: float) -> np.ndarray:
    """Which of ``values`` [Hz] are ``bumper`` (both inf for the rigid stop; equal: the dataset's own values)."""
    return np.isinf(values) if math.isinf(bumper) else values == bumper


def rigid_view(dataset: xr.Dataset) -> xr.Dataset:
    """The dataset with the rigid stop's branch and special points only (unchanged without bumpers)."""
    return model_view(dataset, math.inf) if has_bumpers(dataset) else dataset


def bumper_frequencies(dataset: xr.Dataset) -> list[float]:
    """Omega_b / 2 pi of the bumpers [Hz], increasing."""
    values = dataset["branch_bumper_frequency"].values
    return sorted(float(f) for f in np.unique(values[np.isfinite(values)]))


def _closed_form_specials(dataset: xr.Dataset, restitution: float, bumper: float) -> list[tuple[str, float]]:
    """(kind, frequency [Hz]) of the special points on the closed-form branches of one set (bumper inf: rigid)."""
    origins = flags(dataset["branch_origin"])
    codes = [origins.index(k) for k in _CLOSED if k in origins]
    closed = set(dataset["branch"].values[np.isin(dataset["branch_origin"].values, codes)].tolist())
    kinds = flags(dataset["special_point_kind"])
    fb = dataset["special_point_bumper_frequency"].values
    chosen = np.isclose(dataset["special_point_restitution"].values, restitution) & ((fb == bumper) | (np.isinf(fb) & math.isinf(bumper)))
    out = []
    for k in np.flatnonzero(chosen):
        if int(dataset["special_point_branch"].values[k]) in closed and int(dataset["special_point_period_multiplicity"].values[k]) == 1:
            out.append((kinds[int(dataset["special_point_kind"].values[k])], float(dataset["special_point_frequency"].values[k])))
    return sorted(out, key=lambda item: item[1])


def convergence_rows(dataset: xr.Dataset, restitution: float) -> list[dict[str, object]]:
    """One row per special point of the rigid stop's closed-form branches at ``restitution``: its kind, frequency
    [Hz], the matched frequency at each bumper (module docstring; NaN: none, or ``ambiguous`` there: more than one
    candidate, or one another chain also reaches), the differences [Hz] and the observed orders between successive
    bumper frequencies (NaN where a difference is missing or the same point)."""
    bumpers = bumper_frequencies(dataset)
    sets = {fb: _closed_form_specials(dataset, restitution, fb) for fb in bumpers}
    rigid = _closed_form_specials(dataset, restitution, math.inf)
    matched = np.full((len(rigid), len(bumpers)), np.nan)
    ambiguous = np.zeros((len(rigid), len(bumpers)), dtype=bool)
    previous = np.array([f for _k, f in rigid])
    window = np.full(len(rigid), MATCH_WINDOW)
    alive = np.ones(len(rigid), dtype=bool)
    for i in range(len(bumpers) - 1, -1, -1):  # the stiffest first, every chain at once
        near = [sorted((f for k, f in sets[bumpers[i]] if k == kind and abs(f - previous[n]) <= window[n]), key=lambda f, n=n: abs(f - previous[n])) if alive[n] else []
                for n, (kind, _f0) in enumerate(rigid)]  # fmt: skip
        for n, (kind, f0) in enumerate(rigid):
            if not alive[n]:
                continue
            clear = bool(near[n]) and (len(near[n]) == 1 or abs(near[n][0] - previous[n]) <= SEPARATION * abs(near[n][1] - previous[n]))
            rivals = [m for m in range(len(rigid)) if alive[m] and rigid[m][0] == kind]
            if clear and min(rivals, key=lambda m: abs(previous[m] - near[n][0])) == n:  # its nearest, and nearest to it
                matched[n, i] = near[n][0]
            else:  # none, or no clear one: the chain stops here
                ambiguous[n, i], alive[n] = bool(near[n]), False
        for n, (_kind, f0) in enumerate(rigid):
            if alive[n] and np.isfinite(matched[n, i]):
                ratio = bumpers[i] / bumpers[i - 1] if i else 1.0
                previous[n], window[n] = matched[n, i], max(MATCH_FLOOR, GROWTH * ratio * abs(matched[n, i] - f0))
    continued = np.zeros((len(rigid), len(bumpers)), dtype=bool)
    ends = np.full(len(rigid), np.nan)
    followed = np.zeros(len(rigid), dtype=bool)
    pieces: list[tuple[np.ndarray, np.ndarray] | None] = [None] * len(rigid)
    for n, (kind, f0) in enumerate(rigid):
        curve = pieces[n] = _curve_of(dataset, restitution, kind, f0)
        if curve is None:
            continue  # not followed in the stiffness (a contact onset at tangency), or no curve reaches it: by distance
        followed[n], ambiguous[n] = True, False
        for i, fb in enumerate(bumpers):
            matched[n, i], continued[n, i] = _on_curve(curve, 1.0 / fb, [f for k, f in sets[fb] if k == kind])
        if curve[0][-1] < (1.0 - REACH) / bumpers[0]:
            ends[n] = 1.0 / curve[0][-1]
    rows = []
    for n, (kind, f0) in enumerate(rigid):
        errors = matched[n] - f0
        found = np.isfinite(errors)
        same = found & (np.abs(np.nan_to_num(errors)) <= SAME_POINT * f0)
        orders = [
            math.log(abs(errors[i]) / abs(errors[i + 1])) / math.log(bumpers[i + 1] / bumpers[i]) if np.all(np.isfinite(errors[i : i + 2])) and not same[i : i + 2].any() else math.nan
            for i in range(len(bumpers) - 1)
        ]  # fmt: skip
        rows.append({"kind": kind, "rigid": f0, "bumpers": list(matched[n]), "errors": errors, "same": bool(found.any() and np.all(same[found])), "orders": orders,
                     "ambiguous": list(ambiguous[n]), "followed": bool(followed[n]), "continued": list(continued[n]), "ends": float(ends[n]), "curve": pieces[n]})  # fmt: skip
    return rows


def _curves(dataset: xr.Dataset, restitution: float, kind: str) -> list[tuple[np.ndarray, np.ndarray]]:
    """The curves in the bumper's stiffness of special points of ``kind`` at ``restitution``, as their
    :func:`~vibroimpact.kinds.bifurcation.stiffness.monotone_pieces` (T_b [s], frequency [Hz]) (none when the dataset
    has no curves)."""
    if "stiffness_curve" not in dataset.coords:
        return []
    kinds = flags(dataset["stiffness_kind"])
    if kind not in kinds:
        return []
    chosen = (dataset["stiffness_kind"].values == kinds.index(kind)) & np.isclose(dataset["stiffness_restitution"].values, restitution)
    return curve_pieces(*(dataset[name].values[chosen] for name in ("stiffness_curve", "stiffness_bumper_frequency", "stiffness_frequency")))


def _curve_of(dataset: xr.Dataset, restitution: float, kind: str, rigid: float) -> tuple[np.ndarray, np.ndarray] | None:
    """The curve that continues the rigid stop's special point (``kind`` at ``rigid`` Hz): its stiff end extrapolated
    to T_b = 0 by Richardson's rule, 2 f(T) - f(2 T), lands on ``rigid`` within :data:`RICHARDSON` of the distance
    f(T) - rigid that the extrapolation removes (the nearest such curve); None if none does."""
    best, distance = None, math.inf
    for piece in _curves(dataset, restitution, kind):
        t = piece[0][0]
        if 2.0 * t > piece[0][-1]:
            continue  # too short to extrapolate
        near = on_piece(piece, t)
        limit = 2.0 * near - on_piece(piece, 2.0 * t)
        miss = abs(limit - rigid)
        if miss <= RICHARDSON * abs(near - rigid) + SAME_POINT * rigid and miss < distance:
            best, distance = piece, miss
    return best


def _on_curve(piece: tuple[np.ndarray, np.ndarray], period: float, located: list[float]) -> tuple[float, bool]:
    """The special point at bumper period ``period`` [s] on a curve's piece: the located point of that bumper's
    branches within :data:`~vibroimpact.kinds.bifurcation.stiffness.ON_CURVE` of the piece, else the piece's own value
    (True: found by the continuation only, no branch of that bumper passes it); NaN where the piece does not reach
    ``period``."""
    value = on_piece(piece, period)
    if not math.isfinite(value):
        return math.nan, False
    near = [f for f in located if abs(f - value) <= ON_CURVE]
    if near:
        return min(near, key=lambda f: abs(f - value)), False
    return value, True


def _name(kind: str) -> str:
    """The page's name of a kind of special point; grazing is the bumper's contact onset at tangency."""
    return "grazing / contact onset at tangency" if kind == "grazing" else KIND_NAMES.get(kind, kind)


def convergence_table(dataset: xr.Dataset) -> Table:
    """Per restitution and special point: the rigid stop's frequency, each bumper's and its difference, and the
    observed orders of convergence."""
    bumpers = bumper_frequencies(dataset)
    heads = ["R", "special point", "rigid stop [Hz]"] + [f"{bumper_name(dataset, fb)} bumper [Hz] (difference)" for fb in bumpers]
    heads += [f"order {fmt(a, 'g')} → {fmt(b, 'g')} Hz" for a, b in zip(bumpers[:-1], bumpers[1:])]
    body = []
    for r in dataset["restitution"].values:
        for row in convergence_rows(dataset, float(r)):
            cells = [fmt(float(r), "g"), _name(str(row["kind"])), fmt(float(row["rigid"]), ".4f")]
            for fb, f, e, unclear, alone in zip(bumpers, row["bumpers"], row["errors"], row["ambiguous"], row["continued"]):
                if math.isfinite(f):
                    cells.append(f"{fmt(f, '.4f')} ({'+' if e >= 0 else '−'}{fmt(abs(e), '.2e')})" + (", by the continuation alone" if alone else ""))
                elif math.isfinite(row["ends"]) and fb < row["ends"]:
                    cells.append(f"none: its curve ends at {fmt(row['ends'], '.0f')} Hz")
                else:
                    cells.append("ambiguous" if unclear else "not found")
            cells += ["same point" if row["same"] else ("—" if not math.isfinite(p) else fmt(p, ".2f")) for p in row["orders"]]
            body.append("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in cells) + "</tr>")
    header = "".join(f"<th>{html.escape(h)}</th>" for h in heads)
    return Table("How the bumpers' special points converge to the rigid stop's", f"<table><tr>{header}</tr>{''.join(body)}</table>")


def _span(values: list[float]) -> str:
    """``0.91-0.98``, or one value when they agree to the digits shown."""
    low, high = fmt(min(values), ".2f"), fmt(max(values), ".2f")
    return low if low == high else f"{low}-{high}"


def bumper_answer(dataset: xr.Dataset) -> str:
    """The answer (HTML), per restitution: the observed orders of convergence between the two stiffest bumpers by kind
    of special point, the largest shift at the softest bumper, the contact onsets at tangency that are the rigid
    stop's grazing points, and how many rigid points have no counterpart at some bumper (the table has each)."""
    bumpers = bumper_frequencies(dataset)
    parts = []
    for r in dataset["restitution"].values:
        rows = convergence_rows(dataset, float(r))
        words = []
        if len(bumpers) > 1:
            by_kind = {}
            for row in rows:
                if not row["same"] and math.isfinite(row["orders"][-1]):
                    by_kind.setdefault(str(row["kind"]), []).append(float(row["orders"][-1]))
            if by_kind:
                every = [p for values in by_kind.values() for p in values]
                listed = "; ".join(f"{_name(k)} {', '.join(fmt(p, '.2f') for p in sorted(v))}" for k, v in by_kind.items())
                words.append(f"the special points of the one-impact branches move to the rigid stop's as the bumper stiffens: between the "
                             f"{fmt(bumpers[-2], 'g')} Hz and {fmt(bumpers[-1], 'g')} Hz bumpers their observed order of convergence in 1/Omega_b is "
                             f"{_span(every)} ({listed}; 1 is first order)")  # fmt: skip
        shifts = [(abs(float(row["errors"][0])), row) for row in rows if math.isfinite(float(row["errors"][0])) and not row["same"]]
        if shifts:
            size, row = max(shifts, key=lambda item: item[0])
            words.append(f"the {bumper_name(dataset, bumpers[0])} bumper moves them by up to {fmt(size, '.3g')} Hz (the {_name(str(row['kind']))} at {fmt(float(row['rigid']), '.3f')} Hz)")
        same = [row for row in rows if row["same"]]
        if same:
            words.append(f"the contact onsets at tangency at {', '.join(fmt(float(row['rigid']), '.3f') for row in same)} Hz, where the one-impact orbit's entry speed "
                         f"vanishes on the linear orbit touching the surface, are the rigid stop's grazing points for every bumper that has them (within {fmt(SAME_POINT, 'g')} relative)")  # fmt: skip
        followed = [row for row in rows if row["followed"]]
        if followed:
            words.append(f"{len(followed)} of the rigid stop's special points (folds, period doublings, Neimark-Sacker points) have a curve in the bumper's "
                         f"stiffness, followed from the {fmt(bumpers[-1], 'g')} Hz bumper's over {fmt(bumpers[0] / SOFTER, 'g')}-{fmt(bumpers[-1] * STIFFER, 'g')} Hz, "
                         "whose stiff end, extrapolated to the rigid stop, lands on them: the table matches along these curves")  # fmt: skip
        for row in rows:
            if math.isfinite(row["ends"]):
                words.append(f"the {_name(str(row['kind']))} at {fmt(float(row['rigid']), '.3f')} Hz has no counterpart below {fmt(row['ends'], '.0f')} Hz, where its curve in "
                             "the bumper's stiffness ends")  # fmt: skip
        alone = sum(int(np.sum(row["continued"])) for row in rows)
        if alone:
            words.append(f"{alone} of the table's points are found by the continuation in the stiffness alone (no branch of that bumper was started through them)")
        missing = [row for row in rows if not np.all(np.isfinite(np.asarray(row["errors"], dtype=float))) and not math.isfinite(row["ends"])]
        if missing:
            words.append(f"{len(missing)} of the rigid stop's {len(rows)} special points have no counterpart at some bumper (table)")
        parts.append(f"<p><b>R = {fmt(float(r), 'g')}, bumpers of {', '.join(fmt(fb, 'g') for fb in bumpers)} Hz against the rigid stop</b>: " + "; ".join(words) + ".</p>")
    return "".join(parts)


def absent_text(dataset: xr.Dataset) -> str:
    """The closed-form starts a bumper has no orbit for (``bumper_starts_without_orbit``), as HTML: an answer, not a
    failure; empty when every start has one."""
    lines = as_lines(dataset.attrs.get("bumper_starts_without_orbit"))
    if not lines:
        return ""
    items = "".join(f"<li>{html.escape(line)}</li>" for line in lines)
    return ("<p>Where a bumper has no one-contact orbit that the rigid stop has (an answer, not a failure: the rigid stop's orbit, followed in the bumper's "
            f"stiffness from a bumper {fmt(STIFF_START, 'g')} times stiffer, vanishes before it reaches the scene's bumper; {len(lines)} start{'s' if len(lines) != 1 else ''}):</p><ul>{items}</ul>")


def _bumper_colours(count: int) -> str:
    """The bumpers' colours in words (the ordered palette, softest first)."""
    return "dark purple" if count == 1 else "dark purple for the softest to yellow-green for the stiffest" if count > 2 else "dark purple, then yellow-green"


def bumper_figure(dataset: xr.Dataset) -> DrawnFigure:
    """Left: the closed-form branches of the rigid stop and of every bumper, the first coordinate's amplitude against
    frequency; right: each special point's distance from the rigid stop's against 1 / Omega_b (log-log, a slope-1
    line for reference)."""
    name = first_coordinate(dataset)
    label = coordinate_label(name)
    bumpers = bumper_frequencies(dataset)
    unit, scale = length_of(dataset)
    colours = {math.inf: RIGID_COLOUR} | dict(zip(bumpers, ordered_colours(len(bumpers))))
    fig, (left, right) = new_figure(2, panel_height=6.0, columns=2)  # the legends under the panels included
    origins = flags(dataset["branch_origin"])
    codes = [origins.index(k) for k in _CLOSED if k in origins]
    fb_points = dataset["branch_bumper_frequency"].values
    for fb in [math.inf, *bumpers]:
        chosen = np.isin(dataset["branch_origin"].values, codes) & ((fb_points == fb) | (np.isinf(fb_points) & math.isinf(fb)))
        for branch in np.unique(dataset["branch"].values[chosen]):
            index = np.flatnonzero(chosen & (dataset["branch"].values == branch))
            f, amp, stable = dataset["branch_frequency"].values[index], dataset[f"{name}_amplitude"].values[index] * scale, dataset["stable"].values[index] == 1
            change = np.flatnonzero(np.diff(stable.astype(int))) + 1
            for piece in np.split(np.arange(f.size), change):
                run = np.append(piece, piece[-1] + 1) if piece.size and piece[-1] + 1 < f.size else piece
                if run.size:
                    left.plot(f[run], amp[run], color=colours[fb], **(STABLE_STYLE if stable[piece[0]] else UNSTABLE_STYLE))
        left.plot([], [], color=colours[fb], lw=2, label="rigid stop, one-impact branch" if math.isinf(fb) else f"bumper {bumper_name(dataset, fb)}, one-contact branch")
    kinds = flags(dataset["special_point_kind"])
    sp_fb = dataset["special_point_bumper_frequency"].values
    for code, kind in enumerate(kinds):
        for fb in [math.inf, *bumpers]:
            chosen = (dataset["special_point_kind"].values == code) & ((sp_fb == fb) | (np.isinf(sp_fb) & math.isinf(fb)))
            if chosen.any():
                left.scatter(dataset["special_point_frequency"].values[chosen], dataset[f"special_point_{name}_amplitude"].values[chosen] * scale, marker=SPECIAL_MARKERS.get(kind, "x"),
                             s=46, facecolor="none", edgecolor=colours[fb], lw=1.3, zorder=5)  # fmt: skip
        left.scatter([], [], marker=SPECIAL_MARKERS.get(kind, "x"), s=46, facecolor="none", edgecolor="0.3", label=_name(kind))
    inverse = 1.0 / np.array(bumpers)
    drawn = 0
    for r in dataset["restitution"].values:
        for row in convergence_rows(dataset, float(r)):
            errors = np.abs(np.asarray(row["errors"], dtype=float))
            if row["same"] or np.isfinite(errors).sum() < 2:
                continue
            colour, entry = CONVERGENCE_COLOURS[drawn % len(CONVERGENCE_COLOURS)], f"{KIND_NAMES.get(str(row['kind']), str(row['kind']))} at {fmt(float(row['rigid']), '.2f')} Hz"
            if row["curve"] is not None:  # the curve in the stiffness, and the table's points on it
                t, f = row["curve"]
                right.plot(t, np.abs(f - float(row["rigid"])), color=colour, lw=1.4, label=entry)
                right.plot(inverse, errors, marker=SPECIAL_MARKERS.get(str(row["kind"]), "x"), color=colour, lw=0, mfc="none", ms=7)
            else:
                right.plot(inverse, errors, marker=SPECIAL_MARKERS.get(str(row["kind"]), "x"), color=colour, lw=1.4, mfc="none", ms=7, label=entry)
            drawn += 1
    if drawn:
        errors = [np.abs(np.asarray(row["errors"], dtype=float)) for r in dataset["restitution"].values for row in convergence_rows(dataset, float(r)) if not row["same"]]
        middle = float(np.exp(np.nanmedian(np.log([e[-1] for e in errors if np.isfinite(e[-1])]))))
        right.plot(inverse, middle * inverse / inverse[-1], color="k", ls=":", lw=2.0, label="slope 1 (first order in 1/Omega_b)")
        right.set_xscale("log")
        right.set_yscale("log")
        right.set_xticks(inverse, [f"1/{fmt(fb, 'g')}" for fb in bumpers])
        right.minorticks_off()
    finish_axes(left, "excitation frequency [Hz]", f"|{label}| fundamental [{unit}]", f"{label} amplitude: one-impact branches, rigid stop and bumpers")
    finish_axes(right, "1 / (Omega_b / 2 pi) [1/Hz]", "|special point's frequency − rigid stop's| [Hz]", "convergence to the rigid stop's special points")
    # two legends, one under each panel: the left's colours are the contact models (bumpers in the ordered palette),
    # the right's the special points (Okabe-Ito), and neither legend mixes the two
    for ax, title in ((left, "branch colour: contact model; open marker: its special point"), (right, "colour: special point (kind, rigid stop's frequency)")):
        if ax.get_legend_handles_labels()[0]:
            ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.13), ncols=2, fontsize=MIN_FONT_SIZE + 1, title=title, title_fontsize=MIN_FONT_SIZE + 1)
    caption = (
        f"Left: the branches started from the closed form (one impact per period) of the rigid stop (black) and of Kelvin-Voigt bumpers of "
        f"{', '.join(fmt(fb, 'g') for fb in bumpers)} Hz ({_bumper_colours(len(bumpers))}), each with the loss factor whose "
        f"collision restitution is R, Delta = {fmt(float(dataset['clearance']) * scale, 'g')} {unit}: the {label} fundamental, solid where stable, dashed where "
        "unstable; open markers in the branch's colour: its special points. Right: the distance of each special point of the bumpers' branches from the "
        "rigid stop's against 1 / (Omega_b / 2 pi) [1/Hz], log-log, one colour per special point (its own legend, under the panel: its kind and the rigid stop's frequency), "
        "markers at the bumpers of the study, lines: the special point followed in the bumper's stiffness (its curve from the stiffest bumper, "
        "where the table's matching comes from; markers joined by straight lines where no curve was followed); the dotted black line has slope 1 "
        "(first-order convergence). The contact onsets at tangency, the same points for every bumper, and points found at one bumper only are not drawn there."
    )
    return DrawnFigure(fig, "bumper_convergence", "One-impact branches of the bumpers and of the rigid stop, and how their special points converge", caption)
