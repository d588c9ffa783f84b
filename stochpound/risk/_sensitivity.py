"""How far g* moves under the choices the answer rests on: the sensitivity table beside g*.

The interval of g* (and "the gap to design to", its upper bound) covers the
sampling of the motions only: which records, from record to record. Larger,
systematic choices move g* too; each is recomputed here alone, with no
bootstrap. From the store itself:

* **the gap grid**: the chain's grid is refined near each g* until g* lies
  between two gaps at most ``stochpound.risk._gap_grid.GRID_TOLERANCE``
  apart (λ_P of stripes is a step function of the gap); the table shows what
  one more refinement gives, every bracket of a g* split ``REFINEMENT``
  times finer (its Δ is below the tolerance where λ_P falls monotonically);
* **the collapse treatment**: the runs beyond the model counted apart as
  collapses (:func:`~stochpound.risk.collapse_risk`), where some run is;
* **modelling dispersion**: β_m folded into every fitted fragility,
  β' = √(β² + β_m²) (the square root of the sum of squares by which FEMA
  P-58 and FEMA P695 combine independent dispersions; a step at θ becomes a
  lognormal of β_m; P-58's range for modelling uncertainty is 0.2–0.4,
  ``MODELLING_DISPERSIONS``).

From other stores of the same experiment (``alternatives``): the selection
seed, the conditioning measure and the moat wall's stiffness
(``ALTERNATIVES``), each store checked to differ from the store only in that
(:func:`check_alternative`); g* of each at the same targets. A choice no store
was given for is named as not evaluated, with what would evaluate it (the
walls' stiffness only where the scene has a wall).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd
import xarray as xr

from stochpound._plurals import counted
from stochpound.risk._collapse import CollapseRisk
from stochpound.risk._fragility import DECREASING, EMPTY, NEVER, ALWAYS
from stochpound.risk._gap_grid import refinement_gaps
from stochpound.risk._inputs import RiskInputError, RiskInputs, has_walls, store_definition, experiment_name, intensity_setting, site_hazard
from stochpound.risk._maf import mean_annual_frequency, rate_at_separation, risk_targeted_separation, target_text

REFINEMENT = 4
"""How many times finer the table's refinement splits each bracket of a g* of the chain's (already refined) grid."""
MODELLING_DISPERSIONS = (0.2, 0.4)
"""β_m folded into the fragility: the ends of FEMA P-58's range for modelling uncertainty."""
ALTERNATIVES = {"seed": "the selection seed", "measure": "the conditioning measure", "wall": "the moat wall's stiffness"}
"""The choices another store evaluates: its kind (as ``stochpound risk --sensitivity-store KIND=PATH`` names it) and the choice in words."""
EVALUATED_BY = {
    "seed": "a store of the same experiment with another [intensity] seed",
    "measure": "a store of the same experiment with another [intensity] measure (its levels, scenarios and [hazard] in that measure)",
    "wall": "a store of the same experiment with the moat walls' stiffness of a retaining wall with backfill (docs/risk.md)",
}
"""What would evaluate each choice of ``ALTERNATIVES``."""
SEED_COLUMN = "selection seed"
"""The head of a seed alternative's column (``selection seed 2``), by which the text finds the seeds' columns."""
SUMMARISED_SEEDS = 3
"""The fewest selection seeds (the store's and its seed alternatives') over which the table and its text summarise g*."""
RATE_SPREAD = "λ_P at their median g*: largest / smallest (×)"
"""The tail of the head of the seeds' rate spread (``selection seeds (5): λ_P at their median g*: …``), a column with no Δ."""
_ANY = ("name", "description", "design", "limit_states", "scene_source", "output", "intensity.note")
"""Entries of a definition no g* depends on: they may differ between a store and its alternative."""
_ALLOWED = {
    "seed": ("intensity.seed", "intensity.simulated_motions.seed"),
    "measure": ("intensity.measure", "intensity.period", "intensity.periods", "intensity.damping", "intensity.levels", "intensity.units",
                "intensity.site", "hazard", "site"),
}
"""Per kind, the entries (and everything under them) its alternative may change; the wall's: any wall's ``stiffness``."""


@dataclasses.dataclass(frozen=True)
class Sensitivity:
    """The sensitivity table of g* (:func:`separation_sensitivity`).

    Attributes
    ----------
    frame : pandas.DataFrame
        Indexed by the configuration and ``target``; columns ``g* (m)`` and, per choice, its g* and ``Δ (%)``.
    grid : str
        How the chain's gap grid was made (its separation's ``grid`` attribute; "" where it does not say).
    not_evaluated : tuple of str
        The kinds of ``ALTERNATIVES`` no store was given for.
    """

    frame: pd.DataFrame
    grid: str = ""
    not_evaluated: tuple[str, ...] = tuple(ALTERNATIVES)

    def text(self) -> str:
        """The table's message in words (:func:`sensitivity_text`)."""
        return sensitivity_text(self.frame, self.grid, self.not_evaluated)

    @property
    def seeds(self) -> int:
        """How many selection seeds the table summarises: the store's and its seed stores' (0 below ``SUMMARISED_SEEDS``)."""
        return _summarised_seeds(self.frame)

    def seeds_beside_design(self, design: pd.DataFrame, years: float) -> pd.DataFrame:
        """The largest g* over the selection seeds beside the gap to design to, per row where both are finite.

        Parameters
        ----------
        design : pandas.DataFrame
            :meth:`~stochpound.risk.StoreRisk.design_frame` of the store: the configuration's dimensions, ``target``
            (probabilities) and ``design`` (m).
        years : float
            The targets' exposure time (yr).

        Returns
        -------
        pandas.DataFrame
            Indexed as ``frame``; columns ``design`` and ``largest`` (m) and ``above`` (the largest wider than the gap to
            design to); empty below ``SUMMARISED_SEEDS`` seeds.
        """
        if not self.seeds:
            return pd.DataFrame(columns=["design", "largest", "above"])
        labelled = design.assign(target=[target_text(p, years) for p in design["target"]]).set_index(list(self.frame.index.names))
        both = pd.DataFrame({"design": labelled["design"], "largest": self.frame[seeds_column(self.seeds, "largest")]})
        both = both[np.isfinite(both.to_numpy(dtype=float)).all(axis=1)]
        return both.assign(above=both["largest"] > both["design"])


def separation_sensitivity(risk: object, store: xr.Dataset | RiskInputs, collapse: CollapseRisk | None = None,
                           dispersions: Sequence[float] = MODELLING_DISPERSIONS, refinement: int = REFINEMENT,
                           alternatives: Sequence[tuple[str, xr.Dataset]] = ()) -> Sensitivity:
    """g* under each choice it rests on, per configuration and target (m), with its change from g* (%).

    Parameters
    ----------
    risk : StoreRisk
        The chain's answer (:func:`~stochpound.risk.store_risk`) of a stripes store.
    store : xarray.Dataset or RiskInputs
        The same store, or its inputs already read (refitted at the finer gaps; the alternatives need the store).
    collapse : CollapseRisk, optional
        The answer with collapses counted apart (a column where some run collapsed).
    dispersions : sequence of float
        β_m values folded into the fragility (> 0).
    refinement : int
        How many times finer the table's refinement splits each bracket of a g* (>= 2).
    alternatives : sequence of (str, xarray.Dataset)
        Other stores of the same experiment, each with its kind (a key of ``ALTERNATIVES``: ``seed``, ``measure``,
        ``wall``) and differing from ``store`` only in that (:func:`check_alternative`); a kind may come more than once.
        A ``measure`` store's g* is taken at the hazard it carries (in its measure), the others' at ``risk``'s hazard.

    Returns
    -------
    Sensitivity
        Its ``frame``: indexed by the configuration and ``target``; columns ``g* (m)`` and, per choice, its g* and ``Δ (%)``;
        with two seed stores or more, also the median and the largest g* over the seeds (``seeds_summary``).

    Raises
    ------
    ValueError
        A bad ``refinement`` or β_m; (``RiskInputError``) an alternative of an unknown kind, or one that differs from the
        store in anything else than its kind's choice, or not in it.
    """
    from stochpound.risk._chain import store_risk

    if refinement < 2:
        raise ValueError(f"refinement: must be an integer >= 2, got {refinement!r}")
    for value in dispersions:
        if not value > 0.0:
            raise ValueError(f"dispersions: each β_m must be > 0, got {value!r}")
    if alternatives and isinstance(store, RiskInputs):
        raise RiskInputError("alternatives: compared with the store's definition: give the store, not its inputs")
    labels = [check_alternative(store, other, kind) for kind, other in alternatives]  # every alternative checked before any work
    gaps = risk.fragility["gap"].values
    targets, years = risk.separation["target"].values, risk.years
    columns = {"g* (m)": risk.separation["separation"]}
    finer = np.union1d(gaps, refinement_gaps(gaps, risk.separation, tolerance=0.0, split=refinement))
    partial = bool(risk.progress) and not isinstance(store, RiskInputs)  # an unfinished store answered from what ran, as the chain's was
    fine = store_risk(store, risk.hazard, targets, years, gaps=finer, bootstrap=0, grid_tolerance=None, partial=partial)
    columns[f"grid ×{refinement} finer near g*"] = fine.separation["separation"]
    if collapse is not None and collapse.collapsed:
        columns["collapses apart"] = collapse.separation["separation"]
    for value in dispersions:
        columns[f"β_m = {value:g}"] = _with_dispersion(risk.fragility, value, risk.hazard, targets, years)
    seeds = [risk]
    for (kind, other), label in zip(alternatives, labels):
        hazard = site_hazard(other) if kind == "measure" else risk.hazard
        name = _unique(label, columns)
        answer = store_risk(other, hazard, targets, years, bootstrap=0, partial=bool(risk.progress))
        columns[name] = answer.separation["separation"]
        if kind == "seed":
            seeds.append(answer)
    summary = seeds_summary([seed.separation["separation"] for seed in seeds])
    columns.update(summary)
    plain = {} if not summary else {seeds_column(len(seeds), RATE_SPREAD): seeds_rate_spread(
        [seed.curve for seed in seeds], summary[seeds_column(len(seeds), "median")])}
    given = {kind for kind, _ in alternatives}
    moot = set() if isinstance(store, RiskInputs) or has_walls(store) else {"wall"}  # no wall: its stiffness is no choice of this answer
    return Sensitivity(_table(columns, years, plain), risk.grid, tuple(k for k in ALTERNATIVES if k not in given | moot))


def seeds_summary(seeds: Sequence[xr.DataArray]) -> dict[str, xr.DataArray]:
    """The median and the largest g* (m) over the selection seeds: the store's g* and its seed alternatives', in that order.

    Parameters
    ----------
    seeds : sequence of xarray.DataArray
        g* of the store and of each seed store, over the same configurations and targets.

    Returns
    -------
    dict of str to xarray.DataArray
        ``selection seeds (N): median`` and ``selection seeds (N): largest`` with ``SUMMARISED_SEEDS`` (3) seeds or more (the
        store's and two others: where its g* lies among them); none with fewer.
    """
    if len(seeds) < SUMMARISED_SEEDS:
        return {}
    over = xr.concat([_dims_only(seed) for seed in seeds], dim="seed")
    return {seeds_column(len(seeds), "median"): over.median("seed"), seeds_column(len(seeds), "largest"): over.max("seed")}


def seeds_column(count: int, what: str) -> str:
    """The head of a column summarising ``count`` selection seeds: ``selection seeds (5): median``."""
    return f"{SEED_COLUMN}s ({count}): {what}"


def seeds_rate_spread(curves: Sequence[xr.Dataset], at: xr.DataArray) -> xr.DataArray:
    """The spread of the rate of pounding over the selection seeds at one gap per row: the largest λ_P over the smallest (×).

    Parameters
    ----------
    curves : sequence of xarray.Dataset
        The risk curve (``maf`` over ``gap``, 1/yr) of each seed's store (:class:`~stochpound.risk.StoreRisk`'s ``curve``).
    at : xarray.DataArray
        The gap (m) per configuration and target to read every curve at: the seeds' median g* (``seeds_summary``).

    Returns
    -------
    xarray.DataArray
        max λ_P / min λ_P over the seeds (≥ 1), per configuration and target; ``inf`` where some seed's λ_P there is 0 (no
        run of that seed closes the gap) and another's not, NaN where the gap is not finite or lies outside a seed's grid.
    """
    rates = xr.concat([_dims_only(rate_at_separation(curve, at)) for curve in curves], dim="seed")
    largest, smallest = rates.max("seed", skipna=False), rates.min("seed", skipna=False)
    with np.errstate(divide="ignore", invalid="ignore"):
        return xr.where(largest > 0.0, largest / smallest, 1.0).where(largest.notnull())


def _table(columns: Mapping[str, xr.DataArray], years: float, plain: Mapping[str, xr.DataArray]) -> pd.DataFrame:
    """The sensitivity frame of g* per choice (``columns``, the first ``g* (m)``): each with its Δ (%) from g*; then ``plain``
    (columns of other units, no Δ)."""
    table = xr.Dataset({name: _dims_only(data) for name, data in {**columns, **plain}.items()}).to_dataframe()
    frame = table.reset_index()
    frame["target"] = [target_text(p, years) for p in frame["target"]]
    config = [name for name in frame.columns if name not in columns and name not in plain and name != "target"]
    frame = frame.set_index([*config, "target"])
    base = frame["g* (m)"]
    for name in [c for c in columns if c != "g* (m)"]:
        with np.errstate(invalid="ignore", divide="ignore"):
            frame[f"{name}: Δ (%)"] = 100.0 * (frame[name] / base - 1.0)
    return frame[["g* (m)", *(c for name in columns if name != "g* (m)" for c in (name, f"{name}: Δ (%)")), *plain]]


def _unique(label: str, taken: Mapping[str, xr.DataArray]) -> str:
    """``label``, or ``label (2)``, ``label (3)`` … where a column of that name is already taken."""
    count = 2
    name = label
    while name in taken:
        name, count = f"{label} ({count})", count + 1
    return name


def check_alternative(store: xr.Dataset, other: xr.Dataset, kind: str) -> str:
    """Check that ``other`` is ``store``'s experiment with only the choice ``kind`` changed, and name its column.

    Parameters
    ----------
    store, other : xarray.Dataset
        Experiment stores; their definitions (as the stores keep them) are compared entry by entry. Their names,
        descriptions, ``[design]``, ``[limit_states]``, ``[output]`` and the intensity's note may differ as well.
    kind : str
        ``seed`` (the ``[intensity]`` seed, and a simulated pool's), ``measure`` (the ``[intensity]`` measure and what follows
        from it: levels, units, the stripes' scenarios, ``[hazard]`` and ``[site]``) or ``wall`` (the stiffness of any wall).

    Returns
    -------
    str
        The alternative's column in the table, e.g. ``selection seed 2``, ``measure PGA``, ``wall stiffness 3.4e+08 N/m``.

    Raises
    ------
    ValueError
        (``RiskInputError``) One line: an unknown ``kind``, or what else differs (its entries), or that the choice does not.
    """
    if kind not in ALTERNATIVES:
        raise RiskInputError(f"kind: must be one of {', '.join(ALTERNATIVES)}, got {kind!r}")
    ours, theirs = store_definition(store).to_dict(), store_definition(other).to_dict()
    relevant = [path for path in _differences(ours, theirs) if not _under(path, _ANY)]
    chosen = [path for path in relevant if _in_choice(path, kind)]
    others = [path for path in relevant if path not in chosen]
    named = f"{kind} store ({experiment_name(other) or 'unnamed'})"
    if others:
        shown = ", ".join(others[:6]) + (f" and {len(others) - 6} more" if len(others) > 6 else "")
        raise RiskInputError(f"{named}: differs from {experiment_name(store) or 'the store'} in more than {ALTERNATIVES[kind]}: {shown}")
    if not chosen:
        raise RiskInputError(f"{named}: does not differ from {experiment_name(store) or 'the store'} in {ALTERNATIVES[kind]}")
    if kind == "measure":
        return f"measure {intensity_setting(other).description}"
    values = sorted({_value(theirs, path) for path in chosen})
    shown = ", ".join(f"{value:.3g}" for value in values)
    return f"{SEED_COLUMN} {shown}" if kind == "seed" else f"wall stiffness {shown} N/m"


def _value(entry: object, path: str) -> float:
    """The number at ``path`` (``a.b[0].c``) of a canonical definition."""
    for part in path.replace("[", ".[").split("."):
        entry = entry[int(part[1:-1])] if part.startswith("[") else entry[part]
    return float(entry)


def _differences(ours: object, theirs: object, path: str = "") -> list[str]:
    """The paths (``a.b[0].c``) where two canonical definitions differ: a table key by key, a list of the same length item by item."""
    if isinstance(ours, Mapping) and isinstance(theirs, Mapping):
        return [p for key in sorted(set(ours) | set(theirs), key=str)
                for p in (_differences(ours.get(key), theirs.get(key), f"{path}.{key}" if path else str(key))
                          if key in ours and key in theirs else [f"{path}.{key}" if path else str(key)])]
    if isinstance(ours, list | tuple) and isinstance(theirs, list | tuple) and len(ours) == len(theirs):
        return [p for index, (a, b) in enumerate(zip(ours, theirs)) for p in _differences(a, b, f"{path}[{index}]")]
    return [] if _same(ours, theirs) else [path]


def _same(ours: object, theirs: object) -> bool:
    """Whether two leaves of a definition are equal (numbers exactly, a flag only to a flag; NaN equal to NaN)."""
    if isinstance(ours, float) and isinstance(theirs, float) and math.isnan(ours) and math.isnan(theirs):
        return True
    return isinstance(ours, bool) == isinstance(theirs, bool) and ours == theirs


def _under(path: str, entries: Sequence[str]) -> bool:
    """Whether ``path`` is one of ``entries`` or lies under one."""
    return any(path == entry or path.startswith((f"{entry}.", f"{entry}[")) for entry in entries)


def _in_choice(path: str, kind: str) -> bool:
    """Whether ``path`` belongs to the choice ``kind`` (a wall's stiffness: ``….wall[i].stiffness``)."""
    if kind == "wall":
        head, _, last = path.rpartition(".")
        return last == "stiffness" and head.rsplit(".", 1)[-1].startswith("wall[")
    return _under(path, _ALLOWED[kind])


def _with_dispersion(fragility: xr.Dataset, dispersion: float, hazard: object, targets: np.ndarray, years: float) -> xr.DataArray:
    """g* with β_m folded into every fit: β' = √(β² + β_m²); steps 'never', 'always', flat and empty fits as they are."""
    status = fragility["status"]
    kept = (status == NEVER) | (status == ALWAYS) | (status == DECREASING) | (status == EMPTY)
    beta = np.sqrt(fragility["beta"] ** 2 + dispersion**2).where(~kept, fragility["beta"])
    maf = mean_annual_frequency(fragility.assign(beta=beta), hazard)
    return risk_targeted_separation(xr.Dataset({"maf": maf}), targets, years)["separation"]


def sensitivity_text(frame: pd.DataFrame, grid: str = "", not_evaluated: Sequence[str] = tuple(ALTERNATIVES)) -> str:
    """The table's message in words: how the chain's grid was made, the largest change of each choice, with several
    selection seeds their spread (a row's largest g* over its smallest), what is not evaluated (each of ``not_evaluated``,
    kinds of ``ALTERNATIVES``, with what would evaluate it) and what the interval bounds."""
    changes = [column for column in frame.columns if column.endswith("Δ (%)")]
    said = []
    for column in changes:
        values = frame[column].to_numpy(dtype=float)
        finite = values[np.isfinite(values)]
        what = column.removesuffix(": Δ (%)")
        said.append(f"{what}: up to {np.max(np.abs(finite)):.1f} %" if finite.size else f"{what}: no finite change (g* inf on one side)")
    said.extend(_seeds_spread(frame))
    grid_said = f" The chain's gap grid: {grid}." if grid else ""
    missing = ("; ".join(f"{ALTERNATIVES[kind]} (needs {EVALUATED_BY[kind]})" for kind in not_evaluated))
    unsaid = f" Not evaluated (each needs other runs): {missing}." if missing else ""
    return ("Sensitivity of g* to the choices it rests on (each alone, no bootstrap; Δ from g*): " + "; ".join(said) + "."
            + grid_said + " β_m cannot spread a gap no run closes (a 'never' step has no θ): its λ stays 0, so g* with β_m stops short of the "
            f"first gap of the grid no run closes (λ interpolated linearly to 0 there).{unsaid} The interval of g* and the gap to design to (its upper bound) bound the "
            "record-to-record sampling of the motions only, none of these choices.")


def _seeds_spread(frame: pd.DataFrame) -> list[str]:
    """With ``SUMMARISED_SEEDS`` seeds or more (the store's and its seed columns'), the spread of g* over them in words (none with fewer)."""
    if not _summarised_seeds(frame):
        return []
    seeds = _seed_columns(frame)
    values = frame[["g* (m)", *seeds]].to_numpy(dtype=float)
    rows = [row for row in values if np.all(np.isfinite(row)) and np.all(row > 0.0)]
    if not rows:
        return [f"the {len(seeds) + 1} selection seeds together: no row with a finite g* > 0 at every seed"]
    spread = max(float(row.max() / row.min()) for row in rows)
    return [f"the {len(seeds) + 1} selection seeds together (the store's and {len(seeds)} others): g* spans up to ×{spread:.2f} in a row "
            f"(its largest over its smallest, over the {len(rows)} of {counted(len(values), 'row')} finite at every seed){_rate_spread(frame)}"]


def _seed_columns(frame: pd.DataFrame) -> list[str]:
    """The g* columns of the seed alternatives (``selection seed 2``, …), not their Δ nor the seeds' summary."""
    return [column for column in frame.columns if column.startswith(f"{SEED_COLUMN} ") and not column.endswith("Δ (%)")]


def _summarised_seeds(frame: pd.DataFrame) -> int:
    """How many selection seeds ``frame`` summarises, the store's and its seed columns' (0 below ``SUMMARISED_SEEDS``)."""
    count = 1 + len(_seed_columns(frame))
    return count if count >= SUMMARISED_SEEDS else 0


def _rate_spread(frame: pd.DataFrame) -> str:
    """The seeds' spread of λ_P at their median g* (the ``RATE_SPREAD`` column) in words, as a clause ("" without the column)."""
    column = next((c for c in frame.columns if c.endswith(RATE_SPREAD)), None)
    if column is None:
        return ""
    values = frame[column].to_numpy(dtype=float)
    finite = values[np.isfinite(values)]
    if not finite.size:
        return ", and λ_P at their median g* is 0 at some seed, or the median off the gap grid, in every row"
    return (f", and the rate of pounding λ_P at their median g* spans up to ×{finite.max():.2f} (over the {finite.size} of "
            f"{counted(values.size, 'row')} where every seed's λ_P there is > 0 and the median on the gap grid)")


def _dims_only(data: xr.DataArray) -> xr.DataArray:
    """``data`` without its coordinates that are not dimensions."""
    return data.drop_vars([name for name in data.coords if name not in data.dims])
