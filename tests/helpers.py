"""Shared helpers of the tests (no tests here): scenes, small experiments, runs and store comparisons.

Tests import their shared builders from here (``from tests.helpers import
...``), never from another test module or from ``conftest.py``, which holds
fixtures (and the hooks that order the run) only; the reference study's buildings and pairs are
:mod:`stochpound.studies.agarwal2004`'s (``study_scene``, ``reference_building``,
``study_contacts``). The benchmarks import nothing of the tests.
"""

from __future__ import annotations

import builtins
import dataclasses
import errno
import html
import io
import itertools
import os
import re
import stat
import subprocess
import sys
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterator

import numpy as np
import xarray as xr

import stochpound
from stochpound.studies.agarwal2004 import reference_building, study_contacts, study_scene

REPOSITORY = Path(__file__).resolve().parents[1]
"""The repository's root."""
PYTHON_WITH_CTRL_C = [sys.executable, "-c", "import os, signal, sys; signal.signal(signal.SIGINT, signal.SIG_DFL); "
                      "os.execv(sys.executable, [sys.executable, *sys.argv[1:]])"]
"""The start of a command line that runs this Python with SIGINT at its default, as a terminal's foreground job has it,
for tests that send a Ctrl-C: a test run started as a background job (``... &``) has SIGINT ignored, which its
subprocesses inherit, and the command then rightly leaves it ignored."""

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
QUICKSTART = REPOSITORY / "experiments" / "quickstart.toml"


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
    from stochpound.experiment import Experiment
    from stochpound.experiment._file_assembly import PartsIndex

    folder = parts_folder(store)
    if not (folder / "experiment.json").is_file():
        return 0
    return PartsIndex.scan(Experiment(read_experiment_json(folder).definition), folder).n_done


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


# ---------------------------------------------------------------- the experiment CLI


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


# ---------------------------------------------------------------- an experiment over contact laws and walls


PAIR = """
[experiment]
name = "laws"
studied = "B1"

[scene]
g = 9.814
{buildings}
{contacts}

[variants.law.kelvin]
[variants.law.hertz_damp.contact]
law = "hertz_damp"
stiffness = 2.75e9
restitution = 0.5

[variants.moat.none]
[[variants.moat.near.scene.wall]]
building = "B1"
side = "left"
level = 0
gap = 0.002
stiffness = 5.0e8
restitution = 0.5

[grid]
gap = [0.005]
mu = {{ values = [0.1], buildings = ["B1"] }}

[[motions]]
name = "pulse"
type = "harmonic"
amplitude = 3.0
omega = 6.0
duration = 3.0
dt = 0.01

[output]
demands = true
"""


def toml_tables(name: str, tables: list[dict]) -> str:
    lines = []
    for table in tables:
        lines.append(f"[[scene.{name}]]")
        nested = []
        for key, value in table.items():
            if isinstance(value, dict):
                nested.append((key, value))
            else:
                lines.append(f"{key} = {value!r}".replace("'", '"').replace("True", "true").replace("False", "false"))
        for key, value in nested:
            lines.append(f"{key} = {{ {', '.join(f'{k} = {v!r}' for k, v in value.items())} }}")
    return "\n".join(lines)


def laws_pair_text() -> str:
    buildings = [reference_building("B1", 1.0, 0.1), reference_building("B2", 2.0)]
    return PAIR.format(buildings=toml_tables("building", buildings), contacts=toml_tables("contact", study_contacts(0.02)))


# ---------------------------------------------------------------- single impacts of two free masses (contact laws)


M1, M2 = 20000.0, 30000.0  # kg


M_EFF = M1 * M2 / (M1 + M2)


K_HERTZ = 1.0e10  # N/m^1.5


V0, GAP = 0.4, 0.01  # m/s, m


def free_masses(law: str, restitution: float | None = None, duration: float = 0.1, dt: float = 0.005) -> dict:
    """Two free one-floor masses on a still ground, the first approaching the second at V0."""

    def mass(name, m, v):
        return {"name": name, "mass": [m], "stiffness": [0.0], "damping": [0.0], "initial": {"velocity": [v]}}

    contact = {"between": [["A", 1], ["B", 1]], "gap": GAP, "stiffness": K_HERTZ, "law": law}
    if restitution is not None:
        contact["restitution"] = restitution
    return {"building": [mass("A", M1, V0), mass("B", M2, 0.0)], "contact": [contact],
            "motion": {"type": "constant", "acceleration": 0.0, "duration": duration, "dt": dt}}


def run(scene: dict, **options):
    return stochpound.simulate(stochpound.scene_from_dict(scene), rtol=1e-12, atol=1e-15, **options)


def realised_restitution(result) -> float:
    """−(relative velocity after) / (relative velocity before) of the two masses, from their final constant velocities."""
    y = result.total_displacement.sel(floor=1).values
    t = result.time.values
    after = (y[:, -1] - y[:, -2]) / (t[-1] - t[-2])
    return -(after[0] - after[1]) / V0


def docs_restitution_column(law: str) -> dict[float, str]:
    """docs/model.md's realised-restitution table: target e -> the cell of the column whose header starts with ``law``."""
    from pathlib import Path

    lines = (Path(__file__).parents[1] / "docs" / "model.md").read_text().splitlines()
    header = [c.strip() for c in next(line for line in lines if line.startswith("| target e |")).split("|")]
    column = next(i for i, name in enumerate(header) if name.split(" ")[0] == law)
    return {float(cells[1]): cells[column] for line in lines
            if line.startswith("| ") and len(cells := [c.strip() for c in line.split("|")]) == len(header) and cells[1].replace(".", "").isdigit()}


# ---------------------------------------------------------------- exact against ivp


TOLERANCE = 1e-9  # m, on every floor's total displacement over the whole record


def assert_same_run(exact, reference, tolerance: float = TOLERANCE) -> None:
    """Displacements within ``tolerance``, identical impacts, same base states, a closed energy balance."""
    for name in ("total_displacement", "sliding_displacement"):
        difference = np.nan_to_num(exact[name].values - reference[name].values)
        assert np.max(np.abs(difference), initial=0.0) <= tolerance, name
    assert exact.sizes["impact"] == reference.sizes["impact"]
    np.testing.assert_array_equal(exact.impact_contact.values, reference.impact_contact.values)
    np.testing.assert_array_equal(exact.impact_in_phase.values, reference.impact_in_phase.values)
    np.testing.assert_allclose(exact.impact_start.values, reference.impact_start.values, rtol=0, atol=1e-8)
    np.testing.assert_allclose(exact.impact_end.values, reference.impact_end.values, rtol=0, atol=1e-8)
    force_scale = max(float(reference.impact_peak_force.max()) if reference.sizes["impact"] else 0.0, 1.0)
    np.testing.assert_allclose(exact.impact_peak_force.values, reference.impact_peak_force.values, rtol=0, atol=1e-6 * force_scale)
    np.testing.assert_array_equal(exact.base_state.values, reference.base_state.values)
    energy_scale = float(np.abs(reference.energy_input).max()) or 1.0
    assert float(np.abs(exact.energy_residual).max()) <= 1e-6 * energy_scale
    for term in ("input", "damping", "friction", "impact"):
        np.testing.assert_allclose(exact[f"energy_{term}"].values, reference[f"energy_{term}"].values, rtol=0, atol=1e-6 * energy_scale)
    assert exact.attrs["solver"] == "exact"


HARD_CASES = {
    "B1 isolated, El Centro 20 s": study_scene(0.2, None, 2.0, motion={"record": "el_centro_1940_study", "duration": 20.0}),
    "zero gap, stiff B2": study_scene(None, None, 0.5, gap=0.0, motion={"record": "el_centro_1940_study", "duration": 10.0}),
    "stiff contacts x100": study_scene(None, None, 2.0, motion={"record": "el_centro_1940_study", "duration": 10.0}),
    "non-tensile contacts, both isolated": study_scene(0.1, 0.1, 0.5, gap=0.002, motion={"record": "el_centro_1940_study", "duration": 20.0}),
    "frictionless against a neighbour": {
        "building": [reference_building("B1", mu=0.0), reference_building("B2", 2.0)],
        "contact": study_contacts(0.0, mass_factor=2.0),
        "motion": {"type": "constant", "acceleration": -0.5, "duration": 10.0, "dt": 0.02},
    },
}


for contact in HARD_CASES["stiff contacts x100"]["contact"]:
    contact["stiffness"] *= 100.0


for contact in HARD_CASES["non-tensile contacts, both isolated"]["contact"]:
    contact["tensile"] = False


def interpreted_scene() -> dict:
    """B1 isolated (μ = 0.1) against a stiff fixed B2 at zero gap, non-tensile contacts, 2 s of El Centro: 13 impacts."""
    scene = study_scene(0.1, None, 0.5, gap=0.0, motion={"record": "el_centro_1940_study", "duration": 2.0})
    for contact in scene["contact"]:
        contact["tensile"] = False
    return scene


# ---------------------------------------------------------------- random scenes


def random_scene(seed: int, duration: float = 6.0) -> dict:
    """A random scene dictionary (see the module docstring); the same seed gives the same scene."""
    rng = np.random.default_rng(seed)
    buildings = [_random_building(rng, f"B{b + 1}") for b in range(int(rng.integers(1, 5)))]
    contacts = [
        _random_contact(rng, left, right, floor)
        for left, right in itertools.pairwise(buildings)
        for floor in range(1, min(len(left["mass"]), len(right["mass"])) + 1)
        if rng.random() < 0.8
    ]
    return {"g": 9.81, "building": buildings, "contact": contacts, "motion": _random_motion(rng, duration), "study_compat": bool(rng.random() < 0.15)}


def _random_building(rng: np.random.Generator, name: str) -> dict:
    floors = int(rng.integers(1, 5))
    building = {"name": name, "mass": rng.uniform(1e4, 5e4, floors).tolist(), "stiffness": rng.uniform(5e6, 5e7, floors).tolist()}
    if rng.random() < 0.7:
        building["damping_ratio"] = float(rng.uniform(0.0, 0.08))
    else:
        building["damping"] = rng.uniform(0.0, 5e4, floors).tolist()
    if rng.random() < 0.6:
        mu = 0.0 if rng.random() < 0.1 else float(rng.uniform(0.02, 0.4))
        base = {"mass": float(rng.uniform(5e3, 3e4)), "mu": mu}
        if mu > 0 and rng.random() < 0.3:
            base["mu_static"] = mu * float(rng.uniform(1.0, 1.5))
        if rng.random() < 0.2:
            base["restoring_stiffness"] = float(rng.uniform(1e4, 1e6))
        building["base"] = base
    return building


def _random_contact(rng: np.random.Generator, left: dict, right: dict, floor: int) -> dict:
    contact = {
        "between": [[left["name"], floor], [right["name"], floor]],
        "gap": 0.0 if rng.random() < 0.25 else float(rng.uniform(0.0, 0.03)),
        "stiffness": float(10 ** rng.uniform(7.0, 10.0)),
    }
    if rng.random() < 0.7:
        contact["restitution"] = float(rng.uniform(0.3, 0.95))
    else:
        contact["damping"] = float(rng.uniform(0.0, 5e5))
    if rng.random() < 0.3:
        contact["tensile"] = False
    return contact


def _random_motion(rng: np.random.Generator, duration: float) -> dict:
    kind = rng.choice(["record", "kanai_tajimi", "harmonic"], p=[0.4, 0.4, 0.2])
    if kind == "record":
        interpolation = "spline" if rng.random() < 0.3 else "linear"
        return {"record": "el_centro_1940_study", "duration": duration, "scale": float(rng.uniform(0.5, 2.5)), "interpolation": interpolation}
    if kind == "kanai_tajimi":
        return {"type": "kanai_tajimi", "omega_g": float(rng.uniform(5.0, 20.0)), "zeta_g": float(rng.uniform(0.2, 0.7)),
                "pga": float(rng.uniform(1.0, 10.0)), "seed": int(rng.integers(0, 1000)), "duration": duration, "dt": 0.01}
    return {"type": "harmonic", "amplitude": float(rng.uniform(1.0, 8.0)), "omega": float(rng.uniform(2.0, 30.0)),
            "phase": float(rng.uniform(0.0, 2 * np.pi)), "duration": duration, "dt": 0.02}


# ---------------------------------------------------------------- the risk flagship's scene in small experiments

MOTIONS = ["01a", "03b", "05a", "07b", "10a", "12a", "14b", "19a"]
RECORDS = "".join(f'\n[[records]]\nrecord = "fema_p695_far_field/{name}"\nduration = 5.0\n' for name in MOTIONS)
FLAGSHIP = (REPOSITORY / "experiments" / "risk" / "isolated.toml").read_text()
_YIELDING = r"^(storey_height|yield_force|hardening|p_delta) = .*\n"  # the flagship's yielding storeys: these small experiments stay elastic (IDA)
ISOLATED = re.sub(_YIELDING, "", FLAGSHIP[FLAGSHIP.index("[scene]"):FLAGSHIP.index("[variants")], flags=re.MULTILINE)  # its scene, no variants
#: The same pair on fixed bases (the bundled ``elastic_pair``) beside the stiff neighbour (masses x 0.5), else the pair moves as one.
FIXED = '[scene]\nbundled = "elastic_pair"\n[scene.building.B2]\nmass = [13134.0, 8756.0]\n'
BUNDLED = "fox_plaza_los_angeles_sa1p0s"

def risk_text(scene: str, grid: str, intensity: str, hazard: str = f'bundled = "{BUNDLED}"') -> str:
    """A small experiment of the flagship's scene under eight far-field motions, with its intensity and hazard tables."""
    hazard_table = f"\n[hazard]\n{hazard}\n" if hazard else ""
    return (f'[experiment]\nname = "risk"\nstudied = "B1"\n{scene}\n[grid]\n{grid}\n{RECORDS}\n[intensity]\n{intensity}\n{hazard_table}'
            '[output]\nimpacts = true\n')


def with_gaps(scene, gaps: tuple[float, ...]):
    """``scene`` (a :class:`stochpound.model.scene.Scene`) with contact c's gap set to ``gaps[c]`` (m)."""
    return dataclasses.replace(scene, contacts=tuple(dataclasses.replace(c, gap=float(g)) for c, g in zip(scene.contacts, gaps)))


#: Two buildings (a two-storey and a one-storey) and one contact: the scene of the intensity and site experiments' tests.
SITE_SCENE = """
[scene]
g = 9.81
[[scene.building]]
name = "B1"
mass = [2.0e5, 1.5e5]
stiffness = [1.2e8, 0.9e8]
damping_ratio = 0.05
[[scene.building]]
name = "B2"
mass = [1.0e5]
stiffness = [1.5e7]
damping_ratio = 0.02
[[scene.contact]]
between = [["B1", 1], ["B2", 1]]
gap = 0.02
stiffness = 1.0e8
restitution = 0.65
"""


# ---------------------------------------------------------------- report texts, compared without the machine's last digits


ROUNDING = 1e-9
"""Two printed numbers that differ by less than this, absolutely or relative to their size, are the same number: the
machine's last digits. A report's solver differences and residuals are rounding (7.6e-13 m on one machine, 9.2e-13 m on
another) and its tables print 17 digits, the last few set by the BLAS kernels of the CPU; nothing a report states means
anything at 1e-9 (a nanometre, once in a billion years), and any real change is far larger."""
_NUMBER = re.compile(r"(?<![\w.])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?!\w|\.\d)")
_SOFTWARE = re.compile(r"^(Software: .*)$", re.MULTILINE)


def report_page_text(out: Path, folder: Path) -> str:
    """The words and tables of the report built into ``out`` (figures left out), with what differs between machines masked:
    the build date, the commit, the run ``folder`` and the versions of the software it lists (their names kept)."""
    page = (out / "index.html").read_text()
    page = re.sub(r"<(style|script)\b.*?</\1>", "", page, flags=re.S)
    page = re.sub(r'src="data:[^"]*"', "", page)
    lines = (" ".join(line.split()) for line in html.unescape(re.sub(r"<[^>]+>", " ", page)).splitlines())
    parts = ["\n".join(line for line in lines if line)]
    parts += [f"== {table.name}\n{table.read_text()}" for table in sorted((out / "tables").glob("*.csv"))]
    text = "\n".join(parts).replace(str(folder), "<folder>")
    text = re.sub(r"\b[0-9a-f]{40}\b(\+dirty)?", "<commit>", text)  # a build from a tree with changes says +dirty
    text = _SOFTWARE.sub(lambda line: re.sub(r" \d[\w.+-]*(?=[,.]( |$))", " <version>", line.group(1)), text)
    return re.sub(r"\b\d{4}-\d{2}-\d{2}\b", "<date>", text) + "\n"


def text_difference(text: str, reference: str, rounding: float = ROUNDING) -> str:
    """Where ``text`` differs from ``reference`` beyond the machine's last digits ("" where it does not).

    The words, punctuation and layout must be identical; each number must
    equal the reference's to ``rounding``, absolutely or relatively
    (:data:`ROUNDING`). Returns the first line that differs, both versions,
    with the numbers that differ named.
    """
    ours, theirs = text.splitlines(), reference.splitlines()
    for number, (line, expected) in enumerate(zip(ours, theirs), start=1):
        if line == expected:
            continue
        if _NUMBER.split(line) != _NUMBER.split(expected):
            return f"line {number}: the words differ:\n  now:       {line}\n  reference: {expected}"
        pairs = zip(_NUMBER.findall(line), _NUMBER.findall(expected))
        far = [(a, b) for a, b in pairs if abs(float(a) - float(b)) > rounding * max(1.0, abs(float(a)), abs(float(b)))]
        if far:
            return f"line {number}: the numbers {', '.join(f'{a} (reference {b})' for a, b in far)} differ beyond {rounding:g}:\n  now:       {line}"
    if len(ours) != len(theirs):
        return f"the text has {len(ours)} lines, the reference {len(theirs)}"
    return ""


TILTED_MEMBERS = [f"fema_p695_far_field/{i:02d}{c}" for i in range(1, 4) for c in "ab"]
"""Six records of the far-field set: the records of the small tilted-pool experiment (:func:`tilted_site_text`)."""
SIMULATED_SITE = '[site]\nvs30 = 400.0\nmagnitude = 6.5\ndistance_km = 20.0\nmechanism = "strike_slip"\nsimulated_motions = 12\n'
"""A ``[site]`` of one given scenario with 12 simulated motions a stripe."""
TILTED_SITE = SIMULATED_SITE + 'simulated_sampling = "tilted"\n'
"""The same, tilted to each stripe."""


def tilted_site_text(site: str = TILTED_SITE) -> str:
    """A small conditional-spectrum experiment (2 stripes of PSA(0.5 s), 4 motions each, 6 records) with ``site`` as its ``[site]``."""
    records = "".join(f'\n[[records]]\nrecord = "{name}"\nduration = 5.0\n' for name in TILTED_MEMBERS)
    intensity = ('[intensity]\nmeasure = "psa"\nperiod = 0.5\nlevels = [0.6, 0.2]\nselection = "conditional_spectrum"\nmotions = 4\n'
                 'max_scale_factor = 5.0\nseed = 2\n')
    return f'[experiment]\nname = "tilted"\n{SITE_SCENE}\n[grid]\ngap = ["inf"]\n{records}\n{intensity}{site}\n[solver]\nmethod = "exact"\n'


def stripes_site_text(hazard: str) -> str:
    """An experiment of two conditional-spectrum stripes of PSA(1 s) (0.5611 and 0.9299 g, 4 motions each of 12 FEMA P695
    far-field components, 5 s of each) under :data:`SITE_SCENE`, contact-free and at a 5 cm gap, with the ``[hazard]`` lines given."""
    members = [f"fema_p695_far_field/{i:02d}{c}" for i in range(1, 7) for c in "ab"]
    records = "".join(f'\n[[records]]\nrecord = "{name}"\nduration = 5.0\n' for name in members)
    intensity = ('[intensity]\nmeasure = "psa"\nperiod = 1.0\ndamping = 0.05\nunits = "g"\nlevels = [0.5611, 0.9299]\nselection = "conditional_spectrum"\n'
                 'motions = 4\nmax_scale_factor = 8.0\nseed = 3\n'
                 '[site]\nvs30 = 400.0\nmagnitude = 7.2\ndistance_km = 10.0\nmechanism = "reverse"\n')
    return f'[experiment]\nname = "site"\n{SITE_SCENE}\n[grid]\ngap = ["inf", 0.05]\n{records}\n{intensity}\n{hazard}\n[solver]\nmethod = "exact"\n'
