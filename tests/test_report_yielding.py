"""The report of yielding buildings: what the Methods section says of them, the yielding check, and the Damage section.

A small store: the risk flagship's fixed pair with weak yielding storeys
(F_y = 100, 70 kN; 2 % hardening; P-Δ; 3 m storeys), 8 far-field motions
(5 s) × 3 stripes of PSA(1 s) (0.3 g and the site's 10 %/2 % in 50 yr
intensities), contact-free and at a 5 cm gap, with a [design] table. Every
expected number is derived from the store or the scene here.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from stochpound._errors import VerificationError
from stochpound.report.sections import damage_section, methods_section
from stochpound.analysis import ReferenceRun
from stochpound.report.sections._accuracy import yielding_check
from stochpound.report.sections._damage import ratio_text
from stochpound.report.sections._description import StoreDefinition, buildings_table, design_paragraph
from stochpound.risk import DEFAULT_LIMIT_STATES, MODEL_DRIFT_LIMIT, store_damage
from stochpound.store import contact_free, open_store
from tests.helpers import REPOSITORY, risk_text, run_in_process

YIELDING = "yield_force = [1.0e5, 0.7e5]\nhardening = 0.02\nstorey_height = [3.0, 3.0]\np_delta = true\n"
#: The helpers' fixed pair (the bundled elastic pair, its neighbour's masses x 0.5) inline, with both buildings' storeys yielding.
_PAIR = (REPOSITORY / "data" / "scenes" / "elastic_pair.toml").read_text().replace("[[building]]", "[[scene.building]]").replace("[[contact]]", "[[scene.contact]]")
_B2 = _PAIR.rindex("mass = [26268.0, 17512.0]")
SCENE = "[scene]\n" + (_PAIR[:_B2] + "mass = [13134.0, 8756.0]" + _PAIR[_B2 + len("mass = [26268.0, 17512.0]"):]).replace("damping_ratio = 0.05", "damping_ratio = 0.05\n" + YIELDING)
DESIGN = "\n[design]\nsds = 1.32925\nsd1 = 0.80204\nr = 8.0\ncd = 5.5\nomega0 = 3.0\nie = 1.0\n"
STRIPES = 'measure = "psa"\nperiod = 1.0\nlevels = [0.3, 0.7399, 1.2031]\nmethod = "stripes"'


@pytest.fixture(scope="module")
def store_path(tmp_path_factory):
    assert SCENE.count("yield_force") == 2
    text = risk_text(SCENE, "gap = [0.05, inf]", STRIPES) + "demands = true\n" + DESIGN
    return run_in_process(tmp_path_factory.mktemp("yreport"), "yfix", text)


@pytest.fixture(scope="module")
def store(store_path):
    return open_store(store_path).load()


def _text(block) -> str:
    return block.text if hasattr(block, "text") else ""


def test_the_buildings_table_gives_storey_heights_strength_and_p_delta(store):
    table = buildings_table([StoreDefinition("yfix", store)])
    assert {"storey height (m)", "storeys", "P-Δ"} <= set(table.frame.columns)
    b1 = table.frame[table.frame["building"] == "B1"].iloc[0]
    drift = [1.0e5 / 24516800.0, 0.7e5 / 17512000.0]  # F_y / k, m
    assert b1["storeys"] == f"F_y = 100000, 70000 N (yield drift {1000 * drift[0]:.3g}, {1000 * drift[1]:.3g} mm; " \
                            f"{100 * drift[0] / 3:.3g} %, {100 * drift[1] / 3:.3g} % of h), hardening α = 2 %"
    weight_above = 9.81 * np.array([26268.0 + 17512.0, 17512.0])
    assert b1["P-Δ"].startswith(f"W/h = {weight_above[0] / 3:.4g}, {weight_above[1] / 3:.4g} N/m taken off k")


def test_the_design_paragraph_sets_the_strength_beside_the_elf_design(store):
    from stochpound.model import design_yield_shears
    from stochpound.model.modal_solution import modal_properties
    text = design_paragraph(StoreDefinition("yfix", store)).text
    assert "S_DS = 1.329 g, S_D1 = 0.802 g, T_L = 8 s, R = 8, C_d = 5.5, Ω0 = 3, I_e = 1" in text
    b1 = store.pound.scene(gap=np.inf, intensity=0.3, record=str(store["record"].values[0]), realization=0).buildings[0]
    period = float(modal_properties(b1).periods[0])
    code = design_yield_shears(b1.mass, b1.storey_height, period=period, sds=1.32925, sd1=0.80204, r=8.0, overstrength=3.0, importance=1.0)
    weight = 9.81 * sum(b1.mass)
    assert f"B1: F_y,1 / W = {1.0e5 / weight:.3g}, the design's Ω0 V / W = {code[0] / weight:.3g} at T1 = {period:.3g} s" in text


def test_methods_says_what_yielding_is_and_that_the_modal_check_runs_an_elastic_copy(store):
    texts = " ".join(_text(block) for block in methods_section({"yfix": store}).blocks)
    assert "Storeys given a yield shear F_y are bilinear with kinematic hardening" in texts
    assert "There is no strength loss: no degradation, no collapse." in texts
    assert "so its yield and its elastic unloading are located on the same exact flow" in texts
    assert "(an elastic copy of a yielding building: its yield shears, hardening and P-Δ left out" in texts
    assert "dissipated in storey dashpots, yielding storeys (hysteretic), friction and impacts" in texts
    assert "Yielding check on a stored case of yfix" in texts


def test_the_yielding_check_reruns_a_yielded_case_and_fails_on_a_corrupted_store(store):
    labels = ReferenceRun.yielding_case(store)
    ductility = store["peak_ductility"].max("building")
    yielded = np.sort(ductility.values[ductility.values > 1.0])
    assert float(ductility.sel(labels)) == yielded[(yielded.size - 1) // 2]  # the median of the cases that yielded
    definition = StoreDefinition("yfix", store)
    assert "equal the store's within 1e-09" in yielding_check(definition).text
    corrupted = store.copy(deep=True)
    corrupted["residual_drift"].loc[labels] = corrupted["residual_drift"].loc[labels] * 1.001
    with pytest.raises(VerificationError, match=r"^yielding check: the stored case of yfix .* re-run gives residual_drift"):
        yielding_check(StoreDefinition("yfix", corrupted))


def test_store_damage_fractiles_and_runs_beyond_the_model(store):
    damage = store_damage(store)
    free = contact_free(store)
    assert damage.contact_free and damage.design_stripes == {0.1: 0.7399, 0.02: 1.2031}
    runs = free["peak_ductility"].sel(intensity=1.2031, building="B1").values.ravel()
    np.testing.assert_allclose(damage.demands["peak_ductility"].sel(intensity=1.2031, building="B1").values,
                               np.quantile(runs, [0.5, 0.84]), rtol=1e-12)
    drift = free["peak_drift_ratio"].max("building")
    for level in store["intensity"].values:
        assert int(damage.beyond_model.sel(intensity=level)) == int((drift.sel(intensity=level) > MODEL_DRIFT_LIMIT).sum())
    assert int(damage.beyond_model.sum()) > 0  # these weak storeys go beyond the model at the upper stripes
    # each default limit state judged per building, with FEMA 356's objectives: IO 50 %, LS 10 % (and 1 % residual), CP 2 % in 50 yr
    assert damage.limit_states == tuple(state.for_building(b) for state in DEFAULT_LIMIT_STATES for b in ("B1", "B2"))
    assert [state.target for state in DEFAULT_LIMIT_STATES] == [0.5, 0.1, 0.1, 0.02]
    maf = damage.risk["maf"]
    target_rate = -np.log(1 - np.array([0.5, 0.5, 0.1, 0.1, 0.1, 0.1, 0.02, 0.02])) / 50  # λ_target of each, in the order above
    ratio = maf.values / target_rate
    np.testing.assert_allclose(damage.ratio().values, ratio, rtol=1e-12)
    # judged: the fit's ratio where the runs pin it (a lognormal they identify), else the stripes' lower bound λ⁻'s
    fits = [str(fit) for fit in damage.fits().values]
    pinned = np.array([fit == "lognormal" for fit in fits])
    np.testing.assert_array_equal(damage.pinned().values, pinned)
    judged = np.where(pinned, ratio, damage.risk["maf_lower"].values / target_rate)
    np.testing.assert_allclose(damage.judged().values, judged, rtol=1e-12)
    np.testing.assert_array_equal(damage.misses_objective().values, judged > 1.0)
    governing = damage.governing().item()  # the same at every target: each limit state has its own objective
    assert governing == (str(maf["limit_state"].values[int(np.argmax(judged))]) if judged.max() > 1.0 else "pounding at g*")
    assert judged.max() > 1.0  # these weak storeys miss an objective


def test_governs_is_the_largest_ratio_to_the_objective_not_the_most_frequent_limit_state():
    """Issue 45: 'immediate-occupancy drift governs everywhere' ranked rates of different events. Immediate occupancy is the
    most frequent (0.01 /yr) but within its objective (50 % in 50 yr: 0.01386 /yr, ratio 0.72); collapse prevention is rarer
    (0.001 /yr) but misses its own (2 % in 50 yr: 4.04e-4 /yr, ratio 2.47): it governs. Without objectives nothing governs."""
    import xarray as xr

    from stochpound.risk import LimitState, StoreDamage

    states = (LimitState("drift_ratio", 0.007, "B1", 0.5), LimitState("drift_ratio", 0.05, "B1", 0.02))
    risk = xr.Dataset({"maf": ("limit_state", [0.01, 0.001])},
                      coords={"limit_state": [s.label for s in states], "target": ("limit_state", [0.5, 0.02])})
    empty = xr.DataArray([0])
    damage = StoreDamage(xr.Dataset(), empty, empty, {0.1: 1.0}, risk, states, "a test", True)
    np.testing.assert_allclose(damage.ratio().values, [0.01 / (-np.log(0.5) / 50), 0.001 / (-np.log(0.98) / 50)], rtol=1e-12)
    assert damage.governing().item() == states[1].label  # the same at every target: governing takes none
    unjudged = StoreDamage(xr.Dataset(), empty, empty, {0.1: 1.0}, risk.assign_coords(target=("limit_state", [np.nan, np.nan])),
                           (LimitState("drift_ratio", 0.007, "B1"), LimitState("drift_ratio", 0.05, "B1")), "a test", True)
    assert unjudged.governing() is None and unjudged.governing_counts() is None


def test_pounding_at_g_star_governs_where_no_limit_state_is_as_frequent(store):
    """Capacities no run reaches: every λ is 0, within its objective, so pounding at g* (ratio 1) governs; without an objective
    the word goes."""
    from stochpound.risk import LimitState
    damage = store_damage(store, [LimitState("ductility", 1.0e4, target=0.02)], "a test")
    assert float(damage.risk["maf"].max()) == 0.0
    assert damage.governing().item() == "pounding at g*"
    assert "Governing: as run, pounding at g* (no limit state the runs put beyond its objective; the largest λ/λ_target is 0" in " ".join(
        _text(block) for block in damage_section("yfix", damage).blocks)
    unjudged = store_damage(store, [LimitState("ductility", 1.0e4)], "a test")
    text = " ".join(_text(block) for block in damage_section("yfix", unjudged).blocks)
    assert unjudged.governing() is None and "none is said to govern" in text and "Governing:" not in text


def _two_treatments():
    """Two configurations (μ 0.05, 0.08) of immediate occupancy (0.7 %, 50 % in 50 yr) and collapse prevention (5 %, 2 % in 50 yr),
    λ as run and with the collapses counted apart, chosen so that the treatments disagree in the first configuration only."""
    import xarray as xr

    from stochpound.risk import LimitState, StoreDamage

    states = (LimitState("drift_ratio", 0.007, "B1", 0.5), LimitState("drift_ratio", 0.05, "B1", 0.02))
    coords = {"limit_state": [s.label for s in states], "mu": [0.05, 0.08], "target": ("limit_state", [0.5, 0.02])}
    risk = xr.Dataset({"maf": (("limit_state", "mu"), [[0.01, 0.02], [3e-4, 1e-4]]),
                       "maf_collapses_apart": (("limit_state", "mu"), [[0.011, 0.021], [9e-4, 2e-4]])}, coords=coords)
    runs, beyond = xr.DataArray([8]), xr.DataArray([1])  # one of 8 runs beyond the model
    return states, risk, StoreDamage(xr.Dataset(), runs, beyond, {0.1: 1.0}, risk, states, "a test", True)


def test_governs_is_judged_in_each_treatment_of_the_collapses_and_a_disagreement_is_said():
    """Issue 45: with the runs beyond the model counted apart the governing objective can differ. By hand (λ_target = −ln(1 − p)/50:
    0.013863 and 4.0405e-4 /yr): μ 0.05 as run 0.72 and 0.74, nothing beyond its objective (pounding at g*), collapses apart 0.79
    and 2.23: collapse prevention; μ 0.08 as run 1.44 and 0.25, collapses apart 1.51 and 0.49: immediate occupancy both ways."""
    from stochpound.report.sections._damage import _governing_text
    from stochpound.report.sections._risk import _structural_governs
    from stochpound.risk import disagreement_text, governing_limit_state, objectives_frame

    states, risk, damage = _two_treatments()
    rates = -np.log(1.0 - np.array([0.5, 0.02])) / 50.0
    np.testing.assert_allclose(damage.ratio(apart=True).values, risk["maf_collapses_apart"].values / rates[:, None], rtol=1e-12)
    assert list(damage.governing().values) == ["pounding at g*", states[0].label]
    assert list(damage.governing(apart=True).values) == [states[1].label, states[0].label]
    assert list(damage.disagreement().values) == [True, False]
    assert damage.governing_counts(apart=True) == ({states[1].label: 1, states[0].label: 1}, 2)
    text = _governing_text(damage)
    assert (f"Governing: as run, mu 0.05: pounding at g* (no limit state the runs put beyond its objective; the largest "
            f"λ/λ_target is {3e-4 / rates[1]:.2g}, {states[1].label}); mu 0.08: {states[0].label} (λ/λ_target = {0.02 / rates[0]:.2g}); with the runs "
            f"beyond the model counted apart as collapses, mu 0.05: {states[1].label} (λ/λ_target = {9e-4 / rates[1]:.2g})") in text
    assert (f"The two treatments disagree on what governs in 1 of 2 configurations (mu 0.05: pounding at g* as run, {states[1].label} "
            "with collapses apart)") in text
    summary = _structural_governs(damage)  # the same at every target: no target, and no separation's limit, in it
    assert summary.startswith(f"as run, {states[0].label} in 1 of 2 configurations") and "the two treatments disagree in 1 of 2" in summary
    assert f"with the runs beyond the model counted apart as collapses, {states[1].label} in 1 of 2 configurations, {states[0].label} in 1" in summary
    # the same judgement for stochpound risk --limit-states: a finite-gap grid says none beyond its objective where nothing misses
    frame = objectives_frame(risk)
    assert list(frame["governs, as run"]) == ["none beyond its objective", states[0].label]
    assert list(frame["governs, collapses apart"]) == [states[1].label, states[0].label] and list(frame["treatments agree"]) == [False, True]
    np.testing.assert_allclose(frame["largest λ/λ_target, collapses apart"], [9e-4 / rates[1], 0.021 / rates[0]], rtol=1e-12)
    assert disagreement_text(frame).startswith(f"The two treatments disagree on what governs in 1 of 2 configurations (mu 0.05: none beyond "
                                               f"its objective as run, {states[1].label} with the collapses counted apart)")
    # agreeing treatments are said to agree; one treatment (no run beyond the model) says nothing of a second
    agreeing = risk.assign(maf_collapses_apart=risk["maf"] * 1.01)
    assert governing_limit_state(agreeing, apart=True).equals(governing_limit_state(agreeing))
    assert disagreement_text(objectives_frame(agreeing)) == ("The two treatments of the runs beyond the model name the same governing "
                                                            "limit state in every configuration.")
    alone = objectives_frame(risk.drop_vars("maf_collapses_apart"))
    assert list(alone.columns) == ["governs, as run", "largest λ/λ_target, as run"] and disagreement_text(alone) == ""
    assert objectives_frame(risk.assign_coords(target=("limit_state", [np.nan, np.nan]))) is None


def test_the_store_s_collapses_alone_miss_an_objective_no_run_reaches_as_run(store, store_path, tmp_path):
    """A ductility of 10⁴ no run reaches: as run λ = 0 and pounding at g* governs; counted apart, the collapses reach it, at the
    collapse rate, so it governs where that rate misses its 2 %/50 yr objective. The report and stochpound risk --limit-states say
    which governs each way and that they disagree."""
    from click.testing import CliRunner

    from stochpound.cli import main
    from stochpound.risk import LimitState, governing_limit_state, limit_state_risk, site_hazard

    state = LimitState("ductility", 1.0e4, target=0.02)
    damage = store_damage(store, [state], "a test")
    collapse = float(damage.risk["maf_collapses_apart"].item())
    assert collapse > 0.0 and float(damage.risk["maf"].item()) == 0.0
    rate = -math.log(0.98) / 50.0
    apart = damage.governing(apart=True).item()
    assert apart == (state.label if collapse > rate else "pounding at g*")
    assert collapse > rate  # these weak storeys collapse more often than once in 2475 years
    text = " ".join(_text(block) for block in damage_section("yfix", damage).blocks)
    assert (f"with the runs beyond the model counted apart as collapses, {state.label} (λ/λ_target = {collapse / rate:.2g}). The two "
            f"treatments disagree on what governs in 1 of 1 configurations (pounding at g* as run, {state.label} with collapses apart)") in text
    # the CLI, on every configuration of the grid (the 5 cm gap's runs too)
    (tmp_path / "states.toml").write_text("[limit_states]\nductility = [1.0e4]\n[limit_states.targets]\nductility = [0.02]\n")
    result = CliRunner().invoke(main, ["risk", str(store_path), "--bootstrap", "0", "--limit-states", str(tmp_path / "states.toml"),
                                       "--csv", str(tmp_path / "tables")])
    assert result.exit_code == 0, result.output
    risk = limit_state_risk(store, [state], site_hazard(store))
    at_gap = risk.sel(gap=0.05)
    assert at_gap["maf"].item() == 0.0 and at_gap["maf_collapses_apart"].item() > rate  # the 5 cm runs: the same two answers
    expected = [governing_limit_state(at_gap, apart, "none beyond its objective").item() for apart in (False, True)]
    assert expected == ["none beyond its objective", state.label]
    written = pd.read_csv(tmp_path / "tables" / "objectives.csv")
    assert list(written["governs, as run"]) == [expected[0]] and list(written["governs, collapses apart"]) == [expected[1]]
    np.testing.assert_allclose(written["largest λ/λ_target, collapses apart"], at_gap["maf_collapses_apart"].item() / rate, rtol=1e-9)
    assert "What governs, judged against each limit state's objective" in result.output
    assert (f"warning: The two treatments disagree on what governs in 1 of 1 configurations (gap 0.05: none beyond its objective as "
            f"run, {state.label} with the collapses counted apart)") in result.output
    assert "step" in "".join(pd.read_csv(tmp_path / "tables" / "limit_states.csv")["fit"])  # the fit named: no run reaches it


def test_the_damage_section_states_fractiles_flags_and_the_governing_limit_state(store):
    damage = store_damage(store)
    section = damage_section("yfix", damage)
    texts = " ".join(_text(block) for block in section.blocks)
    table = next(block for block in section.blocks if getattr(block, "key", "") == "table-damage-yfix").frame
    row = table.loc[("–", "1.2031 (2 %/50 yr)", "B1")]
    median = float(damage.demands["peak_ductility"].sel(intensity=1.2031, building="B1", quantile=0.5))
    assert row["peak storey ductility, median"] == f"{median:.3g}"
    beyond, runs = int(damage.beyond_model.sel(intensity=1.2031)), int(damage.runs.sel(intensity=1.2031))
    assert row["runs > model"] == f"{beyond} of {runs}"
    assert f"{beyond} of {runs} at stripe 1.2031" in texts and "are not credible" in texts
    assert "FEMA 356 (2000), Table C1-3, steel moment frames" in texts
    ratio = damage.judged()
    worst = damage.governing().item()
    others = [str(state) for state in ratio["limit_state"].values if float(ratio.sel(limit_state=state)) > 1.0 and state != worst]
    assert bool(damage.pinned().sel(limit_state=worst))  # a lognormal the runs identify: its ratio is a rate's
    expected = f"{worst} (λ/λ_target = {float(ratio.max()):.2g})" + (f"; also beyond their objectives: {', '.join(others)}" if others else "")
    assert damage.collapses_apart() and f"Governing: as run, {expected}" in texts
    assert "; with the runs beyond the model counted apart as collapses, " in texts
    assert "(objective: 50 % in 50 yr)" in texts and "(objective: 2 % in 50 yr)" in texts


# ---------------------------------------------------------------- the [limit_states] table of an experiment file


def test_a_limit_states_table_is_not_part_of_the_identity_and_replaces_the_defaults(store):
    import json

    import tomllib

    from stochpound.experiment._spec import parse_experiment
    from stochpound.store import definition_sha256
    text = risk_text(SCENE, "gap = [0.05, inf]", STRIPES) + "demands = true\n" + DESIGN
    table = '\n[limit_states]\nsource = "a test"\nductility = { B1 = [4.0, 8.0] }\nresidual_drift_ratio = 0.005\n'
    plain, with_table = parse_experiment(tomllib.loads(text)), parse_experiment(tomllib.loads(text + table))
    assert with_table["limit_states"] == {"source": "a test", "capacities": {"ductility": {"B1": [4.0, 8.0]}, "residual_drift_ratio": [0.005]}}
    assert definition_sha256(with_table) == definition_sha256(plain) == store.attrs["definition_sha256"]
    edited = store.copy()
    edited.attrs = {**store.attrs, "definition": json.dumps({**json.loads(store.attrs["definition"]), "limit_states": with_table["limit_states"]})}
    damage = store_damage(edited)
    assert damage.source == 'the experiment\'s [limit_states] table, whose source reads "a test"'
    assert [state.label for state in damage.limit_states] == ["peak storey ductility of B1 ≥ 4", "peak storey ductility of B1 ≥ 8",
                                                              "residual storey drift ratio of B1 ≥ 0.005", "residual storey drift ratio of B2 ≥ 0.005"]
    assert all(state.target is None for state in damage.limit_states)  # no targets given, and none of FEMA 356's capacities
    assert "Limit states (capacities from the experiment's [limit_states] table, whose source reads \"a test\"; each building judged by its own demand): " \
           "peak storey ductility of B1 ≥ 4 (no objective);" in " ".join(
        _text(block) for block in damage_section("yfix", damage).blocks)
    # targets, shaped as the capacities, are carried in the definition and given to each state
    targeted = parse_experiment(tomllib.loads(text + table + "targets = { ductility = { B1 = [0.5, 0.1] }, residual_drift_ratio = 0.1 }\n"))
    assert targeted["limit_states"]["targets"] == {"ductility": {"B1": [0.5, 0.1]}, "residual_drift_ratio": [0.1]}
    edited.attrs = {**store.attrs, "definition": json.dumps({**json.loads(store.attrs["definition"]), "limit_states": targeted["limit_states"]})}
    assert [state.target for state in store_damage(edited).limit_states] == [0.5, 0.1, 0.1, 0.1]


@pytest.mark.parametrize(
    "table, message",
    [
        ("drift = 0.01", r"^limit_states\.drift: not a limit state; one of drift_ratio, residual_drift_ratio"),
        ("drift_ratio = [0.01, -1.0]", r"^limit_states\.drift_ratio\[1\]: a capacity must be a number > 0 \(1\), got -1\.0"),
        ("impact_force = { B1 = 1.0e5 }", r"^limit_states\.impact_force\.B1: has no building \(an impact force is a contact's\), got 'B1'"),
        ("ductility = { B9 = 4.0 }", r"^limit_states\.ductility\.B9: unknown building \(buildings: B1, B2\)"),
        ('source = "x"', r"^limit_states: give at least one limit state"),
        ("drift_ratio = [0.01, 0.02]\ntargets = { drift_ratio = [0.5, 1.5] }", r"^limit_states\.targets\.drift_ratio\[1\]: a target must be a probability in 50 years in \(0, 1\), got 1\.5"),
        ("drift_ratio = [0.01, 0.02]\ntargets = { drift_ratio = [0.5] }", r"^limit_states\.targets\.drift_ratio: give one target or 2 \(one per capacity\), got 1"),
        ("drift_ratio = 0.01\ntargets = { drift = 0.5 }", r"^limit_states\.targets\.drift: unknown field"),
    ],
)
def test_bad_limit_states_tables_are_named(table, message):
    import tomllib

    from stochpound.experiment import ExperimentError
    from stochpound.experiment._spec import parse_experiment
    text = risk_text(SCENE, "gap = [inf]", STRIPES) + f"\n[limit_states]\n{table}\n"
    with pytest.raises(ExperimentError, match=message):
        parse_experiment(tomllib.loads(text))


def test_the_damage_section_says_which_runs_and_stripes_and_lists_every_limit_states_rate(store):
    damage = store_damage(store)
    section = damage_section("yfix", damage)
    texts = " ".join(_text(block) for block in section.blocks)
    assert ("from its contact-free runs (those the separations come from)" in texts
            and "(10 % in 50 yr: stripe 0.7399; 2 % in 50 yr: stripe 1.2031)" in texts)
    table = next(block for block in section.blocks if getattr(block, "key", "") == "table-limit-states-yfix").frame
    maf = damage.risk["maf"]
    assert len(table) == maf.sizes["limit_state"] == 2 * len(DEFAULT_LIMIT_STATES)  # one per building
    from stochpound.risk import unidentified

    why = unidentified(damage.risk)
    free = contact_free(store).isel(realization=0, drop=True)
    hazard = damage_hazard(store)
    levels = store["intensity"].values
    rates = hazard(levels)
    lowest_end = float(hazard(hazard.support[0]))
    bounded = 0
    for one in damage.limit_states:
        state = one.label
        rate = float(maf.sel(limit_state=state))
        target = float(maf["target"].sel(limit_state=state))  # its objective and λ/λ_target, and the fit's kind (issue 45: λ without its fit)
        target_rate = -math.log(1 - target) / 50
        assert table.loc[("–", str(state)), "objective"] == f"{100 * target:g} % in 50 yr"
        row = table.loc[("–", str(state))]
        reason = str(why.sel(limit_state=state).item())
        if row["fit"] == "lognormal":  # pinned by the runs: the fitted rate
            assert (row["λ (1/yr)"], row["once in (yr)"]) == (f"{rate:.3g}", f"{1.0 / rate:.3g}")
            assert row["λ/λ_target"] == ratio_text(rate / target_rate)
            continue
        # issue 45: a fit the runs do not pin (a step, a flat fit, a lognormal not identified) gives the bounds of the stripes'
        # fractions alone, by hand: λ⁻ = Σ p_j (λ(x_j) − λ(x_{j+1})), λ⁺ = p_1 (λ(lo) − λ(x_1)) + Σ p_j (λ(x_{j−1}) − λ(x_j)) + λ(x_n)
        variable = {"drift_ratio": "peak_drift_ratio", "residual_drift_ratio": "residual_drift_ratio"}[one.kind]
        p = (free[variable].sel(building=one.building) >= one.capacity).mean("record").values
        low = float(np.sum(p * (rates - np.append(rates[1:], 0.0))))
        high = float(np.sum(p * (np.append(lowest_end, rates[:-1]) - rates)) + rates[-1])
        assert row["λ (1/yr)"] == f"[{low:.3g}, {high:.3g}]"
        assert row["once in (yr)"] == f"[{1 / high:.3g}, {(f'{1 / low:.3g}' if low > 0 else 'inf')}]"
        assert row["λ/λ_target"] == f"[{ratio_text(low / target_rate)}, {ratio_text(high / target_rate)}]"
        assert low <= high
        assert row["fit"] in (f"lognormal, not identified ({reason})", "step: never", "step: separated", "step at the lowest stripe: a bound",
                              "flat: decreasing (F ≡ fraction of runs that reached it)")  # reached, not pounded
        bounded += 1
    assert bounded  # the store has a fit the runs do not pin to print


def damage_hazard(store):
    from stochpound.risk import site_hazard

    return site_hazard(store)


def test_the_limit_states_and_demands_are_given_both_ways(store):
    """Issue 45 item 3: the limit states' λ and λ/λ_target and the demand curves with the runs beyond the model counted apart;
    a collapse reaches every limit state and level, so λ apart ≥ λ_C, and drift ≥ 5 % apart (no credible run passes 5 %) is λ_C;
    the report says which runs (per stripe) and shows both."""
    from stochpound.report.sections._risk import risk_section
    from stochpound.risk import collapse_risk, store_demands, store_risk

    damage = store_damage(store)
    risk = store_risk(store, bootstrap=0)
    collapse = collapse_risk(store, risk.hazard, risk.fragility["gap"].values, risk.separation["target"].values)
    lambda_c = float(collapse.collapse["maf"])
    assert damage.collapses_apart() and lambda_c > 0
    apart = damage.risk["maf_collapses_apart"]
    assert bool((apart >= lambda_c * (1 - 2e-3)).all())
    for building in ("B1", "B2"):
        assert float(apart.sel(limit_state=f"peak storey drift ratio of {building} ≥ 0.05")) == pytest.approx(lambda_c, rel=2e-3)
    np.testing.assert_allclose(damage.ratio(apart=True).values, apart.values / (-np.log(1 - damage.risk["target"].values) / 50), rtol=1e-12)
    section = damage_section("yfix", damage)
    table = next(block for block in section.blocks if getattr(block, "key", "") == "table-limit-states-yfix").frame
    free = contact_free(store).isel(realization=0, drop=True)
    collapsed = free["peak_drift_ratio"].max("building") > MODEL_DRIFT_LIMIT
    levels = store["intensity"].values
    rates = np.append(risk.hazard(levels), 0.0)
    lowest_end = float(risk.hazard(risk.hazard.support[0]))
    bounded = 0
    pinned = damage.pinned(apart=True)
    for state, one in zip(apart["limit_state"].values, damage.limit_states):
        cell = table.loc[("–", str(state)), "λ collapses apart (1/yr)"]
        if bool(pinned.sel(limit_state=state)):
            assert cell == f"{float(apart.sel(limit_state=state)):.3g}"
            continue
        # a fit the runs do not pin: the bounds of the stripes' fractions, a collapse counted as reaching it, by hand
        variable = {"drift_ratio": "peak_drift_ratio", "residual_drift_ratio": "residual_drift_ratio"}[one.kind]
        reached = (free[variable].sel(building=one.building) >= one.capacity) | collapsed
        fractions = reached.mean("record").values
        low = float(np.sum(fractions * (rates[:-1] - rates[1:])))
        high = float(np.sum(fractions * (np.append(lowest_end, rates[:-2]) - rates[:-1])) + rates[-2])
        assert cell == f"[{low:.3g}, {high:.3g}]"
        bounded += 1
    assert bounded > 0  # immediate occupancy is a step at the lowest stripe here
    texts = " ".join(_text(block) for block in section.blocks)
    assert "The limit states' table gives each λ both ways" in texts and "a collapse counted as reaching every limit state" in texts
    demands = store_demands(store, risk.hazard)
    assert demands.apart and set(demands.apart) == set(demands.curves)
    drift = contact_free(store)["peak_drift_ratio"].max("building").isel(realization=0, drop=True)
    hand = (drift > MODEL_DRIFT_LIMIT).sum("record")
    np.testing.assert_array_equal(demands.beyond_model.values.ravel(), hand.values.ravel())
    for label, rate in demands.apart.items():  # the highest level: reached by collapses (and perhaps a few credible runs) only
        assert float(rate.isel(level=-1)) >= lambda_c * (1 - 2e-3)
    levels = demands.levels_at(risk.separation["target"].values, risk.years)
    assert set(levels["demand"]) == {f"{label} ({demands.units[label]})" for label in demands.curves}
    assert lambda_c > -np.log(1 - 0.1) / 50 and bool(np.isinf(levels["collapses apart"]).all())  # collapse alone exceeds both targets
    assert bool(np.isfinite(levels["as run"]).any())
    blocks = risk_section("yfix", risk, demands, damage, None, collapse).blocks
    shown = " ".join(_text(block) for block in blocks)
    per_stripe = "; ".join(f"{int(b)} of {int(n)} at stripe {float(x):.4g}" for x, b, n in
                           zip(store["intensity"].values, hand.values, drift.notnull().sum("record").values))
    assert f"per stripe over every configuration, {per_stripe}." in shown
    assert any(getattr(block, "key", "") == "risk-demands-apart-yfix" for block in blocks)


def test_no_run_beyond_the_model_is_said_so(store):
    import dataclasses

    from stochpound.report.sections._damage import _beyond_model_text
    damage = store_damage(store)
    none = dataclasses.replace(damage, beyond_model=damage.beyond_model * 0)
    assert _beyond_model_text(none).endswith(f"none of the {int(damage.runs.sum())} runs reaches it.")
    assert "not credible" not in _beyond_model_text(none)


def test_methods_says_what_p_delta_does_only_where_a_building_has_it(store):
    from stochpound.report.sections._description import model_paragraph
    definition = StoreDefinition("yfix", store)
    sentence = "With P-Δ a storey's spring is softened by the geometric stiffness −W/h of the weight above it"
    assert sentence in model_paragraph([definition]).text
    for configuration in definition.configurations:
        object.__setattr__(configuration, "scene", _without_p_delta(configuration.scene))
    text = model_paragraph([definition]).text
    assert sentence not in text and "Storeys given a yield shear F_y are bilinear" in text


def _without_p_delta(scene):
    import dataclasses
    return dataclasses.replace(scene, buildings=tuple(dataclasses.replace(b, p_delta=False) for b in scene.buildings))


def test_the_design_summary_names_the_limit_state_the_damage_section_finds_governing(store):
    """The summary's governing limit state agrees with the Damage section's: a structural limit state reached more often than
    pounding at g* is named there with its count of configurations; with capacities no run reaches, pounding alone."""
    from stochpound.report.sections._risk import design_summary_text
    from stochpound.risk import LimitState, store_risk
    risk, damage = store_risk(store), store_damage(store)
    text = design_summary_text(risk, None, damage)
    governing = [str(v) for v in damage.governing().values.ravel()]
    structural = [g for g in governing if g != "pounding at g*"]
    assert structural, "the weak storeys of this store reach a drift limit more often than the target's rate"
    assert f"{structural[0]} in {governing.count(structural[0])} of {len(governing)} configurations" in text
    assert "the largest λ/λ_target of the limit states beyond 1, each against its own objective" in text
    assert ") (" not in text  # the flagship's summary set two brackets back to back: '(… table) (a limit state …)'
    # what the governing limit state rests on is among the summary's assumptions
    assert (f"limit states: {len(damage.limit_states)} capacities, each with its objective, as the Damage section lists them; each λ "
            "from its fit where the runs pin it") in text
    unreached = store_damage(store, [LimitState("ductility", 1.0e4, target=0.1)], "a test")
    text = design_summary_text(risk, None, unreached)
    # as run no run reaches it; counted apart, the collapses do, more often than 10 % in 50 yr allows: the treatments disagree
    collapse = unreached.risk["maf_collapses_apart"].item()
    assert collapse > -math.log(0.9) / 50.0
    assert ("Governing limit state (the largest λ/λ_target of the limit states beyond 1, each against its own objective, the same at "
            "every target; pounding at g* has 1; each ratio in the Damage section): as run, no limit state beyond its objective; with the "
            "runs beyond the model counted apart as collapses, peak storey ductility ≥ 10000 in 1 of 1 configurations") in text
    # said once, not once per target (the flagship's summary repeated the whole verdict for 10 % and for 2 % in 50 yr)
    assert text.count("Governing limit state") == 1 and text.count("the two treatments disagree in 1 of 1 configurations") == 1
    assert ("; the two treatments disagree in 1 of 1 configurations: what governs depends on whether the runs beyond the model are "
            "taken as computed or as collapses. At g*, what limits the separation: pounding between the buildings for 10 % in 50 yr; "
            "pounding between the buildings for 2 % in 50 yr.") in text
    for damage in (store_damage(store, [LimitState("ductility", 1.0e4)], "a test"), None):  # no objective: nothing ranked
        text = design_summary_text(risk, None, damage)
        assert ("Limit state judged (no structural limit state with an objective, so none is ranked against it; at g*, what limits the "
                "separation): pounding between") in text
        assert "Governing" not in text


def test_the_design_summary_says_how_many_runs_are_beyond_the_model(store):
    """The summary's assumptions count the runs beyond the model's drift (from StoreDamage), and say nothing of it without them."""
    import dataclasses

    from stochpound.report.sections._risk import design_summary_text
    from stochpound.risk import store_risk
    risk, damage = store_risk(store), store_damage(store)
    beyond, runs = int(damage.beyond_model.sum()), int(damage.runs.sum())
    assert beyond > 0, "the weak storeys of this store drift beyond the model at the top stripe"
    assert f"beyond the model: {beyond} of {runs} runs exceed a {100 * MODEL_DRIFT_LIMIT:g} % storey drift" in design_summary_text(risk, None, damage)
    assert "beyond the model" not in design_summary_text(risk, None, None)
    within = dataclasses.replace(damage, beyond_model=damage.beyond_model * 0)
    assert "beyond the model" not in design_summary_text(risk, None, within)
    # every assumption of this fixed, yielding pair with a [design], each derived from the store; none of a sliding base or walls
    text = design_summary_text(risk, None, damage)
    for said in ("storeys: B1: storey heights 3, 3 m (the drift ratios, their limit states and P-Δ rest on them), damping ratio 5 %, "
                 "bilinear storeys, F_y = 100, 70 kN", "No storey loses strength, degrades or collapses (no such model)",
                 "gap identity: a run with gap g pounds if and only if", "suite: 8 motions ran (records without a named suite)",
                 "code design: ASCE 7-16: S_DS = 1.329 g, S_D1 = 0.802 g, T_L = 8 s, R = 8, C_d = 5.5, Ω0 = 3, I_e = 1"):
        assert said in text, said
    assert all(absent not in text for absent in ("sliding base:", "moat walls:", "chapter 17 (", "simulated motions:", "Coulomb"))


def _cells(section) -> list[str]:
    """Every paragraph and every table cell of a section, as text."""
    texts = [_text(block) for block in section.blocks]
    return texts + [str(cell) for block in section.blocks if hasattr(block, "frame") for cell in block.cell_text().to_numpy().ravel()]


def test_the_damage_of_elastic_buildings_has_no_nan_and_no_warning(store):
    """Elastic buildings (storey heights, no yield force) store NaN ductility: their Damage section says they are elastic, with
    no 'nan' cell and no RuntimeWarning; with one building elastic, its ductility cells say so and the other's stand."""
    import warnings

    elastic = store.assign(peak_ductility=store["peak_ductility"] * np.nan)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        damage = store_damage(elastic)
        section = damage_section("yfix", damage)
    assert damage.elastic == ("B1", "B2") and "peak_ductility" not in damage.demands
    assert damage.runs.equals(store_damage(store).runs)  # the runs done are counted without a ductility
    cells = _cells(section)
    assert not any("nan" in cell.lower() for cell in cells), [cell for cell in cells if "nan" in cell.lower()]
    assert "The buildings are elastic (no storey yields in any run)" in " ".join(cells) and "ductility, median" not in " ".join(
        str(c) for block in section.blocks if hasattr(block, "frame") for c in block.frame.columns)
    one = store.assign(peak_ductility=store["peak_ductility"].where(store["building"] == "B1"))
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        damage = store_damage(one)
        section = damage_section("yfix", damage)
    assert damage.elastic == ("B2",)
    table = next(block for block in section.blocks if getattr(block, "key", "") == "table-damage-yfix").frame
    assert table.loc[("–", "1.2031 (2 %/50 yr)", "B2"), "peak storey ductility, median"] == "elastic"
    median = float(store_damage(store).demands["peak_ductility"].sel(intensity=1.2031, building="B1", quantile=0.5))
    assert table.loc[("–", "1.2031 (2 %/50 yr)", "B1"), "peak storey ductility, median"] == f"{median:.3g}"
    assert not any("nan" in cell.lower() for cell in _cells(section))


# ---------------------------------------------------------------- collapse as PBEE treats it (issue 45 item 3)


def test_collapses_are_counted_apart_and_combined_by_total_probability(store):
    """The runs past the model's 5 % drift are collapses: counted by hand, P(C | IM) fitted on them, and
    λ_P(g) = ∫ [P_C + (1 − P_C) P(P | no C)] |dλ|. Checks with closed forms: no collapse at all (a limit no run passes) gives the
    chain's own g* (an independent integrator: trapezoids against Gauss–Legendre); at a gap no credible run reaches,
    P(P | no C) ≡ 0 and λ_P is λ_C."""
    from stochpound.risk import collapse_risk, mean_annual_frequency, store_risk, stripe_fragility

    risk = store_risk(store, bootstrap=0)
    gaps, targets = risk.fragility["gap"].values, risk.separation["target"].values
    collapse = collapse_risk(store, risk.hazard, gaps, targets)
    drift = contact_free(store)["peak_drift_ratio"].max("building").isel(realization=0, drop=True)
    hand = (drift > MODEL_DRIFT_LIMIT).astype(float).where(drift.notnull())
    assert collapse.collapsed == int(hand.sum()) > 0 and collapse.runs == int(drift.notnull().sum())
    np.testing.assert_array_equal(collapse.collapse["exceeded"].values.ravel(), hand.sum("record").values.ravel())
    fit = stripe_fragility(hand, bootstrap=0)
    assert float(collapse.collapse["maf"]) == pytest.approx(float(mean_annual_frequency(fit, risk.hazard)), rel=1e-12)
    # no collapse: the chain's g*, to the integrators' difference
    none = collapse_risk(store, risk.hazard, gaps, targets, limit=1.0e9)
    assert none.collapsed == 0
    np.testing.assert_allclose(none.separation["separation"].values, risk.separation["separation"].values, rtol=2e-3)
    # the widest gap: no credible run reaches it, so only collapses pound there
    closure = contact_free(store)["peak_contact_closure"].max("contact").isel(realization=0, drop=True)
    assert float(closure.where(hand == 0.0).max()) < gaps[-1]
    assert float(collapse.maf.isel(gap=-1)) == pytest.approx(float(collapse.collapse["maf"]), rel=2e-3)
    # the answer both ways: collapse alone is more frequent than either target here, so no gap meets them
    assert float(collapse.collapse["maf"]) > -np.log(1 - 0.1) / 50
    frame = collapse.both_ways(risk.separation)
    assert list(frame["g* collapses apart (m)"]) == [np.inf, np.inf]
    np.testing.assert_allclose(frame["g* as run (m)"].values, risk.separation["separation"].values.ravel(), rtol=1e-12)
    assert list(frame["runs beyond the model"]) == [f"{collapse.collapsed} of {collapse.runs}"] * 2
    assert "there the structure, not the gap, governs" in collapse.text()


def test_stochpound_risk_and_the_report_give_g_star_both_ways(store, tmp_path):
    from click.testing import CliRunner

    from stochpound.cli import main
    from stochpound.report.sections._risk import risk_section
    from stochpound.risk import collapse_risk, store_damage, store_risk

    path = tmp_path / "yfix.nc"
    store.to_netcdf(path)
    result = CliRunner().invoke(main, ["risk", str(path), "--bootstrap", "0"])
    assert result.exit_code == 0, result.output
    assert "Collapse as FEMA P-58 treats it:" in result.output and "g* both ways (m):" in result.output
    risk = store_risk(store, bootstrap=0)
    collapse = collapse_risk(store, risk.hazard, risk.fragility["gap"].values, risk.separation["target"].values)
    section = risk_section("yfix", risk, None, store_damage(store), None, collapse)
    assert any(getattr(block, "key", "") == "risk-collapse-yfix" for block in section.blocks)
    summary = " ".join(_text(block) for block in section.blocks)
    assert "g* with them counted apart as collapses (FEMA P-58, by total probability) is given beside it" in summary
    assert "they enter g* and the limit states as computed" not in summary


def test_the_sensitivity_table_recomputes_g_star_under_each_choice(store):
    """Issue 45 item 4: the grid refined once more near g* (the chain refitted on the chain's grid with each bracket of a g*
    split 4 times), the collapse treatment, β_m folded into the fragility; a vanishing β_m gives g* back (a closed-form limit),
    and Δ is the change from g*."""
    from stochpound.risk import collapse_risk, separation_sensitivity, sensitivity_text, store_risk
    from stochpound.risk._gap_grid import refinement_gaps

    risk = store_risk(store, bootstrap=0)
    gaps = risk.fragility["gap"].values
    collapse = collapse_risk(store, risk.hazard, gaps, risk.separation["target"].values)
    sensitivity = separation_sensitivity(risk, store, collapse, dispersions=(1e-6, 0.3))
    frame = sensitivity.frame
    fine = np.union1d(gaps, refinement_gaps(gaps, risk.separation, tolerance=0.0, split=4))
    assert fine.size > gaps.size
    refined = store_risk(store, risk.hazard, gaps=fine, bootstrap=0, grid_tolerance=None).separation["separation"].values.ravel()
    np.testing.assert_allclose(frame["grid ×4 finer near g*"].values, refined, rtol=1e-12)
    np.testing.assert_allclose(frame["g* (m)"].values, risk.separation["separation"].values.ravel(), rtol=1e-12)
    np.testing.assert_allclose(frame["β_m = 1e-06"].values, frame["g* (m)"].values, rtol=1e-4)
    np.testing.assert_allclose(frame["grid ×4 finer near g*: Δ (%)"].values, 100 * (refined / frame["g* (m)"].values - 1), rtol=1e-12)
    assert list(frame["collapses apart"]) == [np.inf, np.inf]
    # a pair without walls: their stiffness is no choice its answer rests on (the fixed flagship listed it as not evaluated)
    assert sensitivity.not_evaluated == ("seed", "measure") and "moat wall" not in sensitivity.text()
    text = sensitivity_text(frame, not_evaluated=("seed", "measure", "wall"))
    assert "Not evaluated (each needs other runs): the selection seed (needs a store of the same experiment with another" in text
    assert "bound the record-to-record sampling of the motions only" in text


def test_a_rule_row_whose_fit_is_a_step_at_the_lowest_stripe_says_its_rate_is_a_bound(store):
    """Issue 45: 'Steps at the lowest stripe are printed as rates; they are bounds (nothing is known below)'. Each rule row's
    fit is named from the rule's own fit: a step (always, or separated with θ at the lowest stripe) says its λ_P is a bound."""
    from stochpound.risk import store_risk
    from stochpound.risk._chain import LOWEST_STRIPE_STEP, RULE_NAMES
    from stochpound.risk._fragility import ALWAYS, SEPARATED

    risk = store_risk(store, bootstrap=0)
    rows = risk.rules_frame()
    lowest = float(store["intensity"].min())
    flagged = 0
    for rules in (risk.rules, risk.design_rules):
        if rules is None or "theta" not in rules:
            continue
        step = ((rules["status"] == ALWAYS) | ((rules["status"] == SEPARATED) & (rules["theta"] <= lowest * (1 + 1e-9))))
        flagged += int(step.where(rules["gap"].notnull().all("contact")).sum()) if "contact" in rules["gap"].dims else int(step.sum())
    assert int((rows["fit"] == LOWEST_STRIPE_STEP).sum()) == flagged
    # this store's rules are all lognormals: make one suite-mean rule's fit a step at the lowest stripe, and another just above it
    import dataclasses

    status, theta = risk.rules["status"].copy(), risk.rules["theta"].copy()
    first, second = {"rule": risk.rules["rule"].values[0]}, {"rule": risk.rules["rule"].values[1]}
    status.loc[first], theta.loc[first] = SEPARATED, lowest
    status.loc[second], theta.loc[second] = SEPARATED, lowest * 1.01
    stepped = dataclasses.replace(risk, rules=risk.rules.assign(status=status, theta=theta)).rules_frame().reset_index()
    suite_mean = ~stepped["design_level"].str.contains("design analysis")
    fits = {name: set(stepped.loc[suite_mean & (stepped["rule"] == RULE_NAMES.get(rule, rule)), "fit"])
            for name, rule in (("first", first["rule"]), ("second", second["rule"]))}
    assert fits == {"first": {LOWEST_STRIPE_STEP}, "second": {"step: separated"}}  # the step above the lowest stripe keeps its name


def test_a_ratio_that_decides_the_objective_never_prints_as_one():
    """The flagship's table printed λ/λ_target = '1' for 0.0139/0.01386 while the text said the objective was missed."""
    assert (ratio_text(1.003), ratio_text(0.998), ratio_text(1.02), ratio_text(0.25, 2)) == ("1.003", "0.998", "1.02", "0.25")
    # the governs sentence (2 digits) printed '(λ/λ_target = 1)' for 1.03 and 1.01, where the table said they miss the objective
    assert (ratio_text(1.03, 2), ratio_text(1.01, 2), ratio_text(0.96, 2), ratio_text(2.45, 2)) == ("1.03", "1.01", "0.96", "2.5")


def test_a_limit_state_on_a_fit_the_runs_do_not_pin_governs_only_on_its_lower_bound():
    """Issue 45: the isolated flagship named 'peak storey drift ratio of B2 ≥ 0.025' governing with the collapses counted apart
    (λ/λ_target 2.0–2.5) from the credible runs' fit over counts 0, 1, 1, 1, 1, 0, 0 of 40, a flat fit held down to the hazard
    table's 0.01 g, flagged but still governing. A fit the runs do not pin (here a lognormal with θ beyond the top stripe) now
    gives the bounds its stripes' fractions give, and governs only where the lower bound misses the objective; where the bounds
    straddle it the runs leave it open, said so. By hand at the power law λ = 1e-3 x^-2 over stripes 0.2, 0.5, 1 g."""
    import dataclasses

    from stochpound.report.sections._damage import _governing_text, _limit_states_table
    from stochpound.report.sections._risk import _structural_governs
    from stochpound.risk import limit_state_fits
    from stochpound.risk._fragility import DECREASING, FIT

    states, risk, damage = _two_treatments()
    levels = [0.2, 0.5, 1.0]
    fit = {"status": (("limit_state", "mu"), [[FIT, FIT], [FIT, FIT]]), "theta": (("limit_state", "mu"), [[0.5, 0.5], [0.8, 0.8]]),
           "beta": (("limit_state", "mu"), [[0.4, 0.4], [0.5, 0.5]])}
    apart = {f"{name}_collapses_apart": (dims, [[*row] for row in values]) for name, (dims, values) in fit.items()}
    apart["theta_collapses_apart"] = (("limit_state", "mu"), [[0.5, 0.5], [5.0, 0.8]])  # collapse prevention at μ 0.05: beyond the top
    rate = [1e-3 * x**-2.0 for x in levels]
    # collapse prevention at μ 0.05 counted apart: 0, 0 and 1 of 8 reach it (a collapse counted as reaching it)
    low, high = 1 / 8 * rate[2], 1 / 8 * (rate[1] - rate[2]) + rate[2]
    target = -math.log(0.98) / 50
    bounds = {name: (("limit_state", "mu"), [[np.nan, np.nan], [value, np.nan]]) for name, value in
              (("lower_collapses_apart", low), ("upper_collapses_apart", high), ("maf_lower", np.nan), ("maf_upper", np.nan))}
    damage = dataclasses.replace(damage, risk=risk.assign(**fit, **apart, **bounds).assign_coords(intensity=levels))
    assert not bool(damage.pinned(apart=True).sel(mu=0.05, limit_state=states[1].label))
    assert float(damage.judged(apart=True).sel(mu=0.05, limit_state=states[1].label)) == pytest.approx(low / target, rel=1e-12)
    assert low / target < 1.0 < high / target  # the runs leave it open: it no longer governs on its extrapolated fit (2.2)
    assert list(damage.governing(apart=True).values) == ["pounding at g*", states[0].label]
    assert bool(damage.undecided(apart=True).sel(mu=0.05, limit_state=states[1].label))
    text = _governing_text(damage)
    assert (f"left open by the runs (a fit they do not pin, its bounds either side of the objective): {states[1].label} "
            f"({ratio_text(low / target, 2)}–{ratio_text(high / target, 2)} times λ_target)") in text
    summary = _structural_governs(damage)
    assert (f"left open by the runs, its fit not pinning λ and the bounds the stripes give either side of its objective: "
            f"{states[1].label} in 1 of 2 configurations") in summary and ") (" not in summary
    table = _limit_states_table("t", damage).frame
    row = table.loc[("mu 0.05", states[1].label)]
    assert row["fit collapses apart"] == "lognormal, not identified (θ = 5 beyond the top stripe 1)"
    assert row["λ collapses apart (1/yr)"] == f"[{low:.3g}, {high:.3g}]"
    assert row["λ/λ_target collapses apart"] == f"[{ratio_text(low / target)}, {ratio_text(high / target)}]"
    assert row["once in, collapses apart (yr)"] == f"[{1 / high:.3g}, {1 / low:.3g}]"
    # a lower bound beyond the objective governs, said to rest on the lower bound
    above = damage.risk.assign(lower_collapses_apart=damage.risk["lower_collapses_apart"] * 0 + 2 * target)
    damage = dataclasses.replace(damage, risk=above)
    assert list(damage.governing(apart=True).values) == [states[1].label, states[0].label]
    assert damage.governing_unpinned(apart=True) == (states[1].label,)
    assert f"{states[1].label} (λ/λ_target ≥ 2, the lower bound the stripes' fractions alone give" in _governing_text(damage)
    assert (f"{states[1].label} in 1 of 2 configurations (on the lower bound of λ the stripes' fractions alone give: its fit does not "
            "pin λ)") in _structural_governs(damage)
    # a flat fit is not pinned either (the flagship's): its fraction held down to the hazard table's lowest intensity is no rate
    flat = damage.risk.assign(status_collapses_apart=damage.risk["status_collapses_apart"] * 0 + DECREASING)
    assert set(limit_state_fits(flat, apart=True).values.ravel()) == {"flat: decreasing (F ≡ fraction of runs that reached it)"}
    assert not bool(dataclasses.replace(damage, risk=flat).pinned(apart=True).any())


def test_a_base_displacement_limit_state_names_no_stop_the_runs_do_not_have():
    """Issue 45: the isolated flagship's limit state 'base displacement (the bearing's stop) of B1 ≥ 0.6 m' named a stop that no
    configuration without a moat has: it is the base passing 0.6 m, the walled twin's clearance there, the wall in the others."""
    import xarray as xr

    from stochpound.report.sections._damage import _governing_text
    from stochpound.risk import LimitState, StoreDamage

    state = LimitState("isolator_displacement", 0.6, "B1", 0.02)
    assert state.label == "peak base displacement of B1 ≥ 0.6 m"
    risk = xr.Dataset({"maf": (("limit_state", "moat"), [[5e-4, 5e-4]])},
                      coords={"limit_state": [state.label], "moat": ["none", "wall"], "target": ("limit_state", [0.02])})
    walled = xr.DataArray([False, True], dims="moat", coords={"moat": ["none", "wall"]})
    empty = xr.DataArray([0])
    damage = StoreDamage(xr.Dataset(), empty, empty, {0.1: 1.0}, risk, (state,), "a test", True, (), (0.6,), walled)
    text = _governing_text(damage)
    assert ("peak base displacement of B1 ≥ 0.6 m counts the runs whose base passes 0.6 m: no stop is modelled at the bearing in these "
            "runs; 0.6 m is the moat wall's clearance, so in the 1 of 2 configurations with the wall passing it is reaching the wall, and "
            "in the 1 without it the base passes the walled twin's clearance with nothing there.") in text
    assert "stop)" not in text and "bearing's stop" not in text
    # the design summary says the same where it names that limit state governing
    from stochpound.report.sections._risk import _structural_governs

    summary = _structural_governs(StoreDamage(xr.Dataset(), empty, empty, {0.1: 1.0}, risk.assign(maf=risk["maf"] * 0 + 1e-3), (state,),
                                              "a test", True, (), (0.6,), walled))
    assert summary == (f"{state.label} in 2 of 2 configurations; in the 1 configuration without the moat wall, {state.label} is the "
                       "base passing the walled twin's clearance, with no stop modelled there")
