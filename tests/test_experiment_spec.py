"""Experiment files: validation errors name the field, variants derive consistent constants, cases have stable ids."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

import stochpound
from stochpound.experiment import Experiment, ExperimentError, load_experiment, run_experiment
from stochpound.experiment._sources import resolve_motions
from stochpound.experiment._spec import parse_experiment
from tests.helpers import N_CASES, SMALL_EXPERIMENT, cli, write_experiment


def small(**changes) -> dict:
    data = tomllib.loads(SMALL_EXPERIMENT)
    for path, value in changes.items():
        table = data
        keys = path.split("__")
        for key in keys[:-1]:
            table = table[key]
        if value is None:
            table.pop(keys[-1])
        else:
            table[keys[-1]] = value
    return data


def experiment(data: dict) -> Experiment:
    exp = Experiment(parse_experiment(data))
    exp.validate()
    return exp


@pytest.mark.parametrize(
    "changes, message",
    [
        ({"grid__speed": [1.0]}, r"^grid\.speed: unknown axis \(allowed: gap, gap_<name>, mu, neighbour"),
        ({"grid__gap": []}, r"^grid\.gap: must be a non-empty list \(an empty axis makes an empty grid\)"),
        ({"grid__gap": [0.01, -0.02]}, r"^grid\.gap\[1\]: must be >= 0 or inf, got -0.02"),
        ({"grid__gap": [0.01, 0.01]}, r"^grid\.gap\[1\]: repeated value"),
        ({"grid__mu": {"values": [0.1, -0.1]}}, r"^grid\.mu\.values\[1\]: must be >= 0 or inf, got -0.1"),
        ({"grid__mu": {"values": [0.1], "buildings": ["B9"]}}, r"^grid\.mu\.buildings: must be a non-empty list of building names \(B1, B2\)"),
        ({"grid__mu": {"values": [0.1], "buildings": ["B2"]}}, r"^grid\.mu: building\(s\) B2 have no \[building\.base\] in case neighbour=stiff, gap=0.01, mu=0.1"),
        ({"grid__neighbour": ["soft"]}, r"^grid\.neighbour\[0\]: unknown variant 'soft' \(declared: stiff, flexible\)"),
        ({"variants__neighbour__stiff__building__B2__mass_factor": 0.0}, r"^variants\.neighbour\.stiff\.building\.B2\.mass_factor: must be > 0, got 0"),
        ({"variants__neighbour__stiff__building__B3": {"mass_factor": 2.0}}, r"^variants\.neighbour\.stiff\.building\.B3: unknown building \(buildings: B1, B2\)"),
        ({"variants__neighbour__stiff__building__B2__colour": "red"}, r"^variants\.neighbour\.stiff\.building\.B2\.colour: unknown field \(allowed: base, damping"),
        ({"variants__neighbour__stiff__building__B2__damping_ratio": 1.5}, r"^case neighbour=stiff, gap=0.01, mu=0.2: building\[1\]\.damping_ratio: must be < 1, got 1.5"),
        ({"motions": [{"name": "h", "type": "kanai_tajimi"}]}, r"^motions\[0\]\.type: must be one of harmonic, constant \(records go in \[\[records\]\]\), got 'kanai_tajimi'"),
        ({"motions": [{"type": "harmonic"}]}, r"^motions\[0\]\.name: "),
        ({"motions": {"name": "h"}}, r"^motions: must be an array of tables"),
        ({"synthetic__kt__count": 0}, r"^synthetic\.kt\.count: must be an integer in \[1, 100000000\], got 0"),
        ({"synthetic__kt__count": 10**12}, r"^synthetic\.kt\.count: must be an integer in \[1, 100000000\], got 1000000000000$"),
        ({"synthetic__kt__seed": None}, r"^synthetic\.kt\.seed: missing"),
        ({"output__time_histories": ["velocity"]}, r"^output\.time_histories\[0\]: unknown variable 'velocity' \(allowed: total_displacement"),
        ({"solver": {"method": "euler"}}, r"^solver\.method: must be one of auto, exact, ivp, got 'euler'"),
        ({"solver": {"rtol": -1.0}}, r"^solver\.rtol: must be > 0, got -1"),
        ({"experiment__studied": "B7"}, r"^experiment\.studied: must be one of the scene's buildings \(B1, B2\), got 'B7'"),
        ({"scene__building": []}, r"^case neighbour=stiff.*building: at least one \[\[building\]\] is required|experiment\.studied"),
        ({"bogus": 1}, r"^bogus: unknown field \(allowed: design, experiment, grid, hazard, intensity, limit_states, motions, output, records, scene, site, solver, synthetic, variants\)"),
    ],
)
def test_bad_fields_are_named(changes, message):
    with pytest.raises(ExperimentError, match=message):
        experiment(small(**changes))


def test_a_misspelt_count_is_an_unknown_field_listing_count_and_start():
    """``cont = 2`` for ``count = 2``: named as the unknown field, the allowed list has count and start, not the rejected realization."""
    with pytest.raises(ExperimentError) as raised:
        experiment(small(synthetic__kt__count=None, synthetic__kt__cont=2))
    message = str(raised.value)
    assert message.startswith("synthetic.kt.cont: unknown field (allowed: "), message
    allowed = message.split("(allowed: ")[1].rstrip(")").split(", ")
    assert {"count", "start", "seed", "omega_g", "envelope"} <= set(allowed) and "realization" not in allowed, allowed
    with pytest.raises(ExperimentError, match=r"^synthetic\.kt\.realization: not used here"):
        experiment(small(synthetic__kt__realization=3))


def test_bad_motions_are_named(tmp_path):
    path = write_experiment(tmp_path, SMALL_EXPERIMENT.replace('record = "el_centro_1940_study"', 'record = "no_such_record"'))
    with pytest.raises(ExperimentError, match=r"^records\[0\]\.record: .*no_such_record"):
        run_experiment(load_experiment(path), workers=0, progress=False)
    path = write_experiment(tmp_path, SMALL_EXPERIMENT.replace("pga = 3.0", "pga = -3.0"))
    with pytest.raises(ExperimentError, match=r"^synthetic\.kt.*pga"):
        run_experiment(load_experiment(path), workers=0, progress=False)
    assert not (tmp_path / "small.nc").exists() and not (tmp_path / "small.nc.parts").exists()


def test_mass_factor_keeps_damping_ratio_and_impact_frequency():
    exp = experiment(small())
    base = stochpound.scene_from_dict({**exp.structure(exp.cases[-1])})
    for case in exp.cases:
        if case.kind != "case" or case.label_dict["record"] != "el_centro":
            continue
        factor = {"stiff": 0.5, "flexible": 2.0}[case.label_dict["neighbour"]]
        scene = stochpound.scene_from_dict(exp.structure(case))
        b1, b2 = scene.buildings
        assert np.allclose(b2.mass, np.array([26268.0, 17512.0]) * factor, rtol=1e-15)
        assert b2.damping_ratio == 0.01
        for contact in scene.contacts:
            m1, m2 = b1.mass[contact.left_floor - 1], b2.mass[contact.right_floor - 1]
            effective = m1 * m2 / (m1 + m2)
            assert math.sqrt(contact.stiffness / effective) == pytest.approx(57.05, rel=1e-8)
            xi = -math.log(0.5) / math.sqrt(math.pi**2 + math.log(0.5) ** 2)
            assert contact.damping == pytest.approx(2 * xi * math.sqrt(contact.stiffness * effective), rel=1e-12)
            assert contact.gap == case.label_dict["gap"]
        mu = case.label_dict["mu"]
        assert (b1.base is None) if math.isinf(mu) else (b1.base.mu == mu and b1.base.mu_static == mu)
    # the flexible pair of the study: k_imp = 56 993 585 N/m at floor 1 (the reference study's Table 3.3)
    flexible = next(c for c in exp.cases if c.kind == "case" and c.label_dict["neighbour"] == "flexible")
    assert stochpound.scene_from_dict(exp.structure(flexible)).contacts[0].stiffness == pytest.approx(56993585.0, rel=1e-4)
    assert base.buildings[0].name == "B1"


def test_mass_factor_scales_dashpots_by_sqrt_and_keeps_explicit_contact_damping_ratio():
    data = small()
    data["scene"]["building"][1] = {**data["scene"]["building"][0], "name": "B2"}
    data["scene"]["building"][1].pop("base")
    data["scene"]["contact"][0] = {**data["scene"]["contact"][0], "damping": 1000.0}
    data["scene"]["contact"][0].pop("restitution")
    exp = experiment(data)
    stiff = next(c for c in exp.cases if c.kind == "case" and c.label_dict["neighbour"] == "stiff")
    scene = stochpound.scene_from_dict(exp.structure(stiff))
    assert scene.buildings[1].damping == pytest.approx((23634.2 * math.sqrt(0.5), 16881.57 * math.sqrt(0.5)), rel=1e-14)
    ratio = (26268.0 * 13134.0 / 39402.0) / (26268.0 / 2)
    assert scene.contacts[0].damping == pytest.approx(1000.0 * ratio, rel=1e-12)


def test_cases_grid_and_reference():
    exp = experiment(small())
    assert [d.name for d in exp.dims] == ["neighbour", "gap", "mu", "record", "realization"]
    assert [d.name for d in exp.reference_dims] == ["record", "realization"]
    assert len(exp.cases) == N_CASES
    assert len({c.case_id for c in exp.cases}) == N_CASES
    reference = [c for c in exp.cases if c.kind == "reference"]
    assert len(reference) == 3
    structure = exp.structure(reference[0])
    assert [b["name"] for b in structure["building"]] == ["B1"] and "base" not in structure["building"][0] and structure["contact"] == []
    # ids do not depend on the order of the axes' values
    reordered = small(grid__gap=[0.02, 0.01])
    other = experiment(reordered)
    assert {c.case_id for c in other.cases} == {c.case_id for c in exp.cases}
    assert other.sha256 != exp.sha256


def test_variant_touching_the_studied_building_enters_the_reference():
    data = small()
    data["variants"]["heavy"] = {"yes": {"building": {"B1": {"mass_factor": 1.5}}}, "no": {}}
    exp = experiment(data)
    assert [d.name for d in exp.reference_dims] == ["heavy", "record", "realization"]
    assert sum(c.kind == "reference" for c in exp.cases) == 6


def test_check_command_and_load(tmp_path):
    path = write_experiment(tmp_path)
    assert len(load_experiment(path).cases) == N_CASES
    out = cli("experiment", "check", str(path)).stdout
    assert "24 cases + 3 fixed-base reference cases" in out and "neighbour" in out


def test_analytic_motions_are_labelled_and_run(tmp_path):
    data = small(records=None, synthetic=None)
    data["motions"] = [
        {"name": "slow", "type": "harmonic", "amplitude": 1.0, "omega": 2.0, "duration": 2.0, "dt": 0.01},
        {"name": "push", "type": "constant", "acceleration": 0.5, "duration": 2.0, "dt": 0.01},
    ]
    exp = experiment(data)
    assert {case.label_dict["record"] for case in exp.cases} == {"slow", "push"}
    with pytest.raises(ExperimentError, match=r"^motions\[1\]\.amplitude: unknown field"):
        bad = small(records=None, synthetic=None)
        bad["motions"] = [data["motions"][0], {**data["motions"][1], "amplitude": 1.0}]
        resolve_motions(experiment(bad))


def test_run_takes_several_files_but_one_store(tmp_path):
    first = write_experiment(tmp_path)
    second = write_experiment(tmp_path, name="other.toml")
    result = cli("experiment", "run", str(first), str(second), "--store", str(tmp_path / "x.nc"), check=False)
    assert result.returncode != 0 and "--store names one store" in result.stderr
    result = cli("experiment", "run", str(first), str(tmp_path / "missing.toml"), check=False)
    assert result.returncode != 0 and not (tmp_path / "small.nc").exists()


def _yielding_b2(data: dict) -> dict:
    data["scene"]["building"][1].update(yield_force=[2.0e5, 1.2e5], hardening=0.02)
    return data


def test_a_variant_sets_yield_force_and_hardening():
    """A variant replaces a building's yield shears and hardening; mass_factor leaves the yield shears as given (N)."""
    data = _yielding_b2(small())
    data["variants"]["neighbour"]["stiff"]["building"]["B2"].update(yield_force=[1.0e5, 6.0e4], hardening=0.05)
    exp = experiment(data)
    seen = {}
    for case in exp.cases:
        if case.kind == "case":
            b2 = stochpound.scene_from_dict(exp.structure(case)).buildings[1]
            seen[case.label_dict["neighbour"]] = (b2.yield_force, b2.hardening, b2.mass[0])
    assert seen["stiff"] == ((1.0e5, 6.0e4), 0.05, pytest.approx(26268.0 * 0.5))
    assert seen["flexible"] == ((2.0e5, 1.2e5), 0.02, pytest.approx(26268.0 * 2.0))  # mass × 2, strength unchanged


@pytest.mark.parametrize(
    "fields, message",
    [
        ({"yield_force": [1.0e5, -1.0]}, r"^case neighbour=stiff, gap=0.01, mu=0.2: building\[1\]\.yield_force\[1\]: must be > 0, got -1"),
        ({"yield_force": [1.0e5]}, r"^case neighbour=stiff, gap=0.01, mu=0.2: building\[1\]\.yield_force: must have 2 values"),
        ({"hardening": 1.0}, r"^case neighbour=stiff, gap=0.01, mu=0.2: building\[1\]\.hardening: must be < 1, got 1"),
    ],
)
def test_bad_yielding_variants_are_named(fields, message):
    data = _yielding_b2(small())
    data["variants"]["neighbour"]["stiff"]["building"]["B2"].update(fields)
    with pytest.raises(ExperimentError, match=message):
        experiment(data)


def test_a_variant_cannot_give_hardening_to_an_elastic_building():
    data = small()
    data["variants"]["neighbour"]["stiff"]["building"]["B2"]["hardening"] = 0.02
    with pytest.raises(ExperimentError, match=r"^case neighbour=stiff, gap=0.01, mu=0.2: building\[1\]\.hardening: only a building with yield_force"):
        experiment(data)


def test_a_bundled_scenes_edit_sets_yield_force_and_hardening():
    from tests.helpers import FIXED, RECORDS
    text = f'[experiment]\nname = "e"\nstudied = "B1"\n{FIXED}[scene.building.B1]\nyield_force = [2.0e5, 1.2e5]\nhardening = 0.03\n[grid]\ngap = [0.02]\n{RECORDS}'
    exp = experiment(tomllib.loads(text))
    b1 = stochpound.scene_from_dict(exp.structure(next(c for c in exp.cases if c.kind == "case"))).buildings[0]
    assert (b1.yield_force, b1.hardening) == ((2.0e5, 1.2e5), 0.03)
