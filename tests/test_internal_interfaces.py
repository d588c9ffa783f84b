"""Internal interfaces, read from the code's imports (docs/contributing.md, "Public and private modules").

**The rule.** A package's underscore modules (``stochpound.<package>._name``)
are imported only by the modules of that package (its subpackages included);
every other module uses the package's namespace (``from stochpound.experiment
import read_definition``). A subpackage is a package of its own:
``stochpound.report.render._figures`` is private to ``stochpound.report.render``,
and ``stochpound.report.sections`` imports ``stochpound.report.render.figures``.
The rule holds for ``stochpound/``, ``benchmarks/`` and the Python files under
``docs/``; imports inside functions and under ``TYPE_CHECKING`` count.
**Tests are exempt**: a test may import a private module to test it (and
``tests/helpers.py`` with them).

``ALLOWED`` lists today's exceptions. It only shrinks: an import that is
not listed fails, and so does a listed one that is gone.

The same imports, as a graph of modules, hold no cycle; as a graph of the
house's rooms (each package of ``stochpound`` and each of its top-level
modules), they run one way, floor by floor, but for the imports listed in
``ALLOWED_BACK_UP``: at most one, which closes no cycle of modules.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[1]
SCANNED = ("stochpound", "benchmarks", "docs")
GENERATED = ("docs/_build", "docs/generated", "docs/auto_examples")

#: Importer (a path from the repository root) -> the private modules of other packages it imports. Empty: keep it so.
ALLOWED: dict[str, set[str]] = {}

#: The imports (importing room -> imported room, as :func:`room` names them) that run back up a floor: at most one, and
#: it closes no cycle of modules. Empty: keep it so.
ALLOWED_BACK_UP: set[tuple[str, str]] = set()


def module_name(path: Path) -> str:
    """The dotted name of a file under the repository root (a package by its own name)."""
    parts = list(path.with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def package_modules() -> set[str]:
    """Every module of stochpound by its dotted name."""
    return {module_name(path.relative_to(ROOT)) for path in (ROOT / "stochpound").rglob("*.py")}


def scanned_files() -> list[Path]:
    """The Python files the rule holds for, relative to the repository root."""
    files = []
    for top in SCANNED:
        for path in sorted((ROOT / top).rglob("*.py")):
            relative = path.relative_to(ROOT)
            if not str(relative).startswith(GENERATED):
                files.append(relative)
    return files


def imports(source: str) -> set[str]:
    """Every module a source imports, anywhere in it, by its dotted name; ``from a import b`` gives a and a.b."""
    found = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found.add(node.module)
            found.update(f"{node.module}.{alias.name}" for alias in node.names)
    return found


def imported_modules(source: str, modules: set[str]) -> set[str]:
    """The modules of stochpound a source imports (``from a import b`` names a.b only when that is a module)."""
    return imports(source) & modules


def owner(module: str) -> str | None:
    """The package a private module belongs to (None for a public module)."""
    parts = module.split(".")
    for index, part in enumerate(parts[1:], start=1):
        if part.startswith("_"):
            return ".".join(parts[:index])
    return None


def crossings(importer: str, imported: set[str]) -> set[str]:
    """The private modules of other packages among ``imported``, for the module named ``importer``."""
    result = set()
    for module in imported:
        package = owner(module)
        if package is not None and importer != package and not importer.startswith(package + "."):
            result.add(module)
    return result


def offenders() -> dict[str, set[str]]:
    """Every scanned file that imports another package's private modules, with those modules."""
    modules = package_modules()
    found = {}
    for path in scanned_files():
        crossed = crossings(module_name(path), imported_modules((ROOT / path).read_text(), modules))
        if crossed:
            found[path.as_posix()] = crossed
    return found


def test_no_import_crosses_into_another_package_s_private_module_but_the_listed_ones():
    found = offenders()
    new = {path: sorted(modules - ALLOWED.get(path, set())) for path, modules in found.items() if modules - ALLOWED.get(path, set())}
    gone = {path: sorted(modules - found.get(path, set())) for path, modules in ALLOWED.items() if modules - found.get(path, set())}
    assert not new, f"import from the package's namespace instead (export the name from its __init__): {new}"
    assert not gone, f"fixed: take these off ALLOWED in {Path(__file__).name}: {gone}"


@pytest.mark.parametrize(
    ("importer", "source", "crossed"),
    [
        ("stochpound.report.sections._generic", "from stochpound.experiment._file_layout import PREFIX", {"stochpound.experiment._file_layout"}),
        ("stochpound.report.sections._generic", "from stochpound.report.render import _figures as figures", {"stochpound.report.render._figures"}),
        ("stochpound.report.sections._generic", "def f():\n    import stochpound.analysis._summary\n", {"stochpound.analysis._summary"}),
        ("stochpound.cli._records", "if TYPE_CHECKING:\n    from stochpound.motions.records._record import Record\n", {"stochpound.motions.records._record"}),
        ("stochpound.motions.records._statistics", "from stochpound.motions._arias import arias_intensity", set()),
        ("stochpound.experiment._runner", "from stochpound.experiment._spec import parse_experiment", set()),
        ("stochpound.report.sections._generic", "from stochpound.report.render import figures", set()),
        ("stochpound.report.assemble", "from stochpound._errors import StochpoundError", set()),
        ("benchmarks.suite", "from stochpound._errors import StochpoundError", {"stochpound._errors"}),
    ],
)
def test_the_rule_as_read_from_a_source(importer, source, crossed):
    assert crossings(importer, imported_modules(source, package_modules())) == crossed


def import_graph() -> dict[str, set[str]]:
    """Module -> the modules of stochpound it imports (anywhere in it); a package is its ``__init__``.

    A package the module is in is no arrow: Python runs it before the module
    (``from stochpound import __version__``).
    """
    modules = package_modules()
    graph = {}
    for path in (ROOT / "stochpound").rglob("*.py"):
        name = module_name(path.relative_to(ROOT))
        imported = imported_modules(path.read_text(), modules)
        graph[name] = {target for target in imported if target in modules and target != name and not name.startswith(target + ".")}
    return graph


def cycles(graph: dict[str, set[str]]) -> list[tuple[str, ...]]:
    """The strongly connected components of more than one module (Tarjan's algorithm), each as sorted names."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for successor in sorted(graph.get(node, ())):
            if successor not in index:
                visit(successor)
                low[node] = min(low[node], low[successor])
            elif successor in on_stack:
                low[node] = min(low[node], index[successor])
        if low[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == node:
                    break
            if len(component) > 1:
                found.append(tuple(sorted(component)))

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return sorted(found)


def room(module: str) -> str:
    """The room of the house a module of stochpound is in: its top-level package or module (``stochpound`` for the namespace)."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else parts[0]


def room_graph(graph: dict[str, set[str]]) -> dict[str, set[str]]:
    """The module graph's arrows between rooms: room -> the other rooms its modules import."""
    rooms: dict[str, set[str]] = {}
    for importer, imported in graph.items():
        rooms.setdefault(room(importer), set()).update(room(target) for target in imported if room(target) != room(importer))
    return rooms


def test_the_modules_import_each_other_in_no_cycle():
    assert cycles(import_graph()) == []


def test_the_rooms_import_each_other_one_way_but_through_at_most_one_listed_import():
    rooms = room_graph(import_graph())
    assert len(ALLOWED_BACK_UP) <= 1
    gone = sorted(edge for edge in ALLOWED_BACK_UP if edge[1] not in rooms.get(edge[0], set()))
    assert not gone, f"fixed: take these off ALLOWED_BACK_UP in {Path(__file__).name}: {gone}"
    for importer, imported in ALLOWED_BACK_UP:
        rooms[importer].discard(imported)
    assert cycles(rooms) == [], "these rooms import each other: an import runs back up a floor"


def test_rooms_that_import_each_other_are_found():
    graph = {"stochpound.risk._maf": {"stochpound.analysis"}, "stochpound.analysis": {"stochpound.risk"},
             "stochpound.analysis._moments": {"stochpound.stats"}, "stochpound._errors": set()}
    assert room_graph(graph) == {"risk": {"analysis"}, "analysis": {"risk", "stats"}, "_errors": set()}
    assert cycles(room_graph(graph)) == [("analysis", "risk")]
    assert cycles(graph) == []  # no cycle of modules: the rooms' one is seen only drawn by rooms


def test_cycles_are_found():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}, "e": {"e"}}
    assert cycles(graph) == [("a", "b", "c")]


def test_tests_import_no_test_module_and_benchmarks_no_test():
    """Shared test code is in tests/helpers.py (and tests/chromium.py, tests/au_beck_oscillator.py); a test imports the benchmarks only to test them."""
    found = []
    for path in sorted((ROOT / "tests").glob("*.py")) + sorted((ROOT / "benchmarks").glob("*.py")):
        for module in imports(path.read_text()):
            from_tests = module == "conftest" or module.startswith(("tests.test_", "tests.conftest")) or module == "tests"
            if path.parent.name == "benchmarks" and (module.startswith("tests") or module == "conftest"):
                found.append(f"{path.name} imports {module}")
            elif path.parent.name == "tests" and from_tests:
                found.append(f"{path.name} imports {module}")
            elif path.parent.name == "tests" and module.startswith("benchmarks") and not path.name.startswith("test_benchmark_"):
                found.append(f"{path.name} imports {module}")
    assert not found



def test_the_command_line_imports_no_report_section():
    """``stochpound risk`` prints the risk chain's own tables: the CLI reads no report section (and, above, no private module)."""
    found = {path.name: sorted(module for module in imports(path.read_text()) if module.startswith("stochpound.report.sections"))
             for path in sorted((ROOT / "stochpound" / "cli").glob("*.py"))}
    assert {name: modules for name, modules in found.items() if modules} == {}
