"""The risk chain as its own package (docs/risk.md, "Where things live").

* ``stochpound.risk`` is the canonical home of the chain's names; the ones the
  contract lists under ``stochpound.analysis`` stay importable there as the
  same objects, the other old aliases are retired, and importing the
  statistics does not import the risk chain;
* every store read of the chain is in ``stochpound/risk/_inputs.py``;
* report sections compute nothing and cache nothing: no process-wide cache;
* ``stochpound risk`` imports no report section and no private module of
  another package.
"""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
RISK = ROOT / "stochpound" / "risk"
SECTIONS = ROOT / "stochpound" / "report" / "sections"


def _imports(path: Path) -> set[str]:
    """The modules a file imports (``from a.b import c`` gives ``a.b`` and ``a.b.c``: c may be a module)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module:
            found.add(node.module)
            found |= {f"{node.module}.{alias.name}" for alias in node.names}
    return found


@pytest.mark.parametrize("name", ["fit_fragility", "HazardCurve", "mean_annual_frequency", "subset_simulation"])
def test_the_contract_s_analysis_names_stay(name):
    """The names the project's contract lists under stochpound.analysis; its risk names are the risk package's objects."""
    import stochpound.analysis
    import stochpound.risk

    assert name in stochpound.analysis.__all__
    if name in stochpound.risk.__all__:
        assert getattr(stochpound.analysis, name) is getattr(stochpound.risk, name)


@pytest.mark.parametrize("name", ["Fragility", "stripe_fragility", "risk_curve", "risk_targeted_separation", "code_rules_risk", "store_risk",
                                  "StoreRisk", "contact_free_closure", "pounding_fragility", "risk_gaps", "RISK_NAMES"])
def test_the_retired_risk_aliases_of_analysis_are_gone(name):
    import stochpound.analysis

    assert name not in stochpound.analysis.__all__
    with pytest.raises(AttributeError, match=name):
        getattr(stochpound.analysis, name)


def test_the_kernels_have_one_path():
    """``stochpound.analysis.kernels`` (the kernels' old path, an alias in sys.modules) is retired: stochpound.stats.kernels."""
    code = "import stochpound.analysis.kernels"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert result.returncode != 0 and "ModuleNotFoundError" in result.stderr


def test_an_unknown_analysis_name_is_still_an_attribute_error():
    import stochpound.analysis

    with pytest.raises(AttributeError, match="no_such_name"):
        stochpound.analysis.no_such_name  # noqa: B018


def test_importing_the_statistics_does_not_import_the_risk_chain():
    code = "import sys, stochpound.analysis; print(sorted(m for m in sys.modules if m.startswith('stochpound.risk')))"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    assert result.stdout.strip() == "[]"


def test_every_store_read_of_the_chain_is_in_one_module():
    """Only ``_inputs.py`` imports the experiment or store layers (the definition, the store's hazard, the gap axes that
    select cases), and only it looks into a store (its attributes, variables, dimensions, accessor)."""
    readers = {path.name for path in RISK.glob("*.py")
               if any(module.startswith(("stochpound.experiment", "stochpound.store")) for module in _imports(path))}
    assert readers <= {"_inputs.py"}
    touching = {path.name for path in RISK.glob("*.py") if re.search(r"\bstore(\.attrs|\[|\.dims|\.sizes|\.sel|\.isel|\.data_vars|\.pound)", path.read_text())}
    assert touching <= {"_inputs.py"}  # the other modules hand the store to _inputs's functions, never look into it


def test_report_sections_keep_no_cache():
    for path in SECTIONS.glob("*.py"):
        text = path.read_text()
        assert "_CACHE" not in text and "lru_cache" not in text and "functools.cache" not in text, path.name
    risk = _imports(SECTIONS / "_risk.py")
    assert not any(module.startswith("stochpound.risk._") for module in risk)
    assert not {"store_risk", "store_demands"} & {node.id for node in ast.walk(ast.parse((SECTIONS / "_risk.py").read_text()))
                                                   if isinstance(node, ast.Name)}


def test_the_risk_command_imports_only_public_namespaces():
    """No report section, and no private module of another package (the root package's own utilities, ``stochpound._errors``,
    ``stochpound._atomic``, ``stochpound._text_files`` and ``stochpound._plurals``, are the CLI's)."""
    imported = {module for module in _imports(ROOT / "stochpound" / "cli" / "_risk.py") if module.startswith("stochpound")}
    assert not any(module.startswith("stochpound.report") for module in imported)
    private = sorted(module for module in imported if any(part.startswith("_") for part in module.split(".")[1:])
                     and not module.startswith(("stochpound._errors", "stochpound._atomic", "stochpound._text_files", "stochpound._plurals",
                                                "stochpound.cli.")))
    assert private == []
    code = ("import sys, stochpound.cli._risk, stochpound.risk, stochpound.experiment; "
            "print(sorted(m for m in sys.modules if m.startswith('stochpound.report')))")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    assert result.stdout.strip() == "[]"


def test_every_risk_name_analysis_gives_is_the_risk_package_s():
    import stochpound.analysis
    import stochpound.risk

    assert stochpound.analysis.CONTRACT_RISK_NAMES == ("fit_fragility", "mean_annual_frequency")
    assert all(getattr(stochpound.analysis, name) is getattr(stochpound.risk, name) for name in stochpound.analysis.CONTRACT_RISK_NAMES)


@pytest.mark.parametrize("name", ["HazardCurve", "HazardFile", "read_hazard_file", "bundled_curves", "bundled_measure", "bundled_site_curves",
                                  "probability_from_rate", "rate_from_probability", "return_period", "hazard_consistency", "stripe_rate_weights"])
def test_the_analysis_hazard_names_are_the_hazard_package_s(name):
    """The hazard names analysis exported before stochpound.hazard existed: still there, the same objects."""
    import stochpound.analysis
    import stochpound.hazard

    assert name in stochpound.analysis.__all__ and name in stochpound.hazard.__all__
    assert getattr(stochpound.analysis, name) is getattr(stochpound.hazard, name)
