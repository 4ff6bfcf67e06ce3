"""The golden suite in tolerance mode, for a change that alters numbers on purpose:
``python -m tests.golden.compare [NAME ...] [--out FILE]``.

Each golden scene is run again and compared with its blessed dataset (its file's groups joined, every solution on
every frequency: :func:`vibroimpact.runs.run.join_groups`):

* **settled points** (the points whose regime, blessed and now, is neither irregular, quasi-periodic, chaotic nor
  failed, or whose simulation converged, by :data:`MARKERS`; every point where nothing says): every float variable to :data:`TOLERANCE` relative to the
  variable's largest magnitude, every integer variable (flags, counts) equal;
* **unsettled points** (not periodic, blessed or now: chaotic sets re-rolled by round-off): by class, count and
  statistics (the count of each regime and the median |X1| over them), reported, not held to a tolerance;
* the layout: the groups of the file and the variables that appeared in or vanished from each (a move, values equal);
* the page's text: the lines that changed.

It prints, and writes to ``--out`` (Markdown), the largest difference of every variable and every point whose regime
changed: the body of the ``CHANGES.md`` of a re-bless. Exit status 1 where a settled point breaks the tolerance or a
variable appeared or vanished.
"""

from __future__ import annotations

import argparse
import difflib
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import xarray as xr

from tests.golden.golden import Groups, compute, joined, scene_names, stored, written

#: Relative tolerance of settled points (relative to the variable's largest magnitude in the blessed dataset).
TOLERANCE = 1e-10
#: Regime flags of motions that are not periodic: their points re-roll with round-off.
UNSETTLED = (9, 11, 12, 13)  # irregular, failed, quasi_periodic, chaotic


@dataclass
class SceneChanges:
    """What changed in one golden scene."""

    name: str
    rows: list[tuple[str, str, str, bool]] = field(default_factory=list)  # variable, largest difference, where, within
    reclassified: list[str] = field(default_factory=list)
    unsettled: list[str] = field(default_factory=list)
    structure: list[str] = field(default_factory=list)
    page: list[str] = field(default_factory=list)

    @property
    def failed(self) -> bool:
        return bool(self.structure) or not all(row[3] for row in self.rows)


def _where(array: xr.DataArray, index: int) -> str:
    position = np.unravel_index(index, array.shape)
    return ", ".join(f"{dim}={array[dim].values[i]}" if dim in array.coords else f"{dim}[{i}]" for dim, i in zip(array.dims, position))


#: Which variable says whether a point settled, by the prefix of the variables it covers (the longest prefix wins):
#: a regime flag (unsettled: :data:`UNSETTLED`) or a converged flag (unsettled: 0).
MARKERS = {"": "regime", "brute_": "brute_regime", "simulated_": "simulated_converged", "bumper_": "bumper_converged"}


def _unsettled(marker: xr.DataArray) -> xr.DataArray:
    return marker.isin(UNSETTLED) if "regime" in str(marker.name) else marker == 0


def _settled_mask(now: xr.Dataset, blessed: xr.Dataset, name: str, variable: xr.DataArray) -> np.ndarray:
    """Points of ``variable`` whose motion is periodic blessed and now (all points where nothing says)."""
    prefix = max((p for p in MARKERS if name.startswith(p) and MARKERS[p] in blessed), key=len, default=None)
    marker = MARKERS[prefix] if prefix is not None else None
    if marker is None or marker not in now or not set(blessed[marker].dims) <= set(variable.dims):
        return np.ones(variable.shape, dtype=bool)
    unsettled = _unsettled(blessed[marker]) | _unsettled(now[marker])
    return ~xr.broadcast(unsettled, variable)[0].transpose(*variable.dims).values


def compare_datasets(name: str, now: xr.Dataset, blessed: xr.Dataset) -> SceneChanges:
    """The changes from ``blessed`` to ``now``."""
    changes = SceneChanges(name)
    for missing in sorted(set(blessed.variables) - set(now.variables)):
        changes.structure.append(f"`{missing}` vanished")
    for added in sorted(set(now.variables) - set(blessed.variables)):
        changes.structure.append(f"`{added}` appeared")
    for key in sorted(set(blessed.attrs) | set(now.attrs)):
        if str(blessed.attrs.get(key)) != str(now.attrs.get(key)):
            changes.rows.append((f"attribute `{key}`", f"{str(blessed.attrs.get(key))[:60]!r} -> {str(now.attrs.get(key))[:60]!r}", "", True))
    for variable_name in sorted(set(blessed.variables) & set(now.variables)):
        old, new = blessed[variable_name], now[variable_name]
        if old.shape != new.shape:
            changes.structure.append(f"`{variable_name}`: shape {old.shape} -> {new.shape}")
            continue
        if old.dtype.kind not in "fiuc" or new.dtype.kind not in "fiuc":
            if not np.array_equal(old.values, new.values):
                changes.structure.append(f"`{variable_name}`: values changed")
            continue
        settled = _settled_mask(now, blessed, str(variable_name), old)
        a, b = np.asarray(new.values), np.asarray(old.values)
        if old.dtype.kind in "iu":
            differ = (a != b) & settled
            count = int(np.count_nonzero(differ))
            where = _where(old, int(np.flatnonzero(differ)[0])) if count else ""
            changes.rows.append((f"`{variable_name}`", f"{count} of {int(settled.sum())} settled points differ", where, count == 0))
            if variable_name in ("regime", "brute_regime"):
                for index in np.flatnonzero((a != b).ravel()):
                    changes.reclassified.append(f"{_where(old, int(index))}: {int(b.ravel()[index])} -> {int(a.ravel()[index])}")
            continue
        finite_old, finite_new = np.isfinite(b), np.isfinite(a)
        nan_moved = int(np.count_nonzero((finite_old != finite_new) & settled))
        both = finite_old & finite_new & settled
        scale = float(np.max(np.abs(b[finite_old]))) if finite_old.any() else 0.0
        if both.any() and scale > 0.0:
            relative = np.where(both, np.abs(a - b) / scale, 0.0)
            worst = int(np.argmax(relative))
            largest = float(relative.ravel()[worst])
            text = f"{largest:.1e}" + (f"; NaN at {nan_moved} other points" if nan_moved else "")
            changes.rows.append((f"`{variable_name}`", text, _where(old, worst) if largest > 0.0 else "", largest <= TOLERANCE and not nan_moved))
        elif nan_moved:
            changes.rows.append((f"`{variable_name}`", f"NaN at {nan_moved} points", "", False))
    if "regime" in blessed and "regime" in now:
        for label, regime in (("blessed", blessed["regime"]), ("now", now["regime"])):
            values = regime.values.ravel()
            counts = {int(v): int(c) for v, c in zip(*np.unique(values[np.isin(values, UNSETTLED)], return_counts=True))}
            x1 = (blessed if label == "blessed" else now).get("x1_amplitude")
            median = ""
            if x1 is not None and x1.shape == regime.shape:
                chosen = x1.values.ravel()[np.isin(values, UNSETTLED)]
                chosen = chosen[np.isfinite(chosen)]
                median = f", median |X1| {np.median(chosen) * 1e3:.4g} mm over {chosen.size}" if chosen.size else ""
            changes.unsettled.append(f"{label}: {counts or 'none'}{median}")
    return changes


def layout_changes(now: Groups, blessed: Groups) -> list[str]:
    """The groups and the variables of each group that appeared or vanished (values may be the same: a move)."""
    found = []
    for key in sorted(set(now) | set(blessed)):
        if key not in now or key not in blessed:
            found.append(f"group `{key}` {'vanished' if key not in now else 'appeared'}{f' ({len(now[key].data_vars)} variables)' if key in now else ''}")
            continue
        for change, names in (("vanished from", set(blessed[key].data_vars) - set(now[key].data_vars)), ("appeared in", set(now[key].data_vars) - set(blessed[key].data_vars))):
            if names:
                found.append(f"{', '.join(f'`{n}`' for n in sorted(map(str, names)))} {change} group `{key}`")
    return found


def compare_scene(name: str) -> SceneChanges:
    """Run the golden scene ``name`` and compare it with its blessed files: the values of the joined groups (every
    solution on every frequency), then the layout (which group holds which variable)."""
    with tempfile.TemporaryDirectory() as folder:
        dataset, text = compute(name, Path(folder))
        now = written(dataset, Path(folder))
    blessed, blessed_text = stored(name)
    changes = compare_datasets(name, joined(now), joined(blessed))
    changes.structure += layout_changes(now, blessed)
    if text != blessed_text:
        changes.page = [line.rstrip("\n") for line in difflib.unified_diff((blessed_text or "").splitlines(True), (text or "").splitlines(True), "blessed", "now", n=0) if line[:1] in "+-" and line[:3] not in ("+++", "---")]
    return changes


def markdown(all_changes: list[SceneChanges]) -> str:
    """The changes as Markdown: a table per scene, the reclassified points, the page lines."""
    lines = [f"Settled points held to {TOLERANCE:.0e} of each variable's largest magnitude (flags and counts equal); unsettled points (regimes {UNSETTLED}) by class, count and median.", ""]
    for changes in all_changes:
        lines += [f"## {changes.name}{' (FAILS the tolerance)' if changes.failed else ''}", ""]
        lines += [f"- {item}" for item in changes.structure]
        moved = [row for row in changes.rows if row[1] not in ("0.0e+00",) and not row[1].startswith("0 of")]
        if moved:
            lines += ["| variable | largest difference | where | within |", "|---|---|---|---|"]
            lines += [f"| {v} | {d} | {w} | {'yes' if ok else '**no**'} |" for v, d, w, ok in moved]
        else:
            lines.append("Every variable identical.")
        if changes.unsettled:
            lines += ["", "Unsettled points: " + "; ".join(changes.unsettled) + "."]
        if changes.reclassified:
            lines += ["", f"Reclassified points ({len(changes.reclassified)}):", ""] + [f"- {item}" for item in changes.reclassified]
        if changes.page:
            lines += ["", f"Page text: {len(changes.page)} lines changed:", "", "```diff", *changes.page[:40], *(["..."] if len(changes.page) > 40 else []), "```"]
        lines.append("")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", help="golden scenes (default: all)")
    parser.add_argument("--out", type=Path, help="write the Markdown report here")
    args = parser.parse_args(argv)
    results = []
    for name in args.names or scene_names():
        results.append(compare_scene(name))
        print(f"{name}: {'FAILS' if results[-1].failed else 'within'}", file=sys.stderr, flush=True)
    text = markdown(results)
    print(text)
    if args.out:
        args.out.write_text(text, encoding="utf-8")
    return 1 if any(changes.failed for changes in results) else 0


if __name__ == "__main__":
    sys.exit(main())
