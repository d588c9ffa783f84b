"""Atomic file writes: a temporary file beside the target, renamed over it once complete.

A reader never sees a partial file, and an interrupted write leaves the old
file as it was (plus, at worst, a stray temporary, ``.<name>.<random>.tmp``,
which :func:`temporaries` finds). Temporaries are created with mode 0666
filtered by the umask, as the target itself would be (``tempfile.mkstemp``
would make every result private to its owner, 0600).
"""

from __future__ import annotations

import errno
import os
import secrets
import shutil
from contextlib import contextmanager
from pathlib import Path
from typing import Iterable, Iterator

TEMPORARY_SUFFIX = ".tmp"


@contextmanager
def replacing(path: str | Path) -> Iterator[Path]:
    """Yield the path of a new, empty temporary file beside ``path``; rename it over ``path`` when the block ends.

    If the block raises (or is interrupted), the temporary is deleted and
    ``path`` is left unchanged. A file-system error that names no file (a
    full disk while writing, say) or the temporary is raised naming ``path``,
    so that its one-line message says which file could not be written. The caller writes the temporary (it may
    reopen and truncate it) and flushes it to disk if it needs to.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = _create_temporary(path)
    try:
        yield temporary
        os.replace(temporary, path)
    except OSError as error:
        temporary.unlink(missing_ok=True)
        if error.filename is None or error.filename == str(temporary):
            raise OSError(error.errno, error.strerror or str(error), str(path)) from error
        raise
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise


def check_writable(path: str | Path) -> None:
    """Raise the ``OSError`` that writing ``path`` would raise, before any work: create (and remove) a temporary beside it.

    Its folder is created if needed (as :func:`replacing` would). The error
    names that folder (not the temporary's name).
    """
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        os.unlink(_create_temporary(path))
    except OSError as error:
        raise OSError(error.errno, error.strerror, str(path.parent)) from None


def check_not_input(output: str | Path, inputs: Iterable[tuple[str | Path, str]], option: str) -> None:
    """Refuse to write ``output`` over a file the same command reads: raise ``ValueError`` naming it and what it is.

    Parameters
    ----------
    output : str or Path
        The file the command would write (or replace).
    inputs : iterable of (path, str)
        The files the command reads, each with what it is (``"the experiment file"``).
    option : str
        The option that names ``output`` (``--store``), for the message.
    """
    output = Path(output)
    for path, what in inputs:
        path = Path(path)
        if output.exists() and path.exists() and os.path.samefile(output, path):
            raise ValueError(f"{output}: is {what}, an input of this command; {option} must name another file")


def check_room(path: str | Path, needed: int) -> None:
    """Raise ``OSError(ENOSPC)`` naming ``path`` if its disk has less than ``needed`` bytes free.

    Called before a large write, so that a full disk is reported before any
    byte is written (a library that writes the file may not fail cleanly).
    """
    free = free_bytes(path)
    if free is not None and free < needed:
        raise OSError(errno.ENOSPC, f"No space left on device: {free / 1e6:.1f} MB free, about {needed / 1e6:.1f} MB needed", str(path))


def free_bytes(path: str | Path) -> int | None:
    """Free bytes on the disk of ``path``'s folder (of the working folder if it does not exist yet); None if unknown."""
    path = Path(path)
    try:
        return shutil.disk_usage(path.parent if path.parent.is_dir() else Path.cwd()).free
    except OSError:
        return None  # the write itself reports it


def _create_temporary(path: Path) -> Path:
    while True:
        temporary = path.with_name(f".{path.name}.{secrets.token_hex(6)}{TEMPORARY_SUFFIX}")
        try:
            os.close(os.open(temporary, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o666))
        except FileExistsError:
            continue
        return temporary


def temporaries(folder: str | Path, name: str = "*") -> list[Path]:
    """Temporaries left in ``folder`` by interrupted writes of ``name`` (default: of any file)."""
    return sorted(Path(folder).glob(f".{name}.*{TEMPORARY_SUFFIX}"))
