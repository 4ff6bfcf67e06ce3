"""What every report page shares: figure and table records, the PNG writer, and the HTML page with its contents.

Figure builders return a :class:`DrawnFigure` (the matplotlib figure still open, so that tests can inspect what was
drawn); :func:`save_figure` writes it and closes it. A page is a list of :class:`Section`; :func:`render_page` writes
the HTML with a table of contents linking every section, figure and table. Each kind of study has a page type
(:class:`StudyPage`) that gives the line naming what was computed and the sections, both read from the dataset.

:func:`write_report` writes a dataset's report: PNG figures and a self-contained ``report.html`` (figures embedded as
base64) into a folder, everything read from the dataset itself (:mod:`vibroimpact.reporting.record`), never from a
re-validated scene; :func:`page_for` asks the dataset's kind (:data:`vibroimpact.scene.kinds.KINDS`) for its page
(each kind's ``page.py``: concepts, validation, benchmark, bifurcation, swept, design; stepped: the bumper
stiffness page and one frequency-response page for every other layout, whose sections follow what the dataset holds).
"""

from __future__ import annotations

import base64
import html
import io
import pickle
import re
from collections.abc import Iterator
from concurrent.futures import Executor, Future, ProcessPoolExecutor
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterable, Protocol

from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.reporting.style import DPI, REPORT_RC, linear_under_a_decade, readable_axes, thin_minor_log_ticks  # first: selects the Agg backend before pyplot is imported

import matplotlib.pyplot as plt  # noqa: E402
import xarray as xr  # noqa: E402
from matplotlib.figure import Figure as MatplotlibFigure  # noqa: E402

from vibroimpact.reporting.record import study_kind, study_record  # noqa: E402
from vibroimpact.runs.failures import failure_details, run_failures  # noqa: E402
from vibroimpact.runs.output_files import atomic_path  # noqa: E402
from vibroimpact.scene.kinds import kind_named  # noqa: E402

__all__ = ["DrawnFigure", "Figure", "Table", "Section", "StudyPage", "save_figure", "saved", "rendering", "render_page", "write_page", "write_report", "with_failures", "page_for"]

#: The processes that render figures while :func:`rendering` is active, and the figures handed to them (their PNG
#: paths and pending bytes); None: this process renders.
_RENDERERS: ContextVar[tuple[Executor, list[tuple[Path, "Future[bytes]"]]] | None] = ContextVar("renderers", default=None)


@dataclass(frozen=True)
class DrawnFigure:
    """A drawn matplotlib figure, not yet written.

    Attributes
    ----------
    figure : matplotlib.figure.Figure
        The open figure.
    name : str
        File name without extension (unique within a page).
    title : str
        Heading of the figure on the page and in its contents.
    caption : str
        What the figure shows, generated from what was drawn.
    """

    figure: MatplotlibFigure
    name: str
    title: str
    caption: str


@dataclass(frozen=True)
class Figure:
    """A figure written to disk, its heading and caption."""

    path: Path
    title: str
    caption: str


@dataclass(frozen=True)
class Table:
    """An HTML table (or any HTML block) with its heading."""

    title: str
    html: str


@dataclass
class Section:
    """A part of a page: a heading, an optional introduction (HTML), then figures and tables in that order."""

    title: str
    intro: str = ""
    figures: list[Figure] = field(default_factory=list)
    tables: list[Table] = field(default_factory=list)


class StudyPage(Protocol):
    """The page of one kind of study (:func:`vibroimpact.reporting.page.page_for` chooses it)."""

    def summary(self) -> str:
        """What was computed, for the page's heading: ``solutions: ...`` or ``methods: ...``."""
        ...

    def sections(self, out: Path) -> list[Section]:
        """The page's sections, their figures written into ``out``."""
        ...

    # A page may set ``states_failures = True`` when it says the run's failures itself (:func:`write_report` then adds
    # no "What failed in this run" section of its own).


def save_figure(drawn: DrawnFigure, out_dir: Path) -> Figure:
    """Write ``drawn`` as ``out_dir/<name>.png`` atomically, close it, and return its record."""
    png = _png(drawn.figure)
    return _write(drawn, png, out_dir)


def _png(figure: MatplotlibFigure) -> bytes:
    """The figure rendered to PNG bytes, then closed."""
    buffer = io.BytesIO()
    linear_under_a_decade(figure)
    thin_minor_log_ticks(figure)
    readable_axes(figure)
    figure.savefig(buffer, format="png", dpi=DPI, bbox_inches="tight", pad_inches=0.08)
    plt.close(figure)
    return buffer.getvalue()


def _png_of_pickle(data: bytes) -> bytes:
    """:func:`_png` of a pickled figure (what a rendering process receives)."""
    return _png(pickle.loads(data))


def _write(drawn: DrawnFigure, png: bytes, out_dir: Path) -> Figure:
    path = _png_path(drawn, out_dir)
    _write_png(path, png)
    return Figure(path, drawn.title, drawn.caption)


def _png_path(drawn: DrawnFigure, out_dir: Path) -> Path:
    return Path(out_dir) / f"{drawn.name}.png"


def _write_png(path: Path, png: bytes) -> None:
    with atomic_path(path) as temporary:
        temporary.write_bytes(png)


@contextmanager
def rendering(jobs: int) -> Iterator[None]:
    """Inside, :func:`saved` hands figures to ``jobs`` processes that render them to PNG (rendering is most of a
    report's time: ~0.5 s per figure of a 30 000-point study) and returns at once, so the page draws its next figures
    meanwhile; the files are written as the context ends (before the page is). ``jobs`` <= 1 renders here."""
    if jobs <= 1:
        yield
        return
    pending: list[tuple[Path, Future[bytes]]] = []
    with ProcessPoolExecutor(max_workers=jobs) as pool:
        token = _RENDERERS.set((pool, pending))
        try:
            yield
        finally:
            _RENDERERS.reset(token)
        for path, png in pending:
            _write_png(path, png.result())


def saved(drawn: Iterable[DrawnFigure | None], out: Path) -> list[Figure]:
    """Each drawn figure's record (skipping None): written as soon as it comes, so that few are open at once, or,
    inside :func:`rendering`, handed pickled to the rendering processes and written when the context ends (a figure
    that cannot be pickled is written here and now)."""
    renderers = _RENDERERS.get()
    if renderers is None:
        return [save_figure(figure, out) for figure in drawn if figure is not None]
    pool, pending = renderers
    figures = []
    for figure in drawn:
        if figure is None:
            continue
        try:
            data = pickle.dumps(figure.figure)
        except Exception:  # noqa: BLE001 - any figure that does not pickle (a lambda formatter; pandas caches filled
            # while being pickled: "dictionary changed size during iteration", seen on clearance_peaks) is drawn here
            figures.append(save_figure(figure, out))
            continue
        plt.close(figure.figure)
        path = _png_path(figure, out)
        pending.append((path, pool.submit(_png_of_pickle, data)))
        figures.append(Figure(path, figure.title, figure.caption))
    return figures


_STYLE = (
    "body{font-family:sans-serif;max-width:1360px;margin:1.5em auto;padding:0 12px;color:#222;line-height:1.4}"
    "table{border-collapse:collapse;margin:0.6em 0;display:block;overflow-x:auto;max-width:100%}"
    "td,th{border:1px solid #bbb;padding:3px 8px;text-align:right}td{white-space:nowrap}"
    "th{background:#f2f2f2}td:first-child,th:first-child{text-align:left}"
    "img{max-width:100%;height:auto;display:block}pre{background:#f4f4f4;padding:1em;overflow:auto}"
    "figure{margin:1.2em 0 2em 0}figcaption{font-size:95%;color:#333;max-width:1320px}"
    "nav{background:#f7f7f7;border:1px solid #ddd;padding:0.4em 1.2em;margin:1em 0}nav ol{margin:0.2em 0}"
    "nav ol ol{list-style:none;padding-left:1.2em;margin:0 0 0.4em 0;font-size:95%}nav ol ol li{display:inline}"
    "nav ol ol li+li:before{content:' \\00b7  ';color:#888}"
    "h3{margin-bottom:0.3em}.filename{color:#777}"
)


def _anchor(text: str, used: set[str]) -> str:
    """A unique HTML id made of ``text``."""
    base = re.sub(r"[^a-z0-9]+", "-", text.lower()).strip("-") or "item"
    anchor, n = base, 2
    while anchor in used:
        anchor, n = f"{base}-{n}", n + 1
    used.add(anchor)
    return anchor


def _short(title: str, prefix: str, suffix: str | None) -> str:
    """``title`` without the ``prefix`` and ``suffix`` its section's title already says, for the contents."""
    if suffix and title.endswith(suffix) and len(title) > len(suffix):
        title = title[: -len(suffix)]
    if title.startswith(prefix) and len(title) > len(prefix):
        title = title[len(prefix) :]
        title = title[:1].upper() + title[1:]
    return title


def render_page(title: str, paragraphs: list[str], sections: list[Section], scene_text: str) -> str:
    """The HTML page: heading, ``paragraphs`` (plain text), contents, the sections, and the scene.

    Every section, figure and table gets an anchor and an entry in the contents; figures are embedded (base64).
    """
    used: set[str] = set()
    contents: list[str] = []
    body: list[str] = []
    for section in [*sections, Section("Scene")]:
        section_id = _anchor(section.title, used)
        entries = []
        # the contents do not repeat what the section's title says ("Simulations ...: " before, ", Delta = 3 mm" after)
        suffix = section.title[section.title.index(", ") :] if ", " in section.title else None
        prefix = section.title.split(", ")[0] + ": "
        body.append(f"<section id='{section_id}'><h2>{html.escape(section.title)}</h2>{section.intro}")
        for figure in section.figures:
            figure_id = _anchor(figure.path.stem, used)
            entries.append(f"<li><a href='#{figure_id}'>{html.escape(_short(figure.title, prefix, suffix))}</a></li>")
            encoded = base64.b64encode(figure.path.read_bytes()).decode("ascii")
            body.append(
                f"<figure id='{figure_id}'><h3>{html.escape(figure.title)}</h3><img alt='{html.escape(figure.title)}' "
                f"src='data:image/png;base64,{encoded}'><figcaption>{html.escape(figure.caption)} "
                f"<span class='filename'>({html.escape(figure.path.name)})</span></figcaption></figure>"
            )
        for table in section.tables:
            table_id = _anchor(table.title, used)
            entries.append(f"<li><a href='#{table_id}'>{html.escape(_short(table.title, prefix, suffix))}</a></li>")
            body.append(f"<div id='{table_id}'><h3>{html.escape(table.title)}</h3>{table.html}</div>")
        if section.title == "Scene":
            body.append(f"<pre>{html.escape(scene_text)}</pre>")
        body.append("</section>")
        sub = f"<ol>{''.join(entries)}</ol>" if entries else ""
        contents.append(f"<li><a href='#{section_id}'>{html.escape(section.title)}</a>{sub}</li>")
    head = (
        f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{html.escape(title)}</title><style>{_STYLE}</style></head><body>"
        f"<h1>{html.escape(title)}</h1>" + "".join(f"<p>{html.escape(p)}</p>" for p in paragraphs)
    )
    nav = f"<nav id='contents'><h2>Contents</h2><ol>{''.join(contents)}</ol></nav>"
    return "\n".join([head, nav, *body, "</body></html>"])


def write_page(path: Path, text: str) -> Path:
    """Write ``text`` to ``path`` atomically; return the path."""
    with atomic_path(path) as temporary:
        temporary.write_text(text, encoding="utf-8")
    return path


# --------------------------------------------------------------------------------------------------------------------
# The report of a dataset: its kind's page, written. 
# --------------------------------------------------------------------------------------------------------------------

@suggest_keywords
def write_report(dataset: xr.Dataset, out_dir: str | Path, jobs: int = 1) -> Path:
    """Write the PNG figures and ``report.html`` for ``dataset`` into ``out_dir``, rendering the figures in ``jobs``
    processes; return the HTML path."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    record = study_record(dataset)
    page = page_for(dataset)
    with rendering(jobs), plt.rc_context(REPORT_RC):
        sections = page.sections(out)
    if not getattr(page, "states_failures", False):  # a page that places them itself (bifurcation: before its tables)
        sections = with_failures(sections, run_failures(dataset), failure_details(dataset))
    paragraphs = [record.description, f"vibroimpact {record.version}; {page.summary()}."]
    return write_page(out / "report.html", render_page(f"Study '{record.name}'", paragraphs, sections, record.scene_text))


def with_failures(sections: list[Section], failures: list[str], details: list[str]) -> list[Section]:
    """``sections`` with the run's failures said right after the page's answer (its first section), each in one line,
    and their raw messages in a collapsed section at the end; unchanged when nothing failed."""
    if not failures:
        return sections
    items = "".join(f"<li>{html.escape(line)}</li>" for line in failures)
    summary = Section("What failed in this run", f"<p><b>The run finished, but not everywhere.</b></p><ul>{items}</ul>")
    out = [*sections[:1], summary, *sections[1:]]
    if details:
        raw = html.escape("\n".join(details))
        out.append(Section("Failure details", f"<details><summary>The raw messages ({len(details)})</summary><pre>{raw}</pre></details>"))
    return out


def page_for(dataset: xr.Dataset) -> StudyPage:
    """The page of ``dataset``: its kind's (:func:`~vibroimpact.reporting.record.study_kind`, the kind's ``page_for``
    in :data:`vibroimpact.scene.kinds.KINDS`)."""
    page: StudyPage = kind_named(study_kind(dataset)).page_for(dataset)
    return page
