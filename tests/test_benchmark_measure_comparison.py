"""The measure comparison benchmark's experiments are at the demo site's ruptures (site and hazard), its stripes at the site's
intensities, and its command writes its section (benchmarks/measure_comparison.py)."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest

from benchmarks import measure_comparison
from stochpound.analysis import RuptureSite


@pytest.mark.parametrize("name", ["PGA", "PSA(1 s)"])
def test_each_experiment_is_at_the_demo_sites_ruptures_and_levels(name):
    table = tomllib.loads(measure_comparison.experiment_text(name, seed=2, motions=7))
    assert table["site"] == {"ruptures": measure_comparison.SITE} and table["hazard"] == {"ruptures": measure_comparison.SITE}
    intensity = table["intensity"]
    kind, period = measure_comparison.MEASURES[name]
    assert (intensity["measure"], intensity.get("period"), intensity["seed"], intensity["motions"]) == (kind, period, 2, 7)
    expected = RuptureSite.bundled(measure_comparison.SITE).intensity_at(kind, period, 1.0 / np.array(measure_comparison.RETURN_PERIODS))
    np.testing.assert_allclose(intensity["levels"], expected, rtol=1e-5)  # written to 6 significant digits
    assert table["grid"]["gap"] == [float("inf")]


@pytest.mark.slow
def test_a_reduced_run_writes_the_section(tmp_path):
    out = tmp_path / "benchmarks.md"
    out.write_text("# Benchmarks\n")
    assert measure_comparison.main(["--measures", "PGA", "--seeds", "1", "--motions", "3", "--runs", "28", "--out", str(out)]) == 0
    section = measure_comparison.SECTION.kept(out.read_text())
    rows = [line for line in section.splitlines() if line.startswith("| ") and "in 50 yr | PGA |" in line]
    assert len(rows) == 2 * 2  # two targets, g* from the counts and from the lognormal demand
