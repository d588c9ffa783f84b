"""A user's files are safe and named (issue 48): no command writes over an input or a file that is not its own,
every file read as text is refused in one line when it is not UTF-8 text, a hand-edited store is flagged,
and a walls-only store's records table has no phase columns."""

from __future__ import annotations

import codecs
import json
import re
import shutil

import h5py
import pytest
import xarray as xr

from stochpound.experiment import load_experiment, open_store
from stochpound.experiment._parts import parts_folder
from stochpound.experiment._session import NOT_A_STORE, clear_store
from stochpound.hazard import HazardCurve, read_hazard_file
from stochpound.model.scene_file import read_scene_table
from stochpound.report.render import Report
from stochpound.report.render.output import MANIFEST, check_output_folder, write_report
from stochpound.report.sections._generic import summary_table
from stochpound.store import definition_sha256
from tests.helpers import QUICKSTART, REPOSITORY, TINY_EXPERIMENT, invoke, run_in_process

RECORD = REPOSITORY / "data" / "records" / "RSN6_IMPVALL.I_I-ELC180.AT2"


def _one_line_error(result, *fragments: str) -> str:
    """The command failed with one line (click's ``Error: ...``) holding every fragment; that line."""
    assert result.exit_code == 1, result.output
    assert result.exception is None or isinstance(result.exception, SystemExit), repr(result.exception)
    assert "Traceback" not in result.output
    lines = [line for line in result.stderr.splitlines() if line.startswith("Error: ")]  # after a command's progress lines, if any
    assert len(lines) == 1 and result.stderr.strip().endswith(lines[0]), result.stderr
    for fragment in fragments:
        assert fragment in lines[0], lines[0]
    return lines[0]


def _scene_file_experiment(folder):
    """TINY_EXPERIMENT with its scene in ``pair.toml`` and its motion from the record file ``rec.AT2``: the experiment file's path."""
    text = TINY_EXPERIMENT
    scene = text[text.index("[scene]"):text.index("[variants")]
    (folder / "pair.toml").write_text(scene.replace("[scene]", "").replace("[[scene.", "[["))
    shutil.copy(RECORD, folder / "rec.AT2")
    experiment = text.replace(scene, '[scene]\nfile = "pair.toml"\n\n')
    experiment = experiment[:experiment.index("[[motions]]")] + '[[records]]\nrecord = "rec.AT2"\nduration = 1.0\n'
    path = folder / "small.toml"
    path.write_text(experiment)
    return path


# ---------------------------------------------------------------- item 1: --restart and other writes touch only their own files


@pytest.mark.parametrize("restart", [[], ["--restart"]])
@pytest.mark.parametrize("name, what", [("small.toml", "the experiment file"), ("pair.toml", "the experiment's scene file"),
                                        ("rec.AT2", "a record file of the experiment")])
def test_a_run_never_takes_one_of_its_inputs_for_its_store(tmp_path, name, what, restart):
    experiment = _scene_file_experiment(tmp_path)
    before = {path.name: path.read_bytes() for path in tmp_path.iterdir()}
    result = invoke("experiment", "run", str(experiment), "--store", str(tmp_path / name), "--workers", "0", *restart)
    line = _one_line_error(result, f"{tmp_path / name}: is {what}, an input of this command; --store must name another file")
    assert "use --restart" not in line
    assert {path.name: path.read_bytes() for path in tmp_path.iterdir()} == before, "nothing written, nothing lost"


@pytest.mark.parametrize("restart", [[], ["--restart"]])
def test_restart_discards_only_a_file_it_can_tell_is_a_store(tmp_path, restart):
    experiment = tmp_path / "tiny.toml"
    experiment.write_text(TINY_EXPERIMENT)
    notes = tmp_path / "notes.nc"
    notes.write_text("the user's notes")
    other = tmp_path / "other.nc"  # a netCDF file of another program: readable, but not a store
    xr.Dataset({"x": ("t", [1.0, 2.0])}).to_netcdf(other, engine="h5netcdf")
    for path, why in ((notes, "not a readable netCDF4/HDF5 file"), (other, "not a stochpound experiment store")):
        before = path.read_bytes()
        result = invoke("experiment", "run", str(experiment), "--store", str(path), "--workers", "0", *restart)
        line = _one_line_error(result, f"{path}: {why}", NOT_A_STORE)
        assert "use --restart" not in line
        assert path.read_bytes() == before and not parts_folder(path).exists()


def test_restart_keeps_what_a_user_put_in_the_parts_folder(tmp_path):
    store = tmp_path / "run.nc"
    folder = parts_folder(store)
    folder.mkdir()
    own = [folder / "experiment.json", folder / "runs.jsonl", folder / "part-1-0.npz", folder / ".part-1-1.npz.0a1b2c.tmp"]
    for path in [store, *own]:
        path.write_bytes(b"x")
    mine = folder / "notes.txt"
    mine.write_text("the user's")
    clear_store(store)
    assert not store.exists() and not any(path.exists() for path in own)
    assert mine.read_text() == "the user's"


def test_an_output_is_never_an_input_of_its_command(tmp_path):
    scene = tmp_path / "pair.toml"
    shutil.copy(REPOSITORY / "experiments" / "scenes" / "study_b1_isolated_flexible.toml", scene)
    before = scene.read_bytes()
    result = invoke("simulate", str(scene), "--out", str(scene), "--overwrite")
    assert result.exit_code == 2 and "is the scene file, an input of this command" in result.output
    record = tmp_path / "rec.AT2"
    shutil.copy(RECORD, record)
    for command in ("show", "spectrum"):
        result = invoke("records", command, str(record), "--plot", str(record))
        assert result.exit_code == 2 and "is the record file, an input of this command" in result.output
    assert scene.read_bytes() == before and record.read_bytes() == RECORD.read_bytes()


# ---------------------------------------------------------------- item 2: files that are not UTF-8 text, named in one line


def _not_text(folder):
    """Files that are not UTF-8 text, each with what the one-line error says of it."""
    files = {
        "store.toml": (b"\x89HDF\r\n\x1a\n" + bytes(64), "a netCDF4/HDF5 file (a store?), not a text file"),
        "utf16.toml": (codecs.BOM_UTF16_LE + "[experiment]\n".encode("utf-16-le"), "UTF-16 text; save it as UTF-8"),
        "image.toml": (b"\x00\x01\x02binary", "a binary file, not text"),
        "latin1.toml": ("# é\n".encode("latin-1"), "not UTF-8 text (byte 0xe9 at position 2)"),
    }
    for name, (data, _) in files.items():
        (folder / name).write_bytes(data)
    return {folder / name: message for name, (_, message) in files.items()}


def test_every_file_read_as_text_is_named_when_it_is_not_utf8_text(tmp_path):
    for path, message in _not_text(tmp_path).items():
        _one_line_error(invoke("experiment", "check", str(path)), f"{path}: {message}")
        _one_line_error(invoke("experiment", "run", str(path)), f"{path}: {message}")
        _one_line_error(invoke("simulate", str(path), "--out", str(tmp_path / "run.nc")), f"{path}: {message}")
        for read in (read_hazard_file, HazardCurve.from_file, read_scene_table):
            with pytest.raises(ValueError, match=re.escape(f"{path}: {message}")):
                read(path)


def test_a_byte_order_mark_is_not_an_error(tmp_path):
    scene = tmp_path / "pair.toml"
    scene.write_bytes(codecs.BOM_UTF8 + (REPOSITORY / "experiments" / "scenes" / "study_b1_isolated_flexible.toml").read_bytes())
    assert read_scene_table(scene)["building"]


def test_check_of_a_pool_too_small_for_its_motions_is_one_line(tmp_path):
    text = (REPOSITORY / "experiments" / "risk" / "fixed_pair.toml").read_text()
    records = '[[records]]\nsuite = "fema_p695_far_field"\nmembers = ["01a", "03b", "05a"]\n\n'
    text = text[:text.index("\n[[records]]") + 1] + records + text[text.index("\n[intensity]") + 1:]  # the tables, not the comments naming them
    path = tmp_path / "cs.toml"
    text = re.sub(r"(?m)^simulated_(motions|sampling) = .*\n", "", re.sub(r"(?m)^motions = \d+", "motions = 4", text))  # the three records only
    assert not re.search(r"(?m)^simulated_motions", text)
    path.write_text(text)
    _one_line_error(invoke("experiment", "check", str(path)), "intensity.motions: only", "fewer than motions = 4")


# ---------------------------------------------------------------- items 4 and 6 on a small walls-only store

_QUICKSTART = QUICKSTART.read_text()
_B1 = _QUICKSTART[_QUICKSTART.index("[[scene.building]]"):_QUICKSTART.index("[[scene.building]]", _QUICKSTART.index("name = \"B1\""))]
WALLS = f"""
[experiment]
name = "walls"
studied = "B1"

[scene]
g = 9.814

{_B1}
[[scene.wall]]
building = "B1"
side = "left"
level = 0
gap = 0.01
stiffness = 3283500000.0
restitution = 0.5

[grid]
gap_wall = {{ values = [0.005], walls = [0] }}
""" + TINY_EXPERIMENT[TINY_EXPERIMENT.index("[[motions]]"):TINY_EXPERIMENT.index("[solver]")] + "[output]\nimpacts = true\n"
"""B1 of the quick start on its sliding base beside a moat wall 5 mm away (no other building), pushed by the tiny experiment's harmonic motion."""


@pytest.fixture(scope="module")
def walls(tmp_path_factory):
    """A store of B1 on a sliding base beside a moat wall 5 mm away, pushed by a harmonic motion: the wall is hit."""
    return run_in_process(tmp_path_factory.mktemp("walls"), "walls", WALLS)


def test_a_walls_only_records_table_has_no_phase_columns(walls):
    with open_store(walls) as store:
        assert store.sizes["contact"] == 0 and float(store["impacts"].max()) > 0
        table = summary_table("walls", store.isel(realization=0))
    assert "impacts" in table.frame.columns and not {"in-phase", "out-of-phase"} & set(table.frame.columns)
    assert "Every impact is a wall hit, which has no phase" in table.note


def _edited(walls, tmp_path):
    """A copy of the store whose definition was changed by hand (its description), its recorded sha256 left as it was."""
    edited = tmp_path / "edited.nc"
    shutil.copy(walls, edited)
    with h5py.File(edited, "a") as handle:
        definition = json.loads(handle.attrs["definition"])
        recorded = handle.attrs["definition_sha256"]
        definition["description"] = "changed by hand"
        handle.attrs["definition"] = json.dumps(definition, sort_keys=True, separators=(",", ":"))
    assert definition_sha256(definition) != recorded
    return edited


def test_a_hand_edited_store_is_flagged_on_open_and_refused_by_report_build(walls, tmp_path):
    edited = _edited(walls, tmp_path)
    with pytest.warns(UserWarning, match=rf"{edited.name}: its definition does not match its recorded definition_sha256"):
        open_store(edited).close()
    with open_store(edited, edited="accept") as store:
        assert store.attrs["experiment_name"] == "walls"
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        open_store(walls).close()  # the store as written: no warning
    out = tmp_path / "report"
    _one_line_error(invoke("report", "build", str(edited), "--out", str(out)), f"{edited}: its definition does not match", "--accept-edited")
    assert not (out / "index.html").exists(), "refused before any work"


def test_a_report_keeps_a_user_s_file_in_out_and_never_writes_over_its_store(tmp_path):
    report = Report(title="t", subtitle="s", sources=[])
    out = tmp_path / "report"
    out.mkdir()
    (out / "index.html").write_text("the user's page")
    with pytest.raises(ValueError, match=re.escape(f"{out / 'index.html'}: exists, and {out} holds no earlier report")):
        write_report(report, out, ["html"])
    assert (out / "index.html").read_text() == "the user's page" and not (out / MANIFEST).exists()
    fresh = tmp_path / "fresh"
    write_report(report, fresh, ["html"])
    write_report(report, fresh, ["html"])  # its own earlier build: replaced
    assert (fresh / "index.html").is_file() and json.loads((fresh / MANIFEST).read_text()) == []
    store = tmp_path / "index.html"
    store.write_bytes(b"a store")
    with pytest.raises(ValueError, match="is a store of this report, an input of this command; --out must name another file"):
        check_output_folder(tmp_path, [store])


def test_an_experiment_file_given_as_a_store_is_named(walls, tmp_path):
    experiment = walls.with_suffix(".toml")
    assert load_experiment(experiment).name == "walls"
    _one_line_error(invoke("report", "build", str(experiment), "--out", str(tmp_path / "report")), f"{experiment}: not a readable netCDF4/HDF5 file")
    _one_line_error(invoke("experiment", "check", str(walls)), f"{walls}: a netCDF4/HDF5 file (a store?), not a text file")
