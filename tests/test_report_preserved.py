"""Behaviour preserved: a store's report text is the reference's, word for word.

The reference ``tests/data/reports/risk_stripes.txt`` holds the text of the page and every table (the
build date, the commit and the run folder masked) of a small risk report: the flagship's isolated scene
(elastic) under eight far-field motions at three stripes, a 5 cm gap and the contact-free twin, with the
bundled hazard, so the store, intensity, hazard and risk sections all run. It was first written by the
code before the store-layer step (issue 32), which this test showed to be behaviour-preserving. A change
that means to change the report rewrites it on purpose (``STOCHPOUND_WRITE_REFERENCE=1 pytest
tests/test_report_preserved.py``) and the diff of the reference shows, in review, every sentence it changed.
"""

from __future__ import annotations

import html
import os
import re
from pathlib import Path

from tests.helpers import ISOLATED, invoke, risk_text, run_in_process

REFERENCE = Path(__file__).parent / "data" / "reports" / "risk_stripes.txt"
STRIPES = 'measure = "psa"\nperiod = 1.0\nlevels = [0.3, 0.8, 1.5]'


def report_text(out: Path, folder: Path) -> str:
    """The words and tables of the report built into ``out`` (figures left out; date, commit and ``folder`` masked)."""
    page = (out / "index.html").read_text()
    page = re.sub(r"<(style|script)\b.*?</\1>", "", page, flags=re.S)
    page = re.sub(r'src="data:[^"]*"', "", page)
    lines = (" ".join(line.split()) for line in html.unescape(re.sub(r"<[^>]+>", " ", page)).splitlines())
    parts = ["\n".join(line for line in lines if line)]
    parts += [f"== {table.name}\n{table.read_text()}" for table in sorted((out / "tables").glob("*.csv"))]
    text = "\n".join(parts).replace(str(folder), "<folder>")
    text = re.sub(r"\b[0-9a-f]{40}\b(\+dirty)?", "<commit>", text)  # a build from a tree with changes says +dirty
    return re.sub(r"\b\d{4}-\d{2}-\d{2}\b", "<date>", text) + "\n"


def build_risk_report(folder: Path) -> str:
    """Run the small risk experiment in ``folder``, build its HTML report and return its text."""
    store = run_in_process(folder, "risk", risk_text(ISOLATED, "gap = [0.05, inf]", STRIPES))
    result = invoke("report", "build", str(store), "--out", str(folder / "report"), "--format", "html")
    assert result.exit_code == 0, result.output
    return report_text(folder / "report", folder)


def test_the_risk_report_text_is_the_reference_s(tmp_path):
    text = build_risk_report(tmp_path)
    if os.environ.get("STOCHPOUND_WRITE_REFERENCE") == "1":
        REFERENCE.write_text(text)
    reference = REFERENCE.read_text()
    assert "<folder>/risk.toml" in text and "separation" in text.lower(), "the masking and the sections are in place"
    assert text == reference, "the report text changed: compare with tests/data/reports/risk_stripes.txt"
