"""A report an engineer can sign (issue "Reports an engineer can sign", its "Done when" test).

The report of a small experiment that is not the study's: Hertz-damp
contacts (stiffness in N/m^1.5), a friction-pendulum base, finite and
contact-free gaps and a small synthetic ensemble. It must name the law that
ran with its units and no law that did not, bound D by ABS on every
contact-free run, give no negative bound of a quantity that cannot be
negative in any table or CSV, and open with its summary.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from stochpound.analysis import separation_rules, store_contact_demands
from stochpound.experiment import open_store
from stochpound.report.assemble import assemble_report
from stochpound.report.render._document import Paragraph, Table
from stochpound.report.render.output import write_report
from tests.helpers import run_in_process

EXPERIMENT = """
[experiment]
name = "pendulum"
description = "An isolated three-storey building on a friction pendulum beside a fixed two-storey one, Hertz-damp contacts."
studied = "A"

[[scene.building]]
name = "A"
mass = [28000.0, 24000.0, 21000.0]
stiffness = [3.4e7, 2.9e7, 2.2e7]
damping_ratio = 0.04
base = { mass = 16000.0, mu = 0.06, radius = 2.2 }

[[scene.building]]
name = "C"
mass = [45000.0, 35000.0]
stiffness = [2.2e7, 1.6e7]
damping_ratio = 0.03

[[scene.contact]]
between = [["A", 2], ["C", 2]]
gap = 0.01
law = "hertz_damp"
stiffness = 2.75e9
restitution = 0.7

[grid]
gap = [0.005, 0.02, inf]
mu = { values = [0.06, inf], buildings = ["A"] }

[synthetic.kt]
type = "kanai_tajimi"
count = 6
seed = 5
omega_g = 12.0
zeta_g = 0.5
pga = 4.0
envelope = "jennings"
duration = 4.0
dt = 0.02
"""
#: Quantities of either sign: their Student-t bounds may be negative (column labels of the report's tables).
SIGNED = ("skewness", "excess", "correlation", "residual sliding")


@pytest.fixture(scope="module")
def store(tmp_path_factory) -> Path:
    return run_in_process(tmp_path_factory.mktemp("pendulum"), "pendulum", EXPERIMENT)


@pytest.fixture(scope="module")
def built(store, tmp_path_factory):
    report = assemble_report([store])
    return report, write_report(report, tmp_path_factory.mktemp("out"))


def _text(section) -> str:
    return "\n".join(block.text if isinstance(block, Paragraph) else f"{block.caption}\n{block.note}\n{block.frame.to_csv()}" if isinstance(block, Table)
                     else block.caption for block in section.blocks)


def test_the_summary_comes_first_with_its_answers(built):
    report, written = built
    summary = report.sections[0]
    assert summary.title == "Summary" and report.sections[1].title == "About this report" and report.sections[-1].key == "appendix"
    text = _text(summary)
    assert "How wide must the gap be?" in text and "for P(pounding) = 5%" in text and "for P(pounding) = 1%" in text
    assert "How likely is pounding at the grid's gaps?" in text and re.search(r"Details: section \d+ \(Experiment pendulum\)", text)
    html = written["html"].read_text()
    assert html.index('<section id="summary">') < html.index('<section id="about">')
    contents = html[html.index('<nav class="toc"'):html.index("</nav>")]
    assert "Summary" in contents and "Figure 1" not in contents and "Table 1" not in contents  # section titles, not bare labels


def test_abs_bounds_the_peak_closure_on_every_contact_free_run(store):
    with open_store(store) as ds:
        free = ds.sel(gap=np.inf)
        done = (free.case_status == 1).broadcast_like(free.peak_contact_closure)
        assert int(done.sum()) == 2 * 6  # mu x realizations
        gaps = separation_rules(store_contact_demands(free)).sel(rule="abs")
        assert bool(((gaps >= free.peak_contact_closure) | ~done).all())


def test_no_negative_bound_of_a_non_negative_quantity_in_any_table_or_csv(built):
    report, written = built
    checked = 0
    for table in report.tables():
        frames = [table.frame, pd.read_csv(written["tables"] / f"{table.key}.csv", header=[0, 1] if table.frame.columns.nlevels == 2 else 0)]
        for frame in frames:
            for column in frame.columns:
                label = column if isinstance(column, tuple) else (str(column), str(column))
                if label[-1] in ("lower", "lower bound") and not any(word in str(label[0]) for word in SIGNED):
                    values = pd.to_numeric(frame[column], errors="coerce")
                    assert not (values < 0).any(), (table.key, label)
                    checked += int(values.notna().sum())
    assert checked > 0
    # and the quantities of either sign keep their Student-t bounds: the check above exempts only those
    displacements = next(t for t in report.tables() if t.key.endswith("-kt-displacements")).frame
    assert ("residual sliding (cm)", "lower") in displacements.columns


def test_methods_name_the_law_that_ran_with_its_units_and_no_other(built):
    """The law registry (branch ``laws``) describes each law by its name, parameters and units; this checks its wording only for the law's name and unit."""
    pytest.importorskip("stochpound.model.laws", reason="the law registry describes the laws in methods")
    report, _ = built
    methods = _text(next(s for s in report.sections if s.key == "methods"))
    assert "Hertz" in methods and "N/m^1.5" in methods
    assert "Kelvin" not in methods


def test_no_wall_wording_without_walls(built):
    """A store without walls has no penetration column, and no caption or sentence speaks of walls' penetration."""
    report, written = built
    text = "\n".join(_text(section) for section in report.sections)
    assert not re.search(r"penetration of a wall|wall penetration|walls were penetrated|peak_wall_penetration", text, re.IGNORECASE)
