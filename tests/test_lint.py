"""ruff holds the code to the rules in ``pyproject.toml`` (``[tool.ruff]``): run ``python -m ruff check .`` before a commit."""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).parents[1]


def ruff(*args: str, stdin: str | None = None) -> subprocess.CompletedProcess:
    """``python -m ruff check`` with the project's configuration, from the repository root."""
    return subprocess.run([sys.executable, "-m", "ruff", "check", "--no-cache", "--output-format", "concise", *args],
                          cwd=ROOT, input=stdin, capture_output=True, text=True, timeout=300)


def test_the_code_base_passes_ruff():
    result = ruff(".")
    assert result.returncode == 0, result.stdout + result.stderr


def test_the_configuration_catches_what_it_names():
    """The rules are on: a relative import (TID252), a line over the limit (E501) and an unused import (F401) are reported."""
    source = "from . import spam\nimport os\nx = '" + "a" * 200 + "'\n"
    result = ruff("--stdin-filename", "stochpound/_lint_probe.py", "-", stdin=source)
    assert result.returncode == 1
    for code in ("TID252", "E501", "F401"):
        assert code in result.stdout, result.stdout


def test_pytest_refuses_an_unregistered_marker(tmp_path):
    """``--strict-markers`` (pytest's addopts): a misspelt marker is an error, not a silently unselected test."""
    probe = tmp_path / "test_probe.py"
    probe.write_text("import pytest\n\n\n@pytest.mark.slwo\ndef test_probe():\n    pass\n")
    result = subprocess.run([sys.executable, "-m", "pytest", "-c", str(ROOT / "pyproject.toml"), "--rootdir", str(tmp_path),
                             "-p", "no:cacheprovider", "-p", "no:xdist", str(probe)], capture_output=True, text=True, timeout=300)
    assert result.returncode != 0
    assert "'slwo' not found in `markers` configuration option" in result.stdout + result.stderr
