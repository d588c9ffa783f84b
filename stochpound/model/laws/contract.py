"""What every law declares: the contract the law registry (:mod:`stochpound.model.laws`) holds laws to.

A *contact law* (of an impact element, between floors or against a wall) is
one :class:`ContactLaw` object in its own module; a *friction law* (of a
sliding base) one :class:`FrictionLaw`. Each object holds, behind one
signature per kind of law:

* its name (the scene file's ``law``), its scene keys and their validation
  (:meth:`ContactLaw.read`, :meth:`FrictionLaw.read`);
* whether it is piecewise linear (only then does every mode stay linear, which
  the exact solver needs; a nonlinear law's force is a read-out of the mode,
  evaluated by :mod:`stochpound.model.readouts`);
* its force and partial derivatives: the element's force F(δ, δ̇, δ̇₀) and
  ∂F/∂δ, ∂F/∂δ̇ (for a piecewise-linear law, k δ + c δ̇ and (k, c): the terms
  it adds to a closed mode, :func:`stochpound.model.contact.closed_terms`);
* its power (the rate of work of its force, the energy term it enters);
* what an experiment's axes do to its parameters: a contact law's mass
  rescaling for variants (:meth:`ContactLaw.rescaled`), a friction law's
  answer to a μ axis (:meth:`FrictionLaw.with_mu`: scale its coefficients or
  refuse, never replace the law);
* ``describe()``: its name, parameters and units, for methods text;
* a friction law's result variables (``FrictionLaw.variables``): how a
  result and a store name its parameters.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from typing import Any, NamedTuple

import numpy as np

from stochpound.model.fields import TomlTable


class ElementParameters(NamedTuple):
    """An impact element's law parameters, as a law reads them from its table (SI units).

    Attributes
    ----------
    stiffness : float
        k (N/m) of a Kelvin–Voigt element; k_h (N/m^1.5) of the Hertz family.
    damping : float
        Dashpot c (N·s/m) of a Kelvin–Voigt element; 0 for laws without one.
    restitution : float or None
        The coefficient of restitution e the law was given (None: none given).
    tensile : bool
        Whether the element separates at δ = 0 (True) or when its force returns to 0.
    mass : float
        The collision's effective mass m_eff (kg): m1 m2/(m1 + m2), or the level's mass against a wall.
    """

    stiffness: float
    damping: float
    restitution: float | None
    tensile: bool
    mass: float


def quantity(value: float, unit: str = "") -> str:
    """``value`` to 4 significant digits with its unit, e.g. ``2.75e+09 N/m^1.5``."""
    return f"{value:.4g}" + (f" {unit}" if unit else "")


class ContactLaw(ABC):
    """A contact law of an impact element (class attributes and methods every law defines).

    Attributes
    ----------
    name : str
        The scene file's ``law``.
    title : str
        Its name in text, with its reference, e.g. ``Hertz-damp (Muthukumar & DesRoches 2006)``.
    formula : str
        Its force while δ > 0, e.g. ``F = k_h δ^{3/2}``.
    keys : frozenset of str
        The element keys it accepts (besides ``law`` and ``gap``).
    piecewise_linear : bool
        True: a closed element adds linear terms to its mode (the exact solver applies).
    stiffness_unit : str
        The unit of its ``stiffness``.
    energy_term : str
        The energy-balance term its power enters (``stochpound.results.record.ENERGY_TERMS``).
    """

    name: str
    title: str
    formula: str
    keys: frozenset[str]
    piecewise_linear: bool
    stiffness_unit: str = "N/m^1.5"
    energy_term: str = "impact"

    @abstractmethod
    def read(self, table: TomlTable, mass: float) -> ElementParameters:
        """The element's parameters from its table (unknown keys already rejected), validated; ``mass``: m_eff (kg)."""

    @abstractmethod
    def force(self, element: ElementParameters, delta: np.ndarray, rate: np.ndarray, onset: float) -> np.ndarray:
        """The element's force F (N) at penetration δ (m), its rate δ̇ (m/s) and the impact's approach velocity δ̇₀ (m/s)."""

    @abstractmethod
    def partials(self, element: ElementParameters, delta: np.ndarray, rate: np.ndarray, onset: float) -> tuple[np.ndarray, np.ndarray]:
        """∂F/∂δ (N/m) and ∂F/∂δ̇ (N·s/m) at (δ, δ̇, δ̇₀)."""

    @abstractmethod
    def describe(self, element: ElementParameters) -> str:
        """The law with its parameters and units, for methods text."""

    def power(self, element: ElementParameters, delta: np.ndarray, rate: np.ndarray, onset: float) -> np.ndarray:
        """The rate of work F δ̇ (W) the element takes from the structure (its ``energy_term``)."""
        return self.force(element, delta, rate, onset) * rate

    def refuse(self, key: str) -> str:
        """Why ``key`` (an impact element's key this law does not take) is refused, for the error message."""
        return f"not a field of law {self.name!r} (its fields: {', '.join(sorted(self.keys))})"

    def separation(self, element: ElementParameters) -> str:
        """When a closed element opens, in words (the nonlinear laws' force vanishes with δ: they never pull)."""
        return "at δ = 0, where its force vanishes (never pulls)"

    def rescaled(self, table: TomlTable, mass_ratio: float) -> dict[str, float]:
        """The fields of the element's table that change when its m_eff changes by ``mass_ratio`` (new/old).

        The stiffness × ratio keeps the impact's time scale for a given
        approach velocity (√(k/m_eff) for Kelvin–Voigt); a given ``damping``
        × ratio keeps its damping ratio (a ``restitution`` is kept). A field
        the table lacks is left for the scene's validation to name.
        """
        return {key: float(table.raw(key)) * mass_ratio for key in ("stiffness", "damping") if key in table}


class FrictionParameters(NamedTuple):
    """A sliding base's friction parameters, as its law reads them from its ``[building.base]`` table.

    Attributes
    ----------
    mu : float
        Kinetic coefficient (at vanishing sliding velocity for velocity-dependent friction), ≥ 0.
    mu_static : float
        Static coefficient, ≥ ``mu``.
    mu_fast, mu_rate : float or None
        Velocity-dependent friction's coefficient at high velocity and its rate a (s/m); None for Coulomb friction.
    """

    mu: float
    mu_static: float
    mu_fast: float | None = None
    mu_rate: float | None = None


class ResultVariable(NamedTuple):
    """A result variable that reports one parameter of a law, one value per building (a sliding base's law).

    Attributes
    ----------
    name : str
        The variable's name in a result and a store, e.g. ``base_mu_fast``.
    field : str
        The :class:`~stochpound.model.friction.Base` attribute it reports.
    units : str
        Its ``units`` attribute (CF spelling, ``1`` for a coefficient).
    long_name : str
        Its ``long_name`` attribute.
    missing : float
        Its value for a building without a base: NaN, or ∞ for the friction
        coefficients (a fixed base is μ = ∞, :data:`~stochpound.model.friction.FIXED_BASE`).
        A base whose law lacks the parameter (its attribute None) gives NaN.
    """

    name: str
    field: str
    units: str
    long_name: str
    missing: float = math.nan


class FrictionLaw(ABC):
    """A friction law of a sliding base: the foundation's force on the base while it slips.

    Attributes
    ----------
    name : str
        The law's name (a base's :attr:`~stochpound.model.friction.Base.friction_law`).
    title : str
        Its name in text, with its reference.
    piecewise_linear : bool
        True: the slip force is a constant of each slip mode (the exact solver applies).
    energy_term : str
        The energy-balance term its power enters.
    variables : tuple of ResultVariable
        The result variables of the parameters it reads
        (:meth:`read`), beyond those of a law before it in the registry.
    """

    name: str
    title: str
    piecewise_linear: bool
    variables: tuple[ResultVariable, ...]
    energy_term: str = "friction"

    @abstractmethod
    def spells(self, mu: Any) -> bool:
        """Whether a base table's ``mu`` value is written in this law's form (a number, a table...)."""

    @abstractmethod
    def read_mu(self, table: TomlTable) -> tuple[float, float | None, float | None]:
        """The law's coefficients from the base table's ``mu``, validated: (μ, μ_fast, a in s/m)."""

    def read(self, table: TomlTable) -> FrictionParameters:
        """The base's friction parameters from its ``[building.base]`` table, validated.

        ``mu`` as the law spells it (:meth:`read_mu`), then ``mu_static``
        (≥ μ, default μ: the coefficient at vanishing velocity).
        """
        mu, fast, rate = self.read_mu(table)
        return FrictionParameters(mu, table.number("mu_static", mu, low=mu), fast, rate)

    @abstractmethod
    def with_mu(self, table: TomlTable, mu: float) -> dict[str, float | dict[str, float]]:
        """The fields of the base table that an experiment's μ-axis value ``mu`` (finite, dimensionless) sets.

        The law scales its coefficients (its rule in its docstring) or
        refuses with a :class:`~stochpound._errors.SceneError` naming the
        field; it never replaces itself by another law.
        """

    @abstractmethod
    def force(self, base: Any, state: int, speed: np.ndarray) -> np.ndarray:
        """The foundation's force (N, positive to the right) on ``base`` (a :class:`~stochpound.model.friction.SlidingBase`) slipping in direction ``state`` (±1) at speed abs(ṡ) (m/s)."""

    @abstractmethod
    def partial(self, base: Any, speed: np.ndarray) -> np.ndarray:
        """∂F/∂ṡ (N·s/m) of :meth:`force` at speed abs(ṡ) (m/s), in either slip direction."""

    @abstractmethod
    def describe(self, base: Any) -> str:
        """The law with its parameters, for methods text (``base``: a :class:`~stochpound.model.friction.Base`)."""

    def power(self, base: Any, state: int, speed: np.ndarray) -> np.ndarray:
        """The rate of work F ṡ (W, ≤ 0) of the foundation's force on the slipping base."""
        return self.force(base, state, speed) * state * speed
