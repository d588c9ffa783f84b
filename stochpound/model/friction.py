"""A sliding base (the reference study's isolator), flat or a friction pendulum: its states and guards.

Scene keys (``[building.base]``): ``mass`` (kg), the friction law's ``mu``
and ``mu_static``, read by the law (:mod:`stochpound.model.laws`: Coulomb for
a number, velocity-dependent for a table), and either ``restoring_stiffness`` (N/m)
or ``radius`` (m: a friction pendulum of radius R, whose restoring stiffness
is k_r = W/R, so that the isolated rigid mass swings with period
2π √(R/g)). A building without the table stands on a fixed base.

The law (docs/model.md, "Sliding bases"). W = g × (base + floor masses).
A base is in one of four states:

* ``STUCK``: its sliding displacement s is held; the foundation supplies the
  force F_req the stuck equations need, while abs(F_req) ≤ μ_s W;
* ``SLIP_RIGHT`` (+1) / ``SLIP_LEFT`` (−1): the foundation's force on the
  base is −σ μ W for sliding direction σ;
* ``FREE``: a frictionless base (μ = μ_s = 0) is a free degree of freedom
  with no stick state (round-off would flip stick and slip forever).

Guards: a stuck base slips in direction σ when σ F_req − μ_s W crosses 0
upwards (``SLIP``, both directions watched); a slipping base stops when
−σ ṡ crosses 0 upwards (``STOP``). The law is piecewise linear: every state
is a linear mode, so the exact solver takes it.

Mass scaling (experiment variants): W follows the masses; μ is kept.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from stochpound.model import laws
from stochpound.model.fields import TomlTable
from stochpound.model.guards import Guard
from stochpound.model.laws import coulomb, velocity_friction

STUCK = 0
"""Base state: stuck to its foundation."""
SLIP_RIGHT, SLIP_LEFT = 1, -1
"""Base states: slipping right or left."""
FREE = 2
"""Base state: frictionless base, a free degree of freedom."""
FIXED_BASE = math.inf
"""The friction coefficient that stands for a fixed base (no sliding base at all): ∞.

An experiment's μ axis removes the base of a building at this value, and a
result gives it as the ``base_mu`` of a building without a base."""
BASE_KEYS = {"mass", "mu", "mu_static", "restoring_stiffness", "radius"}


def friction_law_name(mu_fast: float | None) -> str:
    """The name of a base's friction law (:data:`stochpound.model.laws.FRICTION_LAWS`): velocity-dependent when it has a μ_fast."""
    return coulomb.COULOMB.name if mu_fast is None else velocity_friction.VELOCITY_DEPENDENT.name


@dataclass(frozen=True)
class Base:
    """A flat sliding (friction) base under a building.

    Attributes
    ----------
    mass : float
        Base mass M_b, kg (> 0).
    mu : float
        Kinetic friction coefficient (>= 0). ``0`` makes a frictionless,
        free base with no stick state.
    mu_static : float
        Static friction coefficient (>= mu); the base sticks while the
        friction force it needs stays within ``mu_static * W``.
    restoring_stiffness : float
        Optional restoring stiffness k_r, N/m (0 with a ``radius``).
    radius : float or None
        Radius R of a friction pendulum, m: k_r = W/R (see :meth:`restoring`).
    mu_fast, mu_rate : float or None
        Velocity-dependent friction (:mod:`stochpound.model.laws.velocity_friction`):
        the coefficient at high velocity and the rate a (s/m); ``mu`` is then
        the coefficient at vanishing velocity. None: Coulomb friction.
    """

    mass: float
    mu: float
    mu_static: float
    restoring_stiffness: float = 0.0
    radius: float | None = None
    mu_fast: float | None = None
    mu_rate: float | None = None

    def restoring(self, weight: float) -> float:
        """The restoring stiffness k_r (N/m) of the base under the building's weight W (N): W/R for a friction pendulum."""
        return weight / self.radius if self.radius is not None else self.restoring_stiffness

    @property
    def friction_law(self) -> str:
        """The name of its friction law (:data:`stochpound.model.laws.FRICTION_LAWS`)."""
        return friction_law_name(self.mu_fast)

    def describe_restoring(self, g: float) -> str:
        """Its restoring force with its parameters and units, for methods text (``g`` in m/s²); its friction: the law's ``describe``."""
        if self.radius is not None:
            return f"friction pendulum, R = {self.radius:.4g} m (k_r = W/R, T_b = 2π √(R/g) = {2.0 * math.pi * math.sqrt(self.radius / g):.4g} s)"
        if self.restoring_stiffness:
            return f"restoring stiffness k_r = {self.restoring_stiffness:.4g} N/m"
        return "flat slider (no restoring force)"

    @property
    def frictionless(self) -> bool:
        """True when the base has no friction (a free degree of freedom)."""
        return self.mu == 0.0 and self.mu_static == 0.0


def is_fixed_base(mu: float | str) -> bool:
    """Whether a friction coefficient stands for a fixed base (μ = ∞, :data:`FIXED_BASE`).

    Parameters
    ----------
    mu : float or str
        Friction coefficient (dimensionless); a store's JSON spells ∞ ``"inf"``.
    """
    return math.isinf(float(mu))


def base_from_table(table: TomlTable | None) -> Base | None:
    """A ``[building.base]`` table, validated; None (a fixed base) when there is none."""
    if table is None:
        return None
    table.reject_unknown(BASE_KEYS)
    mass = table.number("mass", low=0.0, low_open=True)
    mu, mu_static, mu_fast, mu_rate = laws.base_friction_law(table).read(table)
    if "radius" in table and "restoring_stiffness" in table:
        raise table.error("radius", "give either radius (a friction pendulum, k_r = W/R) or restoring_stiffness, not both")
    restoring = table.number("restoring_stiffness", 0.0, low=0.0)
    radius = table.number("radius", None, low=0.0, low_open=True)
    return Base(mass, mu, mu_static, restoring, radius, mu_fast, mu_rate)


@dataclass(frozen=True)
class SlidingBase:
    """A sliding base in a system's layout.

    Attributes
    ----------
    building : int
        Index of its building in the scene.
    dof : int
        Index of its sliding displacement s among the system's DOFs.
    weight : float
        W = g × (base + floor masses), N.
    mu, mu_static : float
        Kinetic (at vanishing velocity, for velocity-dependent friction) and static friction coefficients.
    mu_fast, mu_rate : float or None
        Velocity-dependent friction's coefficient at high velocity and rate (s/m); None: Coulomb.
    """

    building: int
    dof: int
    weight: float
    mu: float
    mu_static: float
    mu_fast: float | None = None
    mu_rate: float | None = None

    @property
    def friction_law(self) -> str:
        """The name of its friction law (:data:`stochpound.model.laws.FRICTION_LAWS`)."""
        return friction_law_name(self.mu_fast)

    @property
    def frictionless(self) -> bool:
        """True when the base has no friction (state ``FREE``)."""
        return self.mu == 0.0 and self.mu_static == 0.0


def initial_state(base: SlidingBase, velocity: float) -> int:
    """The state a base starts settling from: FREE if frictionless, else the sign of its sliding velocity (m/s)."""
    return FREE if base.frictionless else int(np.sign(velocity))


def slipping(state: int) -> bool:
    """True for SLIP_RIGHT and SLIP_LEFT."""
    return state in (SLIP_RIGHT, SLIP_LEFT)


def slip_force(base: SlidingBase, state: int) -> float:
    """The foundation's force on a slipping base with a piecewise-linear friction law (N, positive to the right: Coulomb's −σ μ W).

    A constant of its mode; 0 in other states and with a nonlinear law (a read-out).
    """
    law = laws.friction_law(base.friction_law)
    return float(law.force(base, state, 0.0)) if slipping(state) and law.piecewise_linear else 0.0


def stuck_foundation_force(dof: int, mass: np.ndarray, stiffness: np.ndarray, damping: np.ndarray, load: np.ndarray, inputs: np.ndarray,
                           influence: np.ndarray, rate: tuple[np.ndarray, np.ndarray, np.ndarray], free: np.ndarray) -> tuple[np.ndarray, float, float]:
    """The foundation's force −F_req on a stuck base as an affine map (row over ξ = [q, v, f], a_g coefficient, constant).

    From the base's equation with s̈ = 0: F_req is what the base needs to
    stay put, given the free DOFs' accelerations of the stuck mode.

    Parameters
    ----------
    dof : int
        The base's DOF.
    mass, stiffness, damping : np.ndarray
        The mode's M, K, C (N × N).
    load : np.ndarray
        The mode's constant generalised load (N).
    inputs : np.ndarray
        The generalised load of each read-out f per unit (N × n_f).
    influence : np.ndarray
        r: the ground-acceleration load is −r a_g (kg).
    rate : (A, B, c)
        The mode's ẋ = A x + B a_g + c.
    free : np.ndarray of int
        The DOFs that move in this mode.
    """
    A, B, c = rate
    n = len(mass)
    coupling = mass[dof, free]
    required = -np.concatenate([stiffness[dof], damping[dof], -inputs[dof]]) - coupling @ A[n + free]
    return -required, float(influence[dof] + coupling @ B[n + free]), float(-(load[dof] - coupling @ c[n + free]))


def guards(base: SlidingBase, index: int, state: int, foundation: tuple[np.ndarray, float, float], n_dof: int) -> list[tuple]:
    """The guards of base ``index`` in ``state``: rows (row over x, a_g coefficient, constant, kind, target, direction).

    ``foundation`` is the base's foundation-force map (:func:`stuck_foundation_force` when stuck).
    """
    if state == STUCK:
        row, ground, constant = foundation
        limit = base.mu_static * base.weight
        # F_req = −(foundation force); slip in direction σ when σ F_req > μ_s W
        return [(-sense * row, -sense * ground, -sense * constant - limit, Guard.SLIP, index, sense) for sense in (SLIP_RIGHT, SLIP_LEFT)]
    if slipping(state):
        row = np.zeros(len(foundation[0]))
        row[n_dof + base.dof] = -state
        return [(row, 0.0, 0.0, Guard.STOP, index, 0)]
    return []
