"""Reading fields of scene and experiment files (parsed TOML), with errors that name the field.

Every reader takes the table, the key and the path of the table (``prefix``,
e.g. ``building[0].base``) and raises :class:`~stochpound._errors.SceneError`
whose message starts with the field's full path and says what is allowed,
e.g. ``building[0].base.mu: must be >= 0, got -0.2``.
"""

from __future__ import annotations

import math
from typing import Any, Hashable, Mapping, Sequence

from stochpound._errors import SceneError


def field_path(prefix: str, key: str) -> str:
    """The full path of field ``key`` of the table at ``prefix`` (e.g. ``building[0].base.mu``)."""
    return f"{prefix}.{key}" if prefix else key


def reject_unknown(table: Mapping[str, Any], allowed: set[str], prefix: str) -> None:
    """Raise for the first key of ``table`` not in ``allowed``, listing the allowed ones."""
    for key in table:
        if key not in allowed:
            raise SceneError(f"{field_path(prefix, key)}: unknown field (allowed: {', '.join(sorted(allowed))})")


def is_number(value: Any) -> bool:
    """True for an int or a float (not a bool)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def check_range(value: float, path: str, low: float | None, low_open: bool, high: float | None, high_open: bool) -> None:
    """Raise unless ``value`` is a number within [low, high] (open ends where asked; None: unbounded)."""
    if math.isnan(value):
        raise SceneError(f"{path}: must be a number, got nan")
    if low is not None and (value < low or (low_open and value == low)):
        raise SceneError(f"{path}: must be {'>' if low_open else '>='} {low:g}, got {value:g}")
    if high is not None and (value > high or (high_open and value == high)):
        raise SceneError(f"{path}: must be {'<' if high_open else '<='} {high:g}, got {value:g}")


def number(
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
    """The number ``table[key]`` within its range, or ``default`` when absent (an error when ``required``)."""
    path = field_path(prefix, key)
    if key not in table:
        if required:
            raise SceneError(f"{path}: missing (a number is required)")
        return default
    value = table[key]
    if not is_number(value):
        raise SceneError(f"{path}: must be a number, got {type(value).__name__} {value!r}")
    value = float(value)
    if math.isinf(value) and not allow_inf:
        raise SceneError(f"{path}: must be finite, got {value}")
    check_range(value, path, low, low_open, high, high_open)
    return value


def boolean(table: Mapping[str, Any], key: str, prefix: str, default: bool) -> bool:
    """The boolean ``table[key]``, or ``default`` when absent."""
    value = table.get(key, default)
    if not isinstance(value, bool):
        raise SceneError(f"{field_path(prefix, key)}: must be true or false, got {value!r}")
    return value


def string(table: Mapping[str, Any], key: str, prefix: str, default: str | None = None) -> str:
    """The non-empty string ``table[key]``, or ``default`` when absent (an error when ``default`` is None)."""
    path = field_path(prefix, key)
    if key not in table:
        if default is None:
            raise SceneError(f"{path}: missing (a string is required)")
        return default
    value = table[key]
    if not isinstance(value, str) or not value:
        raise SceneError(f"{path}: must be a non-empty string, got {value!r}")
    return value


def number_list(table: Mapping[str, Any], key: str, prefix: str, *, low: float, low_open: bool, length: int | None = None) -> tuple[float, ...]:
    """The list of finite numbers ``table[key]`` (required), each >= ``low`` (> when ``low_open``), of ``length`` values if given."""
    path = field_path(prefix, key)
    if key not in table:
        raise SceneError(f"{path}: missing (a list of numbers is required)")
    values = table[key]
    if not isinstance(values, list):
        raise SceneError(f"{path}: must be a list of numbers, got {type(values).__name__} {values!r}")
    if length is not None and len(values) != length:
        raise SceneError(f"{path}: must have {length} values (one per floor), got {len(values)}")
    for i, value in enumerate(values):
        item = f"{path}[{i}]"
        if not is_number(value):
            raise SceneError(f"{item}: must be a number, got {type(value).__name__} {value!r}")
        if math.isinf(value):
            raise SceneError(f"{item}: must be finite, got {value}")
        check_range(float(value), item, low, low_open, None, False)
    return tuple(float(v) for v in values)


def table(parent: Mapping[str, Any], key: str, prefix: str) -> Mapping[str, Any] | None:
    """The table ``parent[key]``, or None when absent."""
    value = parent.get(key)
    if value is not None and not isinstance(value, dict):
        raise SceneError(f"{field_path(prefix, key)}: must be a table, got {type(value).__name__}")
    return value


def array_of_tables(parent: Mapping[str, Any], key: str) -> list[Mapping[str, Any]]:
    """The array of tables ``parent[key]`` (``[[key]]``), empty when absent."""
    value = parent.get(key, [])
    if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
        raise SceneError(f"{key}: must be an array of tables ([[{key}]])")
    return value


def reject_repeated(places: Sequence[tuple[Hashable, str]], table: str, field: str, what: str) -> None:
    """Raise for the first ``[[table]]`` whose place an earlier one already holds.

    ``places`` gives each table's place (a key to compare, and how it reads in
    the message), in the file's order; ``field`` is the field that sets it
    (empty: several fields); ``what`` says what two tables at one place would do.
    """
    first: dict[Hashable, int] = {}
    for i, (key, shown) in enumerate(places):
        if key in first:
            path = field_path(f"{table}[{i}]", field) if field else f"{table}[{i}]"
            raise SceneError(f"{path}: {shown}, the same as {table}[{first[key]}]; {what}: write one [[{table}]] there")
        first[key] = i
