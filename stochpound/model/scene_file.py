"""Scene files (TOML, docs/scene-files.md): parsing and validation into a :class:`~stochpound.model.scene.Scene`.

Every field is checked before anything is computed. A bad field raises
:class:`~stochpound._errors.SceneError` whose message starts with the field's
path (0-based indices), e.g. ``building[0].base.mu: must be >= 0, got -0.2``.
"""

from __future__ import annotations

import inspect
import math
import tomllib
from pathlib import Path
from typing import Any

import numpy as np

from stochpound._data_files import bundled_data_dir
from stochpound._errors import RecordError, SceneError
from stochpound._memory import check_memory, sample_bytes
from stochpound._text_files import read_text_file
from stochpound.model.fields import REQUIRED, TomlTable, field_path
from stochpound.model.building import buildings_from_tables
from stochpound.model.contact import contacts_from_tables
from stochpound.model.scene import Scene
from stochpound.model.scene_tables import SceneEntry
from stochpound.model.wall import walls_from_tables
from stochpound.motions import DEFAULT_G, SYNTHETIC_TYPES
from stochpound.motions.ground import GroundMotion, HarmonicMotion, SampledMotion

_TOP_KEYS = {"g", "study_compat", "building", "contact", "wall", "motion"}
EARTH_GRAVITY = (9.7, 9.9)
"""The range of g at the Earth's surface, m/s²: a scene's ``g`` outside it is allowed, with a warning (:func:`~stochpound.model.scene_warnings`)."""


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file.

    Parameters
    ----------
    path : str or Path
        A TOML scene file (docs/scene-files.md). Relative record paths inside it are
        resolved against the file's folder.

    Returns
    -------
    Scene

    Raises
    ------
    SceneError
        If the file is not valid TOML or any field is missing, of the wrong
        type or out of range.
    """
    path = Path(path)
    return scene_from_dict(read_scene_table(path), base_dir=path.parent, source=path.name)


def read_scene_table(path: str | Path) -> SceneEntry:
    """The parsed TOML of a scene file, not yet validated (:func:`~stochpound.model.scene_file.scene_from_dict` validates it).

    Parameters
    ----------
    path : str or Path
        A TOML scene file (docs/scene-files.md).

    Returns
    -------
    dict
        The file's tables and fields as given (its ``[motion]`` included when it has one).

    Raises
    ------
    SceneError
        If the file is missing, not UTF-8 text or not valid TOML (the message starts with its path).
    """
    path = Path(path)
    try:
        return tomllib.loads(read_text_file(path, SceneError))
    except (FileNotFoundError, IsADirectoryError):
        raise SceneError(f"{path}: scene file not found") from None
    except tomllib.TOMLDecodeError as error:
        raise SceneError(f"{path}: not valid TOML: {error}") from None


def bundled_scenes() -> list[str]:
    """Names of the scenes shipped with stochpound (``data/scenes/<name>.toml``; provenance in ``data/scenes/SOURCES.md``)."""
    folder = bundled_data_dir("scenes", "SOURCES.md")
    return sorted(path.stem for path in folder.glob("*.toml")) if folder is not None else []


def bundled_scene_path(name: str) -> Path:
    """The file of the bundled scene ``name`` (an experiment's ``[scene] bundled = name``).

    Parameters
    ----------
    name : str
        One of :func:`~stochpound.model.bundled_scenes`, e.g. ``"elastic_pair"``.

    Returns
    -------
    Path
        The scene file (a scene file's buildings and contacts, without a ``[motion]``).

    Raises
    ------
    SceneError
        If no bundled scene has that name (the message lists them).
    """
    names = bundled_scenes()
    if name not in names:  # a name, never a path into the data folder
        raise SceneError(f"no bundled scene {name!r} (bundled: {', '.join(names) or 'none'})")
    return bundled_data_dir("scenes", "SOURCES.md") / f"{name}.toml"


def scene_from_dict(data: SceneEntry, base_dir: str | Path = ".", source: str = "python") -> Scene:
    """Validate a scene given as a dictionary (the parsed TOML) and build it.

    Parameters
    ----------
    data : mapping
        The scene, with the structure of a scene file.
    base_dir : str or Path
        Folder against which relative record paths are resolved.
    source : str
        Provenance label stored with the scene.
    """
    table = TomlTable(data, "", _TOP_KEYS)
    g = table.number("g", DEFAULT_G, low=0.0, low_open=True)
    study_compat = table.boolean("study_compat", False)
    buildings = buildings_from_tables(table.tables("building"))
    contacts = contacts_from_tables(table.tables("contact"), buildings)
    walls = walls_from_tables(table.tables("wall"), buildings)
    n_dof = sum(b.n_floors + (b.base is not None) for b in buildings)
    per_sample = sample_bytes(n_dof, len(buildings), max((b.n_floors for b in buildings), default=1), len(contacts) + len(walls))
    motion = _motion(table, Path(base_dir), g, per_sample)
    return Scene(tuple(buildings), tuple(contacts), motion, g=g, study_compat=study_compat, walls=tuple(walls), source=source)


def scene_warnings(scene: Scene, prefix: str = "") -> list[str]:
    """What a valid scene holds that looks like a slip, one line each starting with the field; empty when nothing does.

    A ``g`` outside :data:`~stochpound.model.scene_file.EARTH_GRAVITY` (``g = 1``, or g in ft/s²) is
    allowed (a model may want another gravity), and said here.

    Parameters
    ----------
    scene : Scene
        A scene (from :func:`~stochpound.load_scene` or :func:`~stochpound.scene_from_dict`).
    prefix : str
        The path of the scene's table, prefixed to the field (``"scene"`` in an experiment file).

    Returns
    -------
    list of str
        The warnings, e.g. ``g: 1 m/s² is outside 9.7-9.9 m/s², the Earth's gravity (g is in m/s²); used as given``.
    """
    low, high = EARTH_GRAVITY
    if low <= scene.g <= high:
        return []
    return [f"{field_path(prefix, 'g')}: {scene.g:g} m/s² is outside {low:g}-{high:g} m/s², the Earth's gravity (g is in m/s², "
            "e.g. 9.81); used as given"]


# ---------------------------------------------------------------- motion


_MOTION_KEYS = {
    "record": {"type", "record", "scale", "dt", "duration", "units", "interpolation"},
    "harmonic": {"type", "amplitude", "omega", "phase", "duration", "dt"},
    "constant": {"type", "acceleration", "duration", "dt"},
    "site_motions": {"type", "magnitude", "distance_km", "vs30", "mechanism", "n", "seed", "dt", "model", "calibration", "realization", "scale",
                     "normal_shift", "rupture", "distance_jb_km", "distance_x_km", "ztor_km", "dip", "z1p0_km", "z2p5_km"},
}


def _motion(scene: TomlTable, base_dir: Path, g: float, per_sample: int) -> GroundMotion:
    """The scene's ground motion; a run needing more than the memory limit (``per_sample`` bytes a sample) is refused first."""
    table = scene.table("motion")
    if table is None:
        raise SceneError(f"motion: missing ([motion] with a record, or type = harmonic | constant | {' | '.join(SYNTHETIC_TYPES)})")
    kind = table.string("type", "record")
    if kind in SYNTHETIC_TYPES:
        return _synthetic_motion(table, kind, per_sample)
    if kind not in _MOTION_KEYS:
        raise SceneError(f"motion.type: must be one of record, harmonic, constant, site_motions, {', '.join(SYNTHETIC_TYPES)}; got {kind!r}")
    table.reject_unknown(_MOTION_KEYS[kind])
    if kind == "harmonic":
        return _harmonic_motion(table, per_sample)
    if kind == "constant":
        return _constant_motion(table, per_sample)
    if kind == "site_motions":
        return _site_motion(table, per_sample)
    return _record_motion(table, base_dir, g, per_sample)


def _timing(table: TomlTable, required: bool, per_sample: int) -> tuple[float | None, float | None]:
    duration = table.number("duration", REQUIRED if required else None, low=0.0, low_open=True)
    dt = table.number("dt", REQUIRED if required else None, low=0.0, low_open=True)
    if duration is not None and dt is not None and dt > duration:
        raise SceneError(f"motion.dt: must be <= motion.duration ({duration:g} s), got {dt:g}")
    if required:  # a record's own length bounds its samples: checked once read
        n_samples = duration / dt + 1
        check_memory(n_samples * per_sample, f"motion: duration {duration:g} s at dt {dt:g} s is {n_samples:.3g} samples; a run")
    return duration, dt


def _harmonic_motion(table: TomlTable, per_sample: int) -> HarmonicMotion:
    amplitude = table.number("amplitude")
    omega = table.number("omega", low=0.0)
    phase = table.number("phase", 0.0)
    duration, dt = _timing(table, required=True, per_sample=per_sample)
    return HarmonicMotion(amplitude, omega, duration, dt, phase)


def _constant_motion(table: TomlTable, per_sample: int) -> SampledMotion:
    acceleration = table.number("acceleration")
    duration, dt = _timing(table, required=True, per_sample=per_sample)
    n_samples = int(round(duration / dt)) + 1
    return SampledMotion(dt, np.full(n_samples, acceleration), description=f"constant {acceleration:g} m/s²")


def _site_motion(table: TomlTable, per_sample: int) -> SampledMotion:
    """Motion ``realization`` of :func:`~stochpound.motions.site_motions` (``n`` motions of a scenario from ``seed``), times ``scale``.

    ``calibration``, when given, must name the model's calibration
    (:func:`~stochpound.motions.site_model_provenance`): a table written with
    another calibration cannot regenerate its motion. A rupture's geometry
    (:data:`~stochpound.motions.GEOMETRY_FIELDS`), when given, is the
    scenario's; ``rupture`` names the rupture (provenance only); ``normal_shift``, when given, the shift of its parameter
    normals (a motion of a tilted pool, :func:`~stochpound.motions.site_motions`).
    """
    from stochpound._errors import SiteError
    from stochpound.motions import GEOMETRY_FIELDS, Scenario, site_motions, stated_calibration

    model = table.string("model", "hazard_compatible")
    realization = table.raw("realization", 0)
    scale = table.number("scale", 1.0)
    missing = [key for key in ("magnitude", "distance_km", "vs30", "mechanism", "n", "seed") if key not in table]
    if missing:
        raise SceneError(f"motion.{missing[0]}: required for type = 'site_motions' (see docs/motions.md)")
    n = table.raw("n")
    if isinstance(realization, bool) or not isinstance(realization, int) or not (0 <= realization < n if isinstance(n, int) else realization >= 0):
        raise SceneError(f"motion.realization: must be an integer within 0 and n - 1 = {n!r} - 1, got {realization!r}")
    try:
        stated_calibration(model, table.raw("calibration", None))
        table.string("rupture", "")
        scenario = Scenario(**{key: table.raw(key) for key in ("magnitude", "distance_km", "vs30", "mechanism", *GEOMETRY_FIELDS) if key in table})
        generated = site_motions(scenario=scenario, n=n, seed=table.raw("seed"), dt=table.raw("dt", 0.01), model=model,
                                 realizations=[realization], normal_shift=table.raw("normal_shift", None))
    except SiteError as error:
        raise SceneError(f"motion.{error}") from None
    values = np.asarray(generated["acceleration"].values[0], dtype=float)
    check_memory(len(values) * per_sample, f"motion: {len(values)} samples; a run")
    if scale != 1.0:
        values = values * scale
    description = f"site_motions realization {realization} of {n} (seed {table.raw('seed')}, {model})" + (f" x {scale:.9g}" if scale != 1.0 else "")
    return SampledMotion(float(generated.attrs["dt"]), values, "linear", description)


def _record_motion(table: TomlTable, base_dir: Path, g: float, per_sample: int) -> SampledMotion:
    from stochpound.motions.records import load_record, normalize_units

    spec = table.string("record")
    scale = table.number("scale", 1.0)
    duration, dt = _timing(table, required=False, per_sample=per_sample)
    units = table.string("units", None)
    try:
        units = None if units is None else normalize_units(units)
    except ValueError as error:
        raise SceneError(f"motion.{error}") from None
    interpolation = table.string("interpolation", "linear")
    if interpolation not in ("linear", "spline"):
        raise SceneError(f"motion.interpolation: must be 'linear' or 'spline', got {interpolation!r}")
    candidate = base_dir / spec
    try:
        record = load_record(str(candidate) if candidate.exists() else spec, dt=dt, units=units)
    except RecordError as error:
        raise SceneError(f"motion.record: {error}") from None
    values = np.asarray(record.acceleration(g=g), dtype=float) * scale
    if duration is not None:
        n_keep = int(math.floor(duration / record.dt + 1e-9)) + 1
        values = values[:n_keep]
    if len(values) < 2:
        raise SceneError(f"motion.record: {spec!r} has {len(values)} sample(s) in the requested duration; at least 2 are needed")
    check_memory(len(values) * per_sample, f"motion.record: {len(values)} samples; a run")
    description = f"{record.name} x {scale:g}" + (f", first {duration:g} s" if duration is not None else "")
    return SampledMotion(record.dt, values, interpolation, description)


def generator_fields(generator: Any) -> set[str]:
    """The fields of a synthetic motion table other than ``realization``: the generator's own parameters, ``type`` and ``interpolation``."""
    return {name for name in inspect.signature(generator).parameters if name not in ("n_realizations", "start")} | {"type", "interpolation"}


def _check_generator_fields(table: TomlTable, generator: Any, kind: str) -> None:
    """Reject fields the generator does not take, and name the required ones that are missing."""
    signature = inspect.signature(generator).parameters
    own = {name for name in signature if name not in ("n_realizations", "start")}
    table.reject_unknown(generator_fields(generator) | {"realization"})
    for name, parameter in signature.items():
        if name in own and parameter.default is inspect.Parameter.empty and name not in table:
            raise SceneError(f"motion.{name}: required for type = {kind!r} (see docs/motions.md)")


def _synthetic_motion(table: TomlTable, kind: str, per_sample: int) -> SampledMotion:
    """One realization of a synthetic ensemble, fixed by (seed, realization) alone."""
    from stochpound import motions

    generator = getattr(motions, kind)
    _check_generator_fields(table, generator, kind)
    parameters = {key: table.raw(key) for key in table if key not in ("type", "realization", "interpolation")}
    realization = table.raw("realization", 0)
    if not isinstance(realization, int) or isinstance(realization, bool) or realization < 0:
        raise SceneError(f"motion.realization: must be an integer >= 0, got {realization!r}")
    duration, dt = _timing(table, required=True, per_sample=per_sample)
    parameters.update(duration=duration, dt=dt)
    try:
        ensemble = generator(1, start=realization, **parameters)
    except (TypeError, ValueError) as error:
        raise SceneError(f"motion: {error}") from None
    description = f"{kind} realization {realization} (seed {table.raw('seed', 0)})"
    return SampledMotion(dt, np.asarray(ensemble.values[0], dtype=float), "linear", description)
