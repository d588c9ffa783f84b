"""The measure comparison benchmark's experiments are the risk flagship's scenes at the demo site's ruptures (site and hazard), its
stripes at the site's intensities, and its command writes its section and figure (benchmarks/measure_comparison.py)."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest

from benchmarks import measure_comparison
from benchmarks.timing import REPOSITORY
from stochpound.analysis import RuptureSite

CASES = [(flagship, name) for flagship in measure_comparison.FLAGSHIPS for name in flagship.measures]


@pytest.mark.parametrize(("flagship", "name"), CASES, ids=[f"{f.name}-{n}" for f, n in CASES])
def test_each_experiment_is_the_flagships_scene_at_the_demo_sites_ruptures_and_levels(flagship, name):
    table = tomllib.loads(measure_comparison.experiment_text(flagship, name, seed=2, motions=7))
    assert table["site"] == {"ruptures": measure_comparison.SITE} and table["hazard"] == {"ruptures": measure_comparison.SITE}
    intensity = table["intensity"]
    kind, period = measure_comparison.MEASURES[name]
    periods = tuple(intensity["periods"]) if "periods" in intensity else intensity.get("period")  # Sa_avg's band, or PSA's period
    assert (intensity["measure"], periods, intensity["seed"], intensity["motions"]) == (kind, period, 2, 7)
    assert (intensity["selection"], intensity["method"]) == ("conditional_spectrum", "stripes")
    expected = RuptureSite.bundled(measure_comparison.SITE).intensity_at(kind, period, 1.0 / np.array(measure_comparison.RETURN_PERIODS))
    np.testing.assert_allclose(intensity["levels"], expected, rtol=1e-5)  # written to 6 significant digits
    flagship_table = tomllib.loads((REPOSITORY / "experiments" / "risk" / flagship.file).read_text())
    assert table["scene"] == flagship_table["scene"] and table["variants"] == flagship_table["variants"]
    assert table["grid"]["gap"] == [float("inf")]


def test_the_configurations_are_the_issues():
    fixed, isolated = (tomllib.loads(measure_comparison.experiment_text(f, "PGA", seed=1, motions=40))["grid"] for f in measure_comparison.FLAGSHIPS)
    assert fixed["mu"]["values"] == [float("inf")] and "neighbour" not in fixed  # both neighbours, fixed bases
    assert isolated["mu"] == {"values": [0.05], "buildings": ["B1"]} and isolated["neighbour"] == ["stiff"] and isolated["moat"] == ["none"]


@pytest.mark.slow
def test_a_reduced_run_writes_the_section_and_its_figure(tmp_path):
    out, figure = tmp_path / "benchmarks.md", tmp_path / "figure.png"
    out.write_text("# Benchmarks\n")
    arguments = ["--flagships", "isolated", "--measures", "PGA", "--seeds", "1", "--motions", "3", "--runs", "28", "28"]
    saved = tmp_path / "isolated.pkl"
    assert measure_comparison.main([*arguments, "--out", str(out), "--figure", str(figure), "--save", str(saved)]) == 0
    again = tmp_path / "again.md"
    again.write_text("# Benchmarks\n")
    assert measure_comparison.main(["--assemble", str(saved), "--out", str(again), "--figure", str(tmp_path / "again" / "figure.png")]) == 0
    assert again.read_text() == out.read_text()  # the section assembled from the saved comparisons is the run's own
    section = measure_comparison.SECTION.kept(out.read_text())
    rows = [line for line in section.splitlines() if line.startswith("| ") and "in 50 yr | PGA |" in line]
    assert len(rows) == 2 * 3  # two targets; g* from the counts, from the lognormal demand, from the counts on the earlier stripes
    assert all(row.startswith("| neighbour stiff, moat none, mu 0.05 |") for row in rows)
    efficiency = [line for line in section.splitlines() if line.startswith("| neighbour stiff, moat none, mu 0.05 | PGA | ")]
    assert len(efficiency) == 1 and float(efficiency[0].split("|")[3]) > 0  # β on the measure's own store, the only measure in bold
    assert "3–3 motions a stripe" in section and figure.stat().st_size > 0


def test_the_simulated_pool_replaces_the_records_by_motions_of_the_sites_ruptures():
    flagship = measure_comparison.FLAGSHIPS[1]
    table = tomllib.loads(measure_comparison.experiment_text(flagship, "PSA(3 s)", seed=1, motions=40, simulated=300))
    assert "records" not in table and table["site"] == {"ruptures": measure_comparison.SITE, "simulated_motions": 300}
    with_records = tomllib.loads(measure_comparison.experiment_text(flagship, "PSA(3 s)", seed=1, motions=40))
    assert len(with_records["records"]) == 2 and "simulated_motions" not in with_records["site"]
