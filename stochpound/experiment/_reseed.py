"""An experiment file's text with another ``[intensity] seed``: ``stochpound experiment run --seed``.

The seed of a conditional-spectrum selection chooses a stripe's motions and
draws its simulated ones; another seed is the same experiment with another
sample of motions (the report's "selection seed" sensitivity). Rather than a
copy of the file, the run edits one line of its text: the ``seed`` line of its
``[intensity]`` table (added after the table's header where the file has
none). The edited text is what the store records, so the store says the
seed it ran with, and a rerun of the same command finds the same definition
and resumes. The edit is checked: the edited text, read as TOML, must equal
the file's with that one value changed, else the file is refused (a layout
the line edit cannot reach: a dotted or inline ``intensity`` table).
"""

from __future__ import annotations

import re
import tomllib

from stochpound._errors import ExperimentError
from stochpound.experiment._site import DEFAULT_SEED
from stochpound.store import CONDITIONAL_SPECTRUM

_HEADER = re.compile(r"^\s*\[\s*intensity\s*\]\s*(#.*)?$")
"""The ``[intensity]`` table's header line."""
_TABLE = re.compile(r"^\s*\[")
"""A table's header line (the end of the one before it)."""
_SEED = re.compile(r"^(\s*seed\s*=\s*)[^#\s]+(.*)$")
"""A ``seed = <value>`` line: its key, and what follows the value (a comment)."""


def reseeded_text(text: str, seed: int, source: str) -> str:
    """``text``, an experiment file's (valid TOML), with its ``[intensity] seed`` set to ``seed`` (module docstring).

    Parameters
    ----------
    text : str
        The experiment file's text.
    seed : int
        The selection's seed (>= 0).
    source : str
        The file, for the error message.

    Returns
    -------
    str
        The text with that one line changed or added.

    Raises
    ------
    ExperimentError
        One line: a seed that is not an integer >= 0, a file with no conditional-spectrum selection in an ``[intensity]``
        table, the file's own seed (its store is the file's: nothing to run twice), or a file whose seed the line edit
        cannot set alone.
    """
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise ExperimentError(f"--seed: must be an integer >= 0, got {seed!r}")
    expected = tomllib.loads(text)
    intensity = expected["intensity"] if "intensity" in expected else None
    if not isinstance(intensity, dict) or "selection" not in intensity or intensity["selection"] != CONDITIONAL_SPECTRUM:
        raise ExperimentError(f'--seed: {source} has no [intensity] selection = "{CONDITIONAL_SPECTRUM}", whose seed it sets')
    if (intensity["seed"] if "seed" in intensity else DEFAULT_SEED) == seed:
        raise ExperimentError(f"--seed: {seed} is {source}'s own [intensity] seed: run the file without --seed (its store is beside it)")
    lines = text.splitlines(keepends=True)
    start = next((i for i, line in enumerate(lines) if _HEADER.match(line)), None)
    if start is not None:
        end = next((i for i in range(start + 1, len(lines)) if _TABLE.match(lines[i])), len(lines))
        found = next((i for i in range(start + 1, end) if _SEED.match(lines[i].rstrip("\r\n"))), None)
        if found is None:
            lines.insert(start + 1, f"seed = {seed}\n")
        else:
            body = lines[found].rstrip("\r\n")
            lines[found] = _SEED.sub(rf"\g<1>{seed}\g<2>", body) + lines[found][len(body):]
    edited = "".join(lines)
    intensity["seed"] = seed
    if start is None or tomllib.loads(edited) != expected:
        raise ExperimentError(f"--seed: cannot set the [intensity] seed of {source} alone by editing its seed line (set it in the file)")
    return edited
