"""The moat's clearance as a gap axis over walls: P(wall hit | c) from the wall-free runs, the clearance for a target, in the report."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from stochpound.analysis import pounding_curve, pounding_probability
from stochpound.experiment import open_store
from stochpound.store import contact_free, has_contact_free, has_wall_free, wall_free, wall_gap_dims, with_walls
from stochpound.report.assemble import assemble_report
from stochpound.report.render._document import FigureItem, Paragraph, Table
from stochpound.report.sections._mechanism_findings import mechanism_answer
from stochpound.store import wall_axis
from tests.helpers import run_in_process

ROOT = Path(__file__).resolve().parents[1]
COUNT = 40


@pytest.fixture(scope="module")
def moat(tmp_path_factory) -> Path:
    """experiments/laws/moat_wall.toml with 40 realizations instead of 200 (every other value the file's)."""
    text = (ROOT / "experiments" / "laws" / "moat_wall.toml").read_text()
    assert text.count("count = 200") == 1
    return run_in_process(tmp_path_factory.mktemp("moat"), "moat_wall", text.replace("count = 200", f"count = {COUNT}"))


@pytest.fixture(scope="module")
def report(moat):
    return assemble_report([moat])


def _text(section) -> str:
    return "\n".join(block.text if isinstance(block, Paragraph) else f"{block.caption}\n{block.note}\n{block.frame.to_csv()}" if isinstance(block, Table)
                     else block.caption for block in section.blocks)


def test_a_gap_axis_over_walls_is_a_wall_axis_not_contact_free(moat):
    with open_store(moat) as store:
        assert wall_gap_dims(store) == ["gap_wall"] and store["gap_wall"].attrs["sets"] == "walls"
        assert has_wall_free(store) and not has_contact_free(store)
        assert contact_free(store).sizes == store.sizes  # no contact axis: nothing selected away
        assert wall_free(store).sizes.get("gap_wall") is None and list(with_walls(store)["gap_wall"].values) == [0.1, 0.2, 0.3, 0.4]
        assert wall_axis(store) == ("gap_wall", np.inf)
        closure = wall_free(store)["largest_wall_closure"]
        assert bool((closure > 0).all()) and bool((wall_free(store)["peak_wall_penetration"] == 0).all())


def test_the_wall_free_runs_give_the_hits_at_every_finite_clearance(moat):
    """P(wall hit | c) = P(D ≥ c) from the wall-free runs against the runs at c: per run, and the fraction within its interval."""
    with open_store(moat) as store:
        demand = wall_free(store)["largest_wall_closure"].load()
        walled = with_walls(store)
        hit = (walled["peak_wall_penetration"] > 0).load()
        clearances = xr.DataArray(walled["gap_wall"].values, dims="gap_wall", coords={"gap_wall": walled["gap_wall"].values})
        assert bool((hit == (demand >= clearances)).all())  # run by run, the same realization
        assert bool((hit == (walled["impacts"] > 0)).all())  # no contacts: every impact is a wall's
        curve = pounding_curve(demand, clearances.values, contact_dim=None).rename(gap="gap_wall").assign_coords(gap_wall=clearances.values)
        observed = pounding_probability(walled["peak_wall_penetration"])["probability"]
        assert bool(((observed >= curve["lower"]) & (observed <= curve["upper"])).all())
        assert float(observed.min()) > 0.0 and bool((curve["probability"].sel(gap_wall=0.1) >= curve["probability"].sel(gap_wall=0.4)).all())


def test_the_summary_answers_the_moat_question_first(report, moat):
    summary = report.sections[0]
    first = summary.blocks[1].text
    assert first.startswith("How likely is the moat wall hit at each clearance c, and what clearance keeps it rare?")
    assert f"({COUNT} wall-free realizations in each of 2 cells" in first
    for clearance in ("10 cm", "20 cm", "30 cm", "40 cm"):
        assert re.search(rf"{clearance}: [0-9.–]+ \(upper bound [0-9.–]+; runs there [0-9.–]+\)", first)
    assert re.search(r"P\(wall hit\) ≤ 5% needs a clearance of [0-9.]+(–[0-9.]+)? cm", first) and "P(wall hit) ≤ 1% needs a clearance of" in first
    assert "How wide must the gap be?" not in _text(summary)  # no contacts: no separation between buildings
    with open_store(moat) as store:
        demand = wall_free(store)["largest_wall_closure"].load()
        for mu in (0.05, 0.12):
            at = pounding_curve(demand.sel(mu=mu), [0.1, 0.2, 0.3, 0.4], contact_dim=None)["probability"].values.ravel()
            for value in at:
                assert f"{value:.3f}" in first


def test_the_clearance_section_and_its_figure_against_the_clearance(report):
    section = next(s for s in report.sections if s.key == "clearance-moat_wall")
    text = _text(section)
    assert "every one hits a wall exactly when D ≥ c" in text
    assert re.search(r"runs at those clearances hit a wall in a fraction within its 95% Clopper–Pearson interval in (\d+) of \1 cells?", text)
    assert "P(wall hit) = 5% needs a clearance of" in text and "ABS" not in text and "SRSS" not in text
    curve = next(b for b in section.blocks if isinstance(b, FigureItem) and b.key.endswith("clearance-curve"))
    axes = curve.figure.axes[0]
    assert axes.get_xlabel() == "clearance c (cm)" and axes.get_ylabel() == "P(wall hit)"
    assert max(float(line.get_xdata().max()) for line in axes.get_lines() if len(line.get_xdata())) > 40.0  # in cm, beyond the grid's 40 cm
    experiment = next(s for s in report.sections if s.key == "experiment-moat_wall")
    assert "gap_wall (5: 4 clearances here and the wall-free one of the Moat clearance section)" in _text(experiment)
    assert "pounding" not in _text(experiment)
    figure = next(b for b in experiment.blocks if isinstance(b, FigureItem) and b.key.endswith("gap_wall"))
    assert figure.figure.axes[0].get_xlabel() == "gap_wall (cm)" and figure.figure.axes[0].get_ylabel() == "P(wall hit)"
    assert "The probability of a wall hit falls as gap_wall widens" in _text(experiment) and "A wall hit becomes rare" in _text(experiment)


def test_the_mechanisms_speak_of_a_wall_not_of_pounding(report, moat):
    with open_store(moat) as store:
        answer = mechanism_answer("moat_wall", store)
        largest = float(with_walls(store)["peak_wall_penetration"].max())
    assert "a wall raises the peak floor acceleration in" in answer and "pounding" not in answer and "ratchets" not in answer
    assert f"the walls were penetrated by up to {largest * 100:.3g} cm" in answer
    experiment = _text(next(s for s in report.sections if s.key == "experiment-moat_wall"))
    assert "over the same motion with the walls never reached (gap_wall = ∞)" in experiment
    assert "Amplification of the peak floor acceleration by a wall" in experiment and "by pounding" not in experiment
    assert "Ratcheting" not in experiment and "contact-free" not in experiment
    assert "the largest per value of gap_wall: 10 cm:" in experiment


def test_the_risk_section_s_moat_clearances_are_the_gap_axis_s():
    """With a hazard, the moat-wall limit state is judged at the clearances the gap axis sets (not the walls' own placeholder gap)."""
    from stochpound.experiment._spec import load_definition
    from stochpound.risk._inputs import moat_clearances
    from stochpound.store import canonical_json

    definition, _ = load_definition(ROOT / "experiments" / "laws" / "moat_wall.toml")
    assert [w["gap"] for w in definition["scene"]["wall"]] == [0.1, 0.1]
    store = xr.Dataset(attrs={"definition": canonical_json(definition)})
    assert moat_clearances(store, "B1") == [0.1, 0.2, 0.3, 0.4]
    assert moat_clearances(store, "B2") == []


def test_the_per_cell_tables_of_a_walls_only_store_name_wall_hits(report):
    tables = [b for s in report.sections for b in s.blocks if isinstance(b, Table) and b.key.startswith("table-moat_wall-") and b.key.endswith("-pounding")]
    assert tables
    for table in tables:
        heads = {str(column[0]) for column in table.frame.columns}
        assert "P(wall hit)" in heads and "P(pounding)" not in heads
        assert not any("phase" in head for head in heads) and "peak wall force, given a wall hit (kN)" in heads
        assert "wall hit" in table.caption and "pounding" not in table.caption and "P(pounding)" not in table.note


def test_the_clearance_table_s_footnote_states_the_rule_its_empty_bounds_follow(report):
    """Table 11's footnote said pⁿ for the upper bound; it is (1 − p)ⁿ: the bound is empty exactly where that exceeds (1 − c)/2."""
    tables = [b for s in report.sections for b in s.blocks if isinstance(b, Table) and b.key.endswith("-clearance")]
    assert tables
    for table in tables:
        assert "the upper bound needs (1 − p)ⁿ ≤ 0.025, the lower bound pⁿ ≤ 0.025" in table.note
        frame = table.frame
        n = frame[("realizations", "n")].to_numpy(dtype=float)
        heads = {h for h, _ in frame.columns if h.startswith("clearance for P(wall hit) = ")}
        assert len(heads) >= 2
        for head in heads:
            p = float(re.search(r"= ([0-9.]+) \(cm\)", head).group(1))
            np.testing.assert_array_equal(np.isnan(frame[(head, "upper")].to_numpy(dtype=float)), (1 - p) ** n > 0.025)
            np.testing.assert_array_equal(np.isnan(frame[(head, "lower")].to_numpy(dtype=float)), p**n > 0.025)
