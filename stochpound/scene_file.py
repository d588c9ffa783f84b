"""Scene files (TOML, CONTRACT.md): parsing and validation into a :class:`~stochpound.scene.Scene`.

Every field is checked before anything is computed. A bad field raises
:class:`~stochpound.errors.SceneError` whose message starts with the field's
path (0-based indices), e.g. ``building[0].base.mu: must be >= 0, got -0.2``.
"""

from __future__ import annotations

import inspect
import math
import tomllib
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from stochpound.errors import RecordError, SceneError
from stochpound.memory import check_memory, sample_bytes
from stochpound.motion import GroundMotion, HarmonicMotion, SampledMotion
from stochpound.scene import (
    Base,
    Building,
    Contact,
    InitialState,
    Scene,
    impact_damping,
    stiffness_proportional_damping,
)

_TOP_KEYS = {"g", "study_compat", "building", "contact", "motion"}
_BUILDING_KEYS = {"name", "mass", "stiffness", "damping", "damping_ratio", "base", "initial"}
_BASE_KEYS = {"mass", "mu", "mu_static", "restoring_stiffness"}
_INITIAL_KEYS = {"displacement", "velocity", "base_displacement", "base_velocity"}
_CONTACT_KEYS = {"between", "gap", "stiffness", "restitution", "damping", "tensile"}
_SYNTHETIC_TYPES = {"kanai_tajimi", "clough_penzien"}


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file.

    Parameters
    ----------
    path : str or Path
        A TOML scene file (CONTRACT.md). Relative record paths inside it are
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
    try:
        data = tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise SceneError(f"{path}: scene file not found") from None
    except tomllib.TOMLDecodeError as error:
        raise SceneError(f"{path}: not valid TOML: {error}") from None
    return scene_from_dict(data, base_dir=path.parent, source=path.name)


def scene_from_dict(data: Mapping[str, Any], base_dir: str | Path = ".", source: str = "python") -> Scene:
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
    _reject_unknown(data, _TOP_KEYS, "")
    g = _number(data, "g", "", default=9.81, low=0.0, low_open=True)
    study_compat = _boolean(data, "study_compat", "", default=False)
    buildings = _buildings(data)
    contacts = _contacts(data, buildings)
    n_dof = sum(b.n_floors + (b.base is not None) for b in buildings)
    per_sample = sample_bytes(n_dof, len(buildings), max((b.n_floors for b in buildings), default=1), len(contacts))
    motion = _motion(data, Path(base_dir), g, per_sample)
    return Scene(tuple(buildings), tuple(contacts), motion, g=g, study_compat=study_compat, source=source)


# ---------------------------------------------------------------- field helpers


def _where(prefix: str, key: str) -> str:
    return f"{prefix}.{key}" if prefix else key


def _reject_unknown(table: Mapping[str, Any], allowed: set[str], prefix: str) -> None:
    for key in table:
        if key not in allowed:
            raise SceneError(f"{_where(prefix, key)}: unknown field (allowed: {', '.join(sorted(allowed))})")


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _check_range(value: float, where: str, low: float | None, low_open: bool, high: float | None, high_open: bool) -> None:
    if math.isnan(value):
        raise SceneError(f"{where}: must be a number, got nan")
    if low is not None and (value < low or (low_open and value == low)):
        raise SceneError(f"{where}: must be {'>' if low_open else '>='} {low:g}, got {value:g}")
    if high is not None and (value > high or (high_open and value == high)):
        raise SceneError(f"{where}: must be {'<' if high_open else '<='} {high:g}, got {value:g}")


def _number(
    table: Mapping[str, Any],
    key: str,
    prefix: str,
    *,
    default: float | None = None,
    required: bool = False,
    low: float | None = None,
    low_open: bool = False,
    high: float | None = None,
    high_open: bool = False,
    allow_inf: bool = False,
) -> float | None:
    where = _where(prefix, key)
    if key not in table:
        if required:
            raise SceneError(f"{where}: missing (a number is required)")
        return default
    value = table[key]
    if not _is_number(value):
        raise SceneError(f"{where}: must be a number, got {type(value).__name__} {value!r}")
    value = float(value)
    if math.isinf(value) and not allow_inf:
        raise SceneError(f"{where}: must be finite, got {value}")
    _check_range(value, where, low, low_open, high, high_open)
    return value


def _boolean(table: Mapping[str, Any], key: str, prefix: str, default: bool) -> bool:
    value = table.get(key, default)
    if not isinstance(value, bool):
        raise SceneError(f"{_where(prefix, key)}: must be true or false, got {value!r}")
    return value


def _string(table: Mapping[str, Any], key: str, prefix: str, default: str | None = None) -> str:
    where = _where(prefix, key)
    if key not in table:
        if default is None:
            raise SceneError(f"{where}: missing (a string is required)")
        return default
    value = table[key]
    if not isinstance(value, str) or not value:
        raise SceneError(f"{where}: must be a non-empty string, got {value!r}")
    return value


def _number_list(table: Mapping[str, Any], key: str, prefix: str, *, low: float, low_open: bool, length: int | None = None) -> tuple[float, ...]:
    where = _where(prefix, key)
    if key not in table:
        raise SceneError(f"{where}: missing (a list of numbers is required)")
    values = table[key]
    if not isinstance(values, list):
        raise SceneError(f"{where}: must be a list of numbers, got {type(values).__name__} {values!r}")
    if length is not None and len(values) != length:
        raise SceneError(f"{where}: must have {length} values (one per floor), got {len(values)}")
    for i, value in enumerate(values):
        item = f"{where}[{i}]"
        if not _is_number(value):
            raise SceneError(f"{item}: must be a number, got {type(value).__name__} {value!r}")
        if math.isinf(value):
            raise SceneError(f"{item}: must be finite, got {value}")
        _check_range(float(value), item, low, low_open, None, False)
    return tuple(float(v) for v in values)


def _table(table: Mapping[str, Any], key: str, prefix: str) -> Mapping[str, Any] | None:
    value = table.get(key)
    if value is not None and not isinstance(value, dict):
        raise SceneError(f"{_where(prefix, key)}: must be a table, got {type(value).__name__}")
    return value


def _array_of_tables(table: Mapping[str, Any], key: str) -> list[Mapping[str, Any]]:
    value = table.get(key, [])
    if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
        raise SceneError(f"{key}: must be an array of tables ([[{key}]])")
    return value


# ---------------------------------------------------------------- buildings


def _buildings(data: Mapping[str, Any]) -> list[Building]:
    tables = _array_of_tables(data, "building")
    if not tables:
        raise SceneError("building: at least one [[building]] is required")
    buildings = [_building(table, f"building[{i}]", i) for i, table in enumerate(tables)]
    names = [b.name for b in buildings]
    for i, name in enumerate(names):
        if names.index(name) != i:
            raise SceneError(f"building[{i}].name: must be unique, {name!r} is used twice")
    return buildings


def _building(table: Mapping[str, Any], prefix: str, index: int) -> Building:
    _reject_unknown(table, _BUILDING_KEYS, prefix)
    name = _string(table, "name", prefix, default=f"B{index + 1}")
    base = _base(_table(table, "base", prefix), f"{prefix}.base")
    mass = _number_list(table, "mass", prefix, low=0.0, low_open=True)
    if not mass and base is None:
        raise SceneError(f"{prefix}.mass: must have at least one floor (only a sliding base may carry no floors)")
    stiffness = _number_list(table, "stiffness", prefix, low=0.0, low_open=False, length=len(mass))
    damping, ratio = _storey_damping(table, prefix, np.array(mass), np.array(stiffness))
    initial = _initial(_table(table, "initial", prefix), f"{prefix}.initial", len(mass), base is not None)
    return Building(name, mass, stiffness, damping, ratio, base, initial)


def _storey_damping(table: Mapping[str, Any], prefix: str, mass: np.ndarray, stiffness: np.ndarray) -> tuple[tuple[float, ...], float | None]:
    if "damping" in table and "damping_ratio" in table:
        raise SceneError(f"{prefix}.damping: give either damping (N·s/m per storey) or damping_ratio, not both")
    if "damping_ratio" in table:
        ratio = _number(table, "damping_ratio", prefix, low=0.0, high=1.0, high_open=True)
        if len(mass) == 0 or np.any(stiffness <= 0.0):
            raise SceneError(f"{prefix}.damping_ratio: needs every storey stiffness > 0 (mode 1 must have a frequency); give damping instead")
        return tuple(stiffness_proportional_damping(mass, stiffness, ratio)), ratio
    if "damping" in table:
        return _number_list(table, "damping", prefix, low=0.0, low_open=False, length=len(mass)), None
    return tuple(0.0 for _ in mass), None


def _base(table: Mapping[str, Any] | None, prefix: str) -> Base | None:
    if table is None:
        return None
    _reject_unknown(table, _BASE_KEYS, prefix)
    mass = _number(table, "mass", prefix, required=True, low=0.0, low_open=True)
    mu = _number(table, "mu", prefix, required=True, low=0.0)
    mu_static = _number(table, "mu_static", prefix, default=mu, low=mu)
    restoring = _number(table, "restoring_stiffness", prefix, default=0.0, low=0.0)
    return Base(mass, mu, mu_static, restoring)


def _initial(table: Mapping[str, Any] | None, prefix: str, n_floors: int, has_base: bool) -> InitialState:
    zeros = tuple(0.0 for _ in range(n_floors))
    if table is None:
        return InitialState(zeros, zeros)
    _reject_unknown(table, _INITIAL_KEYS, prefix)
    for key in ("base_displacement", "base_velocity"):
        if key in table and not has_base:
            raise SceneError(f"{prefix}.{key}: only a building with a sliding [building.base] can have it")
    displacement = _number_list(table, "displacement", prefix, low=-math.inf, low_open=False, length=n_floors) if "displacement" in table else zeros
    velocity = _number_list(table, "velocity", prefix, low=-math.inf, low_open=False, length=n_floors) if "velocity" in table else zeros
    return InitialState(
        displacement,
        velocity,
        _number(table, "base_displacement", prefix, default=0.0),
        _number(table, "base_velocity", prefix, default=0.0),
    )


# ---------------------------------------------------------------- contacts


def _contacts(data: Mapping[str, Any], buildings: list[Building]) -> list[Contact]:
    return [_contact(table, f"contact[{i}]", buildings) for i, table in enumerate(_array_of_tables(data, "contact"))]


def _contact_end(value: Any, where: str, buildings: list[Building]) -> tuple[int, int]:
    names = [b.name for b in buildings]
    if not (isinstance(value, list) and len(value) == 2 and isinstance(value[0], str) and isinstance(value[1], int) and not isinstance(value[1], bool)):
        raise SceneError(f"{where}: must be [building name, floor number], got {value!r}")
    name, floor = value
    if name not in names:
        raise SceneError(f"{where}: unknown building {name!r} (buildings: {', '.join(names)})")
    index = names.index(name)
    n_floors = buildings[index].n_floors
    if not 1 <= floor <= n_floors:
        raise SceneError(f"{where}: floor must be in 1..{n_floors} for building {name!r}, got {floor}")
    return index, floor


def _contact(table: Mapping[str, Any], prefix: str, buildings: list[Building]) -> Contact:
    _reject_unknown(table, _CONTACT_KEYS, prefix)
    between = table.get("between")
    if not isinstance(between, list) or len(between) != 2:
        raise SceneError(f"{prefix}.between: must be [[left building, floor], [right building, floor]], got {between!r}")
    left, left_floor = _contact_end(between[0], f"{prefix}.between[0]", buildings)
    right, right_floor = _contact_end(between[1], f"{prefix}.between[1]", buildings)
    if right != left + 1:
        raise SceneError(
            f"{prefix}.between: contacts join neighbours, left building first; "
            f"{buildings[left].name!r} and {buildings[right].name!r} are not left/right neighbours"
        )
    gap = _number(table, "gap", prefix, required=True, low=0.0)
    stiffness = _number(table, "stiffness", prefix, required=True, low=0.0, low_open=True)
    restitution = None
    if "restitution" in table and "damping" in table:
        raise SceneError(f"{prefix}.damping: give either restitution or damping, not both")
    if "damping" in table:
        damping = _number(table, "damping", prefix, low=0.0)
    else:
        restitution = _number(table, "restitution", prefix, required=True, low=0.0, low_open=True, high=1.0)
        masses = buildings[left].mass[left_floor - 1], buildings[right].mass[right_floor - 1]
        damping = impact_damping(stiffness, restitution, *masses)
    tensile = _boolean(table, "tensile", prefix, default=True)
    return Contact(left, left_floor, right, right_floor, gap, stiffness, damping, restitution, tensile)


# ---------------------------------------------------------------- motion


_MOTION_KEYS = {
    "record": {"type", "record", "scale", "dt", "duration", "units", "interpolation"},
    "harmonic": {"type", "amplitude", "omega", "phase", "duration", "dt"},
    "constant": {"type", "acceleration", "duration", "dt"},
}


def _motion(data: Mapping[str, Any], base_dir: Path, g: float, per_sample: int) -> GroundMotion:
    """The scene's ground motion; a run needing more than the memory limit (``per_sample`` bytes a sample) is refused first."""
    table = _table(data, "motion", "")
    if table is None:
        raise SceneError("motion: missing ([motion] with a record, or type = harmonic | constant | kanai_tajimi | clough_penzien)")
    kind = _string(table, "type", "motion", default="record")
    if kind in _SYNTHETIC_TYPES:
        return _synthetic_motion(table, kind, per_sample)
    if kind not in _MOTION_KEYS:
        raise SceneError(f"motion.type: must be one of record, harmonic, constant, kanai_tajimi, clough_penzien; got {kind!r}")
    _reject_unknown(table, _MOTION_KEYS[kind], "motion")
    if kind == "harmonic":
        return _harmonic_motion(table, per_sample)
    if kind == "constant":
        return _constant_motion(table, per_sample)
    return _record_motion(table, base_dir, g, per_sample)


def _timing(table: Mapping[str, Any], required: bool, per_sample: int) -> tuple[float | None, float | None]:
    duration = _number(table, "duration", "motion", required=required, low=0.0, low_open=True)
    dt = _number(table, "dt", "motion", required=required, low=0.0, low_open=True)
    if duration is not None and dt is not None and dt > duration:
        raise SceneError(f"motion.dt: must be <= motion.duration ({duration:g} s), got {dt:g}")
    if required:  # a record's own length bounds its samples: checked once read
        n_samples = duration / dt + 1
        check_memory(n_samples * per_sample, f"motion: duration {duration:g} s at dt {dt:g} s is {n_samples:.3g} samples; a run")
    return duration, dt


def _harmonic_motion(table: Mapping[str, Any], per_sample: int) -> HarmonicMotion:
    amplitude = _number(table, "amplitude", "motion", required=True)
    omega = _number(table, "omega", "motion", required=True, low=0.0)
    phase = _number(table, "phase", "motion", default=0.0)
    duration, dt = _timing(table, required=True, per_sample=per_sample)
    return HarmonicMotion(amplitude, omega, duration, dt, phase)


def _constant_motion(table: Mapping[str, Any], per_sample: int) -> SampledMotion:
    acceleration = _number(table, "acceleration", "motion", required=True)
    duration, dt = _timing(table, required=True, per_sample=per_sample)
    n_samples = int(round(duration / dt)) + 1
    return SampledMotion(dt, np.full(n_samples, acceleration), description=f"constant {acceleration:g} m/s²")


def _record_motion(table: Mapping[str, Any], base_dir: Path, g: float, per_sample: int) -> SampledMotion:
    from stochpound.records import load_record

    spec = _string(table, "record", "motion")
    scale = _number(table, "scale", "motion", default=1.0)
    duration, dt = _timing(table, required=False, per_sample=per_sample)
    units = _string(table, "units", "motion", default="") or None
    if units not in (None, "g", "m/s2", "cm/s2"):
        raise SceneError(f"motion.units: must be one of g, m/s2, cm/s2; got {units!r}")
    interpolation = _string(table, "interpolation", "motion", default="linear")
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


def _check_generator_fields(table: Mapping[str, Any], generator: Any, kind: str) -> None:
    """Reject fields the generator does not take, and name the required ones that are missing."""
    signature = inspect.signature(generator).parameters
    own = {name for name in signature if name not in ("n_realizations", "start")}
    _reject_unknown(table, own | {"type", "realization", "interpolation"}, "motion")
    for name, parameter in signature.items():
        if name in own and parameter.default is inspect.Parameter.empty and name not in table:
            raise SceneError(f"motion.{name}: required for type = {kind!r} (see docs/motions.md)")


def _synthetic_motion(table: Mapping[str, Any], kind: str, per_sample: int) -> SampledMotion:
    """One realization of a synthetic ensemble, fixed by (seed, realization) alone."""
    from stochpound import motions

    generator = getattr(motions, kind)
    _check_generator_fields(table, generator, kind)
    parameters = {key: value for key, value in table.items() if key not in ("type", "realization", "interpolation")}
    realization = table.get("realization", 0)
    if not isinstance(realization, int) or isinstance(realization, bool) or realization < 0:
        raise SceneError(f"motion.realization: must be an integer >= 0, got {realization!r}")
    duration, dt = _timing(table, required=True, per_sample=per_sample)
    parameters.update(duration=duration, dt=dt)
    try:
        ensemble = generator(1, start=realization, **parameters)
    except (TypeError, ValueError) as error:
        raise SceneError(f"motion: {error}") from None
    description = f"{kind} realization {realization} (seed {parameters.get('seed', 0)})"
    return SampledMotion(dt, np.asarray(ensemble.values[0], dtype=float), "linear", description)
