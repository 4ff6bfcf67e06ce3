"""One answer by every route (issue 51): the README's Python recipe (a guarded script, two worker processes), the same
script unguarded (how a notebook user writes it; it hung before), ``run-study`` on the command line, and a scene made
in Python as a mapping (``parse_scene``: no file text) give the same answer sentence, on their pages and as values
(``design_answer``), for the golden suite's shrunk ``design_rigid_stop``."""

from __future__ import annotations

import html
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
import yaml

from vibroimpact import design_answer, parse_scene, run_study, write_report

pytestmark = pytest.mark.slow  # four design runs of ~10-60 s each

ROOT = Path(__file__).resolve().parents[3]
SCENE = ROOT / "tests" / "golden" / "scenes" / "design_rigid_stop.yaml"
#: Longest one route may take here, however loaded the machine [s].
ROUTE_TIMEOUT = 900


def _recipe() -> str:
    """The README's Python recipe, on the shrunk scene."""
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    block = re.search(r"From Python, the same run and page.*?```python\n(.*?)```", readme, flags=re.S)
    assert block is not None, "the README's Python recipe is gone"
    code = block.group(1)
    assert 'load_scene("design_rigid_stop")' in code
    return code.replace('load_scene("design_rigid_stop")', f"load_scene({str(SCENE)!r})")


def _page_answer(page: Path) -> str:
    """The answer sentence of a design page (its first bold paragraph)."""
    found = re.search(r"<p><b>(.*?)</b></p>", page.read_text(encoding="utf-8"), flags=re.S)
    assert found is not None, page
    return html.unescape(found.group(1))


def _script(tmp_path: Path, name: str, code: str) -> str:
    script = tmp_path / name
    script.write_text(code)
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=ROUTE_TIMEOUT, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_the_readme_recipe_the_unguarded_script_the_command_line_and_a_mapping_give_one_answer(tmp_path: Path) -> None:
    recipe = _recipe()
    printed = _script(tmp_path, "recipe.py", recipe)
    recipe_page = _page_answer(tmp_path / "results" / "design_rigid_stop" / "report.html")
    assert printed.startswith(recipe_page + " {'clearance': "), printed  # print(answer.headline, answer.recommended.variables)

    body = textwrap.dedent(recipe.split('if __name__ == "__main__":', 1)[1].split("\n", 1)[1])
    unguarded = recipe.split("if __name__", 1)[0] + body.replace("results/", "unguarded/")
    assert "if __name__" not in unguarded
    assert _script(tmp_path, "unguarded.py", unguarded) == printed  # no hang, the same values to the last digit

    cli = subprocess.run([sys.executable, "-m", "vibroimpact.cli", str(SCENE), "--out", str(tmp_path / "cli"), "--jobs", "1"], capture_output=True, text=True,
                         timeout=ROUTE_TIMEOUT, cwd=tmp_path)  # fmt: skip
    assert cli.returncode == 0, cli.stderr
    assert _page_answer(tmp_path / "cli" / "report.html") == recipe_page

    mapping = parse_scene(yaml.safe_load(SCENE.read_text()))  # a scene made in Python: no file text
    dataset = run_study(mapping, progress=None)
    write_report(dataset, tmp_path / "mapping")
    assert _page_answer(tmp_path / "mapping" / "report.html") == recipe_page == design_answer(dataset).headline
