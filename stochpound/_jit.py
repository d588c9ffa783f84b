"""numba's on-disk cache of stochpound's compiled kernels, and where it goes when numba cannot write one.

Every kernel kept between processes is decorated with :func:`cached_njit`,
``numba.njit(cache=True, ...)``. numba chooses where a function's cache lives
when the function is decorated, that is when its module is imported:
``NUMBA_CACHE_DIR``, else the ``__pycache__`` folder beside the source, else
the user's cache folder. When none of them can be written (a read-only
installation without a writable home, an unwritable ``NUMBA_CACHE_DIR``),
numba raises, and every import of the package would fail, ``stochpound
--version`` included. :func:`cached_njit` then caches the kernels in a
private folder of the system's temporary directory (:func:`fallback_folder`),
said once per process by one warning line of the logger ``stochpound``; the
folder is handed to the processes this one starts (``NUMBA_CACHE_DIR``), so
that workers load what this process compiled. Where even that folder cannot
be written, the kernels are compiled without a cache: every process then
compiles them on its first use.

Decorating compiles nothing: a kernel is compiled (or loaded from the cache)
on its first call.
"""

from __future__ import annotations

import functools
import logging
import os
import stat
import tempfile
from pathlib import Path
from typing import Any, Callable

import numba

_LOG = logging.getLogger("stochpound")

FALLBACK_PREFIX = "stochpound-numba-cache-"
"""Name of the fallback cache folder in the temporary directory, followed by the user's id."""


def cached_njit(**options: Any) -> Callable[[Callable[..., Any]], Any]:
    """``numba.njit(cache=True, **options)``, or the same in :func:`fallback_folder` (or without a cache) when numba finds no writable cache.

    Parameters
    ----------
    **options
        numba's jit options (``nogil``, ``error_model``, ...), ``cache`` excepted.
    """

    def decorate(function: Callable[..., Any]) -> Any:
        try:
            return numba.njit(cache=True, **options)(function)
        except RuntimeError as error:  # numba: "cannot cache function ...: no locator available for file ..."
            if "cannot cache" not in str(error):
                raise
        return numba.njit(cache=fallback_folder() is not None, **options)(function)

    return decorate


@functools.cache
def fallback_folder() -> Path | None:
    """The folder numba caches the kernels in when it can write no cache of its own (None: none can be written either).

    ``stochpound-numba-cache-<uid>`` in the system's temporary directory,
    owned by the user and private to them (a fresh private folder instead
    when that one is someone else's or open to others). Chosen once per
    process, with one warning line; numba's configuration and the
    environment (``NUMBA_CACHE_DIR``, inherited by the processes this one
    starts) are pointed to it.
    """
    where = numba.config.CACHE_DIR or "the installation's folder or the user's cache folder"  # NUMBA_CACHE_DIR, as numba read it
    try:
        folder = _private_folder(Path(tempfile.gettempdir()) / f"{FALLBACK_PREFIX}{_user()}")
        tempfile.TemporaryFile(dir=folder).close()
    except OSError as error:
        _LOG.warning("stochpound: numba can write no cache of compiled code (%s; nor the temporary directory: %s): "
                     "the solver is compiled again in every process, on first use", where, error.strerror or error)
        return None
    numba.config.CACHE_DIR = os.environ["NUMBA_CACHE_DIR"] = str(folder)
    _LOG.warning("stochpound: numba cannot write its cache of compiled code in %s: caching it in %s instead", where, folder)
    return folder


def _private_folder(folder: Path) -> Path:
    """``folder``, created private (0700) if absent; a fresh private folder when it is not the user's own private folder."""
    try:
        folder.mkdir(mode=0o700)
    except FileExistsError:  # a folder (checked below), or another kind of file
        pass
    status = folder.lstat()
    owned = not hasattr(os, "getuid") or status.st_uid == os.getuid()
    if stat.S_ISDIR(status.st_mode) and owned and not status.st_mode & (stat.S_IWGRP | stat.S_IWOTH):
        return folder
    return Path(tempfile.mkdtemp(prefix=FALLBACK_PREFIX))


def _user() -> str:
    return str(os.getuid()) if hasattr(os, "getuid") else "user"
