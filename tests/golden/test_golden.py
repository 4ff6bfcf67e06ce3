"""The golden suite (``pytest -m golden``): every shipped scene, shrunk, gives the blessed dataset and page text bit for
bit. A move of code must pass it unchanged; a change of numbers re-blesses it in a commit of its own
(``python -m tests.golden.bless``, see :mod:`tests.golden.golden`)."""

from __future__ import annotations

import difflib
from pathlib import Path

import pytest
import xarray as xr

from tests.golden.arithmetic import pinned, unpinned_message
from tests.golden.golden import DATA, SCENES, compute, dtypes, scene_names, stored, written

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.golden
@pytest.mark.timeout(900)
@pytest.mark.parametrize("name", scene_names())
def test_scene_gives_its_golden_dataset_and_page(name: str, tmp_path: Path) -> None:
    assert pinned(), unpinned_message()
    dataset, text = compute(name, tmp_path)
    blessed, blessed_text = stored(name)
    now = written(dataset, tmp_path)
    assert now.keys() == blessed.keys(), "the file's groups changed"  # "/", and "/simulated" where the study simulates
    for key in now:
        xr.testing.assert_identical(now[key], blessed[key])
    assert dtypes(now) == dtypes(blessed)  # assert_identical compares values: an int64 index equals an int32 one
    assert text == blessed_text, "the page's text changed:\n" + "".join(difflib.unified_diff((blessed_text or "").splitlines(True), (text or "").splitlines(True), "blessed", "now"))


def test_every_shipped_scene_has_a_golden_scene_and_its_files() -> None:
    """A shipped study without a shrunk twin here would move unguarded; a golden scene without its blessed files
    would fail only under ``-m golden``."""
    shipped = {path.stem if path.parent.name == "studies" else f"{path.parent.name}_{path.stem}" for path in (ROOT / "studies").rglob("*.yaml")}
    assert shipped == set(scene_names())
    for name in scene_names():
        assert (DATA / f"{name}.nc").is_file(), name
        assert (SCENES / f"{name}.yaml").is_file()


def test_page_text_keeps_headings_captions_and_cells_but_not_the_scene() -> None:
    from tests.golden.golden import page_text

    text = page_text("<h1>T</h1><p>a  <b>b</b></p><pre>scene: x</pre><figure><figcaption>cap <span>(f.png)</span></figcaption></figure><table><tr><th>h</th><td>1.5</td></tr></table>")
    assert text == "h1: T\np: a b\nfigcaption: cap (f.png)\nth: h\ntd: 1.5\n"


def test_ci_runs_the_golden_suite_in_the_pinned_arithmetic() -> None:
    """``.ci/run`` sets every pin of :data:`tests.golden.arithmetic.PINS` on its golden line (a drifted pin would make
    CI compare in another arithmetic than the files were blessed in)."""
    from tests.golden.arithmetic import PINS

    line = next(line for line in (ROOT / ".ci" / "run").read_text().splitlines() if "-m golden" in line and not line.lstrip().startswith("#"))
    for key, value in PINS.items():
        assert f'{key}="{value}"' in line or f"{key}={value}" in line, (key, line)
