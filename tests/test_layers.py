"""The package's layers import downward only, and the lower layers know nothing of YAML, xarray or plotting.

Read from the source (every ``import`` statement, including those inside functions), so a new upward import fails
here however rarely it runs.
"""

from __future__ import annotations

import ast
import importlib
import re
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "vibroimpact"
#: Lowest first: a module may import from its own layer and those before it (README, "Architecture").
LAYERS = ("model", "analysis", "engines", "orbits", "simulation", "measures", "scene", "runs", "reporting", "grids", "kinds", "cli")
#: Third-party libraries a layer must not import (lower layers are physics and numerics only); the layers from ``runs``
#: up (``runs``, ``reporting``, ``grids``, ``kinds``, ``cli``) write datasets and draw, and may import any.
FORBIDDEN_LIBRARIES = {
    "model": ("yaml", "xarray", "matplotlib", "netCDF4", "sksundae"),
    "analysis": ("yaml", "xarray", "matplotlib", "netCDF4", "sksundae"),
    "engines": ("yaml", "xarray", "matplotlib", "netCDF4"),
    "orbits": ("yaml", "xarray", "matplotlib", "netCDF4", "sksundae"),
    "simulation": ("yaml", "xarray", "matplotlib", "netCDF4"),
    "measures": ("yaml", "xarray", "matplotlib", "netCDF4"),
    "scene": ("xarray", "matplotlib", "netCDF4", "sksundae", "scipy.integrate"),
}
#: A kind's scene section is read with the scene layer (reading a scene loads no solver): these kind modules are held
#: to the scene layer's rules, and may import each other.
SCENE_LEVEL_KIND_MODULES = ("scene", "settings")


def layer_of(module: str) -> str | None:
    """The layer of ``vibroimpact.<layer>...`` (``cli`` and the package itself are the top), None outside; a kind's
    scene section (``vibroimpact.kinds.<kind>.scene``, ``.settings``) is of the scene layer."""
    parts = module.split(".")
    if parts[0] != "vibroimpact" or module in ("vibroimpact", "vibroimpact.__version__"):
        return None  # outside, or the package's version: metadata every layer may read
    if len(parts) == 1:
        return "cli"  # the package's __init__: lazy public names, the top
    if parts[1] == "kinds" and len(parts) >= 4 and parts[3] in SCENE_LEVEL_KIND_MODULES:
        return "scene"
    return parts[1] if parts[1] in LAYERS else "cli"


def module_name(path: Path) -> str:
    relative = path.relative_to(PACKAGE.parent).with_suffix("")
    parts = list(relative.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def imports(path: Path) -> list[tuple[int, str]]:
    """(line, absolute module) of every import in ``path``, relative imports resolved."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                package = module_name(path).split(".")[: None if path.name == "__init__.py" else -1]
                base = package[: len(package) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            found.append((node.lineno, target))
            # ``from vibroimpact.x import y`` may name a module y: check it too
            found += [(node.lineno, f"{target}.{alias.name}") for alias in node.names]
    return found


SOURCES = sorted(PACKAGE.rglob("*.py"))


def test_every_subpackage_is_a_known_layer() -> None:
    subpackages = {p.parent.relative_to(PACKAGE).parts[0] for p in SOURCES if p.parent != PACKAGE}
    assert subpackages <= set(LAYERS) | {"studies"}, f"a subpackage that is no layer: {sorted(subpackages - set(LAYERS))}"


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_imports_go_downward_only(path: Path) -> None:
    own = layer_of(module_name(path)) or "cli"  # the package's own __init__ is the top
    upward = []
    for line, target in imports(path):
        layer = layer_of(target)
        if layer is not None and LAYERS.index(layer) > LAYERS.index(own):
            upward.append(f"line {line}: {target} ({layer} is above {own})")
    assert not upward, "upward imports:\n" + "\n".join(upward)


@pytest.mark.parametrize("path", [p for p in SOURCES if layer_of(module_name(p)) in FORBIDDEN_LIBRARIES], ids=lambda p: str(p.relative_to(PACKAGE)))
def test_lower_layers_import_no_io_or_plotting(path: Path) -> None:
    forbidden = FORBIDDEN_LIBRARIES[layer_of(module_name(path))]  # type: ignore[index]
    bad = [f"line {line}: {target}" for line, target in imports(path) if any(target == name or target.startswith(name + ".") for name in forbidden)]
    assert not bad, "forbidden imports:\n" + "\n".join(bad)


def test_the_checks_see_an_upward_import(tmp_path: Path) -> None:
    """The scan is not blind: an import of the study layer from a model module, even inside a function, is found."""
    module = tmp_path / "probe.py"
    module.write_text("def f():\n    from vibroimpact.runs.run import run_study\n    import xarray\n")
    found = [target for _line, target in imports(module)]
    assert "vibroimpact.runs.run" in found and "xarray" in found
    assert LAYERS.index(layer_of("vibroimpact.runs.run")) > LAYERS.index("model")  # type: ignore[arg-type]


def test_a_kind_scene_section_is_held_to_the_scene_layer() -> None:
    """The kinds' scene parsers named by the table are scene-level modules (no solver, no xarray), so the scan above
    holds them to the scene layer's imports."""
    from vibroimpact.scene.kinds import KINDS

    for kind in KINDS:
        module = kind.scene.partition(":")[0]
        assert layer_of(module) == "scene", f"{kind.name}: {module} is not read at the scene layer"
        assert layer_of(kind.study.partition(":")[0]) == "kinds" and layer_of(kind.page.partition(":")[0]) == "kinds"


def kind_folder(module: str) -> str | None:
    """The kind folder of ``vibroimpact.kinds.<kind>...`` (None outside every kind folder)."""
    parts = module.split(".")
    return parts[2] if len(parts) >= 3 and parts[:2] == ["vibroimpact", "kinds"] else None


def kind_crossings(own: str | None, found: list[tuple[int, str]]) -> list[str]:
    """The imports among ``found`` of a kind folder other than ``own`` (``line n: module``). None is wanted: what two
    kinds share is a layer below the kinds (the stepped and swept kinds' frequency-grid study is ``grids``)."""
    return [f"line {line}: {target}" for line, target in found if kind_folder(target) not in (None, own)]


@pytest.mark.parametrize("path", [p for p in SOURCES if kind_folder(module_name(p))], ids=lambda p: str(p.relative_to(PACKAGE)))
def test_no_kind_folder_imports_another(path: Path) -> None:
    own = kind_folder(module_name(path))
    crossing = kind_crossings(own, imports(path))
    assert not crossing, f"imports of another kind's folder from {own}:\n" + "\n".join(crossing)


def test_the_check_sees_a_kind_importing_another(tmp_path: Path) -> None:
    """The strict check is not blind: a swept module's import of the stepped kind's folder, even inside a function, is
    a crossing; its own folder and the layers below the kinds (``grids``) are not."""
    module = tmp_path / "probe.py"
    module.write_text(
        "from vibroimpact.grids.grid import StudyGrid\n"
        "from vibroimpact.kinds.swept.variables import swept_attributes\n"
        "def f():\n"
        "    from vibroimpact.kinds.stepped.study import SteppedStudy\n"
    )
    found = kind_crossings("swept", imports(module))
    assert found and all(crossing.startswith("line 4: vibroimpact.kinds.stepped.study") for crossing in found)
    assert LAYERS.index("grids") < LAYERS.index("kinds")  # the grid study both kinds share is below them


#: ``module:attribute`` (or a bare module) named in a string: a module loaded by name.
_BY_NAME = re.compile(r"^vibroimpact(\.[A-Za-z_][A-Za-z0-9_]*)+(:[A-Za-z_][A-Za-z0-9_]*)?$")


def loaded_by_name(path: Path) -> list[tuple[int, str]]:
    """(line, ``module[:attribute]``) of every string constant in ``path`` that names a module of the package: the
    kinds table, the engine registry, the package's lazy public names."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return [(node.lineno, node.value) for node in ast.walk(tree) if isinstance(node, ast.Constant) and isinstance(node.value, str) and _BY_NAME.match(node.value)]


def test_modules_loaded_by_name_exist_and_keep_the_layers() -> None:
    """What a table names by string is an import the scan above cannot see: each one resolves (the module and its
    attribute), and goes downward like an import, except the kinds table's studies and pages, which must be in the
    folder of the kind whose row names them (a kind is loaded by its row, by the runner and the report above it)."""
    from vibroimpact.scene.kinds import KINDS

    plugins = {target for kind in KINDS for target in (kind.study, kind.page)}
    for kind in KINDS:
        for target in (kind.scene, kind.study, kind.page):
            assert kind_folder(target.partition(":")[0]) == kind.name, f"{kind.name}: {target} is outside the kind's folder"
    public = PACKAGE / "__init__.py"
    found = 0
    for path in SOURCES:
        own = layer_of(module_name(path)) or "cli"
        for line, target in loaded_by_name(path):
            module, _, attribute = target.partition(":")
            if path == public:
                attribute = attribute or None  # the lazy table maps a name to its module: checked below
            found += 1
            loaded = importlib.import_module(module)
            assert not attribute or hasattr(loaded, attribute), f"{path.name}:{line}: {target} does not exist"
            layer = None if module == "vibroimpact.studies" else layer_of(module)  # the shipped scenes: data, no layer
            if target not in plugins and layer is not None:
                assert LAYERS.index(layer) <= LAYERS.index(own), f"{path.name}:{line}: {target} is loaded by name from below ({layer} above {own})"
    assert found >= 20  # the kinds table (3 per kind), the engine registry, the lazy names: the scan is not blind
    import vibroimpact

    for name in vibroimpact.__all__:
        assert getattr(vibroimpact, name) is not None, name
