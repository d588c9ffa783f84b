"""The experiment commands as a user meets them: Ctrl-C, file permissions, errors naming their file, code identity."""

from __future__ import annotations

import os
import shutil
import signal
import stat
import subprocess
import sys
import time

import pytest
import xarray as xr

from stochpound.experiment.parts import part_paths, parts_folder
from stochpound.experiment.session import PACKAGE, git_commit, sources_sha256
from tests.test_experiment_helpers import REPO, SMALL_EXPERIMENT, invoke, quickstart_cell, write_experiment

#: One cell of the quick-start grid under a short harmonic motion, solved by ivp: a small, quick experiment.
TINY_EXPERIMENT = quickstart_cell("""
[[motions]]
name = "push"
type = "harmonic"
amplitude = 3.0
omega = 9.0
duration = 2.0
dt = 0.02

[solver]
method = "ivp"
""")


@pytest.mark.slow
def test_ctrl_c_prints_only_the_message(tmp_path):
    """SIGINT to the whole process group, as a terminal's Ctrl-C: no worker traceback, exit status 130."""
    experiment = write_experiment(tmp_path, SMALL_EXPERIMENT.replace("count = 2", "count = 400"))
    env = {**os.environ, "STOCHPOUND_EXPERIMENT_PART_CASES": "5"}
    command = [sys.executable, "-m", "stochpound", "experiment", "run", str(experiment), "--workers", "2", "--quiet", "--batch", "4"]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env, start_new_session=True)
    deadline = time.monotonic() + 300
    while not part_paths(parts_folder(tmp_path / "small.nc")):
        assert process.poll() is None and time.monotonic() < deadline, process.communicate()
        time.sleep(0.05)
    os.killpg(process.pid, signal.SIGINT)
    out, err = process.communicate(timeout=120)
    assert process.returncode == 130, (out, err)
    assert err == "", err
    assert out.startswith("interrupted: ") and "rerun the same command to complete the missing cases" in out, out


def test_the_store_and_its_parts_follow_the_umask(tmp_path):
    umask, mode = 0o027, 0o640  # neither mkstemp's 0600 nor the usual 0644
    experiment = write_experiment(tmp_path, TINY_EXPERIMENT, "tiny.toml")
    subprocess.run(
        [sys.executable, "-m", "stochpound", "experiment", "run", str(experiment), "--workers", "0", "--quiet"],
        check=True, capture_output=True, preexec_fn=lambda: os.umask(umask),
    )
    folder = parts_folder(tmp_path / "tiny.nc")
    files = [tmp_path / "tiny.nc", folder / "experiment.json", folder / "runs.jsonl", *part_paths(folder)]
    assert len(files) == 4
    for path in files:
        assert stat.S_IMODE(path.stat().st_mode) == mode, path


def test_errors_of_the_base_scene_name_the_scene(tmp_path):
    broken = SMALL_EXPERIMENT.replace("damping_ratio = 0.01", "damping_ratio = 1.5")
    result = invoke("experiment", "check", str(write_experiment(tmp_path, broken)))
    assert result.exit_code == 1
    assert result.stderr.strip() == "Error: scene.building[1].damping_ratio: must be < 1, got 1.5"
    scene_file = tmp_path / "scenes" / "pair.toml"
    scene_file.parent.mkdir()
    start, end = broken.index("[scene]"), broken.index("[variants")
    scene_file.write_text(broken[start:end].replace("[scene]", "").replace("scene.building", "building").replace("scene.contact", "contact"))
    from_file = broken[:start] + broken[end:]
    from_file = from_file.replace('studied = "B1"', 'studied = "B1"\nscene = "scenes/pair.toml"')
    result = invoke("experiment", "check", str(write_experiment(tmp_path, from_file, "from_file.toml")))
    assert result.stderr.strip() == f"Error: {tmp_path / 'scenes' / 'pair.toml'}: building[1].damping_ratio: must be < 1, got 1.5"


def test_with_several_files_every_error_names_its_file(tmp_path):
    good = write_experiment(tmp_path, TINY_EXPERIMENT, "good.toml")
    bad = write_experiment(tmp_path, SMALL_EXPERIMENT.replace("gap = [0.01, 0.02]", "gap = [0.01, -0.02]"), "bad.toml")
    result = invoke("experiment", "run", str(good), str(bad), "--workers", "0")
    assert result.exit_code == 1
    assert result.stderr.strip() == f"Error: {bad}: grid.gap[1]: must be >= 0 or inf, got -0.02"
    assert not (tmp_path / "good.nc").exists(), "every file is checked before any runs"


@pytest.mark.slow
def test_an_installed_copy_records_its_version_and_sources(tmp_path):
    """The package copied out of the git checkout (as ``pip install .`` does): git_commit "none", and the sources' sha256."""
    copy = tmp_path / "site" / "stochpound"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    assert git_commit(copy) == "none"
    assert sources_sha256(copy) == sources_sha256(PACKAGE)
    experiment = write_experiment(tmp_path, TINY_EXPERIMENT, "tiny.toml")
    env = {**os.environ, "PYTHONPATH": str(copy.parent)}
    command = [sys.executable, "-m", "stochpound", "experiment", "run", str(experiment), "--workers", "0", "--quiet"]
    subprocess.run(command, check=True, capture_output=True, env=env, cwd=tmp_path)  # not the checkout's folder: python -m looks there first
    with xr.open_dataset(tmp_path / "tiny.nc") as store:
        assert store.attrs["git_commit"] == "none"
        assert store.attrs["stochpound_sources_sha256"] == sources_sha256(copy)
    (copy / "memory.py").write_text((copy / "memory.py").read_text() + "\n# changed\n")
    sources_sha256.cache_clear()
    assert sources_sha256(copy) != sources_sha256(PACKAGE)


def test_a_git_checkout_records_its_commit():
    commit = git_commit()
    if not (REPO / ".git").exists():
        pytest.skip("not a git checkout")
    assert len(commit.split("+")[0]) == 40
