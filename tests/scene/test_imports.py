"""The scene layer knows no solver: reading every shipped scene loads no engine, solver library, xarray or plotting."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

#: Modules (and everything under them) that reading a scene must not load.
FORBIDDEN = (
    "sksundae",
    "scipy.integrate",
    "xarray",
    "matplotlib",
    "netCDF4",
    "vibroimpact.simulation.steady",
    "vibroimpact.simulation.harmonics",
    "vibroimpact.runs",
    "vibroimpact.reporting",
    "vibroimpact.grids",
)
#: What reading a scene may load of a kind's folder: its scene section (``vibroimpact.kinds.<kind>.scene``, ``.settings``).
KIND_SCENE_MODULES = ("scene", "settings")
#: What the scene may use of the engines package: the settings and the registry of names (no engine module).
ENGINE_MODULES_ALLOWED = ("vibroimpact.engines", "vibroimpact.engines.settings", "vibroimpact.engines.registry")

#: Run in a fresh interpreter: import the scene, parse every shipped scene, print the loaded modules.
_PROGRAM = """
import json, sys
import vibroimpact.scene as scene
for path in sorted(scene.shipped_studies_dir().rglob("*.yaml")):
    scene.load_scene(path)
print(json.dumps(sorted(sys.modules)))
"""


def loaded_modules(program: str) -> list[str]:
    """The names in ``sys.modules`` after ``program`` (which prints them as JSON) ran in a fresh interpreter."""
    done = subprocess.run([sys.executable, "-c", program], capture_output=True, text=True, check=True, timeout=120)
    return json.loads(done.stdout.splitlines()[-1])


def forbidden_among(modules: list[str]) -> list[str]:
    """The modules of ``modules`` that the scene layer must not load."""
    def under(name: str, package: str) -> bool:
        return name == package or name.startswith(package + ".")

    return [
        name
        for name in modules
        if any(under(name, package) for package in FORBIDDEN)
        or (under(name, "vibroimpact.engines") and name not in ENGINE_MODULES_ALLOWED)
        or (under(name, "vibroimpact.kinds") and name.count(".") == 3 and name.rsplit(".", 1)[1] not in KIND_SCENE_MODULES)
    ]


def test_reading_every_shipped_scene_loads_no_engine_solver_or_xarray() -> None:
    modules = loaded_modules(_PROGRAM)
    assert "vibroimpact.scene.reader" in modules  # the program did read scenes
    assert forbidden_among(modules) == []


def test_the_check_sees_an_engine_module() -> None:
    """The same check on a program that also imports an engine names it (and its solver library)."""
    modules = loaded_modules("import vibroimpact.engines.momentary\n" + _PROGRAM)
    found = forbidden_among(modules)
    assert "vibroimpact.engines.momentary" in found
    assert any(name.startswith("sksundae") for name in found)


def test_the_check_sees_a_kind_study_module() -> None:
    """A kind's study module (its run) is no part of reading a scene, and the check names it."""
    modules = loaded_modules("import vibroimpact.kinds.stepped.study\n" + _PROGRAM)
    assert "vibroimpact.kinds.stepped.study" in forbidden_among(modules)


def test_engine_names_come_from_the_registry() -> None:
    """Solutions integrated by an engine and benchmark methods are registered engines; the reference is no method."""
    from vibroimpact.engines.registry import engine_names
    from vibroimpact.scene import SceneError, load_scene, parse_scene, shipped_studies_dir
    from vibroimpact.scene.schema import ENGINE_SOLUTIONS

    assert set(ENGINE_SOLUTIONS) <= set(engine_names())
    shipped = load_scene(shipped_studies_dir() / "accuracy_cost.yaml").settings
    assert shipped is not None and set(shipped.settings.methods) <= set(engine_names())
    case = {"name": "a", "frequency": 25.0, "restitution": 0.2, "clearance": 0.003, "start": "pgf"}
    document = {"name": "b", "system": {"m1": 1.0, "m2": 0.1, "k1": 25000.0, "k2": 4300.0}, "excitation": {"amplitude": 10.0}, "benchmark": {"duration": 1.0, "methods": ["solve_ivp_BDF", "exact"], "tolerances": [1e-6], "cases": [case]}}
    with pytest.raises(SceneError) as caught:
        parse_scene(document)
    assert len(caught.value.problems) == 1 and caught.value.problems[0].startswith("benchmark.methods[1]: unknown name 'exact'")
