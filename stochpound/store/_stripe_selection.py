"""The conditional-spectrum selection of an ``[intensity]`` table, typed: how every stripe's motions are chosen (docs/intensity.md).

With ``[intensity] selection = "conditional_spectrum"`` every stripe runs
``motions`` motions chosen from the pool and scaled to its level within
``max_scale_factor``, to match the conditional spectrum of the stripe's
scenario. :class:`Selection` holds what that choice depends on, parsed and
checked once (``stochpound.experiment._site.parse_selection``); the
definition's ``intensity`` entry is written from it (:meth:`Selection.entry`)
and read back by :meth:`Selection.from_entry`, unchanged, so definitions and
their identities are. The default ``selection = "scale"`` has no record
(``Intensity.selection`` is None) and adds nothing to the definition.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from stochpound.motions import Scenario
from stochpound.model.fields import TomlTable

@dataclass(frozen=True)
class SimulatedMotions:
    """``[site] simulated_motions``: site-based stochastic motions of each stripe's scenario added to its pool.

    They are not stored: a chosen one is regenerated bit for bit from these
    fields and its realization (``stochpound.motions.site_motions``).

    Attributes
    ----------
    count : int
        Simulated motions per stripe.
    model : str
        The site-motion model (``hazard_compatible``).
    calibration : str
        The model's published equations and calibration (``stochpound.motions.site_model_provenance``).
    seed : int
        The seed of the motions (the selection's).
    dt : float
        Their time step, s.
    sampling : str
        ``scenario``: the scenario's motions, one pool for the stripes of a scenario; ``tilted``: each stripe's own
        ``count`` motions, importance-sampled toward its level (``[site] simulated_sampling``; docs/intensity.md).
        In the entry only when not ``scenario`` (so that the definitions without it keep their identity).
    """

    count: int
    model: str
    calibration: str
    seed: int
    dt: float
    sampling: str = "scenario"

    @classmethod
    def from_entry(cls, entry: Mapping[str, int | str | float]) -> SimulatedMotions:
        """The record of a canonical ``simulated_motions`` entry."""
        sampling = str(entry["sampling"]) if "sampling" in entry else "scenario"
        return cls(entry["count"], entry["model"], entry["calibration"], entry["seed"], entry["dt"], sampling)

    def entry(self) -> dict[str, int | str | float]:
        """The canonical ``simulated_motions`` entry."""
        written: dict[str, int | str | float] = {"count": self.count, "model": self.model, "calibration": self.calibration, "seed": self.seed,
                                                 "dt": self.dt}
        if self.sampling != "scenario":
            written["sampling"] = self.sampling
        return written

    @property
    def sampling_words(self) -> str:
        """How the motions were drawn, in words to follow their count: "" for the scenario's own, a parenthesis for a tilted pool."""
        return " (each stripe's own, importance-sampled toward its level)" if self.sampling == "tilted" else ""

    @property
    def pool_words(self) -> str:
        """The pool's simulated motions in words, e.g. ``2000 simulated motions of each stripe's scenario`` (:attr:`sampling_words`)."""
        return f"{self.count} simulated motions of each stripe's scenario{self.sampling_words}"


@dataclass(frozen=True)
class Selection:
    """How the motions of every stripe are chosen (``[intensity] selection = "conditional_spectrum"``).

    Attributes
    ----------
    method : str
        ``conditional_spectrum`` (the definition's ``intensity.selection``).
    motions : int
        Motions per stripe.
    max_scale_factor : float
        Largest scale factor of a chosen motion (≥ 1).
    seed : int
        Seed of the selection (and of any simulated motions).
    scenarios : tuple of stochpound.motions.Scenario
        The scenario of every stripe, in the order of the sorted levels (the entry's ``site``).
    max_per_earthquake : int or None
        At most this many motions of one earthquake per stripe; None: not given (no limit).
    exclude_pulses : bool or None
        Whether records marked as pulses are left out of the pool; None: not given (kept).
    tolerance_first : bool or None
        Whether a stripe whose set of least misfit misses its target takes a set within the tolerance where the integer
        programme finds one (``stochpound.motions.select_motions``); None: not given (the set of least misfit).
    ruptures : mapping or None
        A site of ruptures' canonical entry (``stochpound.analysis.RuptureSite.to_entry``), whose exact
        conditional spectra are the targets; None for a given or fitted scenario.
    simulated : SimulatedMotions or None
        Simulated motions in every stripe's pool; None without them.
    """

    method: str
    motions: int
    max_scale_factor: float
    seed: int
    scenarios: tuple[Scenario, ...]
    max_per_earthquake: int | None = None
    exclude_pulses: bool | None = None
    ruptures: Mapping[str, Any] | None = None
    simulated: SimulatedMotions | None = None
    tolerance_first: bool | None = None

    @classmethod
    def from_entry(cls, entry: Mapping[str, Any]) -> Selection | None:
        """The selection of a canonical ``intensity`` entry (None for the default ``scale``, which has no ``selection`` key)."""
        if "selection" not in entry:
            return None
        table = TomlTable(entry, "intensity")
        simulated, ruptures = table.table("simulated_motions"), table.table("ruptures")
        return cls(entry["selection"], entry["motions"], entry["max_scale_factor"], entry["seed"],
                   tuple(Scenario(s["magnitude"], s["distance_km"], s["vs30"], s["mechanism"]) for s in entry["site"]),
                   table.integer("max_per_earthquake", None, low=1), table.raw("exclude_pulses"), None if ruptures is None else ruptures.values,
                   SimulatedMotions.from_entry(simulated.values) if simulated is not None else None, table.raw("tolerance_first"))

    def entry(self) -> dict[str, Any]:
        """The selection's keys of the canonical ``intensity`` entry (the optional ones only where given)."""
        written: dict[str, Any] = {"selection": self.method, "motions": self.motions, "max_scale_factor": self.max_scale_factor, "seed": self.seed,
                                   **self.rules, "site": [scenario.loose() for scenario in self.scenarios]}
        if self.ruptures is not None:
            written["ruptures"] = copy.deepcopy(dict(self.ruptures))
        if self.simulated is not None:
            written["simulated_motions"] = self.simulated.entry()
        return written

    @property
    def rules(self) -> dict[str, int | bool]:
        """The selection's rules that were given, as ``stochpound.motions.select_motions`` takes them (``max_per_earthquake``, ``exclude_pulses``,
        ``tolerance_first``)."""
        given = {"max_per_earthquake": self.max_per_earthquake, "exclude_pulses": self.exclude_pulses, "tolerance_first": self.tolerance_first}
        return {key: value for key, value in given.items() if value is not None}
