"""The test suite's own rules, checked on its source so that no test brings back what failed on a fresh machine:
no exact comparison of computed floats, no assertion on how fast the machine is."""

from __future__ import annotations

import ast
from pathlib import Path

TESTS = Path(__file__).resolve().parent
#: A comparison with a float literal is allowed only on a line that says why it is exact (a count, a parsed input).
EXACT_MARK = "# exact"
CLOCKS = {"perf_counter", "time", "monotonic", "process_time", "perf_counter_ns", "monotonic_ns"}


def _float_literal(node: ast.expr) -> bool:
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        node = node.operand
    return isinstance(node, ast.Constant) and isinstance(node.value, float)


def _reads_a_clock(node: ast.AST) -> bool:
    return any(isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute) and n.func.attr in CLOCKS and isinstance(n.func.value, ast.Name) and n.func.value.id == "time" for n in ast.walk(node))


def exact_float_comparisons(source: str) -> list[int]:
    """Lines comparing with ``==`` or ``!=`` against a float literal, without an ``# exact`` reason."""
    lines = source.splitlines()
    found = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Compare) and any(isinstance(op, (ast.Eq, ast.NotEq)) for op in node.ops):
            if any(_float_literal(operand) for operand in (node.left, *node.comparators)) and EXACT_MARK not in lines[node.lineno - 1]:
                found.add(node.lineno)
    return sorted(found)


def clock_assertions(source: str) -> list[int]:
    """Lines asserting on a reading of the wall clock."""
    return sorted({node.lineno for node in ast.walk(ast.parse(source)) if isinstance(node, ast.Assert) and _reads_a_clock(node.test)})


def _sources() -> dict[str, str]:
    return {str(path.relative_to(TESTS)): path.read_text(encoding="utf-8") for path in sorted(TESTS.rglob("*.py"))}


def test_no_exact_comparison_of_computed_floats() -> None:
    """Use ``pytest.approx`` or ``assert_allclose`` with a tolerance scaled to the quantity; a value that is exact by
    construction (a count stored as float, a parsed input) says so with ``# exact: why`` on its line."""
    offending = {name: lines for name, source in _sources().items() if (lines := exact_float_comparisons(source))}
    assert offending == {}


def test_no_assertion_on_wall_clock_speed() -> None:
    """Speed targets live in benchmarks as ratios; a hang is caught by ``@pytest.mark.timeout``."""
    offending = {name: lines for name, source in _sources().items() if (lines := clock_assertions(source))}
    assert offending == {}


def test_the_checks_see_what_they_look_for() -> None:
    source = "import time\nx = 0.1 + 0.2\nassert x == 0.3\nassert x != -1.5\nassert 3 == 3  # ints are fine\nassert 1.0 == x  # exact: why\nt = time.perf_counter()\nassert time.perf_counter() - t < 5.0\n"
    assert exact_float_comparisons(source) == [3, 4]
    assert clock_assertions(source) == [8]
