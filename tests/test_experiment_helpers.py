"""Shared helpers of the experiment tests (no tests here): a small experiment and store comparisons."""

from __future__ import annotations

import builtins
import errno
import io
import os
import stat
import subprocess
import sys
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterator

import numpy as np
import xarray as xr

REPO = Path(__file__).resolve().parents[1]

#: 2 neighbours x 2 gaps x 2 mu x (El Centro 8 s + 2 Kanai-Tajimi realizations) = 24 cases + 3 references.
SMALL_EXPERIMENT = """
[experiment]
name = "small"
studied = "B1"

[scene]
g = 9.814

[[scene.building]]
name = "B1"
mass = [26268.0, 17512.0]
stiffness = [24516800.0, 17512000.0]
damping = [23634.2, 16881.57]
base = { mass = 13134.0, mu = 0.2 }

[[scene.building]]
name = "B2"
mass = [26268.0, 17512.0]
stiffness = [24516800.0, 17512000.0]
damping_ratio = 0.01

[[scene.contact]]
between = [["B1", 1], ["B2", 1]]
gap = 0.02
stiffness = 42747262.6
restitution = 0.5

[[scene.contact]]
between = [["B1", 2], ["B2", 2]]
gap = 0.02
stiffness = 28498175.1
restitution = 0.5

[variants.neighbour.stiff.building.B2]
mass_factor = 0.5

[variants.neighbour.flexible.building.B2]
mass_factor = 2.0

[grid]
gap = [0.01, 0.02]
mu = { values = [0.2, inf], buildings = ["B1"] }

[[records]]
name = "el_centro"
record = "el_centro_1940_study"
duration = 8.0

[synthetic.kt]
type = "kanai_tajimi"
count = 2
seed = 7
omega_g = 15.0
zeta_g = 0.6
pga = 3.0
envelope = "jennings"
duration = 8.0
dt = 0.02

[output]
time_histories = ["total_displacement", "impact_force"]
buildings = ["B1"]
"""

N_CASES = 27
QUICKSTART = REPO / "experiments" / "quickstart.toml"


def quickstart_cell(motions: str, gap: float = 0.02, mu: float = 0.2, neighbour: str = "flexible") -> str:
    """An experiment file: the quick-start file's scene and variants, one cell of its grid, under ``motions``.

    ``motions`` is the rest of the file: ``[[records]]``, ``[[motions]]``,
    ``[synthetic.<name>]``, ``[output]`` and ``[solver]`` tables.
    """
    text = QUICKSTART.read_text()
    grid = f'[grid]\ngap = [{gap}]\nmu = {{ values = [{mu}], buildings = ["B1"] }}\nneighbour = ["{neighbour}"]\n\n'
    return text[: text.index("[grid]")] + grid + motions


def write_experiment(folder: Path, text: str = SMALL_EXPERIMENT, name: str = "small.toml") -> Path:
    """Write an experiment file and return its path."""
    path = folder / name
    path.write_text(text)
    return path


def run_in_process(folder: Path, name: str, text: str) -> Path:
    """Write experiment ``text`` as ``folder/<name>.toml``, run it in this process and return its store (every case done)."""
    from stochpound.experiment import load_experiment, run_experiment

    (folder / f"{name}.toml").write_text(text)
    report = run_experiment(load_experiment(folder / f"{name}.toml"), workers=0, progress=False)
    assert report.complete and not report.failed
    return report.store


def cli(*args: str, env: dict | None = None, check: bool = True, timeout: float = 600) -> subprocess.CompletedProcess:
    """Run ``python -m stochpound ARGS`` and return the completed process."""
    environment = {**os.environ, **(env or {})}
    result = subprocess.run([sys.executable, "-m", "stochpound", *args], capture_output=True, text=True, env=environment, timeout=timeout)
    if check and result.returncode != 0:
        raise AssertionError(f"stochpound {' '.join(args)} exited {result.returncode}\n{result.stdout}\n{result.stderr}")
    return result


def invoke(*args: str, env: dict | None = None):
    """Run ``stochpound ARGS`` in this process (click's test runner): ``exit_code``, ``stdout``, ``stderr``."""
    from click.testing import CliRunner

    from stochpound.cli import main

    return CliRunner().invoke(main, list(args), env=env)


def cli_process(*args: str, env: dict | None = None) -> subprocess.Popen:
    """Start ``python -m stochpound ARGS`` in the background."""
    return subprocess.Popen(
        [sys.executable, "-m", "stochpound", *args], env={**os.environ, **(env or {})}, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )


def done_cases(store: Path) -> int:
    """Finished cases in a store's parts folder."""
    from stochpound.experiment._parts import parts_folder, read_experiment_json
    from stochpound.experiment._grid import Experiment
    from stochpound.experiment._store_writer import PartsIndex

    folder = parts_folder(store)
    if not (folder / "experiment.json").is_file():
        return 0
    return PartsIndex.scan(Experiment(read_experiment_json(folder)["definition"]), folder).n_done


def assert_same_results(first: Path, second: Path) -> None:
    """Every variable and coordinate of two stores is bitwise identical (attributes aside)."""
    with xr.open_dataset(first) as a, xr.open_dataset(second) as b:
        assert sorted(a.variables) == sorted(b.variables)
        for name in a.variables:
            x, y = a[name].values, b[name].values
            assert x.shape == y.shape, name
            if x.dtype.kind == "f":
                assert np.array_equal(x.view(np.uint8), y.view(np.uint8)), name
            else:
                assert np.array_equal(x, y), name



@contextmanager
def read_only(folder: Path, monkeypatch) -> Iterator[None]:
    """Inside the block, ``folder`` (and everything in it) cannot be written, as on a read-only disk.

    As another user than root, by ``chmod`` (restored afterwards). Root writes
    through any mode and a test cannot mount a read-only file system, so for
    root every way stochpound creates or writes a file (``open`` and
    ``os.open`` for writing, ``os.mkdir``) raises ``OSError(EROFS)`` for paths
    inside ``folder``, as the kernel would; reading is untouched. Only this
    process is affected: use it with click's test runner, not a subprocess.
    """
    folder = Path(folder).resolve()
    if os.geteuid() != 0:
        modes = {path: stat.S_IMODE(path.stat().st_mode) for path in [folder, *folder.rglob("*")]}
        for path, mode in modes.items():
            path.chmod(mode & ~0o222)
        try:
            yield
        finally:
            for path, mode in modes.items():
                path.chmod(mode)
        return

    def inside(path: Any) -> bool:
        return isinstance(path, (str, os.PathLike)) and Path(os.path.abspath(os.fspath(path))).is_relative_to(folder)

    def refuse(path: Any) -> None:
        raise OSError(errno.EROFS, os.strerror(errno.EROFS), os.fspath(path))

    real_open, real_os_open, real_mkdir = builtins.open, os.open, os.mkdir

    def fake_open(file: Any, mode: str = "r", *args: Any, **kwargs: Any) -> Any:
        if inside(file) and any(c in mode for c in "wax+"):
            refuse(file)
        return real_open(file, mode, *args, **kwargs)

    def fake_os_open(path: Any, flags: int, *args: Any, **kwargs: Any) -> int:
        if inside(path) and flags & (os.O_WRONLY | os.O_RDWR | os.O_CREAT | os.O_APPEND | os.O_TRUNC):
            refuse(path)
        return real_os_open(path, flags, *args, **kwargs)

    def fake_mkdir(path: Any, *args: Any, **kwargs: Any) -> None:
        if inside(path):
            if os.path.isdir(path):
                raise FileExistsError(errno.EEXIST, os.strerror(errno.EEXIST), os.fspath(path))
            if not os.path.isdir(os.path.dirname(os.path.abspath(path))):
                raise FileNotFoundError(errno.ENOENT, os.strerror(errno.ENOENT), os.fspath(path))
            refuse(path)
        real_mkdir(path, *args, **kwargs)

    with monkeypatch.context() as patch:
        patch.setattr(builtins, "open", fake_open)
        patch.setattr(io, "open", fake_open)  # pathlib's
        patch.setattr(os, "open", fake_os_open)
        patch.setattr(os, "mkdir", fake_mkdir)
        yield
