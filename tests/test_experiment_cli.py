"""The experiment commands as a user meets them: Ctrl-C, file permissions, errors naming their file, code identity."""

from __future__ import annotations

import errno
import json
import os
import re
import shutil
import signal
import stat
import subprocess
import sys
import textwrap
import time
from collections.abc import Iterator

import pytest
import xarray as xr

from stochpound import open_store
from stochpound.experiment._parts import part_paths, parts_folder
from stochpound.experiment._session import PACKAGE, git_commit, sources_sha256
from tests.helpers import PYTHON_WITH_CTRL_C, REPOSITORY, SMALL_EXPERIMENT, TINY_EXPERIMENT, invoke, quickstart_cell, read_only, write_experiment


@pytest.mark.slow
def test_ctrl_c_prints_only_the_message(tmp_path):
    """SIGINT to the whole process group, as a terminal's Ctrl-C: no worker traceback, exit status 130."""
    experiment = write_experiment(tmp_path, SMALL_EXPERIMENT.replace("count = 2", "count = 400"))
    env = {**os.environ, "STOCHPOUND_EXPERIMENT_PART_CASES": "5"}
    command = [*PYTHON_WITH_CTRL_C, "-m", "stochpound", "experiment", "run", str(experiment), "--workers", "2", "--quiet", "--batch", "4"]
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


WORKER_ERROR_RECORD = """
import logging
from stochpound.experiment._runner import _dask_client

with _dask_client(2, None, lambda message: None) as client:
    client.run(lambda: logging.getLogger("distributed.worker").error("Failed to communicate with scheduler during heartbeat."))
print("done")
"""


@pytest.mark.slow
def test_the_local_workers_error_records_do_not_reach_the_terminal():
    """What made a Ctrl-C print a worker's record now and then: an ERROR of ``distributed.worker`` in a worker process."""
    result = subprocess.run([sys.executable, "-c", WORKER_ERROR_RECORD], capture_output=True, text=True, timeout=300, cwd=REPOSITORY)
    assert (result.returncode, result.stdout, result.stderr) == (0, "done\n", ""), result.stderr


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
    # the engine run by Python (NUMBA_DISABLE_JIT): the copy's cache is empty, and its cold compile (tens of seconds) is not what this checks
    env = {**os.environ, "PYTHONPATH": str(copy.parent), "NUMBA_DISABLE_JIT": "1"}
    command = [sys.executable, "-m", "stochpound", "experiment", "run", str(experiment), "--workers", "0", "--quiet"]
    subprocess.run(command, check=True, capture_output=True, env=env, cwd=tmp_path)  # not the checkout's folder: python -m looks there first
    with xr.open_dataset(tmp_path / "tiny.nc") as store:
        assert store.attrs["git_commit"] == "none"
        assert store.attrs["stochpound_sources_sha256"] == sources_sha256(copy)
    (copy / "_memory.py").write_text((copy / "_memory.py").read_text() + "\n# changed\n")
    sources_sha256.cache_clear()
    assert sources_sha256(copy) != sources_sha256(PACKAGE)


def test_a_git_checkout_records_its_commit():
    commit = git_commit()
    if not (REPOSITORY / ".git").exists():
        pytest.skip("not a git checkout")
    assert len(commit.split("+")[0]) == 40


# ---------------------------------------------------------------- issue 27: what a new user trips over

#: The tiny cell under a stationary Kanai-Tajimi ensemble (no envelope, as docs/experiments.md allows): 2 cases + 2 references.
STATIONARY_EXPERIMENT = quickstart_cell("""
[synthetic.still]
type = "kanai_tajimi"
count = 2
seed = 5
omega_g = 15.0
zeta_g = 0.6
pga = 3.0
duration = 2.0
dt = 0.02

[solver]
method = "ivp"
""")


@pytest.fixture(scope="module")
def stationary(tmp_path_factory):
    """A complete store of :data:`STATIONARY_EXPERIMENT` (its experiment file beside it); tests copy it before changing it."""
    folder = tmp_path_factory.mktemp("stationary")
    experiment = write_experiment(folder, STATIONARY_EXPERIMENT, "still.toml")
    result = invoke("experiment", "run", str(experiment), "--workers", "0", "--quiet")
    assert result.exit_code == 0, result.output
    return folder


def _copy(stationary, tmp_path):
    """A copy of the stationary store's folder; its experiment file and store."""
    folder = tmp_path / "copy"
    shutil.copytree(stationary, folder)
    return folder / "still.toml", folder / "still.nc"


def test_a_stationary_ensemble_stores_a_json_envelope_and_builds_its_report(stationary, tmp_path):
    from stochpound.motions import kanai_tajimi

    assert json.loads(kanai_tajimi(1, 1.0, 0.02, omega_g=15.0, zeta_g=0.6, pga=3.0, seed=1).attrs["envelope"]) is None
    out = tmp_path / "report"
    result = invoke("report", "build", str(stationary / "still.nc"), "--out", str(out), "--format", "html")
    assert result.exit_code == 0, result.output
    assert "; stationary;" in (out / "index.html").read_text()


def test_report_out_not_writable_fails_before_the_work(stationary, tmp_path, monkeypatch):
    locked = tmp_path / "locked"
    locked.mkdir()
    with read_only(locked, monkeypatch):
        result = invoke("report", "build", str(stationary / "still.nc"), "--out", str(locked / "report"), "--format", "html")
    assert result.exit_code == 1
    assert result.stderr.strip().startswith(f"Error: {locked / 'report'}: cannot write here ("), result.stderr
    assert "reading stores" not in result.stderr and len(result.stderr.strip().splitlines()) == 1, "no work before the check"


def test_a_reused_out_loses_only_its_own_stale_figures(stationary, tmp_path):
    out = tmp_path / "report"
    build = ("report", "build", str(stationary / "still.nc"), "--out", str(out), "--format", "html")
    assert invoke(*build).exit_code == 0
    manifest = out / ".stochpound-report.json"
    owned = json.loads(manifest.read_text())
    assert owned and all(name.startswith(("figures/", "tables/")) for name in owned)
    # as if an earlier build (another store) had written figure-old.png and tables/old.csv
    (out / "figures" / "figure-old.png").write_bytes(b"old")
    (out / "tables" / "old.csv").write_text("old")
    manifest.write_text(json.dumps([*owned, "figures/figure-old.png", "tables/old.csv", "../outside.png", "notes.txt"]))
    user_files = [out / "figures" / "mine.png", out / "notes.txt", tmp_path / "outside.png"]
    for path in user_files:
        path.write_text("the user's")
    assert invoke(*build).exit_code == 0
    assert not (out / "figures" / "figure-old.png").exists() and not (out / "tables" / "old.csv").exists()
    assert all(path.read_text() == "the user's" for path in user_files), "only files an earlier build listed are removed"
    assert json.loads(manifest.read_text()) == owned
    assert all((out / name).is_file() for name in owned)


def test_a_damaged_store_with_intact_parts_is_repaired_by_run(stationary, tmp_path):
    experiment, store = _copy(stationary, tmp_path)
    store.write_bytes(b"not a store")
    result = invoke("experiment", "run", str(experiment), "--workers", "0")
    assert result.exit_code == 0, result.output
    assert "rebuilt from the finished cases in still.nc.parts/" in result.stdout and "--restart" not in result.output
    assert "damaged; rebuilding it from the 4 finished cases" in result.stderr
    with open_store(store) as dataset:
        assert int((dataset.case_status == 1).sum()) == 2 and int((dataset.reference_status == 1).sum()) == 2
    # without parts nothing tells it is a store: no advice to discard it, and --restart does not (issue 48)
    shutil.rmtree(parts_folder(store))
    store.write_bytes(b"not a store")
    for restart in ([], ["--restart"]):
        result = invoke("experiment", "run", str(experiment), "--workers", "0", *restart)
        assert result.exit_code == 1 and "not a store of stochpound's" in result.stderr and "use --restart" not in result.stderr, result.stderr
        assert store.read_bytes() == b"not a store"


def test_a_complete_store_is_not_run_again(stationary, tmp_path):
    experiment, store = _copy(stationary, tmp_path)
    before = (store.stat().st_mtime_ns, (parts_folder(store) / "runs.jsonl").read_text())
    result = invoke("experiment", "run", str(experiment))  # default workers: a cluster would start if anything ran
    assert result.exit_code == 0, result.output
    assert result.stdout.startswith("nothing to run: store complete (4/4 cases)"), result.stdout
    assert "cluster" not in result.output and "solver" not in result.output
    assert (store.stat().st_mtime_ns, (parts_folder(store) / "runs.jsonl").read_text()) == before
    assert f"next: stochpound report build {store} --out " in result.stdout


def test_a_store_on_a_read_only_disk_can_be_read(stationary, tmp_path, monkeypatch):
    experiment, store = _copy(stationary, tmp_path)
    (parts_folder(store) / ".lock").unlink(missing_ok=True)  # a store copied without its lock file
    with read_only(store.parent, monkeypatch):
        status = invoke("experiment", "status", str(store))
        with open_store(store) as dataset:
            assert dataset.attrs["experiment_name"] == "quickstart"
        report = invoke("report", "build", str(store), "--out", str(tmp_path / "report"), "--format", "html")
        rerun = invoke("experiment", "run", str(experiment), "--workers", "0")
    assert status.exit_code == 0, status.output
    assert "4/4 cases done, 0 missing" in status.stdout and "rebuilt" not in status.stdout
    assert report.exit_code == 0, report.output
    assert rerun.exit_code == 0 and rerun.stdout.startswith("nothing to run"), rerun.output


def test_writing_onto_a_read_only_disk_is_a_one_line_error(stationary, tmp_path, monkeypatch):
    experiment, store = _copy(stationary, tmp_path)
    store.unlink()  # a resume: the store file must be rebuilt from the parts
    scene = REPOSITORY / "experiments" / "scenes" / "study_b1_isolated_flexible.toml"
    with read_only(store.parent, monkeypatch):
        resume = invoke("experiment", "run", str(experiment), "--workers", "0")
        fresh = invoke("experiment", "run", str(experiment), "--workers", "0", "--store", str(store.parent / "new" / "fresh.nc"))
        simulated = invoke("simulate", str(scene), "--out", str(store.parent / "run.nc"), "--method", "ivp")
    for result, path in ((resume, parts_folder(store) / ".lock"), (fresh, store.parent / "new"), (simulated, store.parent)):
        assert result.exit_code == 1, result.output
        assert result.stderr.strip().startswith(f"Error: {path}: cannot write here ("), result.stderr
        assert len(result.stderr.strip().splitlines()) == 1, result.stderr


def test_a_large_experiment_shows_its_estimate_and_asks_for_yes(tmp_path, monkeypatch):
    """2·10⁶ cases: refused before anything is written, with the time and size; with --yes it goes past the check
    (and here stops at the read-only folder, so that nothing runs)."""
    experiment = write_experiment(tmp_path, STATIONARY_EXPERIMENT.replace("count = 2", "count = 1000000"), "large.toml")
    result = invoke("experiment", "run", str(experiment), "--workers", "0")
    assert result.exit_code == 1
    message = result.stderr.strip()
    assert re.fullmatch(
        rf"Error: {re.escape(str(experiment))}: 2,000,000 cases to run: roughly [0-9.]+ \w+ on 1 core after a start-up[^;]*, store about [0-9.]+ MiB "
        r"\(and as much again in its \.parts folder\); above 1,000,000 cases or 10 GiB of store: give --yes to run it",
        message,
    ), message
    assert sorted(path.name for path in tmp_path.iterdir()) == ["large.toml"]
    with read_only(tmp_path, monkeypatch):
        result = invoke("experiment", "run", str(experiment), "--workers", "0", "--yes")
    assert result.exit_code == 1 and "cannot write here" in result.stderr and "--yes" not in result.stderr, result.stderr


def test_a_first_run_says_what_it_does_and_ctrl_c_during_the_cluster_start_stops_it(tmp_path):
    """The start-up messages as they happen; SIGINT to the process group while the local cluster starts: exit 130, a readable store."""
    experiment = write_experiment(tmp_path, STATIONARY_EXPERIMENT, "still.toml")
    command = [*PYTHON_WITH_CTRL_C, "-m", "stochpound", "experiment", "run", str(experiment), "--workers", "2"]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    lines = []
    for line in process.stderr:
        lines.append(line)
        if line.startswith("starting a local dask cluster"):
            break
    assert lines[0].startswith("4 cases to run: roughly "), lines
    assert lines[1].startswith("stochpound: compiling the exact solver's engine (") or lines[1] == "loading the compiled solver…\n", lines
    assert lines[2] == "starting a local dask cluster (2 workers)…\n", lines
    time.sleep(0.5)  # inside LocalCluster(...): its workers take seconds to start
    os.killpg(process.pid, signal.SIGINT)
    out, err = process.communicate(timeout=120)
    assert process.returncode == 130, (out, err)
    assert "Traceback" not in err, err
    assert out.startswith("interrupted: 0/4 cases done"), out
    assert "rerun the same command to complete the missing cases" in out
    with open_store(tmp_path / "still.nc") as dataset:
        assert int((dataset.case_status == 0).sum()) == 2


def test_a_finished_run_names_the_next_command_and_its_times(tmp_path):
    experiment = write_experiment(tmp_path, STATIONARY_EXPERIMENT, "still.toml")
    result = invoke("experiment", "run", str(experiment), "--workers", "0")
    assert result.exit_code == 0, result.output
    first = result.stdout.splitlines()[0]
    assert re.fullmatch(
        r"complete: 4/4 cases done \(4 this run, 0 before\) on this process \(no dask\); "
        r"(?P<all>[0-9.]+) s in all: (?P<setup>[0-9.]+) s start-up, (?P<run>[0-9.]+) s running, [0-9.]+ cases/s", first
    ), first
    assert result.stdout.splitlines()[-1] == f"next: stochpound report build {tmp_path / 'still.nc'} --out {tmp_path / 'still'}-report"


def test_the_help_is_whole_and_the_bare_command_prints_it():
    bare = invoke()
    assert bare.exit_code == 0 and bare.stdout.startswith("Usage: ") and "Commands:" in bare.stdout
    listed = " ".join(invoke("experiment", "--help").stdout.split())
    assert "run Run the missing cases of each EXPERIMENT_FILE into its store, one after the other." in listed
    for group in ((), ("experiment",), ("records",), ("report",)):
        commands = invoke(*group, "--help").stdout.split("Commands:")[1]
        assert "..." not in commands, commands
    report = " ".join(invoke("report", "--help").stdout.split())
    assert "built from experiment stores: any experiment's" in report


def test_experiment_error_is_importable_from_the_package():
    import stochpound
    from stochpound.experiment._spec import ExperimentError

    assert stochpound.ExperimentError is ExperimentError and "ExperimentError" in stochpound.__all__


def test_the_readme_plot_example_shows_or_saves_its_figure():
    text = (REPOSITORY / "README.md").read_text()
    block = text[text.index("```python\nimport matplotlib.pyplot as plt\nimport stochpound") :]
    block = block[: block.index("```", 3)]
    assert ".plot()" in block and ("plt.savefig(" in block or "plt.show()" in block)


def _disk_full(*args, **kwargs):
    raise OSError(errno.ENOSPC, "No space left on device")  # as write() raises it: no file named


def test_a_full_disk_during_status_names_the_store_and_keeps_everything(stationary, tmp_path, monkeypatch):
    from stochpound.experiment import _file_assembly

    experiment, store = _copy(stationary, tmp_path)
    before = store.read_bytes()
    monkeypatch.setattr(_file_assembly, "_create", _disk_full)
    result = invoke("experiment", "status", str(store))
    assert result.exit_code == 0, result.output
    assert result.stderr.strip() == f"store not rebuilt (its finished cases are kept in its parts): {store}: cannot write here (No space left on device)"
    assert re.search(r"^(\d+)/\1 cases done, 0 missing$", result.stdout, re.MULTILINE), result.stdout
    assert store.read_bytes() == before and not list(store.parent.glob(".still.nc.*"))
    monkeypatch.undo()
    assert invoke("experiment", "status", str(store)).exit_code == 0 and open_store(store).attrs["complete"] == 1


def test_a_full_disk_is_found_before_the_store_is_written(stationary, tmp_path, monkeypatch):
    """Less room than the old store file: nothing is written (the library writing it may not fail cleanly); one line naming it."""
    from stochpound import _atomic

    experiment, store = _copy(stationary, tmp_path)
    monkeypatch.setattr(_atomic.shutil, "disk_usage", lambda path: shutil._ntuple_diskusage(10**9, 10**9, 0))
    result = invoke("experiment", "status", str(store))
    assert f"{store}: cannot write here (No space left on device: 0.0 MB free, about " in result.stderr and result.exit_code == 0


def test_the_estimate_counts_the_start_up_as_last_timed_on_this_machine(tmp_path, monkeypatch, caplog):
    """A cold cache: the estimate names the compile and the rest of the start-up, not yet timed; the compile is announced
    (a log line) and both are timed; the next run's estimate adds them as measured. A warm cache: no compile, no line."""
    from stochpound.experiment._estimate import COMPILE, _duration
    from stochpound.solvers import first_call

    timings = tmp_path / "timings.json"
    monkeypatch.setattr(first_call, "_timings_path", lambda: timings)
    monkeypatch.setattr(first_call, "engine_cached", lambda: False)
    experiment = write_experiment(tmp_path, TINY_EXPERIMENT, "tiny.toml")
    rest = "opening the store and loading the solver"
    with caplog.at_level("WARNING", logger="stochpound.solvers"):
        result = invoke("experiment", "run", str(experiment), "--workers", "0")
    assert result.exit_code == 0, result.output
    assert (f"on 1 core after a start-up: {COMPILE} (not yet timed on this machine: about 15 s on an idle one, minutes on a loaded one), "
            f"{rest} (not yet timed on this machine), store about ") in result.stderr, result.stderr
    assert [r.getMessage() for r in caplog.records if r.name == "stochpound.solvers"] == [
        "stochpound: compiling the exact solver's engine (numba's cache of it is empty; not yet timed on this machine: about 15 s on an idle "
        "one, minutes on a loaded one); later calls, and later processes, load it from the cache"]
    measured = json.loads(timings.read_text())
    assert measured["compile"] >= 0 and measured[rest] > 0, measured  # this process had the engine loaded: the warm-up takes ~0 s
    setup = float(re.search(r"in all: ([\d.]+) s start-up", result.stdout).group(1))
    assert measured["compile"] + measured[rest] == pytest.approx(setup, abs=0.2)  # the start-up the summary reports, split in two
    caplog.clear()
    result = invoke("experiment", "run", str(experiment), "--workers", "0", "--restart")
    total = _duration(measured["compile"] + measured[rest])
    assert (f"after a start-up of about {total} ({COMPILE} {_duration(measured['compile'])}, {rest} {_duration(measured[rest])}, "
            "as last timed on this machine)") in result.stderr, result.stderr
    caplog.clear()
    result = invoke("experiment", "run", str(experiment), "--workers", "0", "--restart", "--quiet")
    assert result.exit_code == 0 and result.stderr == "" and not caplog.records, (result.stderr, caplog.records)  # --quiet: not even the compile's line
    monkeypatch.setattr(first_call, "engine_cached", lambda: True)
    caplog.clear()
    with caplog.at_level("WARNING", logger="stochpound.solvers"):
        result = invoke("experiment", "run", str(experiment), "--workers", "0", "--restart")
    assert COMPILE not in result.stderr and "loading the compiled solver" in result.stderr and not caplog.records, result.stderr


@pytest.mark.slow
def test_a_cold_cache_compile_is_said_once_by_the_python_api_and_timed(tmp_path):
    """A real empty numba cache: the first simulate() of a process logs one line on stderr (no logging set up), the next
    process none; the compile's duration is kept beside the cache for the estimates."""
    from stochpound.solvers.first_call import TIMINGS_FILE

    code = ("import stochpound\nfrom stochpound.model.scene_file import scene_from_dict\nfrom stochpound.solvers.exact import WARM_UP_SCENE\n"
            "stochpound.simulate(scene_from_dict(WARM_UP_SCENE))\nprint('done')")
    env = {**os.environ, "PYTHONPATH": str(REPOSITORY), "NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    first, second = (subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=600) for _ in range(2))
    assert first.returncode == 0 and first.stdout == "done\n", first.stderr
    assert first.stderr.startswith("stochpound: compiling the exact solver's engine (numba's cache of it is empty; not yet timed")
    assert len(first.stderr.splitlines()) == 1, first.stderr
    assert second.returncode == 0 and second.stderr == "", second.stderr
    (timings,) = (tmp_path / "cache").rglob(TIMINGS_FILE)
    assert json.loads(timings.read_text())["compile"] > 0


def test_the_store_size_is_measured_within_a_few_per_cent(tmp_path, monkeypatch):
    """file_bytes (the run's estimate, and the room checked before a write) against the written files: within 5 % without
    time histories; with them (written compressed) not below 95 % of the file (the estimate's 'or less')."""
    from stochpound.experiment._estimate import estimate_run
    from stochpound.experiment._runner import load_experiment
    from stochpound.experiment._sources import resolve_motions
    from stochpound.experiment._file_layout import layout
    from stochpound import _atomic
    from stochpound.experiment import _file_assembly
    from stochpound.experiment._file_assembly import file_bytes

    histories = TINY_EXPERIMENT + '\n[output]\ntime_histories = ["total_displacement"]\nbuildings = ["B1"]\nimpacts = true\n'
    for name, text in (("plain.toml", TINY_EXPERIMENT), ("histories.toml", histories)):
        experiment = load_experiment(write_experiment(tmp_path, text, name))
        assert invoke("experiment", "run", str(experiment.path), "--workers", "0", "--quiet").exit_code == 0
        store = tmp_path / name.replace(".toml", ".nc")
        grids = {label: m.grid for label, m in resolve_motions(experiment).items()}
        actual = store.stat().st_size
        with open_store(store) as data:
            store_layout, attrs = layout(experiment, grids, data.sizes["impact"]), dict(data.attrs)
        measured = file_bytes(store_layout, attrs)
        needed = int(_file_assembly.ROOM_FACTOR * measured) + _file_assembly.ROOM_MARGIN
        for module in (_file_assembly, _atomic):  # one byte too few: the quick bound must not skip the measure
            monkeypatch.setattr(module, "free_bytes", lambda path: needed - 1)
        with pytest.raises(OSError, match=f"about {needed / 1e6:.1f} MB needed"):
            _file_assembly._check_room(store, store_layout, attrs)
        monkeypatch.undo()
        estimate = estimate_run(experiment, grids, experiment.n_cases)
        if name == "plain.toml":
            assert abs(measured / actual - 1) < 0.05 and estimate.history_bytes == 0, (measured, actual)
        else:
            assert measured > 0.95 * actual and estimate.history_bytes > 0, (measured, actual)
            assert " or less (" in estimate.describe(1) and "of it time histories before compression)" in estimate.describe(1)


@pytest.fixture
def small_disk(tmp_path):
    """A real 4 MB file system (tmpfs) at tmp_path/disk: a full disk as HDF5 meets it (it crashed status with a segfault)."""
    disk = tmp_path / "disk"
    disk.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=4m", "tmpfs", str(disk)], capture_output=True).returncode != 0:
        pytest.skip("mounting a small tmpfs needs root (the monkeypatched tests above cover the messages)")
    try:
        yield disk
    finally:
        subprocess.run(["umount", str(disk)], check=True)


def _fill(disk, leave: int) -> None:
    """Fill ``disk`` but ``leave`` bytes."""
    (disk / "filler").write_bytes(b"\0" * max(0, shutil.disk_usage(disk).free - leave))


def _stochpound(*args: str, cwd) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "stochpound", *args], capture_output=True, text=True, cwd=cwd, timeout=600,
                          env={**os.environ, "PYTHONPATH": str(REPOSITORY)})


def test_a_really_full_disk_crashes_nothing_and_loses_nothing(stationary, small_disk):
    """status and run on a full tmpfs: exit 0 or 1 (not a segfault's 139), one line naming the store; the parts rebuild it later."""
    shutil.copytree(stationary, small_disk / "copy")
    store = small_disk / "copy" / "still.nc"
    store.unlink()  # status must write it anew from the parts
    _fill(small_disk, 200_000)  # less than the store needs (about 0.3 MB)
    result = _stochpound("experiment", "status", str(store), cwd=small_disk)
    assert result.returncode == 0, (result.returncode, result.stderr[-2000:])
    assert re.fullmatch(rf"store not rebuilt \(its finished cases are kept in its parts\): {store}: cannot write here "
                        r"\(No space left on device: 0\.\d MB free, about \d+\.\d MB needed\)\n", result.stderr), result.stderr[-2000:]
    assert not store.exists() and not list(store.parent.glob(".still.nc.*"))
    experiment = write_experiment(small_disk, TINY_EXPERIMENT, "tiny.toml")
    (small_disk / "filler").unlink()
    _fill(small_disk, 1_390_000)  # room for the run's store file (0.26 MB, its room 1.34 MB) as first written (empty: 0.1 MB), not beside it for the last
    result = _stochpound("experiment", "run", str(experiment), "--workers", "0", cwd=small_disk)
    assert result.returncode == 1, (result.returncode, result.stderr[-2000:])
    last = result.stderr.splitlines()[-1]
    assert re.fullmatch(rf"Error: {small_disk / 'tiny.nc'}: cannot write here \(No space left on device.*\)", last), result.stderr[-2000:]
    assert result.stderr.endswith(f"\n{last}\n") and "%|" in result.stderr, result.stderr[-2000:]  # after the bar, on a line of its own
    (small_disk / "filler").unlink()
    assert _stochpound("experiment", "status", str(store), cwd=small_disk).returncode == 0 and open_store(store).attrs["complete"] == 1
    result = _stochpound("experiment", "run", str(experiment), "--workers", "0", "--quiet", cwd=small_disk)
    assert result.returncode == 0 and open_store(small_disk / "tiny.nc").attrs["complete"] == 1, result.stderr[-2000:]


def test_a_full_disk_during_a_run_is_one_line_naming_the_store_and_loses_nothing(tmp_path, monkeypatch):
    from stochpound.experiment import _file_assembly

    experiment = write_experiment(tmp_path, TINY_EXPERIMENT, "tiny.toml")
    monkeypatch.setattr(_file_assembly, "_create", _disk_full)
    result = invoke("experiment", "run", str(experiment), "--workers", "0")
    assert result.exit_code == 1
    assert result.stderr.strip().splitlines()[-1] == f"Error: {tmp_path / 'tiny.nc'}: cannot write here (No space left on device)", result.stderr
    monkeypatch.undo()
    result = invoke("experiment", "run", str(experiment), "--workers", "0", "--quiet")
    assert result.exit_code == 0 and open_store(tmp_path / "tiny.nc").attrs["complete"] == 1, result.output


def test_every_command_s_g_option_has_the_same_default():
    """Issue 35: `records show` and `records spectrum` defaulted to 9.814 and 9.81; one g for every command."""
    import click

    from stochpound.cli import main

    def options(command: click.Command, path: str) -> Iterator[tuple[str, object]]:
        for param in command.params:
            if "--g" in getattr(param, "opts", ()):
                yield path, param.default
        for name, sub in getattr(command, "commands", {}).items():
            yield from options(sub, f"{path} {name}")

    found = dict(options(main, "stochpound"))
    assert len(found) >= 2 and len(set(found.values())) == 1, found


def _ctrl_c() -> None:
    """A Ctrl-C to this process: Python's handler raises in the sleep."""
    os.kill(os.getpid(), signal.SIGINT)
    time.sleep(0.5)


def _group_with_a_library_that_turns_ctrl_c_into_its_error(ctrl_c: bool):
    """A command group whose command meets a library that raises its own error in place of a KeyboardInterrupt."""
    import click

    from stochpound.cli._group import HelpGroup

    @click.group(cls=HelpGroup)
    def group() -> None:
        """A group."""

    @group.command()
    def read() -> None:
        """Read a file."""
        try:
            if ctrl_c:
                _ctrl_c()
        except KeyboardInterrupt:
            pass
        raise click.ClickException("NetCDF: HDF error")  # the error the library raised instead, as a command words it

    return group


@pytest.mark.parametrize(("ctrl_c", "sigint"), [
    (True, signal.default_int_handler),
    (False, signal.default_int_handler),
    (True, signal.SIG_IGN),
])  # fmt: skip
def test_an_error_raised_after_a_ctrl_c_is_the_ctrl_c(ctrl_c, sigint):
    """What made `report build` now and then exit 1 with a library's message after a Ctrl-C: the error, not the interrupt,
    reached the command's end. After a SIGINT any error ends the command as interrupted (130); without one the error stands,
    and so it does where SIGINT is ignored (a job started in the background, as a shell starts one with &: the process
    starts with SIGINT ignored, and the command leaves it so). The test sets SIGINT's handler itself: it is inherited."""
    from click.testing import CliRunner

    from stochpound._signals import handling

    with handling(sigint):
        result = CliRunner().invoke(_group_with_a_library_that_turns_ctrl_c_into_its_error(ctrl_c), ["read"])
        assert signal.getsignal(signal.SIGINT) is sigint
    if ctrl_c and sigint is signal.default_int_handler:
        assert (result.exit_code, result.stderr) == (130, "interrupted\n"), result.output
    else:
        assert result.exit_code == 1 and result.stderr == "Error: NetCDF: HDF error\n", result.output


def _work_for_a_minute() -> None:
    """A minute of work in Python code (a Ctrl-C raised meanwhile stops it)."""
    deadline = time.monotonic() + 60.0
    while time.monotonic() < deadline:
        pass


class _FileHandle:
    """An object whose finaliser meets the Ctrl-C (as a netCDF file or a figure closed by the garbage collector may)."""

    def __del__(self) -> None:
        _ctrl_c()  # raised in the finaliser: Python prints "Exception ignored" and goes on


def _group_whose_ctrl_c_never_reaches_the_command(where: str):
    """A command group whose command returns normally although a Ctrl-C came: it was caught by a library, or in a finaliser."""
    import click

    from stochpound.cli._group import HelpGroup

    @click.group(cls=HelpGroup)
    def group() -> None:
        """A group."""

    @group.command()
    def read() -> None:
        """Read a file."""
        if where == "library":
            try:
                _ctrl_c()
            except KeyboardInterrupt:
                pass
        else:
            _FileHandle()
            _work_for_a_minute()
        click.echo("read")

    return group


@pytest.mark.parametrize("where", ["library", "finaliser"])
def test_a_ctrl_c_that_never_reaches_the_command_still_ends_it(where):
    """What made `report build` now and then exit 0 after a Ctrl-C (the last CI run on a clone failed on it): the
    KeyboardInterrupt was raised in a finaliser, which Python reports as 'Exception ignored' with a traceback and goes on,
    or caught by a library. The command still ends as interrupted (130), with no traceback."""
    from click.testing import CliRunner

    from stochpound._signals import handling

    hook = sys.unraisablehook
    with handling(signal.default_int_handler):
        result = CliRunner().invoke(_group_whose_ctrl_c_never_reaches_the_command(where), ["read"])
    assert (result.exit_code, result.stderr) == (130, "interrupted\n"), (result.exit_code, result.stderr)
    assert ("read" in result.stdout) == (where == "library"), result.stdout  # from a finaliser it is raised again in the command
    assert sys.unraisablehook is hook


def test_a_ctrl_c_raised_in_a_finaliser_stops_the_work_at_once():
    """A Ctrl-C whose KeyboardInterrupt a finaliser swallowed is raised again in the code the finaliser interrupted: the work
    stops within a few steps, not when it would have ended (one run of the suite waited 4 minutes for a `risk --bootstrap`
    to finish before it ended as interrupted)."""
    from stochpound._signals import handling, noting_ctrl_c

    with handling(signal.default_int_handler), noting_ctrl_c() as ctrl_c:
        with pytest.raises(KeyboardInterrupt):
            _FileHandle()  # collected at once: its finaliser meets the Ctrl-C
            _work_for_a_minute()
    assert ctrl_c


@pytest.mark.parametrize("where", ["finaliser", "extension"])
def test_a_ctrl_c_swallowed_while_the_commands_load_still_ends_the_process(where):
    """The same while click and the command modules load (`stochpound.cli._load`): a KeyboardInterrupt raised in a
    finaliser meanwhile, or one that an extension module's import turned into 'ImportError: initialization failed' (a
    run under load printed that traceback), ends the process as interrupted (130) before any command starts, with no
    traceback. The script sets Python's own SIGINT handler: a process started with SIGINT ignored (a background job's)
    rightly leaves it so."""
    script = textwrap.dedent("""
        import os, signal, sys, time
        signal.signal(signal.SIGINT, signal.default_int_handler)
        import stochpound.cli as cli

        class FileHandle:
            def __del__(self):
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(0.5)

        def build():
            if sys.argv[1] == "finaliser":
                FileHandle()
                return "the group"
            try:
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(0.5)
            except KeyboardInterrupt:
                raise ImportError("initialization failed") from None

        cli._build = build
        print(cli._load())
    """)
    result = subprocess.run([sys.executable, "-c", script, where], capture_output=True, text=True, timeout=120,
                            env={**os.environ, "PYTHONPATH": str(REPOSITORY)})
    assert (result.returncode, result.stdout, result.stderr) == (130, "", "interrupted\n"), result


def _group_with_a_ctrl_c_around_its_command(when: str):
    """A command group that meets a Ctrl-C while click parses its options (before the command) or closes its context (after)."""
    import click

    from stochpound.cli._group import HelpGroup

    @click.group(cls=HelpGroup)
    @click.option("--early", is_flag=True, callback=lambda ctx, param, value: _ctrl_c() if value else None)
    def group(early: bool) -> None:
        """A group."""
        if when == "after":
            click.get_current_context().call_on_close(_ctrl_c)

    @group.command()
    def read() -> None:
        """Read a file."""
        click.echo("read")

    return group, (["--early", "read"] if when == "before" else ["read"])


@pytest.mark.parametrize("when", ["before", "after"])
def test_a_ctrl_c_just_before_or_after_the_command_ends_it_as_interrupted(when):
    """click's own main turns a KeyboardInterrupt into 'Aborted!' and status 1 (a sweep of Ctrl-C moments under load met it
    once): around the command a Ctrl-C is only noted, and the command ends as interrupted (130)."""
    from click.testing import CliRunner

    from stochpound._signals import handling

    group, args = _group_with_a_ctrl_c_around_its_command(when)
    with handling(signal.default_int_handler):
        result = CliRunner().invoke(group, args)
    assert (result.exit_code, result.stderr) == (130, "interrupted\n"), (result.exit_code, result.output)
    assert result.stdout == ("" if when == "before" else "read\n")
