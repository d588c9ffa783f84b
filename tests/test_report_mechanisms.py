"""The report states the mechanisms the store holds (ratcheting, amplification by impacts, wall penetration), and only those."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from stochpound.analysis import StoreEnsemble
from stochpound.experiment import open_store
from stochpound.report.sections._ensembles import MIN_RUNS, Ensemble
from stochpound.report.sections._mechanism_findings import (
    _lowered_summary, _pushed_summary, amplification_text, mechanism_answer, mechanism_findings, ratcheting_text,
)
from stochpound.store import wall_axis
from tests.helpers import run_in_process

N = 40


class Runs:
    """The part of an ensemble the mechanism sentences read: per-run samples of the studied building."""

    def __init__(self, samples: dict[str, xr.DataArray]) -> None:
        self.samples, self.label, self.studied, self.confidence, self.sliding = samples, "kt", "B1", 0.95, True

    def sample(self, variable: str) -> xr.DataArray:
        return self.samples[variable]

    ratcheting_against = StoreEnsemble.ratcheting_against
    amplification_over = StoreEnsemble.amplification_over


def _runs(values: np.ndarray) -> xr.DataArray:
    return xr.DataArray(values, dims="realization", coords={"realization": np.arange(len(values))})


@pytest.fixture
def free() -> xr.DataArray:
    return _runs(np.random.default_rng(5).normal(0.0, 0.05, N))


def test_ratcheting_is_stated_where_the_runs_hold_it(free):
    pushed = (free - 0.1).expand_dims(gap=[0.02])
    text = ratcheting_text(Runs({"residual_sliding": pushed}), Runs({"residual_sliding": free}), away=-1)
    assert "pounding ratchets B1's sliding base" in text and f"in 1 of the 1 cell with contacts that have at least {MIN_RUNS}" in text
    assert f"at gap 2 cm, mean abs(residual sliding) {float(abs(pushed).mean()) * 100:.3g} cm" in text and f"(n = {N})" in text
    assert "No resolved ratcheting" not in text


def test_ratcheting_absent_is_said_to_be_absent(free):
    same = (free + np.random.default_rng(6).normal(0.0, 0.001, N)).expand_dims(gap=[0.02])
    text = ratcheting_text(Runs({"residual_sliding": same}), Runs({"residual_sliding": free}), away=-1)
    assert "it does not ratchet it in any of them" in text and "No resolved ratcheting at gap 2 cm" in text
    assert "pounding ratchets B1's sliding base —" in text and "in 0 of the 1 cell" in text
    few = same.where(same.realization < MIN_RUNS - 1)
    assert "not assessed: no cell has" in ratcheting_text(Runs({"residual_sliding": few}), Runs({"residual_sliding": free}), away=-1)
    assert "not assessed" in ratcheting_text(Runs({"residual_sliding": same}), Runs({"residual_sliding": free}), away=None)


def test_amplification_is_stated_with_its_ratio_and_absent_when_there_is_none():
    twin = _runs(np.random.default_rng(7).uniform(2.0, 4.0, N))
    raised = xr.concat([twin * 9.0, twin], dim="moat").assign_coords(moat=["w05", "w10"])
    text = amplification_text(Runs({"peak_floor_acceleration": raised}), Runs({"peak_floor_acceleration": twin}),
                              "peak_floor_acceleration", "a wall", "the same motion without a wall")
    assert "It raises it in 1 of the 2 cells" in text and "moat w05: 9 [9, 9] times" in text and "No resolved change at moat w10" in text


@pytest.fixture(scope="module")
def moat_store(tmp_path_factory):
    """A sliding building with and without a moat wall 2 cm away, 30 soft-soil realizations (demands kept)."""
    text = f"""
[experiment]
name = "moat_test"
studied = "B1"

[scene]
g = 9.814

[[scene.building]]
name = "B1"
mass = [26268.0, 17512.0]
stiffness = [24516800.0, 17512000.0]
damping = [23634.2, 16881.57]
base = {{ mass = 13134.0, mu = 0.05 }}

[variants.moat.none]

[[variants.moat.w02.scene.wall]]
building = "B1"
side = "left"
level = 0
gap = 0.02
stiffness = 42747262.6
restitution = 0.5

[[variants.moat.w02.scene.wall]]
building = "B1"
side = "right"
level = 0
gap = 0.02
stiffness = 42747262.6
restitution = 0.5

[synthetic.kt_soft]
type = "kanai_tajimi"
count = {MIN_RUNS}
seed = 20042
omega_g = 5.0
zeta_g = 0.2
pga = 3.0
envelope = "jennings"
duration = 10.0
dt = 0.02

[output]
impacts = true
demands = true
"""
    return run_in_process(tmp_path_factory.mktemp("moat"), "moat_test", text)


def test_a_moat_store_states_the_wall_s_amplification_and_its_largest_penetration(moat_store):
    with open_store(moat_store) as store:
        assert wall_axis(store) == ("moat", "none")
        texts = [block.text for block in mechanism_findings("moat_test", store, "kt_soft")]
        answer = mechanism_answer("moat_test", store)
        penetration = store["peak_wall_penetration"].sel(moat="w02")
        largest = float(penetration.max())
        assert np.isnan(store["peak_wall_penetration"].sel(moat="none")).all() and largest > 0
    assert len(texts) == 3 and not any("Ratcheting" in t for t in texts)  # no contacts: no contact-free twins
    acceleration, drift, wall = texts
    assert acceleration.startswith("Amplification of the peak floor acceleration by a wall (kt_soft, B1)") and "It raises it in 1 of the 1 cell" in acceleration
    assert drift.startswith("Amplification of the peak storey drift by a wall") and "raises it in 1 of the 1" in drift
    assert f"the largest penetration is {largest * 100:.3g} cm" in wall and "at moat w02, realization" in wall
    assert "(k = 42.75 MN/m)" in wall
    assert "ensemble kt_soft: a wall raises the peak floor acceleration in 1 of 1 cell" in answer
    assert f"the walls were penetrated by up to {largest * 100:.3g} cm" in answer and "ratchets" not in answer
    with open_store(moat_store) as store:
        tables = Ensemble("moat_test", store, "kt_soft").tables()
    displacements = next(table for table in tables if table.key.endswith("-displacements"))
    assert displacements.caption.endswith("and the largest penetration of a wall per run.")


def test_a_pair_with_contact_free_twins_gets_the_ratcheting_and_pounding_findings_in_its_section(tmp_path):
    """The store section, given the whole store, compares the cases with contacts with their contact-free twins."""
    from stochpound.store import with_contacts
    from stochpound.report.sections._generic import store_section
    from stochpound.studies.agarwal2004 import reference_building, study_contacts
    from tests.helpers import toml_tables

    text = f"""
[experiment]
name = "pair_test"
studied = "B1"

[scene]
g = 9.814
{toml_tables("building", [reference_building("B1", 1.0, 0.05), reference_building("B2", 1.0)])}
{toml_tables("contact", study_contacts(0.01))}

[grid]
gap = [0.01, inf]
mu = {{ values = [0.05], buildings = ["B1"] }}

[synthetic.kt]
type = "kanai_tajimi"
count = {MIN_RUNS}
seed = 2024
omega_g = 15.0
zeta_g = 0.6
pga = 3.0
envelope = "jennings"
duration = 10.0
dt = 0.02

[output]
impacts = true
demands = true
"""
    with open_store(run_in_process(tmp_path, "pair_test", text)) as store:
        section = store_section("pair_test", with_contacts(store), True, store)
    texts = [getattr(block, "text", "") for block in section.blocks]
    ratchet = next(t for t in texts if t.startswith("Ratcheting (kt, B1): "))
    assert "with contacts that have at least" in ratchet and "(to the left)" in ratchet
    assert any(t.startswith("Amplification of the peak floor acceleration by pounding (kt, B1)") for t in texts)
    assert not any(t.startswith("Wall penetration") for t in texts)
    with open_store(tmp_path / "pair_test.nc") as store:
        answer = mechanism_answer("pair_test", store)
    assert "pounding ratchets B1's sliding base in" in answer and "pounding raises the peak floor acceleration in" in answer


def test_walls_of_the_base_scene_state_their_largest_penetration(tmp_path):
    """Without a wall axis (walls in the base scene) the penetration is still stated, over every run, and no amplification claimed."""
    text = f"""
[experiment]
name = "walled"
studied = "B1"

[scene]
g = 9.814

[[scene.building]]
name = "B1"
mass = [26268.0, 17512.0]
stiffness = [24516800.0, 17512000.0]
damping = [23634.2, 16881.57]
base = {{ mass = 13134.0, mu = 0.05 }}

[[scene.wall]]
building = "B1"
side = "right"
level = 0
gap = 0.01
stiffness = 42747262.6
restitution = 0.5

[synthetic.kt]
type = "kanai_tajimi"
count = {MIN_RUNS}
seed = 20042
omega_g = 5.0
zeta_g = 0.2
pga = 3.0
envelope = "jennings"
duration = 5.0
dt = 0.02
"""
    with open_store(run_in_process(tmp_path, "walled", text)) as store:
        assert wall_axis(store) is None
        largest = float(store["peak_wall_penetration"].max())
        texts = [block.text for block in mechanism_findings("walled", store, "kt")]
        answer = mechanism_answer("walled", store)
    assert largest > 0 and len(texts) == 1
    assert answer == f"Which mechanisms do the runs show? ensemble kt: the walls were penetrated by up to {largest * 100:.3g} cm."
    assert texts[0].startswith("Wall penetration (kt, B1)") and f"Over the {MIN_RUNS} runs with a wall the largest penetration is {largest * 100:.3g} cm" in texts[0]
    assert "per value of" not in texts[0]


def test_a_residual_pushed_away_without_a_change_of_size_is_its_own_class_with_its_size_in_the_summary():
    half = 0.01 + np.abs(np.random.default_rng(8).normal(0.0, 0.05, N // 2))
    free = _runs(np.concatenate([half, -half]))  # as many residuals right as left, none within 1 cm of the start
    pushed = (free - 0.002 + np.random.default_rng(9).normal(0.0, 0.0005, N)).expand_dims(gap=[0.02])  # 2 mm further left: abs ± 2 mm
    pounding, twins = Runs({"residual_sliding": pushed}), Runs({"residual_sliding": free})
    found = pounding.ratcheting_against(twins, away=-1)
    assert found.flagged_count == 0 and len(found.pushed()) == 1 and not found.lowered()
    text = ratcheting_text(pounding, twins, away=-1)
    assert "In 1 cell the impacts push the residual away from the neighbour without a resolved change of its size" in text
    assert "nearer its start" not in text
    push = -float((pushed.squeeze("gap") - free).mean()) * 100  # cm to the left (away), the paired mean computed here
    assert _pushed_summary(found) == (f" and pushes its residual away from the neighbour (by {push:.2g} cm on average), without a resolved "
                                      "change of its size, in 1 more")


def test_a_residual_moved_back_from_the_neighbours_side_is_lowered_not_pushed(free):
    """Moved away from the neighbour and made smaller (a base left toward the neighbour brought back to its start): one class only,
    the lowered one, in the findings and in the summary (it was counted in both, and as a push away in the summary)."""
    start = _runs(np.random.default_rng(8).normal(0.05, 0.005, N))
    back = (start - 0.05 + np.random.default_rng(9).normal(0.0, 0.001, N)).expand_dims(gap=[0.02])
    pounding, twins = Runs({"residual_sliding": back}), Runs({"residual_sliding": start})
    found = pounding.ratcheting_against(twins, away=-1)
    assert float(found.found["away_change_lower"].squeeze()) > 0  # it did move away from the neighbour ...
    assert found.flagged_count == 0 and len(found.lowered()) == 1 and not found.pushed()  # ... but is stated once, as lowered
    text = ratcheting_text(pounding, twins, away=-1)
    assert "In 1 cell pounding leaves the base nearer its start than without contacts" in text and "push the residual away" not in text
    assert _pushed_summary(found) == "" and _lowered_summary(found) == "; it leaves the base nearer its start than without contacts in 1 cell"
