"""Exception types raised by stochpound.

Every error caused by user input names the offending field (or file and line)
and the allowed range, so that it can be fixed without reading the source.
"""

import contextlib
import errno
import re
from typing import Iterator


class StochpoundError(Exception):
    """Base class of every error raised on purpose by stochpound."""


class SceneError(StochpoundError, ValueError):
    """A scene definition is invalid; the message names the field, e.g.
    ``building[1].base.mu: must be >= 0, got -0.2``."""


class ExperimentError(SceneError):
    """An experiment definition or store is invalid; the message names the field
    (e.g. ``grid.gap[1]: must be >= 0, got -0.01``) or the file."""


class RecordError(StochpoundError, ValueError):
    """A ground-motion record cannot be read or is unusable; the message names
    the file (and line, where there is one)."""


class VerificationError(StochpoundError):
    """A self-check of a report disagrees with what it checks (e.g. a stored case re-run does not reproduce the store)."""


class IntensityError(ValueError):
    """An ``[intensity]`` (or ``[hazard]``) field is invalid (the message starts with the field)."""


class SiteError(StochpoundError, ValueError):
    """A site scenario, a conditional-spectrum target or a motion selection is invalid;
    the message names the field, e.g. ``magnitude: must be within 3.5-8.5, got 9``."""


def os_error_message(error: OSError) -> str:
    """One line for a file-system error, naming the path: ``PATH: cannot write here (Read-only file system)``.

    Without a path in ``error``, its message as it is.
    """
    if error.filename is None:
        return str(error)
    action = "cannot write here" if error.errno in _WRITE_ERRORS else "cannot access"
    return f"{error.filename}: {action} ({error.strerror or error})"


_WRITE_ERRORS = {errno.EROFS, errno.EACCES, errno.EPERM, errno.ENOSPC, errno.EDQUOT}


@contextlib.contextmanager
def field_errors(prefix: str = "", scene_prefix: str | None = None) -> Iterator[None]:
    """Re-raise :class:`SceneError` (and ``ValueError``) as :class:`ExperimentError`.

    Parameters
    ----------
    prefix : str
        Prepended to the message (``"variants.neighbour.stiff: "``).
    scene_prefix : str, optional
        Replaces a leading ``motion.`` / ``motion:`` of scene messages, so that a
        record's errors name the experiment's field (``records[0].duration``).
    """
    try:
        yield
    except ExperimentError:
        raise
    except (SceneError, ValueError) as error:
        message = str(error)
        if scene_prefix is not None:
            message = re.sub(r"^motion([.:])", lambda m: scene_prefix + ("." if m.group(1) == "." else ":"), message)
        raise ExperimentError(prefix + message) from None
