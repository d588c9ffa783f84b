"""The measure-free benchmark's scenes are the risk flagship's, and its command writes its section (benchmarks/measure_free.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from benchmarks import measure_free
from stochpound.analysis._measure_free_store import scene_demands


def test_the_scenes_are_the_flagship_s_contact_free_with_the_neighbour_and_base_asked_for():
    fixed = measure_free.flagship_scene("fixed_pair.toml", measure_free.FLEXIBLE, None)
    isolated = measure_free.flagship_scene("isolated.toml", measure_free.STIFF, 0.05)
    assert all(math.isinf(contact.gap) for scene in (fixed, isolated) for contact in scene.contacts)
    assert fixed.buildings[0].base is None and isolated.buildings[0].base is not None and not isolated.walls
    np.testing.assert_allclose(fixed.buildings[1].stiffness, measure_free.FLEXIBLE)
    np.testing.assert_allclose(isolated.buildings[1].stiffness, measure_free.STIFF)


@pytest.mark.slow
def test_a_reduced_run_writes_the_section_with_every_configuration_and_target(tmp_path):
    out = tmp_path / "benchmarks.md"
    out.write_text("# Benchmarks\n")
    assert measure_free.main(["--motions", "2", "--extra", "6", "--bootstrap", "100", "--out", str(out)]) == 0
    section = measure_free.SECTION.kept(out.read_text())
    rows = [line for line in section.splitlines() if line.startswith("| ") and "in 50 yr" in line]
    demands = [len(scene_demands(measure_free.flagship_scene(file, neighbour, mu))) for _, file, neighbour, mu in measure_free.CONFIGURATIONS]
    assert demands == [3, 3, 4]  # closure and both storey drifts; the isolated building's base displacement too
    assert len(rows) == 2 * sum(demands) and sum("closure: g*" in row for row in rows) == 2 * len(demands)
    assert all(" 34 |" in row for row in rows)  # 14 ruptures x 2 + 6 runs


@pytest.mark.slow
def test_at_fox_plaza_it_runs_on_the_ruptures_fitted_to_its_curves_and_prints_the_table_without_writing(tmp_path, capsys):
    out = tmp_path / "benchmarks.md"
    out.write_text("# Benchmarks\n")
    assert measure_free.main(["--fox-plaza", "300", "--motions", "2", "--extra", "6", "--bootstrap", "100", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "fitted to its 17 curves at Vs30 300 m/s" in printed
    rows = [line for line in printed.splitlines() if line.startswith("| ") and "in 50 yr" in line]
    assert len(rows) == 2 * (3 + 3 + 4) and all(" 18 |" in row for row in rows)  # 6 ruptures x 2 + 6 runs
    assert out.read_text() == "# Benchmarks\n"


def test_fox_plaza_s_vs30_outside_the_models_is_a_one_line_usage_error(tmp_path, capsys):
    with pytest.raises(SystemExit):
        measure_free.main(["--fox-plaza", "1050", "--out", str(tmp_path / "benchmarks.md")])
    assert "--fox-plaza: must be within 180-1000 (the NGA-West2 models' range), got 1050.0" in capsys.readouterr().err
    assert not (tmp_path / "benchmarks.md").exists()
