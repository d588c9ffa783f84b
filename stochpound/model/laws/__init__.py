"""The law registry: every contact law and friction law by name (the contract: :mod:`stochpound.model.laws.contract`).

Code asks the registry, never a law's name: ``contact_law(element.law).piecewise_linear``,
``.read(...)``, ``.force(...)``, ``.describe(...)``. A new law is one module
defining its law object, one line here, its tests and its docs entry
(docs/contributing.md, "Adding a physical law").
"""

from __future__ import annotations


from stochpound._errors import SceneError
from stochpound.model.laws import coulomb, hertz, hertz_damp_exact, hertz_damp_ye, jankowski, kelvin, velocity_friction
from stochpound.model.fields import TomlTable
from stochpound.model.laws.contract import ContactLaw, FrictionLaw, ResultVariable

CONTACT_LAWS: dict[str, ContactLaw] = {law.name: law for law in (kelvin.KELVIN, hertz.HERTZ, hertz.HERTZ_DAMP, jankowski.JANKOWSKI,
                                                                 hertz_damp_ye.HERTZ_DAMP_YE, hertz_damp_exact.HERTZ_DAMP_EXACT)}
"""The contact laws of impact elements (contacts and walls), by the scene file's ``law``."""
DEFAULT_CONTACT_LAW = kelvin.KELVIN.name
"""The law of an element whose table gives none."""
FRICTION_LAWS: dict[str, FrictionLaw] = {law.name: law for law in (coulomb.COULOMB, velocity_friction.VELOCITY_DEPENDENT)}
"""The friction laws of sliding bases, by name (a base's ``friction_law``)."""
FRICTION_VARIABLES: tuple[ResultVariable, ...] = tuple(variable for law in FRICTION_LAWS.values() for variable in law.variables)
"""The result variables of every friction law's parameters, in registry order (``base_mu``, ``base_mu_static``, ``base_mu_fast``, ``base_mu_rate``)."""


def contact_law(name: str, prefix: str = "law") -> ContactLaw:
    """The contact law called ``name``; a :class:`~stochpound._errors.SceneError` at ``prefix`` naming the laws if there is none."""
    law = CONTACT_LAWS.get(name)
    if law is None:
        raise SceneError(f"{prefix}: must be one of {', '.join(CONTACT_LAWS)}; got {name!r}")
    return law


def friction_law(name: str) -> FrictionLaw:
    """The friction law called ``name`` (:data:`FRICTION_LAWS`)."""
    return FRICTION_LAWS[name]


def base_friction_law(table: TomlTable) -> FrictionLaw:
    """The friction law of a ``[building.base]`` table: the one whose form its ``mu`` has (:meth:`~stochpound.model.laws.contract.FrictionLaw.spells`)."""
    return next(law for law in FRICTION_LAWS.values() if law.spells(table.raw("mu")))
