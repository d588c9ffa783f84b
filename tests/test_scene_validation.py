"""Every bad scene field is rejected before any computation, with the field and the allowed range named."""

import copy
import subprocess
import sys

import pytest

import stochpound
from stochpound import SceneError
from stochpound.studies.agarwal2004 import study_scene

VALID = study_scene(0.2, None, 2.0, motion={"type": "harmonic", "amplitude": 1.0, "omega": 2.0, "duration": 1.0, "dt": 0.01})


def rejected(mutate, tmp_path=None) -> str:
    scene = copy.deepcopy(VALID)
    mutate(scene)
    with pytest.raises(SceneError) as error:
        stochpound.scene_from_dict(scene, base_dir=tmp_path or ".")
    return str(error.value)


def setter(path: str, value):
    """A mutation setting scene[path] (dotted, with [i] indices) to value."""

    def mutate(scene):
        *parents, last = path.replace("]", "").replace("[", ".").split(".")
        target = scene
        for key in parents:
            target = target[int(key)] if key.isdigit() else target[key]
        if last.isdigit():
            target[int(last)] = value
        else:
            target[last] = value

    return mutate


CASES = [
    ("g", -9.81, "g: must be > 0"),
    ("g", "9.81", "g: must be a number, got str"),
    ("study_compat", 1, "study_compat: must be true or false"),
    ("building[0].mass", "heavy", "building[0].mass: must be a list of numbers"),
    ("building[0].mass[1]", -17512.0, "building[0].mass[1]: must be > 0, got -17512"),
    ("building[0].mass[0]", 0.0, "building[0].mass[0]: must be > 0, got 0"),
    ("building[0].stiffness", [1.0], "building[0].stiffness: must have 2 values"),
    ("building[0].stiffness[0]", -1.0, "building[0].stiffness[0]: must be >= 0"),
    ("building[0].damping[1]", -5.0, "building[0].damping[1]: must be >= 0"),
    ("building[1].damping_ratio", 1.5, "building[1].damping_ratio: must be < 1"),
    ("building[1].damping_ratio", True, "building[1].damping_ratio: must be a number, got bool"),
    ("building[0].base.mu", -0.2, "building[0].base.mu: must be >= 0, got -0.2"),
    ("building[0].base.mu_static", 0.1, "building[0].base.mu_static: must be >= 0.2, got 0.1"),
    ("building[0].base.mass", -1.0, "building[0].base.mass: must be > 0"),
    ("building[0].base.restoring_stiffness", -1.0, "building[0].base.restoring_stiffness: must be >= 0"),
    ("building[0].base.friction", 0.2, "building[0].base.friction: unknown field"),
    ("building[1].name", "B1", "building[1].name: must be unique"),
    ("contact[0].restitution", 0.0, "contact[0].restitution: must be > 0, got 0"),
    ("contact[0].restitution", 1.5, "contact[0].restitution: must be <= 1, got 1.5"),
    ("contact[0].gap", -0.01, "contact[0].gap: must be >= 0"),
    ("contact[0].stiffness", 0.0, "contact[0].stiffness: must be > 0"),
    ("contact[0].tensile", "yes", "contact[0].tensile: must be true or false"),
    ("contact[0].between", [["B3", 1], ["B2", 1]], "contact[0].between[0]: unknown building 'B3'"),
    ("contact[0].between", [["B1", 3], ["B2", 1]], "contact[0].between[0]: floor must be in 1..2"),
    ("contact[0].between", [["B1", 1], ["B2", 0]], "contact[0].between[1]: floor must be in 1..2"),
    ("contact[0].between", [["B2", 1], ["B1", 1]], "contact[0].between: contacts join neighbours, left building first"),
    ("contact[0].between", [["B1", 1]], "contact[0].between: must be [[left building, floor], [right building, floor]]"),
    ("motion.type", "earthquake", "motion.type: must be one of"),
    ("motion.omega", -2.0, "motion.omega: must be >= 0"),
    ("motion.dt", 0.0, "motion.dt: must be > 0"),
    ("motion.dt", 2.0, "motion.dt: must be <= motion.duration"),
    ("motion.amplitude", float("nan"), "motion.amplitude: must be a number, got nan"),
]


@pytest.mark.parametrize("path, value, message", CASES, ids=[f"{c[0]}={c[1]!r}" for c in CASES])
def test_bad_field_is_named(path, value, message):
    assert message in rejected(setter(path, value))


def test_missing_required_fields_are_named():
    assert "building[0].base.mu: missing" in rejected(lambda s: s["building"][0]["base"].pop("mu"))
    assert "contact[0].stiffness: missing" in rejected(lambda s: s["contact"][0].pop("stiffness"))
    assert "motion: missing" in rejected(lambda s: s.pop("motion"))
    assert "building: at least one" in rejected(lambda s: s.update(building=[]))


def test_non_neighbour_contact_is_rejected():
    def three_buildings(scene):
        third = copy.deepcopy(scene["building"][1])
        third["name"] = "B3"
        scene["building"].append(third)
        scene["contact"][0]["between"] = [["B1", 1], ["B3", 1]]

    assert "are not left/right neighbours" in rejected(three_buildings)


def record_motion(tmp_path, text: str, **extra) -> dict:
    path = tmp_path / "record.txt"
    path.write_text(text)
    return {"record": "record.txt", **extra}


@pytest.mark.parametrize(
    "text, extra, message",
    [
        ("0.01\n0.02\nnan\n0.01\n", {"dt": 0.02, "units": "g"}, "motion.record"),
        ("0.0 0.01\n0.02 0.02\n0.05 0.01\n", {"units": "g"}, "motion.record"),
        ("", {"dt": 0.02, "units": "g"}, "motion.record"),
        ("0.01\n0.02\n0.03\n", {"units": "g"}, "motion.record"),
    ],
    ids=["nan", "non-uniform time step", "zero length", "missing dt"],
)
def test_bad_records_are_rejected(tmp_path, text, extra, message):
    assert message in rejected(lambda s: s.update(motion=record_motion(tmp_path, text, **extra)), tmp_path)


def test_missing_record_is_rejected():
    assert "motion.record" in rejected(lambda s: s.update(motion={"record": "no_such_record"}))


SYNTHETIC = {"type": "kanai_tajimi", "omega_g": 15.0, "zeta_g": 0.6, "pga": 3.0, "seed": 1, "duration": 2.0, "dt": 0.01}


@pytest.mark.parametrize(
    "change, message",
    [
        ({"omega_g": None}, "motion.omega_g: required for type = 'kanai_tajimi'"),
        ({"type": "clough_penzien"}, "motion.omega_f: required for type = 'clough_penzien'"),
        ({"soil": "firm"}, "motion.soil: unknown field (allowed: S0, band_limit"),
        ({"zeta_g": -0.1}, "motion: zeta_g"),
        ({"realization": -1}, "motion.realization: must be an integer >= 0"),
    ],
    ids=["missing omega_g", "missing filter of clough_penzien", "unknown field", "bad value", "bad realization"],
)
def test_bad_synthetic_motions_are_rejected(change, message):
    motion = {key: value for key, value in {**SYNTHETIC, **change}.items() if value is not None}
    assert message in rejected(lambda s: s.update(motion=motion))


def test_cli_reports_the_field_and_writes_nothing(tmp_path):
    scene_file = tmp_path / "bad.toml"
    scene_file.write_text(
        '[[building]]\nname = "B1"\nmass = [1000.0]\nstiffness = [1e6]\n[building.base]\nmass = 500.0\nmu = -0.2\n'
        '[motion]\ntype = "harmonic"\namplitude = 1.0\nomega = 2.0\nduration = 1.0\ndt = 0.01\n'
    )
    out = tmp_path / "run.nc"
    result = subprocess.run(
        [sys.executable, "-m", "stochpound", "simulate", str(scene_file), "--out", str(out)], capture_output=True, text=True
    )
    assert result.returncode != 0
    assert "building[0].base.mu: must be >= 0, got -0.2" in result.stderr
    assert not out.exists()
    assert list(tmp_path.iterdir()) == [scene_file]
