"""Datasets are CF-1.8 clean: the IOOS compliance checker finds no error and no warning in what ``run-study`` writes."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
import yaml
from compliance_checker.runner import CheckSuite, ComplianceChecker

from vibroimpact.scene import parse_scene
from vibroimpact.runs.run import write_dataset
from vibroimpact.runs.run import run_study

from tests.scene.test_scene import PAPER_SYSTEM_SPEC
from tests.study.test_swept_study import sweep_document

#: The checker's priorities: 3 errors, 2 warnings (1 is advice, not checked here).
ERRORS_AND_WARNINGS = ("high_priorities", "medium_priorities")


def cf_findings(path: Path, report: Path) -> list[str]:
    """Every error and warning of ``compliance-checker --test=cf:1.8`` on ``path``, one line each."""
    CheckSuite.load_all_available_checkers()
    ComplianceChecker.run_checker(str(path), ["cf:1.8"], 0, "normal", output_filename=str(report), output_format="json")
    result = json.loads(report.read_text())["cf:1.8"]
    findings = []
    for priority in ERRORS_AND_WARNINGS:
        for check in result[priority]:
            scored, possible = check["value"]
            if scored < possible:
                findings.append(f"{check['name']}: {'; '.join(check['msgs'])}")
    return findings


def write(document: dict[str, Any], folder: Path) -> Path:
    scene = parse_scene(document, text=yaml.safe_dump(document))
    return write_dataset(run_study(scene, progress=None), folder / f"{scene.name}.nc")


@pytest.mark.timeout(120)
def test_stepped_study_with_every_kind_of_solution_is_cf_clean(tmp_path: Path) -> None:
    """Swept R and Delta, closed forms, a simulation on its own grid (regime -1 elsewhere) and a bumper."""
    document = {
        "name": "cf_stepped",
        "system": dict(PAPER_SYSTEM_SPEC),
        "excitation": {"amplitude": 10.0},
        "bumper": {"frequency": 1000.0},
        "sweep": {"restitution": [0.2, 0.6], "clearance": [0.002, 0.003], "frequency": {"start": 24.0, "stop": 26.0, "step": 0.5}},
        "solutions": ["linear", "pgf", "pgf_paper", "exact"],
        "simulation": {"frequency": [25.0], "start": "pgf"},
    }
    path = write(document, tmp_path)
    assert cf_findings(path, tmp_path / "cf.json") == []


@pytest.mark.timeout(120)
def test_swept_sine_study_is_cf_clean(tmp_path: Path) -> None:
    """Running estimates over the sweep's elapsed time, string coordinates, per-run statistics."""
    document = sweep_document(name="cf_swept", swept_sine={"start": 24.0, "stop": 24.5, "rate": 0.25, "sample_rate": 2000.0, "directions": ["up"]})
    document["sweep"] = {"frequency": [24.2, 24.25]}
    path = write(document, tmp_path)
    assert cf_findings(path, tmp_path / "cf.json") == []


@pytest.mark.timeout(120)
def test_benchmark_study_is_cf_clean(tmp_path: Path) -> None:
    """A benchmark scene's dataset (case, engine, rtol), as engine_cost and accuracy_cost write it."""
    document = {
        "name": "cf_benchmark",
        "system": dict(PAPER_SYSTEM_SPEC),
        "excitation": {"amplitude": 10.0},
        "benchmark": {
            "duration": 0.2,
            "methods": ["momentary_adams"],
            "tolerances": [1.0e-6],
            "repeats": 1,
            "cases": [{"name": "one_impact_25Hz", "frequency": 25.0, "restitution": 0.2, "clearance": 0.003, "start": "rest"}],
        },
    }
    path = write(document, tmp_path)
    assert cf_findings(path, tmp_path / "cf.json") == []


def test_the_check_finds_what_it_should(tmp_path: Path) -> None:
    """The check is not blind: a coordinate with a _FillValue and a file without history are reported."""
    import xarray as xr

    dataset = xr.Dataset({"x": ("frequency", [1.0, 2.0], {"units": "m", "long_name": "x"})}, coords={"frequency": ("frequency", [1.0, 2.0], {"units": "Hz", "long_name": "f"})}, attrs={"Conventions": "CF-1.8", "title": "t"})
    path = tmp_path / "bad.nc"
    dataset.to_netcdf(path)  # xarray's default: _FillValue on every float variable, no history
    findings = " ".join(cf_findings(path, tmp_path / "cf.json"))
    assert "_FillValue" in findings and "history" in findings
