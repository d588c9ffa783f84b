"""Report sections compute nothing: each formats what the risk and analysis objects hand it (issue 47, item 4).

Every module of ``stochpound/report/sections/`` is read (its syntax tree,
nothing is run) for what computes: reductions and arithmetic of numpy,
xarray and pandas objects (``.sum()``, ``.max()``, ``.quantile()``,
``np.log`` …) and calls to the computing packages' functions (the
statistics, the risk chain, the hazard, the codes, the model's modal
analysis). A result object's own methods (``risk.rules_frame()``,
``damage.governing()``) are what a section formats, not computation.

What sections computed when this test was written is listed in
``COMPUTED`` per section, call by call: the test fails when a section
computes anything not listed there (a new computation), and when a
listed computation is gone (the list must then shrink with it). Every
section not listed computes nothing; the goal is an empty ``COMPUTED``.
"""

from __future__ import annotations

import ast
from collections import Counter
from pathlib import Path

import pytest

SECTIONS = Path(__file__).resolve().parent.parent / "stochpound" / "report" / "sections"
REDUCTIONS = {"mean", "sum", "std", "var", "quantile", "median", "max", "min", "argmax", "argmin", "idxmax", "idxmin", "cumsum", "cumprod",
              "prod", "any", "all", "count", "polyfit", "diff", "interp", "groupby", "rolling", "nanmean", "nanmax", "nanmin", "nansum",
              "nanquantile", "percentile", "nanpercentile", "log", "log10", "exp", "sqrt", "histogram", "corrcoef", "geomspace",
              "linspace", "hypot", "cbrt", "power", "square"}
"""Methods and numpy functions that reduce or compute."""
COMPUTING = ("stochpound.analysis", "stochpound.stats", "stochpound.risk", "stochpound.hazard", "stochpound.codes",
             "stochpound.model.modal_solution", "stochpound.model.contact", "stochpound.model")
"""The packages whose functions compute (a section may import their constants and classes, to name and type what it formats)."""


def _computing_names(tree: ast.Module) -> tuple[set[str], set[str]]:
    """The functions a module imports from the computing packages, and the computing modules it imports by name."""
    functions, modules = set(), set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith(COMPUTING):
            for alias in node.names:
                name = alias.asname or alias.name
                if alias.name in {"kernels", "laws", "mechanisms", "modal_solution"}:
                    modules.add(name)
                elif alias.name[0].islower() and not alias.name.isupper():
                    functions.add(name)
    return functions, modules


def computations(path: Path) -> Counter:
    """What a module computes: ``.name`` for a reducing method or numpy function, ``name`` for a computing package's function."""
    tree = ast.parse(path.read_text())
    functions, modules = _computing_names(tree)
    found: Counter = Counter()
    for node in ast.walk(tree):
        if not isinstance(node, ast.Call):
            continue
        func = node.func
        if isinstance(func, ast.Name) and func.id in functions:
            found[func.id] += 1
        elif isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name) and func.value.id in modules:
            found[f"{func.value.id}.{func.attr}"] += 1
        elif isinstance(func, ast.Attribute) and func.attr in REDUCTIONS:
            found[f".{func.attr}"] += 1
    return found


COMPUTED: dict[str, dict[str, int]] = {
    "_intensity.py": {
        ".any": 2, ".exp": 5, ".linspace": 2, ".max": 3, ".median": 1, ".min": 2, ".nanpercentile": 1, ".quantile": 2, ".sum": 7,
        "clopper_pearson": 3, "consistency_at_targets": 1, "contact_free_closure": 1, "limit_state_events": 1, "rate_from_probability": 1,
        "selection_misses": 1, "site_consistency": 1, "stripes_beyond_truncation": 1
    },
    "_stripe_motions.py": {".max": 2, ".min": 3, ".nanmax": 1, ".nanmin": 1, ".sum": 2},
}
"""Per section module, what it still computes (as the sections stood when this test was written): to be emptied, never grown."""


@pytest.mark.parametrize("path", sorted(SECTIONS.glob("*.py")), ids=lambda path: path.name)
def test_a_section_computes_nothing_beyond_what_is_listed(path):
    assert dict(computations(path)) == COMPUTED.get(path.name, {}), path.name


def test_the_detector_sees_a_computation(tmp_path):
    """A section that computes is caught (the check itself can fail)."""
    probe = tmp_path / "_probe.py"
    probe.write_text("import numpy as np\nfrom stochpound.analysis import pounding_probability\nfrom stochpound.risk import StoreRisk\n"
                     "def f(x, ds, risk: StoreRisk):\n    return np.log(x).max(), pounding_probability(ds, 'record'), risk.rules_frame()\n")
    assert computations(probe) == Counter({".log": 1, ".max": 1, "pounding_probability": 1})
