"""The line between the public API and the internals, drawn by module names (docs/contributing.md, "Public and private modules").

A module of stochpound has a name without a leading underscore only when it
is a package's namespace (``__init__``), a module named in docs/api.md
(``py:module``) or documented in docs/developer-reference.md
(``automodule``), or an entry point users run or import; every other module
is private by name.
"""

import importlib
import re
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[1]
PACKAGE = ROOT / "stochpound"
PUBLIC_PACKAGES = ["stochpound", "stochpound.model", "stochpound.motions", "stochpound.motions.records",
                   "stochpound.experiment", "stochpound.analysis", "stochpound.store", "stochpound.risk", "stochpound.report"]
"""The packages whose ``__all__`` is the public API (docs/api.md)."""
ENTRY_POINTS = {"stochpound.report.assemble", "stochpound.report.render.output"}
"""Modules users import as the docs show: the report built from Python (docs/reports.md); the command is the ``stochpound.cli`` package."""


def documented_modules(page: str, directive: str) -> set[str]:
    """The modules a page of docs/ declares with ``directive`` (``py:module`` or ``automodule``)."""
    return set(re.findall(rf"{directive}:: (stochpound[\w.]*)", (ROOT / "docs" / page).read_text()))


def modules() -> dict[str, Path]:
    """Every module of the package by its dotted name (a package by its own name)."""
    found = {}
    for path in PACKAGE.rglob("*.py"):
        parts = list(path.relative_to(ROOT).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        found[".".join(parts)] = path
    return found


def test_a_module_without_a_leading_underscore_is_a_namespace_documented_or_an_entry_point():
    documented = documented_modules("api.md", "py:module") | documented_modules("developer-reference.md", "automodule")
    allowed = documented | ENTRY_POINTS
    public_by_name = {name: path for name, path in modules().items() if not name.rsplit(".", 1)[-1].startswith("_")}
    undeclared = sorted(name for name, path in public_by_name.items() if path.name != "__init__.py" and name not in allowed)
    assert undeclared == [], (f"{undeclared}: give these modules a leading underscore, or document them "
                              "(docs/api.md, docs/developer-reference.md); see docs/contributing.md")
    # the declarations name modules that exist under their public names
    assert sorted(allowed - set(public_by_name)) == []
    assert {"stochpound.motions.psd", "stochpound.model.laws", "stochpound.solvers.engine"} <= documented


@pytest.mark.parametrize("package", PUBLIC_PACKAGES)
def test_every_name_a_public_package_exports_resolves(package):
    module = importlib.import_module(package)
    exported = module.__all__
    assert len(exported) == len(set(exported)), sorted(name for name in exported if exported.count(name) > 1)
    missing = [name for name in exported if not hasattr(module, name)]
    assert missing == []
    assert not any(name.startswith("_") and name != "__version__" for name in exported)


def test_the_installed_command_resolves():
    scripts = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["scripts"]
    for target in scripts.values():
        module, attribute = target.split(":")
        assert callable(getattr(importlib.import_module(module), attribute)), target
