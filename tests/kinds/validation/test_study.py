"""A validation scene end to end: read, run, dataset (CF-clean), report page with its table and figure."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from vibroimpact.kinds.validation.page import ValidationPage, write_validation_report
from vibroimpact.scene.reader import read_yaml
from vibroimpact.scene.kinds import KIND_NAMES as STUDY_KINDS
from vibroimpact.kinds.validation.scene import parse_validation_scene
from vibroimpact.runs.run import run_study, write_dataset
from vibroimpact.kinds.validation.formulas import PASSED_MEANINGS

from tests.study.test_cf import cf_findings

STUDIES = Path(__file__).resolve().parents[3] / "studies" / "validation"
#: The kind is registered in the scene schema, the reader, the study kinds and the report (by their owners).
REGISTERED = "validation" in STUDY_KINDS


def _zeno(tmp_path: Path):
    text = (STUDIES / "zeno.yaml").read_text(encoding="utf-8")
    scene = parse_validation_scene(read_yaml(text), text)
    return scene, run_study(scene, progress=None)


def test_dataset_table_and_page(tmp_path: Path) -> None:
    """The shipped Zeno scene: every check passes; the dataset is CF-clean; the page shows one row per check (with
    published, computed, relative error, tolerance and the verdict) and the figure."""
    scene, dataset = _zeno(tmp_path)
    assert dataset.attrs["validation_case"] == "zeno" and int(dataset.attrs["validation_passed"]) == 1
    assert dataset["passed"].attrs["flag_meanings"].split() == list(PASSED_MEANINGS)
    assert np.all(dataset["passed"].values == 1)
    path = write_dataset(dataset, tmp_path / f"{scene.name}.nc")
    assert cf_findings(path, tmp_path / "cf.json") == []
    page = write_validation_report(dataset, tmp_path / "report")
    text = page.read_text(encoding="utf-8")
    assert text.count("<tr>") == dataset.sizes["check"] + 1
    assert "validation_zeno.png" in text and "<p><b>Every check passed</b>. Source: " in text  # the answer before the source
    assert ValidationPage(dataset).summary() == f"validation case zeno: {dataset.sizes['check']} of {dataset.sizes['check']} checks passed"


@pytest.mark.skipif(not REGISTERED, reason="the kind 'validation' is not registered yet (scene/schema.py, reader, scene/kinds.py, reporting/page.py)")
def test_every_shipped_scene_is_a_validation_scene() -> None:
    """Once registered, the scene reader dispatches on the ``validation`` section and the scene's kind says so."""
    from vibroimpact.scene import load_scene

    for path in sorted(STUDIES.glob("*.yaml")):
        scene = load_scene(path)
        assert scene.kind == "validation" and scene.settings is not None and scene.settings.name in path.stem


@pytest.mark.skipif(not REGISTERED, reason="the kind 'validation' is not registered yet (scene/schema.py, reader, scene/kinds.py, reporting/page.py)")
def test_run_study_runs_a_validation_scene(tmp_path: Path) -> None:
    """Once registered, ``run-study`` reads, runs and reports a validation scene like any other."""
    from vibroimpact.cli import main

    assert main([str(STUDIES / "zeno.yaml"), "--out", str(tmp_path), "--jobs", "1"]) == 0
    assert (tmp_path / "validation_zeno.nc").is_file() and (tmp_path / "report.html").is_file()
