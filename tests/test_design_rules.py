"""The codes' own gaps of a scene from its [design] table (against hand computations), and their rows in the risk chain.

The documented example (docs/risk.md, "The codes' own gaps"): two one-storey buildings of 3 m storeys, B1 of period
0.5 s and B2 of 1.0 s, in contact at their roofs; g = 9.81 m/s². A one-storey building's only mode has participation 1,
so its design displacement is S(T) g (T / 2π)².

* ASCE 7-16, S_DS = 1.0 g, S_D1 = 0.6 g (T_S = 0.6 s), R = 8, C_d = 5.5, I_e = 1: B1 on the plateau, S_a = 1.0 g,
  elastic 0.062123 m, δ_M = C_d (0.062123 / (R / I_e)) / I_e = 0.042709 m (eq. 12.12-1); B2 on S_D1 / T = 0.6 g,
  elastic 0.149094 m, δ_M = 0.102502 m; δ_MT = √(0.042709² + 0.102502²) = 0.111044 m (eq. 12.12-2).
* Eurocode 8, a_g = 0.3 g, ground B (S 1.2, T_B 0.15 s, T_C 0.5 s, T_D 2 s), q = 4: B1 on the plateau,
  S_d = a_g S 2.5 / q = 0.225 g, d_e = 0.013978 m, d_s = q d_e = 0.055910 m (eq. 4.23); B2 at T_C / T: S_d = 0.1125 g,
  d_e = 0.027955 m, d_s = 0.111821 m; SRSS 0.125019 m, times 0.7 (roofs at the same height, §4.4.2.7(3)) = 0.087513 m.
* ASCE 7-16 eq. 17.5-1 with B1 on a friction pendulum (μ = 0.05, R = 2.24 m) and S_M1 = 1.2 g: D_M ≈ 0.73 m,
  T_M ≈ 2.80 s, β_M ≈ 8.4 % (B_M ≈ 1.14 by Table 17.5-1): checked as the equation's fixed point, every term recomputed here.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from click.testing import CliRunner

from stochpound.cli import main
from stochpound.experiment import load_experiment, run_experiment
from stochpound.experiment._spec import ExperimentError, parse_experiment
from stochpound.model.scene_file import scene_from_dict
from stochpound.risk import design_separations, risk_curve, store_risk, stripe_fragility
from stochpound.store import Design, definition_sha256, open_store
from tests.helpers import FIXED, REPOSITORY, risk_text, write_experiment

G = 9.81
DESIGN = Design.from_entry({"sds": 1.0, "sd1": 0.6, "tl": 8.0, "r": 8.0, "cd": 5.5, "omega0": 3.0, "ie": 1.0, "sm1": 1.2,
                            "ec8": {"ag": 0.3, "ground": "B", "q": 4.0}})
DESIGN_TABLE = '\n[design]\nsds = 1.0\nsd1 = 0.6\nr = 8.0\ncd = 5.5\nomega0 = 3.0\nec8 = { ag = 0.3, ground = "B", q = 4.0 }\n'


def _building(name: str, period: float, base: dict | None = None) -> dict:
    mass = 1.0e5
    building = {"name": name, "mass": [mass], "stiffness": [mass * (2.0 * math.pi / period) ** 2], "damping_ratio": 0.05, "storey_height": [3.0]}
    return {**building, "base": base} if base else building


def _scene(base: dict | None = None) -> object:
    return scene_from_dict({"g": G, "building": [_building("B1", 0.5, base), _building("B2", 1.0)],
                            "contact": [{"between": [["B1", 1], ["B2", 1]], "gap": 0.05, "stiffness": 1.0e7, "restitution": 0.5}],
                            "motion": {"type": "harmonic", "amplitude": 1.0, "omega": 5.0, "duration": 1.0, "dt": 0.01}})


def test_the_codes_gaps_of_the_documented_example_equal_the_hand_computation():
    gaps = design_separations(_scene(), DESIGN, studied="B1")
    assert sorted(gaps) == ["asce7_delta_mt", "ec8_ds"]  # fixed bases: no eq. 17.5-1
    assert gaps["asce7_delta_mt"][0] == pytest.approx(0.111044, abs=2e-6)
    assert gaps["ec8_ds"][0] == pytest.approx(0.087513, abs=2e-6)
    # the same from the formulas, term by term
    elastic = [sa * G * (t / (2.0 * math.pi)) ** 2 for sa, t in ((1.0, 0.5), (0.6 / 1.0, 1.0))]
    assert gaps["asce7_delta_mt"][0] == pytest.approx(math.hypot(*(5.5 * e / 8.0 for e in elastic)), rel=1e-12)
    ec8 = [sd * G * (t / (2.0 * math.pi)) ** 2 for sd, t in ((0.3 * 1.2 * 2.5 / 4.0, 0.5), (0.3 * 1.2 * 2.5 / 4.0 * 0.5 / 1.0, 1.0))]
    assert gaps["ec8_ds"][0] == pytest.approx(0.7 * math.hypot(*(4.0 * d for d in ec8)), rel=1e-12)


def test_the_eurocode_reduction_applies_only_where_the_floors_stand_level():
    scene = _scene()
    uneven = scene_from_dict({"g": G, "building": [{**_building("B1", 0.5), "storey_height": [3.5]}, _building("B2", 1.0)],
                              "contact": [{"between": [["B1", 1], ["B2", 1]], "gap": 0.05, "stiffness": 1.0e7, "restitution": 0.5}],
                              "motion": {"type": "harmonic", "amplitude": 1.0, "omega": 5.0, "duration": 1.0, "dt": 0.01}})
    level, not_level = design_separations(scene, DESIGN)["ec8_ds"][0], design_separations(uneven, DESIGN)["ec8_ds"][0]
    assert not_level == pytest.approx(0.125019, abs=2e-6) and level == pytest.approx(0.7 * not_level, rel=1e-12)


def test_a_sliding_building_is_designed_by_chapter_17_and_gets_no_section_12_12_3_row():
    """B1 on a friction pendulum (μ = 0.05, R = 2.24 m) beside the fixed B2, S_M1 = 1.2 g given (sm1), S_MS = 1.5 S_DS: the
    separation is D_TM (eq. 17.5-3, lower-bound friction μ = 0.6 × 0.05 = 0.03, square plan: × 1.15) + B2's δ_M (0.102502 m,
    the module docstring); §12.12.3's δ_MT, a fixed-base structure's rule, is not given for the sliding pair (issue 45)."""
    gaps = design_separations(_scene({"mass": 5.0e4, "mu": 0.05, "radius": 2.24}), DESIGN, studied="B1")
    assert sorted(gaps) == ["asce7_delta_mt", "asce7_isolated", "ec8_ds"] and math.isnan(gaps["asce7_delta_mt"][0])
    separation = gaps["asce7_isolated"][0]
    displacement = (separation - 0.102502) / 1.15  # D_M at the lower bound, within the 1e-6 m of δ_M's digits
    mu = 0.03
    period = 2.0 * math.pi / math.sqrt(G / 2.24 + mu * G / displacement)  # eq. 17.5-2, k_M = W/R + μW/D
    damping = 2.0 * mu / (math.pi * (mu + displacement / 2.24))
    coefficient = 0.8 + (damping - 0.02) / (0.05 - 0.02) * (1.0 - 0.8)  # Table 17.5-1 between 2 % and 5 %
    assert 0.02 < damping < 0.05
    assert displacement == pytest.approx(G * 1.2 * period / (4.0 * math.pi**2 * coefficient), rel=1e-5)  # eq. 17.5-1's fixed point
    # the same building studied or not: every building on a pendulum is designed by chapter 17
    assert design_separations(_scene({"mass": 5.0e4, "mu": 0.05, "radius": 2.24}), DESIGN, studied="B2")["asce7_isolated"][0] == separation


_ASCE7 = "sds = 1.0\nsd1 = 0.6\nr = 8.0\ncd = 5.5\nomega0 = 3.0"


@pytest.mark.parametrize(("table", "message"), [
    ("sds = 1.0\nsd1 = 0.6\nr = 0.5\ncd = 5.5\nomega0 = 3.0", "design.r: must be >= 1, got 0.5"),
    ("sds = 1.0\nsd1 = 0.6\nr = 8.0\ncd = 5.5", "design.omega0: missing"),
    ("sds = 1.0\nsd1 = 0.6\nr = 8.0\ncd = 5.5\nomega0 = 3.0\nq = 4.0", "design.q: unknown field"),
    ('sds = 1.0\nsd1 = 0.6\nr = 8.0\ncd = 5.5\nomega0 = 3.0\nec8 = { ag = 0.3, ground = "F", q = 4.0 }', "design.ec8.ground: must be one of A, B, C, D, E"),
    ("sds = -1.0\nsd1 = 0.6\nr = 8.0\ncd = 5.5\nomega0 = 3.0", "design.sds: must be > 0"),
    (f"{_ASCE7}\n[design.isolation]\nplan = [20.0, 10.0]", "design.isolation.plan: must be [b, d], the shortest and longest plan dimensions"),
    (f"{_ASCE7}\n[design.isolation]\neccentricity = 1.0", "design.isolation.eccentricity: needs plan = [b, d] (m) beside it"),
    (f"{_ASCE7}\n[design.isolation]\nsa_short = 1.8", "design.isolation.sa_long: give sa_short and sa_long together"),
    (f"{_ASCE7}\n[design.isolation]\nlambda_max = 0.5", "design.isolation.lambda_max: must be >= 1"),
    (f"{_ASCE7}\n[design.isolation]\nmoat = 0.6", "design.isolation.moat: unknown field"),
])
def test_design_errors_are_one_line_naming_the_field_and_range(table, message):
    text = risk_text(FIXED, "gap = [inf]", 'measure = "psa"\nperiod = 1.0\nlevels = [0.3, 0.8]') + f"\n[design]\n{table}\n"
    with pytest.raises(ExperimentError) as error:
        parse_experiment(tomllib.loads(text), base_dir=REPOSITORY)
    assert message in str(error.value) and "\n" not in str(error.value)


def test_design_isolation_reads_the_site_s_own_sa_0_2_and_sa_1_at_2_percent_in_50_years():
    """Issue 45: S_MS and S_M1 from the site's SA(0.2 s) and SA(1 s), not PGA / 0.4: the bundled site's curves at the rate of
    2 % in 50 yr, their source recorded; given values are kept as given (and then no source)."""
    from stochpound.risk import HazardCurve, rate_from_probability

    text = risk_text(FIXED, "gap = [inf]", 'measure = "psa"\nperiod = 1.0\nlevels = [0.3, 0.8]') + f"\n[design]\n{_ASCE7}\n[design.isolation]\n"
    isolation = parse_experiment(tomllib.loads(text), base_dir=REPOSITORY)["design"]["isolation"]
    rate = -math.log(1.0 - 0.02) / 50.0
    assert rate_from_probability(0.02, 50.0) == pytest.approx(rate, rel=1e-12)
    assert isolation["sa_short"] == pytest.approx(float(HazardCurve.bundled("fox_plaza_los_angeles_sa0p2s").intensity_at(rate)), rel=1e-12)
    assert isolation["sa_long"] == pytest.approx(float(HazardCurve.bundled("fox_plaza_los_angeles_sa1p0s").intensity_at(rate)), rel=1e-12)
    assert round(isolation["sa_short"], 2) == 1.82 and round(isolation["sa_long"], 2) == 1.20  # the 1.82 g; PGA / 0.4 is 1.99 g
    assert "fox_plaza_los_angeles_sa0p2s" in isolation["spectrum_source"] and "2 %/50 yr" in isolation["spectrum_source"]
    given = parse_experiment(tomllib.loads(text + "sa_short = 1.5\nsa_long = 0.6\nplan = [10.0, 30.0]\n"), base_dir=REPOSITORY)["design"]["isolation"]
    assert given == {"sa_short": 1.5, "sa_long": 0.6, "plan": [10.0, 30.0]}
    assert Design.from_entry(parse_experiment(tomllib.loads(text), base_dir=REPOSITORY)["design"]).isolation.sa_long == isolation["sa_long"]


def test_the_design_is_not_part_of_the_runs_identity():
    text = risk_text(FIXED, "gap = [inf]", 'measure = "psa"\nperiod = 1.0\nlevels = [0.3, 0.8]')
    without, with_design = (parse_experiment(tomllib.loads(t), base_dir=REPOSITORY) for t in (text, text + DESIGN_TABLE))
    assert "design" not in without and with_design["design"]["cd"] == 5.5 and with_design["design"]["ie"] == 1.0
    assert definition_sha256(with_design) == definition_sha256(without)


@pytest.fixture(scope="module")
def design_store(tmp_path_factory) -> Path:
    """The fixed pair (tests.helpers.FIXED) with the [design] above: 8 motions x 3 stripes, contact-free."""
    text = risk_text(FIXED, "gap = [inf]", 'measure = "psa"\nperiod = 1.0\nlevels = [0.3, 0.8, 1.5]') + DESIGN_TABLE
    report = run_experiment(load_experiment(write_experiment(tmp_path_factory.mktemp("design"), text, "design.toml")), workers=0, progress=False)
    assert report.complete
    return report.store


def test_the_codes_gaps_are_rows_of_the_rules_table_with_their_risk(design_store):
    store = open_store(design_store)
    risk = store_risk(store, bootstrap=40)
    expected = design_separations(store.pound.scene(gap=math.inf, intensity=0.3, record=store["record"].values[0]), store.pound.definition.design)
    np.testing.assert_allclose(risk.design_rules["gap"].sel(rule="asce7_delta_mt").values, expected["asce7_delta_mt"], rtol=1e-12)
    np.testing.assert_allclose(risk.design_rules["gap"].sel(rule="ec8_ds").values, expected["ec8_ds"], rtol=1e-12)
    frame = risk.rules_frame().reset_index()
    rows = frame[frame["design_level"].str.endswith("(design analysis)")]
    assert list(rows["rule"]) == ["ASCE 7 §12.12.3 δ_MT of the design analysis", "Eurocode 8 §4.4.2.7 d_s of the design analysis"]
    assert list(rows["design_level"]) == ["2 %/50 yr (design analysis)", "10 %/50 yr (design analysis)"]
    assert (frame["design_level"].str.contains("stripe")).sum() > 0  # the suite-mean rows stay beside them
    # the risk at the gap: runs that pound counted here from the stored closures, contact by contact, and fitted by the chain
    closure = store["peak_contact_closure"].sel(gap=math.inf).isel(realization=0).transpose("intensity", "record", "contact").values
    for rule in ("asce7_delta_mt", "ec8_ds"):
        gap = risk.design_rules["gap"].sel(rule=rule).values
        pounds = np.array([[float(any(closure[i, r, c] >= gap[c] for c in range(closure.shape[2]))) for r in range(closure.shape[1])]
                           for i in range(closure.shape[0])])
        events = xr.DataArray(pounds, dims=("intensity", "record"), coords={"intensity": store["intensity"].values})
        maf = risk_curve(stripe_fragility(events, bootstrap=0), risk.hazard)["maf"]
        assert 0.0 < pounds.mean() < 1.0  # the example pounds in some runs, not all
        assert float(risk.design_rules["maf"].sel(rule=rule)) == pytest.approx(float(maf), rel=1e-9)
    allowed = -np.log(1.0 - np.array([0.02, 0.10])) / 50.0
    assert list(rows["meets its level"]) == list(risk.design_rules["maf"].values <= allowed)
    assert all(rows["once in (yr)"] == 1.0 / risk.design_rules["maf"].values)


def test_stochpound_risk_prints_the_codes_gaps_beside_the_suite_mean_rules(design_store):
    result = CliRunner().invoke(main, ["risk", str(design_store), "--bootstrap", "0"])
    assert result.exit_code == 0, result.output
    risk = store_risk(open_store(design_store), bootstrap=0)
    for text in ("SRSS of suite-mean peaks", "ASCE 7 §12.12.3 δ_MT of the design analysis", "Eurocode 8 §4.4.2.7 d_s of the design analysis",
                 "2 %/50 yr (design analysis)", "10 %/50 yr (design analysis)"):
        assert text in result.output
    period = float(risk.design_rules["return_period"].sel(rule="asce7_delta_mt"))
    assert f"ASCE 7 §12.12.3 δ_MT of the design analysis, pounding once in {period:.3g} years" in result.output.replace("\n", " ")
    assert ("note: The row 'suite-mean peak base displacement (ASCE 7 D_M form: no torsion)' is not given: the studied building's base "
            "slides in no run of this store (a fixed base") in " ".join(result.output.split())  # why none
    assert "Chapter 17 design" not in result.output and "ch. 17" not in result.output  # fixed bases: no chapter 17


def test_stochpound_risk_takes_a_design_file_and_refuses_a_bad_one(design_store, tmp_path):
    (tmp_path / "stronger.toml").write_text("[design]\nsds = 1.0\nsd1 = 0.6\nr = 4.0\ncd = 4.0\nomega0 = 2.5\n")
    result = CliRunner().invoke(main, ["risk", str(design_store), "--bootstrap", "0", "--design", str(tmp_path / "stronger.toml")])
    assert result.exit_code == 0, result.output
    gaps = design_separations(open_store(design_store).pound.scene(gap=math.inf, intensity=0.3, record=open_store(design_store)["record"].values[0]),
                              Design(sds=1.0, sd1=0.6, tl=8.0, r=4.0, cd=4.0, omega0=2.5, ie=1.0))
    assert f"{gaps['asce7_delta_mt'][0]:.4g}" in result.output and "Eurocode 8 §4.4.2.7 d_s of the design analysis" not in result.output
    (tmp_path / "bad.toml").write_text("[design]\nsds = 1.0\nsd1 = 0.6\nr = 8.0\ncd = 12.0\nomega0 = 3.0\n")
    result = CliRunner().invoke(main, ["risk", str(design_store), "--bootstrap", "0", "--design", str(tmp_path / "bad.toml")])
    assert result.exit_code != 0 and "design.cd: must be <= 10, got 12" in result.output and "Traceback" not in result.output


def test_editing_the_design_keeps_the_runs_and_records_it(tmp_path):
    """A run after only [design] changed keeps the store's cases (no run depends on it) and records the new design."""
    text = risk_text(FIXED, "gap = [inf]", 'measure = "psa"\nperiod = 1.0\nlevels = [0.3, 0.8]').replace("duration = 5.0", "duration = 1.0")
    path = write_experiment(tmp_path, text, "edit.toml")
    store = run_experiment(load_experiment(path), workers=0, progress=False).store
    with open_store(store) as ds:
        before = ds["peak_contact_closure"].load()
        assert ds.pound.definition.design is None
    path.write_text(text + DESIGN_TABLE)
    said: list[str] = []
    report = run_experiment(load_experiment(path), workers=0, progress=False, say=said.append)
    assert report.nothing_to_run and report.done_now == 0
    assert any("the [design] changed" in line for line in said) and not any("hazard changed" in line for line in said)
    with open_store(store) as ds:
        assert ds.pound.definition.design.cd == 5.5 and ds.pound.definition.design.ec8.q == 4.0
        xr.testing.assert_identical(ds["peak_contact_closure"].load(), before)


def test_the_flagship_s_d_m_in_the_docs_is_eq_17_5_1_s():
    """docs/risk.md once gave β_eff 12–17 % and D_M 0.55–0.65 m for the flagship's pendulum; eq. 17.5-1 gives what it says now."""
    import re
    from pathlib import Path

    from stochpound.risk import asce7_isolator_displacement
    from stochpound.codes import damping_coefficient

    docs = re.sub(r"\s+", " ", (Path(__file__).resolve().parents[1] / "docs" / "risk.md").read_text())
    for mu in (0.08, 0.05):
        displacement, period, damping = asce7_isolator_displacement(1.0, mu, 2.24, 1.20306)
        stated = (f"μ = {mu:g} gives T_M = {period:.2f} s, β_M = {100 * damping:.2g} %, B_M = {damping_coefficient(damping):.2f} and "
                  f"D_M = {displacement:.2f} m")
        assert stated in docs, stated
    assert "12–17 %" not in docs and "0.55–0.65 m" not in docs


def test_a_base_beyond_a_slider_s_friction_gets_neither_code_row():
    """μ = 0.5 on a pendulum is no slider chapter 17 designs (SlidingBase takes μ <= 0.3), nor a fixed base: no row at all,
    not an error that stops the whole risk answer."""
    gaps = design_separations(_scene({"mass": 5.0e4, "mu": 0.5, "radius": 2.24}), DESIGN, studied="B1")
    assert "asce7_isolated" not in gaps and math.isnan(gaps["asce7_delta_mt"][0])
