"""Coulomb friction of a sliding base (``coulomb``, the reference study's law).

Scene keys (``[building.base]``): ``mu`` (kinetic coefficient, a number) and
``mu_static`` (≥ mu, default mu); the base itself (:mod:`stochpound.model.friction`).

While the base slips in direction σ the foundation's force on it is −σ μ W
(W = g × the building's mass): a constant of each slip mode, so the law is
piecewise linear (:func:`stochpound.model.friction.slip_force` adds it to
the mode's load) and the exact solver takes it. Mass scaling: W follows the
masses; μ is kept.

An experiment's μ axis (:meth:`Coulomb.with_mu`) sets ``mu``; ``mu_static``
keeps its ratio to ``mu`` (equal to it unless the scene gives it).
"""

from __future__ import annotations

from typing import Any, Mapping

import math

import numpy as np

from stochpound.model.fields import TomlTable
from stochpound.model.laws.contract import FrictionLaw, ResultVariable


class Coulomb(FrictionLaw):
    """``coulomb``: F = −σ μ W while slipping."""

    name = "coulomb"
    title = "Coulomb friction"
    piecewise_linear = True
    variables = (ResultVariable("base_mu", "mu", "1", "kinetic friction coefficient of the base (inf: a fixed base)", math.inf),
                 ResultVariable("base_mu_static", "mu_static", "1", "static friction coefficient of the base (inf: a fixed base)", math.inf))

    def spells(self, mu: Any) -> bool:
        """``mu`` is a number (or missing or malformed: :meth:`read_mu` names the error)."""
        return not isinstance(mu, Mapping)

    def read_mu(self, table: TomlTable) -> tuple[float, None, None]:
        return table.number("mu", low=0.0), None, None

    def with_mu(self, table: TomlTable, mu: float) -> dict[str, float | dict[str, float]]:
        """``mu`` ← the axis value; ``mu_static`` ← μ × (μ_s/μ) of the table (refused when the table has μ = 0 < μ_s: no ratio)."""
        parameters = self.read(table)
        if parameters.mu == 0.0 and parameters.mu_static > 0.0:
            raise table.error("mu_static", "a μ axis keeps mu_static/mu, which mu = 0 leaves undefined; give mu > 0 or no mu_static")
        return {"mu": float(mu), "mu_static": float(mu) * (parameters.mu_static / parameters.mu if parameters.mu > 0.0 else 1.0)}

    def force(self, base: Any, state: int, speed: np.ndarray) -> np.ndarray:
        return np.full(np.shape(speed), -state * base.mu * base.weight)

    def partial(self, base: Any, speed: np.ndarray) -> np.ndarray:
        return np.zeros(np.shape(speed))

    def describe(self, base: Any) -> str:
        return f"{self.title}, μ = {base.mu:.4g}, μ_s = {base.mu_static:.4g}"


COULOMB = Coulomb()
"""Coulomb friction."""
