"""The report of a scenario ensemble on a single line of the grid (a gap axis and nothing else), read as an engineer reads it.

Found in reports/stochastic_scenario (issue 43, item 7): sentences written for many cells counted one cell ("in each of
1 cells", "over the 1 combinations of the grid", "at 20 to 20 cm", "in 0% of the cells", "1 runs"), one ensemble of 200
realizations was "1 motion(s)", the motions' table gave the Kanai–Tajimi PSD convention and said the high-pass corner was
drawn (this calibration fixes it), and it gave the motions no intensity and no limits of validity.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from stochpound.experiment import open_store
from stochpound.report.assemble import assemble_report
from stochpound.report.render._document import Paragraph, Table
from tests.helpers import run_in_process

COUNT = 32  # at least the 30 paired runs a mechanism finding needs
EXPERIMENT = f"""
[experiment]
name = "one_line"
description = "The study's pair, B1 on a friction pendulum, under a scenario ensemble, gaps only"
studied = "B1"

[scene]
g = 9.814

[[scene.building]]
name = "B1"
mass = [26268.0, 17512.0]
stiffness = [24516800.0, 17512000.0]
damping = [23634.2, 16881.57]
base = {{ mass = 13134.0, mu = 0.08, radius = 2.24 }}

[[scene.building]]
name = "B2"
mass = [26268.0, 17512.0]
stiffness = [24516800.0, 17512000.0]
damping = [23634.2, 16881.57]

[[scene.contact]]
between = [["B1", 1], ["B2", 1]]
gap = 0.02
stiffness = 42747262.6
restitution = 0.5

[[scene.contact]]
between = [["B1", 2], ["B2", 2]]
gap = 0.02
stiffness = 28498175.1
restitution = 0.5

[grid]
gap = [0.0, 0.005, 0.03, inf]

[synthetic.quake]
type = "scenario_motions"
magnitude = 7.0
distance_km = 10.0
vs30 = 400.0
mechanism = "strike_slip"
count = {COUNT}
seed = 7
dt = 0.02
duration = 20.0

[output]
demands = true
"""


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    path = run_in_process(tmp_path_factory.mktemp("one_line"), "one_line", EXPERIMENT)
    with open_store(path) as store:
        impacts = store["impacts"].sel(record="quake").load()
    return assemble_report([path]), impacts


def _text(report) -> str:
    parts = []
    for section in report.sections:
        for block in section.blocks:
            if isinstance(block, Paragraph):
                parts.append(block.text)
            elif isinstance(block, Table):
                parts += [block.caption, block.note, block.frame.to_csv()]
            else:
                parts.append(block.caption)
    return "\n".join(parts)


@pytest.mark.slow
def test_one_cell_is_not_counted_as_cells(built):
    text = _text(built[0])
    assert not re.search(r"\b1 (cells|runs|combinations)\b", text), re.search(r".{80}\b1 (cells|runs|combinations)\b.{40}", text)
    assert "of 1 cells" not in text and "of the cells)" not in text and "each of 1 " not in text
    assert not re.search(r"at (\d+(?:\.\d+)?) to \1 cm", text)  # "at 20 to 20 cm"
    assert "motion(s)" not in text and "under 1 synthetic ensemble of 32 realizations" in text


@pytest.mark.slow
def test_the_gap_sentence_gives_the_lines_own_probabilities(built):
    report, impacts = built
    first, last = (float((impacts.sel(gap=g) > 0).mean()) for g in (0.0, 0.03))  # P(pounding) counted here
    trend = "falls" if last < first else "does not fall"
    assert f"The probability of pounding {trend} as gap widens: from {first:.3f} at 0 cm to {last:.3f} at 3 cm." in _text(report)


@pytest.mark.slow
def test_the_scenario_motions_are_described_as_they_ran(built):
    text = _text(built[0])
    assert "PSD convention" not in text and "corner drawn" not in text and "its corner fixed at 0.2 Hz" in text
    assert "Intensity, the median over the 32 motions as run: PGA " in text and "(NGA-West2 average " in text
    assert "Not valid for: near-fault velocity pulses, directivity, basin effects" in text
    assert np.isfinite(float(re.search(r"motions as run: PGA ([\d.]+) g", text).group(1)))
