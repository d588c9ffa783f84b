"""The "Contact laws compared" section: chosen by the stored definition, every law in one panel, prose from the store."""

from __future__ import annotations

import json
import re

import pytest

from stochpound.experiment import load_experiment, open_store, run_experiment
from stochpound.report.sections import _laws as laws_report
from stochpound.analysis import _cell_statistics as cell_statistics, _store_ensemble as store_ensemble
from stochpound.report.assemble import assemble_report
from stochpound.report.render._document import FigureItem, Paragraph
from tests.helpers import write_experiment

REALIZATIONS = 5
EXPERIMENT = f"""
[experiment]
name = "pair_elements"
description = "An isolated building next to a fixed one, two contact laws"
studied = "B1"

[scene]
g = 9.81

[[scene.building]]
name = "B1"
mass = [26268.0, 17512.0]
stiffness = [24516800.0, 17512000.0]
damping = [23634.2, 16881.57]
base = {{ mass = 13134.0, mu = 0.1 }}

[[scene.building]]
name = "B2"
mass = [26268.0, 17512.0]
stiffness = [24516800.0, 17512000.0]
damping = [23634.2, 16881.57]

[[scene.contact]]
between = [["B1", 1], ["B2", 1]]
gap = 0.01
stiffness = 3.525e8
restitution = 0.5

[[scene.contact]]
between = [["B1", 2], ["B2", 2]]
gap = 0.01
stiffness = 3.25e8
restitution = 0.5

[variants.element.linear]

[variants.element.hertzian.contact]
law = "hertz_damp_exact"
stiffness = 2.75e8                      # N/m^1.5: softer than concrete (2.75e9) to keep the ivp runs of this test short
restitution = 0.5

[grid]
gap = [0.0, 0.01]

[synthetic.kt]
type = "kanai_tajimi"
count = {REALIZATIONS}
seed = 7
omega_g = 15.0
zeta_g = 0.6
pga = 4.0
envelope = "jennings"
duration = 1.5                           # s: short, for the same reason
dt = 0.02

[output]
demands = true
"""


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    folder = tmp_path_factory.mktemp("lawreport")
    report = run_experiment(load_experiment(write_experiment(folder, EXPERIMENT, "pair_elements.toml")), workers=0, progress=False)
    assert report.complete and not report.failed
    return open_store(report.store)


def test_the_law_axis_is_read_from_the_definition_not_the_name(store):
    assert laws_report.law_axis(store) == "element"
    assert laws_report.variant_laws(store.pound.definition, "element") == {"linear": "kelvin", "hertzian": "hertz_damp_exact"}
    assert laws_report.law_axis(store.sel(element=["linear"])) is None  # one law left: nothing to compare
    titles = [section.title for section in assemble_report([store.encoding["source"]]).sections]
    assert "Contact laws compared: experiment pair_elements" in titles


def test_every_law_is_in_the_same_panel_and_the_prose_names_the_largest_force_with_its_n(store, monkeypatch):
    for module in (laws_report, store_ensemble, cell_statistics):  # the section's text and the statistics it is handed
        monkeypatch.setattr(module, "MIN_RUNS", 3)
    section = laws_report.laws_section("pair_elements", store)
    figures = [b for b in section.blocks if isinstance(b, FigureItem)]
    assert [f.key.rsplit("-", 1)[1] for f in figures] == ["pounding", "peak_impact_force", "impacts", "peak_floor_acceleration"]
    for figure in figures:
        panels = [ax for ax in figure.figure.axes if ax.get_visible()]
        assert len(panels) == 1
        gids = {line.get_gid() for line in panels[0].get_lines()}
        assert {json.loads(g.split(":", 1)[1])["element"] for g in gids} == {"linear", "hertzian"}
    force = next(b.text for b, previous in zip(section.blocks[1:], section.blocks) if isinstance(b, Paragraph) and previous.key.endswith("peak_impact_force"))
    impacts, peaks = store["impacts"].sel(record="kt").load(), store["peak_impact_force"].sel(record="kt").load()
    checked = 0
    for gap in (0.0, 0.01):
        means = {law: peaks.sel(element=law, gap=gap).where(impacts.sel(element=law, gap=gap) > 0) for law in ("linear", "hertzian")}
        counts = {law: int(m.notnull().sum()) for law, m in means.items()}
        if min(counts.values()) < 3:
            continue
        largest = max(means, key=lambda law: float(means[law].mean()))
        value = float(means[largest].mean()) / 1e3
        assert re.search(rf"gap {gap * 100:g} cm, {largest} gives the largest mean peak impact force of the runs that pounded, "
                         rf"{value:.3g} kN \[[0-9.]+, [0-9.]+\] \(n = {counts[largest]}\)", force), force
        checked += 1
    assert checked, "no gap with enough pounding runs of both laws"
    bounds = [float(x) for x in re.findall(r"\[(-?[0-9.e+]+), (-?[0-9.e+]+)\]", " ".join(b.text for b in section.blocks if isinstance(b, Paragraph))) for x in x]
    assert bounds and min(bounds) >= 0.0
