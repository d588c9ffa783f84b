"""The ``[limit_states]`` table of an experiment file: the capacities its report's Damage section evaluates.

Each key is a kind of limit state (``stochpound.store.LIMIT_STATE_DEMANDS``:
``drift_ratio``, ``residual_drift_ratio``, ``ductility`` (1),
``floor_acceleration`` (g), ``impact_force`` (N), ``isolator_displacement``
(m)); its value a capacity > 0 or a list of them (any building), or a table
of building names to a capacity or a list. ``source`` (optional) says where
the capacities come from. Without the table the report uses
``stochpound.risk.DEFAULT_LIMIT_STATES``.

No run depends on it, so it is not part of the experiment's identity
(``stochpound.store.NOT_IN_IDENTITY``), like ``[hazard]`` and ``[design]``.
"""

from __future__ import annotations

from typing import Any, Mapping, Sequence

from stochpound._errors import SceneError
from stochpound.model import fields as toml_fields
from stochpound.risk import limit_state_problem
from stochpound.store import LIMIT_STATE_DEMANDS, LimitStateCapacities, LimitStates


def parse_limit_states(data: Mapping[str, Any], buildings: Sequence[str]) -> LimitStates | None:
    """The ``[limit_states]`` table of a definition, typed (None without a ``[limit_states]`` table).

    Parameters
    ----------
    data : mapping
        The parsed experiment file.
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
    table = toml_fields.table(data, "limit_states", "")
    if table is None:
        return None
    source = toml_fields.string(table, "source", "limit_states") if "source" in table else None
    states: list[LimitStateCapacities] = []
    for kind, value in table.items():
        if kind == "source":
            continue
        where = f"limit_states.{kind}"
        if kind not in LIMIT_STATE_DEMANDS:
            raise SceneError(f"{where}: not a limit state; one of {', '.join(LIMIT_STATE_DEMANDS)} (or source)")
        if isinstance(value, Mapping):
            for building in value:
                if building not in buildings:
                    raise SceneError(f"{where}.{building}: unknown building (buildings: {', '.join(buildings)})")
            states += [LimitStateCapacities(kind, _capacities(kind, values, f"{where}.{building}", building), building) for building, values in value.items()]
        else:
            states.append(LimitStateCapacities(kind, _capacities(kind, value, where)))
    if not states:
        raise SceneError(f"limit_states: give at least one limit state ({', '.join(LIMIT_STATE_DEMANDS)})")
    return LimitStates(source, tuple(states))


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
