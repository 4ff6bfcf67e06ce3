"""Datasets are CF-1.8 clean: the IOOS compliance checker finds no error and no warning in what ``run-study`` writes,
for every kind of study and every netCDF group, none of its checks raises, and it exits 0 (what a pipeline gating on
``compliance-checker --test=cf:1.8`` sees); and the numbers a dataset records as attributes stay numbers when it is
read back."""

from __future__ import annotations

import contextlib
import io
import json
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

import netCDF4
import numpy as np
import pytest
import xarray as xr
import yaml
from compliance_checker.runner import CheckSuite, ComplianceChecker

from vibroimpact.scene import load_scene, parse_scene
from vibroimpact.scene.kinds import KIND_NAMES
from vibroimpact.runs.run import netcdf_attribute, read_dataset, write_dataset
from vibroimpact.runs.run import run_study

from tests.golden.golden import DATA, SCENES
from tests.scene.test_scene import PAPER_SYSTEM_SPEC
from tests.kinds.swept.test_swept_study import sweep_document

#: The checker's priorities: 3 errors, 2 warnings (1 is advice, not checked here).
ERRORS_AND_WARNINGS = ("high_priorities", "medium_priorities")


def cf_findings(path: Path, report: Path) -> list[str]:
    """Every error and warning of ``compliance-checker --test=cf:1.8`` on ``path``, one line each, and on each of
    its netCDF groups (the checker checks where attributes sit in groups, but the variables of the root group only:
    each group is checked as a flat copy, :func:`flattened`)."""
    findings = checked(path, report)
    with netCDF4.Dataset(path) as source:
        groups = list(source.groups)
    for group in groups:
        flat = flattened(path, group, report.with_name(f"{report.stem}_{group}.nc"))
        findings += [f"group {group}: {finding}" for finding in checked(flat, report)]
    return findings


def flattened(path: Path, group: str, target: Path) -> Path:
    """The group ``group`` of the file at ``path`` copied to a file of its own at ``target``, as stored (types, fill
    values, attributes; no compression), under the root's attributes (the group's own override them)."""
    with netCDF4.Dataset(path) as source, netCDF4.Dataset(target, "w") as flat:
        part = source.groups[group]
        flat.setncatts({**source.__dict__, **part.__dict__})
        for name, variable in part.variables.items():
            for dimension in variable.get_dims():
                if dimension.name not in flat.dimensions:
                    flat.createDimension(dimension.name, len(dimension))
            attrs = dict(variable.__dict__)
            copy = flat.createVariable(name, variable.datatype, variable.dimensions, fill_value=attrs.pop("_FillValue", None))
            copy.setncatts(attrs)
            variable.set_auto_maskandscale(False)
            copy.set_auto_maskandscale(False)
            copy[...] = variable[...]
    return target


#: What the checker prints to stderr before each check that raised (its exceptions: the check was not made).
EXCEPTION_LINE = re.compile(r"^cf:1\.8\.\w+: ")


def checked(path: Path, report: Path) -> list[str]:
    """Every error and warning of ``compliance-checker --test=cf:1.8`` on the file at ``path``, one line each; every
    check that raised instead of checking (the checker prints it to stderr and exits 2 after "All tests passed!");
    and the checker's exit status where it is not 0 (2 where a check raised, 1 where a check failed), as the command
    line computes it from what :meth:`ComplianceChecker.run_checker` returns."""
    CheckSuite.load_all_available_checkers()
    stderr = io.StringIO()
    with contextlib.redirect_stderr(stderr):
        passed, raised = ComplianceChecker.run_checker(str(path), ["cf:1.8"], 0, "normal", output_filename=str(report), output_format="json")
    result = json.loads(report.read_text())["cf:1.8"]
    findings = []
    for priority in ERRORS_AND_WARNINGS:
        for check in result[priority]:
            scored, possible = check["value"]
            if scored < possible:
                findings.append(f"{check['name']}: {'; '.join(check['msgs'])}")
    findings += [f"raised: {line}" for line in stderr.getvalue().splitlines() if EXCEPTION_LINE.match(line)]
    status = 2 if raised else 0 if passed else 1  # the command line's exit status
    if status:
        findings.append(f"exit status {status}")
    return findings


def write(document: dict[str, Any], folder: Path) -> Path:
    scene = parse_scene(document, text=yaml.safe_dump(document))
    dataset = run_study(scene, progress=None)
    return read_back_as_written(dataset, write_dataset(dataset, folder / f"{scene.name}.nc"))


def read_back_as_written(dataset: xr.Dataset, path: Path) -> Path:
    """``path``, after checking that :func:`read_dataset` reads it back as ``dataset``: labels on their dimensions,
    values, attributes (the writer's ``history`` aside; a one-element sequence is one value in netCDF) and types
    (text is text, fixed-width or not)."""
    back = read_dataset(path)
    assert back.attrs.pop("history")
    expected = dataset.copy()
    expected.attrs = {key: as_netcdf_reads(value) for key, value in dataset.attrs.items() if key != "history"}
    xr.testing.assert_identical(back, expected)
    assert types(back) == types(dataset)
    return path


def as_netcdf_reads(value: object) -> object:
    """An attribute's value as netCDF gives it back: a one-element sequence is its element."""
    if isinstance(value, (list, tuple, np.ndarray)) and np.size(value) == 1:
        return np.asarray(value).ravel()[0]
    return value


def types(dataset: xr.Dataset) -> dict[str, str]:
    """Each variable's type; ``text`` for strings (numpy's fixed-width or Python objects: a file read back gives the
    former)."""
    return {str(name): "text" if variable.dtype.kind in "OU" else str(variable.dtype) for name, variable in dataset.variables.items()}


#: A string attribute that reads as a number or as numpy's text of an array ('[23.02212513 36.07439742]').
_NUMBER = r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?"
NUMBER_TEXT = re.compile(rf"^\s*\[?\s*{_NUMBER}((\s*,\s*|\s+){_NUMBER})*\s*\]?\s*$")
#: Attributes that are text by CF even where they read as a number (units "1").
TEXT_BY_CF = ("units",)


def numbers_as_text(path: Path) -> list[str]:
    """Every attribute of the file at ``path`` (its groups' and their variables') whose value is text that reads as a
    number or an array of numbers: a number written as its repr."""
    found = []
    groups = xr.open_groups(path)
    for group, dataset in groups.items():
        where = "" if group == "/" else f"{group}:"
        owners = [(f"{where}dataset", dataset.attrs)] + [(f"{where}{name}", variable.attrs) for name, variable in dataset.variables.items()]
        for owner, attrs in owners:
            for key, value in attrs.items():
                if isinstance(value, str) and key not in TEXT_BY_CF and NUMBER_TEXT.match(value):
                    found.append(f"{owner}.{key} = {value!r}")
        dataset.close()
    return found


#: A concepts study small enough for the default tier (2 s): a concept without a stop and one with (continued
#: branch points, the notch depth in dB).
CONCEPTS_DOCUMENT: dict[str, Any] = {
    "name": "cf_concepts",
    "system": dict(PAPER_SYSTEM_SPEC),
    "excitation": {"amplitude": 10.0},
    "frequency": {"start": 30.0, "stop": 36.0, "step": 0.25},
    "simulation": {"frequency": [34.0], "rtol": 1.0e-7, "irregular_measure_periods": 16},
    "bumper": {"frequency": 250.0},
    "continuation": {"max_steps": 20},
    "concepts": [
        {"name": "den_hartog", "label": "(a)", "absorber": {"stiffness": "den_hartog", "damping": "den_hartog"}},
        {"name": "absolute", "label": "(b)", "stops": [{"coordinate": "x2", "side": "upper", "clearance": 0.003, "restitution": 0.2}]},
    ],
    "report": False,
}
#: The datasets checked by :func:`test_every_kind_is_cf_clean` (case -> its kind), besides the documents of the
#: three tests above (stepped, swept, benchmark): shrunk shipped scenes of the golden suite (``golden:<name>``, under
#: a second each), the small bifurcation study the other tests share, and :data:`CONCEPTS_DOCUMENT`.
KIND_CASES: dict[str, str] = {
    "golden:base_motion_frame": "stepped",  # two stops (coordinate ``stop``), base motion, a simulation engine
    "bifurcation": "bifurcation",
    "concepts": "concepts",
    # three of the five validation cases (the other two, bouncing ball and grazing, write the same kinds of
    # variables as these and cost 3 s each): continued orbits on ``point``, a table of checks, an impact sequence
    **{f"golden:validation_{case}": "validation" for case in ("budd_dux", "relative_stop", "zeno")},
    "golden:design_vs_linear": "design",  # every evaluation, samples, certificates with branches and attractors, compared designs
}


def write_case(case: str, request: pytest.FixtureRequest, folder: Path) -> Path:
    """The dataset of ``case`` (:data:`KIND_CASES`) as ``run-study`` writes it (and :func:`read_dataset` reads it back)."""
    if case == "bifurcation":
        dataset = request.getfixturevalue("small_bifurcation")  # run once per test run, read back from its file
        return read_back_as_written(dataset, write_dataset(dataset, folder / "bifurcation.nc"))
    if case == "concepts":
        return write(CONCEPTS_DOCUMENT, folder)
    name = case.removeprefix("golden:")
    dataset = run_study(load_scene(SCENES / f"{name}.yaml"), progress=None)
    return read_back_as_written(dataset, write_dataset(dataset, folder / f"{name}.nc"))


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


@pytest.mark.slow
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


@pytest.mark.slow
@pytest.mark.timeout(120)
@pytest.mark.parametrize("case", list(KIND_CASES))
def test_every_kind_is_cf_clean(case: str, request: pytest.FixtureRequest, tmp_path: Path) -> None:
    """Each kind's dataset: no CF error or warning, and no number stored as text."""
    path = write_case(case, request, tmp_path)
    with xr.open_dataset(path) as dataset:
        assert dataset.attrs["study_kind"] == KIND_CASES[case]
    assert cf_findings(path, tmp_path / "cf.json") == []
    assert numbers_as_text(path) == []


@pytest.mark.slow
@pytest.mark.timeout(120)
def test_the_command_line_checker_exits_0_on_every_golden_dataset_and_group(tmp_path: Path) -> None:
    """``compliance-checker --test=cf:1.8`` as a pipeline runs it, on every blessed golden dataset (every shipped
    study, shrunk) and each of their groups (flattened): exit status 0, and no check that raised (which it reports on
    stderr, after the line naming the files)."""
    files = sorted(DATA.glob("*.nc"))
    for path in list(files):
        with netCDF4.Dataset(path) as source:
            groups = list(source.groups)
        files += [flattened(path, group, tmp_path / f"{path.stem}_{group}.nc") for group in groups]
    assert len(files) > len(list(DATA.glob("*.nc")))  # some groups among them
    checker = Path(sys.executable).with_name("compliance-checker")
    done = subprocess.run([str(checker), "--test=cf:1.8", *map(str, files)], capture_output=True, text=True, timeout=110)
    raised = [line for line in done.stderr.splitlines() if EXCEPTION_LINE.match(line) or "exceptions occurred" in line]
    assert (done.returncode, raised) == (0, [])
    assert done.stdout.count("All tests passed!") == len(files)


def test_the_check_finds_a_check_that_raised(tmp_path: Path) -> None:
    """The check is not blind to what the scores do not show: a string coordinate variable (labels along a dimension)
    makes the checker's monotonicity check raise, which it reports apart, exiting 2 after "All tests passed!"."""
    dataset = xr.Dataset({"x": ("solution", [1.0, 2.0], {"units": "m", "long_name": "x"})}, coords={"solution": ("solution", ["exact", "pgf"], {"long_name": "solution method"})}, attrs={"Conventions": "CF-1.8", "title": "t", "history": "written"})
    dataset.to_netcdf(tmp_path / "labels.nc")
    findings = checked(tmp_path / "labels.nc", tmp_path / "cf.json")
    assert findings[-1] == "exit status 2"
    assert any(finding.startswith("raised: cf:1.8.check_coordinate_variables_strict_monotonicity") for finding in findings)


def test_the_cases_cover_every_kind() -> None:
    """A new kind of study needs its case here: the three documents above and :data:`KIND_CASES`."""
    assert {"stepped", "swept", "benchmark", *KIND_CASES.values()} == set(KIND_NAMES)


@pytest.mark.timeout(120)
def test_numeric_attributes_are_numbers_when_read_back(tmp_path: Path) -> None:
    """The three-storey frame's natural frequencies, mass and stiffness matrices and stop clearances are arrays of
    numbers in the file, and agree with each other: the frequencies are the eigenvalues of M^-1 K read back."""
    path = write_dataset(run_study(load_scene(SCENES / "base_motion_frame.yaml"), progress=None), tmp_path / "frame.nc")
    with xr.open_dataset(path) as dataset:
        attrs = dict(dataset.attrs)
    natural, mass, stiffness = (attrs[key] for key in ("natural_frequencies_Hz", "system_mass_kg", "system_stiffness_N_per_m"))
    for value in (natural, mass, stiffness, attrs["stop_clearance_m"], attrs["simulation_frequency_Hz"]):
        assert isinstance(value, np.ndarray) and value.dtype.kind == "f"
    size = int(attrs["system_size"])
    assert isinstance(attrs["system_size"], np.integer) and size == 3 and natural.shape == (size,)
    eigenvalues = np.linalg.eigvals(np.linalg.solve(mass.reshape(size, size), stiffness.reshape(size, size))).real
    np.testing.assert_allclose(natural, np.sqrt(np.sort(eigenvalues)) / (2.0 * np.pi), rtol=1e-12)
    np.testing.assert_allclose(attrs["stop_clearance_m"], [0.002, 0.002], rtol=1e-15)
    assert isinstance(attrs["admissibility_samples_per_period"], np.integer) and int(attrs["admissibility_samples_per_period"]) == 512


def test_attributes_that_netcdf_would_turn_into_text_are_refused() -> None:
    """Sequences become arrays of one type, booleans int8; a mix of numbers and text, or an array of arrays (which
    the netCDF4 library writes as the text of each entry: '[23.02212513 36.07439742]') is an error."""
    as_array = netcdf_attribute([23.0, 36.5], "test")
    assert isinstance(as_array, np.ndarray) and as_array.dtype.kind == "f" and as_array.shape == (2,)
    flag = netcdf_attribute(True, "test")
    assert isinstance(flag, np.int8) and int(flag) == 1
    assert netcdf_attribute("x1 x2", "test") == "x1 x2"
    with pytest.raises(ValueError, match="mixes"):
        netcdf_attribute([np.array([23.0, 36.5]), "Hz"], "test")
    with pytest.raises(ValueError, match="2-d"):
        netcdf_attribute(np.ones((2, 2)), "test")


def test_the_text_check_finds_a_number_written_as_text(tmp_path: Path) -> None:
    """numbers_as_text is not blind: numpy's text of an array and a number as text are found, units "1" is not."""
    dataset = xr.Dataset({"x": ("f", [1.0], {"units": "1", "scale": "2.5"})}, attrs={"natural_frequencies_Hz": "[23.02212513 36.07439742]", "title": "t 1"})
    dataset.to_netcdf(tmp_path / "text.nc")
    assert numbers_as_text(tmp_path / "text.nc") == ["dataset.natural_frequencies_Hz = '[23.02212513 36.07439742]'", "x.scale = '2.5'"]


def test_the_check_finds_what_it_should(tmp_path: Path) -> None:
    """The check is not blind: a coordinate with a _FillValue and a file without history are reported, and so are a
    group's coordinate with a _FillValue and its variable's units unknown to UDUNITS."""
    import xarray as xr

    dataset = xr.Dataset({"x": ("frequency", [1.0, 2.0], {"units": "m", "long_name": "x"})}, coords={"frequency": ("frequency", [1.0, 2.0], {"units": "Hz", "long_name": "f"})}, attrs={"Conventions": "CF-1.8", "title": "t"})
    path = tmp_path / "bad.nc"
    dataset.to_netcdf(path)  # xarray's default: _FillValue on every float variable, no history
    findings = " ".join(cf_findings(path, tmp_path / "cf.json"))
    assert "_FillValue" in findings and "history" in findings
    dataset.attrs["history"] = "written"
    dataset.to_netcdf(path, encoding={"frequency": {"_FillValue": None}})
    assert cf_findings(path, tmp_path / "cf.json") == []
    group = xr.Dataset({"y": ("frequency", [1.0], {"units": "dB", "long_name": "y"})}, coords={"frequency": ("frequency", [1.5], {"units": "Hz", "long_name": "f"})})
    group.to_netcdf(path, mode="a", group="simulated")  # a group's variables: the checker alone does not see them
    findings = cf_findings(path, tmp_path / "cf.json")
    assert all(finding.startswith("group simulated: ") for finding in findings)
    assert "_FillValue" in " ".join(findings) and "dB" in " ".join(findings)
