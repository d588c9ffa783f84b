"""One table of a parsed TOML file, read field by field: the one reader of the experiment file's tables.

A :class:`TomlTable` wraps one table with its dotted name (``intensity``,
``design.ec8``, ``records[2]``) and, when it is given them, the keys it allows
(any other key is refused, naming the table, the key and the allowed keys).
Each read declares its field: a number with its range, an integer, a string
with its choices, a boolean, a sub-table, a list of tables, each optional with
its default. A bad value raises :class:`~stochpound._errors.SceneError` with
one line naming the field and what is allowed, e.g.
``design.sds: must be <= 5, got 7`` (the messages of
:mod:`stochpound.model.fields`, shared with the scene file's reader); the
experiment's parser re-raises them as ``ExperimentError``.
"""

from __future__ import annotations

from collections.abc import Collection, Iterator, Mapping
from typing import Any

from stochpound._errors import SceneError
from stochpound.model import fields as toml_fields

_REQUIRED: Any = object()
"""The default of a field that must be given."""


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

    Raises
    ------
    SceneError
        A key not in ``allowed``: ``design.foo: unknown field (allowed: cd, ec8, ...)``.
    """

    def __init__(self, values: Mapping[str, Any], name: str = "", allowed: Collection[str] | None = None) -> None:
        self.values = values
        self.name = name
        if allowed is not None:
            self.reject_unknown(allowed)

    def reject_unknown(self, allowed: Collection[str]) -> None:
        """Refuse the first key not in ``allowed``, naming the table, the key and the allowed keys."""
        toml_fields.reject_unknown(self.values, set(allowed), self.name)

    def __contains__(self, key: str) -> bool:
        return key in self.values

    def __iter__(self) -> Iterator[str]:
        return iter(self.values)

    def field(self, key: str) -> str:
        """The full name of field ``key`` (``design.sds``, ``records[2].name``)."""
        return toml_fields.field_path(self.name, key)

    def error(self, key: str, problem: str) -> SceneError:
        """The one-line error of field ``key``: its full name, then ``problem`` (what is allowed, what was given)."""
        return SceneError(f"{self.field(key)}: {problem}")

    def raw(self, key: str, default: Any = None) -> Any:
        """The value of ``key`` as parsed (a free-form part the caller checks itself), ``default`` when absent."""
        return self.values[key] if key in self.values else default

    def number(self, key: str, default: Any = _REQUIRED, *, low: float | None = None, low_open: bool = False, high: float | None = None,
               high_open: bool = False, allow_inf: bool = False) -> Any:
        """The number ``key`` within [low, high] (ends open where asked; None: unbounded), or ``default`` when absent.

        Without a ``default`` the field is required; ``default=None`` makes it optional (None when absent).
        """
        required = default is _REQUIRED
        return toml_fields.number(self.values, key, self.name, default=None if required else default, required=required, low=low,
                                  low_open=low_open, high=high, high_open=high_open, allow_inf=allow_inf)

    def integer(self, key: str, default: Any = _REQUIRED, *, low: int | None = None, high: int | None = None, meaning: str = "") -> Any:
        """The integer ``key`` (not a bool) within [low, high] (None: unbounded), or ``default`` when absent (required without one).

        ``meaning`` says what the integer is, in the message of a missing field.
        """
        if key not in self.values:
            if default is _REQUIRED:
                raise self.error(key, f"missing ({meaning or 'an integer'}, an integer{_integer_range(low, high)})")
            return default
        value = self.values[key]
        if not isinstance(value, int) or isinstance(value, bool) or (low is not None and value < low) or (high is not None and value > high):
            raise self.error(key, f"must be an integer{_integer_range(low, high)}, got {value!r}")
        return value

    def string(self, key: str, default: Any = _REQUIRED, *, choices: Collection[str] | None = None, hint: str = "") -> Any:
        """The non-empty string ``key``, one of ``choices`` if given (``hint`` follows them in the message), or ``default`` when absent."""
        if key not in self.values and default is not _REQUIRED:
            return default
        value = toml_fields.string(self.values, key, self.name)
        if choices is not None and value not in choices:
            raise self.error(key, f"must be one of {', '.join(choices)}{f' ({hint})' if hint else ''}, got {value!r}")
        return value

    def boolean(self, key: str, default: bool) -> bool:
        """The boolean ``key``, or ``default`` when absent."""
        return toml_fields.boolean(self.values, key, self.name, default)

    def numbers(self, key: str, default: Any = _REQUIRED, *, low: float | None = None, low_open: bool = False) -> Any:
        """The list of finite numbers ``key`` as a tuple, each >= ``low`` (> when ``low_open``; None: any), or ``default`` when absent."""
        if key not in self.values and default is not _REQUIRED:
            return default
        return toml_fields.number_list(self.values, key, self.name, low=low, low_open=low_open)

    def table(self, key: str, allowed: Collection[str] | None = None, hint: str = "") -> TomlTable | None:
        """The sub-table ``key`` (named ``<name>.<key>``, its keys checked against ``allowed``), or None when absent.

        ``hint`` shows the table's form in the message of a value that is not a table (e.g. ``{ k0 = ..., k = ... }``).
        """
        value = self.raw(key)
        if hint and value is not None and not isinstance(value, dict):
            raise self.error(key, f"must be a table {hint}, got {value!r}")
        values = toml_fields.table(self.values, key, self.name)
        return None if values is None else TomlTable(values, self.field(key), allowed)

    def table_or_empty(self, key: str, allowed: Collection[str] | None = None, hint: str = "") -> TomlTable:
        """The sub-table ``key`` as :meth:`table` reads it, an empty one when absent (a table whose every field has a default)."""
        return self.table(key, allowed, hint) or TomlTable({}, self.field(key))

    def tables(self, key: str, hint: str = "") -> list[TomlTable]:
        """The array of tables ``[[key]]``, each named ``<key>[i]``; empty when absent (``hint`` says what each table holds)."""
        values = self.raw(key, [])
        if not isinstance(values, list) or not all(isinstance(v, dict) for v in values):
            raise self.error(key, f"must be an array of tables ([[{key}]]{f' with {hint}' if hint else ''})")
        return [TomlTable(value, f"{self.field(key)}[{i}]") for i, value in enumerate(values)]


def _integer_range(low: int | None, high: int | None) -> str:
    """`` in [low, high]``, `` >= low`` or `` <= high`` (empty: any integer)."""
    if low is not None and high is not None:
        return f" in [{low}, {high}]"
    return f" >= {low}" if low is not None else (f" <= {high}" if high is not None else "")
