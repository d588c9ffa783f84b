"""The one module that edits an experiment's scene dicts: variants, gaps, μ, the motion.

A scene dict has the structure of a scene file (docs/scene-files.md); this
module edits it on the experiment side, reading it as typed parts
(:class:`stochpound.model.scene_tables.SceneTables`: the buildings by name,
their bases, the contacts and walls; a variant's overrides as
:class:`~stochpound.model.scene_tables.SceneOverrides`). Every edit of a case's
scene goes through it, and every edit is a set of fields given to one table
of the scene in one place (``_give``): the values come from the override
tables, the axes, or the rule that owns them (a building's mass scaling,
:func:`stochpound.model.building.scaled_masses`; a law's parameters,
:mod:`stochpound.model.laws`). Validation of the result is left to
:func:`stochpound.scene_from_dict`.

The *mass factor* rule (docs/experiments.md): multiplying a building's
masses by f (floors and base) keeps its dynamics consistent:

* storey dashpots given as ``damping`` are multiplied by sqrt(f), which keeps
  every modal damping ratio (M → fM, K fixed, C → sqrt(f) C); a
  ``damping_ratio`` is kept as it is;
* every contact touching the building and every wall beside it is rescaled
  by its law's rule (:meth:`stochpound.model.laws.contract.ContactLaw.rescaled`)
  with the ratio m_eff,new / m_eff,old, m_eff = m1 m2 / (m1 + m2): for a
  Kelvin–Voigt element k_imp × ratio keeps its impact frequency
  sqrt(k_imp / m_eff), and c_imp follows from the restitution (or, when given
  as ``damping``, × the same ratio, which keeps its damping ratio).
* yielding storeys keep their ``yield_force`` as given (N): a building f
  times heavier is 1/f as strong per unit weight (a variant gives its own
  ``yield_force`` to keep a design).

The *μ axis* rule: a finite μ is given to each chosen base by its friction
law (:meth:`stochpound.model.laws.contract.FrictionLaw.with_mu`), which scales
its coefficients (Coulomb: ``mu`` = μ, ``mu_static`` keeps its ratio to
``mu``; velocity-dependent: ``fast`` = μ, ``slow`` and ``mu_static`` keep
their ratios to ``fast``) or refuses; μ = inf removes the base (a fixed base).
"""

from __future__ import annotations

import copy
from typing import Any, Iterable, Mapping, cast

from stochpound._errors import SceneError
from stochpound.model import laws
from stochpound.model.building import scaled_masses
from stochpound.model.contact import ELEMENT_KEYS, effective_mass
from stochpound.model.fields import TomlTable
from stochpound.model.friction import is_fixed_base
from stochpound.model.scene_tables import BuildingEntry, MotionEntry, OverridesEntry, SceneEntry, SceneOverrides, SceneTables

#: Motion used while validating a scene's structure (the real motion is set per case).
PLACEHOLDER_MOTION: MotionEntry = {"type": "constant", "acceleration": 0.0, "duration": 1.0, "dt": 1.0}


def building_names(scene: SceneEntry) -> list[str]:
    """The names of the scene's buildings, left to right (default names B1, B2, ...)."""
    return list(SceneTables.of(scene).building_names)


def building_table(scene: SceneEntry, name: str) -> BuildingEntry:
    """The ``[[building]]`` table named ``name`` (default names B1, B2, ... included; KeyError if none)."""
    return SceneTables.of(scene).building(name).table.values


def _give(table: TomlTable, fields: Mapping[str, Any], dropped: Iterable[str] = ()) -> None:
    """Give a table of a scene being edited ``fields`` (copies), after dropping the fields ``dropped``, in place: the one way an edit writes the scene."""
    values = cast(dict, table.values)  # the tables of a scene being edited are its deep copy's dicts
    for key in dropped:
        values.pop(key, None)
    values.update(copy.deepcopy(dict(fields)))


def without_motion(scene: SceneEntry) -> SceneEntry:
    """The scene's structure: a shallow copy without its ``[motion]``."""
    return {key: value for key, value in scene.items() if key != "motion"}


def with_motion(structure: SceneEntry, motion: MotionEntry = PLACEHOLDER_MOTION) -> SceneEntry:
    """The scene ``structure`` under the ``[motion]`` table ``motion`` (a shallow copy; default: :data:`PLACEHOLDER_MOTION`)."""
    return {**structure, "motion": dict(motion)}


def with_open_gaps(scene: SceneEntry) -> SceneEntry:
    """A copy of ``scene`` with every contact's gap infinite: its contact-free twin, whose closures run without impacts."""
    draft = SceneTables.of(copy.deepcopy(dict(scene)))
    set_gaps(draft, range(len(draft.contacts)), float("inf"))
    return draft.to_dict()


def apply_overrides(scene: SceneEntry, overrides: Iterable[OverridesEntry]) -> SceneEntry:
    """Apply variant overrides: explicit fields first (in order), then all mass factors.

    Parameters
    ----------
    scene : mapping
        Base scene dict.
    overrides : iterable of mapping
        One override table per variant axis (``building.<name>`` and ``scene`` tables; :class:`~stochpound.model.scene_tables.SceneOverrides`).

    Returns
    -------
    dict
        The new scene dict. The two phases make the result independent of the
        order of the variant axes.
    """
    edited = copy.deepcopy(dict(scene))
    draft = SceneTables.of(edited)
    factors: dict[str, float] = {}
    for override in map(SceneOverrides.of, overrides):
        _give(draft.table, override.scene.table.values)
        _override_contacts(draft, override.contacts)
        for name, fields in override.buildings.items():
            if "mass_factor" in fields:
                factors[name] = factors.get(name, 1.0) * float(fields.raw("mass_factor"))
            _override_building(draft.building(name).table, fields)
    for name, factor in factors.items():
        scale_masses(draft, name, factor)
    return edited


def _override_building(building: TomlTable, fields: TomlTable) -> None:
    """Give a ``[[building]]`` table a variant's fields (its ``mass_factor`` aside).

    ``base = false`` removes the base, a ``base`` table is merged into the
    base's; a ``damping`` or a ``damping_ratio`` replaces both.
    """
    for key in fields:
        value = fields.raw(key)
        if key == "base":
            _give(building, {}, ["base"]) if value is False else _give(building, {"base": {**building.raw("base", {}), **value}})
        elif key != "mass_factor":
            _give(building, {key: value}, ["damping", "damping_ratio"] if key in ("damping", "damping_ratio") else [])


def _override_contacts(scene: SceneTables, part: tuple[TomlTable, ...] | TomlTable | None) -> None:
    """Replace impact-element fields of every contact (one table) or of each contact (a tuple, one table per contact).

    A table that gives ``law`` replaces the element (the old law's
    ``stiffness``, ``restitution``, ``damping`` and ``tensile`` go); one
    without ``law`` replaces only the fields it gives.
    """
    if part is None:
        return
    contacts = scene.contacts
    for contact, fields in zip(contacts, part if isinstance(part, tuple) else [part] * len(contacts)):
        _give(contact, fields.values, ELEMENT_KEYS if "law" in fields else [])


def scale_masses(scene: SceneTables, name: str, factor: float) -> None:
    """Multiply building ``name``'s masses by ``factor`` in place, with what the laws derive from them.

    The building's own rule (:func:`stochpound.model.building.scaled_masses`:
    dashpots × √factor), then every contact touching it and every wall beside
    it by their law's rule (:meth:`stochpound.model.laws.contract.ContactLaw.rescaled`,
    with the ratio of the effective masses, new over old: the factor itself
    for a wall).
    """
    building = scene.building(name)
    old_mass = [float(m) for m in building.table.values["mass"]]
    scaled, base = scaled_masses(building.table, factor)
    _give(building.table, scaled)
    if base:
        _give(building.base, base)
    for contact in scene.contacts:
        try:
            ends = [(str(end_name), int(floor)) for end_name, floor in contact.values["between"]]
            if name not in [end[0] for end in ends]:
                continue
            masses_new = [float(scene.building(end_name).table.values["mass"][floor - 1]) for end_name, floor in ends]
            masses_old = [old_mass[floor - 1] if end_name == name else new for (end_name, floor), new in zip(ends, masses_new)]
        except (KeyError, IndexError, TypeError, ValueError):
            continue  # a malformed contact: scene validation names it
        _rescale_element(contact, effective_mass(*masses_new) / effective_mass(*masses_old))
    for wall in scene.walls:
        if wall.building == name:  # a wall's effective mass is its level's mass, scaled by the factor
            _rescale_element(wall.table, factor)


def _rescale_element(table: TomlTable, mass_ratio: float) -> None:
    """Rescale an impact element's table by its law's rule (a table naming no known law is left for scene validation to name)."""
    try:
        law = laws.contact_law(str(table.raw("law", laws.DEFAULT_CONTACT_LAW)))
    except SceneError:
        return
    _give(table, law.rescaled(table, mass_ratio))


def set_gaps(scene: SceneTables, contacts: Iterable[int], gap: float, walls: Iterable[int] = ()) -> None:
    """Set the gap (m) of the given contacts and walls (0-based indices into ``contact`` and ``wall``) of a scene being edited, in place."""
    for index in contacts:
        _give(scene.contacts[index], {"gap": float(gap)})
    for index in walls:
        _give(scene.walls[index].table, {"gap": float(gap)})


def set_mu(scene: SceneTables, buildings: Iterable[str] | None, mu: float) -> list[str]:
    """Set the friction coefficient μ of buildings of a scene being edited, in place, by each base's friction law; μ = inf removes their base.

    Parameters
    ----------
    scene : SceneTables
        The scene being edited.
    buildings : iterable of str or None
        Buildings to change; None: every building that has a ``[building.base]``.
    mu : float
        The μ axis value (dimensionless), >= 0, or inf for a fixed base. A
        finite μ goes to the base's law
        (:meth:`stochpound.model.laws.contract.FrictionLaw.with_mu`: it scales
        its coefficients or refuses); a malformed base is left for scene
        validation to name.

    Returns
    -------
    list of str
        The chosen buildings that have no base (an error unless μ is inf).

    Raises
    ------
    SceneError
        When a base's law refuses μ, naming the field (``building[0].base.mu.fast: ...``).
    """
    chosen = list(buildings) if buildings is not None else [b.name for b in scene.buildings if b.base is not None]
    missing = []
    for name in chosen:
        building = scene.building(name)
        base = building.base
        if is_fixed_base(mu):
            _give(building.table, {}, ["base"])
        elif base is None:
            missing.append(name)
        else:
            law = laws.base_friction_law(base)
            try:
                law.read(base)
            except SceneError:
                continue  # a malformed base: scene validation names it, as without the axis
            _give(base, law.with_mu(base, float(mu)))
    if buildings is None and not chosen and not is_fixed_base(mu):
        missing.append("(no building has a [building.base])")
    return missing


def reference_scene(scene: SceneEntry, studied: str) -> SceneEntry:
    """The studied building alone on a fixed base (no contacts), same g."""
    tables = SceneTables.of(scene)
    building = copy.deepcopy(dict(tables.building(studied).table.values))
    _give(TomlTable(building), {"name": studied}, ["base", "initial"])
    return {"g": tables.g, "building": [building], "contact": []}
