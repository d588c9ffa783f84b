"""The documentation builds with Sphinx (nitpicky, warnings as errors, the gallery's scripts executed) and cites nothing outside the repository."""

import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[1]


@pytest.mark.slow
def test_sphinx_builds_the_docs_and_the_api_reference_without_warnings(tmp_path):
    # nitpicky = True in docs/conf.py: every cross-reference must resolve
    result = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html", "docs", str(tmp_path)],
                            cwd=ROOT, capture_output=True, text=True, timeout=900, check=False)
    assert result.returncode == 0, result.stderr[-4000:]
    api = (tmp_path / "api.html").read_text()
    for public in ("stochpound.simulate", "stochpound.open_store", "stochpound.analysis.pounding_curve", "stochpound.motions.kanai_tajimi"):
        assert f'href="generated/{public}.html' in api, public
        assert f'id="{public}"' in (tmp_path / "generated" / f"{public}.html").read_text(), public
    developer = (tmp_path / "developer-reference.html").read_text()
    for internal in ("stochpound.model.contact.contact_from_table", "stochpound.solvers.driver.EngineRun"):
        assert f'id="{internal}"' in developer, internal
    examples = sorted(path.stem for path in (ROOT / "docs" / "examples").glob("plot_*.py"))
    assert len(examples) >= 4
    for example in examples:  # executed: each example page shows the figure its script drew
        assert f"sphx_glr_{example}_001.png" in (tmp_path / "auto_examples" / f"{example}.html").read_text(), example


def test_no_project_file_cites_a_document_outside_the_project():
    outside = re.compile(r"MODEL\.md|CONTRACT\.md|REFERENCE_STUDY\.md|shared/docs|\.\./shared")
    checked = [path for pattern in ("stochpound/**/*.py", "tests/*.py", "benchmarks/*.py", "docs/**/*.md", "*.md", "data/**/*.md",
                                    "data/**/*.toml", "experiments/**/*.toml", "reports/templates/*")
               for path in ROOT.glob(pattern) if path.is_file() and path.name != "test_docs.py"]
    assert len(checked) > 50
    citing = [str(path.relative_to(ROOT)) for path in checked if outside.search(path.read_text(errors="ignore"))]
    assert citing == []


def test_the_readme_names_the_suites_duration_and_the_slow_marker():
    """Beside the test command: how long the whole suite takes, the quick run without the `slow` tests, and how to run the
    `benchmark` tests the suite skips."""
    text = (ROOT / "README.md").read_text()
    tests = text[text.index("<!-- test-command") : text.index("## What it does")]
    assert re.search(r"whole suite takes about \d+ minutes on 2 cores", tests)
    quick = re.search(r'`(python -m pytest[^`]* -m "not slow")`', tests)
    assert quick and re.search(r"quick run of about \d+ minutes", tests), "the README's quick test command"
    markers = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["pytest"]["ini_options"]["markers"]
    assert [marker.split(":")[0] for marker in markers] == ["slow", "benchmark"]
    assert "--benchmarks" in tests, "the README says how to run the tests the suite skips"
