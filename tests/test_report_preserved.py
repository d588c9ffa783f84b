"""Behaviour preserved: a store's report text is the reference's, word for word and number for number.

The reference ``tests/data/reports/risk_stripes.txt`` holds the text of the page and every table (the
build date, the commit, the run folder and the software versions masked) of a small risk report: the
flagship's isolated scene (elastic) under eight far-field motions at three stripes, a 5 cm gap and the
contact-free twin, with the bundled hazard, so the store, intensity, hazard and risk sections all run. It
was first written by the code before the store-layer step (issue 32), which this test showed to be
behaviour-preserving. A change that means to change the report rewrites it on purpose
(``STOCHPOUND_WRITE_REFERENCE=1 pytest tests/test_report_preserved.py``) and the diff of the reference
shows, in review, every sentence it changed.

The words must be identical and every number the reference's to 1e-9, absolutely or relatively
(``tests.helpers.ROUNDING``): the machine's last digits are not the report's text. The solver's
differences and residuals it prints are rounding (7.6e-13 m where the reference was written, 9.2e-13 m on
another machine) and its tables print 17 digits, the last few set by the CPU's BLAS kernels and thread
count; the slow test below rebuilds the report with other kernels and one thread and compares it the same way.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.helpers import ISOLATED, REPOSITORY, invoke, report_page_text, risk_text, run_in_process, text_difference

REFERENCE = Path(__file__).parent / "data" / "reports" / "risk_stripes.txt"
STRIPES = 'measure = "psa"\nperiod = 1.0\nlevels = [0.3, 0.8, 1.5]'
OTHER_MACHINE = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "OPENBLAS_CORETYPE": "Prescott"}
"""The environment of the slow test: one BLAS thread and OpenBLAS's generic SSE3 kernels instead of the CPU's own (another
machine's last digits, on this one)."""


def build_risk_report(folder: Path) -> str:
    """Run the small risk experiment in ``folder``, build its HTML report and return its text."""
    store = run_in_process(folder, "risk", risk_text(ISOLATED, "gap = [0.05, inf]", STRIPES))
    result = invoke("report", "build", str(store), "--out", str(folder / "report"), "--format", "html")
    assert result.exit_code == 0, result.output
    return report_page_text(folder / "report", folder)


def test_the_risk_report_text_is_the_reference_s(tmp_path):
    text = build_risk_report(tmp_path)
    if os.environ.get("STOCHPOUND_WRITE_REFERENCE") == "1":
        REFERENCE.write_text(text)
    reference = REFERENCE.read_text()
    assert "<folder>/risk.toml" in text and "separation" in text.lower(), "the masking and the sections are in place"
    assert "numpy <version>" in text, "the software versions are masked, their names kept"
    difference = text_difference(text, reference)
    assert not difference, f"the report text changed (compare with tests/data/reports/risk_stripes.txt): {difference}"


@pytest.mark.slow
def test_the_reference_holds_with_another_machine_s_blas_kernels_and_one_thread(tmp_path):
    """The same test in a subprocess whose BLAS is another machine's: one thread, OpenBLAS's generic kernels (OTHER_MACHINE)."""
    environment = {**os.environ, **OTHER_MACHINE, "STOCHPOUND_WRITE_REFERENCE": "0"}
    node = f"{Path(__file__).relative_to(REPOSITORY)}::test_the_risk_report_text_is_the_reference_s"
    result = subprocess.run([sys.executable, "-m", "pytest", node, "-q", "-p", "no:cacheprovider", "--basetemp", str(tmp_path / "run")],
                            cwd=REPOSITORY, env=environment, capture_output=True, text=True, timeout=1200)
    assert result.returncode == 0, result.stdout[-3000:]


# ---------------------------------------------------------------- the comparison itself


LINE = ("the exact solver and scipy's DOP853 differ by at most 7.6e-13 m (peak 41.5 cm); 3 impacts.\n"
        "10 % in 50 yr,0.27048257153399585,0.17063058217398472\n")


@pytest.mark.parametrize(("now", "same"), [
    (LINE, True),
    (LINE.replace("7.6e-13 m", "9.2e-13 m"), True),  # rounding: below 1e-9
    (LINE.replace("0.27048257153399585", "0.27048257153399574"), True),  # the 17th digit
    (LINE.replace("7.6e-13 m", "2.1e-06 m"), False),  # a solver difference that grew
    (LINE.replace("41.5 cm", "41.6 cm"), False),
    (LINE.replace("0.27048257153399585", "0.2704826"), False),  # the 7th digit
    (LINE.replace("3 impacts", "4 impacts"), False),
    (LINE.replace("at most", "at least"), False),  # a word
    (LINE + "one more line\n", False),
])  # fmt: skip
def test_texts_are_compared_word_for_word_and_number_to_rounding(now, same):
    assert (text_difference(now, LINE) == "") is same
