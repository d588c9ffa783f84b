"""Every bad scene field is rejected before any computation, with the field and the allowed range named."""

import copy
import subprocess
import sys

import numpy as np
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


def test_a_record_s_units_are_read_in_the_records_spellings(tmp_path):
    """Issue 48: [motion] units took only g, m/s2 and cm/s2; now every spelling the records' reader knows (gal, cm/s², ...)."""
    text = "0.0\n981.0\n-490.5\n0.0\n"
    motions = {units: stochpound.scene_from_dict({**copy.deepcopy(VALID), "motion": record_motion(tmp_path, text, dt=0.02, units=units)},
                                                 base_dir=tmp_path).motion for units in ("cm/s2", "gal", "cm/s²", "cm/s/s")}
    samples = [motion.values for motion in motions.values()]
    np.testing.assert_allclose(samples[0], [0.0, 9.81, -4.905, 0.0], rtol=1e-12)
    assert all(np.array_equal(other, samples[0]) for other in samples[1:])
    message = rejected(lambda s: s.update(motion=record_motion(tmp_path, text, dt=0.02, units="mm/s2")), tmp_path)
    assert message.startswith("motion.units must be one of g, m/s2, cm/s2 (or gal,") and message.endswith("got 'mm/s2'") and "\n" not in message


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


# ---------------------------------------------------------------- scene checks a designer expects: repeated contacts and walls, periods, g


def test_a_contact_written_twice_is_refused_naming_both_tables():
    """The same between pair in two [[contact]] tables added their stiffnesses without a word (75 impacts instead of 46)."""
    message = rejected(lambda s: s["contact"].append(copy.deepcopy(s["contact"][0])))
    assert message.startswith("contact[2].between: 'B1' floor 1 and 'B2' floor 1, the same as contact[0];") and "\n" not in message

    def other_law(scene):
        scene["contact"].insert(0, {**copy.deepcopy(scene["contact"][1]), "stiffness": 1.0e6})

    assert rejected(other_law).startswith("contact[2].between: 'B1' floor 2 and 'B2' floor 2, the same as contact[0];")


WALL = {"building": "B2", "side": "right", "level": 2, "gap": 0.05, "stiffness": 1.0e7, "restitution": 0.5}


def test_a_wall_written_twice_is_refused_naming_both_tables():
    message = rejected(lambda s: s.update(wall=[dict(WALL), {**WALL, "gap": 0.1}]))
    assert message.startswith("wall[1]: building 'B2', side 'right', level 2, the same as wall[0];") and "\n" not in message
    elsewhere = copy.deepcopy(VALID)
    elsewhere["wall"] = [dict(WALL), {**WALL, "level": 1}, {**WALL, "building": "B1", "side": "left"}]
    assert len(stochpound.scene_from_dict(elsewhere).walls) == 3


def _one_storey(floor_mass: float, stiffness: float, **base) -> dict:
    building = {"name": "B1", "mass": [floor_mass], "stiffness": [stiffness]}
    if base:
        building["base"] = base
    return {"building": [building], "motion": {"type": "constant", "acceleration": 0.0, "duration": 0.1, "dt": 0.01}}


def test_building_periods_against_closed_forms():
    from stochpound.model import building_periods, scene_periods

    single = stochpound.scene_from_dict(_one_storey(2.0e5, 3.0e7))
    assert building_periods(single.buildings[0], 9.81) == {"first mode": pytest.approx(2 * np.pi * np.sqrt(2.0e5 / 3.0e7), rel=1e-12)}
    # two equal storeys of equal masses: ω1² = (3 - √5)/2 · k/m
    pair = stochpound.scene_from_dict({"building": [{"name": "A", "mass": [1.0e5, 1.0e5], "stiffness": [4.0e7, 4.0e7]}], "motion": _one_storey(1, 1)["motion"]})
    assert scene_periods(pair) == {"A first mode": pytest.approx(2 * np.pi / np.sqrt((3 - np.sqrt(5)) / 2 * 4.0e7 / 1.0e5), rel=1e-12)}
    spring = stochpound.scene_from_dict(_one_storey(2.0e5, 3.0e7, mass=1.0e5, mu=0.1, restoring_stiffness=6.0e5))
    assert scene_periods(spring)["B1 isolated"] == pytest.approx(2 * np.pi * np.sqrt(3.0e5 / 6.0e5), rel=1e-12)
    pendulum = stochpound.scene_from_dict({**_one_storey(2.0e5, 3.0e7, mass=1.0e5, mu=0.05, radius=2.0), "g": 9.81})
    assert scene_periods(pendulum)["B1 isolated"] == pytest.approx(2 * np.pi * np.sqrt(2.0 / 9.81), rel=1e-12)
    assert set(scene_periods(stochpound.scene_from_dict(_one_storey(2.0e5, 3.0e7, mass=1.0e5, mu=0.1)))) == {"B1 first mode"}


@pytest.mark.parametrize("g, warned", [(9.81, False), (9.7, False), (9.9, False), (9.814, False), (1.0, True), (32.174, True), (9.6, True)])
def test_g_outside_the_earths_range_is_warned_not_refused(g, warned):
    from stochpound.model import scene_warnings

    scene = stochpound.scene_from_dict({**_one_storey(2.0e5, 3.0e7), "g": g})
    assert scene.g == g
    expected = [f"g: {g:g} m/s² is outside 9.7-9.9 m/s², the Earth's gravity (g is in m/s², e.g. 9.81); used as given"] if warned else []
    assert scene_warnings(scene) == expected
    assert scene_warnings(scene, "scene") == [line.replace("g:", "scene.g:", 1) for line in expected]


def _scene_file(tmp_path, mass: float, g: float = 9.81) -> str:
    path = tmp_path / "scene.toml"
    path.write_text(f"g = {g}\n[[building]]\nname = \"B1\"\nmass = [{mass}]\nstiffness = [3.0e7]\n"
                    "[motion]\ntype = \"harmonic\"\namplitude = 1.0\nomega = 5.0\nduration = 0.5\ndt = 0.01\n")
    return str(path)


def test_simulate_prints_each_buildings_period_and_warns_on_g(tmp_path):
    """Masses in tonnes show at once in the printed period; g = 1 is run, with a warning naming the field."""
    from tests.helpers import invoke

    in_tonnes = invoke("simulate", _scene_file(tmp_path, 200.0, g=1.0), "--out", str(tmp_path / "t.nc"), "--method", "ivp")
    assert in_tonnes.exit_code == 0 and (tmp_path / "t.nc").exists(), in_tonnes.output
    assert f"periods B1 first mode {2 * np.pi * np.sqrt(200.0 / 3.0e7):.3g} s" in in_tonnes.stdout  # 0.0162 s: 0.513 s in kg
    assert in_tonnes.stderr.strip().splitlines() == ["warning: g: 1 m/s² is outside 9.7-9.9 m/s², the Earth's gravity (g is in m/s², e.g. 9.81); used as given"]


def _two_storey_first_period(mass: list[float], stiffness: list[float]) -> float:
    """T1 of a two-storey shear building from det(K - ω²M) = 0: m1 m2 ω⁴ - (m1 k2 + m2 (k1 + k2)) ω² + k1 k2 = 0."""
    (m1, m2), (k1, k2) = mass, stiffness
    b = m1 * k2 + m2 * (k1 + k2)
    omega_squared = (b - np.sqrt(b * b - 4 * m1 * m2 * k1 * k2)) / (2 * m1 * m2)
    return 2 * np.pi / np.sqrt(omega_squared)


def test_experiment_check_prints_the_periods_and_warns_on_g(tmp_path):
    """The small experiment: B1 [26268, 17512] kg on [24.5168, 17.512] MN/m; B2 the same with masses x 0.5 (stiff) or x 2 (flexible)."""
    from tests.helpers import SMALL_EXPERIMENT, invoke, write_experiment

    checked = invoke("experiment", "check", str(write_experiment(tmp_path)))
    assert checked.exit_code == 0, checked.output
    periods = [line for line in checked.stdout.splitlines() if line.strip().startswith("periods")]
    mass, stiffness = np.array([26268.0, 17512.0]), [24516800.0, 17512000.0]
    assert len(periods) == 1 and f"B1 first mode {_two_storey_first_period(mass, stiffness):.3g} s" in periods[0]
    assert f"B2 first mode (neighbour=stiff) {_two_storey_first_period(0.5 * mass, stiffness):.3g} s" in periods[0]
    assert f"B2 first mode (neighbour=flexible) {_two_storey_first_period(2.0 * mass, stiffness):.3g} s" in periods[0]
    assert "warning" not in checked.stderr
    one_g = invoke("experiment", "check", str(write_experiment(tmp_path, SMALL_EXPERIMENT.replace("g = 9.814", "g = 1.0"), "one_g.toml")))
    assert one_g.exit_code == 0 and "warning: scene.g: 1 m/s² is outside 9.7-9.9 m/s²" in one_g.stderr
