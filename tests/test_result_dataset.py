"""The result dataset's coordinates are built once per layout and output times (results.dataset): shared, yet independent per result."""

from __future__ import annotations

import numpy as np
import pytest

import stochpound
from stochpound.studies.agarwal2004 import reference_building, study_scene


def run(duration: float = 2.0, **scene_options):
    scene = study_scene(0.2, None, 2.0, motion={"record": "el_centro_1940_study", "duration": duration}, **scene_options)
    return stochpound.simulate(stochpound.scene_from_dict(scene))


def test_results_of_one_layout_share_coordinates_that_no_result_can_change_for_another():
    first, second = run(), run()
    for name in ("time", "building", "floor", "contact"):
        assert first.indexes[name].equals(second.indexes[name])
    first["time"].attrs["units"] = "ms"
    first["building"].attrs["long_name"] = "changed"
    first = first.assign_coords(floor=first.floor * 10)
    with pytest.raises(ValueError):  # an index's values cannot be written in place
        first["time"].values[0] = 1.0
    for result in (second, run()):
        assert result["time"].attrs["units"] == "s"
        assert result["building"].attrs["long_name"] == "building name, left to right"
        np.testing.assert_array_equal(result.floor.values, [1, 2])
        assert result.time.values[0] == 0.0


def test_other_output_times_or_layouts_get_their_own_coordinates():
    short, longer = run(2.0), run(3.0)
    assert short.sizes["time"] < longer.sizes["time"]
    np.testing.assert_array_equal(longer.time.values[: short.sizes["time"]], short.time.values)
    np.testing.assert_allclose(np.diff(longer.time.values), 0.02)
    assert longer.time.values[-1] == pytest.approx(3.0)
    alone = stochpound.simulate(stochpound.scene_from_dict({"building": [reference_building("B1", 1.0, None)],
                                                            "motion": {"record": "el_centro_1940_study", "duration": 2.0}}))
    np.testing.assert_array_equal(alone.time.values, short.time.values)
    assert alone.building.values.tolist() == ["B1"] and alone.sizes["contact"] == 0
    assert short.building.values.tolist() == ["B1", "B2"] and short.sizes["contact"] == 2
