"""Memory a run needs, estimated before anything is allocated, and the limit it is checked against.

A run's memory grows with its number of samples: the motion (samples, times,
interval polynomials), the solver's recorded states and energy history, and
the result dataset's time histories. :func:`sample_bytes` bounds the bytes
per sample of a scene from its size alone, so that a motion of absurd length
(``duration = 1e9`` s, ``dt = 1e-9`` s) is refused with one line naming it
instead of failing deep inside numpy.

The limit is ``STOCHPOUND_MEMORY_LIMIT`` (bytes, or a size such as ``64GiB``
or ``500MB``) when set, else half of this machine's physical memory.
"""

from __future__ import annotations

import os
import re

from stochpound._errors import StochpoundError

LIMIT_VARIABLE = "STOCHPOUND_MEMORY_LIMIT"
"""Environment variable that sets the memory limit (a size, e.g. ``64GiB``)."""

_UNITS = {"": 1, "b": 1, "k": 10**3, "kb": 10**3, "kib": 2**10, "m": 10**6, "mb": 10**6, "mib": 2**20,
          "g": 10**9, "gb": 10**9, "gib": 2**30, "t": 10**12, "tb": 10**12, "tib": 2**40}
_SIZE = re.compile(r"^\s*([0-9.]+(?:e[+-]?[0-9]+)?)\s*([a-z]*)\s*$", re.IGNORECASE)


class MemoryLimitError(StochpoundError, ValueError):
    """A run or an ensemble would need more memory than the limit; the message names the field."""


def parse_size(text: str) -> int:
    """Bytes of a size such as ``64GiB``, ``500MB``, ``2e9`` (decimal and binary units).

    Raises
    ------
    ValueError
        If ``text`` is not a size.
    """
    match = _SIZE.match(text)
    if match is None or match.group(2).lower() not in _UNITS:
        raise ValueError(f"{LIMIT_VARIABLE}: must be a size such as 64GiB, 500MB or 2e9 (bytes), got {text!r}")
    return int(float(match.group(1)) * _UNITS[match.group(2).lower()])


def physical_memory() -> int:
    """This machine's physical memory, bytes."""
    return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")


def memory_limit() -> tuple[int, str]:
    """The limit (bytes) and where it comes from (for messages)."""
    text = os.environ.get(LIMIT_VARIABLE, "").strip()
    if text:
        return parse_size(text), f"{LIMIT_VARIABLE}={text}"
    return physical_memory() // 2, f"half of this machine's memory; set {LIMIT_VARIABLE}, e.g. {LIMIT_VARIABLE}=64GiB, to raise it"


def format_bytes(size: float) -> str:
    """``size`` in B, KiB, MiB, GiB or TiB, three significant digits."""
    for unit in ("B", "KiB", "MiB", "GiB", "TiB"):
        if abs(size) < 1024 or unit == "TiB":
            return f"{size:.3g} {unit}"
        size /= 1024
    raise AssertionError("unreachable")


def sample_bytes(n_dof: int, n_buildings: int, max_floors: int, n_contacts: int) -> int:
    """Upper estimate of a run's memory per motion sample, bytes.

    Parameters
    ----------
    n_dof : int
        Degrees of freedom (floors plus sliding bases).
    n_buildings, max_floors, n_contacts : int
        Size of the scene.

    Notes
    -----
    Counted in doubles per sample: the motion (samples, times, four
    polynomial coefficients, the ground at the samples: 7) and a synthetic
    realization's generation (complex spectrum and work arrays: 8); the
    solver's states, twice (engine and recorder: 2 × 2N), energy histories
    (twice, 2 × 6), contact forces, base friction and states (C + 2B); the
    result's displacements (three B × F arrays with a temporary), sliding,
    friction, state and impact-force histories (3B + C) and energies (8).
    The tests check it against the measured peak of real runs.
    """
    doubles = 7 + 8 + 4 * n_dof + 12 + (n_contacts + 2 * n_buildings) + 3 * n_buildings * max_floors + (3 * n_buildings + n_contacts) + 8
    return 8 * doubles


def check_memory(needed: int, what: str) -> None:
    """Refuse ``needed`` bytes above the limit.

    Parameters
    ----------
    needed : int
        Estimated bytes.
    what : str
        The field and what needs the memory, e.g. ``"motion: duration 1e+09 s at dt 0.02 s is 5e+10 samples; a run"``.

    Raises
    ------
    MemoryLimitError
        ``<what> needs about <size>, more than the memory limit of <limit> (<where the limit comes from>)``.
    """
    limit, source = memory_limit()
    if needed > limit:
        raise MemoryLimitError(f"{what} needs about {format_bytes(needed)}, more than the memory limit of {format_bytes(limit)} ({source})")
