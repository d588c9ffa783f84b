"""Experiment files (TOML): parsing and validation into a canonical definition.

An experiment file names a base scene, named variants of it, grid axes (gap,
μ, variants), the ground motions (records and synthetic ensembles), the
outputs to keep and the solver settings (docs/experiments.md, field by
field). :func:`parse_experiment` checks every field and returns the
*canonical definition*: a JSON-able dict with every default filled in and the
base scene inlined. Its sha256, without the hazard that no run depends on
(``stochpound.store.definition_sha256``), identifies the experiment: a store
made from a different definition is refused. :class:`stochpound.store.ExperimentGrid`
is built from it.

Errors raise :class:`ExperimentError` whose message starts with the field's
path, e.g. ``grid.mu[2]: must be >= 0 or inf, got -0.1``.
"""

from __future__ import annotations

import copy
import hashlib
import math
import re
import tomllib
from pathlib import Path
from typing import Any, Mapping

from stochpound._errors import ExperimentError, SceneError, field_errors
from stochpound._studies import parse_reproduces
from stochpound._text_files import read_text_file
from stochpound.experiment._design_table import parse_design
from stochpound.experiment._limit_states_table import parse_limit_states
from stochpound.hazard import parse_hazard
from stochpound.motions import SYNTHETIC_TYPES
from stochpound.experiment._intensity import parse_intensity
from stochpound.experiment._site import site_entry
from stochpound.model import fields as toml_fields
from stochpound.model.contact import ELEMENT_KEYS
from stochpound.store import apply_overrides, building_names
from stochpound.model.scene_file import bundled_scene_path, bundled_scenes, generator_fields, read_scene_table
from stochpound.solvers.simulate import METHODS
from stochpound.solvers.ivp import INTEGRATORS
from stochpound.store import TIME_HISTORIES, Definition, GapAxis, MotionSource, MuAxis, Output, Solver, VariantAxis, is_gap_axis, scene_g

#: Format version of the canonical definition (stored with every store).
FORMAT_VERSION = 1

_TOP_KEYS = {"experiment", "scene", "variants", "grid", "records", "motions", "synthetic", "output", "solver", "intensity", "hazard", "site", "design", "limit_states"}
_EXPERIMENT_KEYS = {"name", "description", "scene", "studied", "reproduces"}
_BUILDING_OVERRIDES = {"mass_factor", "mass", "stiffness", "damping", "damping_ratio", "base", "initial", "yield_force", "hardening"}
_SCENE_OVERRIDES = {"study_compat", "wall"}
SCENE_SOURCES = ("file", "bundled")
"""The ``[scene]`` keys that take the base scene from a scene file (at most one; beside it only ``[scene.building.<name>]`` edits)."""
AUTO = "auto"
"""``solver.method`` default: each case's solver chosen by :func:`stochpound.simulate` (exact unless a law is nonlinear)."""
_RECORD_KEYS = {"name", "record", "scale", "dt", "duration", "units", "interpolation"}
_SUITE_KEYS = {"name", "suite", "scale", "duration", "interpolation"}
MAX_REALIZATIONS = 10**8
"""Largest ``count`` of a synthetic ensemble: the run's client holds a few hundred bytes per case
(a larger count is refused before anything is allocated; runs above
:data:`~stochpound.experiment._estimate.LARGE_RUN_CASES` cases ask for ``--yes``)."""
_ANALYTIC_TYPES = ("harmonic", "constant")
_DIM_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
_RESERVED_DIMS = {
    "mu", "record", "realization", "time", "building", "floor", "contact", "impact", "intensity", "spectrum_period",
    # suffixes of the impact table's columns (impact_<dim> labels the table)
    "start", "end", "duration", "peak_force", "peak_time", "impulse", "onset_velocity", "in_phase", "complete", "case_id",
}

#: Time-history variables of a result that an experiment can keep (declared in ``stochpound.store._catalogue``).
TIME_HISTORY_VARIABLES = tuple(TIME_HISTORIES)


def load_definition(path: str | Path) -> tuple[dict[str, Any], str]:
    """Read an experiment file and return its canonical definition and its text.

    Parameters
    ----------
    path : str or Path
        The TOML experiment file. A base scene given as a path is resolved
        against the file's folder, and so are record files.

    Raises
    ------
    ExperimentError
        If the file is missing, not UTF-8 text, not TOML, or any field is invalid.
    """
    path = Path(path)
    try:
        text = read_text_file(path, ExperimentError)
    except (FileNotFoundError, IsADirectoryError):
        raise ExperimentError(f"{path}: experiment file not found") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise ExperimentError(f"{path}: not valid TOML: {error}") from None
    return parse_experiment(data, base_dir=path.parent, default_name=path.stem), text


def parse_experiment(data: Mapping[str, Any], base_dir: str | Path = ".", default_name: str = "experiment") -> dict[str, Any]:
    """Validate a parsed experiment file and return its canonical definition.

    Parameters
    ----------
    data : mapping
        The parsed TOML.
    base_dir : str or Path
        Folder of the experiment file (for a scene path and record files).
    default_name : str
        Name when ``experiment.name`` is not given.

    Returns
    -------
    dict
        Canonical definition: ``format``, ``name``, ``description``,
        ``scene`` (the base scene's dict, its ``[motion]`` included when it has one),
        ``studied``, ``variants``, ``gaps``, ``mu``, ``motions``, ``output``, ``solver``;
        ``intensity``, ``hazard``, ``design`` and ``site`` only when the file has those tables;
        ``reproduces`` only when the file declares it; ``scene_source`` only when
        the base scene comes from a file (``file`` as given, or ``bundled``, and the file's
        ``sha256``: not part of the identity, ``scene`` holds the content).
    """
    base_dir = Path(base_dir)
    with field_errors():
        toml_fields.reject_unknown(data, _TOP_KEYS, "")
        header = toml_fields.table(data, "experiment", "") or {}
        toml_fields.reject_unknown(header, _EXPERIMENT_KEYS, "experiment")
        name = toml_fields.string(header, "name", "experiment", default=default_name)
        description = header.get("description", "")
        if not isinstance(description, str):
            raise ExperimentError(f"experiment.description: must be a string, got {description!r}")
        reproduces = header.get("reproduces")
        if reproduces is not None:
            try:
                parse_reproduces(reproduces)
            except ValueError as error:
                raise ExperimentError(f"experiment.reproduces: {error} (a published study's part, \"<study>:<part>\")") from None
    scene, scene_source = _base_scene(data, header, base_dir)
    buildings = building_names(scene)
    contacts = scene.get("contact", [])
    studied = header.get("studied", buildings[0] if buildings else "B1")
    if studied not in buildings:
        raise ExperimentError(f"experiment.studied: must be one of the scene's buildings ({', '.join(buildings)}), got {studied!r}")
    declared = _variants(data, buildings, len(contacts))
    grid = _table_or_error(data, "grid", "")
    for key in grid:
        if not (is_gap_axis(key) or key == "mu" or key in declared):
            allowed = ["gap", "gap_<name>", "mu", *sorted(declared)]
            raise ExperimentError(f"grid.{key}: unknown axis (allowed: {', '.join(allowed)}; variant axes are declared in [variants.<axis>])")
    variants = [VariantAxis(name, tuple(_variant_selection(grid, name, list(overrides))), overrides) for name, overrides in declared.items()]
    n_contacts = len(contacts)
    contact_floors = [c.get("between", [[None, None]])[0][1] for c in contacts]
    n_walls = len(scene.get("wall", []))
    gaps = [_gap_axis(key, grid[key], n_contacts, contact_floors, n_walls) for key in grid if is_gap_axis(key)]
    mu = _mu_axis(grid["mu"], buildings) if "mu" in grid else None
    with field_errors():
        intensity = parse_intensity(data, scene, variants, gaps, mu, base_dir)
        hazard = parse_hazard(data, intensity, base_dir, scene_g(scene))
        design = parse_design(data)
        limit_states = parse_limit_states(data, buildings)
    motions = _motions(data, scene, base_dir)
    output, solver = _output(data, buildings), _solver(data)
    with field_errors():
        site = site_entry(data.get("site"), intensity)
    # optional records left None are absent from the written definition: the definitions (and hashes) of other files are unchanged
    definition = Definition(name, description, scene, studied, tuple(variants), tuple(gaps), mu, motions, output, solver, intensity, FORMAT_VERSION,
                            reproduces=reproduces, hazard=hazard, design=design, limit_states=limit_states, scene_source=scene_source, site=site)
    return definition.to_dict()


def _table_or_error(data: Mapping[str, Any], key: str, prefix: str) -> dict[str, Any]:
    with field_errors():
        return dict(toml_fields.table(data, key, prefix) or {})


def _base_scene(data: Mapping[str, Any], header: Mapping[str, Any], base_dir: Path) -> tuple[dict[str, Any], dict[str, str] | None]:
    """The base scene's dict (a file's content, its building edits applied) and its source's provenance (None: inline)."""
    inline = data.get("scene")
    path = header.get("scene")
    if inline is not None and path is not None:
        raise ExperimentError("experiment.scene: give either a scene path here or an inline [scene] table, not both")
    if inline is None and path is None:
        raise ExperimentError("scene: missing (an inline [scene] table, [scene] file = \"path/to/scene.toml\", or [scene] bundled = \"<name>\")")
    if path is not None:
        return _scene_from_file(path, base_dir, "experiment.scene", "file")
    if not isinstance(inline, dict):
        raise ExperimentError(f"scene: must be a table (the scene, as in a scene file), got {type(inline).__name__}")
    given = [key for key in SCENE_SOURCES if key in inline]
    if not given:
        return copy.deepcopy(inline), None
    if len(given) > 1:
        raise ExperimentError(f"scene.{given[1]}: give one of scene.file and scene.bundled, not both")
    key = given[0]
    others = sorted(set(inline) - {key, "building"})
    if others or ("building" in inline and not isinstance(inline["building"], dict)):
        field = others[0] if others else "building"
        raise ExperimentError(f"scene.{field}: not allowed beside scene.{key} (the scene is the file's; edit its buildings in [scene.building.<name>] tables)")
    scene, source = _scene_from_file(inline[key], base_dir, f"scene.{key}", key)
    edits = inline.get("building")
    if edits:
        edit = _override({"building": edits}, "scene", building_names(scene), len(scene.get("contact", [])))
        scene = apply_overrides(scene, [edit])
    return scene, source


def _scene_from_file(name: Any, base_dir: Path, field: str, kind: str) -> tuple[dict[str, Any], dict[str, str]]:
    """A scene file's dict (``kind`` ``file``: relative to ``base_dir``; ``bundled``: a bundled scene's name) and its provenance."""
    if not isinstance(name, str) or not name:
        what = "a path to a scene file (relative to the experiment file)" if kind == "file" else f"a bundled scene's name ({', '.join(bundled_scenes())})"
        raise ExperimentError(f"{field}: must be {what}, got {name!r}")
    try:
        path = base_dir / name if kind == "file" else bundled_scene_path(name)
        scene = read_scene_table(path)
    except SceneError as error:
        raise ExperimentError(f"{field}: {error}") from None
    return scene, {kind: name, "sha256": hashlib.sha256(path.read_bytes()).hexdigest()}


# ---------------------------------------------------------------- variants


def _variants(data: Mapping[str, Any], buildings: list[str], n_contacts: int) -> dict[str, dict[str, dict[str, Any]]]:
    """The declared variant axes: each axis's variants' overrides, by name."""
    table = _table_or_error(data, "variants", "")
    axes = {}
    for axis, values in table.items():
        where = f"variants.{axis}"
        _check_dim_name(axis, where)
        if not isinstance(values, dict) or not values:
            raise ExperimentError(f"{where}: must be a table of named variants, e.g. [{where}.stiff] (at least one)")
        overrides = {}
        for value, override in values.items():
            overrides[value] = _override(override, f"{where}.{value}", buildings, n_contacts)
        axes[axis] = overrides
    return axes


def _check_dim_name(name: str, where: str) -> None:
    if not _DIM_NAME.match(name) or name in _RESERVED_DIMS or is_gap_axis(name):
        raise ExperimentError(
            f"{where}: axis name must be a letter followed by letters, digits or _, and none of "
            f"{', '.join(sorted(_RESERVED_DIMS))}, gap, gap_*; got {name!r}"
        )


def _contact_override(part: Any, where: str, n_contacts: int) -> None:
    """A variant's ``contact``: one table of impact-element fields for every contact, or one table per contact."""
    if part is None:
        return
    tables = part if isinstance(part, list) else [part]
    if not all(isinstance(t, dict) for t in tables) or not tables:
        raise ExperimentError(f"{where}: must be a table of contact fields ({', '.join(sorted(ELEMENT_KEYS))}) or a list of one table per contact")
    if isinstance(part, list) and len(part) != n_contacts:
        raise ExperimentError(f"{where}: a list must have one table per contact of the scene ({n_contacts}), got {len(part)}")
    for i, table in enumerate(tables):
        with field_errors():
            toml_fields.reject_unknown(table, ELEMENT_KEYS, f"{where}[{i}]" if isinstance(part, list) else where)


def _override(override: Any, where: str, buildings: list[str], n_contacts: int) -> dict[str, Any]:
    if not isinstance(override, dict):
        raise ExperimentError(f"{where}: must be a table (with building.<name> and/or scene tables)")
    with field_errors():
        toml_fields.reject_unknown(override, {"building", "scene", "contact"}, where)
    scene_part = override.get("scene", {})
    if not isinstance(scene_part, dict):
        raise ExperimentError(f"{where}.scene: must be a table")
    with field_errors():
        toml_fields.reject_unknown(scene_part, _SCENE_OVERRIDES, f"{where}.scene")
    _contact_override(override.get("contact"), f"{where}.contact", n_contacts)
    building_part = override.get("building", {})
    if not isinstance(building_part, dict):
        raise ExperimentError(f"{where}.building: must be a table of buildings by name, e.g. [{where}.building.B2]")
    for name, fields in building_part.items():
        prefix = f"{where}.building.{name}"
        if name not in buildings:
            raise ExperimentError(f"{prefix}: unknown building (buildings: {', '.join(buildings)})")
        if not isinstance(fields, dict):
            raise ExperimentError(f"{prefix}: must be a table of building fields")
        with field_errors():
            toml_fields.reject_unknown(fields, _BUILDING_OVERRIDES, prefix)
            if "mass_factor" in fields:
                toml_fields.number(fields, "mass_factor", prefix, low=0.0, low_open=True)
        base = fields.get("base")
        if base is not None and base is not False and not isinstance(base, dict):
            raise ExperimentError(f"{prefix}.base: must be a table (merged into the base) or false (a fixed base), got {base!r}")
    return copy.deepcopy(dict(override))


def _variant_selection(grid: Mapping[str, Any], name: str, declared: list[str]) -> list[str]:
    if name not in grid:
        return list(declared)
    chosen = grid[name]
    where = f"grid.{name}"
    if not isinstance(chosen, list) or not chosen:
        raise ExperimentError(f"{where}: must be a non-empty list of variant names ({', '.join(declared)})")
    for i, value in enumerate(chosen):
        if value not in declared:
            raise ExperimentError(f"{where}[{i}]: unknown variant {value!r} (declared: {', '.join(declared)})")
    _check_unique(chosen, where)
    return list(chosen)


def _check_unique(values: list[Any], where: str) -> None:
    for i, value in enumerate(values):
        if values.index(value) != i:
            raise ExperimentError(f"{where}[{i}]: repeated value {value!r}")


# ---------------------------------------------------------------- axes


def _axis_values(spec: Any, where: str, allowed: set[str]) -> tuple[list[Any], dict[str, Any]]:
    """An axis is a list of values, or a table with ``values`` and options."""
    if isinstance(spec, list):
        return spec, {}
    if isinstance(spec, dict):
        with field_errors():
            toml_fields.reject_unknown(spec, {"values", *allowed}, where)
        if "values" not in spec:
            raise ExperimentError(f"{where}.values: missing (a non-empty list)")
        return spec["values"], spec
    raise ExperimentError(f"{where}: must be a list of values or a table with values = [...], got {spec!r}")


def _numbers(values: Any, where: str, allow_inf: bool, inf_meaning: str = "a fixed base") -> list[float]:
    if not isinstance(values, list) or not values:
        raise ExperimentError(f"{where}: must be a non-empty list (an empty axis makes an empty grid)")
    numbers = []
    for i, value in enumerate(values):
        item = f"{where}[{i}]"
        if allow_inf and isinstance(value, str) and value.lower() in ("inf", "infinity"):
            value = math.inf
        if not toml_fields.is_number(value) or math.isnan(value) or (math.isinf(value) and not (allow_inf and value > 0)):
            allowed = f"a number >= 0 or inf ({inf_meaning})" if allow_inf else "a finite number >= 0"
            raise ExperimentError(f"{item}: must be {allowed}, got {value!r}")
        if value < 0:
            raise ExperimentError(f"{item}: must be >= 0{' or inf' if allow_inf else ''}, got {value!r}")
        numbers.append(float(value))
    _check_unique(numbers, where)
    return numbers


def _gap_axis(key: str, spec: Any, n_contacts: int, contact_floors: list[Any], n_walls: int) -> GapAxis:
    """A gap axis: its contacts (every contact, or ``contacts`` / ``floors``) and, with ``walls``, the scene's walls it sets."""
    where = f"grid.{key}"
    values, options = _axis_values(spec, where, {"contacts", "floors", "walls"})
    gaps = _numbers(values, f"{where}.values" if options else where, allow_inf=True, inf_meaning="contact-free: the peak closure answers every gap")
    walls = _indices(options, "walls", where, n_walls, "wall") if "walls" in options else None
    if n_contacts == 0 and walls is None:
        raise ExperimentError(f"{where}: the scene has no [[contact]] whose gap could vary (give walls = [...] to vary the gap of walls)")
    contacts = list(range(n_contacts)) if walls is None else []  # with walls only: the contacts keep their gaps
    if "contacts" in options and "floors" in options:
        raise ExperimentError(f"{where}: give contacts or floors, not both")
    if "contacts" in options:
        contacts = _indices(options, "contacts", where, n_contacts, "contact")
    if "floors" in options:
        floors = options["floors"]
        if not isinstance(floors, list) or not floors:
            raise ExperimentError(f"{where}.floors: must be a non-empty list of floor levels, got {floors!r}")
        contacts = [i for i, floor in enumerate(contact_floors) if floor in floors]
        if not contacts:
            raise ExperimentError(f"{where}.floors: no contact has its left floor in {floors!r} (contact floors: {contact_floors})")
    return GapAxis(key, tuple(gaps), tuple(sorted(set(contacts))), tuple(walls or ()))


def _indices(options: Mapping[str, Any], key: str, where: str, count: int, what: str) -> list[int]:
    """``options[key]``: a non-empty list of indices in 0..count-1, sorted and without repeats."""
    chosen = options[key]
    if count == 0:
        raise ExperimentError(f"{where}.{key}: the base scene has no {what}")
    if not isinstance(chosen, list) or not chosen or not all(isinstance(c, int) and not isinstance(c, bool) and 0 <= c < count for c in chosen):
        raise ExperimentError(f"{where}.{key}: must be a non-empty list of {what} indices in 0..{count - 1}, got {chosen!r}")
    return sorted(set(chosen))


def _mu_axis(spec: Any, buildings: list[str]) -> MuAxis:
    values, options = _axis_values(spec, "grid.mu", {"buildings"})
    mus = _numbers(values, "grid.mu.values" if options else "grid.mu", allow_inf=True)
    chosen = options.get("buildings")
    if chosen is not None:
        if not isinstance(chosen, list) or not chosen or not all(b in buildings for b in chosen):
            raise ExperimentError(f"grid.mu.buildings: must be a non-empty list of building names ({', '.join(buildings)}), got {chosen!r}")
        _check_unique(chosen, "grid.mu.buildings")
    return MuAxis(tuple(mus), tuple(chosen) if chosen is not None else None)


# ---------------------------------------------------------------- motions


def _motions(data: Mapping[str, Any], scene: Mapping[str, Any], base_dir: Path) -> tuple[MotionSource, ...]:
    records = _array_of_tables(data, "records")
    synthetic = _table_or_error(data, "synthetic", "")
    motions = [source for i, table in enumerate(records) for source in _record_sources(table, f"records[{i}]", base_dir)]
    motions += [_analytic_source(table, f"motions[{i}]") for i, table in enumerate(_array_of_tables(data, "motions"))]
    motions += [_synthetic_source(label, table, f"synthetic.{label}") for label, table in synthetic.items()]
    if not motions:
        table = scene.get("motion")
        if not isinstance(table, dict):
            raise ExperimentError("records: no motion (give [[records]], [[motions]], [synthetic.<name>], or a [motion] in the base scene)")
        kind = table.get("type", "record")
        if kind in SYNTHETIC_TYPES:
            entry = dict(table)
            realization = entry.pop("realization", 0)
            motions.append(MotionSource(kind, "synthetic", "scene.motion", entry, realization, 1))
        else:  # a record (or a harmonic or constant motion), read on the client and shipped
            motion = dict(table)
            label = kind
            if kind == "record":
                motion["file_sha256"] = _file_sha256(base_dir, table.get("record"))
                label = Path(str(table.get("record", kind))).stem
            motions.append(MotionSource(label, "record", "scene.motion", motion))
    labels = [m.label for m in motions]
    for i, label in enumerate(labels):
        if labels.index(label) != i:
            raise ExperimentError(f"records: motion label {label!r} is used twice (give each [[records]] a distinct name)")
    return tuple(motions)


def _array_of_tables(data: Mapping[str, Any], key: str) -> list[dict[str, Any]]:
    tables = data.get(key, [])
    if not isinstance(tables, list) or not all(isinstance(t, dict) for t in tables):
        what = "record = name or file" if key == "records" else "name, type = harmonic | constant and its parameters"
        raise ExperimentError(f"{key}: must be an array of tables ([[{key}]] with {what})")
    return tables


def _analytic_source(table: Mapping[str, Any], where: str) -> MotionSource:
    """A ``[[motions]]`` entry: a named analytic motion (a scene ``[motion]`` table of type harmonic or constant)."""
    with field_errors():
        label = toml_fields.string(table, "name", where)
    motion = {k: v for k, v in table.items() if k != "name"}
    kind = motion.get("type")
    if kind not in _ANALYTIC_TYPES:
        raise ExperimentError(f"{where}.type: must be one of {', '.join(_ANALYTIC_TYPES)} (records go in [[records]]), got {kind!r}")
    return MotionSource(label, "record", where, motion)


def _file_sha256(base_dir: Path, spec: Any) -> str | None:
    if not isinstance(spec, str):
        return None
    file = base_dir / spec
    return hashlib.sha256(file.read_bytes()).hexdigest() if file.is_file() else None


def _record_sources(table: Mapping[str, Any], where: str, base_dir: Path) -> list[MotionSource]:
    """A ``[[records]]`` entry: one record, or every motion of a suite (``suite = "fema_p695_far_field"`` or a folder)."""
    if "suite" not in table:
        return [_record_source(table, where, base_dir)]
    from stochpound.motions.records import SELECTIONS, SUITES, select_members

    with field_errors():
        toml_fields.reject_unknown(table, _SUITE_KEYS | set(SELECTIONS), where)
        suite = toml_fields.string(table, "suite", where)
        prefix = toml_fields.string(table, "name", where, default="")
    folder = base_dir / suite
    if suite not in SUITES and not folder.is_dir():
        raise ExperimentError(f"{where}.suite: unknown suite {suite!r} and no such folder (suites: {', '.join(SUITES)}, or a folder of .AT2/.txt files)")
    with field_errors(f"{where}."):
        members = select_members(suite if suite in SUITES else folder, **_suite_choice(table, where))
    sources = []
    for member in members:
        record = member if suite in SUITES else str(Path(member).relative_to(base_dir))
        label = member if suite in SUITES else Path(member).stem
        motion = {k: v for k, v in table.items() if k not in ("name", "suite", *SELECTIONS)}
        motion.update(type="record", record=record, file_sha256=_file_sha256(base_dir, record))
        sources.append(MotionSource(f"{prefix}/{label}" if prefix else label, "record", where, motion, suite=suite))
    return sources


def _suite_choice(table: Mapping[str, Any], where: str) -> dict[str, Any]:
    """The ``members``, ``event``, ``magnitude`` and ``distance`` choices of a suite entry (lists of names, closed ranges)."""
    choice: dict[str, Any] = {}
    for key in ("members", "event"):
        if key in table:
            value = table[key]
            if not isinstance(value, list) or not value or not all(isinstance(item, str) and item for item in value):
                example = '["01a", "03b"]' if key == "members" else '["Northridge", "Kobe"]'
                raise ExperimentError(f"{where}.{key}: must be a non-empty list of names, e.g. {key} = {example}; got {value!r}")
            choice[key] = value
    for key, unit in (("magnitude", ""), ("distance", " km")):
        if key in table:
            value = table[key]
            if (not isinstance(value, list) or len(value) != 2 or not all(toml_fields.is_number(v) for v in value)
                    or not value[0] <= value[1]):
                raise ExperimentError(f"{where}.{key}: must be a range [low, high]{unit} with low <= high, got {value!r}")
            choice[key] = (float(value[0]), float(value[1]))
    return choice


def _record_source(table: Mapping[str, Any], where: str, base_dir: Path) -> MotionSource:
    with field_errors():
        toml_fields.reject_unknown(table, _RECORD_KEYS, where)
        record = toml_fields.string(table, "record", where)
        label = toml_fields.string(table, "name", where, default=Path(record).stem if (base_dir / record).is_file() else record)
    motion = {k: v for k, v in table.items() if k != "name"}
    motion["type"] = "record"
    motion["file_sha256"] = _file_sha256(base_dir, record)
    return MotionSource(label, "record", where, motion)


def _synthetic_source(label: str, table: Any, where: str) -> MotionSource:
    if not isinstance(table, dict):
        raise ExperimentError(f"{where}: must be a table (type, count, seed and the generator's parameters)")
    entry = dict(table)
    kind = entry.get("type", "kanai_tajimi")
    if kind not in SYNTHETIC_TYPES:
        raise ExperimentError(f"{where}.type: must be one of {', '.join(SYNTHETIC_TYPES)}, got {kind!r}")
    entry["type"] = kind
    from stochpound import motions

    if "realization" in entry:
        raise ExperimentError(f"{where}.realization: not used here (realizations start .. start + count - 1 are run)")
    with field_errors():  # before the checks below: a misspelt count is an unknown field, not a missing count
        toml_fields.reject_unknown(entry, generator_fields(getattr(motions, kind)) | {"count", "start"}, where)
    counts = {}
    for key, low, high in (("count", 1, MAX_REALIZATIONS), ("start", 0, None)):
        value = entry.pop(key, None if key == "count" else 0)
        if value is None:
            raise ExperimentError(f"{where}.count: missing (the number of realizations, an integer in [1, {MAX_REALIZATIONS}])")
        if not isinstance(value, int) or isinstance(value, bool) or value < low or (high is not None and value > high):
            allowed = f">= {low}" if high is None else f"in [{low}, {high}]"
            raise ExperimentError(f"{where}.{key}: must be an integer {allowed}, got {value!r}")
        counts[key] = value
    if "seed" not in entry:
        raise ExperimentError(f"{where}.seed: missing (an integer >= 0; realization i depends on (seed, i) only)")
    return MotionSource(label, "synthetic", where, entry, counts["start"], counts["count"])


# ---------------------------------------------------------------- output and solver


def _output(data: Mapping[str, Any], buildings: list[str]) -> Output:
    table = _table_or_error(data, "output", "")
    with field_errors():
        toml_fields.reject_unknown(table, {"time_histories", "buildings", "impacts", "demands"}, "output")
    histories = table.get("time_histories", [])
    if not isinstance(histories, list):
        raise ExperimentError(f"output.time_histories: must be a list of variable names, got {histories!r}")
    for i, name in enumerate(histories):
        if name not in TIME_HISTORY_VARIABLES:
            raise ExperimentError(f"output.time_histories[{i}]: unknown variable {name!r} (allowed: {', '.join(TIME_HISTORY_VARIABLES)})")
    _check_unique(histories, "output.time_histories")
    chosen = table.get("buildings", buildings)
    if not isinstance(chosen, list) or not chosen or not all(b in buildings for b in chosen):
        raise ExperimentError(f"output.buildings: must be a non-empty list of building names ({', '.join(buildings)}), got {chosen!r}")
    _check_unique(chosen, "output.buildings")
    with field_errors():
        impacts = toml_fields.boolean(table, "impacts", "output", default=True)
        demands = toml_fields.boolean(table, "demands", "output", default=False)
    return Output(tuple(histories), tuple(b for b in buildings if b in chosen), impacts, demands)


def _solver(data: Mapping[str, Any]) -> Solver:
    table = _table_or_error(data, "solver", "")
    with field_errors():
        toml_fields.reject_unknown(table, {"method", "integrator", "rtol", "atol"}, "solver")
        method = toml_fields.string(table, "method", "solver", default=AUTO)
        integrator = toml_fields.string(table, "integrator", "solver", default="DOP853")
        rtol = toml_fields.number(table, "rtol", "solver", default=1e-10, low=0.0, low_open=True)
        atol = toml_fields.number(table, "atol", "solver", default=1e-12, low=0.0, low_open=True)
    if method not in (AUTO, *METHODS):
        raise ExperimentError(f"solver.method: must be one of {AUTO}, {', '.join(METHODS)}, got {method!r}")
    if integrator not in INTEGRATORS:
        raise ExperimentError(f"solver.integrator: must be one of {', '.join(INTEGRATORS)}, got {integrator!r}")
    return Solver(method, integrator, rtol, atol)
