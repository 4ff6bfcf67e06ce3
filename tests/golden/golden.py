"""The golden suite's machinery: run a shrunk shipped scene, keep what does not depend on the machine, and read its
page as text.

Every scene in ``scenes/`` is a shipped study (``studies/``) shrunk by hand: fewer grid values, a short simulation
grid that keeps non-periodic points where the full scene has them, short transients. Its dataset is stored in
``data/<name>.nc`` without what depends on the machine or the clock (variables whose long name says "wall time", the
run's timing and provenance attributes), and its page's text (headings, paragraphs, captions, table cells, with the
timings replaced by fixed values before drawing) in ``data/<name>.txt``. ``pytest -m golden`` compares both bit for
bit; ``python -m tests.golden.bless [NAME ...]`` writes them again, on purpose, with the reason in the commit.
"""

from __future__ import annotations

import html.parser
import os
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

import numpy as np
import xarray as xr

HERE = Path(__file__).parent
SCENES = HERE / "scenes"
DATA = HERE / "data"

#: Attributes that say when, where, how fast or from which source text a run was made.
MACHINE_ATTRIBUTES = ("history", "vibroimpact_source_sha256", "run_wall_time_s", "run_jobs", "run_scheduler", "run_peak_memory_bytes", "run_peak_memory_worker_bytes")

#: Page elements whose text is compared (the scene's own text, in <pre>, is the input and is left out).
_TEXT_TAGS = {"h1", "h2", "h3", "h4", "p", "figcaption", "td", "th", "li", "caption"}


def scene_names() -> list[str]:
    """The golden scenes, by file name without ``.yaml``."""
    return sorted(path.stem for path in SCENES.glob("*.yaml"))


def is_timing(name: str, variable: xr.Variable) -> bool:
    """Whether ``variable`` measures the machine's speed: its long name speaks of wall time, or it is a time per period
    (the exact engine's floors, whose long names refer to another such variable)."""
    return "wall time" in str(variable.attrs.get("long_name", "")) or str(name).endswith("time_per_period")


def machine_free(dataset: xr.Dataset) -> xr.Dataset:
    """``dataset`` without its timings and the run's provenance attributes."""
    kept = dataset.drop_vars([name for name, variable in dataset.variables.items() if is_timing(str(name), variable)])
    for name in MACHINE_ATTRIBUTES:
        kept.attrs.pop(name, None)
    return kept


def fixed_timings(dataset: xr.Dataset) -> xr.Dataset:
    """``dataset`` with every timing replaced by fixed positive values where it was finite, so that a page drawn from it
    reads the same on every machine."""
    fixed = dataset.copy()
    for name, variable in dataset.variables.items():
        if is_timing(str(name), variable) and variable.dtype.kind == "f":
            pattern = 1e-3 * (1.0 + np.arange(variable.size) % 7).reshape(variable.shape)
            fixed[name] = variable.copy(data=np.where(np.isfinite(variable.values), pattern, np.nan))
    fixed.attrs.update(run_wall_time_s=1.0, run_jobs=1, run_scheduler="this process", run_peak_memory_bytes=1 << 28)
    fixed.attrs.pop("run_peak_memory_worker_bytes", None)
    return fixed


class _PageText(html.parser.HTMLParser):
    """The text of a report page, one line per heading, paragraph, caption or table cell."""

    def __init__(self) -> None:
        super().__init__()
        self.lines: list[str] = []
        self._open: list[str] = []
        self._skip = 0
        self._buffer: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        if tag in ("pre", "style", "script"):
            self._skip += 1
        elif tag in _TEXT_TAGS:
            self._flush()
            self._open.append(tag)

    def handle_endtag(self, tag: str) -> None:
        if tag in ("pre", "style", "script"):
            self._skip -= 1
        elif tag in _TEXT_TAGS:
            self._flush(tag)
            if self._open and self._open[-1] == tag:
                self._open.pop()

    def handle_data(self, data: str) -> None:
        if not self._skip and self._open:
            self._buffer.append(data)

    def _flush(self, tag: str | None = None) -> None:
        text = " ".join("".join(self._buffer).split())
        if text:
            self.lines.append(f"{tag or self._open[-1]}: {text}")
        self._buffer = []


def page_text(html_text: str) -> str:
    """The compared text of a report page."""
    parser = _PageText()
    parser.feed(html_text)
    parser.close()
    return "\n".join(parser.lines) + "\n"


@contextmanager
def _inside(folder: Path) -> Iterator[None]:
    """Work in ``folder`` (the benchmark page looks for the shipped studies' last runs in ``./results``)."""
    before = Path.cwd()
    os.chdir(folder)
    try:
        yield
    finally:
        os.chdir(before)


def compute(name: str, workdir: Path) -> tuple[xr.Dataset, str | None]:
    """The golden scene ``name`` run in this process: its machine-free dataset and its page's text (None: the scene
    draws no report)."""
    from vibroimpact.reporting.page import write_report
    from vibroimpact.scene import load_scene
    from vibroimpact.runs.run import run_study

    scene = load_scene(SCENES / f"{name}.yaml")
    dataset = run_study(scene, progress=None)
    text = None
    if scene.report:
        with _inside(workdir):
            page = write_report(fixed_timings(dataset), workdir / "report")
            text = page_text(page.read_text(encoding="utf-8"))
    return machine_free(dataset), text


#: A dataset as its file holds it: netCDF group path -> that group's dataset (``"/"``; ``"/simulated"`` where the
#: study simulates, :func:`vibroimpact.runs.run.split_groups`).
Groups = dict[str, xr.Dataset]


def read_back(path: Path) -> Groups:
    """Every group of the dataset written at ``path``, loaded, without what the writer adds of the machine
    (``history``)."""
    groups = xr.open_groups(path)
    try:
        return {key: machine_free(group.load()) for key, group in groups.items()}
    finally:
        for group in groups.values():
            group.close()


def written(dataset: xr.Dataset, folder: Path) -> Groups:
    """``dataset`` as the package's writer stores it and a reader reads it back (what the blessed file holds)."""
    from vibroimpact.runs.run import write_dataset

    return read_back(write_dataset(dataset, folder / "golden.nc"))


def dtypes(groups: Groups) -> dict[str, str]:
    """The stored type of every variable of every group (``xarray.testing.assert_identical`` compares values, so
    int32 equals int64)."""
    return {f"{key}:{name}": str(variable.dtype) for key, group in groups.items() for name, variable in group.variables.items()}


def identical(now: Groups, blessed: Groups) -> bool:
    """The same groups, each identical (values, attributes), with the same types."""
    return now.keys() == blessed.keys() and all(now[key].identical(blessed[key]) for key in now) and dtypes(now) == dtypes(blessed)


def joined(groups: Groups) -> xr.Dataset:
    """The one dataset of ``groups`` (:func:`vibroimpact.runs.run.join_groups`): every solution on every frequency."""
    from vibroimpact.runs.run import join_groups

    return join_groups(groups)


def stored(name: str) -> tuple[Groups, str | None]:
    """The blessed dataset's groups and page text of ``name``."""
    page = DATA / f"{name}.txt"
    return read_back(DATA / f"{name}.nc"), page.read_text(encoding="utf-8") if page.exists() else None
