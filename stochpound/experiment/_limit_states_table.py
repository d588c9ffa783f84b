"""The ``[limit_states]`` table of an experiment file: the capacities its report's Damage section evaluates.

Each key is a kind of limit state (``stochpound.store.LIMIT_STATE_DEMANDS``:
``drift_ratio``, ``residual_drift_ratio``, ``ductility`` (1),
``floor_acceleration`` (g), ``impact_force`` (N), ``isolator_displacement``
(m)); its value a capacity > 0 or a list of them (any building), or a table
of building names to a capacity or a list. ``source`` (optional) says where
the capacities come from; ``targets`` (optional) each kind's performance
objectives, probabilities in 50 years in (0, 1), shaped as its capacities
(one for all, or a list of as many), for any building or by building;
without them FEMA 356's drifts get ``stochpound.risk``'s default objectives
and other capacities none. Without the table the report uses
``stochpound.risk.DEFAULT_LIMIT_STATES``.

No run depends on it, so it is not part of the experiment's identity
(``stochpound.store.NOT_IN_IDENTITY``), like ``[hazard]`` and ``[design]``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Any

from stochpound._errors import SceneError
from stochpound.risk import limit_state_problem
from stochpound.store import LIMIT_STATE_DEMANDS, LimitStateCapacities, LimitStates, TomlTable


def parse_limit_states(file: TomlTable, buildings: Sequence[str]) -> LimitStates | None:
    """The ``[limit_states]`` table of a definition, typed (None without a ``[limit_states]`` table).

    Parameters
    ----------
    file : TomlTable
        The parsed experiment file (its top level).
    buildings : sequence of str
        The scene's building names.

    Returns
    -------
    LimitStates or None
        ``source`` (str or None) and the capacities of each kind, for any building or by building.

    Raises
    ------
    SceneError
        An unknown kind or building, or a capacity that is not a number > 0, named with the field.
    """
    table = file.table("limit_states")
    if table is None:
        return None
    source = table.string("source", None)
    targets = table.table("targets", LIMIT_STATE_DEMANDS)
    states: list[LimitStateCapacities] = []
    for kind in table:
        if kind in ("source", "targets"):
            continue
        if kind not in LIMIT_STATE_DEMANDS:
            raise table.error(kind, f"not a limit state; one of {', '.join(LIMIT_STATE_DEMANDS)} (or source, targets)")
        value = table.raw(kind)
        if not isinstance(value, dict):
            states.append(LimitStateCapacities(kind, _capacities(kind, value, table.field(kind))))
            continue
        by_building = TomlTable(value, table.field(kind))
        for building in by_building:
            if building not in buildings:
                raise by_building.error(building, f"unknown building (buildings: {', '.join(buildings)})")
        states += [LimitStateCapacities(kind, _capacities(kind, by_building.raw(building), by_building.field(building), building), building)
                   for building in by_building]
    if not states:
        raise SceneError(f"limit_states: give at least one limit state ({', '.join(LIMIT_STATE_DEMANDS)})")
    return LimitStates(source, tuple(dataclasses.replace(state, targets=_targets(targets, state)) for state in states))


def _targets(targets: TomlTable | None, state: LimitStateCapacities) -> tuple[float, ...] | None:
    """The objectives ``[limit_states] targets`` gives a state (one per capacity; None where it gives none), each in (0, 1)."""
    if targets is None or state.kind not in targets:
        return None
    value, where = targets.raw(state.kind), targets.field(state.kind)
    if isinstance(value, dict):
        if state.building not in value:
            return None
        value, where = value[state.building], f"{where}.{state.building}"
    values = value if isinstance(value, list) else [value] * len(state.capacities)
    if len(values) != len(state.capacities):
        raise SceneError(f"{where}: give one target or {len(state.capacities)} (one per capacity), got {len(values)}")
    for i, target in enumerate(values):
        if isinstance(target, bool) or not isinstance(target, (int, float)) or not 0.0 < target < 1.0:
            raise SceneError(f"{where}{f'[{i}]' if isinstance(value, list) else ''}: a target must be a probability in 50 years in (0, 1), got {target!r}")
    return tuple(float(t) for t in values)


def _capacities(kind: str, value: Any, where: str, building: str | None = None) -> tuple[float, ...]:
    """The capacities of ``value`` (one or a list), each checked by the limit states' one rule (``stochpound.risk.limit_state_problem``)."""
    values = value if isinstance(value, list) else [value]
    if not values:
        raise SceneError(f"{where}: give a capacity > 0 or a list of them")
    for i, capacity in enumerate(values):
        problem = limit_state_problem(kind, capacity, building)
        if problem is not None:
            raise SceneError(f"{where}{f'[{i}]' if isinstance(value, list) else ''}: {problem}")
    return tuple(float(capacity) for capacity in values)
