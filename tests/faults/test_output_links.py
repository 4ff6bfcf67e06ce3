"""An ``--out`` that is a dangling symbolic link, or a loop of them, is refused before any work with its reason
(issue 34, item 8: both were called "File exists")."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.test_cli_runner import _scene_file
from vibroimpact import cli


@pytest.mark.faults
@pytest.mark.parametrize("where", ["out", "out/sub"])
def test_a_dangling_link_as_out_is_named(tmp_path: Path, where: str, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "out").symlink_to(tmp_path / "gone" / "target")
    assert cli.main([str(_scene_file(tmp_path)), "--out", str(tmp_path / where), "--jobs", "1"]) == cli.EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert f"{tmp_path / 'out'} is a symbolic link to {tmp_path / 'gone' / 'target'}, which does not exist" in err, err
    assert "File exists" not in err and not (tmp_path / "gone").exists()


@pytest.mark.faults
def test_a_loop_of_links_as_out_is_named(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "one").symlink_to(tmp_path / "two")
    (tmp_path / "two").symlink_to(tmp_path / "one")
    assert cli.main([str(_scene_file(tmp_path)), "--out", str(tmp_path / "one"), "--jobs", "1"]) == cli.EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "is a symbolic link in a loop of symbolic links" in err and "File exists" not in err, err
