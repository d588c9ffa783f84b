"""Sentences about a conditional-spectrum store's motions are read off the store: pool, motions per stripe, scale factors, scenario."""

from __future__ import annotations

import re

import numpy as np
import pytest

from stochpound import open_store
from stochpound.experiment._runner import load_experiment, run_experiment
from stochpound.report.sections._intensity import method_text
from stochpound.report.sections._stripe_motions import stripe_motions_text
from tests.helpers import write_experiment
from tests.test_experiment_site import _text


@pytest.fixture(scope="module")
def cs_store(tmp_path_factory):
    experiment = load_experiment(write_experiment(tmp_path_factory.mktemp("cs"), _text(), "site.toml"))
    report = run_experiment(experiment, workers=0, progress=False)
    assert report.complete
    return open_store(report.store).load()


def test_a_selection_store_says_motions_per_stripe_from_a_pool_with_the_scale_factors_and_scenario(cs_store) -> None:
    text = stripe_motions_text(cs_store)
    scale = cs_store["selection_scale_factor"].values
    assert text.startswith("4 motions per stripe, chosen by conditional-spectrum selection from a pool of 12 and scaled")
    assert f"(scale factors {np.nanmin(scale):.3g}–{np.nanmax(scale):.3g})" in text
    assert "target scenario M 6.6–7, R 20 km, Vs30 400 m/s" in text
    method = method_text(cs_store, cs_store.pound.intensity)
    assert "each scaled" not in method and "every level" not in method
    assert re.search(r"Levels 0\.2, 0\.4 g: 4 motions per stripe", method), method


def test_a_suite_store_says_every_motion_is_scaled_to_every_level(cs_store) -> None:
    suite = cs_store.drop_vars([name for name in cs_store.variables if str(name).startswith(("selection_", "site_", "target_"))])
    assert stripe_motions_text(suite) == "12 motions, each scaled to every level"
