"""Random streams per realization: realization i depends on (seed, i) alone.

Realization i uses ``numpy.random.Generator(PCG64(SeedSequence(seed, spawn_key=(i,))))``,
which is exactly the i-th child of ``SeedSequence(seed).spawn(n)`` for any n > i.
Generating realizations start..start+n−1 therefore gives the same numbers as
any other split into batches, on any number of workers.
"""

from __future__ import annotations

import numpy as np


def check_seed(seed: object) -> int:
    """Validate a seed (an integer >= 0) and return it."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed: must be an integer >= 0, got {seed!r}")
    return int(seed)


def realization_rng(seed: int, index: int) -> np.random.Generator:
    """The generator of realization ``index`` for ``seed``."""
    return np.random.Generator(np.random.PCG64(np.random.SeedSequence(seed, spawn_key=(int(index),))))


def realization_rngs(seed: int, start: int, count: int) -> list[np.random.Generator]:
    """Generators of the realizations ``start`` to ``start + count − 1``."""
    return [realization_rng(seed, index) for index in range(start, start + count)]
