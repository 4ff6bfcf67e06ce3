"""Ranges that mean something (issue 22, item 4): parameters whose ratios double precision cannot hold are refused by
the scene checker before any work (exit 2, naming the parameters and the allowed ratio); what is accepted is right."""

from __future__ import annotations

import copy
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from vibroimpact import cli
from vibroimpact.analysis.linear import linear_amplitudes
from vibroimpact.grids.closed_forms import first_problem
from vibroimpact.model.structure import LinearStructure
from vibroimpact.model.system import TwoDofSystem
from vibroimpact.scene import SceneError, parse_scene

from tests.scene.test_scene import base_scene, write_yaml


def _refusal(tmp_path: Path, capsys: pytest.CaptureFixture[str], change: Callable[[dict[str, Any]], Any]) -> str:
    """The one-line problem of a scene changed by ``change``: exit 2, nothing written."""
    document = copy.deepcopy(base_scene())
    change(document)
    out = tmp_path / "out"
    assert cli.main([str(write_yaml(tmp_path / "absurd.yaml", document)), "--out", str(out), "--jobs", "1", "--no-report"]) == 2
    assert not out.exists()
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return err


@pytest.mark.parametrize(
    ("key", "expected"),
    [
        ("m1", "system: m2 / m1 = 1e-301 is out of range: allowed [1e-12, 1e12]"),
        ("m2", "system: m2 / m1 = 1e+300 is out of range: allowed [1e-12, 1e12]"),
        ("k1", "system: k2 / k1 = 4.3e-297 is out of range: allowed [1e-9, 1e9]"),
        ("k2", "system: k2 / k1 = 4e+295 is out of range: allowed [1e-9, 1e9]"),
        ("b1", "system: b1^2 / (k1 m1) = inf is out of range: allowed <= 1e12"),
        ("b2", "system: b2^2 / (k2 m2) = inf is out of range: allowed <= 1e12"),
    ],
)
def test_a_named_parameter_of_1e300_is_refused_naming_it_and_the_allowed_ratio(tmp_path: Path, capsys: pytest.CaptureFixture[str], key: str, expected: str) -> None:
    """Before: k2 or b2 = 1e300 gave an all-NaN (or 1e-302 m) linear response with exit 0, m2 = 1e300 x1 = 0 where it
    is 7.4e-4 m, m1 = 1e300 a LinAlgError (or a message about the mass matrix) and an empty store."""
    assert expected in _refusal(tmp_path, capsys, lambda d: d["system"].update({key: 1e300}))


MATRICES = {"mass": [[1.0, 0.0], [0.0, 0.1]], "stiffness": [[29300.0, -4300.0], [-4300.0, 4300.0]], "damping": [[0.88, -0.08], [-0.08, 0.08]]}


@pytest.mark.parametrize(
    ("key", "value", "expected"),
    [
        ("mass", [[1.0, 0.0], [0.0, 1e300]], "system.mass: largest / smallest eigenvalue (the masses' ratio) = 1e+300 is out of range: allowed [1, 1e12]"),
        ("damping", [[1e300, -1e300], [-1e300, 1e300]], "system.damping: c^2 / (k m) of the largest eigenvalues of C, K and M = inf is out of range: allowed <= 1e12"),
        ("stiffness", [[25000.0 + 1e-7, -1e-7], [-1e-7, 1e-7]], "system.stiffness: largest / smallest nonzero eigenvalue = 2.5e+11 is out of range: allowed [1, 1e10]"),
    ],
)
def test_matrices_beyond_double_precision_are_refused_naming_the_matrix(tmp_path: Path, capsys: pytest.CaptureFixture[str], key: str, value: list, expected: str) -> None:
    def change(document: dict[str, Any]) -> None:
        document["system"] = {**MATRICES, key: value}
        document["stops"] = [{"coordinate": "x2", "side": "upper", **document.pop("stop")}]

    assert expected in _refusal(tmp_path, capsys, change)


def test_the_shipped_systems_are_far_inside_the_ratios() -> None:
    """The paper's system: m2 / m1 = 0.1, k2 / k1 = 0.17, b2^2 / (k2 m2) = 1.5e-5: 11, 8 and 17 decades from the limits."""
    TwoDofSystem(1.0, 0.1, 25000.0, 4300.0, 0.8, 0.08).check_ratios()
    LinearStructure(MATRICES["mass"], MATRICES["stiffness"], MATRICES["damping"]).check_dynamic_range()


def test_the_python_api_leaves_extreme_ratios_to_its_caller() -> None:
    """Only scenes are refused: a test may model a free absorber by k2 = 1e-12 k1 (tests/engines/test_compliant.py)."""
    free = TwoDofSystem(m1=1.0, m2=0.1, k1=1.0, k2=1e-12)
    with pytest.raises(ValueError, match=r"system: k2 / k1 = 1e-12 is out of range: allowed \[1e-9, 1e9\]"):
        free.check_ratios()
    with pytest.raises(ValueError, match=r"system.stiffness: largest / smallest nonzero eigenvalue = 1e\+12 is out of range"):
        free.structure.check_dynamic_range()


def test_an_accepted_absorber_locked_by_its_dashpot_gives_the_locked_answer() -> None:
    """b2^2 / (k2 m2) = 1e10, inside the range: the dashpot locks the absorber to the primary mass, so x1 is that of
    one mass m1 + m2 on k1, b1: |X1| = q / |k1 - w^2 (m1 + m2) + j w b1| to ~1e-5 (the absorber's slip is
    ~ m2 w / b2 ~ 1e-5 of the motion). b2 = 1e300 is refused (above)."""
    document = copy.deepcopy(base_scene())
    document["system"]["b2"] = 1e5 * math.sqrt(4300.0 * 0.1)
    frequency = np.array([20.0, 25.0, 30.0])
    x1 = np.abs(linear_amplitudes(first_problem(parse_scene(document)), frequency).amplitudes[:, 0])
    w = 2.0 * np.pi * frequency
    locked = 10.0 / np.abs(25000.0 - w**2 * 1.1 + 1j * w * 0.8)
    np.testing.assert_allclose(x1, locked, rtol=1e-4)


GOLDEN_SCENES = Path(__file__).resolve().parents[1] / "golden" / "scenes"


def test_a_concept_absorber_and_a_validation_case_beyond_the_ratios_are_scene_problems() -> None:
    """The other places a named system is written: a concept's absorber and the relative-stop validation case."""
    concepts = yaml.safe_load((GOLDEN_SCENES / "absorber_concepts.yaml").read_text())
    concepts["concepts"][1]["absorber"] = {"stiffness": 1e300}
    with pytest.raises(SceneError) as caught:
        parse_scene(concepts)
    assert caught.value.problems == ["concepts[1].absorber: k2 / k1 = 4e+295 is out of range: allowed [1e-9, 1e9]: one spring is lost to round-off next to the other"]
    validation = yaml.safe_load((GOLDEN_SCENES / "validation_relative_stop.yaml").read_text())
    validation["validation"]["m2"] = 1e300
    with pytest.raises(SceneError) as caught:
        parse_scene(validation)
    assert caught.value.problems == ["validation: m2 / m1 = 1e+300 is out of range: allowed [1e-12, 1e12]: one mass is lost to round-off next to the other"]
