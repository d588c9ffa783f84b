"""``python -m benchmarks compare --experiment``: its pure parts (the options, the stores' comparison, the section), no timing."""

from __future__ import annotations

import numpy as np
import xarray as xr

from benchmarks import compare


def _store(path, peak, attrs, extra=False):
    data = xr.Dataset({"peak": (("gap", "record"), np.array(peak)), "impacts": (("gap",), np.array([3, 0]))},
                      coords={"gap": [0.02, np.inf], "record": ["a", "b"]}, attrs=attrs)
    if extra:
        data["closure"] = ("gap", np.array([0.1, 0.2]))
    data.to_netcdf(path)
    return path


def test_the_stores_compare_by_their_data_not_their_provenance(tmp_path):
    peak = [[0.1, np.nan], [0.3, 0.4]]
    ours = _store(tmp_path / "ours.nc", peak, {"created": "today", "git_commit": "abc"})
    same = _store(tmp_path / "same.nc", peak, {"created": "yesterday", "git_commit": "def"})
    assert compare.store_differences(ours, same) == []
    changed = _store(tmp_path / "changed.nc", [[0.1, np.nan], [0.3, 0.4 + 1e-12]], {})
    assert compare.store_differences(ours, changed) == ["peak"]
    longer = _store(tmp_path / "longer.nc", peak, {}, extra=True)
    assert compare.store_differences(longer, ours) == ["closure (only in one)"]
    with xr.open_dataset(ours) as data:  # a new coordinate on a dimension: only it differs, not every variable on that dimension
        tagged = data.load().assign_coords(record_pulse=("record", [0.0, 1.0]))
    tagged.to_netcdf(tmp_path / "tagged.nc")
    assert compare.store_differences(ours, tmp_path / "tagged.nc") == ["record_pulse (only in one)"]


def test_the_option_takes_the_shipped_experiment_or_a_file():
    assert compare.parse_arguments(["4566c96"]).experiment is None
    assert compare.parse_arguments(["4566c96", "--experiment"]).experiment == compare.EXPERIMENT and compare.EXPERIMENT.is_file()
    assert str(compare.parse_arguments(["4566c96", "--experiment", "mine.toml"]).experiment) == "mine.toml"
    assert compare.throughput({"cases": 880, "elapsed": 12.0, "setup": 1.0}) == 80.0


def _round(engine_ms, rate, setup, differ=None):
    scenes = {key: {"first_call": 10.0, "simulate": engine_ms * 1.5e-3, "engine": engine_ms * 1e-3, "impacts": 2, "peak": 0.05} for key in compare.SCENES}
    measured = {**scenes, "experiment": {"cases": 880, "failed": 0, "elapsed": setup + 880 / rate, "setup": setup}}
    if differ is not None:
        measured["stores_differ"] = {"earlier": differ}
    return measured


def test_the_section_shows_the_experiments_throughput_and_whether_the_stores_agree():
    results = {"revision": "earlier", "head": "abc1234", "repeats": 30, "demands": False, "elapsed": 300.0, "load_at_end": "3.00",
               "experiment": "experiments/intensity/far_field_stripes.toml",
               "rounds": {"this tree": [_round(3.0, 100.0, 1.0, []), _round(3.0, 80.0, 2.0, [])],
                          "earlier": [_round(3.0, 50.0, 1.0), _round(3.0, 40.0, 4.0)]}}
    text = compare.section(results, {"commit": "abc1234"})
    assert "| cases/s | 100.0 (90.0) | 50.0 (45.0) | 2.000 |" in text
    assert "| cases/s, start-up included | 89.8 (78.7) | 47.3 (40.6) | 1.898 |" in text  # 880 cases in 9.8, 13, 18.6 and 26 s
    assert "| start-up (s) | 1.00 (1.50) | 1.00 (2.50) | 1.00 |" in text
    assert "`python -m benchmarks compare earlier --experiment` (5 min)" in text and "880 cases" in text
    assert "stores hold the same data in every round" in text and "load average (1 min) at end 3.00" in text
    results["rounds"]["this tree"][1]["stores_differ"] = {"earlier": ["peak"]}
    assert "stores differ in peak" in compare.section(results, {"commit": "abc1234"})
    del results["experiment"]
    assert "cases/s" not in compare.section(results, {"commit": "abc1234"})
