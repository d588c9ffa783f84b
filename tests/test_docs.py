"""The documentation builds with Sphinx, warnings as errors, and cites nothing outside the repository."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[1]


@pytest.mark.slow
def test_sphinx_builds_the_docs_and_the_api_reference_without_warnings(tmp_path):
    result = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html", "docs", str(tmp_path)],
                            cwd=ROOT, capture_output=True, text=True, timeout=900, check=False)
    assert result.returncode == 0, result.stderr[-4000:]
    api = (tmp_path / "api.html").read_text()
    for documented in ("stochpound.model.contact.contact_from_table", "stochpound.solvers.driver.EngineRun", "stochpound.simulate"):
        assert f'id="{documented}"' in api, documented


def test_no_project_file_cites_a_document_outside_the_project():
    outside = re.compile(r"MODEL\.md|CONTRACT\.md|REFERENCE_STUDY\.md|shared/docs|\.\./shared")
    checked = [path for pattern in ("stochpound/**/*.py", "tests/*.py", "benchmarks/*.py", "docs/**/*.md", "*.md", "data/**/*.md",
                                    "data/**/*.toml", "experiments/**/*.toml", "reports/templates/*")
               for path in ROOT.glob(pattern) if path.is_file() and path.name != "test_docs.py"]
    assert len(checked) > 50
    citing = [str(path.relative_to(ROOT)) for path in checked if outside.search(path.read_text(errors="ignore"))]
    assert citing == []
