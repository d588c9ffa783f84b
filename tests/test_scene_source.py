"""An experiment's base scene from a scene file or a bundled scene: the definition holds its content, its identity is the inline scene's."""

from __future__ import annotations

import hashlib
import json
import re
import tomllib
from pathlib import Path

import pytest

from stochpound._errors import SceneError
from stochpound.experiment import load_experiment, run_experiment
from stochpound.experiment._spec import ExperimentError, load_definition, parse_experiment
from stochpound.model.scene_file import bundled_scene_path, bundled_scenes, read_scene_table
from stochpound.store import canonical_json, definition_sha256, open_store
from tests.helpers import FIXED, REPOSITORY, invoke, write_experiment

REST = '\n[grid]\ngap = [0.01, inf]\n[[motions]]\nname = "pulse"\ntype = "harmonic"\namplitude = 3.0\nomega = 6.0\nduration = 1.0\ndt = 0.01\n'
BUNDLED_PAIR = bundled_scene_path("elastic_pair")


def inline(scene_file: Path) -> str:
    """A scene file's text as an experiment's inline ``[scene]`` (its tables renamed ``scene.*``)."""
    text = re.sub(r"^\[\[(building|contact|wall)\]\]", r"[[scene.\1]]", scene_file.read_text(), flags=re.MULTILINE)
    return "[scene]\n" + text


def stiff_neighbour_inline() -> str:
    """The bundled pair written out inline, B2's masses halved (the stiff neighbour)."""
    text = inline(BUNDLED_PAIR)
    b2 = text.rindex("mass = [26268.0, 17512.0]")
    return text[:b2] + "mass = [13134.0, 8756.0]" + text[b2 + len("mass = [26268.0, 17512.0]"):]


def definition(scene: str, base_dir: Path = Path(".")) -> dict:
    return parse_experiment(tomllib.loads(f'[experiment]\nname = "pair"\n{scene}\n{REST}'), base_dir=base_dir)


def test_bundled_scenes_are_listed_and_found() -> None:
    assert "elastic_pair" in bundled_scenes()
    assert BUNDLED_PAIR.name == "elastic_pair.toml"
    for name in ("nope", "../study/reference_tables", "elastic_pair.toml"):
        with pytest.raises(SceneError, match=r"^no bundled scene '.*' \(bundled: .*elastic_pair"):
            bundled_scene_path(name)


def test_a_scene_file_or_a_bundled_scene_has_the_identity_of_the_same_scene_inlined(tmp_path: Path) -> None:
    """The definition holds the file's content: the canonical dict (but its provenance) and the sha256 are the inline scene's."""
    (tmp_path / "scenes").mkdir()
    (tmp_path / "scenes" / "pair.toml").write_bytes(BUNDLED_PAIR.read_bytes())
    sha256 = hashlib.sha256(BUNDLED_PAIR.read_bytes()).hexdigest()
    inlined = definition(inline(BUNDLED_PAIR))
    assert "scene_source" not in inlined
    sources = {
        '[scene]\nbundled = "elastic_pair"': {"bundled": "elastic_pair", "sha256": sha256},
        '[scene]\nfile = "scenes/pair.toml"': {"file": "scenes/pair.toml", "sha256": sha256},
    }
    for scene, provenance in sources.items():
        read = definition(scene, base_dir=tmp_path)
        assert read["scene"] == tomllib.loads(BUNDLED_PAIR.read_text())
        assert read.pop("scene_source") == provenance
        assert canonical_json(read) == canonical_json(inlined)
        assert definition_sha256({**read, "scene_source": provenance}) == definition_sha256(inlined)


def test_building_edits_of_a_bundled_scene_give_the_edited_scene_inlined() -> None:
    """``[scene.building.B2]`` beside ``bundled`` is applied once, with the variants' rules: the identity of the edited scene written out."""
    edited = definition('[scene]\nbundled = "elastic_pair"\n[scene.building.B2]\nmass = [13134.0, 8756.0]\n[scene.building.B1]\nbase = { mass = 13134.0, mu = 0.05 }\n')
    written = stiff_neighbour_inline().replace('damping_ratio = 0.05\n', 'damping_ratio = 0.05\nbase = { mass = 13134.0, mu = 0.05 }\n', 1)
    assert edited["scene"]["building"][0]["base"] == {"mass": 13134.0, "mu": 0.05}
    assert definition_sha256(edited) == definition_sha256(definition(written))


def test_the_bundled_pair_is_the_risk_flagships_pair_without_yielding_and_base() -> None:
    """The risk experiments' pair (experiments/risk/isolated.toml) without its yielding storeys and B1's base is the bundled one,
    and the tests' fixed pair (tests.helpers.FIXED, its stiff neighbour) is that pair with B2's masses halved."""
    flagship, _ = load_definition(REPOSITORY / "experiments" / "risk" / "isolated.toml")
    scene = flagship["scene"]
    for building in scene["building"]:
        for key in ("storey_height", "yield_force", "hardening", "p_delta", "base"):
            building.pop(key, None)
    assert scene == read_scene_table(BUNDLED_PAIR)
    fixed = definition(FIXED)
    assert fixed["scene_source"]["bundled"] == "elastic_pair"
    assert fixed["scene"]["building"][1]["mass"] == [13134.0, 8756.0]
    assert fixed["scene"]["building"][0] == scene["building"][0] and fixed["scene"]["contact"] == scene["contact"]


@pytest.mark.parametrize(("scene", "message"), [
    ('[scene]\nfile = "missing.toml"', "scene.file: {tmp}/missing.toml: scene file not found"),
    ('[scene]\nbundled = "nope"', "scene.bundled: no bundled scene 'nope' (bundled: elastic_pair)"),
    ('[scene]\nbundled = 3', "scene.bundled: must be a bundled scene's name (elastic_pair), got 3"),
    ('[scene]\nfile = ""', "scene.file: must be a path to a scene file (relative to the experiment file), got ''"),
    ('[scene]\nbundled = "elastic_pair"\nfile = "pair.toml"', "scene.bundled: give one of scene.file and scene.bundled, not both"),
    ('[scene]\nbundled = "elastic_pair"\ng = 9.81', "scene.g: not allowed beside scene.bundled (the scene is the file's; edit its buildings in [scene.building.<name>] tables)"),
    ('[scene]\nbundled = "elastic_pair"\n[[scene.building]]\nname = "B3"',
     "scene.building: not allowed beside scene.bundled (the scene is the file's; edit its buildings in [scene.building.<name>] tables)"),
    ('[scene]\nbundled = "elastic_pair"\n[scene.building.B3]\nmass_factor = 2.0', "scene.building.B3: unknown building (buildings: B1, B2)"),
    ('[scene]\nbundled = "elastic_pair"\n[scene.building.B2]\ncolour = "red"',
     "scene.building.B2.colour: unknown field (allowed: base, damping, damping_ratio, hardening, initial, mass, mass_factor, stiffness, yield_force)"),
    ('[experiment]\nscene = "pair.toml"\n[scene]\nbundled = "elastic_pair"', "experiment.scene: give either a scene path here or an inline [scene] table, not both"),
])
def test_a_bad_scene_source_is_a_one_line_error_naming_the_field(tmp_path: Path, scene: str, message: str) -> None:
    text = f'{scene}\n{REST}' if scene.startswith("[experiment]") else f'[experiment]\nname = "pair"\n{scene}\n{REST}'
    with pytest.raises(ExperimentError) as raised:
        parse_experiment(tomllib.loads(text), base_dir=tmp_path)
    assert str(raised.value) == message.format(tmp=tmp_path)


def test_an_edit_that_breaks_a_bundled_scene_is_named_in_the_scene(tmp_path: Path) -> None:
    text = f'[experiment]\nname = "pair"\n[scene]\nbundled = "elastic_pair"\n[scene.building.B2]\ndamping_ratio = 1.5\n{REST}'
    result = invoke("experiment", "check", str(write_experiment(tmp_path, text, "pair.toml")))
    assert result.exit_code == 1
    assert result.stderr.strip() == "Error: scene.building[1].damping_ratio: must be < 1, got 1.5"


def test_a_complete_store_is_kept_when_only_the_scene_source_changed(tmp_path: Path) -> None:
    """The same content from a bundled scene, then inline: nothing runs, the cases are kept, and the store records the
    file's new text and provenance (no bundled scene any more), so that a report names the file as it is."""
    path = write_experiment(tmp_path, f'[experiment]\nname = "pair"\n{FIXED}\n{REST}', "pair.toml")
    first = run_experiment(load_experiment(path), workers=0, progress=False)
    assert first.complete and not first.failed
    with open_store(first.store) as store:
        before = store.load()
    assert json.loads(before.attrs["definition"])["scene_source"]["bundled"] == "elastic_pair"
    path.write_text(f'[experiment]\nname = "pair"\n{stiff_neighbour_inline()}\n{REST}')
    again = run_experiment(load_experiment(path), workers=0, progress=False)
    assert again.nothing_to_run
    with open_store(again.store) as store:
        after = store.load()
    assert after.attrs["experiment_text"] == path.read_text()
    assert "scene_source" not in json.loads(after.attrs["definition"])
    assert after.attrs["definition_sha256"] == before.attrs["definition_sha256"]
    for name, values in before.data_vars.items():
        assert values.equals(after[name]), name


def test_a_complete_store_run_from_another_file_records_that_file(tmp_path: Path) -> None:
    """The same experiment from a copy elsewhere, with other comments, onto the store: nothing runs, and the store records
    the copy's text and path (before, it kept the first file's path beside the copy's text, so a report named a file
    whose text was not the store's)."""
    text = f'[experiment]\nname = "pair"\n{FIXED}\n{REST}'
    first = run_experiment(load_experiment(write_experiment(tmp_path, text, "pair.toml")), workers=0, progress=False)
    (tmp_path / "moved").mkdir()
    copy = write_experiment(tmp_path / "moved", "# the copy users keep\n" + text, "pair.toml")
    again = run_experiment(load_experiment(copy), workers=0, progress=False, store=first.store)
    assert again.nothing_to_run
    with open_store(first.store) as store:
        attrs = store.load().attrs
    assert attrs["experiment_text"] == copy.read_text()
    assert Path(attrs["experiment_file"]).resolve() == copy.resolve()
