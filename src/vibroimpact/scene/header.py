"""What every scene has, whatever its kind: its name, description, report switch and cluster, and the limits of a
swept-sine run (shared by grid scenes and benchmark cases).

Each function records its problems in a :class:`~vibroimpact.scene.checker.Checker`, naming the key and the allowed
values. The layout (system, excitation, stops) has its own grammar, :func:`vibroimpact.scene.layout_parse.parse_layout`.
"""

from __future__ import annotations

import re
from typing import Any

from vibroimpact.scene.checker import Checker
from vibroimpact.scene.kinds import KINDS
from vibroimpact.scene.declared import OPTIONAL, REQUIRED, Key, Section, Table
from vibroimpact.scene.schema import MAX_SWEEP_SAMPLES

__all__ = ["NAME", "MAX_NAME_LENGTH", "HEADER", "CLUSTER", "HEADER_KEYS", "declared_sections", "open_scene", "parse_names", "parse_cluster", "check_sweep_run"]

#: A scene's or a case's name: safe as a file name, at most :data:`MAX_NAME_LENGTH` characters (the run writes
#: ``.<name>.zarr.removed-<pid>`` and the like, within the 255 bytes a file name may take).
MAX_NAME_LENGTH = 100
NAME = re.compile(rf"^[A-Za-z0-9][A-Za-z0-9_.-]{{0,{MAX_NAME_LENGTH - 1}}}$")

#: The shared header, declared (:mod:`vibroimpact.scene.declared`): the keys every scene may give, whatever its kind,
#: read once by :func:`open_scene` and honoured by every kind.
HEADER = Section("", (
    Key("name", str, f"the study's name: its output folder and files (letters, digits, '_', '-', '.'; at most {MAX_NAME_LENGTH})", REQUIRED),
    Key("description", str, "one line the page and the dataset carry (no number depends on it)", ""),
    Key("report", bool, "whether run-study writes the HTML page beside the dataset", True),
    Key("cluster", Table, "{scheduler: tcp://host:8786}: a running dask scheduler to run on (default: a local cluster)", OPTIONAL),
), "what every scene has, whatever its kind")  # fmt: skip
#: ``cluster``, declared.
CLUSTER = Section("cluster", (
    Key("scheduler", str, "the address of a running dask scheduler, e.g. tcp://head-node:8786", REQUIRED),
), "where the study runs")  # fmt: skip
#: The keys every scene may give, whatever its kind.
HEADER_KEYS = frozenset(HEADER.names)


def declared_sections() -> tuple[Section, ...]:
    """The shared header's and the layout's declared sections, then every kind's (:meth:`~vibroimpact.scene.kinds.Kind.sections`),
    each once (a section two kinds share, in the first's place); imports the kinds' scene parsers only."""
    from vibroimpact.scene.layout_parse import LAYOUT_SECTIONS

    seen: dict[tuple[str, str], Section] = {(section.path, section.form): section for section in (HEADER, CLUSTER, *LAYOUT_SECTIONS)}
    for kind in KINDS:
        for section in kind.sections():
            if seen.setdefault((section.path, section.form), section) is not section:
                raise ValueError(f"kind {kind.name!r} declares a section {section.path!r} ({section.form or 'its only form'}) that another declares otherwise")
    return tuple(seen.values())


def open_scene(document: Any, top_keys: set[str], required: set[str], kind: str) -> tuple[Checker, dict, Any, str, bool, str | None]:
    """How a kind's scene parser begins: a new :class:`Checker`, ``document`` checked as a mapping of the kind's
    ``top_keys`` and the :data:`HEADER_KEYS` with the ``required`` ones (a key of another kind named as such), its
    :func:`parse_names` and its :func:`parse_cluster`: the header every kind reads the same way.

    Returns
    -------
    tuple
        (checker, the document as a mapping, name, description, report, the cluster's scheduler or None).
    """
    c = Checker()
    doc = c.mapping("", document, set(top_keys) | HEADER_KEYS, required, kind=kind)
    return (c, doc, *parse_names(c, doc), parse_cluster(c, doc))


def parse_names(c: Checker, doc: dict) -> tuple[Any, str, bool]:
    """Name, description and the report switch of any scene (:data:`HEADER`; a missing name is the kind's to say)."""
    def given(key: str) -> Any:  # its declared check where the scene gives it, else (or where wrong) its default
        checked = HEADER.key(key).check(c, key, doc[key]) if key in doc else None
        return checked if checked is not None else HEADER.key(key).default

    name = doc.get("name")  # required by each kind's own keys, said once there
    if "name" in doc and HEADER.key("name").check(c, "name", name) is not None and not NAME.match(name):
        c.fail("name", f"expected a file-name-safe string of at most {MAX_NAME_LENGTH} characters (letters, digits, '_', '-', '.'), got {name!r}")
    return name, given("description"), given("report")


def parse_cluster(c: Checker, doc: dict) -> str | None:
    """The scene's ``cluster: {scheduler: ADDRESS}`` (:data:`CLUSTER`): a running dask scheduler to run on (None: a
    local cluster)."""
    if "cluster" not in doc:
        return None
    values = CLUSTER.read(c, doc["cluster"])
    address = values["scheduler"] if values is not None else None
    if address is not None and ":" not in address:
        c.fail("cluster.scheduler", f"expected a scheduler address such as tcp://host:8786, got {address!r}")
        return None
    return address


def check_sweep_run(c: Checker, key: str, low: float, high: float, rate: float | None, sample_rate: float | None, cycles: int | None, window_hint: str = "") -> tuple[float | None, float | None]:
    """Limits of one swept-sine run between ``low`` and ``high`` [Hz], shared by scenes and benchmark cases: 20 output
    samples per cycle at the top, at most :data:`MAX_SWEEP_SAMPLES` samples, and room for two estimator windows of
    ``cycles`` cycles. Returns (rate, sample_rate), each None where it failed."""
    if sample_rate is not None and sample_rate < 20.0 * high:
        c.fail(f"{key}.sample_rate", f"{sample_rate:g} Hz is too coarse for {high:g} Hz: allowed [{20.0 * high:g}, 1e+07] (20 samples per cycle)")
        sample_rate = None
    if rate is not None:
        duration = (high - low) / rate
        if sample_rate is not None and duration * sample_rate > MAX_SWEEP_SAMPLES:
            c.fail(f"{key}.rate", f"{duration:g} s at {sample_rate:g} samples/s is {duration * sample_rate:.3g} samples per run: allowed at most {MAX_SWEEP_SAMPLES:.0e} (raise the rate or lower {key}.sample_rate)")
            rate = None
        elif cycles is not None and 2.0 * cycles / low >= duration:
            c.fail(f"{key}.rate", f"the sweep lasts {duration:g} s, shorter than two {cycles}-cycle estimator windows at {low:g} Hz ({2.0 * cycles / low:g} s): lower the rate{window_hint}")
            rate = None
    return rate, sample_rate
