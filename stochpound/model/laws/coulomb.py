"""Coulomb friction of a sliding base (``coulomb``, the reference study's law).

Scene keys (``[building.base]``): ``mu`` (kinetic coefficient, a number) and
``mu_static`` (≥ mu, default mu); the base itself (:mod:`stochpound.model.friction`).

While the base slips in direction σ the foundation's force on it is −σ μ W
(W = g × the building's mass): a constant of each slip mode, so the law is
piecewise linear (:func:`stochpound.model.friction.slip_force` adds it to
the mode's load) and the exact solver takes it. Mass scaling: W follows the
masses; μ is kept.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from stochpound.model.laws.contract import FrictionLaw


class Coulomb(FrictionLaw):
    """``coulomb``: F = −σ μ W while slipping."""

    name = "coulomb"
    title = "Coulomb friction"
    piecewise_linear = True

    def force(self, base: Any, state: int, speed: np.ndarray) -> np.ndarray:
        return np.full(np.shape(speed), -state * base.mu * base.weight)

    def partial(self, base: Any, speed: np.ndarray) -> np.ndarray:
        return np.zeros(np.shape(speed))

    def describe(self, base: Any) -> str:
        return f"{self.title}, μ = {base.mu:.4g}, μ_s = {base.mu_static:.4g}"


COULOMB = Coulomb()
"""Coulomb friction."""
