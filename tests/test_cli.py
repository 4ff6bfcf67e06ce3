"""``run-study`` as a user meets it: the shipped studies, bad output folders, YAML errors, Ctrl-C, an installed copy."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

from vibroimpact import cli
from vibroimpact.runs import run as study
from vibroimpact.scene import load_scene, shipped_studies, shipped_studies_dir

from tests.run_study_process import start_run_study, stored_blocks
from tests.scene.test_scene import base_scene, write_yaml

REPOSITORY = Path(__file__).resolve().parents[1]


def test_list_shows_every_shipped_study_with_its_description(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["--list"]) == 0
    printed = capsys.readouterr().out.splitlines()
    root = shipped_studies_dir()
    names = sorted(path.relative_to(root).with_suffix("").as_posix() for path in root.rglob("*.yaml"))
    assert "restitution" in names and len(printed) == len(names)
    column = max(len(name) for name in names) + 2
    for line, name, (listed, description) in zip(printed, names, shipped_studies()):
        assert line.split()[0] == name == listed and description
        assert len(line) <= 120 and line[column - 2 : column] == "  " and line[column] != " "  # one aligned line each
        shown = line[column:].removesuffix("...")
        assert description.startswith(shown), (shown, description)  # the description's beginning, cut where it must be


def test_the_listing_shows_a_first_clause_not_an_abbreviation() -> None:
    studies = [("a", "Validation against Holmes (J. Sound Vib. 84, 1982): a ball bouncing. More."), ("long_name", "Short one. Two."), ("b", "After Den Hartog, cf. Ormondroyd: the stop")]
    assert cli.study_listing(studies, 200).splitlines() == [
        "a          Validation against Holmes (J. Sound Vib. 84, 1982)",  # inside parentheses: no clause ends
        "long_name  Short one",
        "b          After Den Hartog, cf. Ormondroyd",  # outside them, a short word's point is an abbreviation
    ]


def test_a_scene_is_required_without_list(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main([]) == 2
    assert "a scene is required" in capsys.readouterr().err


def test_unwritable_out_is_refused_before_any_work(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    """--out under a regular file cannot be created: exit 2 naming the path, and nothing is computed."""
    blocker = tmp_path / "a_file"
    blocker.write_text("not a folder")
    out = blocker / "results"

    def never(*args: object, **kwargs: object) -> None:
        raise AssertionError("work started although --out cannot be written")

    monkeypatch.setattr(study, "run_study", never)  # the CLI imports it when a run starts
    assert cli.main([str(write_yaml(tmp_path / "tiny.yaml", base_scene())), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert f"--out {out} cannot be written" in err and "Traceback" not in err


def test_yaml_syntax_error_names_the_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "broken.yaml"
    path.write_text("name: broken\nsystem: {m1: 1.0\n  k1: [\n", encoding="utf-8")
    assert cli.main([str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert f'in "{path}", line 2' in err and "<unicode string>" not in err
    assert not (tmp_path / "out").exists()


def test_each_searched_place_is_listed_once(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    """In a checkout, ./studies is the shipped folder: it is named once, not twice."""
    monkeypatch.chdir(shipped_studies_dir().parent)
    assert cli.main(["no_such_scene.yaml"]) == 2
    places = capsys.readouterr().err.split("looked at: ")[1].strip().split(", ")
    assert len(places) == len({str(Path(place).resolve()) for place in places}) == 2


def test_a_local_file_wins_over_the_shipped_scene(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from vibroimpact.scene import find_scene

    monkeypatch.chdir(tmp_path)
    local = write_yaml(tmp_path / "restitution.yaml", base_scene())
    assert find_scene("restitution.yaml").resolve() == local.resolve()
    assert find_scene("restitution").resolve() == local.resolve()


def _slow_scene(folder: Path) -> Path:
    """Enough grid blocks (momentary, 32 simulated points each) that an interrupt lands between two of them."""
    document = base_scene()
    document.update(
        name="interrupted",
        stop={"clearance": 0.003, "restitution": 0.2},
        sweep={"frequency": {"start": 33.0, "stop": 40.0, "step": 0.1}},
        solutions=["linear", "momentary"],
        simulation={"start": "pgf"},
        report=False,
    )
    return write_yaml(folder / "interrupted.yaml", document)


@pytest.mark.faults  # whole run-study processes with dask workers: ~12 s, run with the other interrupts (-m faults)
@pytest.mark.timeout(480)
def test_ctrl_c_leaves_one_line_and_a_resumable_store(tmp_path: Path) -> None:
    """Ctrl-C (SIGINT to the whole process group, dask workers included): exit 130, one line saying what was kept,
    no traceback; the same command then starts from the kept blocks."""
    scene = _slow_scene(tmp_path)
    store = tmp_path / "out" / "interrupted.zarr"
    arguments = [str(scene), "--out", "out", "--jobs", "2"]
    run = start_run_study(arguments, tmp_path)
    deadline = time.monotonic() + 180.0
    while stored_blocks(store) == 0 and run.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    assert run.poll() is None, "the study ended before it could be interrupted"
    os.killpg(run.pid, signal.SIGINT)
    _out, err = run.communicate(timeout=120)  # hang guards: ending takes a second on a quiet machine
    kept = stored_blocks(store)
    assert run.returncode == 130, err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
    assert err.rstrip().splitlines()[-1] == f"interrupted: {kept} finished block{'s' if kept != 1 else ''} kept in out/interrupted.zarr; run the same command to resume", err
    assert 1 <= kept < 3  # 71 simulated points in blocks of 32: 3 blocks
    assert not (tmp_path / "out" / ".run-study.lock").exists()
    # the rerun begins with the kept cases done
    rerun = start_run_study(arguments, tmp_path)
    assert rerun.stderr is not None
    first_progress = next(line for line in rerun.stderr if line.startswith("simulating"))
    os.killpg(rerun.pid, signal.SIGINT)
    rerun.communicate(timeout=120)
    done = int(first_progress.split("] ")[1].split("/")[0])
    assert done >= 7 * kept, first_progress  # blocks of 32, 32 and 7 points


@pytest.mark.slow
@pytest.mark.timeout(600)
def test_installed_package_finds_its_studies(tmp_path: Path) -> None:
    """A non-editable install (wheel) run from an empty folder lists and finds the shipped scenes."""
    wheels, site, empty = tmp_path / "wheels", tmp_path / "site", tmp_path / "empty"
    empty.mkdir()
    pip = [sys.executable, "-m", "pip", "--disable-pip-version-check", "--no-cache-dir"]
    subprocess.run([*pip, "wheel", "--no-deps", "-w", str(wheels), str(REPOSITORY)], check=True, capture_output=True)
    wheel = next(wheels.glob("vibroimpact-*.whl"))
    subprocess.run([*pip, "install", "--no-deps", "--target", str(site), str(wheel)], check=True, capture_output=True)
    environment = os.environ | {"PYTHONPATH": str(site)}

    def run(*arguments: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run([sys.executable, "-m", "vibroimpact.cli", *arguments], cwd=empty, env=environment, capture_output=True, text=True, timeout=300)

    where = subprocess.run([sys.executable, "-c", "import vibroimpact; print(vibroimpact.__file__)"], cwd=empty, env=environment, capture_output=True, text=True, check=True)
    assert where.stdout.startswith(str(site)), where.stdout
    listed = run("--list")
    assert listed.returncode == 0 and "restitution" in listed.stdout and "bumper_sweep" in listed.stdout
    estimated = run("restitution.yaml", "--estimate")
    assert estimated.returncode == 0, estimated.stderr
    assert "validation/zeno" in listed.stdout  # a shipped scene in a subfolder is listed and found with its folder
    assert run("validation/zeno.yaml", "--estimate").returncode == 0
    assert yaml.safe_load((site / "vibroimpact" / "studies" / "restitution.yaml").read_text())["name"] == "restitution"
    assert list(empty.iterdir()) == []  # --list and --estimate write nothing


def test_a_code_change_invalidates_the_resume_cache(monkeypatch: pytest.MonkeyPatch) -> None:
    """The cache key hashes the package's source: other code, other key (the version number alone would not do)."""
    from vibroimpact.runs import fingerprints as fingerprint
    from vibroimpact.engines.settings import EngineSettings
    from vibroimpact.model.contact import RigidStop
    from vibroimpact.kinds.stepped.cases import SimulationCase
    from vibroimpact.simulation.settings import SteadySettings
    from vibroimpact.model.system import PAPER_SYSTEM

    case = SimulationCase("exact", PAPER_SYSTEM, 10.0, RigidStop(0.003, 0.2), (25.0,), "pgf", EngineSettings(), SteadySettings())
    before = case.key()
    assert case.key() == before and len(fingerprint.source_hash()) == 64
    monkeypatch.setattr(fingerprint, "source_hash", lambda: "0" * 64)
    assert case.key() != before


def test_datasets_record_the_source_they_came_from(tmp_path: Path) -> None:
    from vibroimpact.runs.store import source_hash
    from vibroimpact.scene import load_scene

    document = base_scene()
    document.update(solutions=["linear"], sweep={"frequency": [20.0, 21.0]})
    dataset = study.run_study(load_scene(write_yaml(tmp_path / "tiny.yaml", document)), progress=None)
    assert dataset.attrs["vibroimpact_source_sha256"] == source_hash()


# ----------------------------------------------------------------------------- subcommands: calibrate, sweep-cost

#: Wall time per simulated period of the tiny accuracy dataset's momentary_adams runs [s] (far from the shipped costs).
TINY_PER_PERIOD = 2.0


def tiny_accuracy_dataset(path: Path) -> Path:
    """An accuracy_cost-shaped dataset: a stepped one-impact case (2 s at 25 Hz: 50 periods) and a swept case (10 s)."""
    import numpy as np
    import xarray as xr

    cases, engines, tolerances = ["one_impact_25Hz", "swept_compliant"], ["momentary_adams", "compliant_ida"], [1e-6, 1e-8]
    wall = np.empty((2, 2, 2))
    wall[0] = [[50 * TINY_PER_PERIOD, 50 * TINY_PER_PERIOD], [10.0, 20.0]]  # stepped: 50 periods
    wall[1] = [[np.nan, np.nan], [5.0, 9.0]]  # swept: the compliant engine only
    dataset = xr.Dataset(
        {"wall_time": (("case", "engine", "rtol"), wall), "reference_wall_time": (("case", "reference"), [[0.5, 1.0], [np.nan, 30.0]])},
        coords={"case": cases, "engine": engines, "rtol": tolerances, "reference": ["exact", "compliant_cvode_adams"]},
        attrs={"case_one_impact_25Hz_duration_s": 2.0, "case_one_impact_25Hz_frequency_Hz": 25.0, "case_swept_compliant_duration_s": 10.0},
    )
    dataset.to_netcdf(path)
    return path


def test_help_lists_the_subcommands(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_info:
        cli.main(["--help"])
    assert exit_info.value.code == 0
    text = capsys.readouterr().out
    assert "run-study calibrate ACCURACY.nc [--out FILE]" in text and "run-study sweep-cost [options]" in text


def test_calibrate_writes_a_cost_file_that_estimate_reads(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """calibrate -> the cost file (measured tables replaced, the rest kept, unmeasured engines scaled by the speed
    probes) -> ``--estimate --costs`` predicts from it."""
    from vibroimpact.runs.estimate import Costs, default_costs
    from vibroimpact.runs.estimate import estimate_scene

    out = tmp_path / "costs" / "costs.json"
    assert cli.main(["calibrate", str(tiny_accuracy_dataset(tmp_path / "accuracy.nc")), "--out", str(out)]) == 0
    assert str(out) in capsys.readouterr().err
    costs = Costs.load(out)
    assert costs.per_period_cost("momentary_adams", 1e-7) == pytest.approx(TINY_PER_PERIOD)
    assert costs.per_period_cost("exact", 1e-7) == pytest.approx(0.5 / 50)
    assert costs.per_sweep_second_cost("compliant_ida", 1e-6) == pytest.approx(0.5) and costs.per_sweep_second_cost("compliant_ida", 1e-8) == pytest.approx(0.9)
    shipped = default_costs()
    # an engine the dataset does not time keeps the shipped cost, carried over by the two machines' speed probes
    ratio = costs.speed_probe_seconds / shipped.speed_probe_seconds
    assert costs.per_period_cost("compliant_cvode_adams", 1e-7) == pytest.approx(shipped.per_period_cost("compliant_cvode_adams", 1e-7) * ratio)
    assert costs.per_period_cost("compliant_exact", 1e-7) == pytest.approx(shipped.per_period_cost("compliant_exact", 1e-7) * ratio)
    assert costs.closed_form_per_point == shipped.closed_form_per_point and costs.startup == shipped.startup
    assert costs.speed_probe_seconds > 0.0 and costs.to_json() == out.read_text()
    # the estimate reads it: every predicted period of momentary costs TINY_PER_PERIOD seconds
    document = base_scene()
    document.update(solutions=["linear", "momentary"], sweep={"frequency": [24.0, 25.0]}, simulation={"rtol": 1e-7, "start": "rest", "max_periods": 100}, report=False)
    scene_path = write_yaml(tmp_path / "tiny.yaml", document)
    scene = load_scene(scene_path)
    assert scene.settings.simulation is not None
    ours = estimate_scene(scene, speed=1.0, costs=costs).parts["momentary"]
    steady = scene.settings.simulation.steady
    # from rest: every point, the whole budget: marching, the Lyapunov run and its perturbed copy, the measurement
    periods = (steady.max_periods + 2 * steady.lyapunov_periods + steady.irregular_measure_periods) * 2
    assert ours == pytest.approx(TINY_PER_PERIOD * periods)
    assert estimate_scene(scene, speed=1.0).parts["momentary"] < ours / 100  # the shipped costs predict far less
    assert cli.main([str(scene_path), "--estimate", "--costs", str(out)]) == 0
    assert "momentary: " in capsys.readouterr().out


def test_calibrate_writes_the_package_file_by_default_or_says_why_not(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    from vibroimpact.runs import estimate

    package_file = tmp_path / "package" / "costs.json"
    package_file.parent.mkdir()
    package_file.write_text(estimate.COSTS_FILE.read_text())  # a copy of the package's (calibrate starts from its costs)
    monkeypatch.setattr(estimate, "COSTS_FILE", package_file)
    estimate.default_costs.cache_clear()  # read from the copy (the same costs), whichever test read the package's first
    accuracy = tiny_accuracy_dataset(tmp_path / "accuracy.nc")
    assert cli.main(["calibrate", str(accuracy)]) == 0
    assert "momentary_adams" in package_file.read_text()
    written = package_file.read_text()
    monkeypatch.setattr(estimate.os, "access", lambda *_args: False)  # an installed, read-only package
    assert cli.main(["calibrate", str(accuracy)]) == 2
    error = capsys.readouterr().err
    assert "not writable" in error and "--out FILE" in error
    assert package_file.read_text() == written


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (["calibrate", "missing.nc"], "No such file"),
        (["calibrate", "not_accuracy.nc"], "not an accuracy_cost dataset"),
        (["calibrate", "no_swept.nc"], "no swept case"),
        (["sweep-cost", "--methods", "Euler"], "not allowed"),
    ],
)
def test_subcommands_refuse_bad_input(arguments: list[str], message: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    import xarray as xr

    monkeypatch.chdir(tmp_path)
    xr.Dataset({"x": ("frequency", [1.0])}).to_netcdf(tmp_path / "not_accuracy.nc")
    with xr.open_dataset(tiny_accuracy_dataset(tmp_path / "accuracy.nc")) as accuracy:
        accuracy.sel(case=["one_impact_25Hz"]).to_netcdf(tmp_path / "no_swept.nc")
    assert cli.main(arguments) == 2
    assert message in capsys.readouterr().err


def test_estimate_refuses_a_bad_cost_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    document = base_scene()
    document.update(solutions=["linear"], sweep={"frequency": [20.0, 21.0]})
    scene = write_yaml(tmp_path / "tiny.yaml", document)
    (tmp_path / "bad.json").write_text('{"per_period": {"euler": 1.0}}')
    assert cli.main([str(scene), "--estimate", "--costs", str(tmp_path / "bad.json")]) == 2
    assert "--costs" in capsys.readouterr().err
    assert cli.main([str(scene), "--estimate", "--costs", str(tmp_path / "missing.json")]) == 2


def test_sweep_cost_options_make_its_settings() -> None:
    import argparse

    from vibroimpact.kinds.benchmark.sweep_cost import add_arguments, settings_from_arguments

    parser = argparse.ArgumentParser()
    add_arguments(parser)
    settings = settings_from_arguments(parser.parse_args(["--methods", "DOP853", "--down", "--no-reference", "--rtol", "1e-7", "--budget", "5"]))
    assert settings.methods == ("DOP853",) and settings.reference_rtol is None
    assert settings.sweep.start_frequency > settings.sweep.stop_frequency  # down: 45 -> 15 Hz
    assert settings.engine_settings.rtol == pytest.approx(1e-7) and settings.budget == pytest.approx(5.0)


#: What a study's run needs and the CLI's help, listing and scene refusals must not load (each costs 0.1-0.5 s of
#: import; together they made ``run-study --help`` take 1.1 s on the quiet machine, 13-21 s under load).
HEAVY_MODULES = ("xarray", "pandas", "zarr", "dask", "distributed", "matplotlib", "numba", "sksundae", "scipy.optimize", "scipy.integrate")


def _loaded_after(code: str) -> set[str]:
    """Which of :data:`HEAVY_MODULES` a fresh interpreter has loaded after running ``code``."""
    probe = code + f"\nimport sys\nprint(','.join(m for m in {HEAVY_MODULES!r} if m in sys.modules))\n"
    found = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True, timeout=120)
    return {name for name in found.stdout.strip().split(",") if name}


def test_help_the_listing_and_a_refused_scene_load_none_of_the_run_s_modules() -> None:
    """The CLI's parser and help, the shipped studies' listing and a refused scene need none of
    :data:`HEAVY_MODULES`: they answer in a fraction of a second (0.25-0.35 s on the quiet machine, was 1.1-1.2 s)."""
    code = (
        "from vibroimpact import cli\n"
        "from vibroimpact.scene import SceneError, parse_scene, shipped_studies\n"
        "cli.build_parser().format_help(); cli.study_listing(shipped_studies())\n"
        "try:\n"
        "    parse_scene({'name': 'x', 'system': {'m1': -1.0}})\n"
        "except SceneError:\n"
        "    pass\n"
    )
    assert _loaded_after(code) == set()


@pytest.mark.parametrize("scene", ["restitution", "design_paper", "bifurcation_bumper", "absorber_concepts"])
def test_reading_a_shipped_scene_loads_none_of_the_run_s_modules(scene: str) -> None:
    """Reading and checking a shipped scene loads nothing a run needs but scipy's solvers (the check converts a
    restitution into a bumper's loss factor by a root search)."""
    assert _loaded_after(f"from vibroimpact.scene import load_scene, shipped_studies_dir\nload_scene(shipped_studies_dir() / '{scene}.yaml')") <= {"scipy.optimize"}
