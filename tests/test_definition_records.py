"""The typed definition (stochpound.store): every table parses to a record, and the canonical dict is written from them.

``Definition.to_dict`` writes the canonical definition from the records; read back
(``read_definition``) and written again, every shipped experiment's definition is the
same dict, with the same JSON and the same identity. The records are values, not
dicts: ``Intensity`` and ``Hazard`` hold a ``stochpound.motions.Measure``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path

import pytest

from stochpound.experiment import is_rare_event_file
from stochpound.experiment._spec import load_definition
from stochpound.motions import DEFAULT_G, Measure
from stochpound.store import (Design, DesignEc8, Hazard, Intensity, LimitStateCapacities, LimitStates, Site, canonical_json, definition_sha256,
                              read_definition, scene_g)

ROOT = Path(__file__).resolve().parents[1]
EXPERIMENTS = sorted(p for p in (ROOT / "experiments").rglob("*.toml") if "scenes" not in p.parts and not is_rare_event_file(p))  # rare-event files: their own definition


@pytest.mark.parametrize("path", EXPERIMENTS, ids=lambda p: str(p.relative_to(ROOT / "experiments")))
def test_the_canonical_dict_written_from_the_records_is_the_parsed_one(path):
    parsed, _ = load_definition(path)
    definition = read_definition(parsed)
    written = definition.to_dict()
    assert written == parsed and canonical_json(written) == canonical_json(parsed)
    assert definition.sha256 == definition_sha256(parsed)
    assert read_definition(canonical_json(parsed)).to_dict() == read_definition(parsed).to_dict()  # through the stored JSON too


def test_a_risk_experiments_tables_are_typed_records():
    definition = read_definition(load_definition(ROOT / "experiments" / "risk" / "isolated.toml")[0])
    intensity, hazard = definition.intensity, definition.hazard
    assert isinstance(intensity, Intensity) and not isinstance(intensity, Mapping)
    assert intensity.measure == Measure("psa", 2.0, (), 0.05) and intensity.measure.kind == "psa"
    assert intensity.description == "PSA(T = 2 s, 5 % damping)" and intensity.selection_method == "conditional_spectrum"
    assert isinstance(hazard, Hazard) and not isinstance(hazard, Mapping)
    assert hazard.measure == intensity.measure and hazard.bundled == "fox_plaza_los_angeles_sa2p0s" and hazard.im and len(hazard.im) == len(hazard.rate)
    assert isinstance(definition.design, Design) and definition.design.sds == 1.33611 and definition.design.tl == 8.0
    limit_states = definition.limit_states
    assert isinstance(limit_states, LimitStates) and limit_states.source.startswith("FEMA 356")
    assert LimitStateCapacities("drift_ratio", (0.007, 0.025, 0.05)) in limit_states.states
    assert LimitStateCapacities("residual_drift_ratio", (0.01,)) in limit_states.states
    assert isinstance(definition.site, Site) and definition.site.scenario == "fitted" and "fox_plaza_los_angeles_pga" in definition.site.curves


def test_each_record_writes_its_entry_back():
    design = {"sds": 1.0, "sd1": 0.6, "tl": 8.0, "r": 8.0, "cd": 5.5, "omega0": 3.0, "ie": 1.0, "sm1": 1.2, "ec8": {"ag": 0.3, "ground": "B", "q": 4.0}}
    assert Design.from_entry(design).entry() == design and Design.from_entry(design).ec8 == DesignEc8(0.3, "B", 4.0)
    limit_states = {"source": None, "capacities": {"drift_ratio": [0.01, 0.02], "ductility": {"B1": [2.0], "B2": [3.0, 4.0]}}}
    assert LimitStates.from_entry(limit_states).entry() == limit_states
    assert [(s.kind, s.building) for s in LimitStates.from_entry(limit_states).states] == [("drift_ratio", None), ("ductility", "B1"), ("ductility", "B2")]
    targeted = {**limit_states, "targets": {"drift_ratio": [0.5, 0.1], "ductility": {"B2": [0.1, 0.02]}}}  # issue 45: objectives
    assert LimitStates.from_entry(targeted).entry() == targeted
    assert [s.targets for s in LimitStates.from_entry(targeted).states] == [(0.5, 0.1), None, (0.1, 0.02)]
    isolated = {**design, "isolation": {"plan": [12.0, 18.0], "lambda_min": 0.7, "sa_short": 1.82, "sa_long": 1.2, "spectrum_source": "x"}}
    assert Design.from_entry(isolated).entry() == isolated and Design.from_entry(isolated).isolation.plan == (12.0, 18.0)
    for site in ({"scenario": "given"}, {"scenario": "fitted", "curves": ["a", "b"]}, {"scenario": "ruptures", "ruptures": "demo"}):
        assert Site.from_entry(site).entry() == site
    law = {"source": "power_law", "measure": "pga", "units": "g", "extrapolate": False, "power_law": {"k0": 2.0e-4, "k": 2.2}, "provenance": "λ"}
    assert Hazard.from_entry(law).entry() == law and Hazard.from_entry(law).im == ()


def test_g_has_one_reader_and_one_default():
    assert scene_g({}) == DEFAULT_G == 9.81 and scene_g({"g": 10}) == 10.0 and isinstance(scene_g({"g": 10}), float)
    definition = read_definition(load_definition(ROOT / "experiments" / "quickstart.toml")[0])
    assert definition.g == scene_g(definition.scene) and math.isfinite(definition.g)
