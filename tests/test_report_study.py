"""The study report built from small versions of the study's experiments (experiments/study/, shortened).

The experiments are the committed definitions with shorter motions and a
coarser gap grid, run in-process; the report must carry every study table
with the study's rows and columns, our numbers taken from the stores, every
figure, the findings and the methods, in HTML and PDF.
"""

import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from stochpound.experiment import load_experiment, open_store, run_experiment
from stochpound.store import canonical_json
from stochpound.report.assemble import assemble_report
from stochpound.report.sections._generic import AGAINST
from stochpound.report.render.output import write_report
from stochpound.studies.agarwal2004._published import published_tables
from stochpound.studies.agarwal2004._tables import CORRECTED, DIFFERENCE, SPLINE, STUDY, STUDY_EQUATIONS
from tests.chromium import render_in_chromium, require_chromium

pytestmark = pytest.mark.slow  # builds the study report from every study experiment (about two minutes)

STUDY_DIR = Path(__file__).resolve().parents[1] / "experiments" / "study"
DURATION = 6.0  # s of every record
STATISTICS = ["mean (cm)", "variance (cm²)", "std (cm)", "skewness", "excess", "impacts"]
MU_COLUMNS = ["single building", "μ = ∞", "μ = 0.5", "μ = 0.4", "μ = 0.3", "μ = 0.2", "μ = 0.1"]


def _shorten(text: str) -> str:
    text = re.sub(r'^(record = "[^"]+")$', rf"\1\nduration = {DURATION}", text, flags=re.MULTILINE)
    text = re.sub(r"^duration = 15\.0.*$", "duration = 3.0", text, flags=re.MULTILINE)
    return re.sub(r"^gap = \[0\.0, 0\.005.*\]$", "gap = [0.0, 0.01, 0.02, 0.08]", text, flags=re.MULTILINE)


@pytest.fixture(scope="module")
def study_stores(tmp_path_factory) -> list[Path]:
    folder = tmp_path_factory.mktemp("study")
    shutil.copytree(STUDY_DIR / "scenes", folder / "scenes")
    stores = []
    for source in sorted(STUDY_DIR.glob("*.toml")):
        (folder / source.name).write_text(_shorten(source.read_text()))
        report = run_experiment(load_experiment(folder / source.name), workers=0, progress=False)
        assert report.complete and not report.failed
        stores.append(report.store)
    return stores


@pytest.fixture(scope="module")
def built(study_stores, tmp_path_factory):
    report = assemble_report(study_stores)
    tables = {table.key: table for table in report.tables()}
    figures = {item.key: item.caption for item in report.figures()}
    figure_items = {item.key: item for item in report.figures()}
    paragraphs = [block.text for section in report.sections for block in section.blocks if hasattr(block, "text")]
    sections = [section.title for section in report.sections]
    findings = [block.text for section in report.sections if section.key == "findings" for block in section.blocks]
    out = tmp_path_factory.mktemp("report")
    written = write_report(report, out)
    return {"tables": tables, "figures": figures, "figure_items": figure_items, "paragraphs": paragraphs, "sections": sections, "findings": findings, "written": written, "out": out}


def test_every_study_experiment_is_shortened_and_complete(study_stores):
    names = {str(open_store(path).attrs["experiment_name"]) for path in study_stores}
    assert names == {"study_harmonic", "study_gap", "study_single", "study_pair_mu", "study_pair_records"}
    gap = open_store(next(p for p in study_stores if p.stem == "gap_study"))
    assert gap["time"].values[-1] <= DURATION


def test_every_table_is_there_in_the_study_layout(built):
    tables = built["tables"]
    expected = {"table-3.2", "table-3.3", "table-scaling", "table-records", "table-4.9-4.10", *(f"table-4.{n}" for n in range(1, 9)), "table-buildings", "table-contacts", "table-motions"}
    assert set(tables) == expected
    for number in ("4.1", "4.3", "4.5", "4.7"):
        frame = tables[f"table-{number}"].frame
        assert list(frame.columns) == MU_COLUMNS
        assert list(frame.index.get_level_values(0).unique()) == STATISTICS
        assert list(frame.loc["std (cm)"].index) == [STUDY, CORRECTED, DIFFERENCE, SPLINE, STUDY_EQUATIONS]
    for number in ("4.2", "4.4", "4.6", "4.8"):
        frame = tables[f"table-{number}"].frame
        assert frame.shape == (16, 6)
        assert [label.split(",")[0] for label in frame.index.get_level_values(0).unique()] == [
            "Mexico City 1985", "El Centro 1940", "Loma Prieta 1989 (substitute)", "Northridge 1994 (substitute)"]
    correlation = tables["table-4.9-4.10"].frame
    assert correlation.shape == (20, 4)
    assert tables["table-3.2"].frame.shape == (8, 7)


def test_tables_carry_the_study_and_the_stores_numbers(built, study_stores):
    frame = built["tables"]["table-4.3"].frame
    published = published_tables()["table"]["4.3"]
    np.testing.assert_allclose(frame.loc[("std (cm)", STUDY)].values, published["std"])
    pair = open_store(next(p for p in study_stores if p.stem == "pair_mu"))
    case = {"isolation": "b1_isolated", "neighbour": "flexible", "model": "corrected", "gap": 0.02, "record": "el_centro", "realization": 0}
    ours = pair["response_std"].sel(case).sel(mu=[0.5, 0.4, 0.3, 0.2, 0.1]).values * 100
    np.testing.assert_allclose(frame.loc[("std (cm)", CORRECTED)].values[2:], ours)
    assert frame.loc[("std (cm)", CORRECTED), "single building"] == pytest.approx(float(pair["reference_response_std"].sel(record="el_centro", realization=0)) * 100)
    np.testing.assert_allclose(frame.loc[("std (cm)", DIFFERENCE)].values, frame.loc[("std (cm)", CORRECTED)].values - np.asarray(published["std"]))
    assert np.isnan(frame.loc[("impacts", CORRECTED), "single building"])
    compat = pair["impacts"].sel(case | {"model": "study_compat", "record": "el_centro"}).sel(mu=0.4)  # the same (linear) input as "corrected model"
    assert frame.loc[("impacts", STUDY_EQUATIONS), "μ = 0.4"] == float(compat)


def test_every_figure_is_written_and_named(built):
    expected = {"northridge-sliding", "3.2", "3.3", "3.4", "3.6", "3.7", "3.8", "3.9", "4.1", "4.2", "4.3", "4.4", "4.5", "4.6",
                "4.8-4.15-b1_isolated", "4.8-4.15-both_isolated", "4.16-4.17", "4.18", "4.19", "4.20"}
    assert set(built["figures"]) == {f"figure-{n}" for n in expected}
    for key in built["figures"]:
        png = built["out"] / "figures" / f"{key}.png"
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 5000
    substitute_captions = [c for c in built["figures"].values() if "Loma Prieta" in c or "four records" in c]
    assert substitute_captions and all("substitute" in c for c in substitute_captions)


def _verdict(holds: bool) -> str:
    return "Holds" if holds else "Does not hold"


def _numbers(pattern: str, text: str) -> list[float]:
    match = re.search(pattern, text)
    assert match, pattern
    return [float(group) for group in match.groups()]


def test_findings_and_methods_are_written_from_the_numbers(built, study_stores):
    """Each finding's verdict is the one its data give: recomputed from the stores, or from the numbers the finding states."""
    assert built["sections"][:3] == ["Summary", "About this report", "Findings"]
    assert built["sections"][-1] == "Methods"
    assert len(built["findings"]) == 7
    finding = {text.split(":")[0]: text for text in built["findings"]}
    stores = {p.stem: open_store(p) for p in study_stores}
    # out-of-phase against in-phase impacts, summed over every El Centro case (corrected model) of the gap and μ studies
    gap_study = stores["gap_study"].sel(record="el_centro")
    pair = stores["pair_mu"].sel(record="el_centro", model="corrected")
    in_phase = float(gap_study["impacts_in_phase"].sum() + pair["impacts_in_phase"].sum())
    out_of_phase = float(gap_study["impacts_out_of_phase"].sum() + pair["impacts_out_of_phase"].sum())
    text = finding["Out-of-phase impacts outnumber in-phase ones"]
    assert text.startswith(f"Out-of-phase impacts outnumber in-phase ones: {_verdict(out_of_phase > in_phase)} ({out_of_phase:.0f} out-of-phase against {in_phase:.0f} in-phase")
    # impacts fall with the gap, faster (sooner to zero) for a stiff neighbour
    fixed = gap_study.sel(mu=np.inf)
    if "realization" in fixed.dims:
        fixed = fixed.isel(realization=0)
    impacts = {n: fixed["impacts"].sel(neighbour=n).values for n in ("stiff", "flexible")}
    last = {n: float(fixed["gap"].values[np.flatnonzero(v > 0)[-1]]) if (v > 0).any() else 0.0 for n, v in impacts.items()}
    falling = all(v[0] >= v[-1] for v in impacts.values()) and last["stiff"] < last["flexible"]
    assert finding["Impacts fall as the gap widens, faster for a stiff neighbour"].startswith(f"Impacts fall as the gap widens, faster for a stiff neighbour: {_verdict(falling)}.")
    # very small gaps: each neighbour's stated peak against the building alone
    text = finding["Very small gaps raise Building 1's peak displacement"]
    raised = [a > b for a, b in re.findall(r"at most ([0-9.]+) cm at gaps ≤ 1 cm against ([0-9.]+) cm alone", text)]
    assert len(raised) == 2
    expected = _verdict(all(raised)) if all(raised) or not any(raised) else "Holds for the"
    assert text.startswith(f"Very small gaps raise Building 1's peak displacement: {expected}")
    # the worst case: more impacts and a peak at least as large with one building isolated, then record by record
    text = finding["One isolated building next to a fixed one is the worst case, and both isolated pound least"]
    one_impacts, one_peak, both_impacts, both_peak = _numbers(
        r"has ([0-9]+) impacts in all and a largest top-floor displacement of ([0-9.]+) cm; with both isolated, ([0-9]+) impacts and ([0-9.]+) cm", text)
    assert f"under El Centro, {_verdict(one_impacts > both_impacts and one_peak >= both_peak)}." in text
    # record by record: a tie is "no difference", a verdict only when it keeps its sign with the record scaled by 0.98 and 1.02
    assert not re.search(r"holds \((\d+) against \1 impacts", text)
    for verdict, one, both, noise in re.findall(r"gap [0-9.]+ cm: (holds|does not hold|not distinguishable|no difference) \(([0-9]+) against ([0-9]+) impacts(?:; ([^)]*))?\)", text):
        if verdict == "no difference":
            assert one == both
            continue
        assert "× 0.98" in noise and "× 1.02" in noise
        scaled = [(int(x), int(y)) for x, y, _ in re.findall(r"([0-9]+) against ([0-9]+) at × ([0-9.]+)", noise)]
        signs = {np.sign(float(one) - float(both)), *(np.sign(x - y) for x, y in scaled)}
        if verdict == "not distinguishable":
            assert len(signs) > 1
        else:
            assert len(signs) == 1 and verdict == _verdict(float(one) > float(both)).lower()
    # the correlation collapses at each μ where every correlation is below 0.1 in magnitude, and the text says where
    text = finding["Correlation with the fixed-base response collapses once sliding acts"]
    collapsed = []
    for verdict, mu, low, high in re.findall(r"(holds|does not hold) at μ = ([0-9.]+) \(ours (-?[0-9.]+) to (-?[0-9.]+),", text, flags=re.I):
        assert verdict.lower() == _verdict(max(abs(float(low)), abs(float(high))) < 0.1).lower()
        collapsed += [mu] if verdict.lower() == "holds" else []
    assert re.search(r"It collapses \(every \|correlation\| below 0\.1; [^)]*\) (at every μ|only at μ = [\d. and,]+|at none of these μ)", text)
    assert ("at none of these μ" in text) == (not collapsed)
    # the fixed columns: their deviation from the study stated per input (the verdict "reproduced" is not derived from it: on these
    # 6 s records it is tens of per cent); the isolated columns: their sign changes counted
    text = finding["The single fixed-base building and the fixed–fixed (μ = ∞) columns of Tables 4.1 and 4.3 are reproduced"]
    assert len(re.findall(r"with (?:linear|spline) input within [0-9.]+ %", text)) == 2
    flipped, cells = _numbers(r"changes sign in ([0-9]+) of the ([0-9]+) columns", finding["The study's isolated columns (μ ≤ 0.5) are not reproduced and should not be"])
    assert 0 < flipped <= cells
    html = built["written"]["html"].read_text()
    assert "closed-form modal solution" in html and "DOP853" in html and "energy input" in html


def test_documents_are_written(built):
    pdf = built["written"]["pdf"].read_bytes()
    assert pdf.startswith(b"%PDF")
    pages = len(re.findall(rb"/Type\s*/Page[^s]", pdf))
    assert pages >= 1 + len(built["figures"]) + len(built["tables"])
    html = built["written"]["html"].read_text()
    assert html.count("<table") == len(built["tables"])
    assert html.count("data:image/png;base64,") == len(built["figures"])


def test_a_store_that_is_not_the_study_gets_a_section_of_its_own(study_stores, tmp_path):
    """The study claims a store by its declaration (``reproduces``), not by its name: renamed, it is still the study's;
    without the declaration (a user's grid, or a store written before the field) it gets the generic sections."""
    single = next(p for p in study_stores if p.stem == "single_isolated")
    data = xr.open_dataset(single).load()
    data.attrs["experiment_name"] = "my_grid"
    renamed = tmp_path / "renamed.nc"
    data.to_netcdf(renamed, engine="h5netcdf")
    assert "Single isolated building against μ" in [s.title for s in assemble_report([renamed]).sections]
    definition = json.loads(data.attrs["definition"])
    assert definition.pop("reproduces") == "agarwal2004:single"
    data.attrs["definition"] = canonical_json(definition)
    other = tmp_path / "my_grid.nc"
    data.to_netcdf(other, engine="h5netcdf")
    report = assemble_report([other])
    assert [s.title for s in report.sections] == ["Summary", "About this report", "Experiment my_grid", "Methods", "Appendix: per-cell tables"]
    table = report.sections[-1].blocks[0]  # the per-cell table of the records' cases, in the appendix
    assert table.key == "table-my_grid-records" and table.frame.shape[0] == data.sizes["mu"] * data.sizes["record"]
    assert [f.key for f in report.figures()] == [f"figure-my_grid-{variable}-mu" for variable in AGAINST]


def test_the_study_report_renders_in_headless_chromium(built, tmp_path):
    executable = require_chromium()
    verdict, problems = render_in_chromium(built["written"]["html"], tmp_path / "screenshot.png", executable)
    assert verdict["readyState"] == "complete"
    assert verdict["tables"] == len(built["tables"])
    assert len(verdict["images"]) == len(built["figures"]) and all(width > 0 for width in verdict["images"])
    assert problems == []


def test_figure_3_6_draws_every_located_peak_its_caption_quotes(built, study_stores):
    gap = open_store(next(p for p in study_stores if p.stem == "gap_study"))
    case = {"neighbour": "flexible", "gap": 0.02, "mu": np.inf, "record": "el_centro", "realization": 0}
    impacts = gap.pound.impacts(**case)
    item = built["figure_items"]["figure-3.6"]
    peaks = [line for ax in item.figure.axes for line in ax.lines if line.get_label().startswith("located peaks")]
    assert sum(len(line.get_xdata()) for line in peaks) == impacts.sizes["impact"]
    drawn = max(max(line.get_ydata()) for line in peaks)
    assert drawn == pytest.approx(float(impacts["impact_peak_force"].max()) / 1e3)
    assert f"Largest located peak {drawn:.0f} kN" in item.caption


def test_impact_extremes_are_not_drawn_where_there_is_no_impact(built, study_stores):
    pair = open_store(next(p for p in study_stores if p.stem == "pair_mu"))
    item = built["figure_items"]["figure-4.8-4.15-b1_isolated"]
    force_axes = next(ax for ax in item.figure.axes if ax.get_title() == "peak impact force")
    line = next(line for line in force_axes.lines if line.get_label() == "B2 stiff")
    case = {"isolation": "b1_isolated", "neighbour": "stiff", "model": "corrected", "gap": 0.02, "record": "el_centro", "realization": 0}
    impacts = pair["impacts"].sel(case).sel(mu=[0.1, 0.2, 0.3, 0.4, 0.5]).values
    np.testing.assert_array_equal(np.isnan(line.get_ydata()), impacts == 0)
    assert next(ax for ax in item.figure.axes if ax.get_title() == "longest impact").get_yscale() == "log"


def test_the_northridge_means_and_the_scaling_sensitivity_are_explained_from_the_stores(built, study_stores):
    records = open_store(next(p for p in study_stores if p.stem == "pair_records"))
    case = {"isolation": "b1_isolated", "model": "corrected", "gap": 0.08, "mu": 0.2, "record": "northridge", "realization": 0}
    text = next(t for t in built["paragraphs"] if t.startswith("The largest effect in Tables 4.2–4.4"))
    for neighbour in ("stiff", "flexible"):
        mean = float(records["response_mean"].sel(case | {"neighbour": neighbour})) * 100
        assert f"over the record is {mean:.1f} cm" in text
    scaling = built["tables"]["table-scaling"].frame
    pair = open_store(next(p for p in study_stores if p.stem == "pair_mu"))
    stored = pair["impacts"].sel(isolation="b1_isolated", neighbour="flexible", model="corrected", gap=0.02, mu=0.2, record="el_centro", realization=0)
    assert scaling.loc[("Building 1 isolated", "B2 flexible"), ("× 1", "impacts")] == float(stored)
    worst = next(t for t in built["findings"] if t.startswith("One isolated building"))
    assert all(name in worst for name in ("Mexico City 1985, gap 2 cm", "Northridge 1994 (substitute), gap 8 cm"))
