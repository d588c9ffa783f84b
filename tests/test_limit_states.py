"""Yielding buildings in an experiment store and limit states beyond first contact through the risk chain (docs/risk.md, "Limit states").

The risk flagship's pair (Building 1 on a friction pendulum beside a fixed
Building 2) with yielding storeys and storey heights, under eight far-field
motions at three stripes, contact-free and at a 5 cm gap.
"""

from __future__ import annotations

import numpy as np
import pytest

import stochpound
from stochpound.store import open_store
from tests.helpers import ISOLATED, risk_text, run_in_process

STRIPES = 'measure = "psa"\nperiod = 1.0\nlevels = [0.3, 0.8, 1.5]'
YIELDING = ('damping_ratio = 0.05\nyield_force = [1.0e5, 0.7e5]\nhardening = 0.05\nstorey_height = [3.5, 3.0]\n')
#: The flagship's scene with both buildings' storeys yielding (B1's about a quarter of its weight at the base).
YIELDING_SCENE = ISOLATED.replace("damping_ratio = 0.05\n", YIELDING)


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    """The yielding pair's store, demands kept (8 motions × 3 stripes × gaps 5 cm and inf)."""
    assert YIELDING_SCENE.count("yield_force") == 2
    text = risk_text(YIELDING_SCENE, "gap = [0.05, inf]", STRIPES) + "demands = true\n"
    return open_store(run_in_process(tmp_path_factory.mktemp("yielding"), "yielding", text)).load()


def test_a_store_keeps_each_cases_storey_summaries(store):
    """The store's storey summaries are those of the case's own run, recomputed here with simulate()."""
    assert {"peak_drift_ratio", "peak_ductility", "residual_drift", "residual_drift_ratio"} <= set(store.data_vars)
    assert store["peak_ductility"].attrs["units"] == "1" and store["residual_drift"].attrs["units"] == "m"
    assert float(store["peak_ductility"].max()) > 2.0 and float(store["residual_drift"].max()) > 1e-3  # they yield
    case = store.isel(intensity=2, record=3, realization=0).sel(gap=0.05)
    scene = store.pound.scene(intensity=float(case["intensity"]), record=str(case["record"].values), realization=0, gap=0.05)
    run = stochpound.simulate(scene, demands=True)
    assert int(case["impacts"]) == run.sizes["impact"]
    for name, source in (("peak_drift_ratio", "peak_storey_drift_ratio"), ("peak_ductility", "peak_storey_ductility"),
                         ("residual_drift", "residual_storey_drift"), ("residual_drift_ratio", "residual_storey_drift_ratio")):
        np.testing.assert_allclose(case[name].values, np.abs(run[source]).max("floor").values, rtol=1e-12, err_msg=name)


def test_the_gap_identity_holds_in_a_yielding_store(store):
    free = store["peak_contact_closure"].sel(gap=np.inf).max("contact")
    pounded = store["impacts"].sel(gap=0.05) > 0
    assert bool(pounded.any()) and not bool(pounded.all())
    assert bool(((free >= 0.05) == pounded).all())
