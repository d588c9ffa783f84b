"""Rare-event experiment files: the ``[rare_event]`` table, its scene and its synthetic motion, typed (docs/rare-events.md).

A file with a ``[rare_event]`` table is a rare-event experiment: one subset
simulation (:class:`~stochpound.analysis.SubsetSampler`) of one response of
its scene under one synthetic motion, which ``stochpound experiment run``
runs into a resumable store (:mod:`stochpound.experiment._rare_event_run`).
Beside it the file has ``[experiment]`` (``name``, ``description``,
``scene``), the base scene (``[scene]``, as in any experiment file) and the
motion: one ``[synthetic.<name>]`` table (its ``count`` and ``seed`` are not
used: the sampler draws the normals) or the scene's own synthetic
``[motion]``. Errors name the field and its allowed range in one line.
"""

from __future__ import annotations

import hashlib
import math
import tomllib
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, Mapping

from stochpound._errors import ExperimentError, field_errors
from stochpound._text_files import read_text_file
from stochpound.experiment._spec import _base_scene
from stochpound.analysis import PROPOSALS, RESPONSES, warn_uncertified
from stochpound.motions import SYNTHETIC_TYPES, normal_motion
from stochpound.store import TomlTable, building_names, building_table, canonical_json

TABLE = "rare_event"
"""The experiment file's table that makes it a rare-event experiment."""
RARE_EVENT_METHODS = ("subset",)
"""``rare_event.method``: subset simulation (Au & Beck 2001)."""
LIMIT_STATES = {"isolator_displacement": "base_displacement", "impact_force": "impact_force"}
"""``rare_event.limit_state`` kinds and the response whose ratio to ``capacity`` they take."""
RESPONSE_CHOICES = (*RESPONSES, "limit_state")
CLOSURES = ("closure", "max_closure")
"""The responses run on the contact-free scene (every contact's gap infinite): their exceedance of g is pounding at a gap g."""
_TOP_KEYS = {"experiment", "scene", "synthetic", TABLE}
_KEYS = {"method", "response", "target_probability", "samples_per_level", "p0", "seed", "motion", "contact", "building", "floor",
         "limit_state", "capacity", "max_levels", "proposal"}
FORMAT_VERSION = 1


@dataclass(frozen=True)
class RareEventTable:
    """The ``[rare_event]`` table of an experiment file.

    Attributes
    ----------
    method : str
        ``subset``.
    response : str
        ``closure`` (of the contact-free pair: every contact's gap set to
        infinity, so one run gives P(pounding) at every gap), ``max_closure``
        (the largest closure of any contact of the contact-free pair: P(pounding)
        at one gap on every contact), ``peak_storey_drift``,
        ``base_displacement``, ``impact_force`` or ``limit_state`` (the ratio of
        ``limit_state``'s demand to ``capacity``).
    target_probability : float
        The probability in (0, 0.1] the levels go down to.
    samples_per_level : int
        N, >= 10; p0·N an integer that divides N.
    p0 : float
        The conditional probability of each level, in (0, 0.5].
    seed : int
        The sampler's seed, >= 0.
    motion : str
        The label of the synthetic motion (``scene`` for the scene's own ``[motion]``).
    contact : int or None
        The contact of ``closure`` and ``impact_force``.
    building : str or None
        The building of ``peak_storey_drift``, ``base_displacement`` and ``isolator_displacement``.
    floor : int or None
        The storey of ``peak_storey_drift``.
    limit_state : str or None
        ``isolator_displacement`` or ``impact_force``, with ``response = "limit_state"``.
    capacity : float or None
        The limit state's capacity (m or N), > 0.
    max_levels : int
        Most levels, in [2, 40].
    proposal : str
        The chains' proposal: ``mma`` (Au & Beck's component-wise modified
        Metropolis) or ``acs`` (adaptive conditional sampling; reading it
        warns that it is not certified on a scene's responses).
    """

    method: str
    response: str
    target_probability: float
    samples_per_level: int
    p0: float
    seed: int
    motion: str
    contact: int | None = None
    building: str | None = None
    floor: int | None = None
    limit_state: str | None = None
    capacity: float | None = None
    max_levels: int = 20
    proposal: str = "mma"

    @property
    def sampled(self) -> str:
        """The run's response the sampler reads (a limit state's demand)."""
        return LIMIT_STATES[self.limit_state] if self.response == "limit_state" else self.response

    def to_dict(self) -> dict[str, Any]:
        """The table as the definition writes it (fields left None omitted, and the default proposal, so that a definition
        written before ``proposal`` existed keeps its identity)."""
        return {key: value for key, value in asdict(self).items() if value is not None and (key, value) != ("proposal", "mma")}


@dataclass(frozen=True)
class RareEventDefinition:
    """A rare-event experiment: its name, scene, motion and ``[rare_event]`` table.

    Attributes
    ----------
    name, description : str
        From ``[experiment]``.
    scene : dict
        The base scene's table, its ``[motion]`` removed.
    motion : dict
        The synthetic motion's fields (``type`` and the generator's parameters).
    table : RareEventTable
        The ``[rare_event]`` table.
    path : str
        The experiment file.
    """

    name: str
    description: str
    scene: dict[str, Any]
    motion: dict[str, Any]
    table: RareEventTable
    path: str = ""

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], path: str = "") -> RareEventDefinition:
        """The definition a store holds (``to_dict``'s), typed again."""
        return cls(data["name"], data["description"], dict(data["scene"]), dict(data["motion"]), RareEventTable(**data[TABLE]), path)

    def to_dict(self) -> dict[str, Any]:
        """The canonical definition (written in the store; its sha256 is the experiment's identity)."""
        return {"format": FORMAT_VERSION, "kind": TABLE, "name": self.name, "description": self.description, "scene": self.scene,
                "motion": self.motion, TABLE: self.table.to_dict()}

    @property
    def sha256(self) -> str:
        """sha256 of the canonical definition's JSON."""
        return hashlib.sha256(canonical_json(self.to_dict()).encode()).hexdigest()


def is_rare_event_file(path: str | Path) -> bool:
    """Whether an experiment file has a ``[rare_event]`` table (False for a file that is not TOML: the experiment's reader says why)."""
    try:
        return TABLE in tomllib.loads(read_text_file(Path(path), ExperimentError))
    except (OSError, ExperimentError, tomllib.TOMLDecodeError):
        return False


def load_rare_event(path: str | Path) -> RareEventDefinition:
    """Read and check a rare-event experiment file.

    Raises
    ------
    ExperimentError
        Naming the field and its allowed range.
    """
    path = Path(path)
    data = tomllib.loads(read_text_file(path, ExperimentError))
    with field_errors():
        file = TomlTable(data, "", _TOP_KEYS)
        header = file.table_or_empty("experiment", {"name", "description", "scene"})
        name = header.string("name", path.stem)
        description = header.raw("description", "")
        if not isinstance(description, str):
            raise header.error("description", f"must be a string, got {description!r}")
    scene, _ = _base_scene(file, header, path.parent)
    label, motion = _motion(data, scene)
    table = parse_rare_event(data[TABLE], label, building_names(scene), scene)
    scene = {key: value for key, value in scene.items() if key != "motion"}
    return RareEventDefinition(name, description, scene, motion, table, str(path))


def parse_rare_event(values: Any, motion: str, buildings: list[str], scene: Mapping[str, Any]) -> RareEventTable:
    """The ``[rare_event]`` table, typed and checked against the scene (``motion``: the label of the file's synthetic motion)."""
    if not isinstance(values, dict):
        raise ExperimentError(f"{TABLE}: must be a table (method, response, target_probability, samples_per_level, p0, seed)")
    with field_errors():
        table = TomlTable(values, TABLE, _KEYS)
        method = table.string("method", "subset", choices=RARE_EVENT_METHODS)
        response = table.string("response", choices=RESPONSE_CHOICES)
        target = table.number("target_probability", low=0.0, low_open=True, high=0.1)
        p0 = table.number("p0", 0.1, low=0.0, low_open=True, high=0.5)
        samples = table.integer("samples_per_level", low=10, high=10**6)
        seed = table.integer("seed", low=0, high=2**63 - 1)
        max_levels = table.integer("max_levels", 20, low=2, high=40)
        proposal = table.string("proposal", "mma", choices=tuple(PROPOSALS))
        chains = round(p0 * samples)
        if chains < 1 or not math.isclose(chains, p0 * samples) or samples % chains:
            raise table.error("samples_per_level", f"p0 × samples_per_level must be an integer that divides it (p0 = {p0:g}), got {samples}")
        if table.raw("motion", motion) != motion:
            raise table.error("motion", f"must name the file's synthetic motion ({motion}), got {table.raw('motion')!r}")
        where = _where(table, response, buildings, scene)
    warn_uncertified(proposal)
    return RareEventTable(method, response, target, samples, p0, seed, motion, max_levels=max_levels, proposal=proposal, **where)


def _where(table: TomlTable, response: str, buildings: list[str], scene: Mapping[str, Any]) -> dict[str, Any]:
    """The contact, building, floor, limit state and capacity the response needs (and no other)."""
    limit_state = table.string("limit_state", choices=tuple(LIMIT_STATES)) if response == "limit_state" else None
    sampled = LIMIT_STATES[limit_state] if limit_state else response
    needs = {"contact"} if sampled in ("closure", "impact_force") else set() if sampled == "max_closure" else \
        {"building"} | ({"floor"} if sampled == "peak_storey_drift" else set())
    needs |= {"limit_state", "capacity"} if limit_state else set()
    for key in ("contact", "building", "floor", "limit_state", "capacity"):
        if key in table and key not in needs:
            raise table.error(key, f"not used by response = {response!r} (it takes {', '.join(sorted(needs)) or 'none of contact, building, floor'})")
    if sampled == "max_closure" and not TomlTable(scene, "scene").tables("contact"):
        raise table.error("response", f"{response!r} needs a contact, and the scene has none")
    found: dict[str, Any] = {}
    if "contact" in needs:
        contacts = len(TomlTable(scene, "scene").tables("contact"))
        if not contacts:
            raise table.error("response", f"{response!r} needs a contact, and the scene has none")
        found["contact"] = table.integer("contact", 0, low=0, high=contacts - 1)
    if "building" in needs:
        single = {"default": buildings[0]} if len(buildings) == 1 else {}  # one building: the default
        found["building"] = table.string("building", **single, choices=tuple(buildings))
        if sampled == "base_displacement" and not isinstance(TomlTable(building_table(scene, found["building"])).raw("base"), dict):
            raise table.error("building", f"{found['building']!r} has a fixed base ({sampled} needs a sliding base)")
    if "floor" in needs:
        found["floor"] = table.integer("floor", low=1, high=len(TomlTable(building_table(scene, found["building"])).numbers("mass", ())))
    if limit_state:
        found["limit_state"] = limit_state
        found["capacity"] = table.number("capacity", low=0.0, low_open=True)
    return found


def _motion(data: Mapping[str, Any], scene: Mapping[str, Any]) -> tuple[str, dict[str, Any]]:
    """The label and fields of the file's one synthetic motion: a ``[synthetic.<name>]`` table, or the scene's own ``[motion]``."""
    synthetic = data.get("synthetic", {})
    if not isinstance(synthetic, dict) or len(synthetic) > 1:
        raise ExperimentError("synthetic: a rare-event experiment takes one [synthetic.<name>] table (or the scene's synthetic [motion])")
    if synthetic:
        label, fields = next(iter(synthetic.items()))
        where = f"synthetic.{label}"
    else:
        label, fields, where = "scene", scene.get("motion"), "scene.motion"
        if not isinstance(fields, dict) or fields.get("type") not in SYNTHETIC_TYPES:
            raise ExperimentError(f"synthetic: missing (a [synthetic.<name>] table, or a scene [motion] of type {', '.join(SYNTHETIC_TYPES)})")
    if not isinstance(fields, dict):
        raise ExperimentError(f"{where}: must be a table (type and the generator's parameters)")
    motion = {key: value for key, value in fields.items() if key not in ("count", "seed", "start", "realization")}
    with field_errors(scene_prefix=where):
        normal_motion(motion)
    return label, motion
