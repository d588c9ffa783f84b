"""Shared helpers of the experiment tests (no tests here): a small experiment and store comparisons."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

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
    from stochpound.experiment.parts import read_definition, parts_folder
    from stochpound.experiment.model import Experiment
    from stochpound.experiment.store_writer import PartsIndex

    folder = parts_folder(store)
    if not (folder / "experiment.json").is_file():
        return 0
    return PartsIndex.scan(Experiment(read_definition(folder)["definition"]), folder).n_done


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
