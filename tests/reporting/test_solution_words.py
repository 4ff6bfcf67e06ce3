"""A solution's words have two homes: its row of SOLUTION_LOOKS and, for an engine, the registry's description.

The pages' captions and the datasets' ``method_<name>`` attributes read them from there; no other module spells them.
"""

from __future__ import annotations

from pathlib import Path


from vibroimpact.engines.registry import ENGINES
from vibroimpact.kinds.stepped.study import SteppedStudy
from vibroimpact.reporting.solutions import GENERAL_SOLUTION_DESCRIPTIONS, SOLUTION_DESCRIPTIONS, SOLUTION_LOOKS, closed_form_methods, solution_method
from vibroimpact.scene import load_scene

PACKAGE = Path(__file__).resolve().parents[2] / "src" / "vibroimpact"
SCENE = Path(__file__).resolve().parents[1] / "golden" / "scenes" / "clearance_peaks.yaml"


def test_each_description_is_spelled_in_one_module() -> None:
    """Each look's words are in reporting/solutions.py alone, each engine's description in engines/registry.py alone (the solve_ivp ones are formatted there, not
    spelled)."""
    sources = {path: path.read_text(encoding="utf-8") for path in PACKAGE.rglob("*.py")}
    home = {text: PACKAGE / "reporting" / "solutions.py" for look in SOLUTION_LOOKS.values() for text in (look.description, look.general, look.method) if text}
    home |= {spec.description: PACKAGE / "engines" / "registry.py" for name, spec in ENGINES.items() if not name.startswith("solve_ivp")}
    assert len(home) > 20
    for text, expected in home.items():
        found = [path for path, source in sources.items() if f'"{text}"' in source]
        assert found == [expected], (text, found)


def test_datasets_record_the_methods_from_the_looks_and_the_registry() -> None:
    """A stepped scene with simulations: every ``method_<solution>`` attribute is :func:`solution_method`; the pgf's
    is its look's, compliant_exact's (no method in its look) the registry's description."""
    scene = load_scene(SCENE)
    attrs = SteppedStudy.simulation_attributes(scene) | closed_form_methods()
    methods = {key.removeprefix("method_"): value for key, value in attrs.items() if key.startswith("method_") and key != "method_force"}
    assert {"pgf", "exact", "momentary", "compliant", "compliant_exact"} <= set(methods)
    assert all(value == solution_method(name) for name, value in methods.items())
    assert methods["pgf"] == SOLUTION_LOOKS["pgf"].method
    assert methods["compliant_exact"] == ENGINES["compliant_exact"].description
    assert not SOLUTION_LOOKS["compliant_exact"].method


def test_general_captions_fall_back_to_the_papers_words() -> None:
    """On a general layout a caption says the look's ``general`` words where it has them, else its description."""
    assert GENERAL_SOLUTION_DESCRIPTIONS["pgf_paper"] == SOLUTION_DESCRIPTIONS["pgf_paper"]
    assert GENERAL_SOLUTION_DESCRIPTIONS["exact"] == SOLUTION_LOOKS["exact"].general != SOLUTION_DESCRIPTIONS["exact"]
    assert set(GENERAL_SOLUTION_DESCRIPTIONS) == set(SOLUTION_LOOKS)
