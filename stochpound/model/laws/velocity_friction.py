"""Velocity-dependent friction of a sliding base (PTFE on steel; Constantinou, Mokha & Reinhorn 1990).

Scene keys: ``[building.base]`` ``mu = { slow = ..., fast = ..., rate = ... }``
instead of a number: the coefficient at vanishing and at high sliding
velocity and the rate a (s/m); ``mu_static`` defaults to ``slow``.

The law (docs/model.md, "Friction laws"): while the base slips at velocity ṡ,

    μ(ṡ) = μ_fast − (μ_fast − μ_slow) exp(−a abs(ṡ)),

and the foundation's force on the base is −sgn(ṡ) μ(ṡ) W; the base sticks
and slips as with Coulomb friction (stick while the force it needs stays
within μ_s W). With μ_fast = μ_slow it is Coulomb friction. Not piecewise
linear: a scene that asks for it runs on the ivp path.

An experiment's μ axis (:meth:`VelocityDependent.with_mu`) sets ``fast``;
``slow`` and a given ``mu_static`` keep their ratios to ``fast`` and
``rate`` is kept: the curve μ(ṡ) is scaled, its shape kept. A μ of 0 is
refused (``fast`` must be > 0).
"""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np

from stochpound._errors import SceneError
from stochpound.model.fields import TomlTable
from stochpound.model.laws.contract import FrictionLaw, ResultVariable

MU_KEYS = {"slow", "fast", "rate"}


def mu_from_table(table: TomlTable) -> tuple[float, float, float]:
    """The ``mu = { slow, fast, rate }`` table: (μ_slow, μ_fast, a in s/m), validated."""
    table.reject_unknown(MU_KEYS)
    slow = table.number("slow", low=0.0)
    fast = table.number("fast", low=slow)
    rate = table.number("rate", low=0.0, low_open=True)
    if fast == 0.0:
        raise table.error("fast", "must be > 0 (a frictionless base is mu = 0)")
    return slow, fast, rate


class VelocityDependent(FrictionLaw):
    """``velocity``: F = −sgn(ṡ) μ(abs(ṡ)) W while slipping (``base.mu`` is μ_slow, ``base.mu_fast`` μ_fast, ``base.mu_rate`` a)."""

    name = "velocity"
    title = "velocity-dependent friction"
    piecewise_linear = False
    variables = (ResultVariable("base_mu_fast", "mu_fast", "1", "friction coefficient at high sliding velocity (nan: Coulomb friction)"),
                 ResultVariable("base_mu_rate", "mu_rate", "s m-1", "rate of the velocity-dependent friction (nan: Coulomb friction)"))

    def spells(self, mu: Any) -> bool:
        """``mu`` is a table ``{ slow, fast, rate }``."""
        return isinstance(mu, Mapping)

    def read_mu(self, table: TomlTable) -> tuple[float, float, float]:
        return mu_from_table(table.table("mu"))

    def with_mu(self, table: TomlTable, mu: float) -> dict[str, float | dict[str, float]]:
        """``fast`` ← the axis value; ``slow`` ← μ × slow/fast and a given ``mu_static`` ← μ × μ_s/fast; ``rate`` kept (μ = 0 refused)."""
        parameters = self.read(table)
        if mu <= 0.0:
            raise SceneError(f"{table.field('mu')}.fast: a μ axis sets fast, which must be > 0 for velocity-dependent friction; got {mu:g}")
        scaled = {"mu": {"slow": float(mu) * (parameters.mu / parameters.mu_fast), "fast": float(mu), "rate": parameters.mu_rate}}
        return scaled | ({"mu_static": float(mu) * (parameters.mu_static / parameters.mu_fast)} if "mu_static" in table else {})

    def force(self, base: Any, state: int, speed: np.ndarray) -> np.ndarray:
        return -state * base.weight * coefficient(base.mu, base.mu_fast, base.mu_rate, speed)

    def partial(self, base: Any, speed: np.ndarray) -> np.ndarray:
        # d(−σ μ(|ṡ|) W)/dṡ = −σ W μ'(|ṡ|) σ: the same in both directions
        return -base.weight * coefficient_slope(base.mu, base.mu_fast, base.mu_rate, speed)

    def describe(self, base: Any) -> str:
        return (f"{self.title} (Constantinou, Mokha & Reinhorn 1990), μ(v) = μ_fast − (μ_fast − μ_slow) exp(−a |v|), μ_slow = {base.mu:.4g}, "
                f"μ_fast = {base.mu_fast:.4g}, a = {base.mu_rate:.4g} s/m, μ_s = {base.mu_static:.4g}")


VELOCITY_DEPENDENT = VelocityDependent()
"""Velocity-dependent friction."""


def coefficient(slow: float, fast: float, rate: float, speed: np.ndarray) -> np.ndarray:
    """μ at sliding speed abs(ṡ) (m/s)."""
    return fast - (fast - slow) * np.exp(-rate * speed)


def coefficient_slope(slow: float, fast: float, rate: float, speed: np.ndarray) -> np.ndarray:
    """dμ/dabs(ṡ) (s/m) at sliding speed abs(ṡ)."""
    return rate * (fast - slow) * np.exp(-rate * speed)
