"""The one reading of a text file stochpound is given (a scene, an experiment, a TOML table, a hazard curve, a record).

A file that is not UTF-8 text is refused in one line that names it and
says what it is instead: a netCDF4/HDF5 file (a store, say), a UTF-16 file
(which some editors write), another binary file, or bytes that are not
UTF-8 (with the first one's position). A UTF-8 byte-order mark is dropped.
"""

from __future__ import annotations

import codecs
from pathlib import Path

HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
"""The first bytes of a netCDF4/HDF5 file (a store)."""
_UTF16_MARKS = (codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)
_SNIFFED = 4096
"""Bytes looked at for a NUL, the mark of a binary file."""


def read_text_file(path: str | Path, error: type[Exception] = ValueError, lenient: bool = False) -> str:
    """The text of the file ``path``, decoded as UTF-8 (a byte-order mark dropped).

    Parameters
    ----------
    path : str or Path
        The file; messages name it as given.
    error : type of Exception
        The error raised for a file that is not UTF-8 text (the caller's kind,
        e.g. :class:`~stochpound.model.SceneError`).
    lenient : bool
        Replace bytes that are not UTF-8 (a record's header in Latin-1)
        instead of refusing the file; a binary file is refused all the same.

    Raises
    ------
    error
        ``PATH: a netCDF4/HDF5 file (a store?), not a text file``, ``PATH: UTF-16 text;
        save it as UTF-8``, ``PATH: a binary file, not text`` or ``PATH: not UTF-8 text
        (byte 0x89 at position 0)``.
    OSError
        If the file cannot be read (missing, a folder, no permission).
    """
    return decode_text(Path(path).read_bytes(), str(path), error, lenient)


def decode_text(raw: bytes, shown: str, error: type[Exception] = ValueError, lenient: bool = False) -> str:
    """The bytes of the file ``shown`` as text, or ``error`` as :func:`read_text_file` says."""
    if raw.startswith(HDF5_SIGNATURE):
        raise error(f"{shown}: a netCDF4/HDF5 file (a store?), not a text file")
    if raw.startswith(_UTF16_MARKS):
        raise error(f"{shown}: UTF-16 text; save it as UTF-8")
    if b"\x00" in raw[:_SNIFFED]:
        raise error(f"{shown}: a binary file, not text")
    start = len(codecs.BOM_UTF8) if raw.startswith(codecs.BOM_UTF8) else 0
    try:
        return raw[start:].decode("utf-8", errors="replace" if lenient else "strict")
    except UnicodeDecodeError as failure:
        position = start + failure.start
        raise error(f"{shown}: not UTF-8 text (byte 0x{raw[position]:02x} at position {position}); save it as UTF-8") from None


def attribute_text(value: object) -> str:
    """An HDF5 attribute h5py read as text (a store's ``definition``, ``kind``): bytes decoded as UTF-8, anything else as ``str``."""
    return value.decode() if isinstance(value, bytes) else str(value)


def written_or_returned(text: str, path: str | Path | None) -> str | None:
    """A writer's result, as pandas' ``to_csv`` gives it: ``text`` itself without ``path``; else ``text`` written there
    (UTF-8) and None."""
    if path is None:
        return text
    Path(path).write_text(text, encoding="utf-8")
    return None
