"""Reading fields of scene and experiment files (parsed TOML), with errors that name the field.

The one reader is :class:`TomlTable`: one table with its dotted name
(``building[0].base``, ``design.ec8``, ``records[2]``) and, when it is given
them, the keys it allows (any other key is refused, naming the table, the key
and the allowed keys). Each read declares its field: a number with its range,
an integer, a string with its choices, a boolean, a list of numbers, a
sub-table, a list of tables, each optional with its default. A bad value
raises :class:`~stochpound._errors.SceneError` whose message starts with the
field's full path and says what is allowed, e.g.
``building[0].base.mu: must be >= 0, got -0.2``; a parser whose errors are of
another class gives it (``raises=SiteError``: the same messages, raised as that class). The model's scene readers
take their tables as :class:`TomlTable` values (the table and its name travel
together); the store layer gives the same class as ``stochpound.store.TomlTable``
to the experiment file's parsers, which re-raise its errors as ``ExperimentError``.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Iterator
from typing import Any, Hashable, Mapping, Sequence

from stochpound._errors import SceneError

REQUIRED: Any = object()
"""The default of a field that must be given (a read without a default is required; ``REQUIRED`` says so where the choice is made at run time)."""


def field_path(prefix: str, key: str) -> str:
    """The full path of field ``key`` of the table at ``prefix`` (e.g. ``building[0].base.mu``)."""
    return f"{prefix}.{key}" if prefix else key


def is_number(value: Any) -> bool:
    """True for an int or a float (not a bool)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def check_range(value: float, path: str, low: float | None, low_open: bool, high: float | None, high_open: bool,
                raises: type[ValueError] = SceneError) -> None:
    """Raise ``raises`` unless ``value`` is a number within [low, high] (open ends where asked; None: unbounded)."""
    if math.isnan(value):
        raise raises(f"{path}: must be a number, got nan")
    if low is not None and (value < low or (low_open and value == low)):
        raise raises(f"{path}: must be {'>' if low_open else '>='} {low:g}, got {value:g}")
    if high is not None and (value > high or (high_open and value == high)):
        raise raises(f"{path}: must be {'<' if high_open else '<='} {high:g}, got {value:g}")


class TomlTable:
    """One table of a parsed TOML file, its fields read with errors that name them.

    Parameters
    ----------
    values : mapping
        The table as parsed (``tomllib``).
    name : str
        Its dotted name, the prefix of its fields' names (empty: the file's top level).
    allowed : collection of str, optional
        The keys it may hold (unknown keys are refused); None: any key.
    raises : type of ValueError
        The class of its errors (and of its sub-tables'): :class:`~stochpound._errors.SceneError`, or the
        caller's own (e.g. :class:`~stochpound._errors.SiteError`); the messages are the same whatever the class.

    Raises
    ------
    SceneError
        A key not in ``allowed``: ``design.foo: unknown field (allowed: cd, ec8, ...)`` (``raises``, when given).
    """

    def __init__(self, values: Mapping[str, Any], name: str = "", allowed: Collection[str] | None = None,
                 raises: type[ValueError] = SceneError) -> None:
        self.values = values
        self.name = name
        self.raises = raises
        if allowed is not None:
            self.reject_unknown(allowed)

    def reject_unknown(self, allowed: Collection[str]) -> None:
        """Refuse the first key not in ``allowed``, naming the table, the key and the allowed keys."""
        for key in self.values:
            if key not in allowed:
                raise self.error(key, f"unknown field (allowed: {', '.join(sorted(allowed))})")

    def __contains__(self, key: str) -> bool:
        return key in self.values

    def __iter__(self) -> Iterator[str]:
        return iter(self.values)

    def field(self, key: str) -> str:
        """The full name of field ``key`` (``design.sds``, ``records[2].name``)."""
        return field_path(self.name, key)

    def error(self, key: str, problem: str) -> ValueError:
        """The one-line error of field ``key`` (of the table's class, ``raises``): its full name, then ``problem`` (what is allowed, what was given)."""
        return self.raises(f"{self.field(key)}: {problem}")

    def raw(self, key: str, default: Any = None) -> Any:
        """The value of ``key`` as parsed (a free-form part the caller checks itself), ``default`` when absent."""
        return self.values[key] if key in self.values else default

    def number(self, key: str, default: Any = REQUIRED, *, low: float | None = None, low_open: bool = False, high: float | None = None,
               high_open: bool = False, allow_inf: bool = False) -> Any:
        """The number ``key`` within [low, high] (ends open where asked; None: unbounded), or ``default`` when absent.

        Without a ``default`` the field is required; ``default=None`` makes it optional (None when absent).
        """
        if key not in self.values:
            if default is REQUIRED:
                raise self.error(key, "missing (a number is required)")
            return default
        value = self.values[key]
        if not is_number(value):
            raise self.error(key, f"must be a number, got {type(value).__name__} {value!r}")
        value = float(value)
        if math.isinf(value) and not allow_inf:
            raise self.error(key, f"must be finite, got {value}")
        check_range(value, self.field(key), low, low_open, high, high_open, self.raises)
        return value

    def integer(self, key: str, default: Any = REQUIRED, *, low: int | None = None, high: int | None = None, meaning: str = "") -> Any:
        """The integer ``key`` (not a bool) within [low, high] (None: unbounded), or ``default`` when absent (required without one).

        ``meaning`` says what the integer is, in the message of a missing field.
        """
        if key not in self.values:
            if default is REQUIRED:
                raise self.error(key, f"missing ({meaning or 'an integer'}, an integer{_integer_range(low, high)})")
            return default
        value = self.values[key]
        if not isinstance(value, int) or isinstance(value, bool) or (low is not None and value < low) or (high is not None and value > high):
            raise self.error(key, f"must be an integer{_integer_range(low, high)}, got {value!r}")
        return value

    def string(self, key: str, default: Any = REQUIRED, *, choices: Collection[str] | None = None, hint: str = "") -> Any:
        """The non-empty string ``key``, one of ``choices`` if given (``hint`` follows them in the message), or ``default`` when absent."""
        if key not in self.values:
            if default is REQUIRED:
                raise self.error(key, "missing (a string is required)")
            return default
        value = self.values[key]
        if not isinstance(value, str) or not value:
            raise self.error(key, f"must be a non-empty string, got {value!r}")
        if choices is not None and value not in choices:
            raise self.error(key, f"must be one of {', '.join(choices)}{f' ({hint})' if hint else ''}, got {value!r}")
        return value

    def boolean(self, key: str, default: bool) -> bool:
        """The boolean ``key``, or ``default`` when absent."""
        value = self.raw(key, default)
        if not isinstance(value, bool):
            raise self.error(key, f"must be true or false, got {value!r}")
        return value

    def numbers(self, key: str, default: Any = REQUIRED, *, low: float | None = None, low_open: bool = False,
                length: int | None = None) -> Any:
        """The list of finite numbers ``key`` as a tuple, or ``default`` when absent (required without one).

        Each value is >= ``low`` (> when ``low_open``; None: any); ``length``, if given, is the number of values
        (one per floor).
        """
        if key not in self.values:
            if default is REQUIRED:
                raise self.error(key, "missing (a list of numbers is required)")
            return default
        values = self.values[key]
        if not isinstance(values, list):
            raise self.error(key, f"must be a list of numbers, got {type(values).__name__} {values!r}")
        if length is not None and len(values) != length:
            raise self.error(key, f"must have {length} values (one per floor), got {len(values)}")
        for i, value in enumerate(values):
            item = f"{self.field(key)}[{i}]"
            if not is_number(value):
                raise self.raises(f"{item}: must be a number, got {type(value).__name__} {value!r}")
            if math.isinf(value):
                raise self.raises(f"{item}: must be finite, got {value}")
            check_range(float(value), item, low, low_open, None, False, self.raises)
        return tuple(float(v) for v in values)

    def table(self, key: str, allowed: Collection[str] | None = None, hint: str = "") -> TomlTable | None:
        """The sub-table ``key`` (named ``<name>.<key>``, its keys checked against ``allowed``), or None when absent.

        ``hint`` shows the table's form in the message of a value that is not a table (e.g. ``{ k0 = ..., k = ... }``).
        """
        value = self.raw(key)
        if value is not None and not isinstance(value, dict):
            raise self.error(key, f"must be a table {hint}, got {value!r}" if hint else f"must be a table, got {type(value).__name__}")
        return None if value is None else TomlTable(value, self.field(key), allowed, self.raises)

    def table_or_empty(self, key: str, allowed: Collection[str] | None = None, hint: str = "") -> TomlTable:
        """The sub-table ``key`` as :meth:`table` reads it, an empty one when absent (a table whose every field has a default)."""
        return self.table(key, allowed, hint) or TomlTable({}, self.field(key), raises=self.raises)

    def tables(self, key: str, hint: str = "") -> list[TomlTable]:
        """The array of tables ``[[key]]``, each named ``<key>[i]``; empty when absent (``hint`` says what each table holds)."""
        values = self.raw(key, [])
        if not isinstance(values, list) or not all(isinstance(v, dict) for v in values):
            raise self.error(key, f"must be an array of tables ([[{key}]]{f' with {hint}' if hint else ''})")
        return [TomlTable(value, f"{self.field(key)}[{i}]", raises=self.raises) for i, value in enumerate(values)]


def _integer_range(low: int | None, high: int | None) -> str:
    """`` in [low, high]``, `` >= low`` or `` <= high`` (empty: any integer)."""
    if low is not None and high is not None:
        return f" in [{low}, {high}]"
    return f" >= {low}" if low is not None else (f" <= {high}" if high is not None else "")


def reject_unknown(table: Mapping[str, Any], allowed: set[str], prefix: str) -> None:
    """Raise for the first key of ``table`` (at ``prefix``) not in ``allowed``, listing the allowed ones (:meth:`TomlTable.reject_unknown`)."""
    TomlTable(table, prefix).reject_unknown(allowed)


def number(table: Mapping[str, Any], key: str, prefix: str, *, default: float | None = None, required: bool = False, low: float | None = None,
           low_open: bool = False, high: float | None = None, high_open: bool = False, allow_inf: bool = False) -> float | None:
    """The number ``table[key]`` (at ``prefix``) within its range, or ``default`` when absent (an error when ``required``; :meth:`TomlTable.number`)."""
    return TomlTable(table, prefix).number(key, REQUIRED if required else default, low=low, low_open=low_open, high=high, high_open=high_open,
                                           allow_inf=allow_inf)


def boolean(table: Mapping[str, Any], key: str, prefix: str, default: bool) -> bool:
    """The boolean ``table[key]`` (at ``prefix``), or ``default`` when absent (:meth:`TomlTable.boolean`)."""
    return TomlTable(table, prefix).boolean(key, default)


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
