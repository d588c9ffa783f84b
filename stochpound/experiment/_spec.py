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

Each table is read with :class:`stochpound.store.TomlTable`, which declares
its fields and refuses unknown keys; errors raise :class:`ExperimentError`
whose message starts with the field's path, e.g.
``grid.mu[2]: must be >= 0 or inf, got -0.1``.
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
from stochpound.experiment._scenario_ensembles import scenario_source
from stochpound.experiment._intensity import parse_intensity
from stochpound.experiment._site import site_entry
from stochpound.experiment._reseed import reseeded_text
from stochpound.model.fields import is_number
from stochpound.model.contact import ELEMENT_KEYS
from stochpound.store import apply_overrides, building_names
from stochpound.model.scene_file import bundled_scene_path, bundled_scenes, generator_fields, read_scene_table
from stochpound.solvers.simulate import METHODS
from stochpound.solvers.ivp import INTEGRATORS
from stochpound.store import TIME_HISTORIES, Definition, GapAxis, MotionSource, MuAxis, Output, Solver, TomlTable, VariantAxis, is_gap_axis, scene_g

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


def load_definition(path: str | Path, seed: int | None = None) -> tuple[dict[str, Any], str]:
    """Read an experiment file and return its canonical definition and its text.

    Parameters
    ----------
    path : str or Path
        The TOML experiment file. A base scene given as a path is resolved
        against the file's folder, and so are record files.
    seed : int, optional
        Another ``[intensity] seed`` than the file's: the text returned is the file's with its seed line set to it
        (``stochpound.experiment._reseed``).

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
    if seed is not None:
        text = reseeded_text(text, seed, str(path))
        data = tomllib.loads(text)
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
    with field_errors():  # the tables' readers raise SceneError: named as the experiment's fields
        return _parsed_definition(TomlTable(data, "", _TOP_KEYS), Path(base_dir), default_name).to_dict()


def _parsed_definition(file: TomlTable, base_dir: Path, default_name: str) -> Definition:
    """The typed definition of a parsed experiment file (its top level, its keys checked)."""
    header = file.table_or_empty("experiment", _EXPERIMENT_KEYS)
    name = header.string("name", default_name)
    description = header.raw("description", "")
    if not isinstance(description, str):
        raise ExperimentError(f"experiment.description: must be a string, got {description!r}")
    reproduces = header.raw("reproduces")
    if reproduces is not None:
        try:
            parse_reproduces(reproduces)
        except ValueError as error:
            raise ExperimentError(f"experiment.reproduces: {error} (a published study's part, \"<study>:<part>\")") from None
    scene, scene_source = _base_scene(file, header, base_dir)
    buildings, scene_table = building_names(scene), TomlTable(scene, "scene")
    contacts = scene_table.tables("contact")
    studied = header.raw("studied", buildings[0] if buildings else "B1")
    if studied not in buildings:
        raise ExperimentError(f"experiment.studied: must be one of the scene's buildings ({', '.join(buildings)}), got {studied!r}")
    declared = _variants(file, buildings, len(contacts))
    grid = file.table_or_empty("grid")
    for key in grid:
        if not (is_gap_axis(key) or key == "mu" or key in declared):
            allowed = ["gap", "gap_<name>", "mu", *sorted(declared)]
            raise ExperimentError(f"grid.{key}: unknown axis (allowed: {', '.join(allowed)}; variant axes are declared in [variants.<axis>])")
    variants = [VariantAxis(name, tuple(_variant_selection(grid, name, list(overrides))), overrides) for name, overrides in declared.items()]
    n_contacts = len(contacts)
    contact_floors = [c.raw("between", [[None, None]])[0][1] for c in contacts]
    n_walls = len(scene_table.tables("wall"))
    gaps = [_gap_axis(key, grid.raw(key), n_contacts, contact_floors, n_walls) for key in grid if is_gap_axis(key)]
    mu = _mu_axis(grid.raw("mu"), buildings) if "mu" in grid else None
    intensity = parse_intensity(file, scene_table, variants, gaps, mu, base_dir)
    hazard = parse_hazard(file, intensity, base_dir, scene_g(scene))
    design = parse_design(file)
    limit_states = parse_limit_states(file, buildings)
    simulated_pool = intensity is not None and intensity.selection is not None and intensity.selection.simulated is not None
    motions = _motions(file, scene_table, base_dir, simulated_pool)
    output, solver = _output(file, buildings), _solver(file)
    site = site_entry(file.raw("site"), intensity)
    # optional records left None are absent from the written definition: the definitions (and hashes) of other files are unchanged
    return Definition(name, description, scene, studied, tuple(variants), tuple(gaps), mu, motions, output, solver, intensity, FORMAT_VERSION,
                      reproduces=reproduces, hazard=hazard, design=design, limit_states=limit_states, scene_source=scene_source, site=site)


def _base_scene(file: TomlTable, header: TomlTable, base_dir: Path) -> tuple[dict[str, Any], dict[str, str] | None]:
    """The base scene's dict (a file's content, its building edits applied) and its source's provenance (None: inline)."""
    inline = file.raw("scene")
    path = header.raw("scene")
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
    edits = inline["building"] if "building" in inline else None
    if edits:
        edit = _override({"building": edits}, "scene", building_names(scene), len(TomlTable(scene, "scene").tables("contact")))
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


def _variants(file: TomlTable, buildings: list[str], n_contacts: int) -> dict[str, dict[str, dict[str, Any]]]:
    """The declared variant axes: each axis's variants' overrides, by name."""
    table = file.table_or_empty("variants")
    axes = {}
    for axis in table:
        values, where = table.raw(axis), table.field(axis)
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
        TomlTable(table, f"{where}[{i}]" if isinstance(part, list) else where, ELEMENT_KEYS)


def _override(override: Any, where: str, buildings: list[str], n_contacts: int) -> dict[str, Any]:
    if not isinstance(override, dict):
        raise ExperimentError(f"{where}: must be a table (with building.<name> and/or scene tables)")
    table = TomlTable(override, where, {"building", "scene", "contact"})
    table.table("scene", _SCENE_OVERRIDES)
    _contact_override(table.raw("contact"), table.field("contact"), n_contacts)
    building_part = table.table_or_empty("building", hint=f"of buildings by name, e.g. [{where}.building.B2]")
    for name in building_part:
        prefix = building_part.field(name)
        if name not in buildings:
            raise ExperimentError(f"{prefix}: unknown building (buildings: {', '.join(buildings)})")
        fields = building_part.table(name, _BUILDING_OVERRIDES, hint="of building fields")
        fields.number("mass_factor", None, low=0.0, low_open=True)
        base = fields.raw("base")
        if base is not None and base is not False and not isinstance(base, dict):
            raise ExperimentError(f"{prefix}.base: must be a table (merged into the base) or false (a fixed base), got {base!r}")
    return copy.deepcopy(dict(override))


def _variant_selection(grid: TomlTable, name: str, declared: list[str]) -> list[str]:
    if name not in grid:
        return list(declared)
    chosen, where = grid.raw(name), grid.field(name)
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


def _axis_values(spec: Any, where: str, allowed: set[str]) -> tuple[Any, str, TomlTable]:
    """An axis is a list of values, or a table with ``values`` and options: its values, their field's name and its options."""
    if isinstance(spec, list):
        return spec, where, TomlTable({}, where)
    if isinstance(spec, dict):
        options = TomlTable(spec, where, {"values", *allowed})
        if "values" not in options:
            raise ExperimentError(f"{where}.values: missing (a non-empty list)")
        return options.raw("values"), options.field("values"), options
    raise ExperimentError(f"{where}: must be a list of values or a table with values = [...], got {spec!r}")


def _numbers(values: Any, where: str, allow_inf: bool, inf_meaning: str = "a fixed base") -> list[float]:
    if not isinstance(values, list) or not values:
        raise ExperimentError(f"{where}: must be a non-empty list (an empty axis makes an empty grid)")
    numbers = []
    for i, value in enumerate(values):
        item = f"{where}[{i}]"
        if allow_inf and isinstance(value, str) and value.lower() in ("inf", "infinity"):
            value = math.inf
        if not is_number(value) or math.isnan(value) or (math.isinf(value) and not (allow_inf and value > 0)):
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
    values, named, options = _axis_values(spec, where, {"contacts", "floors", "walls"})
    gaps = _numbers(values, named, allow_inf=True, inf_meaning="contact-free: the peak closure answers every gap")
    walls = _indices(options, "walls", n_walls, "wall") if "walls" in options else None
    if n_contacts == 0 and walls is None:
        raise ExperimentError(f"{where}: the scene has no [[contact]] whose gap could vary (give walls = [...] to vary the gap of walls)")
    contacts = list(range(n_contacts)) if walls is None else []  # with walls only: the contacts keep their gaps
    if "contacts" in options and "floors" in options:
        raise ExperimentError(f"{where}: give contacts or floors, not both")
    if "contacts" in options:
        contacts = _indices(options, "contacts", n_contacts, "contact")
    if "floors" in options:
        floors = options.raw("floors")
        if not isinstance(floors, list) or not floors:
            raise ExperimentError(f"{where}.floors: must be a non-empty list of floor levels, got {floors!r}")
        contacts = [i for i, floor in enumerate(contact_floors) if floor in floors]
        if not contacts:
            raise ExperimentError(f"{where}.floors: no contact has its left floor in {floors!r} (contact floors: {contact_floors})")
    return GapAxis(key, tuple(gaps), tuple(sorted(set(contacts))), tuple(walls or ()))


def _indices(options: TomlTable, key: str, count: int, what: str) -> list[int]:
    """The option ``key``: a non-empty list of indices in 0..count-1, sorted and without repeats."""
    chosen = options.raw(key)
    if count == 0:
        raise options.error(key, f"the base scene has no {what}")
    if not isinstance(chosen, list) or not chosen or not all(isinstance(c, int) and not isinstance(c, bool) and 0 <= c < count for c in chosen):
        raise options.error(key, f"must be a non-empty list of {what} indices in 0..{count - 1}, got {chosen!r}")
    return sorted(set(chosen))


def _mu_axis(spec: Any, buildings: list[str]) -> MuAxis:
    values, named, options = _axis_values(spec, "grid.mu", {"buildings"})
    mus = _numbers(values, named, allow_inf=True)
    chosen = options.raw("buildings")
    if chosen is not None:
        if not isinstance(chosen, list) or not chosen or not all(b in buildings for b in chosen):
            raise ExperimentError(f"grid.mu.buildings: must be a non-empty list of building names ({', '.join(buildings)}), got {chosen!r}")
        _check_unique(chosen, "grid.mu.buildings")
    return MuAxis(tuple(mus), tuple(chosen) if chosen is not None else None)


# ---------------------------------------------------------------- motions


def _motions(file: TomlTable, scene: TomlTable, base_dir: Path, simulated_pool: bool = False) -> tuple[MotionSource, ...]:
    """The motions the file lists; none needed where a selection's pool holds simulated motions (``simulated_pool``: ``[site] simulated_motions``)."""
    records = file.tables("records", hint="record = name or file")
    synthetic = file.table_or_empty("synthetic")
    motions = [source for table in records for source in _record_sources(table, base_dir)]
    motions += [_analytic_source(table) for table in file.tables("motions", hint="name, type = harmonic | constant and its parameters")]
    motions += [_synthetic_source(label, synthetic.raw(label), synthetic.field(label)) for label in synthetic]
    if not motions and not simulated_pool:
        motions.append(_scene_motion(scene, base_dir))
    labels = [m.label for m in motions]
    for i, label in enumerate(labels):
        if labels.index(label) != i:
            raise ExperimentError(f"records: motion label {label!r} is used twice (give each [[records]] a distinct name)")
    return tuple(motions)


def _scene_motion(scene: TomlTable, base_dir: Path) -> MotionSource:
    """The base scene's ``[motion]``, the experiment's one motion when the file gives none."""
    if not isinstance(scene.raw("motion"), dict):
        raise ExperimentError("records: no motion (give [[records]], [[motions]], [synthetic.<name>], or a [motion] in the base scene)")
    table = scene.table("motion")
    kind = table.raw("type", "record")
    if kind in SYNTHETIC_TYPES:
        entry = {key: value for key, value in table.values.items() if key != "realization"}
        return MotionSource(kind, "synthetic", table.name, entry, table.raw("realization", 0), 1)
    motion = dict(table.values)  # a record (or a harmonic or constant motion), read on the client and shipped
    if kind != "record":
        return MotionSource(kind, "record", table.name, motion)
    motion["file_sha256"] = _file_sha256(base_dir, table.raw("record"))
    return MotionSource(Path(str(table.raw("record", kind))).stem, "record", table.name, motion)


def _analytic_source(table: TomlTable) -> MotionSource:
    """A ``[[motions]]`` entry: a named analytic motion (a scene ``[motion]`` table of type harmonic or constant)."""
    label = table.string("name")
    table.string("type", choices=_ANALYTIC_TYPES, hint="records go in [[records]]")
    return MotionSource(label, "record", table.name, {k: v for k, v in table.values.items() if k != "name"})


def _file_sha256(base_dir: Path, spec: Any) -> str | None:
    if not isinstance(spec, str):
        return None
    file = base_dir / spec
    return hashlib.sha256(file.read_bytes()).hexdigest() if file.is_file() else None


def _record_sources(table: TomlTable, base_dir: Path) -> list[MotionSource]:
    """A ``[[records]]`` entry: one record, or every motion of a suite (``suite = "fema_p695_far_field"`` or a folder)."""
    if "suite" not in table:
        return [_record_source(table, base_dir)]
    from stochpound.motions.records import SELECTIONS, SUITES, select_members

    where = table.name
    table.reject_unknown(_SUITE_KEYS | set(SELECTIONS))
    suite = table.string("suite")
    prefix = table.string("name", "")
    folder = base_dir / suite
    if suite not in SUITES and not folder.is_dir():
        raise ExperimentError(f"{where}.suite: unknown suite {suite!r} and no such folder (suites: {', '.join(SUITES)}, or a folder of .AT2/.txt files)")
    choice = _suite_choice(table)
    with field_errors(f"{where}."):
        members = select_members(suite if suite in SUITES else folder, **choice)
    sources = []
    for member in members:
        record = member if suite in SUITES else str(Path(member).relative_to(base_dir))
        label = member if suite in SUITES else Path(member).stem
        motion = {k: v for k, v in table.values.items() if k not in ("name", "suite", *SELECTIONS)}
        motion.update(type="record", record=record, file_sha256=_file_sha256(base_dir, record))
        sources.append(MotionSource(f"{prefix}/{label}" if prefix else label, "record", where, motion, suite=suite))
    return sources


def _suite_choice(table: TomlTable) -> dict[str, list[str] | tuple[float, float]]:
    """The ``members``, ``event``, ``magnitude`` and ``distance`` choices of a suite entry (lists of names, closed ranges)."""
    choice: dict[str, list[str] | tuple[float, float]] = {}
    for key in ("members", "event"):
        if key in table:
            value = table.raw(key)
            if not isinstance(value, list) or not value or not all(isinstance(item, str) and item for item in value):
                example = '["01a", "03b"]' if key == "members" else '["Northridge", "Kobe"]'
                raise table.error(key, f"must be a non-empty list of names, e.g. {key} = {example}; got {value!r}")
            choice[key] = value
    for key, unit in (("magnitude", ""), ("distance", " km")):
        if key in table:
            value = table.raw(key)
            if not isinstance(value, list) or len(value) != 2 or not all(is_number(v) for v in value) or not value[0] <= value[1]:
                raise table.error(key, f"must be a range [low, high]{unit} with low <= high, got {value!r}")
            choice[key] = (float(value[0]), float(value[1]))
    return choice


def _record_source(table: TomlTable, base_dir: Path) -> MotionSource:
    table.reject_unknown(_RECORD_KEYS)
    record = table.string("record")
    label = table.string("name", Path(record).stem if (base_dir / record).is_file() else record)
    motion = {k: v for k, v in table.values.items() if k != "name"}
    motion["type"] = "record"
    motion["file_sha256"] = _file_sha256(base_dir, record)
    return MotionSource(label, "record", table.name, motion)


def _synthetic_source(label: str, value: Any, where: str) -> MotionSource:
    if not isinstance(value, dict):
        raise ExperimentError(f"{where}: must be a table (type, count, seed and the generator's parameters)")
    table = TomlTable(value, where)
    kind = table.string("type", "kanai_tajimi", choices=SYNTHETIC_TYPES)
    if kind == "scenario_motions":  # the motions of a scenario: its window resolved (experiment/_scenario_ensembles.py)
        return scenario_source(label, table, MAX_REALIZATIONS)
    from stochpound import motions

    if "realization" in table:
        raise table.error("realization", "not used here (realizations start .. start + count - 1 are run)")
    table.reject_unknown(generator_fields(getattr(motions, kind)) | {"count", "start"})  # first: a misspelt count is an unknown field, not a missing one
    count = table.integer("count", low=1, high=MAX_REALIZATIONS, meaning="the number of realizations")
    start = table.integer("start", 0, low=0)
    if "seed" not in table:
        raise table.error("seed", "missing (an integer >= 0; realization i depends on (seed, i) only)")
    entry = {key: item for key, item in value.items() if key not in ("count", "start")}
    entry["type"] = kind
    return MotionSource(label, "synthetic", where, entry, start, count)


# ---------------------------------------------------------------- output and solver


def _output(file: TomlTable, buildings: list[str]) -> Output:
    table = file.table_or_empty("output", {"time_histories", "buildings", "impacts", "demands"})
    histories = table.raw("time_histories", [])
    if not isinstance(histories, list):
        raise ExperimentError(f"output.time_histories: must be a list of variable names, got {histories!r}")
    for i, name in enumerate(histories):
        if name not in TIME_HISTORY_VARIABLES:
            raise ExperimentError(f"output.time_histories[{i}]: unknown variable {name!r} (allowed: {', '.join(TIME_HISTORY_VARIABLES)})")
    _check_unique(histories, "output.time_histories")
    chosen = table.raw("buildings", buildings)
    if not isinstance(chosen, list) or not chosen or not all(b in buildings for b in chosen):
        raise ExperimentError(f"output.buildings: must be a non-empty list of building names ({', '.join(buildings)}), got {chosen!r}")
    _check_unique(chosen, "output.buildings")
    return Output(tuple(histories), tuple(b for b in buildings if b in chosen), table.boolean("impacts", True), table.boolean("demands", False))


def _solver(file: TomlTable) -> Solver:
    table = file.table_or_empty("solver", {"method", "integrator", "rtol", "atol"})
    return Solver(table.string("method", AUTO, choices=(AUTO, *METHODS)), table.string("integrator", "DOP853", choices=INTEGRATORS),
                  table.number("rtol", 1e-10, low=0.0, low_open=True), table.number("atol", 1e-12, low=0.0, low_open=True))
