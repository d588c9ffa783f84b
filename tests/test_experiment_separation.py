"""A contact-free axis in an experiment: the store's peak closures answer every gap of the same grid."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from stochpound.analysis import pounding_curve, rule_exceedance, separation_rules, store_contact_demands
from stochpound.experiment import ExperimentError, load_experiment, open_store, run_experiment
from tests.helpers import SMALL_EXPERIMENT, write_experiment

GAPS = (0.0, 0.005, 0.01, 0.02)


def _experiment(folder, gaps: str) -> object:
    text = SMALL_EXPERIMENT.replace("gap = [0.01, 0.02]", f"gap = {gaps}").replace("count = 2", "count = 4")
    text = text.replace('time_histories = ["total_displacement", "impact_force"]', "time_histories = []").replace("[output]", "[output]\nimpacts = true")
    return load_experiment(write_experiment(folder, text))


@pytest.fixture(scope="module")
def contact_free_store(tmp_path_factory):
    """The small experiment with gaps 0, 0.5, 1, 2 cm and contact-free (inf), 4 Kanai-Tajimi realizations and El Centro."""
    report = run_experiment(_experiment(tmp_path_factory.mktemp("free"), f"[{', '.join(map(str, GAPS))}, inf]"), workers=0, progress=False)
    assert report.complete and not report.failed
    return report.store


def test_store_pounds_at_a_gap_exactly_when_the_contact_free_closure_reaches_it(contact_free_store):
    """Every case of a gap grid (fixed and sliding B1, both neighbours, record and ensemble) against its contact-free twin in the same store."""
    with open_store(contact_free_store) as ds:
        done = ds.case_status.sel(gap=np.inf) == 1
        closure = ds.peak_contact_closure.sel(gap=np.inf).max("contact").where(done)
        assert int(done.sum()) == 2 * 2 * (1 + 4)  # neighbours x mu x (record + realizations)
        assert ((ds.impacts.sel(gap=np.inf) == 0) | ~done).all()
        tested = ties = 0
        for gap in GAPS:
            pounded = ds.impacts.sel(gap=gap) > 0
            reaches = closure >= gap
            tie = abs(closure - gap) <= 1e-9
            disagree = (pounded != reaches) & done & ~tie
            assert not disagree.any(), f"gap {gap}: {disagree.sum().item()} cases disagree"
            tested += int((done & ~tie).sum())
            ties += int((done & tie).sum())
        assert tested >= len(GAPS) * int(done.sum()) - 4 and ties <= 4
        assert bool((ds.impacts.sel(gap=0.0) > 0).where(done, True).any()) and bool((ds.impacts.sel(gap=0.02) == 0).where(done, False).any())
        # the separation functions take the store's contact-free cases directly
        free = ds.sel(gap=np.inf, record="kt")
        curve = pounding_curve(free.peak_contact_closure, gaps=list(GAPS))
        counted = (free.peak_contact_closure.max("contact") >= xr.DataArray(list(GAPS), dims="gap")).mean("realization")
        np.testing.assert_array_equal(curve.probability.transpose(*counted.dims).values, counted.values)
        rules = separation_rules(store_contact_demands(free))
        assert set(rules.rule.values) >= {"abs", "srss", "ddc"} and rule_exceedance(free.peak_contact_closure, rules).probability.notnull().all()


def test_abs_bounds_the_peak_closure_on_every_contact_free_run_of_a_store(contact_free_store):
    """u1, u2 and D are located the same way (on the solution), so ABS = u1 + u2 ≥ D on every contact-free case: fixed and sliding, record and ensemble."""
    with open_store(contact_free_store) as ds:
        free = ds.sel(gap=np.inf)
        done = (free.case_status == 1).broadcast_like(free.peak_contact_closure)
        assert int(done.sum()) >= 2 * 2 * (1 + 4)
        rules = separation_rules(store_contact_demands(free))
        closure = free.peak_contact_closure
        assert bool(((rules.sel(rule="abs") >= closure) | ~done).all())
        assert bool(((rules.sel(rule="abs") - closure).where(done) > 0).any())  # a bound, not an identity
        ensemble = free.sel(record="kt")
        exceeded = rule_exceedance(ensemble.peak_contact_closure, separation_rules(store_contact_demands(ensemble)).sel(rule="abs"))
        assert float(exceeded.probability.max()) == 0.0


def test_gap_axis_accepts_inf_and_refuses_negative_and_nan(tmp_path):
    gap = next(d for d in _experiment(tmp_path, '[0.01, "inf"]').dims if d.name == "gap")
    assert gap.values[-1] == np.inf
    for bad, message in (("[-0.01]", "grid.gap[0]: must be >= 0 or inf"), ("[nan]", "grid.gap[0]: must be a number >= 0 or inf (contact-free")):
        try:
            _experiment(tmp_path, bad)
        except ExperimentError as error:
            assert message in str(error)
        else:
            raise AssertionError(f"grid.gap = {bad} was accepted")


def test_report_has_a_separation_section_built_from_the_store(contact_free_store):
    from stochpound.report.assemble import assemble_report
    from stochpound.report.render._document import FigureItem, Paragraph, Table

    report = assemble_report([contact_free_store])
    keys = [section.key for section in report.sections]
    assert "separation-small" in keys and "experiment-small" in keys
    experiment = report.sections[keys.index("experiment-small")]
    assert all("∞" not in getattr(block, "text", "") and "inf cm" not in getattr(block, "text", "") for block in experiment.blocks)
    section = report.sections[keys.index("separation-small")]
    text = " ".join(block.text for block in section.blocks if isinstance(block, Paragraph))
    with open_store(contact_free_store) as ds:
        compared = int((ds.case_status.sel(gap=list(GAPS), record="kt") == 1).sum())
        closure = ds.peak_contact_closure.sel(gap=np.inf, record="kt").max("contact")
        needed = float(closure.max("realization").max()) * 100  # 4 realizations: a cell's 5 % gap is its largest D
    assert f"{compared} runs with contacts were compared" in text and "every one pounds exactly when D ≥ g" in text
    assert "sliding bases" in text and f"{needed:.1f} cm" in text
    assert "ASCE 7 (§17.2.5.2)" in text and "no such theory" not in text and "ABS is never reached" in text
    # §17.2.5.2's scope: the isolated structure against retaining walls and fixed obstructions, not adjacent (moving) structures
    assert "between an isolated structure and the retaining walls or other fixed obstructions around it" in text
    assert "separation from adjacent structures" not in text and "gives no combination rule for a neighbour that moves too" in text
    assert "the grid's own gaps" in text.lower()  # the two answers to the gap question, related
    dimensions = next(block.text for block in experiment.blocks if isinstance(block, Paragraph) and "Dimensions:" in block.text)
    assert f"gap ({len(GAPS) + 1}: {len(GAPS)} gaps here and the contact-free one" in dimensions
    assert not any(isinstance(block, Table) for block in section.blocks)  # its per-cell tables are in the appendix
    appendix = report.sections[-1]
    assert appendix.key == "appendix" and all(isinstance(block, Table) and block.per_cell for block in appendix.blocks)
    assert {"table-small-separation-records", "table-small-kt-separation", "table-small-kt-separation-rules"} <= {block.key for block in appendix.blocks}
    summary = report.sections[0]
    assert summary.key == "summary" and "How wide must the gap be?" in " ".join(b.text for b in summary.blocks if isinstance(b, Paragraph))
    figures = [block for block in section.blocks if isinstance(block, FigureItem)]
    drawn = {artist.get_gid() for item in figures for ax in item.figure.axes for artist in ax.get_children() if artist.get_gid()}
    for neighbour in ("stiff", "flexible"):
        for mu in (0.2, "inf"):
            assert any(f'"mu": {mu if mu == "inf" else mu}' in gid or f'"mu": "{mu}"' in gid for gid in drawn if neighbour in gid)
