"""The public API says what it is: every name in ``vibroimpact.__all__`` and every name the README's Python code or
prose uses as API exists and is public, and every public docstring states the units of its physical quantities, and
states them truly (a frequency is in Hz, an angular frequency in rad s-1).

The checkable rule (numpydoc): in the ``Parameters``, ``Attributes`` and ``Returns`` sections of each public
function, class and of a public class's public methods, an entry whose name names a physical quantity (:data:`PHYSICAL`)
and whose type is a number or an array (not an int count, a flag, a string or an object) states a unit in brackets,
``[Hz]``, ``[m]``, ``[-]``; an entry called ``frequency`` (or ``*_frequency``) states ``[Hz]`` and ``omega``
``[rad s-1]``; a dataclass field that records its unit (``metadata={"units": ...}``) is documented with that unit; and
anywhere in a public docstring a bracketed unit right after the word "frequency" is ``[Hz]`` unless it is an
"angular frequency"."""

from __future__ import annotations

import ast
import dataclasses
import inspect
import re
from collections.abc import Iterator
from pathlib import Path

import pytest

import vibroimpact

ROOT = Path(__file__).resolve().parents[1]

#: Entry names that carry a physical quantity (a unit is due).
PHYSICAL = re.compile(r"^(frequency|.*_frequency|frequencies|omega|clearance|clearances|mass|masses|m1|m2|k1|k2|b1|b2|stiffness|damping|"
                      r"amplitude|amplitudes|period|duration|.*_time|time|times|force|velocity|impulse|displacement|t|delta)$")  # fmt: skip
#: Types of entries that are no physical quantity: counts, flags, names, objects.
NOT_A_QUANTITY = re.compile(r"^(int|bool|str|callable|dict|tuple of str|sequence of str|\{)")
#: Words the README's prose uses in backticks that are scene keys, files or values, not Python names.
_SECTIONS = ("Parameters", "Attributes", "Returns")


def public_objects() -> Iterator[tuple[str, object]]:
    """(qualified name, object) of every public function and class and of each public class's own public methods and
    properties."""
    for name in vibroimpact.__all__:
        if name == "__version__":
            continue
        value = getattr(vibroimpact, name)
        if inspect.isfunction(value) or inspect.isclass(value):
            yield name, value
        if inspect.isclass(value):
            for attribute, member in vars(value).items():
                if attribute.startswith("_"):
                    continue
                target = member.fget if isinstance(member, property) else getattr(member, "func", member)
                if inspect.isfunction(target) or isinstance(member, (classmethod, staticmethod)):
                    yield f"{name}.{attribute}", getattr(target, "__func__", target)


def entries(doc: str) -> Iterator[tuple[str, str, str]]:
    """(name, type, description) of each entry of the numpydoc sections in :data:`_SECTIONS` (comma-separated names
    split)."""
    lines = inspect.cleandoc(doc).splitlines()
    k = 0
    while k < len(lines):
        if lines[k].strip() in _SECTIONS and k + 1 < len(lines) and set(lines[k + 1].strip()) == {"-"}:
            k += 2
            while k < len(lines) and (not lines[k].strip() or lines[k].startswith(" ") or " : " in lines[k] or re.match(r"^\w", lines[k])):
                line = lines[k]
                if line.strip() in _SECTIONS or (k + 1 < len(lines) and set(lines[k + 1].strip()) == {"-"} and line.strip()):
                    break
                if line and not line.startswith(" "):
                    names, _, kind = line.partition(" : ")
                    described = []
                    k += 1
                    while k < len(lines) and (lines[k].startswith(" ") or not lines[k].strip()):
                        described.append(lines[k].strip())
                        k += 1
                    for entry in names.split(","):
                        yield entry.strip(), kind.strip(), " ".join(described)
                    continue
                k += 1
            continue
        k += 1


def unit_problems(qualified: str, doc: str) -> list[str]:
    """What :func:`entries` and the free text of ``doc`` break of the module docstring's rule."""
    problems = []
    for name, kind, described in entries(doc):
        text = f"{kind} {described}"
        if PHYSICAL.match(name) and not NOT_A_QUANTITY.match(kind) and not re.match(r"^[A-Z]\w+( or [A-Z]\w+)*$", kind) and "[" not in text:
            problems.append(f"{qualified}: {name} ({kind}) states no unit in brackets")
        if re.fullmatch(r"frequency|\w+_frequency|frequencies", name) and "[" in text and "[Hz]" not in text:
            problems.append(f"{qualified}: {name} is a frequency but not in [Hz]: {described[:80]!r}")
        if name == "omega" and "[rad s-1]" not in text:
            problems.append(f"{qualified}: omega does not state [rad s-1]")
    for match in re.finditer(r"frequenc(y|ies)\b([^.,;:()\[\]]{0,40})\[([^\]]+)\]", doc):
        before = doc[max(0, match.start() - 30) : match.start()].lower()
        if match.group(3).strip() != "Hz" and "angular" not in before and "angular" not in match.group(2).lower():
            problems.append(f"{qualified}: '{match.group(0)}' gives a frequency in [{match.group(3)}], not [Hz]")
    return problems


def field_unit_problems(name: str, cls: type) -> list[str]:
    """A dataclass field that records its unit is documented with it."""
    if not dataclasses.is_dataclass(cls):
        return []
    documented = {entry: f"{kind} {described}" for entry, kind, described in entries(cls.__doc__ or "")}
    problems = []
    for field in dataclasses.fields(cls):
        unit = field.metadata.get("units")
        if unit is None or field.name not in documented:
            continue
        expected = "[-]" if unit == "1" else f"[{unit}]"
        if expected not in documented[field.name]:
            problems.append(f"{name}.{field.name}: documented without its unit {expected}: {documented[field.name][:80]!r}")
    return problems


def test_every_public_name_exists_and_its_docstring_states_true_units() -> None:
    missing = [name for name in vibroimpact.__all__ if name != "__version__" and not hasattr(vibroimpact, name)]
    assert not missing, f"vibroimpact.__all__ names what is not there: {missing}"
    undocumented = [qualified for qualified, value in public_objects() if "." not in qualified and not (inspect.getdoc(value) or "").strip()]
    assert not undocumented, f"public names without a docstring: {undocumented}"
    problems: list[str] = []
    checked = 0
    for qualified, value in public_objects():
        doc = inspect.getdoc(value) or ""
        problems += unit_problems(qualified, doc)
        if inspect.isclass(value):
            problems += field_unit_problems(qualified, value)
        checked += sum(1 for name, _, _ in entries(doc) if PHYSICAL.match(name))
    assert checked >= 40, f"only {checked} physical entries were checked: the docstring parser lost its way"
    assert not problems, "\n".join(problems)


def test_the_rule_catches_a_wrong_or_missing_unit() -> None:
    """The checker itself: a frequency in rad s-1, a clearance without a unit, a field without its recorded unit."""
    wrong = '''Summary: apparent natural frequency Omega_b [rad s-1].

    Parameters
    ----------
    frequency : float
        Natural frequency [rad s-1].
    clearance : float
        Delta.
    omega : array_like
        Angular frequency [Hz].
    samples : int
        How many.
    '''
    problems = "\n".join(unit_problems("f", wrong))
    assert "f: 'frequency Omega_b [rad s-1]' gives a frequency in [rad s-1]" in problems, problems
    assert "f: frequency is a frequency but not in [Hz]" in problems and "clearance (float) states no unit" in problems
    assert "omega does not state [rad s-1]" in problems and "samples" not in problems
    assert not unit_problems("g", "Its angular frequency [rad s-1] and its frequency f [Hz].")


def readme_python_blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", (ROOT / "README.md").read_text(), flags=re.S)


def test_the_readme_python_imports_only_public_names() -> None:
    """Every name a README Python section imports from the package comes from ``vibroimpact`` itself and is public."""
    seen, problems = set(), []
    for block in readme_python_blocks():
        for node in ast.walk(ast.parse(block)):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("vibroimpact"):
                for alias in node.names:
                    seen.add(alias.name)
                    if node.module != "vibroimpact":
                        problems.append(f"from {node.module} import {alias.name}: not the public package")
                    elif alias.name not in vibroimpact.__all__:
                        problems.append(f"{alias.name} is not in vibroimpact.__all__")
    assert len(seen) >= 10 and not problems, problems


def test_every_python_name_the_readme_prose_mentions_is_public() -> None:
    """A name in backticks in the README that the package defines at the top of a module (a function or a class) is
    public: a reader can import what the README talks about."""
    defined: set[str] = set()
    for path in (ROOT / "src" / "vibroimpact").rglob("*.py"):
        for node in ast.parse(path.read_text()).body:
            if isinstance(node, (ast.FunctionDef, ast.ClassDef)) and not node.name.startswith("_"):
                defined.add(node.name)
    mentioned = set(re.findall(r"`([A-Za-z_]\w*)(?=[`(.])", (ROOT / "README.md").read_text()))
    not_public = sorted(name for name in mentioned & defined if name not in vibroimpact.__all__ and name != "design_map")  # design_map: a scene's name
    assert not not_public, f"the README mentions names that are not public: {not_public}"


def test_every_error_message_names_public_functions() -> None:
    """An error message that sends the user to a function (``use vibroimpact.solve_two_impacts(problem)``) names one
    that exists and is public."""
    problems = []
    for path in (ROOT / "src" / "vibroimpact").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Raise) and node.exc is not None:
                text = " ".join(part.value for part in ast.walk(node.exc) if isinstance(part, ast.Constant) and isinstance(part.value, str))
                for dotted in re.findall(r"\b(?:vibroimpact|analysis|orbits|model|simulation|engines|runs|grids)\.[\w.]*\w", text):
                    if f"{dotted}.<" in text:  # a template ('vibroimpact.kinds.<module>:<name>'), no function
                        continue
                    public = dotted.count(".") == 1 and dotted.startswith("vibroimpact.") and dotted.split(".")[1] in vibroimpact.__all__
                    if not public:
                        problems.append(f"{path.relative_to(ROOT)}: {dotted!r} is not a public name (vibroimpact.NAME)")
    assert not problems, problems


@pytest.mark.parametrize("name", ["loss_factor_from_restitution", "restitution_from_loss_factor", "orbit_measures", "branch_measures", "closed_form_state", "ImpactOrbit", "LinearAmplitudes"])
def test_the_names_a_user_needs_are_public(name: str) -> None:
    assert name in vibroimpact.__all__ and callable(getattr(vibroimpact, name))
