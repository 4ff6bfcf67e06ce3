"""The package's layers import downward only, the lower layers know nothing of YAML, xarray or plotting, and no
module imports itself through others (no import cycle).

Read from the source (every ``import`` statement, including those inside functions), so a new upward import or
cycle fails here however rarely it runs.
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


# ----------------------------------------------------------------------------------------------- no import cycles
def type_checking_lines(path: Path) -> set[int]:
    """The lines under ``if TYPE_CHECKING:`` (or ``typing.TYPE_CHECKING``) in ``path``: an import there never runs,
    only a type checker reads it (an annotation under ``from __future__ import annotations`` is a string), so it makes
    no import cycle; the layer checks above read it all the same."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    lines: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and ast.unparse(node.test) in ("TYPE_CHECKING", "typing.TYPE_CHECKING"):
            lines |= {inner.lineno for statement in node.body for inner in ast.walk(statement) if hasattr(inner, "lineno")}
    return lines


def import_graph(paths: dict[str, Path]) -> dict[str, set[str]]:
    """Module -> the modules among ``paths`` (module name -> source file) it imports when it runs: at module level or
    inside a function, not under ``if TYPE_CHECKING:``. ``from pkg import name`` imports the module ``pkg.name`` where
    that is a module, else ``pkg`` (a name defined or re-exported by ``pkg/__init__.py``).

    Importing ``pkg.mod`` runs ``pkg/__init__.py`` first; that implicit edge is left out: Python has put the package in
    ``sys.modules`` by then, so a package whose ``__init__`` re-exports its own submodules (``vibroimpact.scene``) is no
    cycle with them. An explicit ``from pkg import name`` of such a re-export is an edge to ``pkg`` like any other.
    """
    graph: dict[str, set[str]] = {}
    for module, path in paths.items():
        skipped = type_checking_lines(path)
        statements: dict[int, set[str]] = {}
        for line, target in imports(path):
            if line not in skipped:
                statements.setdefault(line, set()).add(target)
        edges: set[str] = set()
        for targets in statements.values():
            for target in targets:
                if target in paths:
                    if not any(other in paths and other.startswith(target + ".") for other in targets):
                        edges.add(target)  # not merely the ``pkg`` of ``from pkg import module``
                elif target.rpartition(".")[0] in paths:
                    edges.add(target.rpartition(".")[0])  # ``from pkg import name``: a name of pkg's own
        graph[module] = edges - {module}
    return graph


def find_cycle(graph: dict[str, set[str]]) -> list[str]:
    """A cycle of ``graph`` as its nodes in import order, the first one repeated at the end (``[]``: none)."""
    done: set[str] = set()
    path: list[str] = []

    def visit(node: str) -> list[str]:
        path.append(node)
        for after in sorted(graph.get(node, ())):
            if after in path:
                return path[path.index(after) :] + [after]
            if after not in done and (cycle := visit(after)):
                return cycle
        path.pop()
        done.add(node)
        return []

    for node in sorted(graph):
        if node not in done and (cycle := visit(node)):
            return cycle
    return []


def test_no_import_cycles() -> None:
    """No module imports itself through others, however rarely the import runs (inside a function too): what two
    modules share lives in a module below both."""
    cycle = find_cycle(import_graph({module_name(path): path for path in SOURCES}))
    assert not cycle, "import cycle: " + " -> ".join(cycle)


def test_the_cycle_check_sees_a_cycle(tmp_path: Path) -> None:
    """The cycle check is not blind: a cycle closed by an import inside a function is found, with its modules in
    order; ``from pkg import module`` is an edge to the module, not to the package; an import under
    ``if TYPE_CHECKING:`` is none."""
    sources = {
        "pkg": "",
        "pkg.a": "from pkg.b import helper\n",
        "pkg.b": "def helper():\n    from pkg import c\n",
        "pkg.c": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from pkg.d import D\nimport pkg.a\n",
        "pkg.d": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from pkg.a import A\nfrom pkg import VALUE\n",
    }
    paths = {name: tmp_path / f"{name}.py" for name in sources}
    for name, text in sources.items():
        paths[name].write_text(text)
    graph = import_graph(paths)
    assert graph == {"pkg": set(), "pkg.a": {"pkg.b"}, "pkg.b": {"pkg.c"}, "pkg.c": {"pkg.a"}, "pkg.d": {"pkg"}}
    assert find_cycle(graph) == ["pkg.a", "pkg.b", "pkg.c", "pkg.a"]
    assert find_cycle(graph | {"pkg.c": set()}) == [] and find_cycle({"x": {"y"}, "y": {"x"}}) == ["x", "y", "x"]



#: The modules outside ``model/`` that may name the paper's named system (``TwoDofSystem``, a view of the paper's
#: layout): the public re-export, the scene's ``system:`` key, the page's named parameters, and the paper's formulas
#: and tables. Everything else works on the one model (``Layout``, ``LinearStructure``, ``ImpactProblem``) and reaches
#: the view through it (``problem_of``, ``named_view``, ``named_system``).
NAMED_SYSTEM_VIEWS = 6


def modules_naming(name: str, package: Path) -> list[str]:
    """The modules of ``package`` outside its ``model/`` whose text names ``name`` (in code, an annotation or a
    docstring), as paths relative to ``package``."""
    paths = (path.relative_to(package) for path in sorted(package.rglob("*.py")))
    return [str(path) for path in paths if path.parts[0] != "model" and name in (package / path).read_text(encoding="utf-8")]


def test_the_named_system_is_named_by_views_only() -> None:
    """At most :data:`NAMED_SYSTEM_VIEWS` modules outside ``model/`` name ``TwoDofSystem``."""
    naming = modules_naming("TwoDofSystem", PACKAGE)
    assert len(naming) <= NAMED_SYSTEM_VIEWS, f"{len(naming)} modules outside model/ name TwoDofSystem (allowed {NAMED_SYSTEM_VIEWS}): {naming}"


def test_the_named_system_count_sees_a_new_name(tmp_path: Path) -> None:
    """The count is not blind: a docstring naming the view counts, in a subfolder too; a module under ``model/``
    and one that does not name it do not."""
    files = {"model/system.py": "class TwoDofSystem: ...\n", "analysis/x.py": '"""A TwoDofSystem."""\n', "kinds/k/y.py": "from a import TwoDofSystem\n", "z.py": "x = 1\n"}
    for relative, text in files.items():
        (tmp_path / relative).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / relative).write_text(text)
    assert modules_naming("TwoDofSystem", tmp_path) == ["analysis/x.py", "kinds/k/y.py"]
