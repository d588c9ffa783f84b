"""The report of a store that is not the study's: methods from its own definition, ensemble statistics, every cell drawn.

The experiment deliberately differs from the reference study in every value
the study's report used to state as fixed text: three storeys next to two,
5 % damping, restitution 0.8, non-tensile contacts, g = 9.81.
"""

import re
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

from stochpound.analysis import ensemble_statistics
from stochpound.experiment import open_store
from stochpound.report.assemble import assemble_report
from stochpound.report.render._document import FigureItem, Paragraph, Table
from stochpound.report.sections._facets import cell_gid
from stochpound.report.render.output import write_report
from tests.chromium import render_in_chromium, require_chromium
from tests.helpers import run_in_process

REALIZATIONS = 6
EXPERIMENT = f"""
[experiment]
name = "unusual"
description = "Three storeys next to two, non-tensile contacts"
studied = "A"

[scene]
g = 9.81

[[scene.building]]
name = "A"
mass = [30000.0, 25000.0, 20000.0]
stiffness = [3.0e7, 2.5e7, 2.0e7]
damping_ratio = 0.05
base = {{ mass = 15000.0, mu = 0.1 }}

[[scene.building]]
name = "C"
mass = [40000.0, 30000.0]
stiffness = [2.0e7, 1.5e7]
damping_ratio = 0.05

[[scene.contact]]
between = [["A", 1], ["C", 1]]
gap = 0.01
stiffness = 8.0e7
restitution = 0.8
tensile = false

[[scene.contact]]
between = [["A", 2], ["C", 2]]
gap = 0.01
stiffness = 6.0e7
restitution = 0.8
tensile = false

[grid]
gap = [0.0, 0.01, 0.03]
mu = {{ values = [0.08, inf], buildings = ["A"] }}

[[records]]
name = "el_centro"
record = "el_centro_1940"
duration = 4.0

[synthetic.kt]
type = "kanai_tajimi"
count = {REALIZATIONS}
seed = 11
omega_g = 12.0
zeta_g = 0.5
pga = 4.0
envelope = "jennings"
duration = 4.0
dt = 0.02
"""
#: The reference study's values that the old fixed methods text stated for every store.
STUDY_DEFAULTS = ("57.05", "ζ1 = 1 %", "restitution 0.5", "study_compat", "tensile (separates when the penetration", "9.814", "26268", "El Centro 1940 (the study")


@pytest.fixture(scope="module")
def store(tmp_path_factory) -> Path:
    return run_in_process(tmp_path_factory.mktemp("unusual"), "unusual", EXPERIMENT)


@pytest.fixture(scope="module")
def built(store, tmp_path_factory):
    report = assemble_report([store])
    written = write_report(report, tmp_path_factory.mktemp("out"))
    return report, written


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


def test_methods_state_the_stores_values_and_none_of_the_studys(built):
    report, written = built
    methods = next(s for s in report.sections if s.key == "methods")
    text = _text(report)
    html = written["html"].read_text()
    for default in STUDY_DEFAULTS:
        assert default not in text and default not in html, default
    buildings = next(b for b in methods.blocks if isinstance(b, Table) and b.key == "table-buildings").frame
    assert set(buildings["floors"]) == {"3", "2"}
    assert all("ζ1 = 5 %" in damping for damping in buildings["damping"])
    assert any("μ = μ_s ∈ {0.08} or fixed" in base for base in buildings["base"])
    contacts = next(b for b in methods.blocks if isinstance(b, Table) and b.key == "table-contacts").frame
    assert all(law.startswith("Kelvin–Voigt, k = ") and law.endswith("from e = 0.8") for law in contacts["law"])
    assert all(rule.startswith("non-tensile") for rule in contacts["separation"])
    assert all(gap == "{0, 0.01, 0.03} (axis gap)" for gap in contacts["gap (m)"])
    motions = next(b for b in methods.blocks if isinstance(b, Table) and b.key == "table-motions").frame
    kt = motions[motions["motion"] == "kt"].iloc[0]
    assert "ω_g = 12 rad/s, ζ_g = 0.5" in kt["definition"] and "expected PGA 4 m/s²" in kt["definition"] and "jennings" in kt["definition"]
    assert kt["realizations"] == f"{REALIZATIONS} (indices 0–{REALIZATIONS - 1}), seed 11"
    assert "el_centro_1940" in motions[motions["motion"] == "el_centro"].iloc[0]["definition"]
    assert "g = 9.81 m/s²" in text and "linear Kelvin–Voigt, F = k δ + c δ̇" in text


def test_accuracy_is_measured_on_the_stores_own_buildings_and_contacts(built):
    report, _ = built
    paragraphs = [b.text for s in report.sections if s.key == "methods" for b in s.blocks if isinstance(b, Paragraph)]
    modal = next(p for p in paragraphs if "closed-form modal solution" in p)
    assert "A (3 floors, masses 30000, 25000, 20000 kg)" in modal
    assert float(re.search(r"largest difference ([0-9.e+-]+) m", modal).group(1)) < 1e-9
    collision = next(p for p in paragraphs if "single collision" in p)
    assert collision.count("non-tensile") == 2 and "nominal restitution 0.8" in collision
    measured = [float(m) for m in re.findall(r"measured ([0-9]+\.[0-9]+)", collision)]
    expected = [float(m) for m in re.findall(r"closed form ([0-9]+\.[0-9]+)", collision)]
    assert measured == pytest.approx(expected, abs=1e-6) and all(m > 0.8 for m in measured)  # a non-tensile element separates early
    cross = next(p for p in paragraphs if "DOP853" in p)
    assert "unusual" in cross and float(re.search(r"at most ([0-9.e+-]+) m", cross).group(1)) < 1e-8


def _cells(store_path: Path, kind: str) -> set[str]:
    store = open_store(store_path)
    labels = [r for r, k in zip(store["record"].values, store["record_kind"].values) if k == kind]
    cells = set()
    for gap in store["gap"].values:
        for mu in store["mu"].values:
            for record in labels:
                cells.add(cell_gid({"gap": gap, "mu": mu, "record": record}))
    return cells


def _drawn(item: FigureItem) -> set[str]:
    gids = set()
    for ax in item.figure.axes:
        for artist in [*ax.lines, *ax.collections]:
            gid = artist.get_gid() or ""
            gids.update(part for part in gid.split("|") if part.startswith("cell:"))
    return gids


def test_every_figure_draws_every_cell(built, store):
    report, _ = built
    ensemble, records = _cells(store, "synthetic"), _cells(store, "record")
    figures = report.figures()
    kinds = {re.sub(r"^figure-unusual-(kt-)?", "", item.key) for item in figures}
    assert {"pounding-gap", "pounding-mu", "ecdf-peak_total_displacement", "ecdf-peak_sliding_displacement", "ecdf-peak_impact_force",
            "ecdf-fixed_base_correlation"} <= kinds
    assert not any(kind.startswith("convergence") for kind in kinds)  # 6 realizations: no running estimate below MIN_RUNS
    assert {"impacts-gap", "impacts-mu", "peak_total_displacement-gap"} <= kinds
    for item in figures:
        expected = ensemble if "-kt-" in item.key else records
        assert _drawn(item) == expected, item.key


def test_ensemble_tables_cover_every_cell_with_scipys_intervals(built, store):
    report, written = built
    pounding = next(t for t in report.tables() if t.key == "table-unusual-kt-pounding")
    assert len(pounding.frame) == 3 * 2
    data = open_store(store).sel(record="kt")
    impacts = data["impacts"].sel(gap=0.01, mu=0.08).values
    k = int((impacts > 0).sum())
    interval = stats.binomtest(k, REALIZATIONS).proportion_ci(method="exact")
    row = pounding.frame.loc[("1 cm", "0.08")]
    assert row[("P(pounding)", "P")] == pytest.approx(k / REALIZATIONS)
    assert (row[("P(pounding)", "lower")], row[("P(pounding)", "upper")]) == pytest.approx((interval.low, interval.high))
    peaks = data["peak_total_displacement"].sel(gap=0.01, mu=0.08, building="A").values * 100
    displacements = next(t for t in report.tables() if t.key == "table-unusual-kt-displacements").frame.loc[("1 cm", "0.08")]
    bootstrap = stats.bootstrap((peaks,), np.mean, method="percentile", n_resamples=99999, random_state=1).confidence_interval
    width = bootstrap.high - bootstrap.low
    assert displacements[("peak total displacement (cm)", "lower")] == pytest.approx(bootstrap.low, abs=0.06 * width)
    assert displacements[("peak total displacement (cm)", "upper")] == pytest.approx(bootstrap.high, abs=0.06 * width)
    residual = data["residual_sliding"].sel(gap=0.01, mu=0.08, building="A").values * 100  # either sign: Student t
    low, high = stats.t.interval(0.95, REALIZATIONS - 1, residual.mean(), stats.sem(residual))
    assert displacements[("residual sliding (cm)", "lower")] == pytest.approx(low)
    for table in report.tables():
        assert (written["tables"] / f"{table.key}.csv").is_file()


def test_findings_are_computed_from_the_statistics(built, store):
    report, _ = built
    section = next(s for s in report.sections if s.key == "experiment-unusual")
    texts = [b.text for b in section.blocks if isinstance(b, Paragraph)]
    statistics = ensemble_statistics(open_store(store).sel(record="kt")).compute()
    widest = float(((statistics["pounding_probability_upper"] - statistics["pounding_probability_lower"]) / 2).max())
    assert any(f"at most ±{widest:.3f} wide" in text for text in texts)
    assert any("The probability of pounding falls as gap widens" in text for text in texts)
    assert any(text.startswith("A sliding base against the fixed base") for text in texts)


@pytest.mark.slow
def test_the_report_renders_in_headless_chromium(built, tmp_path):
    executable = require_chromium()
    report, written = built
    verdict, problems = render_in_chromium(written["html"], tmp_path / "screenshot.png", executable)
    assert verdict["readyState"] == "complete"
    assert verdict["tables"] == len(report.tables())
    assert len(verdict["images"]) == len(report.figures()) and all(width > 0 for width in verdict["images"])
    assert problems == []
